//! XCDR1/XCDR2 encoding of a [`Value`] by its [`DynamicType`], following the derive's generated code rule for
//! rule (so that both give the same bytes).

use crate::cdr::members::{begin_encode, end_encode};
use crate::cdr::{
    ByteOrder, CdrType, CdrWriter, EncodeError, EncodeMode, Extensibility, Layout, WString,
};

use super::layout::layout;
use super::types::{DynamicType, Member, Primitive, StructType, TypeKind, UnionType};
use super::value::Value;

fn mismatch(what: &'static str) -> EncodeError {
    EncodeError::InvalidValue { what, value: 0 }
}

/// Encodes `v` of type `ty` (with its DHEADER where the type needs one).
pub(super) fn encode(
    w: &mut CdrWriter<'_>,
    ty: &DynamicType,
    v: &Value,
) -> Result<(), EncodeError> {
    match (ty.resolved().kind(), v) {
        (TypeKind::Primitive(p), v) => encode_primitive(w, *p, v),
        (TypeKind::String { wide, bound }, Value::String(s)) => {
            let bound = bound.map_or(usize::MAX, |b| b as usize);
            if *wide {
                // The wrapper's encoder; a copy of the text is the price of sharing it.
                WString(s.clone()).encode_bounded(w, bound)
            } else {
                crate::cdr::encode_str(s, w, bound)
            }
        }
        (TypeKind::Enum(e), Value::Enum(x)) => {
            write_sized(w, e.size(), *x as u32 as u64);
            Ok(())
        }
        (TypeKind::Bitmask(b), Value::Bitmask(x)) => {
            write_sized(w, b.size(), *x);
            Ok(())
        }
        (TypeKind::Struct(s), Value::Struct(vals)) => encode_struct(w, s, vals),
        (
            TypeKind::Union(u),
            Value::Union {
                discriminator,
                value,
            },
        ) => encode_union(w, u, *discriminator, value.as_deref()),
        (TypeKind::Sequence { element, bound }, Value::Sequence(items)) => {
            if bound.is_some_and(|b| items.len() > b as usize) {
                return Err(EncodeError::BoundExceeded {
                    what: "sequence",
                    bound: bound.unwrap_or(0) as usize,
                    len: items.len(),
                });
            }
            delimited(w, !layout(element).is_primitive(), |w| {
                w.write_len(items.len(), "sequence length")?;
                items.iter().try_for_each(|x| encode(w, element, x))
            })
        }
        (TypeKind::Array { .. }, Value::Array(_)) => {
            delimited(w, layout(ty) == Layout::DelimitedArray, |w| {
                encode_flat(w, ty, v)
            })
        }
        (TypeKind::Map { key, value, bound }, Value::Map(entries)) => {
            if bound.is_some_and(|b| entries.len() > b as usize) {
                return Err(EncodeError::BoundExceeded {
                    what: "map",
                    bound: bound.unwrap_or(0) as usize,
                    len: entries.len(),
                });
            }
            let d = layout(ty) == Layout::Delimited && w.is_xcdr2();
            w.enter()?;
            let slot = d.then(|| w.begin_length());
            w.write_len(entries.len(), "map length")?;
            for (k, x) in entries {
                encode(w, key, k)?;
                encode(w, value, x)?;
            }
            w.leave();
            slot.map_or(Ok(()), |s| w.end_length(s))
        }
        _ => Err(mismatch("a value of another type")),
    }
}

