//! The comparison in `benches/cdr.rs` is only fair if the libraries produce the same bytes for the same value.
//! This checks it: ours against cdr-encoding (plain CDR = XCDR1 for non-mutable types) and against Dust DDS
//! (XCDR1 and XCDR2), and pins down the places where Dust DDS 0.15 writes something else (and why).
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
    assert!(
        o[4 + s.len()..].iter().all(|&b| b == 0) && o.len() - 4 - s.len() < 4,
        "only padding may follow"
    );
}

fn same_as_dust<T: DdsType + TypeSupport + Clone>(v: &T, version: XcdrVersion) {
    assert_eq!(
        ours(v, version),
        dust(v, version),
        "{version:?} differs from Dust DDS"
    );
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
fn nested_matches_cdr_encoding_and_dust_in_xcdr1() {
    let v = telemetry();
    same_as_cdr_encoding(&v);
    same_as_dust(&v, XcdrVersion::Xcdr1);
}

#[test]
fn nested_xcdr2_dust_omits_the_sequence_dheaders() {
    // XTypes 1.3 §7.4.3.5.3: in XCDR2 a sequence of non-primitive elements starts with a DHEADER. Ours writes one
    // before `readings` (sequence<Reading>) and one before `labels` (sequence<string>); Dust DDS 0.15 writes
    // neither, so its XCDR2 payload is 8 bytes shorter and the rest is identical.
    let v = telemetry();
    let (o, d) = (ours(&v, XcdrVersion::Xcdr2), dust(&v, XcdrVersion::Xcdr2));
    assert_eq!(o.len(), d.len() + 8);
    let mut stripped = o.clone();
    // `readings` DHEADER sits after id (8) and source (4 + 15 + 1 pad) = offset 4 + 28.
    let readings_dheader = 4 + 28;
    let len = u32::from_le_bytes(
        o[readings_dheader..readings_dheader + 4]
            .try_into()
            .unwrap(),
    ) as usize;
    let labels_dheader = readings_dheader + 4 + len;
    stripped.drain(labels_dheader..labels_dheader + 4);
    stripped.drain(readings_dheader..readings_dheader + 4);
    assert_eq!(stripped, d);
}

#[test]
fn wide_mutable_xcdr2_dust_writes_xcdr1_style_parameters() {
    // XCDR2 mutable: DHEADER, then per member an EMHEADER (M flag, length code, 28-bit id) and NEXTINT when the
    // length code needs one. Dust DDS 0.15 labels its payload PL_CDR2_LE but writes XCDR1-style short parameter
    // headers (16-bit id, 16-bit length) and no DHEADER, so it is not comparable byte for byte.
    let v = wide();
    let (o, d) = (ours(&v, XcdrVersion::Xcdr2), dust(&v, XcdrVersion::Xcdr2));
    assert_eq!(&o[..2], &[0x00, 0x0b], "ours: PL_CDR2_LE");
    assert_eq!(&d[..2], &[0x00, 0x0b], "dust: PL_CDR2_LE too");
    let dheader = u32::from_le_bytes(o[4..8].try_into().unwrap()) as usize;
    assert_eq!(
        dheader,
        o.len() - 8 - usize::from(o[3] & 3),
        "ours: DHEADER covers the members"
    );
    assert_eq!(
        &o[8..12],
        &[11, 0, 0, 0x20],
        "ours: EMHEADER id 11, LC 2 (4 bytes)"
    );
    assert_eq!(
        &d[4..8],
        &[11, 0, 4, 0],
        "dust: short PID 11, length 4, no DHEADER"
    );
}

#[test]
fn wide_mutable_xcdr1_parameter_lists_differ_from_dust() {
    // Ours writes every member as a PID_EXTENDED parameter and ends the list with PID_LIST_END (0x3f02, with the
    // must-understand bit), as Cyclone DDS does. Dust DDS 0.15 writes short parameters and ends the list with the
    // RTPS PID_SENTINEL (0x0001), which is why it cannot read back a mutable type that has a member with id 1.
    let v = wide();
    let (o, d) = (ours(&v, XcdrVersion::Xcdr1), dust(&v, XcdrVersion::Xcdr1));
    assert_eq!(&o[..2], &d[..2], "both PL_CDR_LE");
    assert_eq!(
        &o[4..8],
        &[0x01, 0x7f, 8, 0],
        "ours: PID_EXTENDED | must-understand, length 8"
    );
    assert_eq!(&d[4..8], &[11, 0, 4, 0], "dust: short PID 11, length 4");
    let pad = usize::from(o[3] & 3);
    assert_eq!(
        &o[o.len() - pad - 4..o.len() - pad],
        &[0x02, 0x7f, 0, 0],
        "ours ends with PID_LIST_END"
    );
    let pad = usize::from(d[3] & 3);
    assert_eq!(
        &d[d.len() - pad - 4..d.len() - pad],
        &[0x01, 0, 0, 0],
        "dust ends with PID_SENTINEL"
    );
}
