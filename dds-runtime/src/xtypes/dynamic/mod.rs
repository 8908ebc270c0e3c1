//! Dynamic types and data (XTypes 1.3 §7.5), in idiomatic Rust: a [`DynamicType`] describes a type at run time
//! (built with [`StructBuilder`] and friends, from discovered type objects with
//! [`DynamicType::from_type_identifier`], or from IDL text with the `idl` feature), and a [`DynamicData`] is a
//! sample of it whose members are read and written by name or id.
//!
//! `DynamicData` encodes and decodes XCDR1 and XCDR2 with the same bytes as `#[derive(DdsType)]` code for the
//! same type (tested on the Cyclone DDS golden corpus), and computes the same key hash and instance key.
//! Decoding is bounded: hostile bytes are an error, never a panic or an unbounded allocation.

mod builder;
mod decode;
mod encode;
mod error;
mod filter;
mod from_object;
#[cfg(feature = "idl")]
mod idl;
mod idl_text;
#[cfg(feature = "json")]
mod json;
mod layout;
mod payload;
mod to_object;
mod types;
mod value;

pub use builder::{
    hash_member_id, BitmaskBuilder, EnumBuilder, MemberBuilder, StructBuilder, UnionBuilder,
};
pub use error::DynamicError;
pub use from_object::TypeObjectLookup;
#[cfg(feature = "idl")]
pub use idl::{types_from_idl, types_from_idl_file, IdlError, IdlOptions};
#[cfg(feature = "json")]
pub use json::{from_json, to_json};
pub use layout::default_version;
pub use types::{
    BitFlag, BitmaskType, DynamicType, EnumType, Enumerator, ForwardType, Member, Primitive,
    StructType, TypeKind, UnionCase, UnionType, MAX_RECURSIVE_TYPES,
};
pub use value::{DynamicData, Value};
