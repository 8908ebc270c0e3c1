//! Shared sample types covering every IDL type family, in the three extensibilities, with proptest strategies.
//! Included by the round-trip and hostile-input tests.

#![allow(dead_code)]

use std::collections::BTreeMap;

use dds_runtime::cdr::{LongDouble, WChar, WString};
use dds_runtime::DdsType;
use proptest::prelude::*;

#[derive(DdsType, Debug, PartialEq, Clone, Copy)]
#[dds(name = "Fam::Color")]
pub(crate) enum Color {
    Red,
    Green = 5,
    Blue,
}

#[derive(DdsType, Debug, PartialEq, Clone, Copy)]
#[dds(bit_bound = 8)]
pub(crate) enum Small {
    A,
    B,
    C,
}

#[derive(DdsType, Debug, PartialEq, Clone, Copy)]
#[dds(bit_bound = 16)]
pub(crate) enum Medium {
    X,
    Y,
}

bitflags::bitflags! {
    #[derive(DdsType, Debug, PartialEq, Eq, Clone, Copy)]
    #[dds(bitmask, bit_bound = 12)]
    pub(crate) struct Flags: u16 {
        const A = 1;
        const B = 1 << 11;
    }
}

bitflags::bitflags! {
    #[derive(DdsType, Debug, PartialEq, Eq, Clone, Copy)]
    #[dds(bitmask, bit_bound = 64)]
    pub(crate) struct WideFlags: u64 {
        const HIGH = 1 << 63;
        const LOW = 1;
    }
}

/// A bitset's storage: a transparent newtype.
#[derive(DdsType, Debug, PartialEq, Clone, Copy)]
#[dds(transparent)]
pub(crate) struct Bits(pub u32);

