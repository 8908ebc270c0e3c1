//! Type objects (XTypes 1.3 §7.3.4.5-6): one Rust shape, [`TypeBody`], for the minimal and the complete form.

use super::identifier::TypeIdentifier;
use super::{MemberFlag, TypeFlag};

/// `TypeObject`: a minimal or a complete type object.
#[derive(Debug, Clone, PartialEq)]
pub enum TypeObject {
    /// `EK_MINIMAL`.
    Minimal(MinimalTypeObject),
    /// `EK_COMPLETE`.
    Complete(CompleteTypeObject),
}

/// `MinimalTypeObject`: written without names (member name hashes instead) and without annotations.
#[derive(Debug, Clone, PartialEq)]
pub struct MinimalTypeObject(pub TypeBody);

/// `CompleteTypeObject`: every name and the annotations kept.
#[derive(Debug, Clone, PartialEq)]
pub struct CompleteTypeObject(pub TypeBody);

/// The content of a type object, by type kind. `detail` fields are written only in the complete form.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum TypeBody {
    /// `TK_ALIAS` (typedef).
    Alias {
        /// Alias flags (unused, 0).
        flags: TypeFlag,
        /// Type detail (complete).
        detail: TypeDetail,
        /// Related-type flags (unused, 0).
        related_flags: MemberFlag,
        /// The aliased type.
        related_type: TypeIdentifier,
        /// `@unit`, `@min`... on the alias (complete).
        ann_builtin: Option<AppliedBuiltinMemberAnnotations>,
        /// Custom annotations (complete).
        ann_custom: Option<Vec<AppliedAnnotation>>,
    },
    /// `TK_STRUCTURE`.
    Struct {
        /// Extensibility, nested, autoid.
        flags: TypeFlag,
        /// The base type, or [`TypeIdentifier::None`].
        base: TypeIdentifier,
        /// Type detail (complete).
        detail: TypeDetail,
        /// Members in declaration order (without the base's).
        members: Vec<StructMember>,
    },
    /// `TK_UNION`.
    Union {
        /// Extensibility, nested, autoid.
        flags: TypeFlag,
        /// Type detail (complete).
        detail: TypeDetail,
        /// Discriminator flags (key, must-understand, try-construct).
        disc_flags: MemberFlag,
        /// Discriminator type.
        disc_type: TypeIdentifier,
        /// Verbatim annotation of the discriminator (complete).
        disc_ann_builtin: Option<AppliedVerbatimAnnotation>,
        /// Custom annotations of the discriminator (complete).
        disc_ann_custom: Option<Vec<AppliedAnnotation>>,
        /// The cases.
        members: Vec<UnionMember>,
    },
    /// `TK_ENUM`.
    Enum {
        /// Extensibility flags.
        flags: TypeFlag,
        /// `@bit_bound` (1..=32).
        bit_bound: u16,
        /// Type detail (complete).
        detail: TypeDetail,
        /// Enumerators, sorted by value.
        literals: Vec<EnumeratedLiteral>,
    },
    /// `TK_BITMASK`.
    Bitmask {
        /// Extensibility flags.
        flags: TypeFlag,
        /// `@bit_bound` (1..=64).
        bit_bound: u16,
        /// Type detail (complete).
        detail: TypeDetail,
        /// Flags, sorted by position.
        bitflags: Vec<Bitflag>,
    },
    /// `TK_BITSET`: bit fields packed in an integer (no peer makes these objects from IDL: Cyclone 11's idlc
    /// rejects `bitset`; the layout is that of Cyclone's type-object IDL, whose `MinimalBitfield` is
    /// appendable where XTypes 1.3 makes it final).
    Bitset {
        /// Bitset flags (unused, 0).
        flags: TypeFlag,
        /// Type detail (complete).
        detail: TypeDetail,
        /// The bit fields, in declaration order.
        fields: Vec<Bitfield>,
    },
    /// `TK_SEQUENCE` (a sequence whose identifier is not plain).
    Sequence {
        /// Collection flags (unused, 0).
        flags: TypeFlag,
        /// Bound (0: unbounded).
        bound: u32,
        /// Optional type detail (complete).
        detail: Option<TypeDetail>,
        /// Element.
        element: CollectionElement,
    },
    /// `TK_ARRAY`.
    Array {
        /// Collection flags (unused, 0).
        flags: TypeFlag,
        /// Dimensions.
        bounds: Vec<u32>,
        /// Type detail (complete).
        detail: TypeDetail,
        /// Element.
        element: CollectionElement,
    },
    /// `TK_MAP`.
    Map {
        /// Collection flags (unused, 0).
        flags: TypeFlag,
        /// Bound (0: unbounded).
        bound: u32,
        /// Optional type detail (complete).
        detail: Option<TypeDetail>,
        /// Key.
        key: CollectionElement,
        /// Value.
        element: CollectionElement,
    },
}

