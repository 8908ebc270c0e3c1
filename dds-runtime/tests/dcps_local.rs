//! Intra-process delivery through the DCPS API (run inside `scripts/isolated`): a reader of the writer's own
//! participant gets every sample with no datagram, keeping history, instance states, content filters,
//! ownership and durability; a reader in another participant of the same process keeps getting UDP.
mod dcps_util;

use std::sync::atomic::Ordering;
use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

fn sent(p: &DomainParticipant) -> u64 {
    p.transport_stats().sent.load(Ordering::Relaxed)
}

fn xs(samples: &[Sample<ShapeType>]) -> Vec<i32> {
    samples
        .iter()
        .filter_map(|s| s.data.as_ref().map(|d| d.x))
        .collect()
}

#[test]
fn local_reader_gets_every_sample_without_a_datagram_and_a_remote_one_over_udp() {
    let p = participant(101);
    let remote = participant(101);
    let (wq, rq) = reliable_keep_all();
    let (w, local) = matched::<ShapeType>(&p, &p, "Local", &wq, &rq);
    let far = reader::<ShapeType>(&remote, "Local", &rq);
    assert!(wait_until(MATCH_TIMEOUT, || {
        w.publication_matched_status().current_count == 2
            && far.subscription_matched_status().current_count == 1
    }));
    // Both are matched readers of the writer; only the remote one has a locator.
    assert_eq!(w.matched_subscription_guids().len(), 2);
    assert_eq!(local.matched_publications().len(), 1);

    let n = 2000;
    for x in 0..n {
        w.write(&shape("RED", x)).unwrap();
    }
    assert_eq!(xs(&take_n(&local, n as usize)), (0..n).collect::<Vec<_>>());
    assert_eq!(xs(&take_n(&far, n as usize)), (0..n).collect::<Vec<_>>());
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();

    // Without the remote reader, writes send nothing (only SPDP, every 200 ms, may go out meanwhile).
    drop(far);
    assert!(wait_until(MATCH_TIMEOUT, || w
        .publication_matched_status()
        .current_count
        == 1));
    let before = sent(&p);
    for x in 0..n {
        w.write(&shape("BLUE", x)).unwrap();
    }
    assert_eq!(xs(&take_n(&local, n as usize)), (0..n).collect::<Vec<_>>());
    let during = sent(&p) - before;
    assert!(during < 20, "{during} datagrams sent for {n} local samples");
}

#[test]
fn without_intra_process_the_same_exchange_goes_over_udp() {
    require_netns();
    init_tracing();
    let c = Config {
        domain_id: 102,
        interface: dds_runtime::config::InterfaceSelection::Name("lo".into()),
        intra_process: false,
        ..Config::default()
    };
    let p = DomainParticipant::builder().config(c).build().unwrap();
    let (wq, rq) = reliable_keep_all();
    let (w, r) = matched::<ShapeType>(&p, &p, "Udp", &wq, &rq);
    let before = sent(&p);
    for x in 0..200 {
        w.write(&shape("RED", x)).unwrap();
    }
    assert_eq!(xs(&take_n(&r, 200)), (0..200).collect::<Vec<_>>());
    assert!(sent(&p) - before >= 200, "each write is a datagram");
}

#[test]
fn local_delivery_keeps_history_instance_states_and_lifespan() {
    let p = participant(103);
    let wq = DataWriterQos::builder()
        .reliability(reliable())
        .history(History::KeepLast(1))
        .lifespan(Duration::from_millis(300))
        .build();
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .history(History::KeepLast(2))
        .build();
    let (w, r) = matched::<ShapeType>(&p, &p, "States", &wq, &rq);
    for x in 0..5 {
        w.write(&shape("RED", x)).unwrap();
    }
    w.write(&shape("GREEN", 7)).unwrap();
    // KEEP_LAST 2 per instance in the reader.
    let got = r.read().unwrap();
    let mut red: Vec<i32> = got
        .iter()
        .filter_map(|s| s.data.as_ref().filter(|d| d.color == "RED").map(|d| d.x))
        .collect();
    red.sort();
    assert_eq!(red, vec![3, 4]);
    w.dispose(&shape("GREEN", 0)).unwrap();
    let green: Vec<_> = r
        .take()
        .unwrap()
        .into_iter()
        .filter(|s| s.info.instance_state == InstanceState::NotAliveDisposed)
        .collect();
    assert!(!green.is_empty(), "the dispose reached the local reader");
    // Lifespan: samples expire in the reader.
    w.write(&shape("RED", 9)).unwrap();
    assert!(wait_until(Duration::from_secs(3), || r
        .read()
        .unwrap()
        .is_empty()));
}

#[test]
fn local_late_joiner_content_filter_and_ownership() {
    let p = participant(104);
    let wq = DataWriterQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(3))
        .build();
    let w = writer::<ShapeType>(&p, "Late", &wq);
    for x in 0..10 {
        w.write(&shape("RED", x)).unwrap();
    }
    // A late-joining durable local reader gets the writer's history (its last 3).
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepAll)
        .build();
    let late = reader::<ShapeType>(&p, "Late", &rq);
    assert_eq!(xs(&take_n(&late, 3)), vec![7, 8, 9]);

    // A content filter applies to local samples.
    let topic = p
        .create_topic::<ShapeType>("Late", &TopicQos::default())
        .unwrap();
    let cft = p
        .create_content_filtered_topic("LateBig", &topic, "x > %0", &["100"])
        .unwrap();
    let filtered = p
        .create_subscriber(&SubscriberQos::default())
        .unwrap()
        .create_datareader(&cft, &rq)
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || filtered
        .subscription_matched_status()
        .current_count
        == 1));
    for x in [5, 150, 50, 200] {
        w.write(&shape("RED", x)).unwrap();
    }
    assert_eq!(xs(&take_n(&filtered, 2)), vec![150, 200]);

    // Exclusive ownership between two local writers: only the stronger one's samples.
    let own = |s: i32| {
        DataWriterQos::builder()
            .reliability(reliable())
            .ownership(Ownership::Exclusive)
            .ownership_strength(s)
            .build()
    };
    let weak = writer::<ShapeType>(&p, "Owned", &own(1));
    let strong = writer::<ShapeType>(&p, "Owned", &own(10));
    let orq = DataReaderQos::builder()
        .reliability(reliable())
        .ownership(Ownership::Exclusive)
        .history(History::KeepAll)
        .build();
    let r = reader::<ShapeType>(&p, "Owned", &orq);
    assert!(wait_until(MATCH_TIMEOUT, || r
        .subscription_matched_status()
        .current_count
        == 2));
    strong.write(&shape("RED", 100)).unwrap();
    weak.write(&shape("RED", 1)).unwrap();
    strong.write(&shape("RED", 101)).unwrap();
    assert_eq!(xs(&take_n(&r, 2)), vec![100, 101]);
    assert!(r.take().unwrap().is_empty());
}
