//! The wire form of the TypeLookup messages: an encapsulation header (`CDR2_LE`, 0x0007; `CDR2_BE` is read
//! too) and the XCDR2 body, with the extensibility Cyclone DDS gives each type in its `ddsi_xt_typelookup.idl`:
//! the request and reply structs and the RPC header are `@final`, the call/return/result unions appendable
//! (a DHEADER), the `_In`/`_Out` structs `@mutable` with `@hashid` member ids.
//!
//! Decoding is bounded: every list is capped ([`MAX_TYPE_IDS`], [`MAX_TYPES`]), every length checked against
//! the input before anything is allocated, and malformed input is an error, never a panic.

use thiserror::Error;

use crate::cdr::{
    ByteOrder, CdrReader, CdrWriter, DecodeError, DecodeErrorKind, EncodeError, EncodeMode,
    XcdrVersion,
};
use crate::xtypes::typeobject::{
    read_appendable, write_appendable as union, write_seq as seq, TypeIdentifier,
    TypeIdentifierPair, TypeIdentifierTypeObjectPair, TypeIdentifierWithSize, XtypesCodec,
};

use super::messages::*;

/// Most type identifiers a request (or a dependencies reply) may carry.
pub const MAX_TYPE_IDS: usize = 256;
/// Most type objects a `getTypes` reply may carry.
pub const MAX_TYPES: usize = 1024;
/// Longest continuation point (`sequence<octet, 32>`).
pub const MAX_CONTINUATION: usize = 32;
/// Longest instance name (`string<255>`).
const MAX_INSTANCE_NAME: usize = 255;

/// `@hashid` member ids of the `@mutable` structs.
mod member {
    pub(super) const TYPE_IDS: u32 = 0x0c53_6065;
    pub(super) const TYPES: u32 = 0x0280_4ad1;
    pub(super) const COMPLETE_TO_MINIMAL: u32 = 0x0b8e_6577;
    pub(super) const DEPENDENT_TYPEIDS: u32 = 0x0ba4_dfc9;
    pub(super) const CONTINUATION_POINT: u32 = 0x0508_e3d2;
}

/// Representation identifiers (XTypes 1.3 §7.6.3.1.2).
const CDR2_BE: u16 = 0x0006;
const CDR2_LE: u16 = 0x0007;

