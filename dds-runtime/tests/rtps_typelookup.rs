//! The TypeLookup service between two sans-I/O participants on the simulated network: a participant that
//! discovers an endpoint whose type it lacks asks for it, the owner answers from its store, and every object
//! is checked against its hash before it is kept; also over a lossy network, and for types nobody has.

mod rtps_support;

use std::time::Duration;

use dds_runtime::qos::*;
use dds_runtime::rtps::*;
use dds_runtime::xtypes::typeobject::{from_bytes, TypeIdentifier, TypeInformation};
use dds_runtime::xtypes::XTypesType;
use dds_runtime::DdsType;
use rtps_support::*;

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(appendable)]
struct Leaf {
    a: i32,
    name: String,
}

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(mutable)]
struct Middle {
    leaves: Vec<Leaf>,
    one: Leaf,
}

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
struct Top {
    #[dds(key)]
    id: u32,
    m: Middle,
    extra: Vec<Middle>,
}

/// Node 0 owns `Top` and writes it; returns its TypeInformation.
fn owner_writes_top(sim: &mut Sim) -> TypeInformation {
    let s = Top::type_support().unwrap();
    let now = sim.now;
    let p = &mut sim.nodes[0].p;
    p.register_types(&s.information_bytes, &s.mapping_bytes)
        .unwrap();
    let mut spec = WriterSpec::new("T", "Top", true, DataWriterQos::default());
    spec.type_information = Some(dds_runtime::xtypes::TypeInformation(
        s.information_bytes.clone(),
    ));
    p.create_writer(now, spec).unwrap();
    from_bytes(&s.information_bytes).unwrap()
}

fn learnt_everything(sim: &Sim, node: usize, info: &TypeInformation) -> bool {
    sim.nodes[node].p.type_store().missing(info).is_empty()
}

#[test]
fn participants_announce_the_service_endpoints() {
    let sim = Sim::with_participants(1, Faults::NONE, 1);
    let bits = sim.nodes[0].p.participant_data().builtin_endpoints;
    assert_eq!(bits & 0xf000, 0xf000, "{bits:#x}");
}

#[test]
fn a_discovered_writers_type_is_fetched_and_verified() {
    let mut sim = Sim::with_participants(2, Faults::NONE, 2);
    let info = owner_writes_top(&mut sim);
    assert!(!learnt_everything(&sim, 1, &info));
    assert!(sim.run_until(Duration::from_secs(3), |s| learnt_everything(s, 1, &info)));
    let top = &info.complete.typeid_with_size.type_id;
    assert_eq!(
        sim.nodes[1].p.type_store().get(top),
        sim.nodes[0].p.type_store().get(top)
    );
    // Top, Middle and Leaf, minimal and complete.
    assert_eq!(sim.nodes[1].p.type_store().len(), 6);
}

#[test]
fn types_are_fetched_over_a_lossy_network() {
    for seed in 0..5 {
        let mut sim = Sim::with_participants(seed, Faults::lossy(0.3), 2);
        let info = owner_writes_top(&mut sim);
        assert!(
            sim.run_until(Duration::from_secs(20), |s| learnt_everything(s, 1, &info)),
            "seed {seed}"
        );
    }
}

/// The service endpoints are matched per peer on the first exchange (not at discovery): two participants
/// fetch from one owner at about the same time (whichever is matched second may find the owner's reply
/// writer past its first sequence numbers) and both learn the type, also with loss; a later request still
/// goes through.
#[test]
fn several_participants_fetch_from_one_owner() {
    for (seed, faults) in [(5, Faults::NONE), (6, Faults::lossy(0.3))] {
        let mut sim = Sim::with_participants(seed, faults, 3);
        let info = owner_writes_top(&mut sim);
        assert!(
            sim.run_until(Duration::from_secs(20), |s| {
                learnt_everything(s, 1, &info) && learnt_everything(s, 2, &info)
            }),
            "seed {seed}"
        );
        let nobody = TypeIdentifier::Complete([0x5b; 14]);
        let now = sim.now;
        sim.nodes[2].p.request_types(now, [nobody]);
        sim.run_until(Duration::from_secs(1), |_| false);
        assert_eq!(sim.nodes[2].p.type_store().len(), 6, "seed {seed}");
    }
}

#[test]
fn a_type_nobody_has_is_asked_for_and_given_up() {
    let mut sim = Sim::with_participants(3, Faults::NONE, 2);
    let info = owner_writes_top(&mut sim);
    assert!(sim.run_until(Duration::from_secs(3), |s| learnt_everything(s, 1, &info)));
    let nobody = TypeIdentifier::Complete([0x5a; 14]);
    let now = sim.now;
    sim.nodes[1].p.request_types(now, [nobody.clone()]);
    sim.run_until(Duration::from_secs(3), |_| false);
    assert!(sim.nodes[1].p.type_store().get(&nobody).is_none());
    // Asked again after the first request expired: the service still answers (empty), nothing breaks.
    let now = sim.now;
    sim.nodes[1].p.request_types(now, [nobody.clone()]);
    sim.run_until(Duration::from_secs(1), |_| false);
    assert!(sim.nodes[1].p.type_store().get(&nobody).is_none());
    assert_eq!(sim.nodes[1].p.type_store().len(), 6);
}

