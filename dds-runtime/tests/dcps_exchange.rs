//! Reliable keyed data exchange between two participants over loopback.
mod dcps_util;

use std::time::{Duration, SystemTime};

use dcps_util::*;
use dds_runtime::prelude::*;

fn take_all(r: &DataReader<ShapeType>, n: usize) -> Vec<Sample<ShapeType>> {
    let mut got = Vec::new();
    wait_until(Duration::from_secs(10), || {
        got.extend(r.take().unwrap());
        got.len() >= n
    });
    got
}

#[test]
fn reliable_keyed_exchange_in_order_with_sample_info() {
    let (p1, p2) = (participant(21), participant(21));
    let (wq, rq) = reliable_keep_all();
    let (w, r) = matched::<ShapeType>(&p1, &p2, "Circle", &wq, &rq);
    let ts = SystemTime::UNIX_EPOCH + Duration::from_secs(1_700_000_000);
    for i in 0..50 {
        for c in ["RED", "BLUE", "GREEN"] {
            w.write_w_timestamp(&shape(c, i), ts).unwrap();
        }
    }
    w.wait_for_acknowledgments(Duration::from_secs(10)).unwrap();
    let got = take_all(&r, 150);
    assert_eq!(got.len(), 150);
    for c in ["RED", "BLUE", "GREEN"] {
        let xs: Vec<i32> = got
            .iter()
            .filter_map(|s| s.data.as_ref())
            .filter(|d| d.color == c)
            .map(|d| d.x)
            .collect();
        assert_eq!(xs, (0..50).collect::<Vec<_>>(), "{c} in order, none lost");
    }
    let s = &got[0];
    assert!(s.info.valid_data);
    assert_eq!(s.info.instance_state, InstanceState::Alive);
    assert_eq!(s.info.view_state, ViewState::New);
    assert_eq!(s.info.sample_state, SampleState::NotRead);
    assert_eq!(s.info.source_timestamp, ts);
    assert_eq!(s.info.publication_handle, w.instance_handle());
    let red = r
        .lookup_instance(&shape("RED", 999))
        .unwrap()
        .expect("RED instance");
    assert_eq!(
        got.iter()
            .find(|s| s.data.as_ref().unwrap().color == "RED")
            .unwrap()
            .info
            .instance_handle,
        red
    );
    assert_eq!(r.instance_count(), 3);
}

#[test]
fn dispose_and_unregister_are_instance_states() {
    let wq = DataWriterQos::builder()
        .reliability(reliable())
        .writer_data_lifecycle(WriterDataLifecycle {
            autodispose_unregistered_instances: false,
        })
        .build();
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .history(History::KeepLast(5))
        .build();
    let (p1, p2) = (participant(22), participant(22));
    let (w, r) = matched::<ShapeType>(&p1, &p2, "Circle", &wq, &rq);
    w.write(&shape("RED", 1)).unwrap();
    w.write(&shape("BLUE", 2)).unwrap();
    assert_eq!(take_all(&r, 2).len(), 2);

    w.dispose(&shape("RED", 0)).unwrap();
    w.unregister_instance(&shape("BLUE", 0)).unwrap();
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    let got = take_all(&r, 2);
    assert_eq!(got.len(), 2, "{got:?}");
    let red = got
        .iter()
        .find(|s| s.info.instance_state == InstanceState::NotAliveDisposed)
        .expect("disposed RED");
    assert!(!red.info.valid_data);
    assert!(red.data.is_none());
    let blue = got
        .iter()
        .find(|s| s.info.instance_state == InstanceState::NotAliveNoWriters)
        .expect("BLUE no writers");
    assert!(!blue.info.valid_data);
    assert_ne!(red.info.instance_handle, blue.info.instance_handle);

    // Writing RED again starts a new generation.
    w.write(&shape("RED", 3)).unwrap();
    let got = take_all(&r, 1);
    assert_eq!(got[0].info.instance_state, InstanceState::Alive);
    assert_eq!(got[0].info.disposed_generation_count, 1);
    assert_eq!(got[0].info.view_state, ViewState::New);
}