#[derive(DdsType, Debug, PartialEq, Clone)]
#[dds(transparent)]
pub(crate) struct Name(#[dds(bound = 16)] pub String);

#[derive(DdsType, Debug, PartialEq, Clone)]
#[dds(discriminator = Color)]
pub(crate) enum Choice {
    #[dds(case = Color::Red)]
    Int(i32),
    #[dds(case = Color::Green)]
    Text(String),
    #[dds(default)]
    Other(Vec<u16>),
}

#[derive(DdsType, Debug, PartialEq, Clone)]
#[dds(final, discriminator = i16)]
pub(crate) enum Tagged {
    #[dds(case = -3)]
    Neg(f64),
    #[dds(case = 7)]
    Empty,
    // Not `default`: a unit variant beside a default case with a member has no type object (refused); -1 is
    // the label the derive wrote for it as the default, so the bytes stay those of the regressions.
    #[dds(case = -1)]
    Rest(u8),
}

#[derive(DdsType, Debug, PartialEq, Clone)]
#[dds(mutable)]
pub(crate) struct InnerM {
    pub(crate) a: u8,
    pub(crate) b: Option<String>,
    pub(crate) c: [u64; 2],
}

#[derive(DdsType, Debug, PartialEq, Clone)]
#[dds(appendable)]
pub(crate) struct InnerA {
    pub(crate) x: i64,
    pub(crate) y: Vec<InnerM>,
}

#[derive(DdsType, Debug, PartialEq, Clone)]
#[dds(final)]
pub(crate) struct InnerF {
    pub(crate) p: u8,
    pub(crate) q: f64,
}

macro_rules! family {
    ($name:ident, $ext:literal) => {
        #[derive(DdsType, Debug, PartialEq, Clone)]
        #[dds(extensibility = $ext)]
        pub(crate) struct $name {
            #[dds(key)]
            pub(crate) id: u32,
            pub(crate) b: bool,
            pub(crate) o: u8,
            pub(crate) i8_: i8,
            pub(crate) c: char,
            pub(crate) wc: WChar,
            pub(crate) s16: i16,
            pub(crate) u16_: u16,
            pub(crate) s32: i32,
            pub(crate) u32_: u32,
            pub(crate) s64: i64,
            pub(crate) u64_: u64,
            pub(crate) f: f32,
            pub(crate) d: f64,
            pub(crate) ld: LongDouble,
            pub(crate) s: String,
            #[dds(bound = 8)]
            pub(crate) bs: String,
            pub(crate) ws: WString,
            pub(crate) vu: Vec<u16>,
            pub(crate) vb: Vec<bool>,
            pub(crate) vf: Vec<f64>,
            pub(crate) vs: Vec<String>,
            pub(crate) vv: Vec<Vec<i64>>,
            pub(crate) arr: [[i16; 2]; 3],
            pub(crate) sarr: [String; 2],
            pub(crate) map: BTreeMap<i32, String>,
            pub(crate) e: Color,
            pub(crate) e8: Small,
            pub(crate) e16: Medium,
            pub(crate) ve: Vec<Small>,
            pub(crate) fl: Flags,
            pub(crate) wf: WideFlags,
            pub(crate) bits: Bits,
            pub(crate) name: Name,
            pub(crate) u: Choice,
            pub(crate) t: Tagged,
            pub(crate) opt: Option<i64>,
            pub(crate) optv: Option<Vec<u8>>,
            pub(crate) ia: InnerA,
            pub(crate) im: InnerM,
            pub(crate) fi: [InnerF; 2],
            #[dds(external)]
            pub(crate) ext: Box<InnerF>,
        }
    };
}

family!(FamFinal, "final");
family!(FamAppendable, "appendable");
family!(FamMutable, "mutable");

pub(crate) fn latin1() -> impl Strategy<Value = char> {
    (0u8..=255).prop_map(char::from)
}

pub(crate) fn text() -> impl Strategy<Value = String> {
    "[a-zA-Z0-9 éß€]{0,12}"
}

pub(crate) fn finite64() -> impl Strategy<Value = f64> {
    any::<f64>().prop_filter("finite", |v| v.is_finite())
}

pub(crate) fn inner_m() -> impl Strategy<Value = InnerM> {
    (any::<u8>(), proptest::option::of(text()), any::<[u64; 2]>()).prop_map(|(a, b, c)| InnerM {
        a,
        b,
        c,
    })
}

pub(crate) fn inner_a() -> impl Strategy<Value = InnerA> {
    (any::<i64>(), proptest::collection::vec(inner_m(), 0..3)).prop_map(|(x, y)| InnerA { x, y })
}

pub(crate) fn inner_f() -> impl Strategy<Value = InnerF> {
    (any::<u8>(), finite64()).prop_map(|(p, q)| InnerF { p, q })
}

pub(crate) fn color() -> impl Strategy<Value = Color> {
    prop_oneof![Just(Color::Red), Just(Color::Green), Just(Color::Blue)]
}

pub(crate) fn choice() -> impl Strategy<Value = Choice> {
    prop_oneof![
        any::<i32>().prop_map(Choice::Int),
        text().prop_map(Choice::Text),
        proptest::collection::vec(any::<u16>(), 0..4).prop_map(Choice::Other),
    ]
}

pub(crate) fn tagged() -> impl Strategy<Value = Tagged> {
    prop_oneof![
        finite64().prop_map(Tagged::Neg),
        Just(Tagged::Empty),
        any::<u8>().prop_map(Tagged::Rest)
    ]
}

/// Everything but the id, as one tuple per group (proptest tuples stop at 12).
macro_rules! family_strategy {
    ($fn:ident, $name:ident) => {
        pub(crate) fn $fn() -> impl Strategy<Value = $name> {
            let prims = (
                any::<u32>(),
                any::<bool>(),
                any::<u8>(),
                any::<i8>(),
                latin1(),
                any::<u16>(),
                any::<i16>(),
                any::<u16>(),
                any::<i32>(),
                any::<u32>(),
                any::<i64>(),
                any::<u64>(),
            );
            let more = (
                any::<f32>().prop_filter("finite", |v| v.is_finite()),
                finite64(),
                any::<[u8; 16]>(),
                text(),
                "[a-z]{0,8}",
                text(),
                proptest::collection::vec(any::<u16>(), 0..5),
                proptest::collection::vec(any::<bool>(), 0..5),
                proptest::collection::vec(finite64(), 0..3),
                proptest::collection::vec(text(), 0..3),
                proptest::collection::vec(proptest::collection::vec(any::<i64>(), 0..3), 0..3),
                any::<[[i16; 2]; 3]>(),
            );
            let rest = (
                (text(), text()),
                proptest::collection::btree_map(any::<i32>(), text(), 0..3),
                color(),
                prop_oneof![Just(Small::A), Just(Small::B), Just(Small::C)],
                prop_oneof![Just(Medium::X), Just(Medium::Y)],
                proptest::collection::vec(prop_oneof![Just(Small::A), Just(Small::C)], 0..4),
                (any::<u16>(), any::<u64>(), any::<u32>(), "[a-z]{0,16}"),
                choice(),
                tagged(),
                (
                    proptest::option::of(any::<i64>()),
                    proptest::option::of(proptest::collection::vec(any::<u8>(), 0..4)),
                ),
                (inner_a(), inner_m(), inner_f(), inner_f(), inner_f()),
            );
            (prims, more, rest).prop_map(|(p, m, r)| $name {
                id: p.0,
                b: p.1,
                o: p.2,
                i8_: p.3,
                c: p.4,
                wc: WChar(p.5),
                s16: p.6,
                u16_: p.7,
                s32: p.8,
                u32_: p.9,
                s64: p.10,
                u64_: p.11,
                f: m.0,
                d: m.1,
                ld: LongDouble(m.2),
                s: m.3,
                bs: m.4,
                ws: WString(m.5),
                vu: m.6,
                vb: m.7,
                vf: m.8,
                vs: m.9,
                vv: m.10,
                arr: m.11,
                sarr: [r.0 .0, r.0 .1],
                map: r.1,
                e: r.2,
                e8: r.3,
                e16: r.4,
                ve: r.5,
                fl: Flags::from_bits_retain(r.6 .0),
                wf: WideFlags::from_bits_retain(r.6 .1),
                bits: Bits(r.6 .2),
                name: Name(r.6 .3),
                u: r.7,
                t: r.8,
                opt: r.9 .0,
                optv: r.9 .1,
                ia: r.10 .0,
                im: r.10 .1,
                fi: [r.10 .2, r.10 .3],
                ext: Box::new(r.10 .4),
            })
        }
    };
}

family_strategy!(fam_final, FamFinal);
family_strategy!(fam_appendable, FamAppendable);
family_strategy!(fam_mutable, FamMutable);
