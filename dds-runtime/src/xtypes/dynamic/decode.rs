//! XCDR1/XCDR2 decoding into a [`Value`] by its [`DynamicType`]: bounded (lengths are checked against the bytes
//! left before anything is allocated, nesting is limited), and hostile bytes are an error, never a panic.

use std::collections::hash_map::{Entry, HashMap};

use crate::cdr::members::{begin_decode, end_member, skip_member};
use crate::cdr::{
    ByteOrder, CdrReader, CdrType, DecodeError, DecodeErrorKind, Extensibility, Layout, WString,
};

use super::layout::layout;
use super::types::{DynamicType, Primitive, StructType, TypeKind, UnionType};
use super::value::Value;

fn invalid(r: &CdrReader<'_>, expected: &'static str, found: u64) -> DecodeError {
    r.error(expected, DecodeErrorKind::InvalidValue { found })
}

/// Lower bound of a value's encoded size (at least 1): hostile counts fail before allocating.
fn min_size(ty: &DynamicType) -> usize {
    match ty.resolved().kind() {
        TypeKind::Primitive(p) => p.size(),
        TypeKind::String { .. } | TypeKind::Sequence { .. } | TypeKind::Map { .. } => 4,
        TypeKind::Enum(e) => e.size(),
        TypeKind::Bitmask(b) => b.size(),
        TypeKind::Array { element, dims } => dims
            .iter()
            .fold(min_size(element), |a, d| a.saturating_mul(*d as usize))
            .max(1),
        _ => 1,
    }
}

/// Decodes one value of type `ty`.
pub(super) fn decode(r: &mut CdrReader<'_>, ty: &DynamicType) -> Result<Value, DecodeError> {
    match ty.resolved().kind() {
        TypeKind::Primitive(p) => decode_primitive(r, *p),
        TypeKind::String { wide: false, bound } => {
            crate::cdr::decode_str(r, bound.map_or(usize::MAX, |b| b as usize)).map(Value::String)
        }
        TypeKind::String { wide: true, bound } => {
            WString::decode_bounded(r, bound.map_or(usize::MAX, |b| b as usize))
                .map(|s| Value::String(s.0))
        }
        TypeKind::Enum(e) => {
            let raw = read_sized(r, e.size(), "enum")?;
            let mask = if e.size() >= 4 {
                u64::from(u32::MAX)
            } else {
                (1u64 << (8 * e.size())) - 1
            };
            e.literals
                .iter()
                .find(|l| u64::from(l.value as u32) & mask == raw)
                .map(|l| Value::Enum(l.value))
                .ok_or_else(|| invalid(r, "an enumerator", raw))
        }
        TypeKind::Bitmask(b) => Ok(Value::Bitmask(read_sized(r, b.size(), "bitmask")?)),
        TypeKind::Struct(s) => decode_struct(r, s),
        TypeKind::Union(u) => decode_union(r, u),
        TypeKind::Sequence { element, bound } => {
            let dheader = !layout(element).is_primitive() && r.is_xcdr2();
            delimited(r, dheader, "sequence", |r| {
                let n = read_count(r, min_size(element), *bound, "sequence length")?;
                let mut items = Vec::with_capacity(n.min(r.remaining()));
                for _ in 0..n {
                    items.push(decode(r, element)?);
                }
                Ok(Value::Sequence(items))
            })
        }
        TypeKind::Array { .. } => {
            let dheader = layout(ty) == Layout::DelimitedArray && r.is_xcdr2();
            delimited(r, dheader, "array", |r| decode_flat(r, ty))
        }
        TypeKind::Map { key, value, bound } => {
            let dheader = layout(ty) == Layout::Delimited && r.is_xcdr2();
            r.enter("map")?;
            let limit = if dheader {
                let len = r.read_u32("map DHEADER")? as usize;
                Some(r.begin_limit(len, "map DHEADER")?)
            } else {
                None
            };
            let n = read_count(r, min_size(key) + min_size(value), *bound, "map length")?;
            let mut entries: Vec<(Value, Value)> = Vec::with_capacity(n.min(r.remaining()));
            // A key that comes again replaces the earlier entry's value (the later wins, as in a map and in
            // the derived code's `BTreeMap`); the first position is kept.
            let mut index: HashMap<String, usize> = HashMap::new();
            for _ in 0..n {
                let k = decode(r, key)?;
                let v = decode(r, value)?;
                match index.entry(format!("{k:?}")) {
                    Entry::Occupied(e) => entries[*e.get()].1 = v,
                    Entry::Vacant(e) => {
                        e.insert(entries.len());
                        entries.push((k, v));
                    }
                }
            }
            if let Some(l) = limit {
                r.end_limit(l);
            }
            r.leave();
            Ok(Value::Map(entries))
        }
        TypeKind::Alias { .. } | TypeKind::Forward(_) => Err(invalid(r, "a resolved type", 0)),
    }
}

