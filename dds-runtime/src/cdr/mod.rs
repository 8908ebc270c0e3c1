//! XCDR1/XCDR2 serialization (XTypes 1.3 §7.4).
//!
//! The entry points are [`serialize`], [`deserialize`], [`serialize_key`], [`deserialize_key`], [`key_hash`]
//! and [`instance_key`], over types implementing [`DdsType`] (usually through `#[derive(DdsType)]`).
//! Generated code drives [`CdrWriter`] and [`CdrReader`] through the helpers in [`members`].

mod collections;
mod error;
mod fixed;
mod header;
mod key;
pub mod members;
mod primitives;
mod reader;
mod traits;
mod wrappers;
mod writer;

pub use error::{DecodeError, DecodeErrorKind, EncodeError};
pub use fixed::{Fixed, FixedError};
pub use header::{ByteOrder, EncapsulationHeader, Extensibility, Representation, XcdrVersion};
pub use key::{deserialize_key, instance_key, key_hash, serialize_key};
pub use members::{DefaultSearch, Discriminator};
pub use reader::{CdrReader, Limit};
pub use traits::{CdrType, DdsType, Layout, MemberDescriptor, StructMembers, TypeDescriptor};
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

pub(crate) fn start_payload<T: DdsType>(
    version: XcdrVersion,
    order: ByteOrder,
    out: &mut Vec<u8>,
) -> usize {
    let start = out.len();
    out.extend_from_slice(
        &EncapsulationHeader::for_type(version, T::EXTENSIBILITY, order).to_bytes(),
    );
    start
}

/// Pads the payload to a multiple of 4 and records the padding in the header options, as Cyclone DDS does;
/// on error removes what was appended.
pub(crate) fn finish_payload(
    start: usize,
    r: Result<(), EncodeError>,
    out: &mut Vec<u8>,
) -> Result<(), EncodeError> {
    if let Err(e) = r {
        out.truncate(start);
        return Err(e);
    }
    let pad = (out.len() - start).wrapping_neg() & 3;
    out.extend_from_slice(&[0u8; 3][..pad]);
    out[start + 3] = (out[start + 3] & !3) | pad as u8;
    Ok(())
}

/// Appends the encapsulation header and the encoding of `sample` to `out`. Allocates nothing when `out` has
/// enough capacity.
pub fn serialize<T: DdsType>(
    sample: &T,
    version: XcdrVersion,
    order: ByteOrder,
    out: &mut Vec<u8>,
) -> Result<(), EncodeError> {
    let start = start_payload::<T>(version, order, out);
    let r = sample.encode(&mut CdrWriter::new(out, version, order, EncodeMode::Sample));
    finish_payload(start, r, out)
}

/// Decodes a payload that starts with its encapsulation header. Never panics; see [`DecodeError`].
pub fn deserialize<T: DdsType>(payload: &[u8]) -> Result<T, DecodeError> {
    let h = EncapsulationHeader::parse(payload)?;
    let mut r = CdrReader::new(
        payload,
        EncapsulationHeader::SIZE,
        h.version()?,
        h.byte_order(),
        false,
    );
    T::decode(&mut r)
}
