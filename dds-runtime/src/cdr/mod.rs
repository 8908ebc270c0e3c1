//! XCDR1/XCDR2 serialization (XTypes 1.3 §7.4).
//!
//! The entry points are [`serialize`], [`deserialize`] (and [`deserialize_into`], which reuses a sample),
//! [`serialize_key`], [`deserialize_key`], [`key_hash`]
//! and [`instance_key`], over types implementing [`DdsType`] (usually through `#[derive(DdsType)]`).
//! Generated code drives [`CdrWriter`] and [`CdrReader`] through the helpers in [`members`].

mod collections;
mod error;
mod fixed;
mod header;
mod key;
pub mod members;
mod payload;
#[cfg(any(test, feature = "shm"))]
mod placement;
mod primitives;
mod reader;
mod short;
mod traits;
mod wrappers;
mod writer;

pub(crate) use collections::{decode_str, encode_str};
pub use error::{DecodeError, DecodeErrorKind, EncodeError};
pub use fixed::{Fixed, FixedError};
pub use header::{ByteOrder, EncapsulationHeader, Extensibility, Representation, XcdrVersion};
pub(crate) use key::hash_key_stream;
pub use key::{deserialize_key, instance_key, key_hash, serialize_key};
pub use members::{DefaultSearch, Discriminator, StructMembers};
pub use payload::{deserialize, deserialize_into, serialize};
pub(crate) use payload::{finish_payload, payload_reader};
#[cfg(feature = "shm")]
pub(crate) use placement::serialize_placed;
pub use reader::{CdrReader, Limit};
pub use traits::{CdrType, DdsType, Layout, MemberDescriptor, TypeDescriptor};
pub use wrappers::{BoundedSeq, BoundedString, LongDouble, WChar, WString};
pub use writer::{CdrWriter, EncodeMode, LengthSlot, ParamSlot};

/// Deepest nesting accepted on decode and produced on encode: structs and unions count one level each, and in
/// XCDR2 so do DHEADER-delimited collections. 64 keeps a debug build of a large recursive type within a 2 MiB
/// thread stack.
pub const MAX_DEPTH: u32 = 64;
/// XCDR1 parameter id announcing a 32-bit member id and length.
pub const PID_EXTENDED: u16 = 0x3f01;
/// XCDR1 parameter id closing a parameter list.
pub const PID_LIST_END: u16 = 0x3f02;
/// XCDR1 parameter id to skip.
pub const PID_IGNORE: u16 = 0x3f03;