/// In XCDR2 with `dheader`: a nesting level and a DHEADER around `body`.
fn delimited(
    w: &mut CdrWriter<'_>,
    dheader: bool,
    body: impl FnOnce(&mut CdrWriter<'_>) -> Result<(), EncodeError>,
) -> Result<(), EncodeError> {
    if dheader && w.is_xcdr2() {
        w.enter()?;
        let slot = w.begin_length();
        body(w)?;
        w.leave();
        w.end_length(slot)
    } else {
        body(w)
    }
}

/// An array's elements without its own DHEADER (inner dimensions of an array of arrays too).
fn encode_flat(w: &mut CdrWriter<'_>, ty: &DynamicType, v: &Value) -> Result<(), EncodeError> {
    let (TypeKind::Array { element, dims }, Value::Array(items)) = (ty.resolved().kind(), v) else {
        return encode(w, ty, v);
    };
    let n: usize = dims.iter().map(|d| *d as usize).product();
    if items.len() != n {
        return Err(EncodeError::InvalidValue {
            what: "array length",
            value: items.len() as u64,
        });
    }
    let inner_array = matches!(element.resolved().kind(), TypeKind::Array { .. });
    for x in items {
        if inner_array {
            encode_flat(w, element, x)?;
        } else {
            encode(w, element, x)?;
        }
    }
    Ok(())
}

fn write_sized(w: &mut CdrWriter<'_>, size: usize, v: u64) {
    match size {
        1 => w.write_u8(v as u8),
        2 => w.write_u16(v as u16),
        4 => w.write_u32(v as u32),
        _ => w.write_u64(v),
    }
}

fn encode_primitive(w: &mut CdrWriter<'_>, p: Primitive, v: &Value) -> Result<(), EncodeError> {
    match (p, v) {
        (Primitive::Bool, Value::Bool(b)) => w.write_u8(u8::from(*b)),
        (Primitive::Byte, Value::Byte(x))
        | (Primitive::UInt8, Value::UInt8(x))
        | (Primitive::Char8, Value::Char8(x)) => w.write_u8(*x),
        (Primitive::Int8, Value::Int8(x)) => w.write_u8(*x as u8),
        (Primitive::Int16, Value::Int16(x)) => w.write_u16(*x as u16),
        (Primitive::UInt16, Value::UInt16(x)) | (Primitive::Char16, Value::Char16(x)) => {
            w.write_u16(*x)
        }
        (Primitive::Int32, Value::Int32(x)) => w.write_u32(*x as u32),
        (Primitive::UInt32, Value::UInt32(x)) => w.write_u32(*x),
        (Primitive::Int64, Value::Int64(x)) => w.write_u64(*x as u64),
        (Primitive::UInt64, Value::UInt64(x)) => w.write_u64(*x),
        (Primitive::Float32, Value::Float32(x)) => w.write_u32(x.to_bits()),
        (Primitive::Float64, Value::Float64(x)) => w.write_u64(x.to_bits()),
        (Primitive::Float128, Value::Float128(b)) => {
            w.align(8);
            let mut b = *b;
            if w.order() == ByteOrder::LittleEndian {
                b.reverse();
            }
            w.write_bytes(&b);
        }
        _ => return Err(mismatch("a primitive of another kind")),
    }
    Ok(())
}

/// The extensibility a struct or union is framed with: the key-hash stream is always plain.
fn framing(w: &CdrWriter<'_>, ext: Extensibility) -> Extensibility {
    if w.mode() == EncodeMode::KeyHash {
        Extensibility::Final
    } else {
        ext
    }
}

fn encode_struct(
    w: &mut CdrWriter<'_>,
    s: &StructType,
    vals: &[Option<Value>],
) -> Result<(), EncodeError> {
    if vals.len() != s.members.len() {
        return Err(mismatch("struct member count"));
    }
    let ext = framing(w, s.extensibility);
    let st = begin_encode(w, ext)?;
    let keys_only = w.key_only() && s.has_keys();
    let order: Vec<usize> = if w.mode() == EncodeMode::KeyHash {
        s.by_id()
    } else {
        (0..s.members.len()).collect()
    };
    for i in order {
        let m = &s.members[i];
        if keys_only && !m.key {
            continue;
        }
        encode_member(w, ext, m, vals[i].as_ref())?;
    }
    end_encode(w, st)
}

/// One struct member: optional framing, member header of mutable types.
fn encode_member(
    w: &mut CdrWriter<'_>,
    ext: Extensibility,
    m: &Member,
    v: Option<&Value>,
) -> Result<(), EncodeError> {
    if !m.optional {
        let v = v.ok_or_else(|| mismatch("a non-optional member without a value"))?;
        return with_header(w, ext, m.id, m.must_understand, &m.ty, v);
    }
    if ext == Extensibility::Mutable {
        return match v {
            Some(v) => with_header(w, ext, m.id, m.must_understand, &m.ty, v),
            None => Ok(()),
        };
    }
    if w.is_xcdr2() {
        w.write_u8(u8::from(v.is_some()));
        v.map_or(Ok(()), |v| encode(w, &m.ty, v))
    } else {
        let p = w.begin_param(m.id, m.must_understand)?;
        if let Some(v) = v {
            encode(w, &m.ty, v)?;
        }
        w.end_param(p)
    }
}

/// A value with the EMHEADER or parameter header of a mutable aggregate (nothing otherwise).
fn with_header(
    w: &mut CdrWriter<'_>,
    ext: Extensibility,
    id: u32,
    must_understand: bool,
    ty: &DynamicType,
    v: &Value,
) -> Result<(), EncodeError> {
    if ext != Extensibility::Mutable {
        return encode(w, ty, v);
    }
    if w.is_xcdr2() {
        let slot = w.write_emheader(id, must_understand, layout(ty).length_code())?;
        encode(w, ty, v)?;
        slot.map_or(Ok(()), |s| w.end_length(s))
    } else {
        let p = w.begin_param(id, must_understand)?;
        encode(w, ty, v)?;
        w.end_param(p)
    }
}

fn encode_disc(w: &mut CdrWriter<'_>, ty: &DynamicType, raw: i64) -> Result<(), EncodeError> {
    match ty.resolved().kind() {
        TypeKind::Enum(e) => write_sized(w, e.size(), raw as u64),
        TypeKind::Primitive(p) if p.size() <= 8 => write_sized(w, p.size(), raw as u64),
        _ => return Err(mismatch("a union discriminator type")),
    }
    Ok(())
}

fn encode_union(
    w: &mut CdrWriter<'_>,
    u: &UnionType,
    disc: i64,
    value: Option<&Value>,
) -> Result<(), EncodeError> {
    let ext = framing(w, u.extensibility);
    let st = begin_encode(w, ext)?;
    if ext == Extensibility::Mutable {
        if w.is_xcdr2() {
            let slot = w.write_emheader(0, true, layout(&u.discriminator).length_code())?;
            encode_disc(w, &u.discriminator, disc)?;
            if let Some(s) = slot {
                w.end_length(s)?;
            }
        } else {
            let p = w.begin_param(0, true)?;
            encode_disc(w, &u.discriminator, disc)?;
            w.end_param(p)?;
        }
    } else {
        encode_disc(w, &u.discriminator, disc)?;
    }
    match (u.case_for(disc), value) {
        (Some(i), Some(v)) => {
            let c = &u.cases[i];
            with_header(w, ext, c.id, false, &c.ty, v)?;
        }
        (None, None) => {}
        _ => return Err(mismatch("a union value for another case")),
    }
    end_encode(w, st)
}
