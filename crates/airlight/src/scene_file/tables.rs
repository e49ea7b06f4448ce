//! Tables of the scene file whose `type` (an SDF node's `shape`) picks the
//! struct their keys fill. Each struct declares the keys of one type, so a
//! key is known to the type whose builder reads it and to no other: a
//! declared field that no builder reads is a compiler warning, and a key
//! that the chosen type does not declare is an error at the key, naming the
//! types that do take it ("`cone_angle` is a key of spot lights, not of
//! point lights"). Like pbrt-v4's report of unused parameters and Mitsuba
//! 3's of unqueried properties, but each table's keys are checked before
//! any of its values is used.
//!
//! The tables are read from the spanned document (`toml::de::DeTable`),
//! so that nested values keep their place in the text.

use super::check::{Checker, Result};
use crate::options::{nearest, one_of};
use serde::de::{self, DeserializeOwned, Visitor};
use serde::{Deserialize, Deserializer};
use std::fmt;
use toml::Spanned;
use toml::de::{DeTable, DeValue, ValueDeserializer};

/// A value of the document as parsed, with its place.
pub(super) type TableValue<'i> = Spanned<DeValue<'i>>;

/// The value of `key` in the table `value` (`None` when it is not a table
/// or has no such key).
pub(super) fn field<'d, 'i>(value: &'d TableValue<'i>, key: &str) -> Option<&'d TableValue<'i>> {
    match value.get_ref() {
        DeValue::Table(t) => t.iter().find(|(k, _)| k.get_ref() == key).map(|(_, v)| v),
        _ => None,
    }
}

/// The `index`th element of the array `value`.
pub(super) fn element<'d, 'i>(value: &'d TableValue<'i>, index: usize) -> Option<&'d TableValue<'i>> {
    match value.get_ref() {
        DeValue::Array(items) => items.get(index),
        _ => None,
    }
}

/// A table's place in the file, all the description keeps of a table that
/// is read later by its type's struct (the `[camera]`, `[medium]`,
/// `[materials]`, `[[objects]]` and `[[lights]]` tables, an SDF node's
/// `children`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TableAt;

impl<'de> Deserialize<'de> for TableAt {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        de::IgnoredAny::deserialize(d).map(|_| TableAt)
    }
}

/// A family of tables told apart by a tag key: the struct of each type,
/// and the keys that every type of the family shares ([`Tagged::Shared`]).
pub(super) trait Tagged: Sized {
    /// The tag's key: `type`, or `shape` for SDF nodes.
    const TAG: &'static str;
    /// The family's name in messages, one and many: ("light", "lights").
    const FAMILY: (&'static str, &'static str);
    /// The type when the table gives no tag (`None`: the tag is required).
    const DEFAULT: Option<&'static str>;
    /// Every type's name, as the tag spells it.
    const TYPES: &'static [&'static str];
    /// The keys every type takes, read into their own struct.
    type Shared: DeserializeOwned;
    /// The keys of type `name`'s struct.
    fn keys(name: &str) -> &'static [&'static str];
    /// The table read as type `name`'s struct.
    fn read(name: &str, table: ValueDeserializer<'_>) -> Result<Self, toml::de::Error>;
}

/// A table read: the keys every type shares, and its type's own.
pub(super) struct Read<'i, T: Tagged> {
    pub shared: T::Shared,
    pub kind: T,
    /// The type's name, as the tag spells it.
    pub name: &'static str,
    /// The type's own keys as written (where an SDF object's node and a
    /// node's children are read from).
    pub table: TableValue<'i>,
}

/// No keys shared by the types of a family.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct NoShared {}

