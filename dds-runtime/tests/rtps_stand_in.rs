//! A durability stand-in next to its original writer, through the simulated network: a reader that the
//! original writer serves gets each change once, from the original (the stand-in sends it GAPs only), and a
//! reader that joins after the original is gone gets everything from the stand-in. The readers here are
//! the core's, without the DCPS duplicate filter, so a repeat would show as a second sample, as it would
//! for another vendor's reader.

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
        .durability(Durability::TransientLocal)
        .build();
    let rq = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepAll)
        .durability(Durability::TransientLocal)
        .build();
    (wq, rq)
}

struct Setup {
    sim: Sim,
    original: EntityId,
    stand_in: EntityId,
}

/// Node 0 holds the original writer and its stand-in (an internal writer with the marker), each with
/// changes `0..n` written.
fn setup(seed: u64, faults: Faults, n: u32) -> Setup {
    let mut sim = Sim::with_participants(seed, faults, 3);
    sim.faults_on_discovery = false;
    let now = sim.now;
    let (wq, _) = durable_qos();
    let p = &mut sim.nodes[0].p;
    let original = p
        .create_writer(now, WriterSpec::new("T", "M::T", false, wq.clone()))
        .unwrap();
    let og = Guid::new(p.guid_prefix(), original);
    let mut sq = wq;
    sq.user_data = marker(og);
    let mut spec = WriterSpec::new("T", "M::T", false, sq);
    spec.internal = true;
    let stand_in = p.create_writer(now, spec).unwrap();
    let mut s = Setup {
        sim,
        original,
        stand_in,
    };
    write_both(&mut s, 0..n);
    s
}

/// Writes each index with the original writer and then with the stand-in, as the service republishes.
fn write_both(s: &mut Setup, range: std::ops::Range<u32>) {
    for i in range {
        write_indexed(&mut s.sim, s.original, i);
        write_indexed(&mut s.sim, s.stand_in, i);
    }
}

fn reader(sim: &mut Sim, node: usize) -> EntityId {
    let now = sim.now;
    let (_, rq) = durable_qos();
    sim.nodes[node]
        .p
        .create_reader(now, ReaderSpec::new("T", "M::T", false, rq))
        .unwrap()
}

/// Runs until `reader` at `node` holds `n` samples and node 0's writers are acknowledged; returns the
/// samples as (writer, index).
fn collect(s: &mut Setup, node: usize, reader: EntityId, n: usize) -> Vec<(Guid, u32)> {
    let mut got = Vec::new();
    let (o, w) = (s.original, s.stand_in);
    let done = s.sim.run_until(Duration::from_secs(60), |sim| {
        let taken = sim.take_samples(node, reader);
        got.extend(taken.iter().map(|x| (x.writer, payload_index(&x.payload))));
        let p = &sim.nodes[0].p;
        got.len() >= n
            && p.is_acknowledged(w)
            && (p.writer_matches(o).is_empty() || p.is_acknowledged(o))
    });
    assert!(done, "no end: {got:?}");
    // Whatever would still come (a late repeat) comes within this.
    s.sim.run_for(Duration::from_secs(2));
    let taken = s.sim.take_samples(node, reader);
    got.extend(taken.iter().map(|x| (x.writer, payload_index(&x.payload))));
    got
}

fn run(seed: u64, faults: Faults) {
    let mut s = setup(seed, faults, 5);
    let og = s.sim.guid(0, s.original);
    let sg = s.sim.guid(0, s.stand_in);
    // A late joiner while the original lives: the history, then live changes, each once, from the original.
    let r1 = reader(&mut s.sim, 1);
    let mut got = collect(&mut s, 1, r1, 5);
    write_both(&mut s, 5..8);
    got.extend(collect(&mut s, 1, r1, 3));
    let want: Vec<(Guid, u32)> = (0..8).map(|i| (og, i)).collect();
    assert_eq!(got, want, "seed {seed}: while the original lives");
    // The original goes; a reader that joins then gets everything from the stand-in.
    let now = s.sim.now;
    s.sim.nodes[0].p.delete_writer(now, s.original);
    let r2 = reader(&mut s.sim, 2);
    let got = collect(&mut s, 2, r2, 8);
    let want: Vec<(Guid, u32)> = (0..8).map(|i| (sg, i)).collect();
    assert_eq!(got, want, "seed {seed}: after the original");
    assert!(
        s.sim.take_samples(1, r1).is_empty(),
        "seed {seed}: the first reader got repeats"
    );
}

#[test]
fn a_reader_the_original_serves_gets_each_change_once() {
    run(1, Faults::NONE);
}

#[test]
fn a_reader_the_original_serves_gets_each_change_once_under_loss_20_seeds() {
    for seed in 0..20 {
        run(seed, Faults::lossy(0.2));
    }
}
