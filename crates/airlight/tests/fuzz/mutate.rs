//! A small, seeded, structure-aware mutator for the fuzz tests (no nightly
//! toolchain, no fuzzing crate): TOML documents mutated as trees (hostile
//! values, keys removed, renamed, duplicated, types swapped, tables
//! nested), then as text; OBJ files by line and token; binary files by
//! byte. The same seed always gives the same input, so a failure is
//! replayed from the seed it prints.
//!
//! Shared with the CLI crate's path-file fuzz test (`#[path]`).

#![allow(dead_code)]

use toml::{Table, Value};

/// SplitMix64: tiny, and every seed gives an independent stream.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 { 0 } else { (self.next() % n as u64) as usize }
    }
    pub fn chance(&mut self, one_in: usize) -> bool {
        self.below(one_in) == 0
    }
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// The seed of input `i` of a run seeded `base`.
pub fn seed(base: u64, i: u64) -> u64 {
    let mut r = Rng(base ^ i.wrapping_mul(0xd605_bbb5_8c8a_bbfd));
    r.next()
}

/// Numbers and values a careless or hostile author might write.
pub fn hostile_value(rng: &mut Rng, names: &[&str]) -> Value {
    let f = |x: f64| Value::Float(x);
    let i = |x: i64| Value::Integer(x);
    let arr = |v: Vec<Value>| Value::Array(v);
    match rng.below(44) {
        0 => f(f64::NAN),
        1 => f(f64::INFINITY),
        2 => f(f64::NEG_INFINITY),
        3 => f(1e38),
        4 => f(-1e38),
        5 => f(3.5e38),
        6 => f(1e20),
        7 => f(1e-45),
        8 => f(-0.0),
        9 => f(0.0),
        10 => i(0),
        11 => i(-1),
        12 => i(i64::MAX),
        13 => i(i64::MIN),
        14 => i(4_294_967_295),
        15 => i(1 << 40),
        16 => i(65_536),
        17 => i(16_777_217),
        18 => Value::String(String::new()),
        19 => Value::String("x".repeat(10_000)),
        20 => Value::String("../../../../etc/passwd".into()),
        21 => Value::String("/dev/zero".into()),
        22 => Value::String((*rng.pick(names)).into()),
        23 => Value::Boolean(rng.chance(2)),
        24 => arr(vec![]),
        25 => arr(vec![i(1), i(2)]),
        26 => arr(vec![f(f64::NAN); 3]),
        27 => arr(vec![f(0.0), f(1e20), f(0.0)]),
        28 => arr(vec![f(1e30), f(0.0), f(0.0)]),
        29 => arr(vec![f(1e19), f(0.0), f(0.0)]),
        30 => arr(vec![f(0.0); 3]),
        31 => arr(vec![Value::String("a".into()); 3]),
        32 => Value::Table(Table::new()),
        33 => Value::Table(Table::from_iter([("value".to_string(), i(1))])),
        34 => arr(vec![f(1e-30), f(0.0), f(1e-30)]),
        35 => arr(vec![f(0.0), f(-1e20), f(1e-20)]),
        36 => arr(vec![i(1); 4]),
        37 => f(1e9),
        38 => f(-1e10),
        39 => i(2),
        40 => f(0.5),
        41 => arr(vec![f(1e38); 3]),
        42 => arr(vec![arr(vec![i(1)])]),
        _ => f(1e-40),
    }
}

/// A hostile value of the same shape as `v` (a number for a number, three
/// numbers for three): such inputs pass the parser and reach the checks.
pub fn hostile_like(rng: &mut Rng, v: &Value, names: &[&str]) -> Value {
    const NUMBERS: [f64; 16] = [
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        1e38,
        -1e38,
        1e20,
        1e-45,
        -0.0,
        0.0,
        1e9,
        2e9,
        -1.0,
        1e-30,
        3e38,
        1e19,
        0.5,
    ];
    const INTEGERS: [i64; 10] =
        [0, -1, i64::MAX, i64::MIN, 4_294_967_295, 1 << 40, 65_536, 65_537, 16_777_217, 1 << 28];
    let number = |rng: &mut Rng| {
        if rng.chance(3) { Value::Integer(*rng.pick(&INTEGERS)) } else { Value::Float(*rng.pick(&NUMBERS)) }
    };
    match v {
        Value::Integer(_) | Value::Float(_) => number(rng),
        Value::Array(a) if a.len() == 3 && rng.chance(2) => {
            let mut a = a.clone();
            let i = rng.below(3);
            a[i] = number(rng);
            Value::Array(a)
        }
        Value::Array(a) if a.len() == 3 => Value::Array((0..3).map(|_| number(rng)).collect()),
        Value::Boolean(b) => Value::Boolean(!b),
        Value::String(_) if rng.chance(2) => Value::String((*rng.pick(names)).into()),
        _ => hostile_value(rng, names),
    }
}

/// A path to a value in a document: keys and array indices.
#[derive(Clone, Debug)]
pub enum Step {
    Key(String),
    Index(usize),
}

