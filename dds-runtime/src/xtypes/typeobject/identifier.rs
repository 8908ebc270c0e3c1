//! `TypeIdentifier` (XTypes 1.3 §7.3.4.2): fully descriptive identifiers of primitives, strings and plain
//! collections, and hash identifiers of everything else.

use super::kind::*;
use super::MemberFlag;

/// The first 14 bytes of the MD5 of a serialized type object.
pub type EquivalenceHash = [u8; 14];

/// Which type objects an identifier or a hash refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EquivalenceKind {
    /// `EK_MINIMAL`: assignability-relevant information only.
    Minimal,
    /// `EK_COMPLETE`: everything, names and annotations included.
    Complete,
    /// `EK_BOTH`: a plain collection whose element identifier is fully descriptive (the same in both).
    Both,
}

impl EquivalenceKind {
    /// The octet on the wire.
    pub const fn octet(self) -> u8 {
        match self {
            EquivalenceKind::Minimal => EK_MINIMAL,
            EquivalenceKind::Complete => EK_COMPLETE,
            EquivalenceKind::Both => EK_BOTH,
        }
    }

    /// The kind of an octet, if it is one.
    pub const fn from_octet(b: u8) -> Option<Self> {
        match b {
            EK_MINIMAL => Some(EquivalenceKind::Minimal),
            EK_COMPLETE => Some(EquivalenceKind::Complete),
            EK_BOTH => Some(EquivalenceKind::Both),
            _ => None,
        }
    }
}

/// `PlainCollectionHeader`: the equivalence kind of a plain collection and its element flags.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PlainCollectionHeader {
    /// `EK_BOTH` when the element is fully descriptive, else the kind of the enclosing identifier.
    pub equiv_kind: EquivalenceKind,
    /// Element flags (try-construct, external).
    pub element_flags: MemberFlag,
}

/// `StronglyConnectedComponentId`: one type of a group of mutually recursive types.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct StronglyConnectedComponentId {
    /// Minimal or complete: which objects the hash covers.
    pub kind: EquivalenceKind,
    /// Hash of the serialized sequence of the component's type objects.
    pub hash: EquivalenceHash,
    /// Number of types in the component.
    pub scc_length: i32,
    /// 1-based position of this type in the component (0: the component as a whole).
    pub scc_index: i32,
}

/// `TypeIdentifier`. Strings, sequences, arrays and maps choose their small or large wire form from their bounds
/// (bounds below 256 are small), as the spec and Cyclone do.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum TypeIdentifier {
    /// `TK_NONE`: no type (a struct without a base).
    None,
    /// A primitive: one of the `TK_*` primitive kinds (see [`kind::is_primitive`](super::kind::is_primitive)).
    Primitive(u8),
    /// `string<bound>` (0: unbounded).
    String8 {
        /// Bound, 0 for none.
        bound: u32,
    },
    /// `wstring<bound>` (0: unbounded).
    String16 {
        /// Bound, 0 for none.
        bound: u32,
    },
    /// A plain `sequence<T, bound>` (0: unbounded).
    PlainSequence {
        /// Header.
        header: PlainCollectionHeader,
        /// Bound, 0 for none.
        bound: u32,
        /// Element type.
        element: Box<TypeIdentifier>,
    },
    /// A plain array, all dimensions at once.
    PlainArray {
        /// Header.
        header: PlainCollectionHeader,
        /// Dimensions, outermost first.
        bounds: Vec<u32>,
        /// Element type.
        element: Box<TypeIdentifier>,
    },
    /// A plain `map<K, V, bound>` (0: unbounded).
    PlainMap {
        /// Header.
        header: PlainCollectionHeader,
        /// Bound, 0 for none.
        bound: u32,
        /// Value type.
        element: Box<TypeIdentifier>,
        /// Key flags.
        key_flags: MemberFlag,
        /// Key type.
        key: Box<TypeIdentifier>,
    },
    /// A type of a strongly connected component (recursive types).
    StronglyConnected(StronglyConnectedComponentId),
    /// `EK_MINIMAL` hash of a minimal type object.
    Minimal(EquivalenceHash),
    /// `EK_COMPLETE` hash of a complete type object.
    Complete(EquivalenceHash),
}

impl TypeIdentifier {
    /// Whether the identifier describes the type entirely (no hash inside): the same in minimal and complete.
    pub fn is_fully_descriptive(&self) -> bool {
        match self {
            TypeIdentifier::None
            | TypeIdentifier::Primitive(_)
            | TypeIdentifier::String8 { .. }
            | TypeIdentifier::String16 { .. } => true,
            TypeIdentifier::PlainSequence { element, .. }
            | TypeIdentifier::PlainArray { element, .. } => element.is_fully_descriptive(),
            TypeIdentifier::PlainMap { element, key, .. } => {
                element.is_fully_descriptive() && key.is_fully_descriptive()
            }
            TypeIdentifier::StronglyConnected(_)
            | TypeIdentifier::Minimal(_)
            | TypeIdentifier::Complete(_) => false,
        }
    }

    /// The hash, for a hashed identifier.
    pub fn hash(&self) -> Option<&EquivalenceHash> {
        match self {
            TypeIdentifier::Minimal(h) | TypeIdentifier::Complete(h) => Some(h),
            _ => None,
        }
    }

    /// The discriminator octet on the wire.
    pub fn discriminator(&self) -> u8 {
        match self {
            TypeIdentifier::None => TK_NONE,
            TypeIdentifier::Primitive(k) => *k,
            TypeIdentifier::String8 { bound } if *bound < 256 => TI_STRING8_SMALL,
            TypeIdentifier::String8 { .. } => TI_STRING8_LARGE,
            TypeIdentifier::String16 { bound } if *bound < 256 => TI_STRING16_SMALL,
            TypeIdentifier::String16 { .. } => TI_STRING16_LARGE,
            TypeIdentifier::PlainSequence { bound, .. } if *bound < 256 => TI_PLAIN_SEQUENCE_SMALL,
            TypeIdentifier::PlainSequence { .. } => TI_PLAIN_SEQUENCE_LARGE,
            TypeIdentifier::PlainArray { bounds, .. } if bounds.iter().all(|b| *b < 256) => {
                TI_PLAIN_ARRAY_SMALL
            }
            TypeIdentifier::PlainArray { .. } => TI_PLAIN_ARRAY_LARGE,
            TypeIdentifier::PlainMap { bound, .. } if *bound < 256 => TI_PLAIN_MAP_SMALL,
            TypeIdentifier::PlainMap { .. } => TI_PLAIN_MAP_LARGE,
            TypeIdentifier::StronglyConnected(_) => TI_STRONGLY_CONNECTED_COMPONENT,
            TypeIdentifier::Minimal(_) => EK_MINIMAL,
            TypeIdentifier::Complete(_) => EK_COMPLETE,
        }
    }
}
