//! Key-only serialization, the RTPS key hash (RTPS 2.5 §9.6.4.8, XTypes 1.3 §7.6.8) and instance identity.

use md5::{Digest, Md5};

use super::error::{DecodeError, EncodeError};
use super::header::{ByteOrder, XcdrVersion};
use super::payload::{decode_payload, encode_payload};
use super::traits::DdsType;
use super::writer::{CdrWriter, EncodeMode};

/// Appends a key-only payload (encapsulation header, then the key members in declaration order, framed as the
/// type's extensibility requires), as carried by DATA(K) and dispose/unregister messages.
pub fn serialize_key<T: DdsType>(
    sample: &T,
    version: XcdrVersion,
    order: ByteOrder,
    out: &mut Vec<u8>,
) -> Result<(), EncodeError> {
    encode_payload(sample, version, order, EncodeMode::Key, out)
}

/// Decodes a key-only payload; members that are not keys get their default values.
pub fn deserialize_key<T: DdsType>(payload: &[u8]) -> Result<T, DecodeError> {
    decode_payload(payload, true)
}

/// Writes the big-endian key stream libddsc hashes: key members only, in member-id order, plain (no DHEADER,
/// EMHEADER or parameter header, whatever the extensibility), aligned as `version` says.
fn key_stream<T: DdsType>(
    sample: &T,
    version: XcdrVersion,
    out: &mut Vec<u8>,
) -> Result<(), EncodeError> {
    sample.encode(&mut CdrWriter::new(
        out,
        version,
        ByteOrder::BigEndian,
        EncodeMode::KeyHash,
    ))
}

/// The 16-byte key hash of `sample` for a payload of XCDR version `version` (Cyclone uses the sample's version).
/// The key stream is zero-padded to 16 bytes when the type's maximum key-stream size is at most 16 (in XCDR1
/// only if no @mutable type is on the key path, as libddsc decides), else hashed with MD5 as it is. Unkeyed
/// types hash to zeros. Use it on the wire only: instance identity is [`instance_key`].
pub fn key_hash<T: DdsType>(sample: &T, version: XcdrVersion) -> Result<[u8; 16], EncodeError> {
    if !T::IS_KEYED {
        return Ok([0u8; 16]);
    }
    let mut buf = Vec::with_capacity(32);
    key_stream(sample, version, &mut buf)?;
    Ok(hash_key_stream(
        &buf,
        T::key_max_end(0, version, None),
        version,
        T::KEY_HAS_MUTABLE,
    ))
}

/// The key hash of a key stream: zero-padded to 16 bytes when the type's largest stream (`max_end`) fits in 16
/// (in XCDR1 only if no @mutable type is on the key path, as libddsc decides), else its MD5.
pub(crate) fn hash_key_stream(
    stream: &[u8],
    max_end: Option<usize>,
    version: XcdrVersion,
    key_has_mutable: bool,
) -> [u8; 16] {
    let mut h = [0u8; 16];
    let fixed = match max_end {
        Some(max) => max <= 16 && !(version == XcdrVersion::Xcdr1 && key_has_mutable),
        None => false,
    };
    if fixed && stream.len() <= 16 {
        h[..stream.len()].copy_from_slice(stream);
    } else {
        h.copy_from_slice(&Md5::digest(stream));
    }
    h
}

/// Appends canonical identity bytes for the instance of `sample` (the XCDR2 big-endian key stream, never
/// hashed): equal keys give equal bytes. Appends nothing for unkeyed types.
pub fn instance_key<T: DdsType>(sample: &T, out: &mut Vec<u8>) -> Result<(), EncodeError> {
    if !T::IS_KEYED {
        return Ok(());
    }
    key_stream(sample, XcdrVersion::Xcdr2, out)
}
