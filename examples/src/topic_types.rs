//! The topic types the example programs exchange with other DDS implementations, declared with
//! `#[derive(DdsType)]` exactly as `idl/shapes.idl` and `idl/ddsperf_types.idl` declare them (type names
//! without a module, as the OMG suite and Cyclone's ddsperf register them).
//!
//! These stand in for the idlc-generated types until examples/build.rs generates them; the programs use
//! only the items re-exported here.

use dds_runtime::DdsType;

/// The OMG interoperability suite's ShapeType: `color` is the key.
#[derive(Debug, Clone, PartialEq, Default, DdsType)]
#[dds(appendable, name = "ShapeType")]
pub struct ShapeType {
    #[dds(key, bound = 128)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
    pub additional_payload_size: Vec<u8>,
}

/// ddsperf `-T OU`.
#[derive(Debug, Clone, PartialEq, Default, DdsType)]
#[dds(final, name = "OneULong")]
pub struct OneULong {
    pub seq: u32,
}

/// ddsperf `-T KS` (the default): the payload size is set with `size`.
#[derive(Debug, Clone, PartialEq, Default, DdsType)]
#[dds(final, name = "KeyedSeq")]
pub struct KeyedSeq {
    pub seq: u32,
    #[dds(key)]
    pub keyval: u32,
    pub baggage: Vec<u8>,
}

/// ddsperf `-T K32`.
#[derive(Debug, Clone, PartialEq, Default, DdsType)]
#[dds(final, name = "Keyed32")]
pub struct Keyed32 {
    pub seq: u32,
    #[dds(key)]
    pub keyval: u32,
    pub baggage: [u8; 24],
}

/// ddsperf `-T K256`.
#[derive(Debug, Clone, PartialEq, DdsType)]
#[dds(final, name = "Keyed256")]
pub struct Keyed256 {
    pub seq: u32,
    #[dds(key)]
    pub keyval: u32,
    pub baggage: [u8; 248],
}

impl Default for Keyed256 {
    fn default() -> Self {
        Keyed256 { seq: 0, keyval: 0, baggage: [0; 248] }
    }
}

/// Building block of the `S*` topics.
#[derive(Debug, Clone, PartialEq, Default, DdsType)]
#[dds(final, name = "Struct16")]
pub struct Struct16 {
    pub struct0: u8,
    pub struct1: u8,
    pub struct2: u8,
    pub struct3: u8,
    pub struct4: u8,
    pub struct5: u8,
    pub struct6: u8,
    pub struct7: u8,
    pub struct8: u8,
    pub struct9: u8,
    pub structa: u8,
    pub structb: u8,
    pub structc: u8,
    pub structd: u8,
    pub structe: u8,
    pub structf: u8,
    pub junk: i64,
    pub seq: u32,
    #[dds(key)]
    pub keyval: u32,
}

/// ddsperf `-T S256`.
#[derive(Debug, Clone, PartialEq, Default, DdsType)]
#[dds(final, name = "Struct256")]
pub struct Struct256 {
    pub struct160: Struct16,
    pub struct161: Struct16,
    pub struct162: Struct16,
    pub struct163: Struct16,
    pub struct164: Struct16,
    pub struct165: Struct16,
    pub struct166: Struct16,
    pub struct167: Struct16,
    pub struct168: Struct16,
    pub struct169: Struct16,
    pub struct16a: Struct16,
    pub struct16b: Struct16,
    pub struct16c: Struct16,
    pub struct16d: Struct16,
    pub struct16e: Struct16,
    pub struct16f: Struct16,
    pub junk: i64,
    pub seq: u32,
    #[dds(key)]
    pub keyval: u32,
}

/// ddsperf `-T S4k`.
#[derive(Debug, Clone, PartialEq, Default, DdsType)]
#[dds(final, name = "Struct4k")]
pub struct Struct4k {
    pub struct2560: Struct256,
    pub struct2561: Struct256,
    pub struct2562: Struct256,
    pub struct2563: Struct256,
    pub struct2564: Struct256,
    pub struct2565: Struct256,
    pub struct2566: Struct256,
    pub struct2567: Struct256,
    pub struct2568: Struct256,
    pub struct2569: Struct256,
    pub struct256a: Struct256,
    pub struct256b: Struct256,
    pub struct256c: Struct256,
    pub struct256d: Struct256,
    pub struct256e: Struct256,
    pub struct256f: Struct256,
    pub junk: i64,
    pub seq: u32,
    #[dds(key)]
    pub keyval: u32,
}

/// ddsperf `-T S32k`.
#[derive(Debug, Clone, PartialEq, Default, DdsType)]
#[dds(final, name = "Struct32k")]
pub struct Struct32k {
    pub struct4k0: Struct4k,
    pub struct4k1: Struct4k,
    pub struct4k2: Struct4k,
    pub struct4k3: Struct4k,
    pub struct4k4: Struct4k,
    pub struct4k5: Struct4k,
    pub struct4k6: Struct4k,
    pub struct4k7: Struct4k,
    pub junk: i64,
    pub seq: u32,
    #[dds(key)]
    pub keyval: u32,
}
