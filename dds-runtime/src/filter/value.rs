//! What a filter reads from a sample: [`FieldValue`], the [`FilterFields`] access trait that
//! `#[derive(DdsType)]` implements, and its impls for the member types of `cdr`.

use std::cmp::Ordering;
use std::collections::BTreeMap;

use crate::cdr::{BoundedSeq, BoundedString, Fixed, LongDouble, WChar, WString};

/// One step of a member path: a member (or union branch) name, or an element index.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum PathSegment {
    /// A member of a struct, or a branch of a union, by its IDL name.
    Member(Box<str>),
    /// An element of a sequence or an array.
    Index(usize),
}

impl PathSegment {
    /// The member name, if this is a member step.
    pub fn member(&self) -> Option<&str> {
        match self {
            PathSegment::Member(m) => Some(m),
            PathSegment::Index(_) => None,
        }
    }
}

/// A value a filter compares. Strings borrow from the sample, so evaluating a filter allocates nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FieldValue<'a> {
    /// A signed integer.
    Int(i64),
    /// An unsigned integer.
    UInt(u64),
    /// A floating-point number.
    Float(f64),
    /// A boolean.
    Bool(bool),
    /// A character.
    Char(char),
    /// A string.
    Str(&'a str),
    /// An enumerator: comparable with a string (by name) and with a number (by value).
    Enum {
        /// The IDL name of the enumerator.
        name: &'static str,
        /// Its value.
        value: i64,
    },
}

impl FieldValue<'_> {
    fn as_f64(&self) -> Option<f64> {
        match *self {
            FieldValue::Int(i) => Some(i as f64),
            FieldValue::UInt(u) => Some(u as f64),
            FieldValue::Float(f) => Some(f),
            _ => None,
        }
    }

    fn as_i128(&self) -> Option<i128> {
        match *self {
            FieldValue::Int(i) => Some(i128::from(i)),
            FieldValue::UInt(u) => Some(i128::from(u)),
            FieldValue::Enum { value, .. } => Some(i128::from(value)),
            _ => None,
        }
    }

    /// A string view for comparisons with text: strings, characters (as a one-character string) and
    /// enumerator names. `buf` holds the encoded character.
    fn as_text<'s>(&'s self, buf: &'s mut [u8; 4]) -> Option<&'s str> {
        match self {
            FieldValue::Str(s) => Some(s),
            FieldValue::Enum { name, .. } => Some(name),
            FieldValue::Char(c) => Some(c.encode_utf8(buf)),
            _ => None,
        }
    }

    /// SQL comparison; `None` when the two values cannot be compared (the predicate is then false).
    pub fn compare(&self, other: &FieldValue<'_>) -> Option<Ordering> {
        use FieldValue::{Bool, Enum, Float, Int, Str, UInt};
        match (self, other) {
            (Bool(a), Bool(b)) => Some(a.cmp(b)),
            (Enum { value: a, .. }, Enum { value: b, .. }) => Some(a.cmp(b)),
            (Int(_) | UInt(_) | Enum { .. }, Int(_) | UInt(_))
            | (Int(_) | UInt(_), Enum { .. }) => Some(self.as_i128()?.cmp(&other.as_i128()?)),
            (Float(_), _) | (_, Float(_)) => self.as_f64()?.partial_cmp(&other.as_f64()?),
            (Enum { name, .. }, Str(s)) => Some(if *name == *s {
                Ordering::Equal
            } else {
                name.cmp(s)
            }),
            _ => {
                let (mut a, mut b) = ([0u8; 4], [0u8; 4]);
                Some(self.as_text(&mut a)?.cmp(other.as_text(&mut b)?))
            }
        }
    }

    /// The text of a string-like value (for `LIKE`).
    pub(crate) fn with_text<R>(&self, f: impl FnOnce(&str) -> R) -> Option<R> {
        let mut buf = [0u8; 4];
        self.as_text(&mut buf).map(f)
    }
}

/// Gives filters and queries access to a sample's members by path. `#[derive(DdsType)]` implements it for
/// every struct (members by IDL name, base members included), union (the active branch by name) and enum
/// (the enumerator, comparable by name and by value); this module implements it for the member types of
/// [`crate::cdr`]: scalars answer the empty path, sequences and arrays answer an index.
pub trait FilterFields {
    /// The value at `path` below `self` (the empty path is `self` itself), or `None` if there is no such
    /// member, the index is out of range, the branch is not the active one or the optional member is absent.
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>>;
}

macro_rules! scalar {
    ($variant:ident, $as:ty, $($t:ty),*) => {$(
        impl FilterFields for $t {
            #[inline]
            fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
                path.is_empty().then(|| FieldValue::$variant(<$as>::from(*self)))
            }
        }
    )*};
}
scalar!(Int, i64, i8, i16, i32, i64);
scalar!(UInt, u64, u8, u16, u32, u64);
scalar!(Float, f64, f32, f64);
scalar!(Bool, bool, bool);
scalar!(Char, char, char);

impl FilterFields for String {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        path.is_empty().then_some(FieldValue::Str(self))
    }
}

impl FilterFields for str {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        path.is_empty().then_some(FieldValue::Str(self))
    }
}

impl<const N: usize> FilterFields for BoundedString<N> {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        self.0.field_value(path)
    }
}

impl FilterFields for WString {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        self.0.field_value(path)
    }
}

impl FilterFields for WChar {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        let c = char::from_u32(u32::from(self.0)).unwrap_or(char::REPLACEMENT_CHARACTER);
        path.is_empty().then_some(FieldValue::Char(c))
    }
}

impl FilterFields for LongDouble {
    /// A `long double` is carried as raw bytes and has no value a filter can compare.
    fn field_value(&self, _path: &[PathSegment]) -> Option<FieldValue<'_>> {
        None
    }
}

impl<const D: u32, const S: u32> FilterFields for Fixed<D, S> {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        path.is_empty().then(|| FieldValue::Float(self.to_f64()))
    }
}

impl<T: FilterFields + ?Sized> FilterFields for Box<T> {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        (**self).field_value(path)
    }
}

impl<T: FilterFields> FilterFields for Option<T> {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        self.as_ref()?.field_value(path)
    }
}

/// Element `i` of a sequence or an array: `path` starts with `[i]`.
fn element<'a, T: FilterFields>(items: &'a [T], path: &[PathSegment]) -> Option<FieldValue<'a>> {
    match path.split_first()? {
        (PathSegment::Index(i), rest) => items.get(*i)?.field_value(rest),
        _ => None,
    }
}

impl<T: FilterFields> FilterFields for Vec<T> {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        element(self, path)
    }
}

impl<T: FilterFields, const N: usize> FilterFields for [T; N] {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        element(self, path)
    }
}

impl<T: FilterFields, const N: usize> FilterFields for BoundedSeq<T, N> {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        element(&self.0, path)
    }
}

impl<K, V> FilterFields for BTreeMap<K, V> {
    /// The filter language has no syntax for map entries.
    fn field_value(&self, _path: &[PathSegment]) -> Option<FieldValue<'_>> {
        None
    }
}
