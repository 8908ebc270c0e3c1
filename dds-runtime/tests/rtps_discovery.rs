//! Discovery and matching through the simulated network.

mod rtps_support;

use std::time::Duration;

use dds_runtime::qos::*;
use dds_runtime::rtps::*;
use rtps_support::*;

fn reliable_writer() -> DataWriterQos {
    DataWriterQos::default()
}
fn reliable_reader() -> DataReaderQos {
    DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .build()
}

#[test]
fn two_participants_discover_and_match() {
    let mut sim = Sim::with_participants(1, Faults::NONE, 2);
    let now = sim.now;
    let w = sim.nodes[0]
        .p
        .create_writer(
            now,
            WriterSpec::new("Square", "ShapeType", true, reliable_writer()),
        )
        .unwrap();
    let r = sim.nodes[1]
        .p
        .create_reader(
            now,
            ReaderSpec::new("Square", "ShapeType", true, reliable_reader()),
        )
        .unwrap();
    let rg = sim.guid(1, r);
    let wg = sim.guid(0, w);
    assert!(sim.run_until(Duration::from_secs(2), |s| {
        s.nodes[0].p.writer_matches(w) == vec![rg] && s.nodes[1].p.reader_matches(r) == vec![wg]
    }));
    assert!(
        sim.elapsed() < Duration::from_millis(100),
        "discovery took {:?}",
        sim.elapsed()
    );
    assert!(sim.has_event(
        0,
        |e| matches!(e, Event::ParticipantDiscovered(d) if d.guid_prefix == prefix(1))
    ));
    assert!(sim.has_event(0, |e| *e
        == Event::PublicationMatched {
            writer: w,
            reader: rg,
            matched: true
        }));
    assert!(sim.has_event(1, |e| *e
        == Event::SubscriptionMatched {
            reader: r,
            writer: wg,
            matched: true
        }));

    let now = sim.now;
    sim.nodes[0]
        .p
        .write(
            now,
            w,
            WriteChange::alive(vec![0, 1, 0, 0, 42, 0, 0, 0]).with_key_hash([7; 16]),
        )
        .unwrap();
    assert!(sim.run_until(Duration::from_secs(1), |s| s
        .has_event(1, |e| matches!(e, Event::Sample(_)))));
    let got = sim.take_samples(1, r);
    assert_eq!(got.len(), 1);
    assert_eq!(&got[0].payload[..], &[0, 1, 0, 0, 42, 0, 0, 0]);
    assert_eq!(got[0].key_hash, Some([7; 16]));
    assert_eq!(got[0].writer, wg);
}

#[test]
fn discovery_converges_under_loss() {
    for seed in 0..200u64 {
        let mut sim = Sim::with_participants(seed, Faults::lossy(0.3), 3);
        let now = sim.now;
        let w = sim.nodes[0]
            .p
            .create_writer(now, WriterSpec::new("T", "T", false, reliable_writer()))
            .unwrap();
        let r1 = sim.nodes[1]
            .p
            .create_reader(now, ReaderSpec::new("T", "T", false, reliable_reader()))
            .unwrap();
        let r2 = sim.nodes[2]
            .p
            .create_reader(
                now,
                ReaderSpec::new("T", "T", false, DataReaderQos::default()),
            )
            .unwrap();
        assert!(
            sim.run_until(Duration::from_secs(10), |s| s.nodes[0]
                .p
                .writer_matches(w)
                .len()
                == 2
                && s.nodes[1].p.reader_matches(r1).len() == 1
                && s.nodes[2].p.reader_matches(r2).len() == 1),
            "seed {seed}"
        );
    }
}

#[test]
fn local_writer_and_reader_match_within_one_participant() {
    let mut sim = Sim::with_participants(1, Faults::NONE, 1);
    let now = sim.now;
    let w = sim.nodes[0]
        .p
        .create_writer(now, WriterSpec::new("L", "T", false, reliable_writer()))
        .unwrap();
    let r = sim.nodes[0]
        .p
        .create_reader(now, ReaderSpec::new("L", "T", false, reliable_reader()))
        .unwrap();
    assert_eq!(sim.nodes[0].p.writer_matches(w), vec![sim.guid(0, r)]);
    assert_eq!(sim.nodes[0].p.reader_matches(r), vec![sim.guid(0, w)]);
    sim.nodes[0]
        .p
        .write(now, w, WriteChange::alive(vec![0, 1, 0, 0, 1, 2, 3, 4]))
        .unwrap();
    assert!(sim.run_until(Duration::from_secs(1), |s| s
        .has_event(0, |e| matches!(e, Event::Sample(_)))));
    assert_eq!(
        &sim.take_samples(0, r)[0].payload[..],
        &[0, 1, 0, 0, 1, 2, 3, 4]
    );
}