/// An element count that the bytes left can hold (`min` bytes each at least) and within the IDL `bound`.
fn read_count(
    r: &mut CdrReader<'_>,
    min: usize,
    bound: Option<u32>,
    what: &'static str,
) -> Result<usize, DecodeError> {
    let at = r.offset();
    let n = r.read_count(min, what)?;
    match bound {
        Some(b) if n > b as usize => Err(DecodeError::new(
            at,
            "a length within its bound",
            DecodeErrorKind::BoundExceeded {
                bound: b as usize,
                len: n,
            },
        )),
        _ => Ok(n),
    }
}

/// In XCDR2 with `dheader`: a nesting level and a DHEADER-limited body.
fn delimited(
    r: &mut CdrReader<'_>,
    dheader: bool,
    what: &'static str,
    body: impl FnOnce(&mut CdrReader<'_>) -> Result<Value, DecodeError>,
) -> Result<Value, DecodeError> {
    if !dheader {
        return body(r);
    }
    r.enter(what)?;
    let len = r.read_u32("DHEADER")? as usize;
    let l = r.begin_limit(len, "DHEADER")?;
    let v = body(r)?;
    r.end_limit(l);
    r.leave();
    Ok(v)
}

/// An array's elements, every dimension, without a DHEADER of its own.
fn decode_flat(r: &mut CdrReader<'_>, ty: &DynamicType) -> Result<Value, DecodeError> {
    let TypeKind::Array { element, dims } = ty.resolved().kind() else {
        return decode(r, ty);
    };
    let n = dims
        .iter()
        .try_fold(1usize, |a, d| a.checked_mul(*d as usize))
        .filter(|n| n.saturating_mul(min_size(element)) <= r.remaining())
        .ok_or_else(|| {
            r.error(
                "array elements",
                DecodeErrorKind::LengthTooLarge {
                    length: u64::from(dims[0]),
                    remaining: r.remaining(),
                },
            )
        })?;
    let inner_array = matches!(element.resolved().kind(), TypeKind::Array { .. });
    let mut items = Vec::with_capacity(n);
    for _ in 0..n {
        items.push(if inner_array {
            decode_flat(r, element)?
        } else {
            decode(r, element)?
        });
    }
    Ok(Value::Array(items))
}

fn read_sized(r: &mut CdrReader<'_>, size: usize, what: &'static str) -> Result<u64, DecodeError> {
    Ok(match size {
        1 => u64::from(r.read_u8(what)?),
        2 => u64::from(r.read_u16(what)?),
        4 => u64::from(r.read_u32(what)?),
        _ => r.read_u64(what)?,
    })
}

fn decode_primitive(r: &mut CdrReader<'_>, p: Primitive) -> Result<Value, DecodeError> {
    Ok(match p {
        Primitive::Bool => match r.read_u8("boolean")? {
            0 => Value::Bool(false),
            1 => Value::Bool(true),
            b => return Err(invalid(r, "boolean (0 or 1)", u64::from(b))),
        },
        Primitive::Byte => Value::Byte(r.read_u8("octet")?),
        Primitive::UInt8 => Value::UInt8(r.read_u8("uint8")?),
        Primitive::Char8 => Value::Char8(r.read_u8("char")?),
        Primitive::Int8 => Value::Int8(r.read_u8("int8")? as i8),
        Primitive::Int16 => Value::Int16(r.read_u16("short")? as i16),
        Primitive::UInt16 => Value::UInt16(r.read_u16("unsigned short")?),
        Primitive::Char16 => Value::Char16(r.read_u16("wchar")?),
        Primitive::Int32 => Value::Int32(r.read_u32("long")? as i32),
        Primitive::UInt32 => Value::UInt32(r.read_u32("unsigned long")?),
        Primitive::Int64 => Value::Int64(r.read_u64("long long")? as i64),
        Primitive::UInt64 => Value::UInt64(r.read_u64("unsigned long long")?),
        Primitive::Float32 => Value::Float32(f32::from_bits(r.read_u32("float")?)),
        Primitive::Float64 => Value::Float64(f64::from_bits(r.read_u64("double")?)),
        Primitive::Float128 => {
            r.align(8, "long double")?;
            let mut b = [0u8; 16];
            b.copy_from_slice(r.read_bytes(16, "long double")?);
            if r.order() == ByteOrder::LittleEndian {
                b.reverse();
            }
            Value::Float128(b)
        }
    })
}

fn decode_struct(r: &mut CdrReader<'_>, s: &StructType) -> Result<Value, DecodeError> {
    let mut st = begin_decode(r, s.extensibility)?;
    let mut vals: Vec<Option<Value>> = vec![None; s.members.len()];
    if s.extensibility == Extensibility::Mutable {
        while let Some(h) = st.next_member(r)? {
            match s.index_of_id(h.id) {
                Some(i) => {
                    vals[i] = Some(decode(r, &s.members[i].ty)?);
                    end_member(r, h);
                }
                None => skip_member(r, h)?,
            }
        }
    } else {
        let keys_only = r.key_only() && s.has_keys();
        for (i, m) in s.members.iter().enumerate() {
            if keys_only && !m.key {
                continue;
            }
            if !st.has_more(r) {
                break;
            }
            vals[i] = if m.optional {
                decode_optional(r, &m.ty)?
            } else {
                Some(decode(r, &m.ty)?)
            };
        }
    }
    st.end(r);
    for (m, v) in s.members.iter().zip(vals.iter_mut()) {
        if v.is_none() && !m.optional {
            *v = Some(Value::default_of(&m.ty));
        }
    }
    Ok(Value::Struct(vals))
}

/// An optional member of a final/appendable struct: a presence octet in XCDR2, a parameter in XCDR1.
fn decode_optional(r: &mut CdrReader<'_>, ty: &DynamicType) -> Result<Option<Value>, DecodeError> {
    if r.is_xcdr2() {
        return match r.read_u8("optional presence flag")? {
            0 => Ok(None),
            1 => decode(r, ty).map(Some),
            b => Err(invalid(r, "optional presence flag (0 or 1)", u64::from(b))),
        };
    }
    // XCDR1 has no DHEADER: a mutable "decoder" only reads the parameter header.
    let mut st = begin_decode(r, Extensibility::Mutable)?;
    let Some(h) = st.next_member(r)? else {
        return Err(invalid(r, "parameter header of an optional member", 0));
    };
    let v = if r.remaining() == 0 {
        None
    } else {
        Some(decode(r, ty)?)
    };
    end_member(r, h);
    st.end(r);
    Ok(v)
}

fn read_disc(r: &mut CdrReader<'_>, ty: &DynamicType) -> Result<i64, DecodeError> {
    Ok(match ty.resolved().kind() {
        TypeKind::Enum(e) if e.size() == 4 => i64::from(r.read_u32("discriminator")? as i32),
        TypeKind::Enum(e) => read_sized(r, e.size(), "discriminator")? as i64,
        TypeKind::Primitive(p) => {
            let raw = read_sized(r, p.size(), "discriminator")?;
            match p {
                Primitive::Int8 => i64::from(raw as u8 as i8),
                Primitive::Int16 => i64::from(raw as u16 as i16),
                Primitive::Int32 => i64::from(raw as u32 as i32),
                _ => raw as i64,
            }
        }
        _ => return Err(invalid(r, "a discriminator type", 0)),
    })
}

fn decode_union(r: &mut CdrReader<'_>, u: &UnionType) -> Result<Value, DecodeError> {
    let mutable = u.extensibility == Extensibility::Mutable;
    let mut st = begin_decode(r, u.extensibility)?;
    let disc = if mutable {
        let h = st
            .next_member(r)?
            .ok_or_else(|| invalid(r, "union discriminator", 0))?;
        let d = read_disc(r, &u.discriminator)?;
        end_member(r, h);
        d
    } else {
        read_disc(r, &u.discriminator)?
    };
    let i = u
        .case_for(disc)
        .ok_or_else(|| invalid(r, "a case label of the union", disc as u64))?;
    let ty = &u.cases[i].ty;
    let v = if mutable {
        let h = st
            .next_member(r)?
            .ok_or_else(|| invalid(r, "union member", 0))?;
        let v = decode(r, ty)?;
        end_member(r, h);
        v
    } else {
        decode(r, ty)?
    };
    st.end(r);
    Ok(Value::Union {
        discriminator: disc,
        value: Some(Box::new(v)),
    })
}
