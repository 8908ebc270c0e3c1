//! [`DynamicType`]: a type described at run time (XTypes 1.3 §7.5.2), shared cheaply through an `Arc`.

use std::cell::RefCell;
use std::collections::HashSet;
use std::sync::Arc;

use crate::cdr::Extensibility;

use super::error::DynamicError;

/// A type known at run time. Cloning shares the description; equality is structural (clones compare in O(1),
/// and each pair of shared sub-types is compared once per comparison, so separately built types that share
/// sub-types, however deeply, compare in time linear in their pairs of nodes).
#[derive(Clone)]
pub struct DynamicType(pub(super) Arc<TypeKind>);

thread_local! {
    /// Within one outermost comparison (depth > 0): the pairs of nodes (by address) found equal so far.
    static EQUAL_PAIRS: RefCell<(u32, HashSet<(usize, usize)>)> = RefCell::new((0, HashSet::new()));
}

impl PartialEq for DynamicType {
    fn eq(&self, other: &Self) -> bool {
        if Arc::ptr_eq(&self.0, &other.0) {
            return true;
        }
        // Both trees are borrowed for the whole outermost comparison, so addresses stay unique until the
        // memo is cleared at its end.
        let pair = (
            Arc::as_ptr(&self.0) as usize,
            Arc::as_ptr(&other.0) as usize,
        );
        let known = EQUAL_PAIRS.with(|m| {
            let mut m = m.borrow_mut();
            m.0 += 1;
            m.1.contains(&pair)
        });
        let same = known || self.0 == other.0;
        EQUAL_PAIRS.with(|m| {
            let mut m = m.borrow_mut();
            if same {
                m.1.insert(pair);
            }
            m.0 -= 1;
            if m.0 == 0 {
                m.1 = HashSet::new();
            }
        });
        same
    }
}

impl std::fmt::Debug for DynamicType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &*self.0 {
            TypeKind::Struct(s) => write!(f, "struct {}", s.name),
            TypeKind::Union(u) => write!(f, "union {}", u.name),
            TypeKind::Enum(e) => write!(f, "enum {}", e.name),
            TypeKind::Bitmask(b) => write!(f, "bitmask {}", b.name),
            TypeKind::Alias { name, .. } => write!(f, "typedef {name}"),
            other => other.fmt(f),
        }
    }
}

/// The primitive types (`TK_BOOLEAN` ... `TK_CHAR16`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Primitive {
    /// `boolean`.
    Bool,
    /// `octet`.
    Byte,
    /// `int8`.
    Int8,
    /// `uint8`.
    UInt8,
    /// `short`.
    Int16,
    /// `unsigned short`.
    UInt16,
    /// `long`.
    Int32,
    /// `unsigned long`.
    UInt32,
    /// `long long`.
    Int64,
    /// `unsigned long long`.
    UInt64,
    /// `float`.
    Float32,
    /// `double`.
    Float64,
    /// `long double` (16 bytes, carried as they are).
    Float128,
    /// `char`.
    Char8,
    /// `wchar`.
    Char16,
}

impl Primitive {
    /// Encoded size in bytes.
    pub const fn size(self) -> usize {
        match self {
            Primitive::Bool
            | Primitive::Byte
            | Primitive::Int8
            | Primitive::UInt8
            | Primitive::Char8 => 1,
            Primitive::Int16 | Primitive::UInt16 | Primitive::Char16 => 2,
            Primitive::Int32 | Primitive::UInt32 | Primitive::Float32 => 4,
            Primitive::Int64 | Primitive::UInt64 | Primitive::Float64 => 8,
            Primitive::Float128 => 16,
        }
    }

