//! Group coherent sets (GROUP access scope, RTPS 2.5 §8.7.6) through the simulated network: two writers of
//! one publisher group, two readers on the other participant. A group set reaches the readers whole or not
//! at all, its changes in the order written across the writers (group sequence numbers: a writer's part
//! comes in pieces when the other writer wrote in between), and group sets arrive in the order they were
//! written, under loss, duplication and reordering.

mod rtps_support;

use std::time::Duration;

use dds_runtime::qos::*;
use dds_runtime::rtps::*;
use rtps_support::*;

/// What the readers got, in order: a sample outside any set (`Plain`), or a whole group set: its pieces
/// (0 = writer A's part, 1 = writer B's), each a run of consecutive changes, in delivery order.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Got {
    Plain(u32),
    Group(Vec<(usize, Vec<u32>)>),
}

struct Setup {
    sim: Sim,
    group: WriterGroup,
    w: [EntityId; 2],
    r: [EntityId; 2],
}

fn setup(seed: u64, faults: Faults, reliable: bool) -> Setup {
    let mut sim = Sim::with_participants(seed, faults, 2);
    sim.faults_on_discovery = false;
    let now = sim.now;
    let (wq, rq) = keep_all_qos(reliable);
    let group = WriterGroup::default();
    let mut w = [EntityId::UNKNOWN; 2];
    let mut r = [EntityId::UNKNOWN; 2];
    for (k, topic) in ["A", "B"].into_iter().enumerate() {
        w[k] = sim.nodes[0]
            .p
            .create_writer(now, WriterSpec::new(topic, "M::T", false, wq.clone()))
            .unwrap();
        sim.nodes[0].p.join_writer_group(now, w[k], &group).unwrap();
        r[k] = sim.nodes[1]
            .p
            .create_reader(now, ReaderSpec::new(topic, "M::T", false, rq.clone()))
            .unwrap();
    }
    assert!(sim.run_until(Duration::from_secs(5), |s| (0..2).all(|k| {
        !s.nodes[0].p.writer_matches(w[k]).is_empty()
            && !s.nodes[1].p.reader_matches(r[k]).is_empty()
    })));
    Setup { sim, group, w, r }
}

/// Takes what the readers delivered so far: consecutive parts of one group set form one `Group`. Also
/// returns the count of samples reported lost.
fn take(sim: &mut Sim, r: [EntityId; 2]) -> (Vec<Got>, u64) {
    let mut got = Vec::new();
    let mut lost = 0;
    let mut last_group = None;
    sim.nodes[1].events.retain(|e| match e {
        Event::Sample(x) if r.contains(&x.reader) => {
            got.push(Got::Plain(payload_index(&x.payload)));
            last_group = None;
            false
        }
        Event::CoherentSet {
            reader,
            samples,
            group,
            ..
        } if r.contains(reader) => {
            let k = usize::from(*reader == r[1]);
            let part = (
                k,
                samples.iter().map(|x| payload_index(&x.payload)).collect(),
            );
            match (&mut got.last_mut(), group) {
                (Some(Got::Group(parts)), Some(g)) if last_group == Some(*g) => parts.push(part),
                _ => got.push(Got::Group(vec![part])),
            }
            last_group = *group;
            false
        }
        Event::SampleLost { reader, count, .. } if r.contains(reader) => {
            lost += count;
            false
        }
        _ => true,
    });
    (got, lost)
}

fn write(s: &mut Setup, k: usize, i: u32) {
    write_indexed(&mut s.sim, s.w[k], i);
}

fn end_set(s: &mut Setup, k: usize) {
    end_coherent(&mut s.sim, s.w[k]);
}

/// Writes group sets spanning both writers (and one writer only), with plain samples between them;
/// returns what a reader that misses nothing gets.
fn write_script(s: &mut Setup) -> Vec<Got> {
    let mut expect = Vec::new();
    let mut i = 0;
    // (changes of A, changes of B) per set; the writes interleave.
    for (k, (na, nb)) in [(2u32, 1u32), (1, 3), (3, 0), (2, 2), (0, 2), (4, 1)]
        .into_iter()
        .enumerate()
    {
        if k % 2 == 1 {
            write(s, 0, i);
            expect.push(Got::Plain(i));
            i += 1;
        }
        let g = s.group.clone();
        s.sim.nodes[0].p.begin_group_set(&g);
        for w in s.w {
            s.sim.nodes[0].p.begin_coherent_set(w).unwrap();
        }
        // The pieces in write order: runs of one writer's changes.
        let mut pieces: Vec<(usize, Vec<u32>)> = Vec::new();
        for j in 0..na.max(nb) {
            for (w, n) in [(0, na), (1, nb)] {
                if j < n {
                    write(s, w, i);
                    match pieces.last_mut() {
                        Some((k, v)) if *k == w => v.push(i),
                        _ => pieces.push((w, vec![i])),
                    }
                    i += 1;
                    s.sim.run_for(Duration::from_micros(200));
                }
            }
        }
        end_set(s, 0);
        end_set(s, 1);
        s.sim.nodes[0].p.end_group_set(&g);
        expect.push(Got::Group(pieces));
    }
    expect
}