/// Why a TypeLookup message could not be read or written.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum TypeLookupError {
    /// The payload is not plain XCDR2 (its representation identifier).
    #[error("representation {0:#06x} is not CDR2")]
    Representation(u16),
    /// The body is malformed or exceeds a limit.
    #[error("malformed TypeLookup message: {0}")]
    Decode(#[from] DecodeError),
    /// A value could not be encoded.
    #[error("TypeLookup message cannot be encoded: {0}")]
    Encode(#[from] EncodeError),
}

/// Serializes a request, encapsulation header included.
pub fn encode_request(req: &Request) -> Result<Vec<u8>, TypeLookupError> {
    encapsulated(|w| {
        sample_identity(w, &req.request_id);
        string(w, &req.instance_name)?;
        union(w, |w| match &req.call {
            Call::GetTypes(ids) => {
                w.write_u32(GET_TYPES_HASH_ID);
                mutable(w, |w| {
                    w.write_emheader(member::TYPE_IDS, false, 5)?;
                    seq(w, ids, |w, id| id.encode(w))
                })
            }
            Call::GetTypeDependencies {
                type_ids,
                continuation_point,
            } => {
                w.write_u32(GET_DEPENDENCIES_HASH_ID);
                mutable(w, |w| {
                    w.write_emheader(member::TYPE_IDS, false, 5)?;
                    seq(w, type_ids, |w, id| id.encode(w))?;
                    octets(w, member::CONTINUATION_POINT, continuation_point)
                })
            }
            Call::Other(d) => {
                w.write_u32(*d);
                Ok(())
            }
        })
    })
}

/// Serializes a reply, encapsulation header included.
pub fn encode_reply(rep: &Reply) -> Result<Vec<u8>, TypeLookupError> {
    encapsulated(|w| {
        sample_identity(w, &rep.related_request_id);
        w.write_u32(rep.remote_ex.to_u32());
        union(w, |w| match &rep.return_data {
            Return::GetTypes(res) => {
                w.write_u32(GET_TYPES_HASH_ID);
                result(w, res, |w, out| {
                    w.write_emheader(member::TYPES, false, 5)?;
                    seq(w, &out.types, |w, p| p.encode(w))?;
                    w.write_emheader(member::COMPLETE_TO_MINIMAL, false, 5)?;
                    seq(w, &out.complete_to_minimal, |w, p| p.encode(w))
                })
            }
            Return::GetTypeDependencies(res) => {
                w.write_u32(GET_DEPENDENCIES_HASH_ID);
                result(w, res, |w, out| {
                    w.write_emheader(member::DEPENDENT_TYPEIDS, false, 5)?;
                    seq(w, &out.dependent_typeids, |w, p| p.encode(w))?;
                    octets(w, member::CONTINUATION_POINT, &out.continuation_point)
                })
            }
            Return::Other(d) => {
                w.write_u32(*d);
                Ok(())
            }
        })
    })
}

/// Reads a request (the sample payload, encapsulation header included).
pub fn decode_request(payload: &[u8]) -> Result<Request, TypeLookupError> {
    let mut r = body_reader(payload)?;
    let r = &mut r;
    let request_id = read_sample_identity(r)?;
    let instance_name = read_string(r)?;
    let call = read_union(r, "TypeLookup_Call", |r, d| {
        Ok(match d {
            GET_TYPES_HASH_ID => {
                let mut ids = Vec::new();
                read_mutable(r, "getTypes_In", |r, id| {
                    if id == member::TYPE_IDS {
                        ids = read_seq(r, "type_ids", MAX_TYPE_IDS, 1, TypeIdentifier::decode)?;
                    }
                    Ok(())
                })?;
                Call::GetTypes(ids)
            }
            GET_DEPENDENCIES_HASH_ID => {
                let (mut type_ids, mut continuation_point) = (Vec::new(), Vec::new());
                read_mutable(r, "getTypeDependencies_In", |r, id| {
                    match id {
                        member::TYPE_IDS => {
                            type_ids =
                                read_seq(r, "type_ids", MAX_TYPE_IDS, 1, TypeIdentifier::decode)?
                        }
                        member::CONTINUATION_POINT => continuation_point = read_octets(r)?,
                        _ => {}
                    }
                    Ok(())
                })?;
                Call::GetTypeDependencies {
                    type_ids,
                    continuation_point,
                }
            }
            other => Call::Other(other),
        })
    })?;
    Ok(Request {
        request_id,
        instance_name,
        call,
    })
}

/// Reads a reply (the sample payload, encapsulation header included).
pub fn decode_reply(payload: &[u8]) -> Result<Reply, TypeLookupError> {
    let mut r = body_reader(payload)?;
    let r = &mut r;
    let related_request_id = read_sample_identity(r)?;
    let ex = r.read_u32("remoteEx")?;
    let remote_ex = RemoteExceptionCode::from_u32(ex).ok_or_else(|| {
        r.error(
            "remoteEx",
            DecodeErrorKind::InvalidValue {
                found: u64::from(ex),
            },
        )
    })?;
    let return_data = read_union(r, "TypeLookup_Return", |r, d| {
        Ok(match d {
            GET_TYPES_HASH_ID => Return::GetTypes(read_result(r, read_types_out)?),
            GET_DEPENDENCIES_HASH_ID => {
                Return::GetTypeDependencies(read_result(r, read_dependencies_out)?)
            }
            other => Return::Other(other),
        })
    })?;
    Ok(Reply {
        related_request_id,
        remote_ex,
        return_data,
    })
}

// ---- writing ----

type W<'a, 'b> = &'a mut CdrWriter<'b>;

fn encapsulated(
    f: impl FnOnce(W<'_, '_>) -> Result<(), EncodeError>,
) -> Result<Vec<u8>, TypeLookupError> {
    let mut out = vec![0x00, CDR2_LE as u8, 0x00, 0x00];
    let mut w = CdrWriter::new(
        &mut out,
        XcdrVersion::Xcdr2,
        ByteOrder::LittleEndian,
        EncodeMode::Sample,
    );
    f(&mut w)?;
    // The body is padded to 4 bytes; the options' low bits say how much of it is padding.
    let pad = (4 - (out.len() - 4) % 4) % 4;
    out.resize(out.len() + pad, 0);
    out[3] = pad as u8;
    Ok(out)
}

fn sample_identity(w: W<'_, '_>, id: &SampleIdentity) {
    w.write_bytes(&id.writer_guid);
    w.write_u32((id.sequence_number >> 32) as u32);
    w.write_u32(id.sequence_number as u32);
}

fn string(w: W<'_, '_>, s: &str) -> Result<(), EncodeError> {
    if s.len() > MAX_INSTANCE_NAME || s.as_bytes().contains(&0) {
        return Err(EncodeError::BoundExceeded {
            what: "instanceName",
            bound: MAX_INSTANCE_NAME,
            len: s.len(),
        });
    }
    w.write_len(s.len() + 1, "instanceName")?;
    w.write_bytes(s.as_bytes());
    w.write_u8(0);
    Ok(())
}

/// A mutable struct: DHEADER, then its members each behind an EMHEADER written by `f`.
fn mutable(
    w: W<'_, '_>,
    f: impl FnOnce(W<'_, '_>) -> Result<(), EncodeError>,
) -> Result<(), EncodeError> {
    union(w, f)
}

/// A `getTypes_Result`/`getTypeDependencies_Result` union: the return code, then the value if it is OK.
fn result<T>(
    w: W<'_, '_>,
    res: &Result<T, i32>,
    f: impl FnOnce(W<'_, '_>, &T) -> Result<(), EncodeError>,
) -> Result<(), EncodeError> {
    union(w, |w| match res {
        Ok(v) => {
            w.write_u32(0);
            mutable(w, |w| f(w, v))
        }
        Err(code) => {
            w.write_u32(*code as u32);
            Ok(())
        }
    })
}

/// A `sequence<octet, 32>` member (LC 5: the count is the NEXTINT).
fn octets(w: W<'_, '_>, id: u32, v: &[u8]) -> Result<(), EncodeError> {
    if v.len() > MAX_CONTINUATION {
        return Err(EncodeError::BoundExceeded {
            what: "continuation_point",
            bound: MAX_CONTINUATION,
            len: v.len(),
        });
    }
    w.write_emheader(id, false, 5)?;
    w.write_len(v.len(), "continuation_point")?;
    w.write_bytes(v);
    Ok(())
}

// ---- reading ----

type R<'a, 'b> = &'a mut CdrReader<'b>;

fn body_reader(payload: &[u8]) -> Result<CdrReader<'_>, TypeLookupError> {
    let Some(h) = payload.get(..4) else {
        return Err(DecodeError::new(
            0,
            "encapsulation header",
            DecodeErrorKind::UnexpectedEof {
                needed: 4,
                available: payload.len(),
            },
        )
        .into());
    };
    let order = match u16::from_be_bytes([h[0], h[1]]) {
        CDR2_LE => ByteOrder::LittleEndian,
        CDR2_BE => ByteOrder::BigEndian,
        other => return Err(TypeLookupError::Representation(other)),
    };
    Ok(CdrReader::new(payload, 4, XcdrVersion::Xcdr2, order, false))
}