    /// The IDL spelling.
    pub const fn idl_name(self) -> &'static str {
        match self {
            Primitive::Bool => "boolean",
            Primitive::Byte => "octet",
            Primitive::Int8 => "int8",
            Primitive::UInt8 => "uint8",
            Primitive::Int16 => "short",
            Primitive::UInt16 => "unsigned short",
            Primitive::Int32 => "long",
            Primitive::UInt32 => "unsigned long",
            Primitive::Int64 => "long long",
            Primitive::UInt64 => "unsigned long long",
            Primitive::Float32 => "float",
            Primitive::Float64 => "double",
            Primitive::Float128 => "long double",
            Primitive::Char8 => "char",
            Primitive::Char16 => "wchar",
        }
    }
}

/// What a [`DynamicType`] is.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum TypeKind {
    /// A primitive.
    Primitive(Primitive),
    /// `string<bound>` or `wstring<bound>`.
    String {
        /// `wstring`.
        wide: bool,
        /// Maximum length in characters (code units for `wstring`), if bounded.
        bound: Option<u32>,
    },
    /// A typedef: values are those of `target`.
    Alias {
        /// Scoped name.
        name: String,
        /// The aliased type.
        target: DynamicType,
    },
    /// An enum.
    Enum(EnumType),
    /// A bitmask.
    Bitmask(BitmaskType),
    /// A struct.
    Struct(StructType),
    /// A union.
    Union(UnionType),
    /// `sequence<T, bound>`.
    Sequence {
        /// Element type.
        element: DynamicType,
        /// Maximum length, if bounded.
        bound: Option<u32>,
    },
    /// An array; multi-dimensional arrays list every dimension, outermost first.
    Array {
        /// Element type (never itself an array: nested arrays are flattened into `dims`).
        element: DynamicType,
        /// Dimensions, outermost first.
        dims: Vec<u32>,
    },
    /// `map<K, V, bound>`.
    Map {
        /// Key type.
        key: DynamicType,
        /// Value type.
        value: DynamicType,
        /// Maximum entries, if bounded.
        bound: Option<u32>,
    },
}

/// An enumerator.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Enumerator {
    /// Its name.
    pub name: String,
    /// Its value.
    pub value: i32,
}

/// An enum type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EnumType {
    /// Scoped name.
    pub name: String,
    /// `@bit_bound` (1..=32): 1, 2 or 4 bytes on the wire.
    pub bit_bound: u16,
    /// Enumerators in declaration order.
    pub literals: Vec<Enumerator>,
    /// Index of the default literal.
    pub default: usize,
    /// Extensibility (in the type object only; `@final` unless annotated).
    pub extensibility: Extensibility,
}

impl EnumType {
    /// Bytes on the wire (both XCDR versions).
    pub fn size(&self) -> usize {
        match self.bit_bound {
            0..=8 => 1,
            9..=16 => 2,
            _ => 4,
        }
    }

    /// The enumerator named `name`.
    pub fn value_of(&self, name: &str) -> Option<i32> {
        self.literals
            .iter()
            .find(|l| l.name == name)
            .map(|l| l.value)
    }

    /// The name of the enumerator with `value`.
    pub fn name_of(&self, value: i32) -> Option<&str> {
        self.literals
            .iter()
            .find(|l| l.value == value)
            .map(|l| l.name.as_str())
    }
}

/// A bitmask flag.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BitFlag {
    /// Its name.
    pub name: String,
    /// Its bit position.
    pub position: u16,
}

/// A bitmask type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BitmaskType {
    /// Scoped name.
    pub name: String,
    /// `@bit_bound` (1..=64): 1, 2, 4 or 8 bytes on the wire.
    pub bit_bound: u16,
    /// The flags.
    pub flags: Vec<BitFlag>,
    /// Extensibility (in the type object only; `@final` unless annotated).
    pub extensibility: Extensibility,
}

impl BitmaskType {
    /// Bytes on the wire.
    pub fn size(&self) -> usize {
        match self.bit_bound {
            0..=8 => 1,
            9..=16 => 2,
            17..=32 => 4,
            _ => 8,
        }
    }
}

