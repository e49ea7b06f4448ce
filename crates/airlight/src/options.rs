//! Options declared once. Each setting of a render (a film setting such as
//! `spp`, or an integrator's option such as `steps`) is one [`OptionSpec`]:
//! its key, the kind of value with its bounds, its unit, a one-line doc and
//! how it is read from and written to the type that holds it. The scene
//! file's `[render]` table, the command line's flags, the Python package's
//! keyword arguments, the docs' tables and the fuzzer's key list are all
//! made from these declarations, so that they cannot drift apart.
//!
//! Values arrive as [`OptionValue`]s, whatever their source (TOML, a
//! command-line word, a Python object); [`OptionSpec::apply`] checks one
//! against the option's [`ValueKind`] and stores it. Defaults are not
//! written here: they are what the holding type's `Default` gives, read
//! back through [`OptionSpec::get`].
//!
//! This module knows nothing of scenes or integrators; the tables of
//! declarations live beside the types they set (`scene::settings` and
//! `integrator::options`).

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use std::fmt;

/// A value as given: a TOML value, a word of a command line parsed by
/// [`OptionValue::parse_word`], or a Python object converted by the Python
/// package. [`OptionValue::Default`] asks for the option's default (Python's
/// `None`).
#[derive(Clone, Debug, PartialEq)]
pub enum OptionValue {
    Bool(bool),
    /// Wider than any count, so that a value out of bounds is reported as
    /// given (a Python int may exceed 64 bits).
    Int(i128),
    Float(f64),
    Text(String),
    /// Numbers in brackets: a colour.
    List(Vec<f64>),
    Default,
}

impl OptionValue {
    /// A command-line word: `true`/`false`, an integer, a number, numbers
    /// in brackets (`[0.1,0.2,0.3]`), else text as it stands (a name needs
    /// no quotes on a command line).
    pub fn parse_word(word: &str) -> OptionValue {
        let w = word.trim();
        match w {
            "true" => return OptionValue::Bool(true),
            "false" => return OptionValue::Bool(false),
            _ => {}
        }
        if let Ok(n) = w.parse::<i128>() {
            return OptionValue::Int(n);
        }
        if let Ok(x) = w.parse::<f64>() {
            return OptionValue::Float(x);
        }
        if let Some(inner) = w.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
            let numbers: Result<Vec<f64>, _> = inner.split(',').map(|p| p.trim().parse::<f64>()).collect();
            if let Ok(numbers) = numbers {
                return OptionValue::List(numbers);
            }
        }
        OptionValue::Text(w.to_string())
    }

    /// What the value is, for a message: "the text \"abc\"", "true", "2.5".
    fn describe(&self) -> String {
        match self {
            OptionValue::Bool(b) => b.to_string(),
            OptionValue::Int(n) => n.to_string(),
            OptionValue::Float(x) => x.to_string(),
            OptionValue::Text(s) => format!("the text {s:?}"),
            OptionValue::List(v) => format!("a list of {} numbers", v.len()),
            OptionValue::Default => "nothing".into(),
        }
    }

    /// A 32-bit number as the option value its shortest decimal spells
    /// (0.02, not 0.019999999552965164).
    pub fn real(x: f32) -> OptionValue {
        OptionValue::Float(x.to_string().parse().unwrap_or(x as f64))
    }

    fn number(&self) -> Option<f64> {
        match *self {
            OptionValue::Int(n) => Some(n as f64),
            OptionValue::Float(x) => Some(x),
            _ => None,
        }
    }
}

impl fmt::Display for OptionValue {
    /// As a command line writes it (a scene file quotes text).
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            OptionValue::Bool(b) => write!(f, "{b}"),
            OptionValue::Int(n) => write!(f, "{n}"),
            OptionValue::Float(x) => write!(f, "{x}"),
            OptionValue::Text(s) => write!(f, "{s}"),
            OptionValue::List(v) => {
                let parts: Vec<String> = v.iter().map(|x| x.to_string()).collect();
                write!(f, "[{}]", parts.join(", "))
            }
            OptionValue::Default => write!(f, "auto"),
        }
    }
}

impl<'de> serde::Deserialize<'de> for OptionValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ValueVisitor)
    }
}

struct ValueVisitor;

