//! Multicast user data in the sans-I/O core: a writer whose readers (in different participants) share a
//! multicast locator sends each new sample once, to that locator; repairs go to each reader's unicast
//! locator; readers in one participant, or a writer with multicast data off, stay on unicast.

mod rtps_support;

use std::time::Duration;

use dds_runtime::qos::*;
use dds_runtime::rtps::messages::{MessageIter, Submessage};
use dds_runtime::rtps::*;
use rtps_support::*;

const SAMPLES: usize = 20;

/// Node 0 writes "T" reliably; the readers sit on `reader_nodes` (a node may appear twice: two readers in
/// one participant). Every node has `multicast_data` as given and the builder's default multicast locator
/// (239.255.0.1:7401).
fn setup(
    multicast_data: bool,
    reader_nodes: &[usize],
    faults: Faults,
) -> (Sim, EntityId, Vec<(usize, EntityId)>) {
    let nodes = reader_nodes.iter().max().copied().unwrap_or(0) + 1;
    let mut sim = Sim::new(7, faults);
    sim.faults_on_discovery = false;
    for i in 0..nodes {
        sim.add(config(i).multicast_data(multicast_data));
    }
    let now = sim.now;
    let wq = DataWriterQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepAll)
        .build();
    let rq = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepAll)
        .build();
    let w = sim.nodes[0]
        .p
        .create_writer(now, WriterSpec::new("T", "M::T", false, wq))
        .unwrap();
    let readers: Vec<(usize, EntityId)> = reader_nodes
        .iter()
        .map(|&n| {
            let r = sim.nodes[n]
                .p
                .create_reader(now, ReaderSpec::new("T", "M::T", false, rq.clone()))
                .unwrap();
            (n, r)
        })
        .collect();
    let want = readers.len();
    assert!(sim.run_until(Duration::from_secs(5), |s| s.nodes[0]
        .p
        .writer_matches(w)
        .len()
        == want));
    (sim, w, readers)
}

/// Writes `SAMPLES` samples with tracing on and runs until every reader has them all (in order).
fn write_all(sim: &mut Sim, w: EntityId, readers: &[(usize, EntityId)]) {
    sim.trace = Some(Vec::new());
    for i in 0..SAMPLES {
        let now = sim.now;
        let payload = vec![0, 1, 0, 0, i as u8, 0, 0, 0];
        sim.nodes[0]
            .p
            .write(now, w, WriteChange::alive(payload))
            .unwrap();
        sim.run_for(Duration::from_millis(1));
    }
    let mut got = vec![Vec::new(); readers.len()];
    let done = sim.run_until(Duration::from_secs(20), |s| {
        for (k, (n, r)) in readers.iter().enumerate() {
            got[k].extend(s.take_samples(*n, *r).into_iter().map(|x| x.payload[4]));
        }
        got.iter().all(|g| g.len() >= SAMPLES)
    });
    assert!(done, "not every reader got every sample: {got:?}");
    for g in &got {
        assert_eq!(*g, (0..SAMPLES as u8).collect::<Vec<_>>());
    }
}

/// The destinations of every datagram node 0 sent that carries a DATA of a user writer.
fn data_sends(sim: &Sim) -> Vec<Vec<Locator>> {
    let trace = sim.trace.as_ref().unwrap();
    trace
        .iter()
        .filter(|(from, _, _)| *from == 0)
        .filter(|(_, _, payload)| {
            let Ok((_, it)) = MessageIter::parse(payload) else {
                return false;
            };
            it.flatten()
                .any(|s| matches!(s, Submessage::Data(d) if !d.writer_id.is_builtin()))
        })
        .map(|(_, d, _)| d.clone())
        .collect()
}

fn group() -> Locator {
    Locator::udpv4([239, 255, 0, 1], 7401)
}

#[test]
fn three_readers_on_a_group_get_each_sample_once() {
    let (mut sim, w, readers) = setup(true, &[1, 2, 3], Faults::NONE);
    write_all(&mut sim, w, &readers);
    let sends = data_sends(&sim);
    assert_eq!(sends.len(), SAMPLES, "{sends:?}");
    assert!(sends.iter().all(|d| d == &vec![group()]), "{sends:?}");
}

#[test]
fn multicast_data_off_sends_unicast_to_each_participant() {
    let (mut sim, w, readers) = setup(false, &[1, 2, 3], Faults::NONE);
    write_all(&mut sim, w, &readers);
    let sends = data_sends(&sim);
    assert_eq!(sends.len(), SAMPLES);
    for d in &sends {
        assert_eq!(d.len(), 3, "{d:?}");
        assert!(d.iter().all(|l| !l.is_multicast()), "{d:?}");
    }
}

#[test]
fn readers_behind_one_unicast_locator_stay_unicast() {
    // Two readers in participant 1: its unicast locator already reaches both.
    let (mut sim, w, readers) = setup(true, &[1, 1], Faults::NONE);
    write_all(&mut sim, w, &readers);
    let sends = data_sends(&sim);
    assert_eq!(sends.len(), SAMPLES);
    assert!(
        sends.iter().all(|d| d.len() == 1 && !d[0].is_multicast()),
        "{sends:?}"
    );
}

#[test]
fn losses_are_repaired_by_unicast() {
    let mut faults = Faults::lossy(0.2);
    faults.duplicate = 0.0;
    let (mut sim, w, readers) = setup(true, &[1, 2, 3], faults);
    write_all(&mut sim, w, &readers);
    let sends = data_sends(&sim);
    let multicast: Vec<_> = sends.iter().filter(|d| d.contains(&group())).collect();
    let unicast: Vec<_> = sends
        .iter()
        .filter(|d| d.iter().all(|l| !l.is_multicast()))
        .collect();
    // New samples went out once each to the group; whatever was lost came back unicast, to one reader.
    assert_eq!(multicast.len(), SAMPLES, "{sends:?}");
    assert!(!unicast.is_empty(), "20% loss and no repair: {sends:?}");
    assert!(unicast.iter().all(|d| d.len() == 1), "{unicast:?}");
}