fn paths(value: &Value, prefix: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    match value {
        Value::Table(t) => {
            for (k, v) in t {
                prefix.push(Step::Key(k.clone()));
                out.push(prefix.clone());
                paths(v, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                prefix.push(Step::Index(i));
                out.push(prefix.clone());
                paths(v, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn get_mut<'a>(root: &'a mut Value, path: &[Step]) -> Option<&'a mut Value> {
    let mut v = root;
    for step in path {
        v = match (step, v) {
            (Step::Key(k), Value::Table(t)) => t.get_mut(k)?,
            (Step::Index(i), Value::Array(a)) => a.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(v)
}

/// The table or array holding `path`'s last step, and that step.
fn parent_mut<'a>(root: &'a mut Value, path: &'a [Step]) -> Option<(&'a mut Value, &'a Step)> {
    let (last, up) = path.split_last()?;
    Some((get_mut(root, up)?, last))
}

/// Applies one to `count` tree mutations to `doc`. `names` are key and
/// value names worth trying (those of the format).
pub fn mutate_tree(rng: &mut Rng, doc: &mut Table, names: &[&str], count: usize) {
    let mut root = Value::Table(std::mem::take(doc));
    for _ in 0..1 + rng.below(count) {
        let mut all = Vec::new();
        paths(&root, &mut Vec::new(), &mut all);
        if all.is_empty() {
            if let Value::Table(t) = &mut root {
                t.insert((*rng.pick(names)).into(), hostile_value(rng, names));
            }
            continue;
        }
        let path = rng.pick(&all).clone();
        // Half the time only values change, keeping their shape.
        if rng.chance(2) {
            if let Some(v) = get_mut(&mut root, &path)
                && !matches!(v, Value::Table(_))
            {
                *v = hostile_like(rng, v, names);
            }
            continue;
        }
        match rng.below(9) {
            // A hostile value in place of one.
            0..=2 => {
                if let Some(v) = get_mut(&mut root, &path) {
                    *v = hostile_value(rng, names);
                }
            }
            // A key removed.
            3 => match parent_mut(&mut root, &path) {
                Some((Value::Table(t), Step::Key(k))) => {
                    t.remove(k);
                }
                Some((Value::Array(a), Step::Index(i))) => {
                    a.remove(*i);
                }
                _ => {}
            },
            // A key renamed: to another name of the format, or garbage.
            4 => {
                if let Some((Value::Table(t), Step::Key(k))) = parent_mut(&mut root, &path)
                    && let Some(v) = t.remove(k)
                {
                    let name = if rng.chance(4) { format!("{k}_") } else { (*rng.pick(names)).to_string() };
                    t.insert(name, v);
                }
            }
            // A type swapped.
            5 => {
                if let Some(v) = get_mut(&mut root, &path) {
                    *v = match std::mem::replace(v, Value::Boolean(false)) {
                        Value::Integer(n) => Value::String(n.to_string()),
                        Value::Float(x) => Value::Integer(x as i64),
                        Value::String(s) => Value::Float(s.len() as f64),
                        Value::Array(mut a) if !a.is_empty() => a.swap_remove(0),
                        Value::Table(t) => Value::Array(vec![Value::Table(t)]),
                        other => Value::Array(vec![other]),
                    };
                }
            }
            // A value nested one table deeper.
            6 => {
                if let Some(v) = get_mut(&mut root, &path) {
                    let inner = std::mem::replace(v, Value::Boolean(false));
                    let key = (*rng.pick(names)).to_string();
                    *v = Value::Table(Table::from_iter([(key, inner)]));
                }
            }
            // A value copied to another place (a light's table into objects, …).
            7 => {
                let source = get_mut(&mut root, &path).map(|v| v.clone());
                let target = rng.pick(&all).clone();
                if let (Some(source), Some(v)) = (source, get_mut(&mut root, &target)) {
                    match v {
                        Value::Array(a) => a.push(source),
                        Value::Table(t) => {
                            t.insert((*rng.pick(names)).into(), source);
                        }
                        other => *other = source,
                    }
                }
            }
            // An array item or table duplicated in place.
            _ => {
                if let Some((Value::Array(a), Step::Index(i))) = parent_mut(&mut root, &path) {
                    let item = a[*i].clone();
                    a.insert(*i, item);
                }
            }
        }
    }
    if let Value::Table(t) = root {
        *doc = t;
    }
}

/// Text mutations, applied sometimes after the tree's: a line duplicated
/// (a duplicate key), removed or swapped, the text cut short, bytes
/// inserted (not always UTF-8).
pub fn mutate_text(rng: &mut Rng, text: &str) -> Vec<u8> {
    let mut lines: Vec<Vec<u8>> = text.lines().map(|l| l.as_bytes().to_vec()).collect();
    if lines.is_empty() {
        lines.push(Vec::new());
    }
    match rng.below(7) {
        0 => {
            let i = rng.below(lines.len());
            let line = lines[i].clone();
            lines.insert(i, line);
        }
        1 => {
            lines.remove(rng.below(lines.len()));
        }
        2 => {
            let (a, b) = (rng.below(lines.len()), rng.below(lines.len()));
            lines.swap(a, b);
        }
        3 => {
            let mut all = lines.join(&b"\n"[..]);
            all.truncate(rng.below(all.len() + 1));
            return all;
        }
        4 => {
            let i = rng.below(lines.len());
            let at = rng.below(lines[i].len() + 1);
            let junk: &[&[u8]] = &[b"\xff", b"\"", b"[", b"]]", b"=", b"\x00", b"#", b"{", b"\\u{0}", b"1e999"];
            let bytes = rng.pick(junk).to_vec();
            lines[i].splice(at..at, bytes);
        }
        5 => {
            let i = rng.below(lines.len());
            lines.insert(i, b"[[objects]]".to_vec());
        }
        _ => {
            let i = rng.below(lines.len());
            lines.insert(i, b"[render]".to_vec());
        }
    }
    lines.join(&b"\n"[..])
}

/// OBJ mutations by line and token.
pub fn mutate_obj(rng: &mut Rng, obj: &str) -> Vec<u8> {
    const TOKENS: [&str; 22] = [
        "nan",
        "inf",
        "-inf",
        "1e38",
        "1e39",
        "-0",
        "0",
        "-1",
        "99999999999",
        "-99999999999",
        "4294967296",
        "1/2/3",
        "//",
        "",
        "x",
        "1e-45",
        "-4",
        "1e19",
        "2147483648",
        "9223372036854775807",
        "1/-9999999999999999999/1",
        "3//",
    ];
    let mut lines: Vec<String> = obj.lines().map(str::to_string).collect();
    for _ in 0..1 + rng.below(3) {
        if lines.is_empty() {
            lines.push("f 1 2 3".into());
        }
        let i = rng.below(lines.len());
        match rng.below(8) {
            0..=2 => {
                let mut words: Vec<String> = lines[i].split_whitespace().map(str::to_string).collect();
                if words.len() > 1 {
                    let w = 1 + rng.below(words.len() - 1);
                    words[w] = rng.pick(&TOKENS).to_string();
                }
                lines[i] = words.join(" ");
            }
            3 => {
                lines.remove(i);
            }
            4 => {
                let line = lines[i].clone();
                lines.insert(i, line);
            }
            5 => {
                let n = 3 + rng.below(2000);
                let face: Vec<String> = (0..n).map(|k| (1 + k % 9).to_string()).collect();
                lines.insert(i, format!("f {}", face.join(" ")));
            }
            6 => lines.insert(
                i,
                rng.pick(&[
                    "mtllib /etc/passwd",
                    "mtllib ../../x.mtl",
                    "usemtl x",
                    "f",
                    "v",
                    "vt 1e99999 2",
                    "o \u{0}",
                    "l 1 2",
                    "p 1",
                ])
                .to_string(),
            ),
            _ => {
                let at = rng.below(lines[i].len() + 1);
                if lines[i].is_char_boundary(at) {
                    let text = *rng.pick(&["\u{fffd}", " ", "/", "-", "e", "."]);
                    lines[i].insert_str(at, text);
                }
            }
        }
    }
    let mut bytes = lines.join("\n").into_bytes();
    if rng.chance(20) {
        bytes.truncate(rng.below(bytes.len() + 1));
    }
    if rng.chance(30) {
        let at = rng.below(bytes.len() + 1);
        bytes.insert(at, 0xff);
    }
    bytes
}

/// Byte mutations of a binary file (an EXR); `fields` are offsets worth
/// hitting (the header's size fields).
pub fn mutate_bytes(rng: &mut Rng, bytes: &mut Vec<u8>, fields: &[usize]) {
    const WORDS: [u32; 10] = [0, 1, 0x7fff_ffff, 0xffff_ffff, 100_000, 99_999, 65_536, 0x8000_0000, 255, 16];
    for _ in 0..1 + rng.below(4) {
        if bytes.is_empty() {
            bytes.push(0);
        }
        match rng.below(7) {
            0 | 1 => {
                let i = rng.below(bytes.len());
                bytes[i] ^= 1 << rng.below(8);
            }
            2 => {
                let i = rng.below(bytes.len());
                bytes[i] = rng.next() as u8;
            }
            3 | 4 => {
                let at = if !fields.is_empty() && rng.chance(2) { *rng.pick(fields) } else { rng.below(bytes.len()) };
                let word = rng.pick(&WORDS).to_le_bytes();
                for (k, b) in word.iter().enumerate() {
                    if let Some(x) = bytes.get_mut(at + k) {
                        *x = *b;
                    }
                }
            }
            5 => {
                let len = rng.below(bytes.len() + 1);
                bytes.truncate(len);
            }
            _ => {
                let (from, len) = (rng.below(bytes.len()), 1 + rng.below(64));
                let chunk: Vec<u8> = bytes[from..(from + len).min(bytes.len())].to_vec();
                let at = rng.below(bytes.len() + 1);
                bytes.splice(at..at, chunk);
            }
        }
    }
}
