//! Whole payloads: the encapsulation header, then the sample, then the padding recorded in the header options.

use super::error::{DecodeError, EncodeError};
use super::header::{ByteOrder, EncapsulationHeader, XcdrVersion};
use super::reader::CdrReader;
use super::traits::DdsType;
use super::writer::{push_zeros, CdrWriter, EncodeMode};

#[inline]
pub(super) fn start_payload<T: DdsType>(
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
#[inline]
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
    if pad != 0 {
        // Not unconditionally: `push_zeros` reserves a word, which regrows (and copies) a buffer sized to the
        // exact payload length.
        push_zeros(out, pad);
    }
    if let Some(options) = out.get_mut(start + 3) {
        *options = (*options & !3) | pad as u8;
    }
    Ok(())
}

/// Appends the encapsulation header and the encoding of `sample` in `mode`, then pads (see [`finish_payload`]).
#[inline]
pub(crate) fn encode_payload<T: DdsType>(
    sample: &T,
    version: XcdrVersion,
    order: ByteOrder,
    mode: EncodeMode,
    out: &mut Vec<u8>,
) -> Result<(), EncodeError> {
    let start = start_payload::<T>(version, order, out);
    let r = sample.encode(&mut CdrWriter::new(out, version, order, mode));
    finish_payload(start, r, out)
}

/// A reader of the body of a payload that starts with its encapsulation header (its version and byte order);
/// `key_only` for a key-only payload. Inlined, so the reader is built where it is used rather than returned
/// through memory and copied.
#[inline]
pub(crate) fn payload_reader(payload: &[u8], key_only: bool) -> Result<CdrReader<'_>, DecodeError> {
    let h = EncapsulationHeader::parse(payload)?;
    Ok(CdrReader::new(
        payload,
        EncapsulationHeader::SIZE,
        h.version()?,
        h.byte_order(),
        key_only,
    ))
}

/// Decodes a payload that starts with its encapsulation header; `key_only` for a key-only payload.
pub(crate) fn decode_payload<T: DdsType>(payload: &[u8], key_only: bool) -> Result<T, DecodeError> {
    T::decode(&mut payload_reader(payload, key_only)?)
}

/// Appends the encapsulation header and the encoding of `sample` to `out`. Allocates nothing when `out` has
/// enough capacity.
pub fn serialize<T: DdsType>(
    sample: &T,
    version: XcdrVersion,
    order: ByteOrder,
    out: &mut Vec<u8>,
) -> Result<(), EncodeError> {
    encode_payload(sample, version, order, EncodeMode::Sample, out)
}

/// Decodes a payload that starts with its encapsulation header. Never panics; see [`DecodeError`].
pub fn deserialize<T: DdsType>(payload: &[u8]) -> Result<T, DecodeError> {
    decode_payload(payload, false)
}

/// [`deserialize`] into an existing sample, reusing the buffers of its strings and sequences: decoding a
/// stream of samples into one value allocates nothing once its buffers are large enough. On error `sample`
/// holds some mix of old and new members.
pub fn deserialize_into<T: DdsType>(payload: &[u8], sample: &mut T) -> Result<(), DecodeError> {
    sample.decode_in_place(&mut payload_reader(payload, false)?, usize::MAX)
}