fn incompatible_case(wq: DataWriterQos, rq: DataReaderQos, policy: QosPolicyId) {
    let mut sim = Sim::with_participants(2, Faults::NONE, 2);
    let now = sim.now;
    let w = sim.nodes[0]
        .p
        .create_writer(now, WriterSpec::new("Q", "T", false, wq))
        .unwrap();
    let r = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("Q", "T", false, rq))
        .unwrap();
    let (wg, rg) = (sim.guid(0, w), sim.guid(1, r));
    assert!(
        sim.run_until(Duration::from_secs(2), |s| s.has_event(0, |e| *e
            == Event::OfferedIncompatibleQos {
                writer: w,
                reader: rg,
                policy
            })
            && s.has_event(1, |e| *e
                == Event::RequestedIncompatibleQos {
                    reader: r,
                    writer: wg,
                    policy
                }))
    );
    sim.run_for(Duration::from_secs(1));
    assert!(sim.nodes[0].p.writer_matches(w).is_empty());
    assert!(sim.nodes[1].p.reader_matches(r).is_empty());
    // Reported once, not at every re-announcement.
    let n = sim.nodes[0]
        .events
        .iter()
        .filter(|e| matches!(e, Event::OfferedIncompatibleQos { .. }))
        .count();
    assert_eq!(n, 1);
}

#[test]
fn incompatible_qos_is_reported_and_not_matched() {
    use std::time::Duration as D;
    incompatible_case(
        DataWriterQos::builder()
            .reliability(Reliability::BestEffort)
            .build(),
        reliable_reader(),
        QosPolicyId::Reliability,
    );
    incompatible_case(
        DataWriterQos::default(),
        DataReaderQos::builder()
            .durability(Durability::TransientLocal)
            .build(),
        QosPolicyId::Durability,
    );
    incompatible_case(
        DataWriterQos::default(),
        DataReaderQos::builder().deadline(D::from_secs(1)).build(),
        QosPolicyId::Deadline,
    );
    incompatible_case(
        DataWriterQos::builder()
            .latency_budget(D::from_secs(2))
            .build(),
        DataReaderQos::builder()
            .latency_budget(D::from_secs(1))
            .build(),
        QosPolicyId::LatencyBudget,
    );
    incompatible_case(
        DataWriterQos::default(),
        DataReaderQos::builder()
            .ownership(Ownership::Exclusive)
            .build(),
        QosPolicyId::Ownership,
    );
    incompatible_case(
        DataWriterQos::default(),
        DataReaderQos::builder()
            .liveliness(Liveliness {
                kind: LivelinessKind::ManualByTopic,
                lease_duration: D::from_secs(1),
            })
            .build(),
        QosPolicyId::Liveliness,
    );
    incompatible_case(
        DataWriterQos::default(),
        DataReaderQos::builder()
            .destination_order(DestinationOrder::BySourceTimestamp)
            .build(),
        QosPolicyId::DestinationOrder,
    );
    incompatible_case(
        DataWriterQos::builder()
            .data_representation(DataRepresentation::xcdr2())
            .build(),
        DataReaderQos::builder()
            .data_representation(DataRepresentation::xcdr1())
            .build(),
        QosPolicyId::DataRepresentation,
    );
}

#[test]
fn presentation_incompatibility_needs_publisher_qos() {
    let mut sim = Sim::with_participants(2, Faults::NONE, 2);
    let now = sim.now;
    let wq = WriterQos::new(
        DataWriterQos::default(),
        &PublisherQos::default(),
        &TopicQos::default(),
    );
    let sq = SubscriberQos::builder()
        .presentation(Presentation {
            access_scope: PresentationAccessScope::Topic,
            coherent_access: false,
            ordered_access: false,
        })
        .build();
    let rq = ReaderQos::new(DataReaderQos::default(), &sq, &TopicQos::default());
    let w = sim.nodes[0]
        .p
        .create_writer(now, WriterSpec::new("P", "T", false, wq))
        .unwrap();
    let r = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("P", "T", false, rq))
        .unwrap();
    let rg = sim.guid(1, r);
    assert!(
        sim.run_until(Duration::from_secs(2), |s| s.has_event(0, |e| *e
            == Event::OfferedIncompatibleQos {
                writer: w,
                reader: rg,
                policy: QosPolicyId::Presentation
            }))
    );
}

