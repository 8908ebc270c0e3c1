//! The benchmark types and samples, shared by `benches/cdr.rs` and the tests under `tests/`.
//!
//! Each type derives all three codecs at once — ours (`dds_runtime::DdsType`), Dust DDS
//! (`dust_dds::...::DdsType`) and serde (for `cdr-encoding`, the codec of RustDDS) — so every library encodes
//! exactly the same Rust value.

#![allow(dead_code)]

use dust_dds::infrastructure::type_support::DdsType as DustType;
use serde::{Deserialize, Serialize};

/// idl/shapes.idl.
#[derive(
    Debug, Clone, PartialEq, Default, dds_runtime::DdsType, DustType, Serialize, Deserialize,
)]
#[dds(appendable, name = "ShapeType")]
#[dust_dds(extensibility = "appendable", name = "ShapeType")]
pub struct ShapeType {
    #[dds(key, bound = 128)]
    #[dust_dds(key)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
    pub additional_payload_size: Vec<u8>,
}

/// ddsperf's `KeyedSeq` (idl/ddsperf_types.idl) carrying 1 KiB of `sequence<octet>`.
#[derive(
    Debug, Clone, PartialEq, Default, dds_runtime::DdsType, DustType, Serialize, Deserialize,
)]
#[dds(final, name = "KeyedSeq")]
#[dust_dds(extensibility = "final", name = "KeyedSeq")]
pub struct KeyedSeq {
    pub seq: u32,
    #[dds(key)]
    #[dust_dds(key)]
    pub keyval: u32,
    pub baggage: Vec<u8>,
}

/// One element of [`Telemetry::readings`]: a string and two sequences.
#[derive(
    Debug, Clone, PartialEq, Default, dds_runtime::DdsType, DustType, Serialize, Deserialize,
)]
#[dds(final, nested, name = "Bench::Reading")]
#[dust_dds(extensibility = "final", nested, name = "Bench::Reading")]
pub struct Reading {
    pub name: String,
    pub values: Vec<f64>,
    pub raw: Vec<i16>,
}

/// Strings and nested sequences: a sequence of structs that hold sequences, plus a sequence of strings.
#[derive(
    Debug, Clone, PartialEq, Default, dds_runtime::DdsType, DustType, Serialize, Deserialize,
)]
#[dds(final, name = "Bench::Telemetry")]
#[dust_dds(extensibility = "final", name = "Bench::Telemetry")]
pub struct Telemetry {
    #[dds(key)]
    #[dust_dds(key)]
    pub id: u64,
    pub source: String,
    pub readings: Vec<Reading>,
    pub labels: Vec<String>,
    pub counters: Vec<i32>,
}

