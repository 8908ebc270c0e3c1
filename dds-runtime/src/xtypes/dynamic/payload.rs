//! Whole payloads of [`DynamicData`]: encapsulation header, sample or key, end padding; the key hash and the
//! instance key. The same rules as `cdr::{serialize, deserialize, serialize_key, key_hash, instance_key}`.

use crate::cdr::{
    finish_payload, hash_key_stream, payload_reader, ByteOrder, CdrWriter, DecodeError,
    EncapsulationHeader, EncodeError, EncodeMode, XcdrVersion,
};

use super::layout::{key_has_mutable, key_max_end};
use super::types::DynamicType;
use super::value::DynamicData;
use super::{decode, encode};

fn encode_payload(
    d: &DynamicData,
    version: XcdrVersion,
    order: ByteOrder,
    mode: EncodeMode,
    out: &mut Vec<u8>,
) -> Result<(), EncodeError> {
    let start = out.len();
    let ext = d.dynamic_type().extensibility();
    out.extend_from_slice(&EncapsulationHeader::for_type(version, ext, order).to_bytes());
    let r = encode::encode(
        &mut CdrWriter::new(out, version, order, mode),
        d.dynamic_type(),
        d.value(),
    );
    finish_payload(start, r, out)
}

fn decode_payload(
    ty: &DynamicType,
    payload: &[u8],
    key_only: bool,
) -> Result<DynamicData, DecodeError> {
    let mut r = payload_reader(payload, key_only)?;
    let v = decode::decode(&mut r, ty)?;
    Ok(DynamicData::from_value_unchecked(ty.clone(), v))
}

impl DynamicData {
    /// Appends the encapsulation header and the sample (as `cdr::serialize` does for a derived type).
    pub fn serialize(
        &self,
        version: XcdrVersion,
        order: ByteOrder,
        out: &mut Vec<u8>,
    ) -> Result<(), EncodeError> {
        encode_payload(self, version, order, EncodeMode::Sample, out)
    }

    /// Decodes a payload (header included) of type `ty`. Bounded; hostile bytes are an error.
    pub fn deserialize(ty: &DynamicType, payload: &[u8]) -> Result<DynamicData, DecodeError> {
        decode_payload(ty, payload, false)
    }

    /// Appends a key-only payload (DATA(K), dispose, unregister).
    pub fn serialize_key(
        &self,
        version: XcdrVersion,
        order: ByteOrder,
        out: &mut Vec<u8>,
    ) -> Result<(), EncodeError> {
        encode_payload(self, version, order, EncodeMode::Key, out)
    }

    /// Decodes a key-only payload; members that are not keys get their defaults.
    pub fn deserialize_key(ty: &DynamicType, payload: &[u8]) -> Result<DynamicData, DecodeError> {
        decode_payload(ty, payload, true)
    }

    fn key_stream(&self, version: XcdrVersion, out: &mut Vec<u8>) -> Result<(), EncodeError> {
        let mut w = CdrWriter::new(out, version, ByteOrder::BigEndian, EncodeMode::KeyHash);
        encode::encode(&mut w, self.dynamic_type(), self.value())
    }

    /// The 16-byte RTPS key hash for a payload of XCDR version `version` (zeros for an unkeyed type): the key
    /// stream zero-padded when it always fits in 16 bytes, else its MD5, as libddsc decides.
    pub fn key_hash(&self, version: XcdrVersion) -> Result<[u8; 16], EncodeError> {
        let ty = self.dynamic_type();
        if !ty.is_keyed() {
            return Ok([0u8; 16]);
        }
        let mut buf = Vec::with_capacity(32);
        self.key_stream(version, &mut buf)?;
        let max_end = key_max_end(ty, 0, version, None);
        Ok(hash_key_stream(&buf, max_end, version, key_has_mutable(ty)))
    }

    /// Appends the instance's identity bytes (the XCDR2 big-endian key stream); nothing for unkeyed types.
    pub fn instance_key(&self, out: &mut Vec<u8>) -> Result<(), EncodeError> {
        if !self.dynamic_type().is_keyed() {
            return Ok(());
        }
        self.key_stream(XcdrVersion::Xcdr2, out)
    }
}
