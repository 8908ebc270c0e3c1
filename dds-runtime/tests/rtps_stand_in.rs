//! A durability stand-in next to its original writer, through the simulated network. The readers here are
//! the core's, without the DCPS duplicate filter, on a participant that announces another vendor's id: a
//! repeat shows as a second sample, as it would for a Cyclone reader.
//!
//! - While the original lives, the stand-in holds a reader the original serves: each change arrives once,
//!   from the original.
//! - The original deleted (it lingers until acknowledged): the stand-in releases the reader with everything
//!   served and sends it nothing again; a reader joining afterwards gets everything from the stand-in.
//! - The original's participant lost (crashed, its lease expired): a held reader, including one that joined
//!   after the crash and so got nothing from the original, gets everything from the stand-in.

mod rtps_support;

use std::time::Duration;

use dds_runtime::qos::*;
use dds_runtime::rtps::*;
use rtps_support::*;

/// The USER_DATA of a durability stand-in for `original` (the marker `dcps::durability` gives it).
fn marker(original: Guid) -> UserData {
    let mut v = b"dds-rs durability stand-in for ".to_vec();
    v.extend_from_slice(&original.to_bytes());
    UserData(v)
}

fn durable_qos() -> (DataWriterQos, DataReaderQos) {
    let wq = DataWriterQos::builder()
        .history(History::KeepAll)
        .durability(Durability::Transient)
        .build();
    let rq = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepAll)
        .durability(Durability::TransientLocal)
        .build();
    (wq, rq)
}

/// Node 0: the stand-in; node `o` (0, or 3 for a remote original): the original writer; nodes 1 and 2:
/// another vendor's participants, for the readers.
struct Setup {
    sim: Sim,
    o_node: usize,
    original: EntityId,
    stand_in: EntityId,
}

fn setup(seed: u64, faults: Faults, o_node: usize) -> Setup {
    let mut sim = Sim::new(seed, faults);
    sim.add(config(0));
    sim.add(config(1).vendor_id(VendorId::CYCLONE));
    sim.add(config(2).vendor_id(VendorId::CYCLONE));
    sim.add(config(3));
    sim.faults_on_discovery = false;
    let now = sim.now;
    let (wq, _) = durable_qos();
    let original = sim.nodes[o_node]
        .p
        .create_writer(now, WriterSpec::new("T", "M::T", false, wq.clone()))
        .unwrap();
    let og = sim.guid(o_node, original);
    let mut sq = wq;
    sq.user_data = marker(og);
    let mut spec = WriterSpec::new("T", "M::T", false, sq);
    spec.internal = true;
    let stand_in = sim.nodes[0].p.create_writer(now, spec).unwrap();
    // The stand-in's participant knows the original before the readers come (as the service does).
    let known = sim.run_until(Duration::from_secs(10), |sim| {
        o_node == 0
            || sim.has_event(
                0,
                |e| matches!(e, Event::PublicationDiscovered(d) if d.guid == og),
            )
    });
    assert!(known, "the original was never discovered");
    Setup {
        sim,
        o_node,
        original,
        stand_in,
    }
}

fn write(sim: &mut Sim, node: usize, w: EntityId, i: u32) {
    let ts = Time {
        seconds: 1_000_000,
        fraction: i,
    };
    until_accepted(sim, |sim| {
        let now = sim.now;
        let ch = WriteChange::alive(indexed_payload(i)).with_timestamp(ts);
        sim.nodes[node].p.write(now, w, ch)
    });
}

/// Writes each index with the original writer and then with the stand-in, as the service republishes.
fn write_both(s: &mut Setup, range: std::ops::Range<u32>) {
    for i in range {
        write(&mut s.sim, s.o_node, s.original, i);
        write(&mut s.sim, 0, s.stand_in, i);
    }
}

fn reader(sim: &mut Sim, node: usize) -> EntityId {
    reader_with(sim, node, Reliability::RELIABLE)
}

fn reader_with(sim: &mut Sim, node: usize, reliability: Reliability) -> EntityId {
    let now = sim.now;
    let (_, mut rq) = durable_qos();
    rq.reliability = reliability;
    sim.nodes[node]
        .p
        .create_reader(now, ReaderSpec::new("T", "M::T", false, rq))
        .unwrap()
}

/// Runs until `reader` at `node` holds `n` samples, then 5 s more for anything else (a repeat); returns
/// the samples as (writer, index).
fn collect(sim: &mut Sim, node: usize, reader: EntityId, n: usize) -> Vec<(Guid, u32)> {
    let mut got = Vec::new();
    let take = |sim: &mut Sim, got: &mut Vec<(Guid, u32)>| {
        let taken = sim.take_samples(node, reader);
        got.extend(taken.iter().map(|x| (x.writer, payload_index(&x.payload))));
    };
    let done = sim.run_until(Duration::from_secs(60), |sim| {
        take(sim, &mut got);
        got.len() >= n
    });
    assert!(done, "no end: {got:?}");
    sim.run_for(Duration::from_secs(5));
    take(sim, &mut got);
    got
}

