//! EXCLUSIVE ownership handed over on a missed deadline, DESTINATION_ORDER BY_SOURCE_TIMESTAMP, and LIFESPAN
//! on the writer's side (expired samples never reach a late-joining TRANSIENT_LOCAL reader), end to end
//! between two of our participants.
mod dcps_util;

use std::time::{Duration, SystemTime};

use dcps_util::*;
use dds_runtime::prelude::*;

const DEADLINE: Duration = Duration::from_millis(200);
/// The strong writer's samples carry x >= STRONG; the weak one's x < STRONG.
const STRONG: i32 = 1000;

/// Takes everything, returning the x of each valid sample.
fn take_xs(r: &DataReader<ShapeType>) -> Vec<i32> {
    r.take()
        .unwrap()
        .into_iter()
        .filter_map(|s| s.data.map(|d| d.x))
        .collect()
}

/// Writes with both writers every 20 ms for `d`; `strong` says whether the strong one writes too.
fn write_both(
    weak: &DataWriter<ShapeType>,
    strong: Option<&DataWriter<ShapeType>>,
    d: Duration,
    x: &mut i32,
) {
    let end = std::time::Instant::now() + d;
    while std::time::Instant::now() < end {
        weak.write(&shape("BLUE", *x)).unwrap();
        if let Some(s) = strong {
            s.write(&shape("BLUE", STRONG + *x)).unwrap();
        }
        *x += 1;
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn exclusive_owner_hands_over_after_its_deadline_and_takes_back() {
    let (p1, p2) = (participant(211), participant(211));
    let (mut wq, mut rq) = reliable_keep_all();
    wq.ownership = Ownership::Exclusive;
    rq.ownership = Ownership::Exclusive;
    wq.deadline = Deadline(DEADLINE);
    rq.deadline = Deadline(DEADLINE);
    let mut sq = wq.clone();
    sq.ownership_strength = OwnershipStrength(10);
    wq.ownership_strength = OwnershipStrength(1);
    let strong = writer::<ShapeType>(&p1, "Square", &sq);
    let weak = writer::<ShapeType>(&p1, "Square", &wq);
    let r = reader::<ShapeType>(&p2, "Square", &rq);
    assert!(wait_until(MATCH_TIMEOUT, || {
        r.subscription_matched_status().current_count == 2
            && strong.publication_matched_status().current_count == 1
            && weak.publication_matched_status().current_count == 1
    }));

    // The strong writer owns the instance: the weak one's samples are dropped.
    strong.write(&shape("BLUE", STRONG)).unwrap();
    assert!(wait_until(Duration::from_secs(5), || r.sample_count() == 1));
    let mut x = 1;
    write_both(&weak, Some(&strong), Duration::from_millis(150), &mut x);
    std::thread::sleep(Duration::from_millis(50));
    let got = take_xs(&r);
    assert!(
        got.iter().all(|x| *x >= STRONG),
        "only the owner's samples: {got:?}"
    );

    // The strong one stops: once its deadline has passed, the weak one's samples are accepted.
    write_both(&weak, None, Duration::from_millis(600), &mut x);
    std::thread::sleep(Duration::from_millis(50));
    let got = take_xs(&r);
    let weak_got = got.iter().filter(|x| **x < STRONG).count();
    assert!(weak_got >= 10, "the weak writer took over: {got:?}");
    assert!(weak_got < 30, "not before the deadline passed: {got:?}");

    // The strong one resumes: it owns the instance again.
    strong.write(&shape("BLUE", STRONG + x)).unwrap();
    assert!(wait_until(Duration::from_secs(5), || {
        r.read()
            .unwrap()
            .iter()
            .any(|s| s.data.as_ref().is_some_and(|d| d.x >= STRONG))
    }));
    take_xs(&r);
    write_both(&weak, Some(&strong), Duration::from_millis(150), &mut x);
    std::thread::sleep(Duration::from_millis(50));
    let got = take_xs(&r);
    assert!(!got.is_empty());
    assert!(
        got.iter().all(|x| *x >= STRONG),
        "the strong writer owns again: {got:?}"
    );
}

#[test]
fn by_source_timestamp_drops_older_samples() {
    let (p1, p2) = (participant(212), participant(212));
    let (mut wq, mut rq) = reliable_keep_all();
    wq.destination_order = DestinationOrder::BySourceTimestamp;
    rq.destination_order = DestinationOrder::BySourceTimestamp;
    let w1 = writer::<ShapeType>(&p1, "Square", &wq);
    let w2 = writer::<ShapeType>(&p1, "Square", &wq);
    let by_source = reader::<ShapeType>(&p2, "Square", &rq);
    let by_reception = reader::<ShapeType>(&p2, "Square", &reliable_keep_all().1);
    assert!(wait_until(MATCH_TIMEOUT, || {
        by_source.subscription_matched_status().current_count == 2
            && by_reception.subscription_matched_status().current_count == 2
            && w1.publication_matched_status().current_count == 2
            && w2.publication_matched_status().current_count == 2
    }));

    let t0 = SystemTime::now();
    w1.write_w_timestamp(&shape("BLUE", 1), t0 + Duration::from_secs(10))
        .unwrap();
    assert!(wait_until(Duration::from_secs(5), || by_source
        .sample_count()
        == 1));
    // Older than the newest of the instance: dropped. Another instance is not affected.
    w2.write_w_timestamp(&shape("BLUE", 2), t0 + Duration::from_secs(5))
        .unwrap();
    w2.write_w_timestamp(&shape("RED", 3), t0).unwrap();
    w2.write_w_timestamp(&shape("BLUE", 4), t0 + Duration::from_secs(20))
        .unwrap();
    assert!(wait_until(Duration::from_secs(5), || {
        by_reception.sample_count() == 4 && by_source.sample_count() == 3
    }));
    std::thread::sleep(Duration::from_millis(100));
    let mut xs = take_xs(&by_source);
    xs.sort();
    assert_eq!(xs, vec![1, 3, 4]);
    let mut xs = take_xs(&by_reception);
    xs.sort();
    assert_eq!(
        xs,
        vec![1, 2, 3, 4],
        "BY_RECEPTION_TIMESTAMP keeps everything"
    );
}

#[test]
fn writer_lifespan_expires_its_history_for_late_joiners() {
    let (p1, p2) = (participant(213), participant(213));
    let durable = |q: &mut DataWriterQos| {
        q.durability = Durability::TransientLocal;
        // Long enough for a late reader to match before the second sample expires, on a loaded machine.
        q.lifespan = Lifespan(Duration::from_millis(1000));
    };
    let (mut wq, mut rq) = reliable_keep_all();
    durable(&mut wq);
    rq.durability = Durability::TransientLocal;
    let w = writer::<ShapeType>(&p1, "Square", &wq);
    // The participants know each other before the late readers come: matching is then quick.
    assert!(wait_until(MATCH_TIMEOUT, || !p1
        .discovered_participants()
        .is_empty()));

    // Stamped an hour ahead, so that the reader's own lifespan check (which counts from the source
    // timestamp) would keep it: only the writer's expiry can hold it back.
    let ahead = SystemTime::now() + Duration::from_secs(3600);
    w.write_w_timestamp(&shape("BLUE", 1), ahead).unwrap();
    std::thread::sleep(Duration::from_millis(1300));
    let late = reader::<ShapeType>(&p2, "Square", &rq);
    assert!(wait_until(MATCH_TIMEOUT, || late
        .subscription_matched_status()
        .current_count
        == 1));
    let mut got = Vec::new();
    wait_until(Duration::from_millis(800), || {
        got.extend(take_xs(&late));
        false
    });
    assert!(
        got.is_empty(),
        "an expired sample reached a late joiner: {got:?}"
    );

    // A sample written just before a reader joins is still in the history: it is received.
    w.write_w_timestamp(&shape("RED", 2), ahead).unwrap();
    let late2 = reader::<ShapeType>(&p2, "Square", &rq);
    let mut got = Vec::new();
    assert!(wait_until(Duration::from_secs(2), || {
        got.extend(take_xs(&late2));
        !got.is_empty()
    }));
    assert_eq!(got, vec![2]);
}
