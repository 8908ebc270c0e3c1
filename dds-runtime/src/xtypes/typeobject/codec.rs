//! XCDR2 (little-endian, no encapsulation header) encoding of the type system, following Cyclone 11's
//! extensibility of each spec type: `@final` types are written plainly, `@appendable` ones behind a DHEADER,
//! `@optional` members of non-mutable types behind a presence octet.

use crate::cdr::{
    ByteOrder, CdrReader, CdrWriter, DecodeError, EncodeError, EncodeMode, XcdrVersion,
};

use super::identifier::{EquivalenceKind, PlainCollectionHeader, TypeIdentifier};
use super::kind::*;
use super::object::*;

/// A value of the type system with an XCDR2 form (the spec's IDL types, as Cyclone writes them).
pub trait XtypesCodec: Sized {
    /// Appends the encoding.
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError>;
    /// Decodes one value; hostile input is an error, and nothing is allocated beyond what the input holds.
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError>;
}

/// Serializes `v` as XCDR2 little-endian, without an encapsulation header (what hashes and SEDP carry).
pub fn to_bytes<T: XtypesCodec>(v: &T) -> Result<Vec<u8>, EncodeError> {
    let mut out = Vec::new();
    let mut w = CdrWriter::new(
        &mut out,
        XcdrVersion::Xcdr2,
        ByteOrder::LittleEndian,
        EncodeMode::Sample,
    );
    v.encode(&mut w)?;
    Ok(out)
}

/// Decodes XCDR2 little-endian bytes without an encapsulation header; trailing bytes are an error.
pub fn from_bytes<T: XtypesCodec>(bytes: &[u8]) -> Result<T, DecodeError> {
    let mut r = CdrReader::new(bytes, 0, XcdrVersion::Xcdr2, ByteOrder::LittleEndian, false);
    let v = T::decode(&mut r)?;
    if r.remaining() != 0 {
        return Err(r.error(
            "end of the type object data",
            crate::cdr::DecodeErrorKind::Overrun {
                excess: r.remaining(),
            },
        ));
    }
    Ok(v)
}

