//! PRESENTATION between two of our participants: coherent sets through `begin_coherent_changes` /
//! `end_coherent_changes` are seen whole or not at all, a set cut short by the writer's deletion is never
//! seen, ordered access with INSTANCE scope groups each instance's samples, and the access scope nests.
mod dcps_util;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

fn presentation(scope: PresentationAccessScope, coherent: bool, ordered: bool) -> Presentation {
    Presentation {
        access_scope: scope,
        coherent_access: coherent,
        ordered_access: ordered,
    }
}

/// A writer under a publisher and a reader under a subscriber, both with `p`, matched.
fn pair(
    domain: u32,
    p: Presentation,
) -> (
    (DomainParticipant, DomainParticipant),
    Publisher,
    DataWriter<ShapeType>,
    Subscriber,
    DataReader<ShapeType>,
) {
    let (p1, p2) = (participant(domain), participant(domain));
    let (wq, rq) = reliable_keep_all();
    let publ = p1
        .create_publisher(&PublisherQos::builder().presentation(p).build())
        .unwrap();
    let sub = p2
        .create_subscriber(&SubscriberQos::builder().presentation(p).build())
        .unwrap();
    let t1 = p1
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let t2 = p2
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let w = publ.create_datawriter(&t1, &wq).unwrap();
    let r = sub.create_datareader(&t2, &rq).unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || w
        .publication_matched_status()
        .current_count
        == 1
        && r.subscription_matched_status().current_count == 1));
    ((p1, p2), publ, w, sub, r)
}

/// Watches the reader's sample count from another thread and records every value it saw.
fn watch(r: &DataReader<ShapeType>) -> (Arc<Mutex<Vec<usize>>>, Arc<AtomicBool>) {
    let seen = Arc::new(Mutex::new(Vec::new()));
    let stop = Arc::new(AtomicBool::new(false));
    let (r, s, st) = (r.clone(), seen.clone(), stop.clone());
    std::thread::spawn(move || {
        while !st.load(Ordering::Relaxed) {
            let n = r.sample_count();
            let mut v = s.lock().unwrap();
            if v.last() != Some(&n) {
                v.push(n);
            }
            drop(v);
            std::thread::sleep(Duration::from_micros(200));
        }
    });
    (seen, stop)
}

#[test]
fn coherent_set_is_seen_whole_or_not_at_all() {
    let (_ps, publ, w, _sub, r) = pair(
        135,
        presentation(PresentationAccessScope::Topic, true, false),
    );
    let (seen, stop) = watch(&r);
    for round in 0..3 {
        publ.begin_coherent_changes().unwrap();
        for i in 0..5 {
            w.write(&shape(["RED", "BLUE"][i % 2], round * 10 + i as i32))
                .unwrap();
            std::thread::sleep(Duration::from_millis(15));
        }
        // Everything sent and acknowledged, but the set is open: nothing is visible.
        w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
        std::thread::sleep(Duration::from_millis(50));
        assert_eq!(r.sample_count(), 5 * round as usize, "round {round}");
        publ.end_coherent_changes().unwrap();
        assert!(wait_until(Duration::from_secs(5), || r.sample_count()
            == 5 * (round as usize + 1)));
    }
    stop.store(true, Ordering::Relaxed);
    let seen = seen.lock().unwrap().clone();
    assert!(
        seen.iter().all(|n| n % 5 == 0),
        "a partial set was visible: {seen:?}"
    );
    let xs: Vec<i32> = r
        .take()
        .unwrap()
        .iter()
        .map(|s| s.data.as_ref().unwrap().x)
        .collect();
    assert_eq!(xs.len(), 15);
    assert!(matches!(
        publ.end_coherent_changes(),
        Err(DdsError::PreconditionNotMet(_))
    ));
}

#[test]
fn nested_coherent_changes_end_with_the_outermost() {
    let (_ps, publ, w, _sub, r) = pair(
        136,
        presentation(PresentationAccessScope::Topic, true, false),
    );
    publ.begin_coherent_changes().unwrap();
    w.write(&shape("RED", 1)).unwrap();
    publ.begin_coherent_changes().unwrap();
    w.write(&shape("RED", 2)).unwrap();
    publ.end_coherent_changes().unwrap();
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(r.sample_count(), 0, "the outer set is still open");
    publ.end_coherent_changes().unwrap();
    assert!(wait_until(Duration::from_secs(5), || r.sample_count() == 2));
}