fn read_sample_identity(r: R<'_, '_>) -> Result<SampleIdentity, DecodeError> {
    let mut writer_guid = [0u8; 16];
    writer_guid.copy_from_slice(r.read_bytes(16, "writer_guid")?);
    let high = r.read_u32("sequence_number.high")? as i32;
    let low = r.read_u32("sequence_number.low")?;
    Ok(SampleIdentity {
        writer_guid,
        sequence_number: (i64::from(high) << 32) | i64::from(low),
    })
}

fn read_string(r: R<'_, '_>) -> Result<String, DecodeError> {
    let n = r.read_count(1, "instanceName")?;
    if n == 0 || n - 1 > MAX_INSTANCE_NAME {
        return Err(r.error(
            "instanceName",
            DecodeErrorKind::BoundExceeded {
                bound: MAX_INSTANCE_NAME,
                len: n.saturating_sub(1),
            },
        ));
    }
    let b = r.read_bytes(n, "instanceName")?;
    let (body, nul) = b.split_at(n - 1);
    if nul != [0] || body.contains(&0) {
        return Err(r.error("instanceName", DecodeErrorKind::MalformedString));
    }
    std::str::from_utf8(body)
        .map(str::to_owned)
        .map_err(|_| r.error("instanceName", DecodeErrorKind::MalformedString))
}

/// An appendable union: DHEADER, a `long` discriminator, the member `f` reads for it.
fn read_union<T>(
    r: R<'_, '_>,
    what: &'static str,
    f: impl FnOnce(R<'_, '_>, u32) -> Result<T, DecodeError>,
) -> Result<T, DecodeError> {
    read_appendable(r, what, |r| {
        let d = r.read_u32(what)?;
        f(r, d)
    })
}

