//! Runs one codec operation in a loop, for profilers:
//! `cdr_loop TYPE OP LIB [ITERATIONS]` with TYPE shape|octets1k|nested|wide, OP encode|decode|into (ours:
//! `deserialize_into` a reused sample),
//! LIB ours1|ours2|serde (cdr-encoding, XCDR1)|dust1|dust2 (the same calls as `cdr.rs` makes). Example, instructions per operation with callgrind:
//! `valgrind --tool=callgrind --callgrind-out-file=cg.out target/bench-cdr/release/examples/cdr_loop shape decode ours1 10000`

mod common;

use std::hint::black_box;

use byteorder::LittleEndian;
use common::*;
use dds_runtime::cdr::{self, ByteOrder, DdsType, XcdrVersion};
use dust_dds::infrastructure::type_support::TypeSupport;
use dust_dds::xtypes::deserializer::CdrDeserializer;
use dust_dds::xtypes::serializer::{Cdr1LeSerializer, Cdr2LeSerializer};
use serde::de::DeserializeOwned;
use serde::Serialize;

fn dust_encode<T: TypeSupport>(v: T, lib: &str) -> Vec<u8> {
    let d = v.create_dynamic_sample();
    if lib == "dust2" {
        Cdr2LeSerializer::serialize(&d)
    } else {
        Cdr1LeSerializer::serialize(&d)
    }
    .unwrap()
}

fn run<T: DdsType + TypeSupport + Clone + Serialize + DeserializeOwned>(
    v: T,
    op: &str,
    lib: &str,
    n: usize,
) {
    let version = if lib == "ours2" {
        XcdrVersion::Xcdr2
    } else {
        XcdrVersion::Xcdr1
    };
    let mut buf = Vec::new();
    if lib.starts_with("dust") {
        let ty = T::get_type();
        let bytes = dust_encode(v.clone(), lib);
        for _ in 0..n {
            if op == "encode" {
                // The clone is part of the measured loop here (cdr.rs keeps it out with iter_batched).
                black_box(dust_encode(black_box(&v).clone(), lib));
            } else {
                black_box(T::create_sample(
                    CdrDeserializer::deserialize(ty.clone(), black_box(&bytes)).unwrap(),
                ));
            }
        }
        return;
    }
    if lib == "serde" {
        buf.extend_from_slice(&[0, 1, 0, 0]);
        cdr_encoding::to_writer::<T, LittleEndian, _>(&mut buf, &v).unwrap();
    } else {
        cdr::serialize(&v, version, ByteOrder::LittleEndian, &mut buf).unwrap();
    }
    let bytes = buf.clone();
    let mut reused = v.clone();
    // The operation is chosen once, outside the loop: matching OP and LIB (string compares) on every
    // iteration cost each library 20-40 instructions per operation, and not the same number for each arm.
    match (op, lib) {
        ("encode", "serde") => repeat(n, || {
            buf.clear();
            buf.extend_from_slice(&[0, 1, 0, 0]);
            cdr_encoding::to_writer::<T, LittleEndian, _>(&mut buf, black_box(&v)).unwrap();
            black_box(&buf);
        }),
        ("encode", _) => repeat(n, || {
            buf.clear();
            cdr::serialize(black_box(&v), version, ByteOrder::LittleEndian, &mut buf).unwrap();
            black_box(&buf);
        }),
        ("decode", "serde") => repeat(n, || {
            black_box(cdr_encoding::from_bytes::<T, LittleEndian>(black_box(&bytes[4..])).unwrap());
        }),
        ("into", _) => repeat(n, || {
            cdr::deserialize_into::<T>(black_box(&bytes), &mut reused).unwrap();
            black_box(&reused);
        }),
        ("decode", _) => repeat(n, || {
            black_box(cdr::deserialize::<T>(black_box(&bytes)).unwrap());
        }),
        _ => panic!("OP is encode, decode or into"),
    }
}

/// Runs `f` `n` times.
fn repeat(n: usize, mut f: impl FnMut()) {
    for _ in 0..n {
        f();
    }
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let [ty, op, lib] = [&a[0], &a[1], &a[2]].map(String::as_str);
    let n = a.get(3).map_or(1_000_000, |s| s.parse().unwrap());
    match ty {
        "shape" => run(shape(), op, lib, n),
        "octets1k" => run(keyed_seq_1k(), op, lib, n),
        "nested" => run(telemetry(), op, lib, n),
        "wide" => run(wide(), op, lib, n),
        t => panic!("unknown type {t}"),
    }
}