#[test]
fn dependencies_are_asked_for_when_the_list_is_cut_short() {
    let mut sim = Sim::with_participants(4, Faults::NONE, 2);
    let info = owner_writes_top(&mut sim);
    let top = info.complete.typeid_with_size.type_id.clone();
    // Node 1 asks with getTypeDependencies first, then for the objects it names.
    let now = sim.now;
    sim.run_until(Duration::from_millis(500), |_| false);
    sim.nodes[1].p.request_type_dependencies(now, top.clone());
    assert!(sim.run_until(Duration::from_secs(3), |s| {
        info.complete
            .dependent_typeids
            .iter()
            .all(|d| s.nodes[1].p.type_store().contains(&d.type_id))
    }));
}

/// Cyclone's TypeInformation and TypeMapping bytes for a type of the CDR golden corpus
/// (`tests/fixtures/typeinfo`, written from Cyclone's Python binding). No type of that corpus is compiled into
/// this test binary, so the process-wide registry of our own types cannot resolve it.
fn cyclone_type(name: &str) -> (Vec<u8>, Vec<u8>) {
    let path = format!(
        "{}/../tests/fixtures/typeinfo/{name}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let field = |key: &str| {
        let at = text.find(&format!("\"{key}\"")).expect(key) + key.len() + 2;
        let start = text[at..].find('"').unwrap() + at + 1;
        let hex = &text[start..start + text[start..].find('"').unwrap()];
        (0..hex.len() / 2)
            .map(|i| u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).unwrap())
            .collect::<Vec<u8>>()
    };
    (field("type_information"), field("type_mapping"))
}

/// Node `n` owns the Cyclone type `fixture` and makes a `T`-named endpoint of it on topic "Evolving".
fn typed_spec<Q: Default>(sim: &mut Sim, n: usize, fixture: &str) -> EndpointSpec<Q> {
    let (info, mapping) = cyclone_type(fixture);
    sim.nodes[n].p.register_types(&info, &mapping).unwrap();
    let mut spec = EndpointSpec::new("Evolving", "T", false, Q::default());
    spec.type_information = Some(dds_runtime::xtypes::TypeInformation(info));
    spec
}

/// Node 0 writes Cyclone's `Primitives`, node 1 reads the Cyclone type `reader_type`, both named `T`; returns
/// the simulator and the reader.
fn primitives_writer_and_reader_of(seed: u64, reader_type: &str) -> (Sim, EntityId) {
    let mut sim = Sim::with_participants(seed, Faults::NONE, 2);
    let now = sim.now;
    let ws: WriterSpec = typed_spec(&mut sim, 0, "Primitives");
    sim.nodes[0].p.create_writer(now, ws).unwrap();
    let rs: ReaderSpec = typed_spec(&mut sim, 1, reader_type);
    let r = sim.nodes[1].p.create_reader(now, rs).unwrap();
    (sim, r)
}

/// A reader matched by type name while the writer's type was still unresolved is re-matched once the type
/// arrives through TypeLookup: the types are not assignable, so the match is undone and reported as an
/// incompatible TYPE_CONSISTENCY_ENFORCEMENT.
#[test]
fn a_match_made_by_name_is_revisited_when_the_type_arrives() {
    let (mut sim, r) = primitives_writer_and_reader_of(5, "Sequences");
    let matched = |on: bool| move |e: &Event| matches!(e, Event::SubscriptionMatched { reader, matched, .. } if *reader == r && *matched == on);
    assert!(sim.run_until(Duration::from_secs(5), |s| s.has_event(1, matched(false))));
    assert!(sim.has_event(1, matched(true)), "first matched by name");
    assert!(sim.has_event(1, |e| matches!(
        e,
        Event::RequestedIncompatibleQos { reader, policy: QosPolicyId::TypeConsistencyEnforcement, .. } if *reader == r
    )));
}

/// The same with assignable types: the match made by name stays.
#[test]
fn a_match_made_by_name_stays_when_the_arriving_type_is_assignable() {
    let (mut sim, r) = primitives_writer_and_reader_of(6, "Primitives");
    sim.run_for(Duration::from_secs(3));
    assert!(sim.has_event(
        1,
        |e| matches!(e, Event::SubscriptionMatched { reader, matched: true, .. } if *reader == r)
    ));
    assert!(!sim.has_event(1, |e| matches!(
        e,
        Event::SubscriptionMatched { matched: false, .. } | Event::RequestedIncompatibleQos { .. }
    )));
}
