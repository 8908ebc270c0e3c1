//! Hostile input: decoding never panics, never allocates what the input cannot justify, and every truncation
//! of a valid payload is an error.

mod cdr_families;

use cdr_families::*;
use dds_runtime::cdr::{
    deserialize, deserialize_key, serialize, ByteOrder, DdsType, DecodeErrorKind, XcdrVersion,
    MAX_DEPTH,
};
use dds_runtime::DdsType;
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::TestRunner;

fn truncations_fail<T: DdsType + std::fmt::Debug>(v: &T) {
    for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
        for order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
            let mut out = Vec::new();
            serialize(v, version, order, &mut out).unwrap();
            let pad = (out[3] & 3) as usize;
            for n in 0..out.len() - pad {
                let r = deserialize::<T>(&out[..n]);
                assert!(
                    r.is_err(),
                    "{version:?} {order:?}: prefix of {n} of {} bytes decoded",
                    out.len()
                );
            }
            // Key-only decoding of a full sample may succeed or fail, but must not panic.
            for n in 0..out.len() {
                let _ = deserialize_key::<T>(&out[..n]);
            }
        }
    }
}

#[test]
fn every_truncation_of_a_valid_payload_is_an_error() {
    let mut runner = TestRunner::deterministic();
    for _ in 0..4 {
        truncations_fail(&fam_final().new_tree(&mut runner).unwrap().current());
        truncations_fail(&fam_appendable().new_tree(&mut runner).unwrap().current());
        truncations_fail(&fam_mutable().new_tree(&mut runner).unwrap().current());
    }
}

#[derive(DdsType, Debug)]
#[dds(final)]
struct Words {
    w: Vec<u32>,
    s: Vec<String>,
}

#[test]
fn huge_lengths_fail_before_allocating() {
    // Sequence of 2^31 u32 in a 40-byte payload.
    let mut p = vec![0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80];
    p.resize(40, 0);
    let e = deserialize::<Words>(&p).unwrap_err();
    assert_eq!(e.offset, 4);
    assert!(matches!(
        e.kind,
        DecodeErrorKind::LengthTooLarge {
            length: 0x8000_0000,
            ..
        }
    ));
    // A string claiming 4 GiB.
    let p = [
        0x00, 0x01, 0x00, 0x00, 0, 0, 0, 0, 1, 0, 0, 0, 0xff, 0xff, 0xff, 0xff, b'a', 0,
    ];
    let e = deserialize::<Words>(&p).unwrap_err();
    assert_eq!(e.offset, 12);
    // A DHEADER larger than the payload.
    let p = [0x00, 0x09, 0x00, 0x00, 0xff, 0xff, 0xff, 0x7f, 0];
    let e = deserialize::<FamAppendable>(&p).unwrap_err();
    assert_eq!((e.offset, e.expected), (8, "DHEADER"));
}

#[derive(DdsType, Debug)]
#[dds(final)]
struct Deep {
    next: Option<Box<Deep>>,
}

#[test]
fn recursion_is_depth_limited() {
    let mut p = vec![0x00, 0x07, 0x00, 0x00];
    p.extend_from_slice(&[1u8; 100_000]);
    p.push(0);
    let e = deserialize::<Deep>(&p).unwrap_err();
    assert_eq!(e.kind, DecodeErrorKind::DepthExceeded { limit: MAX_DEPTH });
    // Within the limit it decodes.
    let mut p = vec![0x00, 0x07, 0x00, 0x00];
    p.extend_from_slice(&vec![1u8; MAX_DEPTH as usize - 1]);
    p.push(0);
    assert!(deserialize::<Deep>(&p).is_ok());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn random_bytes_never_panic(body in proptest::collection::vec(any::<u8>(), 0..200), id in 0usize..10) {
        let headers: [[u8; 4]; 10] = [
            [0, 0, 0, 0], [0, 1, 0, 0], [0, 2, 0, 0], [0, 3, 0, 0], [0, 6, 0, 0],
            [0, 7, 0, 0], [0, 8, 0, 0], [0, 9, 0, 0], [0, 0x0a, 0, 0], [0, 0x0b, 0, 3],
        ];
        let mut p = headers[id].to_vec();
        p.extend_from_slice(&body);
        let _ = deserialize::<FamFinal>(&p);
        let _ = deserialize::<FamAppendable>(&p);
        let _ = deserialize::<FamMutable>(&p);
        let _ = deserialize_key::<FamMutable>(&p);
        let _ = deserialize::<Words>(&p);
        let _ = deserialize::<Deep>(&p);
    }

    #[test]
    fn mutated_valid_payloads_never_panic(v in fam_mutable(), flips in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..8), v2 in any::<bool>()) {
        let mut out = Vec::new();
        let version = if v2 { XcdrVersion::Xcdr2 } else { XcdrVersion::Xcdr1 };
        serialize(&v, version, ByteOrder::LittleEndian, &mut out).unwrap();
        for (i, b) in flips {
            let n = out.len();
            out[i % n] ^= b;
        }
        let _ = deserialize::<FamMutable>(&out);
        let _ = deserialize::<FamAppendable>(&out);
    }
}