impl<'de> Visitor<'de> for ValueVisitor {
    type Value = OptionValue;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a boolean, a number, a string or an array of numbers")
    }
    fn visit_bool<E: de::Error>(self, v: bool) -> Result<OptionValue, E> {
        Ok(OptionValue::Bool(v))
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<OptionValue, E> {
        Ok(OptionValue::Int(v as i128))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<OptionValue, E> {
        Ok(OptionValue::Int(v as i128))
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<OptionValue, E> {
        Ok(OptionValue::Float(v))
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<OptionValue, E> {
        Ok(OptionValue::Text(v.to_string()))
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<OptionValue, A::Error> {
        let mut v = Vec::new();
        // Bounded by the scene file's size, which is checked before parsing.
        while let Some(x) = seq.next_element::<f64>()? {
            v.push(x);
        }
        Ok(OptionValue::List(v))
    }
}

/// The kinds of value an option takes, with their bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ValueKind {
    Bool,
    /// A whole number in `min..=max`.
    Count {
        min: u64,
        max: u64,
    },
    /// A number: any finite one, or only those above or from zero.
    Number(NumberRange),
    /// A colour: one number for all three channels, or three; each finite
    /// and ≥ 0.
    Colour,
    /// A name from a closed set: one of these, each of which the holding
    /// type's `FromStr` knows (each table's tests check it).
    Name(&'static [&'static str]),
}

/// Which numbers a [`ValueKind::Number`] takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NumberRange {
    Finite,
    Positive,
    NonNegative,
}

/// A value checked against its option's kind, ready to store.
#[derive(Clone, Debug, PartialEq)]
pub enum Checked {
    Bool(bool),
    Count(u64),
    Number(f64),
    Colour([f64; 3]),
    Name(String),
    /// The option's default was asked for.
    Default,
}

impl Checked {
    pub fn bool(&self) -> bool {
        matches!(self, Checked::Bool(true))
    }
    /// A count, within the bounds its kind gave (so within `u32` for the
    /// options that store one).
    pub fn count(&self) -> u64 {
        match *self {
            Checked::Count(n) => n,
            _ => 0,
        }
    }
    pub fn number(&self) -> f64 {
        match *self {
            Checked::Number(x) => x,
            _ => 0.0,
        }
    }
    pub fn colour(&self) -> glam::Vec3 {
        match *self {
            Checked::Colour([r, g, b]) => glam::Vec3::new(r as f32, g as f32, b as f32),
            _ => glam::Vec3::ZERO,
        }
    }
    pub fn name(&self) -> &str {
        match self {
            Checked::Name(s) => s,
            _ => "",
        }
    }
}

/// Why a value was refused. `message` begins with the option's key, as
/// the scene file spells it; front ends put their own spelling before it
/// (`render.steps`, `--steps`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct OptionError {
    pub key: &'static str,
    /// The value is of the wrong kind (text for a count), rather than of
    /// the right kind and out of bounds.
    pub wrong_type: bool,
    pub message: String,
}

impl ValueKind {
    /// What a value of this kind is, for messages and docs.
    pub fn expected(&self) -> String {
        match *self {
            ValueKind::Bool => "true or false".into(),
            ValueKind::Count { min, max } => format!("an integer from {min} to {max}"),
            ValueKind::Number(NumberRange::Finite) => "a finite number".into(),
            ValueKind::Number(NumberRange::Positive) => "a positive finite number".into(),
            ValueKind::Number(NumberRange::NonNegative) => "a finite number ≥ 0".into(),
            ValueKind::Colour => "a number or three, each finite and ≥ 0".into(),
            ValueKind::Name(names) => one_of(names),
        }
    }

    /// `value` checked for an option `key` of this kind.
    pub fn check(&self, key: &'static str, value: &OptionValue) -> Result<Checked, OptionError> {
        let refuse = |wrong_type: bool| OptionError {
            key,
            wrong_type,
            message: format!("{key} must be {}, got {}", self.expected(), value.describe()),
        };
        if *value == OptionValue::Default {
            return Ok(Checked::Default);
        }
        match (*self, value) {
            (ValueKind::Bool, OptionValue::Bool(b)) => Ok(Checked::Bool(*b)),
            (ValueKind::Count { min, max }, OptionValue::Int(n)) => {
                if (min as i128..=max as i128).contains(n) {
                    Ok(Checked::Count(*n as u64))
                } else {
                    Err(refuse(false))
                }
            }
            (ValueKind::Number(range), v) if v.number().is_some() => {
                let x = v.number().unwrap_or(f64::NAN);
                let ok = x.is_finite()
                    && match range {
                        NumberRange::Finite => true,
                        NumberRange::Positive => x > 0.0,
                        NumberRange::NonNegative => x >= 0.0,
                    };
                if ok { Ok(Checked::Number(x)) } else { Err(refuse(false)) }
            }
            (ValueKind::Colour, v) => {
                let c = match v {
                    OptionValue::List(list) if list.len() == 3 => [list[0], list[1], list[2]],
                    v => match v.number() {
                        Some(x) => [x; 3],
                        None => return Err(refuse(true)),
                    },
                };
                if c.iter().all(|x| x.is_finite() && *x >= 0.0) { Ok(Checked::Colour(c)) } else { Err(refuse(false)) }
            }
            (ValueKind::Name(names), OptionValue::Text(s)) => {
                if names.contains(&s.as_str()) {
                    Ok(Checked::Name(s.clone()))
                } else {
                    Err(refuse(false))
                }
            }
            _ => Err(refuse(true)),
        }
    }
}