/// A mutable type with 34 members of mixed kinds (explicit, identical member ids in both derives). The ids start
/// at 11: Dust DDS 0.15 ends a parameter list at a member with id 1 (it checks for the RTPS PID_SENTINEL, 1, in
/// XCDR1 and XCDR2 alike) and then cannot decode its own output, which would leave nothing to compare.
#[derive(
    Debug, Clone, PartialEq, Default, dds_runtime::DdsType, DustType, Serialize, Deserialize,
)]
#[dds(mutable, name = "Bench::Wide")]
#[dust_dds(extensibility = "mutable", name = "Bench::Wide")]
pub struct Wide {
    #[dds(key, id = 11)]
    #[dust_dds(key, id = 11)]
    pub id: u32,
    #[dds(id = 12)]
    #[dust_dds(id = 12)]
    pub seq: u64,
    #[dds(id = 13)]
    #[dust_dds(id = 13)]
    pub timestamp: i64,
    #[dds(id = 14)]
    #[dust_dds(id = 14)]
    pub level: i16,
    #[dds(id = 15)]
    #[dust_dds(id = 15)]
    pub flags: u16,
    #[dds(id = 16)]
    #[dust_dds(id = 16)]
    pub min: i32,
    #[dds(id = 17)]
    #[dust_dds(id = 17)]
    pub status: u32,
    #[dds(id = 18)]
    #[dust_dds(id = 18)]
    pub gain: f32,
    #[dds(id = 19)]
    #[dust_dds(id = 19)]
    pub scale: f64,
    #[dds(id = 20)]
    #[dust_dds(id = 20)]
    pub enabled: bool,
    #[dds(id = 21)]
    #[dust_dds(id = 21)]
    pub priority: u8,
    #[dds(id = 22)]
    #[dust_dds(id = 22)]
    pub offset: i8,
    #[dds(id = 23)]
    #[dust_dds(id = 23)]
    pub name: String,
    #[dds(id = 24)]
    #[dust_dds(id = 24)]
    pub description: String,
    #[dds(id = 25)]
    #[dust_dds(id = 25)]
    pub unit: String,
    #[dds(id = 26)]
    #[dust_dds(id = 26)]
    pub blob: Vec<u8>,
    #[dds(id = 27)]
    #[dust_dds(id = 27)]
    pub histogram: Vec<i32>,
    #[dds(id = 28)]
    #[dust_dds(id = 28)]
    pub series: Vec<f64>,
    #[dds(id = 29)]
    #[dust_dds(id = 29)]
    pub tags: Vec<String>,
    #[dds(id = 30)]
    #[dust_dds(id = 30)]
    pub x: f64,
    #[dds(id = 31)]
    #[dust_dds(id = 31)]
    pub y: f64,
    #[dds(id = 32)]
    #[dust_dds(id = 32)]
    pub z: f64,
    #[dds(id = 33)]
    #[dust_dds(id = 33)]
    pub roll: f32,
    #[dds(id = 34)]
    #[dust_dds(id = 34)]
    pub pitch: f32,
    #[dds(id = 35)]
    #[dust_dds(id = 35)]
    pub yaw: f32,
    #[dds(id = 36)]
    #[dust_dds(id = 36)]
    pub errors: u32,
    #[dds(id = 37)]
    #[dust_dds(id = 37)]
    pub mask: u16,
    #[dds(id = 38)]
    #[dust_dds(id = 38)]
    pub delta: i16,
    #[dds(id = 39)]
    #[dust_dds(id = 39)]
    pub count: u64,
    #[dds(id = 40)]
    #[dust_dds(id = 40)]
    pub low: i32,
    #[dds(id = 41)]
    #[dust_dds(id = 41)]
    pub high: i32,
    #[dds(id = 42)]
    #[dust_dds(id = 42)]
    pub ok: bool,
    #[dds(id = 43)]
    #[dust_dds(id = 43)]
    pub note: String,
    #[dds(id = 44)]
    #[dust_dds(id = 44)]
    pub extra: Vec<u16>,
}

pub fn shape() -> ShapeType {
    ShapeType {
        color: "BLUE".into(),
        x: 120,
        y: 75,
        shapesize: 30,
        additional_payload_size: vec![0xa5; 16],
    }
}

pub fn keyed_seq_1k() -> KeyedSeq {
    KeyedSeq {
        seq: 12345,
        keyval: 7,
        baggage: (0..1024u32).map(|i| i as u8).collect(),
    }
}

pub fn telemetry() -> Telemetry {
    Telemetry {
        id: 0x1122_3344_5566_7788,
        source: "vehicle-17/imu".into(),
        readings: (0..8)
            .map(|i| Reading {
                name: format!("channel-{i}"),
                values: (0..16).map(|j| (i * 16 + j) as f64 * 0.25).collect(),
                raw: (0..12).map(|j| (i * 12 + j) as i16 - 40).collect(),
            })
            .collect(),
        labels: ["alpha", "bravo", "charlie", "delta", "echo"]
            .iter()
            .map(|s| s.to_string())
            .collect(),
        counters: (0..32).collect(),
    }
}

pub fn wide() -> Wide {
    Wide {
        id: 99,
        seq: 1 << 40,
        timestamp: -1_700_000_000_000,
        level: -3,
        flags: 0x0f0f,
        min: -100,
        status: 3,
        gain: 1.5,
        scale: 0.001,
        enabled: true,
        priority: 9,
        offset: -7,
        name: "pressure-sensor".into(),
        description: "combined pressure and temperature probe, rack 4".into(),
        unit: "kPa".into(),
        blob: vec![0x5a; 64],
        histogram: (0..16).collect(),
        series: (0..16).map(|i| i as f64 / 3.0).collect(),
        tags: vec!["rack4".into(), "calibrated".into(), "v2".into()],
        x: 1.0,
        y: -2.0,
        z: 3.5,
        roll: 0.1,
        pitch: 0.2,
        yaw: 0.3,
        errors: 0,
        mask: 0xffff,
        delta: 12,
        count: 1_000_000,
        low: -5,
        high: 5,
        ok: true,
        note: "ok".into(),
        extra: vec![1, 2, 3, 4, 5],
    }
}
