//! Recursive types (strongly connected components, XTypes 1.3 §7.3.4.9): our TypeInformation and TypeMapping
//! bytes against those Cyclone DDS 11.0.1's Python binding computes (`tests/fixtures/typeinfo-recursive`,
//! written by `scripts/golden/recursive_typeinfo.py` from `scripts/golden/rec_golden`, each type in a process of
//! its own; never from our encoder). libddsc 11 refuses these objects at topic creation and Cyclone's idlc does
//! not finish on such IDL, so the binding is the only peer reference. Also: values of these types round trip,
//! and hostile nesting is refused at the decoder's depth limit.

use std::path::PathBuf;

use dds_runtime::cdr::{deserialize, serialize, ByteOrder, DdsType, XcdrVersion};
use dds_runtime::xtypes::typeobject::TypeIdentifier;
use dds_runtime::xtypes::XTypesType;

mod recursive_types;
use recursive_types::*;

fn fixture(name: &str) -> serde_json::Value {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join(format!("fixtures/typeinfo-recursive/{name}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).expect("json")
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

fn same_as_the_binding<T: XTypesType>(name: &str) {
    let fx = fixture(name);
    let support = T::type_support().unwrap_or_else(|| panic!("{name}: no type support"));
    assert_eq!(
        hex(&support.information_bytes),
        fx["type_information"].as_str().unwrap(),
        "{name}: TypeInformation"
    );
    assert_eq!(
        hex(&support.mapping_bytes),
        fx["type_mapping"].as_str().unwrap(),
        "{name}: TypeMapping"
    );
}

#[test]
fn a_struct_holding_a_sequence_of_itself() {
    same_as_the_binding::<Node>("Node");
    let id = Node::type_support().unwrap().minimal_id().clone();
    let TypeIdentifier::StronglyConnected(scc) = id else {
        panic!("not a component id: {id:?}")
    };
    assert_eq!((scc.scc_length, scc.scc_index), (1, 1));
}

#[test]
fn two_mutually_recursive_structs_share_one_component() {
    same_as_the_binding::<A>("A");
    same_as_the_binding::<B>("B");
    let scc = |id: &TypeIdentifier| match id {
        TypeIdentifier::StronglyConnected(s) => *s,
        other => panic!("not a component id: {other:?}"),
    };
    let (a, b) = (
        scc(A::type_support().unwrap().complete_id()),
        scc(B::type_support().unwrap().complete_id()),
    );
    assert_eq!(a.hash, b.hash);
    assert_eq!((a.scc_index, b.scc_index), (1, 2), "numbered by name");
}

#[test]
fn a_recursive_appendable_struct_with_a_plain_dependency() {
    same_as_the_binding::<Tree>("Tree");
}

#[test]
fn a_struct_holding_two_components() {
    same_as_the_binding::<Holder>("Holder");
}

#[test]
fn an_optional_member_of_its_own_type() {
    same_as_the_binding::<Chain>("Chain");
}

fn round_trip<T: DdsType + PartialEq + std::fmt::Debug>(v: &T) {
    for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
        for order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
            let mut out = Vec::new();
            serialize(v, version, order, &mut out).unwrap();
            assert_eq!(&deserialize::<T>(&out).unwrap(), v, "{version:?} {order:?}");
        }
    }
}

#[test]
fn recursive_values_round_trip() {
    round_trip(&node_value());
    round_trip(&A {
        x: 1,
        bs: vec![B {
            y: 2,
            as_: vec![A { x: 3, bs: vec![] }],
        }],
    });
    round_trip(&Chain {
        v: 1,
        next: Some(Box::new(Chain { v: 2, next: None })),
    });
    round_trip(&Tree {
        v: 1,
        leaf: Leaf { name: "a".into() },
        kids: vec![Tree::default(); 3],
    });
}

#[test]
fn hostile_nesting_stops_at_the_depth_limit() {
    assert!(deserialize::<Node>(&nested_node_bytes(10)).is_ok());
    for depth in [100, 10_000, 1_000_000] {
        let e = deserialize::<Node>(&nested_node_bytes(depth)).unwrap_err();
        assert!(e.to_string().contains("deep"), "{depth}: {e}");
    }
    let mut chain = Chain::default();
    for v in 0..200 {
        chain = Chain {
            v,
            next: Some(Box::new(chain)),
        };
    }
    let mut out = Vec::new();
    assert!(
        serialize(
            &chain,
            XcdrVersion::Xcdr2,
            ByteOrder::LittleEndian,
            &mut out
        )
        .is_err(),
        "the encoder refuses to write past the depth limit too"
    );
}

/// Typed endpoints of a recursive type announce component identifiers in their type information; a writer
/// and a reader of `Holder` (two components inside) in two participants over loopback still match (the
/// identifiers are equal) and exchange a sample. Needs a network namespace (`scripts/isolated`).
#[test]
fn recursive_typed_endpoints_match_and_exchange_data() {
    use dds_runtime::prelude::*;
    use std::time::{Duration, Instant};
    assert_eq!(
        std::env::var("DDS_IN_NETNS").as_deref(),
        Ok("1"),
        "socket tests must run inside scripts/isolated (loopback-only network namespace)"
    );
    let part = || {
        DomainParticipant::builder()
            .domain_id(220)
            .interface("lo")
            .spdp_interval(Duration::from_millis(200))
            .build()
            .expect("participant")
    };
    let (p1, p2) = (part(), part());
    let qos_w = DataWriterQos::builder()
        .reliability(Reliability::Reliable {
            max_blocking_time: Duration::from_secs(1),
        })
        .durability(Durability::TransientLocal)
        .build();
    let qos_r = DataReaderQos::builder()
        .reliability(Reliability::Reliable {
            max_blocking_time: Duration::from_secs(1),
        })
        .durability(Durability::TransientLocal)
        .build();
    let w = p1
        .create_publisher(&PublisherQos::default())
        .and_then(|p| {
            p.create_datawriter(
                &p1.create_topic::<Holder>("RecTopic", &TopicQos::default())?,
                &qos_w,
            )
        })
        .unwrap();
    let r = p2
        .create_subscriber(&SubscriberQos::default())
        .and_then(|s| {
            s.create_datareader(
                &p2.create_topic::<Holder>("RecTopic", &TopicQos::default())?,
                &qos_r,
            )
        })
        .unwrap();
    let sample = Holder {
        id: 7,
        root: Node {
            value: 1,
            children: vec![Node::default()],
        },
        a: A {
            x: 2,
            bs: vec![B { y: 3, as_: vec![] }],
        },
    };
    w.write(&sample).unwrap();
    let end = Instant::now() + Duration::from_secs(10);
    let mut got = Vec::new();
    while got.is_empty() && Instant::now() < end {
        let _ = r.wait_for_data(Duration::from_millis(100));
        got.extend(r.take().unwrap().into_iter().filter_map(|s| s.data));
    }
    assert_eq!(
        got,
        [sample],
        "matched: {:?}",
        r.matched_publication_guids()
    );
    assert_eq!(r.requested_incompatible_qos_status().total_count, 0);
}