#[test]
fn set_cut_short_by_deleting_the_writer_is_never_seen() {
    let (_ps, publ, w, _sub, r) = pair(
        137,
        presentation(PresentationAccessScope::Topic, true, false),
    );
    w.write(&shape("GREEN", 0)).unwrap();
    publ.begin_coherent_changes().unwrap();
    for i in 1..4 {
        w.write(&shape("RED", i)).unwrap();
    }
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    drop(w);
    assert!(wait_until(Duration::from_secs(5), || r
        .subscription_matched_status()
        .current_count
        == 0));
    std::thread::sleep(Duration::from_millis(100));
    let got: Vec<Sample<ShapeType>> = r.take().unwrap();
    let colors: Vec<&str> = got
        .iter()
        .filter_map(|s| s.data.as_ref().map(|d| d.color.as_str()))
        .collect();
    assert_eq!(colors, vec!["GREEN"], "{got:?}");
}

#[test]
fn ordered_access_instance_scope_groups_instances() {
    let (_ps, _publ, w, _sub, r) = pair(
        138,
        presentation(PresentationAccessScope::Instance, false, true),
    );
    for i in 0..3 {
        w.write(&shape("RED", i)).unwrap();
        w.write(&shape("BLUE", i)).unwrap();
    }
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    assert!(wait_until(Duration::from_secs(5), || r.sample_count() == 6));
    let got: Vec<(String, i32)> = r
        .take()
        .unwrap()
        .into_iter()
        .map(|s| s.data.map(|d| (d.color, d.x)).unwrap())
        .collect();
    let colors: Vec<&str> = got.iter().map(|(c, _)| c.as_str()).collect();
    assert!(
        colors == ["RED", "RED", "RED", "BLUE", "BLUE", "BLUE"]
            || colors == ["BLUE", "BLUE", "BLUE", "RED", "RED", "RED"],
        "{got:?}"
    );
    // Each instance in write order.
    let red: Vec<i32> = got
        .iter()
        .filter(|(c, _)| c == "RED")
        .map(|(_, x)| *x)
        .collect();
    assert_eq!(red, vec![0, 1, 2]);
}

#[test]
fn topic_scope_reads_in_write_order_across_instances() {
    let (_ps, _publ, w, _sub, r) = pair(
        139,
        presentation(PresentationAccessScope::Topic, false, true),
    );
    for i in 0..3 {
        w.write(&shape("RED", i)).unwrap();
        w.write(&shape("BLUE", i)).unwrap();
    }
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    assert!(wait_until(Duration::from_secs(5), || r.sample_count() == 6));
    let colors: Vec<String> = r
        .take()
        .unwrap()
        .into_iter()
        .map(|s| s.data.unwrap().color)
        .collect();
    assert_eq!(colors, ["RED", "BLUE", "RED", "BLUE", "RED", "BLUE"]);
}

#[test]
fn access_scope_nests() {
    let p = participant(135);
    let sub = p
        .create_subscriber(
            &SubscriberQos::builder()
                .presentation(presentation(PresentationAccessScope::Group, true, true))
                .build(),
        )
        .unwrap();
    assert!(sub.end_access().is_err());
    sub.begin_access().unwrap();
    sub.begin_access().unwrap();
    assert!(sub.in_access());
    sub.end_access().unwrap();
    assert!(sub.in_access());
    sub.end_access().unwrap();
    assert!(!sub.in_access());
    assert!(sub.end_access().is_err());
}

/// Two writers (topics Square and Circle) under one GROUP-scope coherent publisher and two readers under
/// one GROUP-scope coherent subscriber, matched.
#[allow(clippy::type_complexity)]
fn group_pair(
    domain: u32,
    g: Presentation,
) -> (
    (DomainParticipant, DomainParticipant),
    Publisher,
    Subscriber,
    Vec<DataWriter<ShapeType>>,
    Vec<DataReader<ShapeType>>,
) {
    let (p1, p2) = (participant(domain), participant(domain));
    let (wq, rq) = reliable_keep_all();
    let publ = p1
        .create_publisher(&PublisherQos::builder().presentation(g).build())
        .unwrap();
    let sub = p2
        .create_subscriber(&SubscriberQos::builder().presentation(g).build())
        .unwrap();
    let mut ws = Vec::new();
    let mut rs = Vec::new();
    for name in ["Square", "Circle"] {
        let t1 = p1
            .create_topic::<ShapeType>(name, &TopicQos::default())
            .unwrap();
        let t2 = p2
            .create_topic::<ShapeType>(name, &TopicQos::default())
            .unwrap();
        ws.push(publ.create_datawriter(&t1, &wq).unwrap());
        rs.push(sub.create_datareader(&t2, &rq).unwrap());
    }
    assert!(wait_until(MATCH_TIMEOUT, || {
        ws.iter()
            .all(|w| w.publication_matched_status().current_count == 1)
            && rs
                .iter()
                .all(|r| r.subscription_matched_status().current_count == 1)
    }));
    ((p1, p2), publ, sub, ws, rs)
}