#[test]
fn transient_local_late_joiner_gets_history() {
    let p1 = participant(23);
    let t1 = p1
        .create_topic::<ShapeType>("Triangle", &TopicQos::default())
        .unwrap();
    let wq = DataWriterQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(2))
        .build();
    let w = p1
        .create_publisher(&PublisherQos::default())
        .unwrap()
        .create_datawriter(&t1, &wq)
        .unwrap();
    for i in 0..5 {
        w.write(&shape("RED", i)).unwrap();
        w.write(&shape("BLUE", 100 + i)).unwrap();
    }
    let p2 = participant(23);
    let t2 = p2
        .create_topic::<ShapeType>("Triangle", &TopicQos::default())
        .unwrap();
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(10))
        .build();
    let r = p2
        .create_subscriber(&SubscriberQos::default())
        .unwrap()
        .create_datareader(&t2, &rq)
        .unwrap();
    let got = take_all(&r, 4);
    let mut xs: Vec<i32> = got
        .iter()
        .filter_map(|s| s.data.as_ref().map(|d| d.x))
        .collect();
    xs.sort();
    assert_eq!(xs, vec![3, 4, 103, 104]);
}

#[test]
fn large_sample_is_fragmented_and_reassembled() {
    let (p1, p2) = (participant(24), participant(24));
    let wq = DataWriterQos::builder().reliability(reliable()).build();
    let rq = DataReaderQos::builder().reliability(reliable()).build();
    let (w, r) = matched::<Blob>(&p1, &p2, "Blob", &wq, &rq);
    let data: Vec<u8> = (0..100_000u32).map(|i| (i * 7 % 251) as u8).collect();
    w.write(&Blob {
        id: 7,
        data: data.clone(),
    })
    .unwrap();
    assert!(r.wait_for_data(Duration::from_secs(10)).unwrap());
    let got = r.take().unwrap();
    assert_eq!(got.len(), 1);
    assert_eq!(got[0].data.as_ref().unwrap().data, data);
    assert_eq!(got[0].data.as_ref().unwrap().id, 7);
}

#[test]
fn partitions_decide_matching() {
    let p1 = participant(25);
    let p2 = participant(25);
    let t1 = p1
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let t2 = p2
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let publ = p1
        .create_publisher(&PublisherQos::builder().partition(["A"]).build())
        .unwrap();
    let w = publ
        .create_datawriter(&t1, &DataWriterQos::default())
        .unwrap();
    let sub_b = p2
        .create_subscriber(&SubscriberQos::builder().partition(["B"]).build())
        .unwrap();
    let rb = sub_b
        .create_datareader(&t2, &DataReaderQos::default())
        .unwrap();
    let sub_a = p2
        .create_subscriber(&SubscriberQos::builder().partition(["A*"]).build())
        .unwrap();
    let ra = sub_a
        .create_datareader(&t2, &DataReaderQos::default())
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || ra
        .subscription_matched_status()
        .current_count
        == 1));
    std::thread::sleep(Duration::from_millis(500));
    assert_eq!(rb.subscription_matched_status().current_count, 0);
    assert_eq!(w.publication_matched_status().current_count, 1);
}

#[test]
fn incompatible_qos_does_not_match() {
    let p1 = participant(26);
    let p2 = participant(26);
    let t1 = p1
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let t2 = p2
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let wq = DataWriterQos::builder()
        .reliability(Reliability::BestEffort)
        .build();
    let w = p1
        .create_publisher(&PublisherQos::default())
        .unwrap()
        .create_datawriter(&t1, &wq)
        .unwrap();
    let rq = DataReaderQos::builder().reliability(reliable()).build();
    let r = p2
        .create_subscriber(&SubscriberQos::default())
        .unwrap()
        .create_datareader(&t2, &rq)
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || r
        .requested_incompatible_qos_status()
        .total_count
        >= 1));
    let st = r.requested_incompatible_qos_status();
    assert_eq!(st.last_policy_id, Some(QosPolicyId::Reliability));
    assert!(wait_until(MATCH_TIMEOUT, || w
        .offered_incompatible_qos_status()
        .total_count
        >= 1));
    assert_eq!(r.subscription_matched_status().current_count, 0);
    assert_eq!(w.publication_matched_status().current_count, 0);
}