#[test]
fn partitions_and_names_decide_matching() {
    let mut sim = Sim::with_participants(3, Faults::NONE, 2);
    let now = sim.now;
    let pubq = PublisherQos::builder().partition(["A", "B*"]).build();
    let wq = WriterQos::new(DataWriterQos::default(), &pubq, &TopicQos::default());
    let w = sim.nodes[0]
        .p
        .create_writer(now, WriterSpec::new("Part", "T", false, wq))
        .unwrap();
    let sub = |parts: &[&str]| {
        ReaderQos::new(
            DataReaderQos::default(),
            &SubscriberQos::builder().partition(parts).build(),
            &TopicQos::default(),
        )
    };
    let r_match = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("Part", "T", false, sub(&["Bee"])))
        .unwrap();
    let r_other = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("Part", "T", false, sub(&["C"])))
        .unwrap();
    let r_default = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("Part", "T", false, sub(&[])))
        .unwrap();
    let r_type = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("Part", "U", false, sub(&["A"])))
        .unwrap();
    let r_topic = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("Other", "T", false, sub(&["A"])))
        .unwrap();
    sim.run_for(Duration::from_secs(1));
    assert_eq!(sim.nodes[0].p.writer_matches(w), vec![sim.guid(1, r_match)]);
    for r in [r_other, r_default, r_type, r_topic] {
        assert!(sim.nodes[1].p.reader_matches(r).is_empty());
    }
    // Different partitions are not an incompatibility.
    assert!(!sim.has_event(0, |e| matches!(e, Event::OfferedIncompatibleQos { .. })));
}

#[test]
fn deleting_endpoints_unmatches_remotely() {
    let mut sim = Sim::with_participants(4, Faults::lossy(0.2), 2);
    let now = sim.now;
    let w = sim.nodes[0]
        .p
        .create_writer(now, WriterSpec::new("D", "T", false, reliable_writer()))
        .unwrap();
    let r = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("D", "T", false, reliable_reader()))
        .unwrap();
    let (wg, rg) = (sim.guid(0, w), sim.guid(1, r));
    assert!(sim.run_until(Duration::from_secs(5), |s| !s.nodes[0]
        .p
        .writer_matches(w)
        .is_empty()
        && !s.nodes[1].p.reader_matches(r).is_empty()));
    let now = sim.now;
    sim.nodes[1].p.delete_reader(now, r);
    assert!(
        sim.run_until(Duration::from_secs(5), |s| s.has_event(0, |e| *e
            == Event::PublicationMatched {
                writer: w,
                reader: rg,
                matched: false
            }))
    );
    assert!(sim.has_event(0, |e| *e == Event::SubscriptionRemoved { guid: rg }));
    let now = sim.now;
    let r2 = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("D", "T", false, reliable_reader()))
        .unwrap();
    assert!(
        sim.run_until(Duration::from_secs(5), |s| s.nodes[1].p.reader_matches(r2)
            == vec![wg])
    );
    let now = sim.now;
    sim.nodes[0].p.delete_writer(now, w);
    assert!(
        sim.run_until(Duration::from_secs(5), |s| s.has_event(1, |e| *e
            == Event::SubscriptionMatched {
                reader: r2,
                writer: wg,
                matched: false
            }))
    );
    assert!(sim.has_event(1, |e| *e == Event::PublicationRemoved { guid: wg }));
}

#[test]
fn lease_expiry_reports_participant_lost() {
    let mut sim = Sim::with_participants(5, Faults::NONE, 2);
    let now = sim.now;
    let w = sim.nodes[0]
        .p
        .create_writer(now, WriterSpec::new("E", "T", false, reliable_writer()))
        .unwrap();
    let r = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("E", "T", false, reliable_reader()))
        .unwrap();
    assert!(sim.run_until(Duration::from_secs(2), |s| !s.nodes[1]
        .p
        .reader_matches(r)
        .is_empty()));
    // Staying quiet but alive keeps the lease (3 s) fresh through periodic SPDP.
    sim.run_for(Duration::from_secs(10));
    assert!(!sim.has_event(1, |e| matches!(e, Event::ParticipantLost { .. })));
    // Node 0 vanishes without a goodbye.
    sim.nodes[0].up = false;
    let vanished = sim.now;
    let wg = sim.guid(0, w);
    assert!(
        sim.run_until(Duration::from_secs(10), |s| s.has_event(1, |e| *e
            == Event::ParticipantLost {
                guid_prefix: prefix(0)
            }))
    );
    let took = sim.now - vanished;
    assert!(
        took >= Duration::from_secs(2) && took <= Duration::from_millis(3600),
        "lost after {took:?}"
    );
    assert!(sim.has_event(1, |e| *e
        == Event::SubscriptionMatched {
            reader: r,
            writer: wg,
            matched: false
        }));
    assert!(sim.has_event(1, |e| *e
        == Event::LivelinessChanged {
            reader: r,
            writer: wg,
            alive: false
        }));
    assert!(sim.nodes[1].p.reader_matches(r).is_empty());
}

#[test]
fn shutdown_announces_departure() {
    let mut sim = Sim::with_participants(6, Faults::NONE, 2);
    assert!(sim.run_until(Duration::from_secs(2), |s| s.nodes[1]
        .p
        .discovered_participants()
        .count()
        == 1));
    let now = sim.now;
    sim.nodes[0].p.shutdown(now);
    sim.pump();
    sim.nodes[0].up = false;
    assert!(
        sim.run_until(Duration::from_millis(50), |s| s.has_event(1, |e| *e
            == Event::ParticipantLost {
                guid_prefix: prefix(0)
            }))
    );
}
