//! Type evolution on the decode side (XTypes 1.3 §7.4): a reader decodes a writer's sample of another version of
//! its type with its own derived decoder. Appendable: members added at the end are skipped by an older reader
//! and defaulted for a newer one. Mutable: members matched by id in any order, unknown members skipped,
//! missing ones defaulted, and an unknown member flagged must_understand rejected. XCDR1 and XCDR2.

use dds_runtime::cdr::{deserialize, serialize, ByteOrder, DdsType, DecodeErrorKind, XcdrVersion};
use dds_runtime::DdsType;

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(appendable, name = "Evo")]
struct AppV1 {
    #[dds(key)]
    id: u32,
    name: String,
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(appendable, name = "Evo")]
struct AppV2 {
    #[dds(key)]
    id: u32,
    name: String,
    #[dds(default = 7)]
    level: i32,
    tags: Vec<String>,
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "EvoM")]
struct MutV1 {
    #[dds(key, id = 1)]
    id: u32,
    #[dds(id = 2)]
    name: String,
    #[dds(id = 3)]
    speed: f64,
}

/// Version 2: members declared in another order, `speed` dropped, two members added.
#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "EvoM")]
struct MutV2 {
    #[dds(id = 5, default = -1)]
    rank: i32,
    #[dds(id = 2)]
    name: String,
    #[dds(id = 4, optional)]
    note: Option<String>,
    #[dds(key, id = 1)]
    id: u32,
}

/// Version 1 with a member the other versions do not know, flagged must_understand.
#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "EvoM")]
struct MutStrict {
    #[dds(key, id = 1)]
    id: u32,
    #[dds(id = 2)]
    name: String,
    #[dds(id = 9, must_understand)]
    unit: u8,
}

fn bytes<T: DdsType>(v: &T, version: XcdrVersion) -> Vec<u8> {
    let mut out = Vec::new();
    serialize(v, version, ByteOrder::LittleEndian, &mut out).unwrap();
    out
}

const VERSIONS: [XcdrVersion; 2] = [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2];

#[test]
fn appendable_newer_reader_defaults_what_an_older_writer_lacks() {
    let v1 = AppV1 {
        id: 3,
        name: "a".into(),
    };
    let got: AppV2 = deserialize(&bytes(&v1, XcdrVersion::Xcdr2)).unwrap();
    assert_eq!(
        got,
        AppV2 {
            id: 3,
            name: "a".into(),
            level: 7,
            tags: vec![],
        }
    );
}

#[test]
fn appendable_older_reader_skips_what_a_newer_writer_added() {
    let v2 = AppV2 {
        id: 4,
        name: "b".into(),
        level: 9,
        tags: vec!["x".into(), "y".into()],
    };
    let got: AppV1 = deserialize(&bytes(&v2, XcdrVersion::Xcdr2)).unwrap();
    assert_eq!(
        got,
        AppV1 {
            id: 4,
            name: "b".into()
        }
    );
}

#[test]
fn mutable_members_are_matched_by_id_both_ways() {
    for version in VERSIONS {
        let v1 = MutV1 {
            id: 5,
            name: "c".into(),
            speed: 2.5,
        };
        let got: MutV2 = deserialize(&bytes(&v1, version)).unwrap();
        assert_eq!(
            got,
            MutV2 {
                rank: -1,
                name: "c".into(),
                note: None,
                id: 5,
            },
            "{version:?}"
        );
        let v2 = MutV2 {
            rank: 8,
            name: "d".into(),
            note: Some("n".into()),
            id: 6,
        };
        let got: MutV1 = deserialize(&bytes(&v2, version)).unwrap();
        assert_eq!(
            got,
            MutV1 {
                id: 6,
                name: "d".into(),
                speed: 0.0,
            },
            "{version:?}"
        );
    }
}

#[test]
fn an_unknown_must_understand_member_is_rejected() {
    let strict = MutStrict {
        id: 1,
        name: "e".into(),
        unit: 3,
    };
    for version in VERSIONS {
        let err = deserialize::<MutV1>(&bytes(&strict, version)).unwrap_err();
        assert!(
            matches!(err.kind, DecodeErrorKind::UnknownMustUnderstand { id: 9 }),
            "{version:?}: {err}"
        );
    }
    // The reverse is fine: a member the writer lacks is defaulted, whatever its flags.
    let v1 = MutV1 {
        id: 2,
        name: "f".into(),
        speed: 1.0,
    };
    let got: MutStrict = deserialize(&bytes(&v1, XcdrVersion::Xcdr2)).unwrap();
    assert_eq!(got.unit, 0);
}