#[test]
fn content_filtered_topic_filters_on_the_reader() {
    let p1 = participant(27);
    let p2 = participant(27);
    let t1 = p1
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let t2 = p2
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let cft = p2
        .create_content_filtered_topic("FilteredSquare", &t2, "x > %0 AND color = 'RED'", &["10"])
        .unwrap();
    let (wq, rq) = reliable_keep_all();
    let w = p1
        .create_publisher(&PublisherQos::default())
        .unwrap()
        .create_datawriter(&t1, &wq)
        .unwrap();
    let r = p2
        .create_subscriber(&SubscriberQos::default())
        .unwrap()
        .create_datareader(&cft, &rq)
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || w
        .publication_matched_status()
        .current_count
        == 1));
    for x in [5, 11, 20] {
        w.write(&shape("RED", x)).unwrap();
        w.write(&shape("BLUE", x)).unwrap();
    }
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    let got = take_all(&r, 2);
    let xs: Vec<(String, i32)> = got
        .into_iter()
        .filter_map(|s| s.data)
        .map(|d| (d.color, d.x))
        .collect();
    assert_eq!(xs, vec![("RED".to_string(), 11), ("RED".to_string(), 20)]);
}

#[test]
fn data_representation_xcdr1_and_xcdr2_both_reach_a_default_reader() {
    let p1 = participant(28);
    let p2 = participant(28);
    let t1 = p1
        .create_topic::<Blob>("Reps", &TopicQos::default())
        .unwrap();
    let t2 = p2
        .create_topic::<Blob>("Reps", &TopicQos::default())
        .unwrap();
    let publ = p1.create_publisher(&PublisherQos::default()).unwrap();
    let q = |rep: DataRepresentation| {
        DataWriterQos::builder()
            .reliability(reliable())
            .data_representation(rep)
            .build()
    };
    let w1 = publ
        .create_datawriter(&t1, &q(DataRepresentation::xcdr1()))
        .unwrap();
    let w2 = publ
        .create_datawriter(&t1, &q(DataRepresentation::xcdr2()))
        .unwrap();
    let wd = publ
        .create_datawriter(&t1, &q(DataRepresentation::default()))
        .unwrap();
    assert_eq!(w1.data_representation(), XcdrVersion::Xcdr1);
    assert_eq!(w2.data_representation(), XcdrVersion::Xcdr2);
    assert_eq!(
        wd.data_representation(),
        XcdrVersion::Xcdr1,
        "@final without optionals: XCDR1 like Cyclone"
    );
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .history(History::KeepAll)
        .build();
    let r = p2
        .create_subscriber(&SubscriberQos::default())
        .unwrap()
        .create_datareader(&t2, &rq)
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || r
        .subscription_matched_status()
        .current_count
        == 3));
    for (i, w) in [&w1, &w2].into_iter().enumerate() {
        assert!(wait_until(MATCH_TIMEOUT, || w
            .publication_matched_status()
            .current_count
            == 1));
        w.write(&Blob {
            id: i as u32,
            data: vec![i as u8; 3],
        })
        .unwrap();
    }
    let mut got = Vec::new();
    assert!(wait_until(Duration::from_secs(5), || {
        got.extend(r.take().unwrap().into_iter().filter_map(|s| s.data));
        got.len() == 2
    }));
    got.sort_by_key(|b| b.id);
    assert_eq!(
        got,
        vec![
            Blob {
                id: 0,
                data: vec![0; 3]
            },
            Blob {
                id: 1,
                data: vec![1; 3]
            }
        ]
    );
}

#[test]
fn flow_control_blocks_and_resumes_without_loss() {
    let (p1, p2) = (participant(29), participant(29));
    let (wq, rq) = reliable_keep_all_blocking(Duration::from_secs(5));
    let (w, r) = matched::<Blob>(&p1, &p2, "Flow", &wq, &rq);
    // 4 MB in 1 KiB samples: well above the writer's unacknowledged-bytes high watermark.
    const N: u32 = 4000;
    let reader = std::thread::spawn(move || {
        let mut next = 0u32;
        while next < N && r.wait_for_data(Duration::from_secs(10)).unwrap() {
            for s in r.take().unwrap() {
                let b = s.data.unwrap();
                assert_eq!(b.id, next, "in order, no loss");
                next += 1;
            }
        }
        next
    });
    let start = std::time::Instant::now();
    for i in 0..N {
        w.write(&Blob {
            id: i,
            data: vec![(i % 251) as u8; 1024],
        })
        .unwrap();
    }
    w.wait_for_acknowledgments(Duration::from_secs(20)).unwrap();
    assert_eq!(reader.join().unwrap(), N);
    eprintln!("{N} x 1 KiB reliable in {:?}", start.elapsed());
}