/// Every group set delivered is one that was written, whole and in write order across its writers; sets
/// come in the order written.
fn assert_whole(got: &[Got], expect: &[Got], seed: u64) {
    for g in got {
        assert!(
            expect.contains(g),
            "seed {seed}: {g:?} is not a written group set; got {got:?}"
        );
    }
    let sets: Vec<&Got> = got.iter().filter(|g| matches!(g, Got::Group(_))).collect();
    let order: Vec<&Got> = expect.iter().filter(|e| sets.contains(e)).collect();
    assert_eq!(sets, order, "seed {seed}: group sets out of order");
}

#[test]
fn group_sets_reliable_30pct_loss_1000_seeds() {
    for seed in 0..1000u64 {
        let mut s = setup(seed, Faults::lossy(0.3), true);
        let expect = write_script(&mut s);
        let n = expect.len();
        let mut got = Vec::new();
        let mut lost = 0;
        let r = s.r;
        s.sim.run_until(Duration::from_secs(60), |sim| {
            let (g, l) = take(sim, r);
            got.extend(g);
            lost += l;
            got.len() >= n
        });
        assert_whole(&got, &expect, seed);
        assert_eq!(
            got.len(),
            n,
            "seed {seed}: reliable delivery is complete: {got:?}"
        );
        assert_eq!(lost, 0, "seed {seed}");
    }
}

#[test]
fn group_sets_best_effort_30pct_loss_1000_seeds_all_or_nothing() {
    let (mut delivered, mut dropped) = (0, 0);
    for seed in 0..1000u64 {
        let mut s = setup(seed, Faults::lossy(0.3), false);
        let expect = write_script(&mut s);
        s.sim.run_for(Duration::from_millis(200));
        let r = s.r;
        let (got, _) = take(&mut s.sim, r);
        assert_whole(&got, &expect, seed);
        let sets = got.iter().filter(|g| matches!(g, Got::Group(_))).count();
        delivered += sets;
        dropped += 6 - sets;
    }
    // Both outcomes happen: group sets arriving whole, and sets with a lost change dropped whole.
    assert!(delivered > 0 && dropped > 0, "{delivered} {dropped}");
}

#[test]
fn group_set_cut_short_by_deleting_one_writer_is_discarded() {
    let mut s = setup(3, Faults::NONE, true);
    let g = s.group.clone();
    s.sim.nodes[0].p.begin_group_set(&g);
    for w in s.w {
        s.sim.nodes[0].p.begin_coherent_set(w).unwrap();
    }
    write(&mut s, 0, 0);
    write(&mut s, 1, 1);
    end_set(&mut s, 0);
    s.sim.run_for(Duration::from_millis(100));
    let r = s.r;
    let (got, _) = take(&mut s.sim, r);
    assert!(
        got.is_empty(),
        "writer A's part alone is not visible: {got:?}"
    );
    let (now, w) = (s.sim.now, s.w[1]);
    s.sim.nodes[0].p.delete_writer(now, w);
    s.sim.nodes[0].p.end_group_set(&g);
    // The next group set (writer A alone) completes; the cut one is discarded, never shown.
    s.sim.nodes[0].p.begin_group_set(&g);
    s.sim.nodes[0].p.begin_coherent_set(s.w[0]).unwrap();
    write(&mut s, 0, 2);
    end_set(&mut s, 0);
    s.sim.nodes[0].p.end_group_set(&g);
    s.sim.run_for(Duration::from_secs(2));
    let (got, lost) = take(&mut s.sim, r);
    assert_eq!(got, vec![Got::Group(vec![(0, vec![2])])]);
    assert_eq!(lost, 1, "writer A's part of the cut set is reported lost");
}

#[test]
fn group_set_with_a_writer_no_reader_matches_completes() {
    // A third writer on a topic nobody reads takes part in the set: its part never comes, yet the set is
    // whole for the readers that exist (the digest names it, and it is a known, unmatched writer).
    let mut s = setup(5, Faults::NONE, true);
    let now = s.sim.now;
    let wq = DataWriterQos::builder().history(History::KeepAll).build();
    let c = s.sim.nodes[0]
        .p
        .create_writer(now, WriterSpec::new("C", "M::T", false, wq))
        .unwrap();
    let g = s.group.clone();
    s.sim.nodes[0].p.join_writer_group(now, c, &g).unwrap();
    s.sim.run_for(Duration::from_millis(500));
    s.sim.nodes[0].p.begin_group_set(&g);
    for w in [s.w[0], s.w[1], c] {
        s.sim.nodes[0].p.begin_coherent_set(w).unwrap();
    }
    write(&mut s, 0, 0);
    let now = s.sim.now;
    s.sim.nodes[0]
        .p
        .write(now, c, WriteChange::alive(indexed_payload(99)))
        .unwrap();
    write(&mut s, 1, 1);
    end_set(&mut s, 0);
    end_set(&mut s, 1);
    let now = s.sim.now;
    s.sim.nodes[0].p.end_coherent_set(now, c).unwrap();
    s.sim.nodes[0].p.end_group_set(&g);
    s.sim.run_for(Duration::from_millis(500));
    let r = s.r;
    let (got, _) = take(&mut s.sim, r);
    assert_eq!(got, vec![Got::Group(vec![(0, vec![0]), (1, vec![1])])]);
}