/// A struct member.
#[derive(Debug, Clone, PartialEq)]
pub struct Member {
    /// Its name.
    pub name: String,
    /// Its member id.
    pub id: u32,
    /// Its type.
    pub ty: DynamicType,
    /// `@key`.
    pub key: bool,
    /// `@optional`.
    pub optional: bool,
    /// `@external`.
    pub external: bool,
    /// `@must_understand`.
    pub must_understand: bool,
    /// `@hashid` as written (the string, empty for the member name): the type object keeps it.
    pub hash_id: Option<String>,
    /// `@default`: the member's try-construct behaviour is USE_DEFAULT (TRY_CONSTRUCT2) instead of DISCARD.
    pub use_default: bool,
}

/// A struct type. Members of the base come first in [`StructType::members`].
#[derive(Debug, Clone, PartialEq)]
pub struct StructType {
    /// Scoped name.
    pub name: String,
    /// Extensibility.
    pub extensibility: Extensibility,
    /// The base struct, if any.
    pub base: Option<DynamicType>,
    /// Every member, the base's first (a sample's values are in this order).
    pub members: Vec<Member>,
    /// `@autoid(HASH)`.
    pub autoid_hash: bool,
    /// `@nested`: not meant as a topic type.
    pub nested: bool,
    /// How many of `members` the base (and its bases) contributes, per inheritance level, outermost first.
    pub(super) levels: Vec<usize>,
}

impl StructType {
    /// Index of the member named `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.members.iter().position(|m| m.name == name)
    }

    /// Index of the member with id `id`.
    pub fn index_of_id(&self, id: u32) -> Option<usize> {
        self.members.iter().position(|m| m.id == id)
    }

    /// The struct's own members (its base's left out).
    pub fn own_members(&self) -> &[Member] {
        let start = self.levels.iter().rev().nth(1).copied().unwrap_or(0);
        &self.members[start..]
    }

    /// Whether the struct (or its base) has key members.
    pub fn has_keys(&self) -> bool {
        self.members.iter().any(|m| m.key)
    }

    /// The members' indices level by level (base first), each level sorted by member id: the key-hash order.
    pub(super) fn by_id(&self) -> Vec<usize> {
        let mut out = Vec::with_capacity(self.members.len());
        let mut start = 0;
        for &end in &self.levels {
            let mut level: Vec<usize> = (start..end).collect();
            level.sort_by_key(|&i| self.members[i].id);
            out.extend(level);
            start = end;
        }
        out
    }
}

/// A union case.
#[derive(Debug, Clone, PartialEq)]
pub struct UnionCase {
    /// Its member name.
    pub name: String,
    /// Its member id.
    pub id: u32,
    /// Its type.
    pub ty: DynamicType,
    /// Its labels (as integers: enumerator values, 0/1 for booleans, character codes).
    pub labels: Vec<i64>,
    /// Carries the `default` label.
    pub is_default: bool,
    /// `@external`.
    pub external: bool,
}

/// A union type.
#[derive(Debug, Clone, PartialEq)]
pub struct UnionType {
    /// Scoped name.
    pub name: String,
    /// Extensibility.
    pub extensibility: Extensibility,
    /// The discriminator type (an integer, `boolean`, `char`, `wchar`, `octet` or an enum, possibly aliased).
    pub discriminator: DynamicType,
    /// `@key` on the discriminator.
    pub disc_key: bool,
    /// The cases.
    pub cases: Vec<UnionCase>,
    /// `@nested`: not meant as a topic type.
    pub nested: bool,
}

