//! The `cdr_decode` check and the types it decodes (shared with the seed generator).
//!
//! Arbitrary bytes go to `dds_runtime::cdr::deserialize` for each type below; when a decode succeeds, the value
//! must re-encode (in the input's version and byte order, and in the other version) and decode again to the
//! same value and the same bytes.

use std::collections::BTreeMap;

use dds_runtime::cdr::{self, ByteOrder, DdsType, EncapsulationHeader, XcdrVersion};
use dds_runtime::DdsType;

/// ShapeType of the OMG interoperability suite (idl/shapes.idl).
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(appendable, name = "ShapeType")]
pub struct ShapeType {
    #[dds(key, bound = 128)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
    pub additional_payload_size: Vec<u8>,
}

#[derive(DdsType, Debug, Clone, Copy, PartialEq, Default)]
#[dds(name = "Fuzz::Kind")]
pub enum Kind {
    #[default]
    Alpha,
    Beta = 4,
    Gamma,
}

/// A union over an enum discriminator, with a multi-label case, a unit case and a default.
#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(discriminator = Kind, name = "Fuzz::Either")]
pub enum Either {
    #[dds(case = Kind::Alpha)]
    Num(i64),
    #[dds(case = Kind::Beta)]
    Text(#[dds(bound = 32)] String),
    #[dds(default)]
    Bytes(Vec<u8>),
}

/// A union over an integer discriminator with an empty case. `Other` has the label the derive wrote when it
/// was the default case (-2, the first unused), so the committed seeds keep their bytes: a unit variant beside
/// a default case with a member has no type object that fits, and the derive refuses it (fuzz/FINDINGS.md).
#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(final, discriminator = i16, name = "Fuzz::Small")]
pub enum SmallUnion {
    #[dds(case = -1)]
    Neg(u16),
    #[dds(case = 9, case = 10)]
    Nothing,
    #[dds(case = -2)]
    Other(bool),
}

/// A mutable struct with optionals, explicit ids and a must-understand member. Unannotated ids follow the
/// previous member's (d = 8, e = 9, ...), so the explicit ones must stay clear of them.
#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "Fuzz::Mut")]
pub struct MutOpt {
    #[dds(key, id = 100)]
    pub id: u32,
    #[dds(id = 3)]
    pub a: Option<i16>,
    #[dds(id = 0x0fff_0000)]
    pub b: Option<String>,
    #[dds(id = 7, must_understand)]
    pub c: u64,
    pub d: Option<Vec<u8>>,
    pub e: Option<Either>,
    pub f: Kind,
    pub g: [u8; 3],
    pub h: Option<Inner>,
}

/// An appendable member struct.
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(appendable, nested, name = "Fuzz::Inner")]
pub struct Inner {
    pub n: i32,
    pub tags: Vec<String>,
}

/// Nested sequences and maps (final, so XCDR1 has no headers at all).
#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(final, name = "Fuzz::Nest")]
pub struct Nest {
    pub vv: Vec<Vec<i16>>,
    pub vs: Vec<Vec<String>>,
    pub m: BTreeMap<String, Vec<u32>>,
    pub mi: BTreeMap<i32, Inner>,
    #[dds(bound = 4)]
    pub bounded: Vec<Inner>,
    pub u: Vec<SmallUnion>,
    pub arr: [[i8; 2]; 2],
    pub ch: char,
    pub flag: bool,
}

/// A mutable wrapper around the other types, so that they also appear as members (EMHEADER length codes).
#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "Fuzz::Outer")]
pub struct Outer {
    pub shape: ShapeType,
    pub nest: Nest,
    pub m: Option<MutOpt>,
    pub u: Either,
    pub f: f64,
}

/// Decodes `payload` as `T`; on success re-encodes in the header's version and byte order and in the other
/// version, and checks that each re-encoding decodes back to the same value and re-encodes to the same bytes.
/// `eq` compares values (so types holding floats can compare bits instead of `==`).
pub fn round_trip<T: DdsType + std::fmt::Debug>(payload: &[u8], eq: impl Fn(&T, &T) -> bool) {
    let Ok(v) = cdr::deserialize::<T>(payload) else {
        return;
    };
    let h = EncapsulationHeader::parse(payload).expect("decode succeeded, so the header parsed");
    let version = h
        .version()
        .expect("decode succeeded, so the version is known");
    let other = match version {
        XcdrVersion::Xcdr1 => XcdrVersion::Xcdr2,
        XcdrVersion::Xcdr2 => XcdrVersion::Xcdr1,
    };
    for (ver, order) in [
        (version, h.byte_order()),
        (other, ByteOrder::LittleEndian),
        (other, ByteOrder::BigEndian),
    ] {
        let mut out = Vec::new();
        cdr::serialize(&v, ver, order, &mut out).unwrap_or_else(|e| {
            panic!("re-encode of a decoded value failed ({ver:?} {order:?}): {e}\n{v:?}")
        });
        let back = cdr::deserialize::<T>(&out).unwrap_or_else(|e| {
            panic!("decode of our own encoding failed ({ver:?} {order:?}): {e}\n{v:?}\n{out:02x?}")
        });
        assert!(
            eq(&v, &back),
            "value changed through {ver:?} {order:?}:\n{v:?}\n{back:?}"
        );
        let mut again = Vec::new();
        cdr::serialize(&back, ver, order, &mut again).expect("second re-encode");
        assert_eq!(out, again, "encoding not stable through {ver:?} {order:?}");
    }
    // The key-only paths must not panic on the value either.
    let mut k = Vec::new();
    if cdr::serialize_key(&v, version, h.byte_order(), &mut k).is_ok() {
        let _ = cdr::deserialize_key::<T>(&k);
    }
    let _ = cdr::key_hash(&v, version);
    let mut ik = Vec::new();
    let _ = cdr::instance_key(&v, &mut ik);
}

/// Compares two `Outer`s, floats by bit pattern (NaN payloads survive a round trip).
pub fn outer_eq(a: &Outer, b: &Outer) -> bool {
    a.f.to_bits() == b.f.to_bits()
        && a.shape == b.shape
        && a.nest == b.nest
        && a.m == b.m
        && a.u == b.u
}

/// The types `cdr_decode` exercises, selected by the first input byte (modulo the count).
pub const TYPE_COUNT: u8 = 6;

/// Runs one fuzz input: first byte selects the type, the rest is the payload (encapsulation header first).
pub fn cdr_one(data: &[u8]) {
    let Some((&sel, payload)) = data.split_first() else {
        return;
    };
    match sel % TYPE_COUNT {
        0 => round_trip::<ShapeType>(payload, PartialEq::eq),
        1 => round_trip::<MutOpt>(payload, PartialEq::eq),
        2 => round_trip::<Nest>(payload, PartialEq::eq),
        3 => round_trip::<Outer>(payload, outer_eq),
        4 => round_trip::<Either>(payload, PartialEq::eq),
        _ => {
            // Key-only decode straight from the input.
            let _ = cdr::deserialize_key::<ShapeType>(payload);
            let _ = cdr::deserialize_key::<MutOpt>(payload);
        }
    }
}