/// GROUP scope: a coherent set spans the publisher's two writers (two topics) and reaches the two readers
/// of the subscriber only once both parts arrived; a set cut short by deleting one of its writers is never
/// seen, not even the other writer's whole part; the next set (one writer only) arrives.
#[test]
fn group_set_spans_writers_and_a_cut_set_is_never_seen() {
    let (_ps, publ, _sub, mut ws, rs) = group_pair(
        138,
        presentation(PresentationAccessScope::Group, true, false),
    );
    // Set 1: both writers.
    publ.begin_coherent_changes().unwrap();
    ws[0].write(&shape("RED", 1)).unwrap();
    ws[1].write(&shape("RED", 1)).unwrap();
    for w in &ws {
        w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    }
    std::thread::sleep(Duration::from_millis(50));
    assert_eq!(rs[0].sample_count() + rs[1].sample_count(), 0, "set open");
    publ.end_coherent_changes().unwrap();
    assert!(wait_until(Duration::from_secs(5), || rs
        .iter()
        .all(|r| r.sample_count() == 1)));
    // Set 2: cut short by deleting the Circle writer before the set ends.
    publ.begin_coherent_changes().unwrap();
    ws[0].write(&shape("RED", 2)).unwrap();
    ws[1].write(&shape("RED", 2)).unwrap();
    for w in &ws {
        w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    }
    drop(ws.pop());
    assert!(wait_until(Duration::from_secs(5), || rs[1]
        .subscription_matched_status()
        .current_count
        == 0));
    publ.end_coherent_changes().unwrap();
    // Set 3: the Square writer alone.
    publ.begin_coherent_changes().unwrap();
    ws[0].write(&shape("RED", 3)).unwrap();
    publ.end_coherent_changes().unwrap();
    assert!(wait_until(Duration::from_secs(5), || rs[0].sample_count() == 2));
    std::thread::sleep(Duration::from_millis(100));
    let xs: Vec<i32> = rs[0]
        .take()
        .unwrap()
        .iter()
        .filter_map(|s| s.data.as_ref().map(|d| d.x))
        .collect();
    assert_eq!(xs, vec![1, 3], "the cut set is never seen");
}

/// Counts what both readers hold at each `on_data_on_readers`.
struct SeesBoth {
    readers: Vec<DataReader<ShapeType>>,
    calls: Arc<Mutex<Vec<(usize, usize)>>>,
}

impl SubscriberListener for SeesBoth {
    fn on_data_on_readers(&self, _s: &Subscriber) {
        let c = (
            self.readers[0].sample_count(),
            self.readers[1].sample_count(),
        );
        self.calls.lock().unwrap().push(c);
    }
}

/// GROUP scope: `on_data_on_readers` fires once per group set, when both readers hold their part.
#[test]
fn data_on_readers_fires_once_per_group_set_with_all_of_it() {
    let (_ps, publ, sub, ws, rs) = group_pair(
        139,
        presentation(PresentationAccessScope::Group, true, false),
    );
    let calls = Arc::new(Mutex::new(Vec::new()));
    sub.set_listener(
        Box::new(SeesBoth {
            readers: rs.clone(),
            calls: calls.clone(),
        }),
        StatusMask::DATA_ON_READERS,
    )
    .unwrap();
    for set in 1..=3 {
        publ.begin_coherent_changes().unwrap();
        for i in 0..2 {
            ws[0].write(&shape("RED", set * 10 + i)).unwrap();
            ws[1].write(&shape("RED", set * 10 + i)).unwrap();
        }
        publ.end_coherent_changes().unwrap();
        let n = 2 * set as usize;
        assert!(wait_until(Duration::from_secs(5), || rs
            .iter()
            .all(|r| r.sample_count() == n)));
        std::thread::sleep(Duration::from_millis(50));
    }
    let calls = calls.lock().unwrap().clone();
    assert_eq!(
        calls,
        vec![(2, 2), (4, 4), (6, 6)],
        "once per set, all of it"
    );
}

