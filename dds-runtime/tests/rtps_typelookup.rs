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