impl UnionType {
    /// The id of the first case when none is given, then numbered on (`@id` continues from its value).
    ///
    /// Cyclone DDS 11 (its idlc and Python binding) numbers union members from 0 in the type objects, and its
    /// endpoints match ours only if the ids agree, so final and appendable unions follow it. XTypes 1.3 gives
    /// the discriminator id 0 and the members 1, 2, ... (Cyclone after 11.0.1 does too); a mutable union
    /// puts the discriminator in member 0 on the wire, so its cases must start at 1. Cyclone 11 has no
    /// mutable unions, so for them the spec applies. The derive (dds-macros `model.rs`) applies the same rule.
    pub fn first_member_id(extensibility: Extensibility) -> u32 {
        match extensibility {
            Extensibility::Mutable => 1,
            Extensibility::Final | Extensibility::Appendable => 0,
        }
    }

    /// The case a discriminator value selects: a labelled case, else the default case.
    pub fn case_for(&self, disc: i64) -> Option<usize> {
        self.cases
            .iter()
            .position(|c| c.labels.contains(&disc))
            .or_else(|| self.cases.iter().rposition(|c| c.is_default))
    }

    /// The discriminator written for the default case: the first value no label uses (libddsc's search).
    pub fn default_discriminator(&self) -> Option<i64> {
        let labels: Vec<i64> = self
            .cases
            .iter()
            .flat_map(|c| c.labels.iter().copied())
            .collect();
        match self.discriminator.kind() {
            TypeKind::Enum(e) => e
                .literals
                .iter()
                .map(|l| i64::from(l.value))
                .find(|v| !labels.contains(v)),
            TypeKind::Primitive(Primitive::Bool) => {
                [1, 0].into_iter().find(|v| !labels.contains(v))
            }
            TypeKind::Primitive(p) if is_signed(*p) => (1..=i64::from(u16::MAX))
                .map(|v| -v)
                .find(|v| !labels.contains(v)),
            _ => (0..=i64::from(u16::MAX)).find(|v| !labels.contains(v)),
        }
    }

    /// The name of the case `disc` selects.
    pub fn case_name(&self, disc: i64) -> Option<&str> {
        self.case_for(disc).map(|i| self.cases[i].name.as_str())
    }
}

pub(super) fn is_signed(p: Primitive) -> bool {
    matches!(
        p,
        Primitive::Int8 | Primitive::Int16 | Primitive::Int32 | Primitive::Int64
    )
}

impl DynamicType {
    /// A type of this kind.
    pub fn new(kind: TypeKind) -> Self {
        DynamicType(Arc::new(kind))
    }

    /// A primitive type.
    pub fn primitive(p: Primitive) -> Self {
        DynamicType::new(TypeKind::Primitive(p))
    }

    /// `string` (unbounded with `None`).
    pub fn string(bound: Option<u32>) -> Self {
        DynamicType::new(TypeKind::String { wide: false, bound })
    }

    /// `wstring` (unbounded with `None`).
    pub fn wstring(bound: Option<u32>) -> Self {
        DynamicType::new(TypeKind::String { wide: true, bound })
    }

    /// `sequence<element, bound>`.
    pub fn sequence(element: DynamicType, bound: Option<u32>) -> Self {
        DynamicType::new(TypeKind::Sequence { element, bound })
    }

    /// An array with these dimensions (an array element's own dimensions are appended).
    pub fn array(element: DynamicType, dims: Vec<u32>) -> Result<Self, DynamicError> {
        if dims.is_empty() || dims.contains(&0) {
            return Err(DynamicError::Invalid(
                "an array needs non-zero dimensions".into(),
            ));
        }
        let (element, dims) = match element.kind() {
            TypeKind::Array {
                element: e,
                dims: d,
            } => {
                let mut all = dims;
                all.extend_from_slice(d);
                (e.clone(), all)
            }
            _ => (element, dims),
        };
        Ok(DynamicType::new(TypeKind::Array { element, dims }))
    }

    /// `map<key, value, bound>`.
    pub fn map(key: DynamicType, value: DynamicType, bound: Option<u32>) -> Self {
        DynamicType::new(TypeKind::Map { key, value, bound })
    }

