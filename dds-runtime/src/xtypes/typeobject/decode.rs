//! The bounded decoder of the type system: every length is checked against the input before anything is
//! allocated, nesting is limited by the reader's depth limit, unknown kinds are errors.

use crate::cdr::{CdrReader, DecodeError, DecodeErrorKind};

use super::identifier::{
    EquivalenceKind, PlainCollectionHeader, StronglyConnectedComponentId, TypeIdentifier,
};
use super::kind::*;
use super::object::*;
use super::{MemberFlag, TypeFlag, NAME_MAX_LENGTH};

type R<'a, 'b> = &'a mut CdrReader<'b>;

fn invalid(r: &CdrReader<'_>, what: &'static str, found: u64) -> DecodeError {
    r.error(what, DecodeErrorKind::InvalidValue { found })
}

/// Reads an `@appendable` body behind its DHEADER; members it does not know are skipped.
pub(crate) fn appendable<T>(
    r: R<'_, '_>,
    what: &'static str,
    f: impl FnOnce(&mut CdrReader<'_>) -> Result<T, DecodeError>,
) -> Result<T, DecodeError> {
    r.enter(what)?;
    let len = r.read_u32(what)? as usize;
    let saved = r.begin_limit(len, what)?;
    let v = f(r)?;
    r.end_limit(saved);
    r.leave();
    Ok(v)
}

pub(super) fn string(
    r: R<'_, '_>,
    what: &'static str,
    bound: usize,
) -> Result<String, DecodeError> {
    let n = r.read_count(1, what)?;
    if n == 0 {
        return Err(r.error(what, DecodeErrorKind::MalformedString));
    }
    if bound != 0 && n - 1 > bound {
        return Err(r.error(what, DecodeErrorKind::BoundExceeded { bound, len: n - 1 }));
    }
    let b = r.read_bytes(n, what)?;
    let (body, nul) = b.split_at(n - 1);
    if nul != [0] || body.contains(&0) {
        return Err(r.error(what, DecodeErrorKind::MalformedString));
    }
    std::str::from_utf8(body)
        .map(str::to_owned)
        .map_err(|_| r.error(what, DecodeErrorKind::MalformedString))
}

fn flag(r: R<'_, '_>, what: &'static str) -> Result<bool, DecodeError> {
    match r.read_u8(what)? {
        0 => Ok(false),
        1 => Ok(true),
        b => Err(invalid(r, what, u64::from(b))),
    }
}

fn optional<T>(
    r: R<'_, '_>,
    what: &'static str,
    f: impl FnOnce(&mut CdrReader<'_>) -> Result<T, DecodeError>,
) -> Result<Option<T>, DecodeError> {
    if flag(r, what)? {
        f(r).map(Some)
    } else {
        Ok(None)
    }
}

/// A sequence of non-primitive elements (DHEADER, count); each element takes at least `min` bytes.
pub(super) fn seq<T>(
    r: R<'_, '_>,
    what: &'static str,
    min: usize,
    f: impl Fn(&mut CdrReader<'_>) -> Result<T, DecodeError>,
) -> Result<Vec<T>, DecodeError> {
    appendable(r, what, |r| {
        let n = r.read_count(min, what)?;
        let mut v = Vec::with_capacity(n);
        for _ in 0..n {
            v.push(f(r)?);
        }
        Ok(v)
    })
}

fn u32_seq(r: R<'_, '_>, what: &'static str) -> Result<Vec<u32>, DecodeError> {
    let n = r.read_count(4, what)?;
    (0..n).map(|_| r.read_u32(what)).collect()
}

fn hash14(r: R<'_, '_>) -> Result<[u8; 14], DecodeError> {
    let mut h = [0u8; 14];
    h.copy_from_slice(r.read_bytes(14, "equivalence hash")?);
    Ok(h)
}

fn plain_header(r: R<'_, '_>) -> Result<PlainCollectionHeader, DecodeError> {
    let k = r.read_u8("equivalence kind")?;
    let equiv_kind = EquivalenceKind::from_octet(k)
        .ok_or_else(|| invalid(r, "equivalence kind", u64::from(k)))?;
    let element_flags = MemberFlag::from_bits_retain(r.read_u16("element flags")?);
    Ok(PlainCollectionHeader {
        equiv_kind,
        element_flags,
    })
}

fn nested_identifier(r: R<'_, '_>) -> Result<Box<TypeIdentifier>, DecodeError> {
    r.enter("type identifier")?;
    let t = type_identifier(r)?;
    r.leave();
    Ok(Box::new(t))
}

/// Decodes a `TypeIdentifier`.
pub(super) fn type_identifier(r: R<'_, '_>) -> Result<TypeIdentifier, DecodeError> {
    let d = r.read_u8("type identifier kind")?;
    let small = |r: R<'_, '_>| r.read_u8("bound").map(u32::from);
    let large = |r: R<'_, '_>| r.read_u32("bound");
    Ok(match d {
        TK_NONE => TypeIdentifier::None,
        k if is_primitive(k) => TypeIdentifier::Primitive(k),
        TI_STRING8_SMALL => TypeIdentifier::String8 { bound: small(r)? },
        TI_STRING8_LARGE => TypeIdentifier::String8 { bound: large(r)? },
        TI_STRING16_SMALL => TypeIdentifier::String16 { bound: small(r)? },
        TI_STRING16_LARGE => TypeIdentifier::String16 { bound: large(r)? },
        TI_PLAIN_SEQUENCE_SMALL | TI_PLAIN_SEQUENCE_LARGE => {
            let header = plain_header(r)?;
            let bound = if d == TI_PLAIN_SEQUENCE_SMALL {
                small(r)?
            } else {
                large(r)?
            };
            TypeIdentifier::PlainSequence {
                header,
                bound,
                element: nested_identifier(r)?,
            }
        }
        TI_PLAIN_ARRAY_SMALL | TI_PLAIN_ARRAY_LARGE => {
            let header = plain_header(r)?;
            let bounds = if d == TI_PLAIN_ARRAY_SMALL {
                let n = r.read_count(1, "array bounds")?;
                (0..n).map(|_| small(r)).collect::<Result<_, _>>()?
            } else {
                u32_seq(r, "array bounds")?
            };
            TypeIdentifier::PlainArray {
                header,
                bounds,
                element: nested_identifier(r)?,
            }
        }
        TI_PLAIN_MAP_SMALL | TI_PLAIN_MAP_LARGE => {
            let header = plain_header(r)?;
            let bound = if d == TI_PLAIN_MAP_SMALL {
                small(r)?
            } else {
                large(r)?
            };
            let element = nested_identifier(r)?;
            let key_flags = MemberFlag::from_bits_retain(r.read_u16("key flags")?);
            TypeIdentifier::PlainMap {
                header,
                bound,
                element,
                key_flags,
                key: nested_identifier(r)?,
            }
        }
        TI_STRONGLY_CONNECTED_COMPONENT => appendable(r, "strongly connected component", |r| {
            let k = r.read_u8("component hash kind")?;
            let kind = match EquivalenceKind::from_octet(k) {
                Some(k @ (EquivalenceKind::Minimal | EquivalenceKind::Complete)) => k,
                _ => return Err(invalid(r, "component hash kind", u64::from(k))),
            };
            let hash = hash14(r)?;
            let scc_length = r.read_u32("scc_length")? as i32;
            let scc_index = r.read_u32("scc_index")? as i32;
            Ok(TypeIdentifier::StronglyConnected(
                StronglyConnectedComponentId {
                    kind,
                    hash,
                    scc_length,
                    scc_index,
                },
            ))
        })?,
        EK_MINIMAL => TypeIdentifier::Minimal(hash14(r)?),
        EK_COMPLETE => TypeIdentifier::Complete(hash14(r)?),
        other => return Err(invalid(r, "type identifier kind", u64::from(other))),
    })
}

/// Decodes a `TypeObject`.
pub(super) fn type_object(r: R<'_, '_>) -> Result<TypeObject, DecodeError> {
    appendable(r, "type object", |r| {
        let k = r.read_u8("type object kind")?;
        match k {
            EK_MINIMAL => Ok(TypeObject::Minimal(MinimalTypeObject(
                BodyReader { complete: false }.body(r)?,
            ))),
            EK_COMPLETE => Ok(TypeObject::Complete(CompleteTypeObject(
                BodyReader { complete: true }.body(r)?,
            ))),
            _ => Err(invalid(r, "type object kind", u64::from(k))),
        }
    })
}

struct BodyReader {
    complete: bool,
}

impl BodyReader {
    fn type_detail(&self, r: R<'_, '_>) -> Result<TypeDetail, DecodeError> {
        if !self.complete {
            return Ok(TypeDetail::default());
        }
        Ok(TypeDetail {
            ann_builtin: optional(r, "type annotations", builtin_type_annotations)?.flatten(),
            ann_custom: optional(r, "custom annotations", applied_annotations)?,
            type_name: string(r, "type name", NAME_MAX_LENGTH)?,
        })
    }

    fn member_detail(&self, r: R<'_, '_>) -> Result<MemberDetail, DecodeError> {
        if !self.complete {
            let mut h = [0u8; 4];
            h.copy_from_slice(r.read_bytes(4, "name hash")?);
            return Ok(MemberDetail {
                name: MemberName::Hash(h),
                ann_builtin: None,
                ann_custom: None,
            });
        }
        Ok(MemberDetail {
            name: MemberName::Name(string(r, "member name", NAME_MAX_LENGTH)?),
            ann_builtin: optional(r, "member annotations", builtin_member_annotations)?,
            ann_custom: optional(r, "custom annotations", applied_annotations)?,
        })
    }

    /// A bit field: at most 64 bits, ending at bit 64 at the latest.
    fn bitfield(&self, r: R<'_, '_>) -> Result<Bitfield, DecodeError> {
        let position = r.read_u16("bit position")?;
        let flags = MemberFlag::from_bits_retain(r.read_u16("member flags")?);
        let bitcount = r.read_u8("bit count")?;
        if bitcount == 0 || u32::from(position) + u32::from(bitcount) > 64 {
            return Err(invalid(r, "bit field within 64 bits", u64::from(bitcount)));
        }
        let holder_type = r.read_u8("bit field holder type")?;
        Ok(Bitfield {
            position,
            flags,
            bitcount,
            holder_type,
            detail: self.member_detail(r)?,
        })
    }

    fn element(&self, r: R<'_, '_>) -> Result<CollectionElement, DecodeError> {
        appendable(r, "collection element", |r| {
            let flags = MemberFlag::from_bits_retain(r.read_u16("element flags")?);
            let type_id = type_identifier(r)?;
            let (ann_builtin, ann_custom) = if self.complete {
                (
                    optional(r, "element annotations", builtin_member_annotations)?,
                    optional(r, "custom annotations", applied_annotations)?,
                )
            } else {
                (None, None)
            };
            Ok(CollectionElement {
                flags,
                type_id,
                ann_builtin,
                ann_custom,
            })
        })
    }

    fn collection_header(&self, r: R<'_, '_>) -> Result<(u32, Option<TypeDetail>), DecodeError> {
        appendable(r, "collection header", |r| {
            let bound = r.read_u32("collection bound")?;
            let detail = if self.complete {
                optional(r, "collection detail", |r| self.type_detail(r))?
            } else {
                None
            };
            Ok((bound, detail))
        })
    }

    /// TK_ALIAS: the related type, with its flags and (complete) annotations.
    fn alias(&self, r: R<'_, '_>) -> Result<TypeBody, DecodeError> {
        let flags = type_flags(r)?;
        let detail = appendable(r, "alias header", |r| self.type_detail(r))?;
        appendable(r, "alias body", |r| {
            let related_flags = member_flags(r)?;
            let related_type = type_identifier(r)?;
            let (ann_builtin, ann_custom) = if self.complete {
                (
                    optional(r, "alias annotations", builtin_member_annotations)?,
                    optional(r, "custom annotations", applied_annotations)?,
                )
            } else {
                (None, None)
            };
            Ok(TypeBody::Alias {
                flags,
                detail,
                related_flags,
                related_type,
                ann_builtin,
                ann_custom,
            })
        })
    }

    /// TK_STRUCTURE: the base type, the header detail and the members.
    fn structure(&self, r: R<'_, '_>) -> Result<TypeBody, DecodeError> {
        let flags = type_flags(r)?;
        let (base, detail) = appendable(r, "struct header", |r| {
            Ok((type_identifier(r)?, self.type_detail(r)?))
        })?;
        let members = seq(r, "struct members", 8, |r| {
            appendable(r, "struct member", |r| {
                let id = r.read_u32("member id")?;
                let flags = member_flags(r)?;
                let type_id = type_identifier(r)?;
                Ok(StructMember {
                    id,
                    flags,
                    type_id,
                    detail: self.member_detail(r)?,
                })
            })
        })?;
        Ok(TypeBody::Struct {
            flags,
            base,
            detail,
            members,
        })
    }

    /// TK_UNION: the discriminator and the members with their case labels.
    fn union(&self, r: R<'_, '_>) -> Result<TypeBody, DecodeError> {
        let flags = type_flags(r)?;
        let detail = appendable(r, "union header", |r| self.type_detail(r))?;
        let (disc_flags, disc_type, disc_ann_builtin, disc_ann_custom) =
            appendable(r, "discriminator", |r| {
                let f = member_flags(r)?;
                let t = type_identifier(r)?;
                if self.complete {
                    let b = optional(r, "discriminator annotations", builtin_type_annotations)?
                        .flatten();
                    let c = optional(r, "custom annotations", applied_annotations)?;
                    Ok((f, t, b, c))
                } else {
                    Ok((f, t, None, None))
                }
            })?;
        let members = seq(r, "union members", 8, |r| {
            appendable(r, "union member", |r| {
                let id = r.read_u32("member id")?;
                let flags = member_flags(r)?;
                let type_id = type_identifier(r)?;
                let n = r.read_count(4, "case labels")?;
                let labels = (0..n)
                    .map(|_| r.read_u32("case label").map(|v| v as i32))
                    .collect::<Result<_, _>>()?;
                Ok(UnionMember {
                    id,
                    flags,
                    type_id,
                    labels,
                    detail: self.member_detail(r)?,
                })
            })
        })?;
        Ok(TypeBody::Union {
            flags,
            detail,
            disc_flags,
            disc_type,
            disc_ann_builtin,
            disc_ann_custom,
            members,
        })
    }

    /// TK_ENUM: the bit bound and the enumerators.
    fn enumeration(&self, r: R<'_, '_>) -> Result<TypeBody, DecodeError> {
        let flags = type_flags(r)?;
        let (bit_bound, detail) = appendable(r, "enum header", |r| {
            Ok((r.read_u16("bit_bound")?, self.type_detail(r)?))
        })?;
        let literals = seq(r, "enumerators", 8, |r| {
            appendable(r, "enumerator", |r| {
                let (value, flags) = appendable(r, "enumerator value", |r| {
                    Ok((r.read_u32("enumerator value")? as i32, member_flags(r)?))
                })?;
                Ok(EnumeratedLiteral {
                    value,
                    flags,
                    detail: self.member_detail(r)?,
                })
            })
        })?;
        Ok(TypeBody::Enum {
            flags,
            bit_bound,
            detail,
            literals,
        })
    }

    /// TK_BITMASK: the bit bound and the flags.
    fn bitmask(&self, r: R<'_, '_>) -> Result<TypeBody, DecodeError> {
        appendable(r, "bitmask", |r| {
            let flags = type_flags(r)?;
            let (bit_bound, detail) = appendable(r, "bitmask header", |r| {
                Ok((r.read_u16("bit_bound")?, self.type_detail(r)?))
            })?;
            let bitflags = seq(r, "bitflags", 8, |r| {
                appendable(r, "bitflag", |r| {
                    let position = r.read_u16("bit position")?;
                    let flags = member_flags(r)?;
                    Ok(Bitflag {
                        position,
                        flags,
                        detail: self.member_detail(r)?,
                    })
                })
            })?;
            Ok(TypeBody::Bitmask {
                flags,
                bit_bound,
                detail,
                bitflags,
            })
        })
    }
    fn body(&self, r: R<'_, '_>) -> Result<TypeBody, DecodeError> {
        let k = r.read_u8("type kind")?;
        Ok(match k {
            TK_ALIAS => self.alias(r)?,
            TK_STRUCTURE => self.structure(r)?,
            TK_UNION => self.union(r)?,
            TK_ENUM => self.enumeration(r)?,
            TK_BITMASK => self.bitmask(r)?,
            TK_BITSET => appendable(r, "bitset", |r| {
                let flags = type_flags(r)?;
                let detail = appendable(r, "bitset header", |r| self.type_detail(r))?;
                let fields = seq(r, "bitfields", 8, |r| {
                    appendable(r, "bitfield", |r| self.bitfield(r))
                })?;
                Ok(TypeBody::Bitset {
                    flags,
                    detail,
                    fields,
                })
            })?,
            TK_SEQUENCE => {
                let flags = type_flags(r)?;
                let (bound, detail) = self.collection_header(r)?;
                TypeBody::Sequence {
                    flags,
                    bound,
                    detail,
                    element: self.element(r)?,
                }
            }
            TK_ARRAY => {
                let read = |r: R<'_, '_>| {
                    let flags = type_flags(r)?;
                    let (bounds, detail) = appendable(r, "array header", |r| {
                        Ok((u32_seq(r, "array bounds")?, self.type_detail(r)?))
                    })?;
                    Ok(TypeBody::Array {
                        flags,
                        bounds,
                        detail,
                        element: self.element(r)?,
                    })
                };
                if self.complete {
                    appendable(r, "complete array", read)?
                } else {
                    read(r)?
                }
            }
            TK_MAP => {
                let flags = type_flags(r)?;
                let (bound, detail) = self.collection_header(r)?;
                let key = self.element(r)?;
                TypeBody::Map {
                    flags,
                    bound,
                    detail,
                    key,
                    element: self.element(r)?,
                }
            }
            other => return Err(invalid(r, "supported type object kind", u64::from(other))),
        })
    }
}

fn builtin_type_annotations(
    r: R<'_, '_>,
) -> Result<Option<AppliedVerbatimAnnotation>, DecodeError> {
    appendable(r, "builtin type annotations", |r| {
        optional(r, "verbatim", |r| {
            Ok(AppliedVerbatimAnnotation {
                placement: string(r, "verbatim placement", 32)?,
                language: string(r, "verbatim language", 32)?,
                text: string(r, "verbatim text", 0)?,
            })
        })
    })
}

fn builtin_member_annotations(
    r: R<'_, '_>,
) -> Result<AppliedBuiltinMemberAnnotations, DecodeError> {
    appendable(r, "builtin member annotations", |r| {
        Ok(AppliedBuiltinMemberAnnotations {
            unit: optional(r, "unit", |r| string(r, "unit", 0))?,
            min: optional(r, "min", annotation_value)?,
            max: optional(r, "max", annotation_value)?,
            hash_id: optional(r, "hash_id", |r| string(r, "hash_id", 0))?,
        })
    })
}

fn applied_annotations(r: R<'_, '_>) -> Result<Vec<AppliedAnnotation>, DecodeError> {
    seq(r, "applied annotations", 5, |r| {
        appendable(r, "applied annotation", |r| {
            let annotation_typeid = type_identifier(r)?;
            let param_seq = optional(r, "annotation parameters", |r| {
                seq(r, "annotation parameters", 8, |r| {
                    appendable(r, "annotation parameter", |r| {
                        let mut h = [0u8; 4];
                        h.copy_from_slice(r.read_bytes(4, "parameter name hash")?);
                        Ok(AppliedAnnotationParameter {
                            paramname_hash: h,
                            value: annotation_value(r)?,
                        })
                    })
                })
            })?;
            Ok(AppliedAnnotation {
                annotation_typeid,
                param_seq,
            })
        })
    })
}

fn annotation_value(r: R<'_, '_>) -> Result<AnnotationParameterValue, DecodeError> {
    use AnnotationParameterValue as V;
    let k = r.read_u8("annotation value kind")?;
    Ok(match k {
        TK_BOOLEAN => V::Boolean(flag(r, "boolean annotation value")?),
        TK_BYTE => V::Byte(r.read_u8("annotation value")?),
        TK_INT8 => V::Int8(r.read_u8("annotation value")? as i8),
        TK_UINT8 => V::Uint8(r.read_u8("annotation value")?),
        TK_INT16 => V::Int16(r.read_u16("annotation value")? as i16),
        TK_UINT16 => V::Uint16(r.read_u16("annotation value")?),
        TK_INT32 => V::Int32(r.read_u32("annotation value")? as i32),
        TK_UINT32 => V::Uint32(r.read_u32("annotation value")?),
        TK_INT64 => V::Int64(r.read_u64("annotation value")? as i64),
        TK_UINT64 => V::Uint64(r.read_u64("annotation value")?),
        TK_FLOAT32 => V::Float32(r.read_u32("annotation value")?),
        TK_FLOAT64 => V::Float64(r.read_u64("annotation value")?),
        TK_CHAR8 => V::Char(r.read_u8("annotation value")?),
        TK_ENUM => V::Enumerated(r.read_u32("annotation value")? as i32),
        TK_STRING8 => V::String8(string(r, "annotation string", 128)?),
        other => {
            return Err(invalid(
                r,
                "supported annotation value kind",
                u64::from(other),
            ))
        }
    })
}

fn type_flags(r: R<'_, '_>) -> Result<TypeFlag, DecodeError> {
    r.read_u16("type flags").map(TypeFlag::from_bits_retain)
}

fn member_flags(r: R<'_, '_>) -> Result<MemberFlag, DecodeError> {
    r.read_u16("member flags").map(MemberFlag::from_bits_retain)
}
