//! Coherent sets (RTPS 2.5 §8.7.6) through the simulated network: a reader sees a set whole or not at all,
//! under loss, duplication and reordering, and never a set that was cut short.

mod rtps_support;

use std::time::Duration;

use dds_runtime::qos::*;
use dds_runtime::rtps::*;
use rtps_support::*;

/// What the reader got, in order: `Plain(i)` for a sample outside any set, `Set([i..])` for a whole set.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Got {
    Plain(u32),
    Set(Vec<u32>),
}

struct Setup {
    sim: Sim,
    w: EntityId,
    r: EntityId,
}

fn setup(seed: u64, faults: Faults, reliable: bool) -> Setup {
    let (wq, rq) = keep_all_qos(reliable);
    let (sim, w, r) = Sim::writer_and_reader(seed, faults, wq, rq);
    Setup { sim, w, r }
}

/// Takes what the reader delivered so far, and the count of samples reported lost.
fn take(sim: &mut Sim, r: EntityId) -> (Vec<Got>, u64) {
    let mut got = Vec::new();
    let mut lost = 0;
    sim.nodes[1].events.retain(|e| match e {
        Event::Sample(s) if s.reader == r => {
            got.push(Got::Plain(payload_index(&s.payload)));
            false
        }
        Event::CoherentSet {
            reader, samples, ..
        } if *reader == r => {
            got.push(Got::Set(
                samples.iter().map(|s| payload_index(&s.payload)).collect(),
            ));
            false
        }
        Event::SampleLost { reader, count, .. } if *reader == r => {
            lost += count;
            false
        }
        _ => true,
    });
    (got, lost)
}

/// Writes one change, running the network while flow control refuses it.
fn write(s: &mut Setup, i: u32) {
    write_indexed(&mut s.sim, s.w, i);
}

fn end_set(s: &mut Setup) {
    end_coherent(&mut s.sim, s.w);
}

/// The script every test writes: plain samples and sets of several sizes, interleaved. Returns what a
/// reader that misses nothing gets.
fn write_script(s: &mut Setup) -> Vec<Got> {
    let mut expect = Vec::new();
    let mut i = 0;
    for (k, size) in [3u32, 1, 5, 2, 8, 4].into_iter().enumerate() {
        if k % 2 == 0 {
            write(s, i);
            expect.push(Got::Plain(i));
            i += 1;
        }
        s.sim.nodes[0].p.begin_coherent_set(s.w).unwrap();
        let mut set = Vec::new();
        for _ in 0..size {
            write(s, i);
            set.push(i);
            i += 1;
            s.sim.run_for(Duration::from_micros(300));
        }
        end_set(s);
        expect.push(Got::Set(set));
    }
    expect
}

/// Every set is whole (one of the written sets, with all its samples in order).
fn assert_whole(got: &[Got], expect: &[Got], seed: u64) {
    for g in got {
        assert!(
            expect.contains(g),
            "seed {seed}: {g:?} is not a written set/sample; got {got:?}"
        );
    }
    let order: Vec<&Got> = expect.iter().filter(|e| got.contains(e)).collect();
    assert_eq!(
        got.iter().collect::<Vec<_>>(),
        order,
        "seed {seed}: out of order"
    );
}

#[test]
fn coherent_sets_reliable_30pct_loss_1000_seeds() {
    for seed in 0..1000u64 {
        let mut s = setup(seed, Faults::lossy(0.3), true);
        let expect = write_script(&mut s);
        let r = s.r;
        let mut got = Vec::new();
        let mut lost = 0;
        let n = expect.len();
        s.sim.run_until(Duration::from_secs(60), |sim| {
            let (g, l) = take(sim, r);
            // All or nothing at every step: whatever is visible is whole.
            got.extend(g);
            lost += l;
            got.len() >= n
        });
        assert_whole(&got, &expect, seed);
        assert_eq!(got, expect, "seed {seed}: reliable delivery is complete");
        assert_eq!(lost, 0, "seed {seed}");
    }
}

#[test]
fn coherent_sets_best_effort_30pct_loss_1000_seeds_all_or_nothing() {
    let mut delivered_sets = 0;
    let mut dropped = 0;
    for seed in 0..1000u64 {
        let mut s = setup(seed, Faults::lossy(0.3), false);
        let expect = write_script(&mut s);
        s.sim.run_for(Duration::from_millis(200));
        let (got, _) = take(&mut s.sim, s.r);
        assert_whole(&got, &expect, seed);
        let sets = got.iter().filter(|g| matches!(g, Got::Set(_))).count();
        delivered_sets += sets;
        dropped += 6 - sets;
    }
    // Both outcomes happen: some sets arrive whole, others lose a change and are dropped whole.
    assert!(
        delivered_sets > 0 && dropped > 0,
        "{delivered_sets} {dropped}"
    );
}

#[test]
fn set_cut_short_by_writer_deletion_is_discarded() {
    let mut s = setup(7, Faults::NONE, true);
    write(&mut s, 0);
    s.sim.nodes[0].p.begin_coherent_set(s.w).unwrap();
    for i in 1..4 {
        write(&mut s, i);
    }
    s.sim.run_for(Duration::from_millis(100));
    let (got, _) = take(&mut s.sim, s.r);
    assert_eq!(
        got,
        vec![Got::Plain(0)],
        "nothing of an open set is visible"
    );
    let (now, w) = (s.sim.now, s.w);
    s.sim.nodes[0].p.delete_writer(now, w);
    s.sim.run_for(Duration::from_secs(2));
    let (got, _) = take(&mut s.sim, s.r);
    assert!(got.is_empty(), "the set was cut short: {got:?}");
    assert!(s.sim.nodes[1].p.reader_matches(s.r).is_empty());
}

#[test]
fn late_volatile_reader_discards_the_set_it_joined_in_the_middle_of() {
    let mut sim = Sim::with_participants(3, Faults::NONE, 2);
    let now = sim.now;
    let wq = DataWriterQos::builder().history(History::KeepAll).build();
    let w = sim.nodes[0]
        .p
        .create_writer(now, WriterSpec::new("T", "M::T", false, wq))
        .unwrap();
    sim.nodes[0].p.begin_coherent_set(w).unwrap();
    for i in 0..3 {
        sim.nodes[0]
            .p
            .write(now, w, WriteChange::alive(indexed_payload(i)))
            .unwrap();
    }
    let rq = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepAll)
        .build();
    let r = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("T", "M::T", false, rq))
        .unwrap();
    assert!(sim.run_until(Duration::from_secs(5), |s| !s.nodes[1]
        .p
        .reader_matches(r)
        .is_empty()));
    let mut s = Setup { sim, w, r };
    for i in 3..5 {
        write(&mut s, i);
    }
    end_set(&mut s);
    s.sim.nodes[0].p.begin_coherent_set(s.w).unwrap();
    write(&mut s, 5);
    write(&mut s, 6);
    end_set(&mut s);
    s.sim.run_for(Duration::from_millis(500));
    let (got, _) = take(&mut s.sim, s.r);
    assert_eq!(got, vec![Got::Set(vec![5, 6])], "only the set seen whole");
}