/// GROUP ordered access: `get_datareaders` lists the subscriber's readers once per sample, in the order
/// the samples were written across the publisher's writers; reading one sample from each listed reader in
/// turn gives the samples in that order.
#[test]
fn group_ordered_access_lists_readers_in_sample_order() {
    let ordered = presentation(PresentationAccessScope::Group, false, true);
    let (_ps, _publ, sub, ws, rs) = group_pair(208, ordered);
    let writes = [(0, 1), (1, 1), (0, 2), (1, 2), (1, 3), (0, 3)];
    for &(w, x) in &writes {
        ws[w].write(&shape("RED", x)).unwrap();
    }
    assert_eq!(read_in_listed_order(&sub, &rs, writes.len()), writes);
    let any = (
        SampleStateMask::ANY,
        ViewStateMask::ANY,
        InstanceStateMask::ANY,
    );
    assert!(sub.get_datareaders(any.0, any.1, any.2).unwrap().is_empty());
}

/// GROUP scope with coherent and ordered access: a group coherent set whose writers take turns is handed
/// over as one, in the order written across the writers. Inside an access scope `get_datareaders` lists
/// the readers once per sample in that order, and reading one sample from each listed reader in turn gives
/// the publisher's write order, set after set (before, each writer's part came whole, writer by writer).
#[test]
fn group_coherent_set_is_read_in_write_order_across_writers() {
    let scope = presentation(PresentationAccessScope::Group, true, true);
    let (_ps, publ, sub, ws, rs) = group_pair(35, scope);
    let sets: [&[(usize, i32)]; 2] = [
        &[(0, 1), (1, 1), (0, 2), (1, 2), (1, 3), (0, 3)],
        &[(1, 4), (0, 4), (0, 5), (1, 5)],
    ];
    for set in sets {
        publ.begin_coherent_changes().unwrap();
        for &(w, x) in set {
            ws[w].write(&shape("RED", x)).unwrap();
        }
        publ.end_coherent_changes().unwrap();
    }
    let writes: Vec<(usize, i32)> = sets.concat();
    assert_eq!(read_in_listed_order(&sub, &rs, writes.len()), writes);
}

/// Once `n` samples are held: inside one access scope, one sample taken from each reader in the order
/// `get_datareaders` lists them (one entry per sample), as (reader index, x). Equal to the write order, it
/// shows the list names each sample's reader in that order.
fn read_in_listed_order(
    sub: &Subscriber,
    rs: &[DataReader<ShapeType>],
    n: usize,
) -> Vec<(usize, i32)> {
    let any = (
        SampleStateMask::ANY,
        ViewStateMask::ANY,
        InstanceStateMask::ANY,
    );
    assert!(wait_until(MATCH_TIMEOUT, || sub
        .get_datareaders(any.0, any.1, any.2)
        .unwrap()
        .len()
        == n));
    sub.begin_access().unwrap();
    let list = sub
        .get_datareaders(SampleStateMask::NOT_READ, any.1, any.2)
        .unwrap();
    let mut seen = Vec::new();
    for h in &list {
        let (i, r) = rs
            .iter()
            .enumerate()
            .find(|(_, r)| r.instance_handle() == *h)
            .unwrap();
        let s = r.select().max_samples(1).take().unwrap();
        seen.push((i, s[0].data.as_ref().unwrap().x));
    }
    sub.end_access().unwrap();
    seen
}

/// GROUP coherent access: inside `begin_access` / `end_access` the subscriber's readers never show part of
/// a group set. A writer thread ends 300 group sets of one sample per writer as fast as it can while this
/// thread counts both readers' samples inside an access scope, over and over: the counts are always
/// equal (one reader holding a set's part that the other does not yet hold is a split set).
#[test]
fn group_set_is_never_split_across_readers_inside_an_access_scope() {
    const SETS: i32 = 300;
    let (_ps, publ, sub, ws, rs) = group_pair(
        209,
        presentation(PresentationAccessScope::Group, true, false),
    );
    let writer = std::thread::spawn(move || {
        for set in 0..SETS {
            publ.begin_coherent_changes().unwrap();
            ws[0].write(&shape("RED", set)).unwrap();
            ws[1].write(&shape("RED", set)).unwrap();
            publ.end_coherent_changes().unwrap();
        }
        (publ, ws)
    });
    let mut splits = Vec::new();
    let deadline = std::time::Instant::now() + Duration::from_secs(30);
    loop {
        sub.begin_access().unwrap();
        let counts = (rs[0].sample_count(), rs[1].sample_count());
        sub.end_access().unwrap();
        if counts.0 != counts.1 {
            splits.push(counts);
        }
        if counts == (SETS as usize, SETS as usize) || std::time::Instant::now() > deadline {
            break;
        }
    }
    let _keep = writer.join().unwrap();
    assert_eq!(
        (rs[0].sample_count(), rs[1].sample_count()),
        (SETS as usize, SETS as usize)
    );
    assert!(splits.is_empty(), "split sets seen: {splits:?}");
}