impl TypeBody {
    /// The `TK_*` kind of the body (the type object union's discriminator).
    pub fn kind(&self) -> u8 {
        use super::kind::*;
        match self {
            TypeBody::Alias { .. } => TK_ALIAS,
            TypeBody::Struct { .. } => TK_STRUCTURE,
            TypeBody::Union { .. } => TK_UNION,
            TypeBody::Enum { .. } => TK_ENUM,
            TypeBody::Bitmask { .. } => TK_BITMASK,
            TypeBody::Bitset { .. } => TK_BITSET,
            TypeBody::Sequence { .. } => TK_SEQUENCE,
            TypeBody::Array { .. } => TK_ARRAY,
            TypeBody::Map { .. } => TK_MAP,
        }
    }

    /// The scoped type name of the complete form (empty in a decoded minimal object).
    pub fn type_name(&self) -> &str {
        match self {
            TypeBody::Alias { detail, .. }
            | TypeBody::Struct { detail, .. }
            | TypeBody::Union { detail, .. }
            | TypeBody::Enum { detail, .. }
            | TypeBody::Bitmask { detail, .. }
            | TypeBody::Bitset { detail, .. }
            | TypeBody::Array { detail, .. } => &detail.type_name,
            TypeBody::Sequence { detail, .. } | TypeBody::Map { detail, .. } => {
                detail.as_ref().map_or("", |d| d.type_name.as_str())
            }
        }
    }
}

/// `CompleteTypeDetail` (the minimal form has none).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct TypeDetail {
    /// `@verbatim`.
    pub ann_builtin: Option<AppliedVerbatimAnnotation>,
    /// Custom annotations.
    pub ann_custom: Option<Vec<AppliedAnnotation>>,
    /// Scoped name, `"Module::Type"`.
    pub type_name: String,
}

/// A member's name: the name itself, or only its hash (a decoded minimal object).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MemberName {
    /// The name.
    Name(String),
    /// The first 4 bytes of the MD5 of the name.
    Hash([u8; 4]),
}

impl MemberName {
    /// The name hash, computed from the name if needed.
    pub fn hash(&self) -> [u8; 4] {
        match self {
            MemberName::Name(n) => super::name_hash(n),
            MemberName::Hash(h) => *h,
        }
    }
}

/// `CompleteMemberDetail` / `MinimalMemberDetail`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MemberDetail {
    /// Name (complete) or name hash (minimal).
    pub name: MemberName,
    /// `@unit`, `@min`, `@max`, `@hashid` (complete).
    pub ann_builtin: Option<AppliedBuiltinMemberAnnotations>,
    /// Custom annotations (complete).
    pub ann_custom: Option<Vec<AppliedAnnotation>>,
}

impl MemberDetail {
    /// A detail with a name and no annotations.
    pub fn named(name: impl Into<String>) -> Self {
        MemberDetail {
            name: MemberName::Name(name.into()),
            ann_builtin: None,
            ann_custom: None,
        }
    }
}

/// A struct member (`CommonStructMember` + detail).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StructMember {
    /// Member id.
    pub id: u32,
    /// Key, optional, external, must-understand, try-construct.
    pub flags: MemberFlag,
    /// The member's type.
    pub type_id: TypeIdentifier,
    /// Name and annotations.
    pub detail: MemberDetail,
}