    /// `typedef target name`.
    pub fn alias(name: impl Into<String>, target: DynamicType) -> Self {
        DynamicType::new(TypeKind::Alias {
            name: name.into(),
            target,
        })
    }

    /// What the type is.
    pub fn kind(&self) -> &TypeKind {
        &self.0
    }

    /// The type with aliases followed.
    pub fn resolved(&self) -> &DynamicType {
        let mut t = self;
        while let TypeKind::Alias { target, .. } = &*t.0 {
            t = target;
        }
        t
    }

    /// The scoped name of a named type (struct, union, enum, bitmask, alias), else the IDL spelling.
    pub fn name(&self) -> String {
        match self.kind() {
            TypeKind::Struct(s) => s.name.clone(),
            TypeKind::Union(u) => u.name.clone(),
            TypeKind::Enum(e) => e.name.clone(),
            TypeKind::Bitmask(b) => b.name.clone(),
            TypeKind::Alias { name, .. } => name.clone(),
            TypeKind::Primitive(p) => p.idl_name().to_string(),
            TypeKind::String { wide, bound } => {
                let s = if *wide { "wstring" } else { "string" };
                match bound {
                    Some(b) => format!("{s}<{b}>"),
                    None => s.to_string(),
                }
            }
            TypeKind::Sequence { element, bound } => match bound {
                Some(b) => format!("sequence<{}, {b}>", element.name()),
                None => format!("sequence<{}>", element.name()),
            },
            TypeKind::Array { element, dims } => {
                let d: String = dims.iter().map(|d| format!("[{d}]")).collect();
                format!("{}{d}", element.name())
            }
            TypeKind::Map { key, value, bound } => match bound {
                Some(b) => format!("map<{}, {}, {b}>", key.name(), value.name()),
                None => format!("map<{}, {}>", key.name(), value.name()),
            },
        }
    }

    /// The struct description, if this (alias-resolved) type is a struct.
    pub fn as_struct(&self) -> Option<&StructType> {
        match self.resolved().kind() {
            TypeKind::Struct(s) => Some(s),
            _ => None,
        }
    }

    /// The union description, if this (alias-resolved) type is a union.
    pub fn as_union(&self) -> Option<&UnionType> {
        match self.resolved().kind() {
            TypeKind::Union(u) => Some(u),
            _ => None,
        }
    }

    /// The extensibility of a struct or union (final for everything else), as a topic type's header says.
    pub fn extensibility(&self) -> Extensibility {
        match self.resolved().kind() {
            TypeKind::Struct(s) => s.extensibility,
            TypeKind::Union(u) => u.extensibility,
            _ => Extensibility::Final,
        }
    }

    /// Whether samples have a key: a struct with key members. A union topic type is unkeyed, as for the derive
    /// (its `disc_key` is kept for the type's description only).
    pub fn is_keyed(&self) -> bool {
        self.as_struct().is_some_and(StructType::has_keys)
    }
}

#[cfg(test)]
mod tests {
    use super::super::builder::StructBuilder;
    use super::*;

    /// `L0 { long a; }`, `Ln { Ln-1 a; Ln-1 b; }`: 2^n paths, n + 1 distinct nodes.
    fn lattice(depth: usize) -> DynamicType {
        let mut t = StructBuilder::new("L0")
            .member("a", DynamicType::primitive(Primitive::Int32))
            .build()
            .unwrap();
        for i in 1..=depth {
            t = StructBuilder::new(format!("L{i}"))
                .member("a", t.clone())
                .member("b", t)
                .build()
                .unwrap();
        }
        t
    }

    #[test]
    fn separately_built_deep_lattices_compare_in_linear_time() {
        // Without the memo this is 2^60 comparisons.
        let (a, b) = (lattice(60), lattice(60));
        let start = std::time::Instant::now();
        assert_eq!(a, b);
        assert_ne!(a, lattice(59));
        assert!(start.elapsed() < std::time::Duration::from_secs(1));
    }
}