/// GROUP access scope: while `begin_access` is open the readers' contents do not change; what arrived
/// meanwhile appears at `end_access`.
#[test]
fn access_scope_holds_back_changes_until_it_ends() {
    let (_ps, publ, sub, ws, rs) = group_pair(
        210,
        presentation(PresentationAccessScope::Group, true, false),
    );
    sub.begin_access().unwrap();
    publ.begin_coherent_changes().unwrap();
    ws[0].write(&shape("RED", 1)).unwrap();
    ws[1].write(&shape("RED", 1)).unwrap();
    publ.end_coherent_changes().unwrap();
    for w in &ws {
        w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    }
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!((rs[0].sample_count(), rs[1].sample_count()), (0, 0));
    sub.end_access().unwrap();
    assert_eq!((rs[0].sample_count(), rs[1].sample_count()), (1, 1));
}

/// A publisher and a subscriber of the same participant: a coherent set is all or nothing there too, with
/// TOPIC scope (one writer, two instances) and GROUP scope (two writers on two topics, read by two readers
/// of one subscriber). Such a pair does not take the intra-process path, which hands samples over as they
/// are written (`rtps/participant/local.rs`, `pair_qualifies`): it goes through the RTPS reader.
#[test]
fn coherent_sets_are_all_or_nothing_within_one_participant() {
    let p = participant(117);
    let (wq, rq) = reliable_keep_all();
    let endpoints = |scope, names: &[&str]| {
        let pres = presentation(scope, true, false);
        let publ = p
            .create_publisher(&PublisherQos::builder().presentation(pres).build())
            .unwrap();
        let sub = p
            .create_subscriber(&SubscriberQos::builder().presentation(pres).build())
            .unwrap();
        let mut ws = Vec::new();
        let mut rs = Vec::new();
        for name in names {
            let t = p
                .create_topic::<ShapeType>(name, &TopicQos::default())
                .unwrap();
            ws.push(publ.create_datawriter(&t, &wq).unwrap());
            rs.push(sub.create_datareader(&t, &rq).unwrap());
        }
        assert!(wait_until(MATCH_TIMEOUT, || rs
            .iter()
            .all(|r| r.subscription_matched_status().current_count == 1)));
        (publ, sub, ws, rs)
    };
    let (topic_pub, _s1, tw, tr) = endpoints(PresentationAccessScope::Topic, &["SameTopic"]);
    let (group_pub, _s2, gw, gr) = endpoints(
        PresentationAccessScope::Group,
        &["SameGroupA", "SameGroupB"],
    );
    let watched: Vec<_> = tr.iter().chain(&gr).map(watch).collect();
    for round in 0..3usize {
        topic_pub.begin_coherent_changes().unwrap();
        group_pub.begin_coherent_changes().unwrap();
        for i in 0..4 {
            let x = (round * 10 + i) as i32;
            tw[0].write(&shape(["RED", "BLUE"][i % 2], x)).unwrap();
            gw[i % 2].write(&shape("RED", x)).unwrap();
            std::thread::sleep(Duration::from_millis(10));
        }
        for w in tw.iter().chain(&gw) {
            w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
        }
        std::thread::sleep(Duration::from_millis(50));
        let counts =
            |rs: &[DataReader<ShapeType>]| rs.iter().map(|r| r.sample_count()).collect::<Vec<_>>();
        assert_eq!(counts(&tr), [4 * round], "round {round}: TOPIC set open");
        assert_eq!(
            counts(&gr),
            [2 * round, 2 * round],
            "round {round}: GROUP set open"
        );
        topic_pub.end_coherent_changes().unwrap();
        group_pub.end_coherent_changes().unwrap();
        assert!(wait_until(Duration::from_secs(5), || counts(&tr)
            == [4 * (round + 1)]
            && counts(&gr) == [2 * (round + 1), 2 * (round + 1)]));
    }
    for (i, (seen, stop)) in watched.iter().enumerate() {
        stop.store(true, Ordering::Relaxed);
        let step = if i == 0 { 4 } else { 2 };
        let seen = seen.lock().unwrap().clone();
        assert!(
            seen.iter().all(|n| n % step == 0),
            "reader {i}: a partial set was visible: {seen:?}"
        );
    }
}
