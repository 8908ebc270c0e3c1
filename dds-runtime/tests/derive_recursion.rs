//! Mutual recursion through sequences (A -> Vec<B> -> A): one field on the cycle is marked
//! `#[dds(recursive)]`, which keeps it out of the type's compile-time constants (otherwise rustc reports a cycle).

use dds_runtime::cdr::{deserialize, serialize, ByteOrder, DdsType, XcdrVersion};
use dds_runtime::DdsType;

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(final)]
struct Node {
    id: u32,
    #[dds(recursive)]
    kids: Vec<Edge>,
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(final)]
struct Edge {
    weight: u8,
    to: Vec<Node>,
}

/// A cycle through an appendable union: the mark sits on the appendable side, so the final struct's constants
/// still see the union and both default to XCDR2, as Cyclone would choose.
#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(final)]
struct Dir {
    name: String,
    entries: Vec<Entry>,
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(discriminator = u8)]
enum Entry {
    #[dds(case = 0)]
    File(String),
    #[dds(case = 1)]
    Sub(#[dds(recursive)] Vec<Dir>),
}

fn sample() -> Node {
    Node {
        id: 1,
        kids: vec![Edge {
            weight: 7,
            to: vec![Node {
                id: 2,
                kids: vec![],
            }],
        }],
    }
}

#[test]
fn mutual_recursion_through_vec_encodes_as_plain_cdr() {
    assert_eq!(Node::DEFAULT_VERSION, XcdrVersion::Xcdr1);
    assert_eq!(Edge::DEFAULT_VERSION, XcdrVersion::Xcdr1);
    let mut out = Vec::new();
    serialize(
        &sample(),
        XcdrVersion::Xcdr1,
        ByteOrder::LittleEndian,
        &mut out,
    )
    .unwrap();
    #[rustfmt::skip]
    let expected = [
        0x00, 0x01, 0x00, 0x00, // CDR_LE
        1, 0, 0, 0,             // id
        1, 0, 0, 0,             // kids: 1 edge
        7, 0, 0, 0,             // weight, padding
        1, 0, 0, 0,             // to: 1 node
        2, 0, 0, 0,             // id
        0, 0, 0, 0,             // kids: none
    ];
    assert_eq!(out, expected);
    assert_eq!(deserialize::<Node>(&out).unwrap(), sample());
}

#[test]
fn mutual_recursion_round_trips_in_both_versions() {
    let deep = Node {
        id: 10,
        kids: vec![
            Edge {
                weight: 1,
                to: vec![sample(), sample()],
            },
            Edge {
                weight: 2,
                to: vec![],
            },
        ],
    };
    for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
        for order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
            let mut out = Vec::new();
            serialize(&deep, version, order, &mut out).unwrap();
            assert_eq!(deserialize::<Node>(&out).unwrap(), deep);
        }
    }
}

#[test]
fn recursive_union_case_and_appendable_side() {
    assert_eq!(Entry::DEFAULT_VERSION, XcdrVersion::Xcdr2);
    assert_eq!(Dir::DEFAULT_VERSION, XcdrVersion::Xcdr2);
    let d = Dir {
        name: "root".into(),
        entries: vec![
            Entry::File("a".into()),
            Entry::Sub(vec![Dir {
                name: "sub".into(),
                entries: vec![Entry::File("b".into())],
            }]),
        ],
    };
    for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
        let mut out = Vec::new();
        serialize(&d, version, ByteOrder::BigEndian, &mut out).unwrap();
        assert_eq!(deserialize::<Dir>(&out).unwrap(), d);
    }
}