/// Writes an `@appendable` body behind its DHEADER.
pub(crate) fn appendable(
    w: &mut CdrWriter<'_>,
    f: impl FnOnce(&mut CdrWriter<'_>) -> Result<(), EncodeError>,
) -> Result<(), EncodeError> {
    w.enter()?;
    let slot = w.begin_length();
    f(w)?;
    w.leave();
    w.end_length(slot)
}

pub(super) fn string(w: &mut CdrWriter<'_>, s: &str) -> Result<(), EncodeError> {
    if s.as_bytes().contains(&0) {
        return Err(EncodeError::InvalidValue {
            what: "type object string",
            value: 0,
        });
    }
    w.write_len(s.len() + 1, "type object string")?;
    w.write_bytes(s.as_bytes());
    w.write_u8(0);
    Ok(())
}

/// An `@optional` member of a non-mutable type: presence octet, then the value.
fn optional<T>(
    w: &mut CdrWriter<'_>,
    v: &Option<T>,
    f: impl FnOnce(&mut CdrWriter<'_>, &T) -> Result<(), EncodeError>,
) -> Result<(), EncodeError> {
    match v {
        None => {
            w.write_u8(0);
            Ok(())
        }
        Some(v) => {
            w.write_u8(1);
            f(w, v)
        }
    }
}

/// A sequence of non-primitive elements: DHEADER, count, elements.
pub(crate) fn seq<T>(
    w: &mut CdrWriter<'_>,
    items: &[T],
    f: impl Fn(&mut CdrWriter<'_>, &T) -> Result<(), EncodeError>,
) -> Result<(), EncodeError> {
    appendable(w, |w| {
        w.write_len(items.len(), "sequence")?;
        items.iter().try_for_each(|i| f(w, i))
    })
}

fn plain_header(w: &mut CdrWriter<'_>, h: &PlainCollectionHeader) {
    w.write_u8(h.equiv_kind.octet());
    w.write_u16(h.element_flags.bits());
}

fn small(w: &mut CdrWriter<'_>, v: u32) -> Result<(), EncodeError> {
    let b = u8::try_from(v).map_err(|_| EncodeError::TooLarge {
        what: "small bound",
        len: u64::from(v),
    })?;
    w.write_u8(b);
    Ok(())
}

impl XtypesCodec for TypeIdentifier {
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        let d = self.discriminator();
        w.write_u8(d);
        match self {
            TypeIdentifier::None | TypeIdentifier::Primitive(_) => {}
            TypeIdentifier::String8 { bound } | TypeIdentifier::String16 { bound } => {
                if matches!(d, TI_STRING8_SMALL | TI_STRING16_SMALL) {
                    small(w, *bound)?;
                } else {
                    w.write_u32(*bound);
                }
            }
            TypeIdentifier::PlainSequence {
                header,
                bound,
                element,
            } => {
                plain_header(w, header);
                if d == TI_PLAIN_SEQUENCE_SMALL {
                    small(w, *bound)?;
                } else {
                    w.write_u32(*bound);
                }
                w.enter()?;
                element.encode(w)?;
                w.leave();
            }
            TypeIdentifier::PlainArray {
                header,
                bounds,
                element,
            } => {
                plain_header(w, header);
                w.write_len(bounds.len(), "array bounds")?;
                for b in bounds {
                    if d == TI_PLAIN_ARRAY_SMALL {
                        small(w, *b)?;
                    } else {
                        w.write_u32(*b);
                    }
                }
                w.enter()?;
                element.encode(w)?;
                w.leave();
            }
            TypeIdentifier::PlainMap {
                header,
                bound,
                element,
                key_flags,
                key,
            } => {
                plain_header(w, header);
                if d == TI_PLAIN_MAP_SMALL {
                    small(w, *bound)?;
                } else {
                    w.write_u32(*bound);
                }
                w.enter()?;
                element.encode(w)?;
                w.write_u16(key_flags.bits());
                key.encode(w)?;
                w.leave();
            }
            TypeIdentifier::StronglyConnected(s) => appendable(w, |w| {
                w.write_u8(s.kind.octet());
                w.write_bytes(&s.hash);
                w.write_u32(s.scc_length as u32);
                w.write_u32(s.scc_index as u32);
                Ok(())
            })?,
            TypeIdentifier::Minimal(h) | TypeIdentifier::Complete(h) => w.write_bytes(h),
        }
        Ok(())
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        super::decode::type_identifier(r)
    }
}

/// Writes a body in the minimal (`complete == false`) or complete form.
pub(super) struct BodyWriter {
    pub(super) complete: bool,
}

impl BodyWriter {
    fn type_detail(&self, w: &mut CdrWriter<'_>, d: &TypeDetail) -> Result<(), EncodeError> {
        if !self.complete {
            return Ok(());
        }
        optional(w, &d.ann_builtin, |w, v| {
            appendable(w, |w| optional(w, &Some(v), |w, v| verbatim(w, v)))
        })?;
        optional(w, &d.ann_custom, |w, v| seq(w, v, applied_annotation))?;
        string(w, &d.type_name)
    }

    fn member_detail(&self, w: &mut CdrWriter<'_>, d: &MemberDetail) -> Result<(), EncodeError> {
        if !self.complete {
            w.write_bytes(&d.name.hash());
            return Ok(());
        }
        let MemberName::Name(name) = &d.name else {
            return Err(EncodeError::InvalidValue {
                what: "complete member without a name",
                value: 0,
            });
        };
        string(w, name)?;
        optional(w, &d.ann_builtin, builtin_member_annotations)?;
        optional(w, &d.ann_custom, |w, v| seq(w, v, applied_annotation))
    }

    fn element(&self, w: &mut CdrWriter<'_>, e: &CollectionElement) -> Result<(), EncodeError> {
        appendable(w, |w| {
            w.write_u16(e.flags.bits());
            e.type_id.encode(w)?;
            if self.complete {
                optional(w, &e.ann_builtin, builtin_member_annotations)?;
                optional(w, &e.ann_custom, |w, v| seq(w, v, applied_annotation))?;
            }
            Ok(())
        })
    }

    fn collection_header(
        &self,
        w: &mut CdrWriter<'_>,
        bound: u32,
        d: &Option<TypeDetail>,
    ) -> Result<(), EncodeError> {
        appendable(w, |w| {
            w.write_u32(bound);
            if self.complete {
                optional(w, d, |w, d| self.type_detail(w, d))?;
            }
            Ok(())
        })
    }

    fn struct_members(
        &self,
        w: &mut CdrWriter<'_>,
        ms: &[StructMember],
    ) -> Result<(), EncodeError> {
        seq(w, ms, |w, m| {
            appendable(w, |w| {
                w.write_u32(m.id);
                w.write_u16(m.flags.bits());
                m.type_id.encode(w)?;
                self.member_detail(w, &m.detail)
            })
        })
    }

    fn union_members(&self, w: &mut CdrWriter<'_>, ms: &[UnionMember]) -> Result<(), EncodeError> {
        seq(w, ms, |w, m| {
            appendable(w, |w| {
                w.write_u32(m.id);
                w.write_u16(m.flags.bits());
                m.type_id.encode(w)?;
                w.write_len(m.labels.len(), "union labels")?;
                m.labels.iter().for_each(|l| w.write_u32(*l as u32));
                self.member_detail(w, &m.detail)
            })
        })
    }

    fn literals(&self, w: &mut CdrWriter<'_>, ls: &[EnumeratedLiteral]) -> Result<(), EncodeError> {
        seq(w, ls, |w, l| {
            appendable(w, |w| {
                appendable(w, |w| {
                    w.write_u32(l.value as u32);
                    w.write_u16(l.flags.bits());
                    Ok(())
                })?;
                self.member_detail(w, &l.detail)
            })
        })
    }

    fn bitflags(&self, w: &mut CdrWriter<'_>, fs: &[Bitflag]) -> Result<(), EncodeError> {
        seq(w, fs, |w, f| {
            appendable(w, |w| {
                w.write_u16(f.position);
                w.write_u16(f.flags.bits());
                self.member_detail(w, &f.detail)
            })
        })
    }

    fn bitfields(&self, w: &mut CdrWriter<'_>, fs: &[Bitfield]) -> Result<(), EncodeError> {
        seq(w, fs, |w, f| {
            appendable(w, |w| {
                w.write_u16(f.position);
                w.write_u16(f.flags.bits());
                w.write_u8(f.bitcount);
                w.write_u8(f.holder_type);
                self.member_detail(w, &f.detail)
            })
        })
    }

    /// The builtin and custom annotations that only the complete form carries.
    fn complete_annotations<B>(
        &self,
        w: &mut CdrWriter<'_>,
        builtin: &Option<B>,
        custom: &Option<Vec<AppliedAnnotation>>,
        write_builtin: impl FnOnce(&mut CdrWriter<'_>, &B) -> Result<(), EncodeError>,
    ) -> Result<(), EncodeError> {
        if self.complete {
            optional(w, builtin, write_builtin)?;
            optional(w, custom, |w, v| seq(w, v, applied_annotation))?;
        }
        Ok(())
    }

    fn array(
        &self,
        w: &mut CdrWriter<'_>,
        flags: super::TypeFlag,
        bounds: &[u32],
        detail: &TypeDetail,
        element: &CollectionElement,
    ) -> Result<(), EncodeError> {
        let write = |w: &mut CdrWriter<'_>| {
            w.write_u16(flags.bits());
            appendable(w, |w| {
                w.write_len(bounds.len(), "array bounds")?;
                bounds.iter().for_each(|b| w.write_u32(*b));
                self.type_detail(w, detail)
            })?;
            self.element(w, element)
        };
        // Cyclone's CompleteArrayType is @appendable, its MinimalArrayType @final.
        if self.complete {
            appendable(w, write)
        } else {
            write(w)
        }
    }

    pub(super) fn body(&self, w: &mut CdrWriter<'_>, b: &TypeBody) -> Result<(), EncodeError> {
        w.write_u8(b.kind());
        match b {
            TypeBody::Alias {
                flags,
                detail,
                related_flags,
                related_type,
                ann_builtin,
                ann_custom,
            } => {
                w.write_u16(flags.bits());
                appendable(w, |w| self.type_detail(w, detail))?;
                appendable(w, |w| {
                    w.write_u16(related_flags.bits());
                    related_type.encode(w)?;
                    self.complete_annotations(
                        w,
                        ann_builtin,
                        ann_custom,
                        builtin_member_annotations,
                    )
                })
            }
            TypeBody::Struct {
                flags,
                base,
                detail,
                members,
            } => {
                w.write_u16(flags.bits());
                appendable(w, |w| {
                    base.encode(w)?;
                    self.type_detail(w, detail)
                })?;
                self.struct_members(w, members)
            }
            TypeBody::Union {
                flags,
                detail,
                disc_flags,
                disc_type,
                disc_ann_builtin,
                disc_ann_custom,
                members,
            } => {
                w.write_u16(flags.bits());
                appendable(w, |w| self.type_detail(w, detail))?;
                appendable(w, |w| {
                    w.write_u16(disc_flags.bits());
                    disc_type.encode(w)?;
                    self.complete_annotations(w, disc_ann_builtin, disc_ann_custom, |w, v| {
                        appendable(w, |w| optional(w, &Some(v), |w, v| verbatim(w, v)))
                    })
                })?;
                self.union_members(w, members)
            }
            TypeBody::Enum {
                flags,
                bit_bound,
                detail,
                literals,
            } => {
                w.write_u16(flags.bits());
                appendable(w, |w| {
                    w.write_u16(*bit_bound);
                    self.type_detail(w, detail)
                })?;
                self.literals(w, literals)
            }
            TypeBody::Bitmask {
                flags,
                bit_bound,
                detail,
                bitflags,
            } => appendable(w, |w| {
                w.write_u16(flags.bits());
                appendable(w, |w| {
                    w.write_u16(*bit_bound);
                    self.type_detail(w, detail)
                })?;
                self.bitflags(w, bitflags)
            }),
            TypeBody::Bitset {
                flags,
                detail,
                fields,
            } => appendable(w, |w| {
                w.write_u16(flags.bits());
                appendable(w, |w| self.type_detail(w, detail))?;
                self.bitfields(w, fields)
            }),
            TypeBody::Sequence {
                flags,
                bound,
                detail,
                element,
            } => {
                w.write_u16(flags.bits());
                self.collection_header(w, *bound, detail)?;
                self.element(w, element)
            }
            TypeBody::Array {
                flags,
                bounds,
                detail,
                element,
            } => self.array(w, *flags, bounds, detail, element),
            TypeBody::Map {
                flags,
                bound,
                detail,
                key,
                element,
            } => {
                w.write_u16(flags.bits());
                self.collection_header(w, *bound, detail)?;
                self.element(w, key)?;
                self.element(w, element)
            }
        }
    }
}

fn verbatim(w: &mut CdrWriter<'_>, v: &AppliedVerbatimAnnotation) -> Result<(), EncodeError> {
    string(w, &v.placement)?;
    string(w, &v.language)?;
    string(w, &v.text)
}

fn builtin_member_annotations(
    w: &mut CdrWriter<'_>,
    a: &AppliedBuiltinMemberAnnotations,
) -> Result<(), EncodeError> {
    appendable(w, |w| {
        optional(w, &a.unit, |w, s| string(w, s))?;
        optional(w, &a.min, annotation_value)?;
        optional(w, &a.max, annotation_value)?;
        optional(w, &a.hash_id, |w, s| string(w, s))
    })
}

fn applied_annotation(w: &mut CdrWriter<'_>, a: &AppliedAnnotation) -> Result<(), EncodeError> {
    appendable(w, |w| {
        a.annotation_typeid.encode(w)?;
        optional(w, &a.param_seq, |w, ps| {
            seq(w, ps, |w, p| {
                appendable(w, |w| {
                    w.write_bytes(&p.paramname_hash);
                    annotation_value(w, &p.value)
                })
            })
        })
    })
}

fn annotation_value(
    w: &mut CdrWriter<'_>,
    v: &AnnotationParameterValue,
) -> Result<(), EncodeError> {
    use AnnotationParameterValue as V;
    match v {
        V::Boolean(b) => {
            w.write_u8(TK_BOOLEAN);
            w.write_u8(u8::from(*b));
        }
        V::Byte(b) => {
            w.write_u8(TK_BYTE);
            w.write_u8(*b);
        }
        V::Int8(b) => {
            w.write_u8(TK_INT8);
            w.write_u8(*b as u8);
        }
        V::Uint8(b) => {
            w.write_u8(TK_UINT8);
            w.write_u8(*b);
        }
        V::Int16(x) => {
            w.write_u8(TK_INT16);
            w.write_u16(*x as u16);
        }
        V::Uint16(x) => {
            w.write_u8(TK_UINT16);
            w.write_u16(*x);
        }
        V::Int32(x) => {
            w.write_u8(TK_INT32);
            w.write_u32(*x as u32);
        }
        V::Uint32(x) => {
            w.write_u8(TK_UINT32);
            w.write_u32(*x);
        }
        V::Int64(x) => {
            w.write_u8(TK_INT64);
            w.write_u64(*x as u64);
        }
        V::Uint64(x) => {
            w.write_u8(TK_UINT64);
            w.write_u64(*x);
        }
        V::Float32(x) => {
            w.write_u8(TK_FLOAT32);
            w.write_u32(*x);
        }
        V::Float64(x) => {
            w.write_u8(TK_FLOAT64);
            w.write_u64(*x);
        }
        V::Char(c) => {
            w.write_u8(TK_CHAR8);
            w.write_u8(*c);
        }
        V::Enumerated(x) => {
            w.write_u8(TK_ENUM);
            w.write_u32(*x as u32);
        }
        V::String8(s) => {
            w.write_u8(TK_STRING8);
            string(w, s)?;
        }
    }
    Ok(())
}

impl XtypesCodec for TypeObject {
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        appendable(w, |w| match self {
            TypeObject::Minimal(m) => {
                w.write_u8(EquivalenceKind::Minimal.octet());
                BodyWriter { complete: false }.body(w, &m.0)
            }
            TypeObject::Complete(c) => {
                w.write_u8(EquivalenceKind::Complete.octet());
                BodyWriter { complete: true }.body(w, &c.0)
            }
        })
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        super::decode::type_object(r)
    }
}