/// Stores a listed name's value in `slot`. Every name a [`ValueKind::Name`]
/// lists parses (each table's tests check it); one that did not would
/// leave `slot` as it was.
pub fn set_named<T: std::str::FromStr>(slot: &mut T, v: &Checked) {
    if let Ok(value) = v.name().parse() {
        *slot = value;
    }
}

/// "a, b or c".
pub fn one_of(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [one] => (*one).to_string(),
        [rest @ .., last] => format!("{} or {last}", rest.join(", ")),
    }
}

/// One option of a type `T` (the film settings, an integrator
/// description): everything known about it, in one place.
pub struct OptionSpec<T: 'static> {
    /// The key, as a scene file spells it; the command line's flag is
    /// `--` and the key with `-` for `_`, Python's keyword the key itself.
    pub key: &'static str,
    pub kind: ValueKind,
    /// Unit of a number ("world units", "stops"); empty for none.
    pub unit: &'static str,
    /// One line: what the option does.
    pub doc: &'static str,
    /// The default in words, where `T::default()`'s value does not say it
    /// (it depends on the scene, or "auto").
    pub default_doc: Option<&'static str>,
    /// The option's value in `T`.
    pub get: fn(&T) -> OptionValue,
    /// Stores a checked value ([`Checked::Default`]: the default) in `T`.
    pub set: fn(&mut T, &Checked),
}

impl<T: Default> OptionSpec<T> {
    /// Checks `value` and stores it in `target`.
    pub fn apply(&self, target: &mut T, value: &OptionValue) -> Result<(), OptionError> {
        let checked = self.kind.check(self.key, value)?;
        let checked = match checked {
            Checked::Default => {
                let fallback = (self.get)(&T::default());
                match fallback {
                    OptionValue::Default => Checked::Default,
                    v => self.kind.check(self.key, &v)?,
                }
            }
            c => c,
        };
        (self.set)(target, &checked);
        Ok(())
    }

    /// The default as the docs give it.
    pub fn default_text(&self) -> String {
        match self.default_doc {
            Some(text) => text.to_string(),
            None => (self.get)(&T::default()).to_string(),
        }
    }

    /// Checks the value `target` holds against the option's bounds (for
    /// values set in Rust rather than through [`OptionSpec::apply`]).
    pub fn validate(&self, target: &T) -> Result<(), OptionError> {
        match (self.get)(target) {
            OptionValue::Default => Ok(()),
            v => self.kind.check(self.key, &v).map(|_| ()),
        }
    }
}

/// The option of `table` named `key`.
pub fn find<'a, T>(table: &'a [OptionSpec<T>], key: &str) -> Option<&'a OptionSpec<T>> {
    table.iter().find(|o| o.key == key)
}

/// The command-line flag of a key: `light_steps` → `--light-steps`.
pub fn flag(key: &str) -> String {
    format!("--{}", key.replace('_', "-"))
}

/// The known key nearest `name` when it is a slip of the pen away (at most
/// two letters added, dropped or changed), for "did you mean".
pub(crate) fn nearest<'k>(name: &str, known: &[&'k str]) -> Option<&'k str> {
    known.iter().copied().filter(|k| edit_distance(k, name) <= 2).min_by_key(|k| edit_distance(k, name))
}

/// The Levenshtein distance of two keys (ASCII).
fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, &ca) in a.iter().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let above = row[j + 1];
            row[j + 1] = (diagonal + usize::from(ca != cb)).min(above + 1).min(row[j] + 1);
            diagonal = above;
        }
    }
    row[b.len()]
}

