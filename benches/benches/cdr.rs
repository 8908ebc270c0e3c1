//! CDR encode/decode: ours (`dds_runtime::cdr`) against Dust DDS 0.15 and cdr-encoding 0.11 (RustDDS), on the
//! same values (see `common/mod.rs`).
//!
//! What each entry measures (per sample):
//! - `ours_xcdr1` / `ours_xcdr2`: `cdr::serialize` into one reused `Vec` (cleared each time; encapsulation
//!   header included) / `cdr::deserialize` of a complete payload.
//! - `ours_into_xcdr1` / `ours_into_xcdr2` (decode only): `cdr::deserialize_into` one reused sample, as a
//!   reader that keeps its sample does (strings and sequences keep their buffers).
//! - `dust_xcdr1` / `dust_xcdr2`: what a Dust DDS DataWriter does per write, `create_dynamic_sample` (the API
//!   consumes the sample, so a clone made outside the timed region is handed in) then
//!   `Cdr{1,2}LeSerializer::serialize` (returns a fresh `Vec`); decode is what its DataReader does,
//!   `CdrDeserializer::deserialize(type.clone(), bytes)` (the API takes the `DynamicType` by value; the type is
//!   built once, outside the loop) then `create_sample`.
//! - `cdr_encoding_xcdr1`: `cdr_encoding::to_writer::<_, LittleEndian, _>` into a reused `Vec` after the 4-byte
//!   CDR_LE header (RustDDS writes the header itself) / `from_bytes` of the body. Plain CDR only: for the mutable
//!   type this is *not* the PL_CDR wire format the other two produce (cdr-encoding has no XTypes support), so
//!   that row compares against a simpler encoding.
//!
//! All payloads are little-endian. Before measuring, every library's output is checked to decode back to the
//! same value with that library.

mod common;

use std::hint::black_box;
use std::time::Duration;

use byteorder::LittleEndian;
use common::*;
use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use dds_runtime::cdr::{self, ByteOrder, DdsType, XcdrVersion};
use dust_dds::infrastructure::type_support::TypeSupport;
use dust_dds::xtypes::deserializer::CdrDeserializer;
use dust_dds::xtypes::serializer::{Cdr1LeSerializer, Cdr2LeSerializer};
use serde::de::DeserializeOwned;
use serde::Serialize;

const LE: ByteOrder = ByteOrder::LittleEndian;
const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

fn ours_encode<T: DdsType>(v: &T, version: XcdrVersion) -> Vec<u8> {
    let mut out = Vec::new();
    cdr::serialize(v, version, LE, &mut out).expect("ours encodes");
    out
}

fn dust_encode<T: TypeSupport + Clone>(v: &T, version: XcdrVersion) -> Vec<u8> {
    let d = v.clone().create_dynamic_sample();
    match version {
        XcdrVersion::Xcdr1 => Cdr1LeSerializer::serialize(&d),
        XcdrVersion::Xcdr2 => Cdr2LeSerializer::serialize(&d),
    }
    .expect("dust encodes")
}

fn serde_encode<T: Serialize>(v: &T, out: &mut Vec<u8>) {
    out.clear();
    out.extend_from_slice(&CDR_LE_HEADER);
    cdr_encoding::to_writer::<T, LittleEndian, _>(&mut *out, v).expect("cdr-encoding encodes");
}

fn serde_decode<T: DeserializeOwned>(bytes: &[u8]) -> T {
    cdr_encoding::from_bytes::<T, LittleEndian>(&bytes[4..])
        .expect("cdr-encoding decodes")
        .0
}