/// A union case (`CommonUnionMember` + detail).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnionMember {
    /// Member id.
    pub id: u32,
    /// Flags (`IS_DEFAULT` for the default case).
    pub flags: MemberFlag,
    /// The case's type.
    pub type_id: TypeIdentifier,
    /// Case labels.
    pub labels: Vec<i32>,
    /// Name and annotations.
    pub detail: MemberDetail,
}

/// An enumerator (`CommonEnumeratedLiteral` + detail).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EnumeratedLiteral {
    /// Value.
    pub value: i32,
    /// `IS_DEFAULT` for the default literal.
    pub flags: MemberFlag,
    /// Name.
    pub detail: MemberDetail,
}

/// A bitmask flag (`CommonBitflag` + detail).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Bitflag {
    /// Bit position.
    pub position: u16,
    /// Flags (unused, 0).
    pub flags: MemberFlag,
    /// Name.
    pub detail: MemberDetail,
}

/// A bit field of a bitset (`CommonBitfield` + detail).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Bitfield {
    /// Position of its lowest bit.
    pub position: u16,
    /// Flags (unused, 0).
    pub flags: MemberFlag,
    /// Number of bits (1..=64).
    pub bitcount: u8,
    /// `TK_*` of the integer (or boolean) type the field's value is read as.
    pub holder_type: u8,
    /// Name.
    pub detail: MemberDetail,
}

/// A collection element (`CommonCollectionElement` + `CompleteElementDetail`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CollectionElement {
    /// Element flags.
    pub flags: MemberFlag,
    /// Element type.
    pub type_id: TypeIdentifier,
    /// Builtin annotations (complete).
    pub ann_builtin: Option<AppliedBuiltinMemberAnnotations>,
    /// Custom annotations (complete).
    pub ann_custom: Option<Vec<AppliedAnnotation>>,
}

/// `AppliedVerbatimAnnotation`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AppliedVerbatimAnnotation {
    /// Placement (at most 32 characters).
    pub placement: String,
    /// Language (at most 32 characters).
    pub language: String,
    /// Text.
    pub text: String,
}

/// `AppliedBuiltinMemberAnnotations`.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct AppliedBuiltinMemberAnnotations {
    /// `@unit`.
    pub unit: Option<String>,
    /// `@min` / `@range` low.
    pub min: Option<AnnotationParameterValue>,
    /// `@max` / `@range` high.
    pub max: Option<AnnotationParameterValue>,
    /// `@hashid` (the string, possibly empty).
    pub hash_id: Option<String>,
}

/// `AppliedAnnotation`: a custom annotation applied to a type or member.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AppliedAnnotation {
    /// The annotation type.
    pub annotation_typeid: TypeIdentifier,
    /// Its parameters.
    pub param_seq: Option<Vec<AppliedAnnotationParameter>>,
}

/// `AppliedAnnotationParameter`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AppliedAnnotationParameter {
    /// Name hash of the parameter.
    pub paramname_hash: [u8; 4],
    /// Value.
    pub value: AnnotationParameterValue,
}

/// `AnnotationParameterValue` (the kinds Cyclone 11 writes). Floats are kept as their bits.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum AnnotationParameterValue {
    /// `TK_BOOLEAN`.
    Boolean(bool),
    /// `TK_BYTE`.
    Byte(u8),
    /// `TK_INT8`.
    Int8(i8),
    /// `TK_UINT8`.
    Uint8(u8),
    /// `TK_INT16`.
    Int16(i16),
    /// `TK_UINT16`.
    Uint16(u16),
    /// `TK_INT32`.
    Int32(i32),
    /// `TK_UINT32`.
    Uint32(u32),
    /// `TK_INT64`.
    Int64(i64),
    /// `TK_UINT64`.
    Uint64(u64),
    /// `TK_FLOAT32` (bits).
    Float32(u32),
    /// `TK_FLOAT64` (bits).
    Float64(u64),
    /// `TK_CHAR8`.
    Char(u8),
    /// `TK_ENUM`: the enumerator's value.
    Enumerated(i32),
    /// `TK_STRING8` (at most 128 characters).
    String8(String),
}
