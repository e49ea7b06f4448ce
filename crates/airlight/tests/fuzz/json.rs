//! glTF's JSON mutated as a tree, the way a broken exporter or a hostile
//! author would write it: numbers replaced by extreme ones and indices by
//! ones out of range, values of the wrong type, keys and array elements
//! dropped or repeated, arrays cut short.

use super::mutate::Rng;
use serde_json::{Map, Number, Value};

/// Numbers a glTF file should not hold, and indices just past the end.
fn hostile_number(rng: &mut Rng) -> Value {
    let n = |x: f64| Number::from_f64(x).map_or(Value::Null, Value::Number);
    match rng.below(16) {
        0 => Value::from(-1),
        1 => Value::from(0),
        2 => Value::from(1),
        3 => Value::from(2),
        4 => Value::from(3 + rng.below(8) as i64),
        5 => Value::from(u32::MAX),
        6 => Value::from(i64::MAX),
        7 => Value::from(u64::MAX),
        8 => n(1e30),
        9 => n(-1e30),
        10 => n(3.4e38),
        11 => n(1e-45),
        12 => n(0.5),
        13 => Value::from(4),
        14 => Value::from(5126),
        _ => Value::from(1i64 << rng.below(40)),
    }
}

/// A value of another kind than `v`.
fn other_kind(rng: &mut Rng, v: &Value) -> Value {
    match rng.below(6) {
        0 => Value::Null,
        1 => Value::Bool(rng.chance(2)),
        2 => Value::String(["SCALAR", "VEC3", "MAT4", "", "data:,", "../x.bin", "%ff"][rng.below(7)].into()),
        3 => Value::Array(vec![v.clone(), v.clone()]),
        4 => Value::Object(Map::new()),
        _ => hostile_number(rng),
    }
}

/// Mutates one place in `v`, chosen by walking down at random; `depth`
/// bounds the walk.
fn mutate_at(rng: &mut Rng, v: &mut Value, depth: usize) {
    let descend = depth > 0 && rng.below(4) != 0;
    match v {
        Value::Object(map) if descend && !map.is_empty() => {
            let keys: Vec<String> = map.keys().cloned().collect();
            let key = rng.pick(&keys).clone();
            match rng.below(8) {
                0 => {
                    map.remove(&key);
                }
                1 => {
                    let copy = map[&key].clone();
                    map.insert(format!("{key}_"), copy);
                }
                _ => mutate_at(rng, map.get_mut(&key).expect("a key of the map"), depth - 1),
            }
        }
        Value::Array(items) if descend && !items.is_empty() => match rng.below(8) {
            0 => {
                let len = rng.below(items.len());
                items.truncate(len);
            }
            1 => {
                let copy = rng.pick(items).clone();
                let times = [1, 2, 64][rng.below(3)];
                items.extend(std::iter::repeat_n(copy, times));
            }
            _ => {
                let i = rng.below(items.len());
                mutate_at(rng, &mut items[i], depth - 1);
            }
        },
        Value::Number(_) if rng.below(3) != 0 => *v = hostile_number(rng),
        _ => *v = other_kind(rng, v),
    }
}

/// One to four mutations of the document.
pub fn mutate_json(rng: &mut Rng, doc: &mut Value) {
    for _ in 0..1 + rng.below(4) {
        mutate_at(rng, doc, 6);
    }
}