fn bench_type<T>(c: &mut Criterion, name: &str, v: &T)
where
    T: DdsType + TypeSupport + Serialize + DeserializeOwned + Clone + PartialEq + std::fmt::Debug,
{
    let versions = [(XcdrVersion::Xcdr1, "xcdr1"), (XcdrVersion::Xcdr2, "xcdr2")];
    let dust_type = T::get_type();

    // Each library must decode its own output back to the value, or the numbers mean nothing. Dust DDS 0.15
    // cannot decode some of its own encodings (its XCDR1 parameter lists of mutable types): those decode
    // entries are left out and reported.
    let mut payloads = Vec::new();
    for (ver, tag) in versions {
        let ours = ours_encode(v, ver);
        assert_eq!(
            &cdr::deserialize::<T>(&ours).expect("ours decodes"),
            v,
            "ours {tag}"
        );
        let dust = dust_encode(v, ver);
        let dust_ok = match CdrDeserializer::deserialize(dust_type.clone(), &dust) {
            Ok(d) => {
                assert_eq!(&T::create_sample(d), v, "dust {tag}");
                true
            }
            Err(e) => {
                eprintln!("note: {name}: dust_dds cannot decode its own {tag} encoding ({e:?}); not measured");
                false
            }
        };
        payloads.push((ver, tag, ours, dust, dust_ok));
    }
    let mut serde_bytes = Vec::new();
    serde_encode(v, &mut serde_bytes);
    assert_eq!(&serde_decode::<T>(&serde_bytes), v, "cdr-encoding");

    eprintln!(
        "payload bytes {name}: ours x1 {} x2 {}, dust x1 {} x2 {}, cdr-encoding {}",
        payloads[0].2.len(),
        payloads[1].2.len(),
        payloads[0].3.len(),
        payloads[1].3.len(),
        serde_bytes.len()
    );

    let mut g = c.benchmark_group(format!("{name}_encode"));
    g.throughput(Throughput::Bytes(payloads[0].2.len() as u64));
    for (ver, tag, ours, _, _) in &payloads {
        let mut buf = Vec::with_capacity(ours.len());
        g.bench_function(format!("ours_{tag}"), |b| {
            b.iter(|| {
                buf.clear();
                cdr::serialize(black_box(v), *ver, LE, &mut buf).unwrap();
                black_box(&buf);
            })
        });
    }
    for (ver, tag, _, _, _) in &payloads {
        g.bench_function(format!("dust_{tag}"), |b| {
            b.iter_batched(
                || v.clone(),
                |s| {
                    let d = s.create_dynamic_sample();
                    match ver {
                        XcdrVersion::Xcdr1 => Cdr1LeSerializer::serialize(&d),
                        XcdrVersion::Xcdr2 => Cdr2LeSerializer::serialize(&d),
                    }
                    .unwrap()
                },
                BatchSize::SmallInput,
            )
        });
    }
    let mut buf = Vec::with_capacity(serde_bytes.len());
    g.bench_function("cdr_encoding_xcdr1", |b| {
        b.iter(|| {
            serde_encode(black_box(v), &mut buf);
            black_box(&buf);
        })
    });
    g.finish();

    let mut g = c.benchmark_group(format!("{name}_decode"));
    g.throughput(Throughput::Bytes(payloads[0].2.len() as u64));
    for (_, tag, ours, _, _) in &payloads {
        g.bench_function(format!("ours_{tag}"), |b| {
            b.iter(|| cdr::deserialize::<T>(black_box(ours)).unwrap())
        });
    }
    // What a reader that keeps a sample to decode into does: its strings and sequences keep their buffers.
    for (_, tag, ours, _, _) in &payloads {
        let mut sample = v.clone();
        g.bench_function(format!("ours_into_{tag}"), |b| {
            b.iter(|| {
                cdr::deserialize_into::<T>(black_box(ours), &mut sample).unwrap();
                black_box(&sample);
            })
        });
    }
    for (_, tag, _, dust, _) in payloads.iter().filter(|p| p.4) {
        g.bench_function(format!("dust_{tag}"), |b| {
            b.iter(|| {
                T::create_sample(
                    CdrDeserializer::deserialize(dust_type.clone(), black_box(dust)).unwrap(),
                )
            })
        });
    }
    g.bench_function("cdr_encoding_xcdr1", |b| {
        b.iter(|| serde_decode::<T>(black_box(&serde_bytes)))
    });
    g.finish();
}

fn cdr_benches(c: &mut Criterion) {
    bench_type(c, "shape", &shape());
    bench_type(c, "octets1k", &keyed_seq_1k());
    bench_type(c, "nested", &telemetry());
    bench_type(c, "wide_mutable", &wide());
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(700))
        .measurement_time(Duration::from_secs(2))
        .sample_size(40);
    targets = cdr_benches
}
criterion_main!(benches);
