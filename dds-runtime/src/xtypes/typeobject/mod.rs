//! The XTypes 1.3 type system (§7.3.4): type identifiers, minimal and complete type objects, `TypeInformation`
//! and `TypeMapping`, with their XCDR2 encoding and a bounded decoder.
//!
//! The data model follows the spec's IDL (annex B) with one simplification: a minimal and a complete type object
//! share one Rust shape, [`TypeBody`]; the wrapper ([`MinimalTypeObject`] or [`CompleteTypeObject`]) decides
//! which details are written. Member names become the 4-byte MD5 name hash in the minimal form.
//!
//! The extensibility of each spec type is the one Cyclone DDS 11 uses (its `ddsi_xt_typeinfo.idl`), which is
//! what its peers hash; docs/xtypes.md lists where that differs from annex B.

mod codec;
mod decode;
mod identifier;
mod info;
mod object;

/// The DHEADER helpers, shared with the TypeLookup codec.
pub(crate) use codec::{appendable as write_appendable, seq as write_seq};
pub use codec::{from_bytes, to_bytes, XtypesCodec};
pub(crate) use decode::appendable as read_appendable;
pub use identifier::{
    EquivalenceHash, EquivalenceKind, PlainCollectionHeader, StronglyConnectedComponentId,
    TypeIdentifier,
};
pub use info::{
    TypeIdentifierPair, TypeIdentifierTypeObjectPair, TypeIdentifierWithDependencies,
    TypeIdentifierWithSize, TypeInformation, TypeMapping,
};
pub use object::{
    AnnotationParameterValue, AppliedAnnotation, AppliedAnnotationParameter,
    AppliedBuiltinMemberAnnotations, AppliedVerbatimAnnotation, Bitfield, Bitflag,
    CollectionElement, CompleteTypeObject, EnumeratedLiteral, MemberDetail, MemberName,
    MinimalTypeObject, StructMember, TypeBody, TypeDetail, TypeObject, UnionMember,
};

/// Type kinds (`TK_*`, XTypes 1.3 §7.3.4.1): the discriminators of fully descriptive identifiers and of type
/// objects.
pub mod kind {
    #![allow(missing_docs)]
    pub const TK_NONE: u8 = 0x00;
    pub const TK_BOOLEAN: u8 = 0x01;
    pub const TK_BYTE: u8 = 0x02;
    pub const TK_INT16: u8 = 0x03;
    pub const TK_INT32: u8 = 0x04;
    pub const TK_INT64: u8 = 0x05;
    pub const TK_UINT16: u8 = 0x06;
    pub const TK_UINT32: u8 = 0x07;
    pub const TK_UINT64: u8 = 0x08;
    pub const TK_FLOAT32: u8 = 0x09;
    pub const TK_FLOAT64: u8 = 0x0A;
    pub const TK_FLOAT128: u8 = 0x0B;
    pub const TK_INT8: u8 = 0x0C;
    pub const TK_UINT8: u8 = 0x0D;
    pub const TK_CHAR8: u8 = 0x10;
    pub const TK_CHAR16: u8 = 0x11;
    pub const TK_STRING8: u8 = 0x20;
    pub const TK_STRING16: u8 = 0x21;
    pub const TK_ALIAS: u8 = 0x30;
    pub const TK_ENUM: u8 = 0x40;
    pub const TK_BITMASK: u8 = 0x41;
    pub const TK_ANNOTATION: u8 = 0x50;
    pub const TK_STRUCTURE: u8 = 0x51;
    pub const TK_UNION: u8 = 0x52;
    pub const TK_BITSET: u8 = 0x53;
    pub const TK_SEQUENCE: u8 = 0x60;
    pub const TK_ARRAY: u8 = 0x61;
    pub const TK_MAP: u8 = 0x62;
    pub const TI_STRING8_SMALL: u8 = 0x70;
    pub const TI_STRING8_LARGE: u8 = 0x71;
    pub const TI_STRING16_SMALL: u8 = 0x72;
    pub const TI_STRING16_LARGE: u8 = 0x73;
    pub const TI_PLAIN_SEQUENCE_SMALL: u8 = 0x80;
    pub const TI_PLAIN_SEQUENCE_LARGE: u8 = 0x81;
    pub const TI_PLAIN_ARRAY_SMALL: u8 = 0x90;
    pub const TI_PLAIN_ARRAY_LARGE: u8 = 0x91;
    pub const TI_PLAIN_MAP_SMALL: u8 = 0xA0;
    pub const TI_PLAIN_MAP_LARGE: u8 = 0xA1;
    pub const TI_STRONGLY_CONNECTED_COMPONENT: u8 = 0xB0;
    pub const EK_MINIMAL: u8 = 0xF1;
    pub const EK_COMPLETE: u8 = 0xF2;
    pub const EK_BOTH: u8 = 0xF3;

    /// Whether `k` is a primitive type kind (an identifier with no body).
    pub const fn is_primitive(k: u8) -> bool {
        matches!(k, 0x01..=0x0D | 0x10 | 0x11)
    }
}

bitflags::bitflags! {
    /// `MemberFlag` (16 bits): flags of struct and union members, collection elements, enumerators, bitflags.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
    pub struct MemberFlag: u16 {
        /// `TRY_CONSTRUCT1` (with `TRY_CONSTRUCT2`: 01 discard, 10 use default, 11 trim).
        const TRY_CONSTRUCT1 = 1 << 0;
        /// `TRY_CONSTRUCT2`.
        const TRY_CONSTRUCT2 = 1 << 1;
        /// `@external`.
        const IS_EXTERNAL = 1 << 2;
        /// `@optional`.
        const IS_OPTIONAL = 1 << 3;
        /// `@must_understand`.
        const IS_MUST_UNDERSTAND = 1 << 4;
        /// `@key`.
        const IS_KEY = 1 << 5;
        /// The default union case or enumerator (`@default_literal`).
        const IS_DEFAULT = 1 << 6;
    }
}

bitflags::bitflags! {
    /// `TypeFlag` (16 bits): flags of struct, union, enum, bitmask and collection types.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
    pub struct TypeFlag: u16 {
        /// `@final`.
        const IS_FINAL = 1 << 0;
        /// `@appendable`.
        const IS_APPENDABLE = 1 << 1;
        /// `@mutable`.
        const IS_MUTABLE = 1 << 2;
        /// `@nested`.
        const IS_NESTED = 1 << 3;
        /// `@autoid(HASH)`.
        const IS_AUTOID_HASH = 1 << 4;
    }
}

/// `@hashid` / name hash: the first 4 bytes of the MD5 of a member name.
pub fn name_hash(name: &str) -> [u8; 4] {
    use md5::{Digest, Md5};
    let d = Md5::digest(name.as_bytes());
    [d[0], d[1], d[2], d[3]]
}

/// `EquivalenceHash` of a serialized type object: the first 14 bytes of its MD5.
pub fn equivalence_hash(serialized: &[u8]) -> EquivalenceHash {
    use md5::{Digest, Md5};
    let d = Md5::digest(serialized);
    let mut h = [0u8; 14];
    h.copy_from_slice(&d[..14]);
    h
}

/// Largest member or type name accepted on decode (`MEMBER_NAME_MAX_LENGTH`, `TYPE_NAME_MAX_LENGTH`).
pub const NAME_MAX_LENGTH: usize = 256;