/// Declares a family of tables: an enum with one variant per type, each
/// holding its struct, and the [`Tagged`] reading that dispatches on the
/// tag. The struct's fields are the type's keys; declare each struct with
/// `#[serde(deny_unknown_fields)]` and no `flatten` (its keys are read
/// from what serde asks for).
macro_rules! tagged {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident {
            tag: $tag:literal, family: $family:expr, default: $default:expr, shared: $shared:ty,
            $($(#[$vmeta:meta])* $variant:ident($ty:ty) = $kind:literal,)+
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug)]
        $vis enum $name {
            $($(#[$vmeta])* $variant($ty),)+
        }

        impl $crate::scene_file::tables::Tagged for $name {
            const TAG: &'static str = $tag;
            const FAMILY: (&'static str, &'static str) = $family;
            const DEFAULT: Option<&'static str> = $default;
            const TYPES: &'static [&'static str] = &[$($kind),+];
            type Shared = $shared;

            fn keys(name: &str) -> &'static [&'static str] {
                match name {
                    $($kind => $crate::scene_file::tables::keys_of::<$ty>(),)+
                    _ => &[],
                }
            }

            fn read(name: &str, table: toml::de::ValueDeserializer<'_>) -> Result<Self, toml::de::Error> {
                match name {
                    $($kind => <$ty as serde::Deserialize>::deserialize(table).map($name::$variant),)+
                    _ => Err(<toml::de::Error as serde::de::Error>::custom(format!("unknown type `{name}`"))),
                }
            }
        }
    };
}
pub(super) use tagged;

impl<'a> Checker<'a> {
    /// The value of the document's top-level `key`.
    pub(super) fn section(&self, key: &str) -> Result<&TableValue<'a>> {
        self.document
            .iter()
            .find(|(k, _)| k.get_ref() == key)
            .map(|(_, v)| v)
            .ok_or_else(|| self.err(0..0, format!("the file has no `{key}`")))
    }

    /// The `index`th table of the document's array of tables `key`.
    pub(super) fn section_element(&self, key: &str, index: usize) -> Result<&TableValue<'a>> {
        let array = self.section(key)?;
        element(array, index).ok_or_else(|| self.err(array.span(), format!("`{key}` has no table {index}")))
    }

    /// The table the document's table `key` holds as `name`.
    pub(super) fn section_field(&self, key: &str, name: &str) -> Result<&TableValue<'a>> {
        let table = self.section(key)?;
        field(table, name).ok_or_else(|| self.err(table.span(), format!("`{key}` has no `{name}`")))
    }

    /// The table `value` read as one type of family `T`: its tag checked
    /// against the family's types, every key against its type's (and the
    /// shared) keys, then the values by their structs. `label` names the
    /// table in messages (`lights[2]`).
    pub(super) fn read_table<'i, T: Tagged>(&self, value: &TableValue<'i>, label: &str) -> Result<Read<'i, T>> {
        let span = value.span();
        let DeValue::Table(table) = value.get_ref() else {
            return Err(self.err(span, format!("{label} must be a table")));
        };
        let name = self.tag::<T>(table, span.clone(), label)?;
        let shared_keys = keys_of::<T::Shared>();
        let own_keys = T::keys(name);
        let singular = T::FAMILY.0;
        let (mut shared, mut own) = (DeTable::new(), DeTable::new());
        for (key, v) in table {
            let k = key.get_ref().as_ref();
            if k == T::TAG {
                continue;
            }
            if shared_keys.contains(&k) {
                shared.insert(key.clone(), v.clone());
            } else if own_keys.contains(&k) {
                own.insert(key.clone(), v.clone());
            } else {
                let message = misplaced::<T>(k, name, own_keys, shared_keys);
                return Err(self.err(key.span(), format!("{label} ({name}): {message}")));
            }
        }
        let place = |t: DeTable<'i>| ValueDeserializer::from(Spanned::new(span.clone(), DeValue::Table(t)));
        let fail = |e: toml::de::Error| {
            let at = e.span().map_or(span.start, |s| s.start);
            let message = e.message().trim_end();
            // A key the type needs and the table lacks (a nested table's
            // missing key is placed at that table, as serde says it).
            let missing = message.strip_prefix("missing field `").and_then(|m| m.strip_suffix('`'));
            match missing.filter(|_| e.span() == Some(span.clone())) {
                Some(key) => self.err(span.clone(), format!("{label} ({name}): a {name} {singular} needs `{key}`")),
                None => self.err(at..at, format!("{label} ({name}): {message}")),
            }
        };
        let shared = T::Shared::deserialize(place(shared)).map_err(fail)?;
        let kind = T::read(name, place(own.clone())).map_err(fail)?;
        Ok(Read { shared, kind, name, table: Spanned::new(span, DeValue::Table(own)) })
    }

    /// The type a table's tag names (or the family's default).
    fn tag<T: Tagged>(&self, table: &DeTable<'_>, span: std::ops::Range<usize>, label: &str) -> Result<&'static str> {
        let Some((_, tag)) = table.iter().find(|(k, _)| k.get_ref() == T::TAG) else {
            return T::DEFAULT
                .ok_or_else(|| self.err(span, format!("{label} needs `{}`: {}", T::TAG, one_of(T::TYPES))));
        };
        let given = match tag.get_ref() {
            DeValue::String(s) => s.as_ref(),
            _ => return Err(self.err(tag.span(), format!("{label}.{} must be a name: {}", T::TAG, one_of(T::TYPES)))),
        };
        T::TYPES.iter().copied().find(|t| *t == given).ok_or_else(|| {
            let hint = nearest(given, T::TYPES).map(|t| format!("did you mean `{t}`? ")).unwrap_or_default();
            self.err(
                tag.span(),
                format!("{label}: unknown {} `{given}`; {hint}{} are {}", T::TAG, T::FAMILY.1, one_of(T::TYPES)),
            )
        })
    }
}