/// A mutable struct: each member behind its EMHEADER is handed to `f` with its id, limited to its length;
/// members `f` does not read are skipped, unknown must-understand members are an error.
fn read_mutable(
    r: R<'_, '_>,
    what: &'static str,
    mut f: impl FnMut(R<'_, '_>, u32) -> Result<(), DecodeError>,
) -> Result<(), DecodeError> {
    read_appendable(r, what, |r| {
        while r.remaining() > 0 {
            let h = r.read_u32(what)?;
            let (must, lc, id) = (h >> 31 == 1, (h >> 28) & 7, h & 0x0fff_ffff);
            let len = match lc {
                0..=3 => 1usize << lc,
                4 => r.read_u32(what)? as usize,
                _ => {
                    let n = r.read_u32(what)? as usize;
                    r.rewind(4);
                    let unit = [1usize, 4, 8][lc as usize - 5];
                    n.checked_mul(unit)
                        .and_then(|b| b.checked_add(4))
                        .ok_or_else(|| {
                            r.error(what, DecodeErrorKind::InvalidValue { found: n as u64 })
                        })?
                }
            };
            let known = matches!(
                id,
                member::TYPE_IDS
                    | member::TYPES
                    | member::COMPLETE_TO_MINIMAL
                    | member::DEPENDENT_TYPEIDS
                    | member::CONTINUATION_POINT
            );
            if must && !known {
                return Err(r.error(what, DecodeErrorKind::UnknownMustUnderstand { id }));
            }
            let saved = r.begin_limit(len, what)?;
            f(r, id)?;
            r.end_limit(saved);
        }
        Ok(())
    })
}

/// A sequence of non-primitive elements (DHEADER, count, elements), at most `max` of them.
fn read_seq<T>(
    r: R<'_, '_>,
    what: &'static str,
    max: usize,
    min_size: usize,
    f: impl Fn(R<'_, '_>) -> Result<T, DecodeError>,
) -> Result<Vec<T>, DecodeError> {
    read_appendable(r, what, |r| {
        let n = r.read_count(min_size, what)?;
        if n > max {
            return Err(r.error(what, DecodeErrorKind::BoundExceeded { bound: max, len: n }));
        }
        let mut v = Vec::with_capacity(n);
        for _ in 0..n {
            v.push(f(r)?);
        }
        Ok(v)
    })
}

fn read_octets(r: R<'_, '_>) -> Result<Vec<u8>, DecodeError> {
    let n = r.read_count(1, "continuation_point")?;
    if n > MAX_CONTINUATION {
        return Err(r.error(
            "continuation_point",
            DecodeErrorKind::BoundExceeded {
                bound: MAX_CONTINUATION,
                len: n,
            },
        ));
    }
    Ok(r.read_bytes(n, "continuation_point")?.to_vec())
}

/// A result union: `Ok` with the value when the discriminator is `DDS_RETCODE_OK`, else `Err(code)`.
fn read_result<T>(
    r: R<'_, '_>,
    f: impl FnOnce(R<'_, '_>) -> Result<T, DecodeError>,
) -> Result<Result<T, i32>, DecodeError> {
    read_union(r, "result", |r, d| {
        if d == 0 {
            f(r).map(Ok)
        } else {
            Ok(Err(d as i32))
        }
    })
}

fn read_types_out(r: R<'_, '_>) -> Result<TypesOut, DecodeError> {
    let mut out = TypesOut::default();
    read_mutable(r, "getTypes_Out", |r, id| {
        match id {
            member::TYPES => {
                out.types = read_seq(
                    r,
                    "types",
                    MAX_TYPES,
                    6,
                    TypeIdentifierTypeObjectPair::decode,
                )?
            }
            member::COMPLETE_TO_MINIMAL => {
                out.complete_to_minimal = read_seq(
                    r,
                    "complete_to_minimal",
                    MAX_TYPES,
                    2,
                    TypeIdentifierPair::decode,
                )?
            }
            _ => {}
        }
        Ok(())
    })?;
    Ok(out)
}

fn read_dependencies_out(r: R<'_, '_>) -> Result<TypeDependencies, DecodeError> {
    let mut out = TypeDependencies::default();
    read_mutable(r, "getTypeDependencies_Out", |r, id| {
        match id {
            member::DEPENDENT_TYPEIDS => {
                out.dependent_typeids = read_seq(
                    r,
                    "dependent_typeids",
                    MAX_TYPE_IDS,
                    5,
                    TypeIdentifierWithSize::decode,
                )?
            }
            member::CONTINUATION_POINT => out.continuation_point = read_octets(r)?,
            _ => {}
        }
        Ok(())
    })?;
    Ok(out)
}