/// Checks every table of declarations takes: each option set to a value
/// other than its default reads back as that value (a `get` that reads
/// another field than `set` writes fails) and back to its default on
/// request; each listed name is known to its type, an unlisted one
/// refused.
#[cfg(test)]
pub(crate) fn check_declarations<'a, T: Default + PartialEq + fmt::Debug + 'static>(
    specs: impl IntoIterator<Item = &'a OptionSpec<T>>,
) {
    for spec in specs {
        let default = T::default();
        let value = match spec.kind {
            ValueKind::Bool => OptionValue::Bool((spec.get)(&default) != OptionValue::Bool(true)),
            ValueKind::Count { min, .. } => OptionValue::Int(min as i128 + 3),
            ValueKind::Number(_) => OptionValue::Float(0.375),
            ValueKind::Colour => OptionValue::List(vec![0.25, 0.5, 0.75]),
            ValueKind::Name(names) => OptionValue::Text(names[names.len() - 1].into()),
        };
        let mut t = T::default();
        spec.apply(&mut t, &value).unwrap_or_else(|e| panic!("{}: {e}", spec.key));
        assert_eq!((spec.get)(&t), value, "{}", spec.key);
        assert_ne!(t, default, "{} changed nothing", spec.key);
        spec.apply(&mut t, &OptionValue::Default).unwrap();
        assert_eq!((spec.get)(&t), (spec.get)(&default), "{} back to its default", spec.key);
        if let ValueKind::Name(names) = spec.kind {
            for name in names {
                let mut t = T::default();
                spec.apply(&mut t, &OptionValue::Text((*name).into())).unwrap();
                assert_eq!((spec.get)(&t), OptionValue::Text((*name).into()), "{}", spec.key);
            }
            assert!(spec.apply(&mut T::default(), &OptionValue::Text("nonesuch".into())).is_err(), "{}", spec.key);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_are_read_as_their_kind() {
        assert_eq!(OptionValue::parse_word("true"), OptionValue::Bool(true));
        assert_eq!(OptionValue::parse_word("12"), OptionValue::Int(12));
        assert_eq!(OptionValue::parse_word("-1.5"), OptionValue::Float(-1.5));
        assert_eq!(OptionValue::parse_word("[0.1, 2,3]"), OptionValue::List(vec![0.1, 2.0, 3.0]));
        assert_eq!(OptionValue::parse_word("filmic"), OptionValue::Text("filmic".into()));
        assert_eq!(OptionValue::parse_word("[a]"), OptionValue::Text("[a]".into()));
    }

    #[test]
    fn kinds_take_their_values_and_refuse_others() {
        let count = ValueKind::Count { min: 1, max: 4 };
        assert_eq!(count.check("n", &OptionValue::Int(4)), Ok(Checked::Count(4)));
        let e = count.check("n", &OptionValue::Int(5)).unwrap_err();
        assert_eq!(e.message, "n must be an integer from 1 to 4, got 5");
        assert!(!e.wrong_type);
        assert!(count.check("n", &OptionValue::Float(2.0)).unwrap_err().wrong_type);
        assert!(count.check("n", &OptionValue::Text("2".into())).unwrap_err().wrong_type);
        let positive = ValueKind::Number(NumberRange::Positive);
        assert_eq!(positive.check("x", &OptionValue::Int(2)), Ok(Checked::Number(2.0)));
        assert!(positive.check("x", &OptionValue::Float(0.0)).is_err());
        assert!(positive.check("x", &OptionValue::Float(f64::INFINITY)).is_err());
        let non_negative = ValueKind::Number(NumberRange::NonNegative);
        assert_eq!(non_negative.check("x", &OptionValue::Float(0.0)), Ok(Checked::Number(0.0)));
        assert!(non_negative.check("x", &OptionValue::Float(-0.1)).is_err());
        assert!(ValueKind::Number(NumberRange::Finite).check("x", &OptionValue::Float(f64::NAN)).is_err());
        assert_eq!(ValueKind::Colour.check("c", &OptionValue::Float(0.5)), Ok(Checked::Colour([0.5; 3])));
        assert_eq!(
            ValueKind::Colour.check("c", &OptionValue::List(vec![0.0, 1.0, 2.0])),
            Ok(Checked::Colour([0.0, 1.0, 2.0]))
        );
        assert!(ValueKind::Colour.check("c", &OptionValue::List(vec![0.0, 1.0])).unwrap_err().wrong_type);
        assert!(!ValueKind::Colour.check("c", &OptionValue::List(vec![0.0, -1.0, 0.0])).unwrap_err().wrong_type);
        assert!(ValueKind::Bool.check("b", &OptionValue::Int(1)).unwrap_err().wrong_type);
        assert_eq!(ValueKind::Bool.check("b", &OptionValue::Default), Ok(Checked::Default));
    }

    #[test]
    fn names_are_listed_in_words() {
        assert_eq!(one_of(&["a"]), "a");
        assert_eq!(one_of(&["a", "b", "c"]), "a, b or c");
    }
}
