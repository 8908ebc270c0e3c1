//! The comparison in `benches/cdr.rs` is only fair if the libraries produce the same bytes for the same value.
//! This checks it: ours against cdr-encoding (plain CDR = XCDR1 for non-mutable types) and against Dust DDS
//! (XCDR1 and XCDR2).
//!
//! Run: `cargo test -p dds-benches --test wire_agreement`.

#[path = "../benches/common/mod.rs"]
mod common;

use byteorder::LittleEndian;
use common::*;
use dds_runtime::cdr::{self, ByteOrder, DdsType, XcdrVersion};
use dust_dds::infrastructure::type_support::TypeSupport;
use dust_dds::xtypes::serializer::{Cdr1LeSerializer, Cdr2LeSerializer};
use serde::Serialize;

fn ours<T: DdsType>(v: &T, version: XcdrVersion) -> Vec<u8> {
    let mut out = Vec::new();
    cdr::serialize(v, version, ByteOrder::LittleEndian, &mut out).unwrap();
    out
}

fn dust<T: TypeSupport + Clone>(v: &T, version: XcdrVersion) -> Vec<u8> {
    let d = v.clone().create_dynamic_sample();
    match version {
        XcdrVersion::Xcdr1 => Cdr1LeSerializer::serialize(&d),
        XcdrVersion::Xcdr2 => Cdr2LeSerializer::serialize(&d),
    }
    .unwrap()
}

/// cdr-encoding writes no encapsulation header and no final padding: compare the body, then check that ours
/// only adds zero padding.
fn same_as_cdr_encoding<T: DdsType + Serialize>(v: &T) {
    let o = ours(v, XcdrVersion::Xcdr1);
    let s = cdr_encoding::to_vec::<T, LittleEndian>(v).unwrap();
    assert_eq!(&o[..2], &[0x00, 0x01], "CDR_LE");
    assert_eq!(&o[4..4 + s.len()], &s[..], "body differs from cdr-encoding");
    assert!(o[4 + s.len()..].iter().all(|&b| b == 0) && o.len() - 4 - s.len() < 4, "only padding may follow");
}

fn same_as_dust<T: DdsType + TypeSupport + Clone>(v: &T, version: XcdrVersion) {
    assert_eq!(ours(v, version), dust(v, version), "{version:?} differs from Dust DDS");
}

#[test]
fn shape_matches_cdr_encoding_and_dust() {
    let v = shape();
    same_as_cdr_encoding(&v);
    same_as_dust(&v, XcdrVersion::Xcdr1);
    same_as_dust(&v, XcdrVersion::Xcdr2);
}

#[test]
fn octets_1k_matches_cdr_encoding_and_dust() {
    let v = keyed_seq_1k();
    same_as_cdr_encoding(&v);
    same_as_dust(&v, XcdrVersion::Xcdr1);
    same_as_dust(&v, XcdrVersion::Xcdr2);
}

#[test]
fn nested_matches_cdr_encoding_and_dust() {
    let v = telemetry();
    same_as_cdr_encoding(&v);
    same_as_dust(&v, XcdrVersion::Xcdr1);
    same_as_dust(&v, XcdrVersion::Xcdr2);
}

#[test]
fn wide_mutable_matches_dust() {
    let v = wide();
    same_as_dust(&v, XcdrVersion::Xcdr1);
    same_as_dust(&v, XcdrVersion::Xcdr2);
}
