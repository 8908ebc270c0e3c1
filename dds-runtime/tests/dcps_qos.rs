//! Reader-side QoS end to end (ownership, deadline, lifespan, history), zero-copy reads, Send + Sync.
mod dcps_util;

use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

fn assert_send_sync<T: Send + Sync>() {}

/// A static assertion: this test does not compile if an entity stops being `Send + Sync`.
#[test]
fn entities_are_send_and_sync() {
    assert_send_sync::<DomainParticipant>();
    assert_send_sync::<DomainParticipantBuilder>();
    assert_send_sync::<Topic<ShapeType>>();
    assert_send_sync::<ContentFilteredTopic<ShapeType>>();
    assert_send_sync::<Publisher>();
    assert_send_sync::<Subscriber>();
    assert_send_sync::<DataWriter<ShapeType>>();
    assert_send_sync::<DataReader<ShapeType>>();
    assert_send_sync::<SampleStream<ShapeType>>();
    assert_send_sync::<Selector<'static, ShapeType>>();
    assert_send_sync::<Sample<ShapeType>>();
    assert_send_sync::<DiscoveredParticipant>();
    assert_send_sync::<WaitSet>();
    assert_send_sync::<ReadCondition>();
    assert_send_sync::<StatusCondition>();
    assert_send_sync::<GuardCondition>();
    assert_send_sync::<DdsError>();
}

#[test]
fn exclusive_ownership_deadline_and_zero_copy_read() {
    let p1 = participant(71);
    let p2 = participant(71);
    let t1 = p1
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let t2 = p2
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let publ = p1.create_publisher(&PublisherQos::default()).unwrap();
    let wq = |s: i32| {
        DataWriterQos::builder()
            .reliability(reliable())
            .ownership(Ownership::Exclusive)
            .ownership_strength(s)
            .deadline(Duration::from_millis(100))
            .history(History::KeepAll)
            .build()
    };
    let weak = publ.create_datawriter(&t1, &wq(1)).unwrap();
    let strong = publ.create_datawriter(&t1, &wq(10)).unwrap();
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .ownership(Ownership::Exclusive)
        .history(History::KeepAll)
        .deadline(Duration::from_millis(200))
        .build();
    let r = p2
        .create_subscriber(&SubscriberQos::default())
        .unwrap()
        .create_datareader(&t2, &rq)
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || r
        .subscription_matched_status()
        .current_count
        == 2));
    assert!(wait_until(MATCH_TIMEOUT, || {
        weak.publication_matched_status().current_count == 1
            && strong.publication_matched_status().current_count == 1
    }));
    strong.write(&shape("RED", 100)).unwrap();
    strong
        .wait_for_acknowledgments(Duration::from_secs(5))
        .unwrap();
    weak.write(&shape("RED", 1)).unwrap();
    weak.wait_for_acknowledgments(Duration::from_secs(5))
        .unwrap();
    strong.write(&shape("RED", 101)).unwrap();
    strong
        .wait_for_acknowledgments(Duration::from_secs(5))
        .unwrap();
    assert!(
        wait_until(Duration::from_secs(5), || r.sample_count() == 2),
        "{:?}",
        r.read().unwrap()
    );

    // Zero-copy read sees both strong samples, without cloning.
    let mut xs = Vec::new();
    let n = r
        .read_with(|d, info| {
            assert!(info.valid_data);
            xs.push(d.unwrap().x);
        })
        .unwrap();
    assert_eq!(n, 2);
    assert_eq!(xs, vec![100, 101]);
    assert!(r
        .select()
        .sample_state(SampleStateMask::NOT_READ)
        .read()
        .unwrap()
        .is_empty());

    // No more writes: the 200 ms deadline is missed.
    assert!(wait_until(Duration::from_secs(5), || r
        .requested_deadline_missed_status()
        .total_count
        >= 1));
}

#[test]
fn keep_last_depth_applies_per_instance() {
    let (p1, p2) = (participant(72), participant(72));
    let (wq, mut rq) = reliable_keep_all();
    rq.history = History::KeepLast(3);
    let (w, r) = matched::<ShapeType>(&p1, &p2, "Square", &wq, &rq);
    for i in 0..10 {
        w.write(&shape("RED", i)).unwrap();
        w.write(&shape("BLUE", i)).unwrap();
    }
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    assert!(wait_until(Duration::from_secs(5), || r.sample_count() == 6));
    let blue = r.lookup_instance(&shape("BLUE", 0)).unwrap().unwrap();
    let got = r.take_instance(blue).unwrap();
    assert_eq!(
        got.iter()
            .map(|s| s.data.as_ref().unwrap().x)
            .collect::<Vec<_>>(),
        vec![7, 8, 9]
    );
    assert_eq!(
        got.iter().map(|s| s.info.sample_rank).collect::<Vec<_>>(),
        vec![2, 1, 0]
    );
    let red = r.take_next_instance(InstanceHandle::NIL).unwrap();
    assert_eq!(red.len(), 3);
    assert!(r.take().unwrap().is_empty());
}

#[test]
fn deleting_a_writer_unregisters_its_instances() {
    // Unregistered, not disposed (as Cyclone does, and as the OMG suite's Test_FinalInstanceState_2 expects).
    let (p1, p2) = (participant(73), participant(73));
    let wq = DataWriterQos::builder().reliability(reliable()).build();
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .history(History::KeepLast(5))
        .build();
    let (w, r) = matched::<ShapeType>(&p1, &p2, "Square", &wq, &rq);
    w.write(&shape("RED", 1)).unwrap();
    w.write(&shape("BLUE", 1)).unwrap();
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    assert_eq!(r.take().unwrap().len(), 2);
    drop(w);
    let mut states = Vec::new();
    assert!(wait_until(Duration::from_secs(5), || {
        states.extend(r.take().unwrap().into_iter().map(|s| s.info.instance_state));
        states.len() >= 2
    }));
    assert!(
        states
            .iter()
            .all(|s| *s == InstanceState::NotAliveNoWriters),
        "{states:?}"
    );
}

#[test]
fn lifespan_expires_samples_in_the_reader() {
    let (p1, p2) = (participant(74), participant(74));
    let wq = DataWriterQos::builder()
        .reliability(reliable())
        .lifespan(Duration::from_millis(300))
        .build();
    let rq = DataReaderQos::builder().reliability(reliable()).build();
    let (w, r) = matched::<ShapeType>(&p1, &p2, "Square", &wq, &rq);
    w.write(&shape("RED", 1)).unwrap();
    assert!(r.wait_for_data(Duration::from_secs(5)).unwrap());
    assert_eq!(r.sample_count(), 1);
    assert!(
        wait_until(Duration::from_secs(3), || r.sample_count() == 0),
        "sample did not expire"
    );
}