fn from(g: Guid, r: std::ops::Range<u32>) -> Vec<(Guid, u32)> {
    r.map(|i| (g, i)).collect()
}

fn deleted_original(seed: u64, faults: Faults) {
    let mut s = setup(seed, faults, 0);
    let og = s.sim.guid(0, s.original);
    let sg = s.sim.guid(0, s.stand_in);
    write_both(&mut s, 0..5);
    let r1 = reader(&mut s.sim, 1);
    let mut got = collect(&mut s.sim, 1, r1, 5);
    write_both(&mut s, 5..8);
    got.extend(collect(&mut s.sim, 1, r1, 3));
    assert_eq!(got, from(og, 0..8), "seed {seed}: while the original lives");
    let now = s.sim.now;
    s.sim.nodes[0].p.delete_writer(now, s.original);
    let gone = s.sim.run_until(Duration::from_secs(60), |sim| {
        sim.has_event(0, |e| matches!(e, Event::WriterDeleted { .. }))
    });
    assert!(gone, "seed {seed}: the original never finished");
    // The service republishes the original's last change late: the released reader had it.
    write(&mut s.sim, 0, s.stand_in, 7);
    let r2 = reader(&mut s.sim, 2);
    let got = collect(&mut s.sim, 2, r2, 9);
    let mut want = from(sg, 0..8);
    want.push((sg, 7));
    assert_eq!(got, want, "seed {seed}: a reader after the original");
    let again = collect(&mut s.sim, 1, r1, 0);
    assert!(
        again.is_empty(),
        "seed {seed}: repeats after the release: {again:?}"
    );
}

#[test]
fn a_reader_the_original_serves_gets_each_change_once_and_nothing_again_after_its_deletion() {
    deleted_original(1, Faults::NONE);
}

#[test]
fn a_reader_the_original_serves_gets_each_change_once_under_loss_10_seeds() {
    for seed in 0..10 {
        deleted_original(seed, Faults::lossy(0.2));
    }
}

/// The original on node 3, which crashes: `late` readers join after the crash, before its lease expires.
fn lost_original(seed: u64, faults: Faults, late: bool) {
    let mut s = setup(seed, faults, 3);
    let og = s.sim.guid(3, s.original);
    let sg = s.sim.guid(0, s.stand_in);
    write_both(&mut s, 0..5);
    let mut got = Vec::new();
    let r1 = if late {
        s.sim.nodes[3].up = false;
        reader(&mut s.sim, 1)
    } else {
        let r1 = reader(&mut s.sim, 1);
        got = collect(&mut s.sim, 1, r1, 5);
        assert_eq!(got, from(og, 0..5), "seed {seed}: while the original lives");
        s.sim.nodes[3].up = false;
        got.clear();
        r1
    };
    // Held until node 3's lease (3 s) expires, then everything from the stand-in.
    got.extend(collect(&mut s.sim, 1, r1, 5));
    assert_eq!(
        got,
        from(sg, 0..5),
        "seed {seed}: after the original was lost"
    );
    assert!(s
        .sim
        .has_event(0, |e| matches!(e, Event::ParticipantLost { .. })));
}

#[test]
fn a_reader_joining_after_the_original_crashed_gets_everything_once_its_lease_expires() {
    lost_original(2, Faults::NONE, true);
    for seed in 0..5 {
        lost_original(seed, Faults::lossy(0.2), true);
    }
}

#[test]
fn a_held_reader_gets_everything_again_after_the_original_is_lost() {
    lost_original(3, Faults::NONE, false);
}

#[test]
fn a_remote_original_that_leaves_cleanly_leaves_nothing_to_repeat() {
    let mut s = setup(4, Faults::NONE, 3);
    let og = s.sim.guid(3, s.original);
    write_both(&mut s, 0..5);
    let r1 = reader(&mut s.sim, 1);
    let got = collect(&mut s.sim, 1, r1, 5);
    assert_eq!(got, from(og, 0..5));
    let now = s.sim.now;
    s.sim.nodes[3].p.delete_writer(now, s.original);
    let gone = s.sim.run_until(Duration::from_secs(60), |sim| {
        sim.has_event(
            0,
            |e| matches!(e, Event::PublicationRemoved { guid } if *guid == og),
        )
    });
    assert!(gone, "the original's departure never reached the stand-in");
    let again = collect(&mut s.sim, 1, r1, 0);
    assert!(
        again.is_empty(),
        "repeats after a clean departure: {again:?}"
    );
}

/// A best-effort reader held while the original lives gets the stand-in's history pushed once the
/// original's participant is lost (as a best-effort reader gets it at matching).
#[test]
fn a_held_best_effort_reader_gets_the_history_after_the_original_is_lost() {
    let mut s = setup(6, Faults::NONE, 3);
    let sg = s.sim.guid(0, s.stand_in);
    write_both(&mut s, 0..5);
    s.sim.nodes[3].up = false;
    let r1 = reader_with(&mut s.sim, 1, Reliability::BestEffort);
    let got = collect(&mut s.sim, 1, r1, 5);
    assert_eq!(got, from(sg, 0..5));
}
