//! GROUP ordered access through the simulated network: the writers of one publisher group write in turn
//! (at random), the readers of a GROUP-ordered subscriber on the other participant hand the changes over
//! in the order written (the group sequence numbers), across writers, under loss, duplication and
//! reordering, whatever order repairs bring them in.

mod rtps_support;

use std::time::Duration;

use dds_runtime::qos::*;
use dds_runtime::rtps::*;
use rtps_support::*;

struct Setup {
    sim: Sim,
    w: Vec<EntityId>,
    r: Vec<EntityId>,
}

fn group_ordered() -> Presentation {
    Presentation {
        access_scope: PresentationAccessScope::Group,
        coherent_access: false,
        ordered_access: true,
    }
}

/// `writers` writers of one group on node 0 (topics T0, T1, ...), and on node 1 a reader of each of the
/// first `read` topics in one GROUP-ordered subscriber.
fn setup(seed: u64, faults: Faults, writers: usize, read: usize) -> Setup {
    let mut sim = Sim::with_participants(seed, faults, 2);
    sim.faults_on_discovery = false;
    let now = sim.now;
    let (wq, rq) = keep_all_qos(true);
    let pubq = PublisherQos::builder()
        .presentation(group_ordered())
        .build();
    let subq = SubscriberQos::builder()
        .presentation(group_ordered())
        .build();
    let tq = TopicQos::default();
    let group = WriterGroup::default();
    let mut w = Vec::new();
    let mut r = Vec::new();
    for k in 0..writers {
        let topic = format!("T{k}");
        let spec = WriterSpec::new(
            &topic,
            "M::T",
            false,
            WriterQos::new(wq.clone(), &pubq, &tq),
        );
        let id = sim.nodes[0].p.create_writer(now, spec).unwrap();
        sim.nodes[0].p.join_writer_group(now, id, &group).unwrap();
        w.push(id);
        if k < read {
            let spec = ReaderSpec::new(
                &topic,
                "M::T",
                false,
                ReaderQos::new(rq.clone(), &subq, &tq),
            );
            r.push(sim.nodes[1].p.create_reader(now, spec).unwrap());
        }
    }
    assert!(sim.run_until(Duration::from_secs(5), |s| {
        (0..read).all(|k| {
            !s.nodes[0].p.writer_matches(w[k]).is_empty()
                && !s.nodes[1].p.reader_matches(r[k]).is_empty()
        })
    }));
    Setup { sim, w, r }
}

/// Writes `n` changes, each with a writer picked at random (the index is the write order); returns the
/// indices the readers should get, in order.
fn write_random(s: &mut Setup, n: u32, read: usize) -> Vec<u32> {
    let mut expect = Vec::new();
    for i in 0..n {
        let k = s.sim.rng.below(s.w.len() as u64) as usize;
        write_indexed(&mut s.sim, s.w[k], i);
        if k < read {
            expect.push(i);
        }
        // Let some traffic through between writes now and then, so that repairs overtake new writes.
        if s.sim.rng.unit() < 0.3 {
            s.sim.step();
        }
    }
    expect
}

/// The indices the readers handed over so far, in order, with their group sequence numbers.
fn take(sim: &mut Sim, r: &[EntityId]) -> Vec<(u32, i64)> {
    let mut got = Vec::new();
    sim.nodes[1].events.retain(|e| match e {
        Event::Sample(x) if r.contains(&x.reader) => {
            let gsn = x
                .group_sequence
                .expect("a group member's change has a GSN")
                .0;
            got.push((payload_index(&x.payload), gsn));
            false
        }
        _ => true,
    });
    got
}

/// 1000 seeds with 30% loss, 10% duplication and 2 ms jitter: every change arrives, in write order.
fn run_seeds(writers: usize, read: usize, seeds: u64) {
    let only: Option<u64> = std::env::var("SEED").ok().and_then(|s| s.parse().ok());
    for seed in 0..seeds {
        if only.is_some_and(|o| o != seed) {
            continue;
        }
        let mut s = setup(seed, Faults::lossy(0.3), writers, read);
        let expect = write_random(&mut s, 40, read);
        let mut got = Vec::new();
        let r = s.r.clone();
        s.sim.run_until(Duration::from_secs(60), |sim| {
            got.extend(take(sim, &r));
            got.len() >= expect.len()
        });
        let order: Vec<u32> = got.iter().map(|(i, _)| *i).collect();
        assert_eq!(order, expect, "seed {seed}: not in write order");
        assert!(
            got.windows(2).all(|p| p[0].1 < p[1].1),
            "seed {seed}: group sequence numbers not increasing: {got:?}"
        );
    }
}

#[test]
fn two_writers_of_one_publisher_arrive_in_group_order_1000_seeds() {
    run_seeds(2, 2, 1000);
}

#[test]
fn three_writers_of_one_publisher_arrive_in_group_order_1000_seeds() {
    run_seeds(3, 3, 1000);
}

#[test]
fn changes_of_an_unread_writer_of_the_publisher_leave_no_hole_500_seeds() {
    // The third writer's topic has no reader: its numbers are holes the readers skip once the other
    // writers' heartbeats say they sent nothing else below.
    run_seeds(3, 2, 500);
}

#[test]
fn without_loss_nothing_waits() {
    // No loss: every change is handed over as it arrives (the numbers have no hole), so the readers'
    // order is the write order at every moment.
    let mut s = setup(1, Faults::NONE, 2, 2);
    let r = s.r.clone();
    for i in 0..20u32 {
        let k = (i as usize * 7 + 3) % 2;
        write_indexed(&mut s.sim, s.w[k], i);
        let start = s.sim.now;
        let mut got = Vec::new();
        assert!(s.sim.run_until(Duration::from_secs(1), |sim| {
            got.extend(take(sim, &r));
            !got.is_empty()
        }));
        assert_eq!(got[0].0, i);
        assert!(
            s.sim.now - start < Duration::from_millis(5),
            "change {i} waited"
        );
    }
}