/// The family's tag, its types' names and every key they take, each once,
/// added to `words`.
pub(super) fn words<T: Tagged>(words: &mut Vec<&'static str>) {
    let keys = T::TYPES.iter().flat_map(|t| T::keys(t).iter().copied());
    for word in
        [T::TAG].into_iter().chain(T::TYPES.iter().copied()).chain(keys_of::<T::Shared>().iter().copied()).chain(keys)
    {
        if !words.contains(&word) {
            words.push(word);
        }
    }
}

/// Why `key` is not a key of type `name`: the types that take it, or the
/// keys the type takes (with the nearest, when it looks like a slip).
fn misplaced<T: Tagged>(key: &str, name: &str, own: &[&str], shared: &[&str]) -> String {
    let family = T::FAMILY.1;
    let takers: Vec<&str> = T::TYPES.iter().copied().filter(|t| T::keys(t).contains(&key)).collect();
    if !takers.is_empty() {
        return format!("`{key}` is a key of {} {family}, not of {name} {family}", one_of(&takers));
    }
    let takes: Vec<&str> = own.iter().chain(shared).copied().collect();
    let hint = nearest(key, &takes).map(|k| format!("did you mean `{k}`? ")).unwrap_or_default();
    format!("`{key}` is not a key of {name} {family}; {hint}they take {}", takes.join(", "))
}

/// The keys a struct's `Deserialize` asks for: derived impls name their
/// fields to `deserialize_struct`, which this deserializer catches.
pub(super) fn keys_of<T: DeserializeOwned>() -> &'static [&'static str] {
    match T::deserialize(KeyProbe) {
        Err(Probed(keys)) => keys,
        Ok(_) => &[],
    }
}

/// A deserializer that answers every request with the fields asked for.
struct KeyProbe;

#[derive(Debug)]
struct Probed(&'static [&'static str]);

impl fmt::Display for Probed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "keys {:?}", self.0)
    }
}

impl std::error::Error for Probed {}

impl de::Error for Probed {
    fn custom<M: fmt::Display>(_: M) -> Self {
        Probed(&[])
    }
}

impl<'de> Deserializer<'de> for KeyProbe {
    type Error = Probed;

    fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Probed> {
        Err(Probed(&[]))
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        fields: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Probed> {
        Err(Probed(fields))
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf option unit
        unit_struct newtype_struct seq tuple tuple_struct map enum identifier ignored_any
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Two {
        first: f32,
        #[serde(rename = "second_key")]
        second: Option<String>,
    }

    #[test]
    fn keys_are_the_fields_serde_reads() {
        assert_eq!(keys_of::<Two>(), &["first", "second_key"]);
        assert_eq!(keys_of::<NoShared>(), &[] as &[&str]);
    }
}
