//! TRANSIENT and PERSISTENT durability end to end: the durability service keeps data past its writer,
//! serves late joiners once each, honours DURABILITY_SERVICE history, survives a restart with its
//! persistent store, and durability kinds match in the order VOLATILE < TRANSIENT_LOCAL < TRANSIENT <
//! PERSISTENT.
mod dcps_util;

use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

const HISTORY_TIMEOUT: Duration = Duration::from_secs(10);

/// A participant on `lo` with the durability service `svc`.
fn participant_with(domain: u32, svc: DurabilityServiceConfig) -> DomainParticipant {
    require_netns();
    DomainParticipant::builder()
        .domain_id(domain)
        .interface("lo")
        .spdp_interval(Duration::from_millis(200))
        .durability_service(svc)
        .build()
        .unwrap()
}

fn durable_writer_qos(kind: Durability, depth: u32) -> DataWriterQos {
    DataWriterQos::builder()
        .reliability(reliable())
        .durability(kind)
        .history(History::KeepLast(depth))
        .durability_service(DurabilityService {
            history: History::KeepLast(depth),
            ..DurabilityService::default()
        })
        // Deleting the writer must not dispose its instances, or the service forgets them (see
        // `disposed_data_is_cleaned_up`).
        .writer_data_lifecycle(WriterDataLifecycle {
            autodispose_unregistered_instances: false,
        })
        .build()
}

fn durable_reader_qos(kind: Durability) -> DataReaderQos {
    DataReaderQos::builder()
        .reliability(reliable())
        .durability(kind)
        .history(History::KeepAll)
        .build()
}

/// Takes until `n` samples arrived (or the timeout passed), then a little longer to catch repeats.
fn take_all(r: &DataReader<ShapeType>, n: usize) -> Vec<(String, i32)> {
    let mut got = Vec::new();
    wait_until(HISTORY_TIMEOUT, || {
        got.extend(
            r.take()
                .unwrap()
                .into_iter()
                .filter_map(|s| s.data.map(|d| (d.color, d.x))),
        );
        got.len() >= n
    });
    std::thread::sleep(Duration::from_millis(500));
    got.extend(
        r.take()
            .unwrap()
            .into_iter()
            .filter_map(|s| s.data.map(|d| (d.color, d.x))),
    );
    got.sort();
    got
}

/// A TRANSIENT reader joining `topic` late: waits for a match and the historical data, then takes `n` samples.
fn late_transient_reader(p: &DomainParticipant, topic: &str, n: usize) -> Vec<(String, i32)> {
    let r = reader::<ShapeType>(p, topic, &durable_reader_qos(Durability::Transient));
    assert!(wait_until(HISTORY_TIMEOUT, || r
        .subscription_matched_status()
        .current_count
        >= 1));
    assert!(r.wait_for_historical_data(HISTORY_TIMEOUT).unwrap());
    take_all(&r, n)
}

fn write_rounds(w: &DataWriter<ShapeType>, rounds: i32) {
    for x in 1..=rounds {
        for color in ["BLUE", "RED"] {
            w.write(&shape(color, x)).unwrap();
        }
    }
}

fn expected(from: i32, to: i32) -> Vec<(String, i32)> {
    let mut v: Vec<(String, i32)> = (from..=to)
        .flat_map(|x| [("BLUE".to_string(), x), ("RED".to_string(), x)])
        .collect();
    v.sort();
    v
}

#[test]
fn transient_data_outlives_its_writer() {
    let pw = participant(141);
    let w = writer::<ShapeType>(
        &pw,
        "Transient",
        &durable_writer_qos(Durability::Transient, 2),
    );
    write_rounds(&w, 3);
    drop(w);
    std::thread::sleep(Duration::from_millis(300));
    let pr = participant(141);
    // DURABILITY_SERVICE keeps the last 2 per instance.
    assert_eq!(late_transient_reader(&pr, "Transient", 4), expected(2, 3));
}

#[test]
fn disposed_data_is_cleaned_up() {
    let pw = participant(146);
    let mut wq = durable_writer_qos(Durability::Transient, 2);
    wq.writer_data_lifecycle = WriterDataLifecycle::default();
    let w = writer::<ShapeType>(&pw, "Disposed", &wq);
    write_rounds(&w, 2);
    // Both instances disposed, then the writer deleted: service_cleanup_delay 0 lets them go.
    for color in ["BLUE", "RED"] {
        w.dispose(&shape(color, 0)).unwrap();
    }
    drop(w);
    std::thread::sleep(Duration::from_millis(500));
    let pr = participant(146);
    let r = reader::<ShapeType>(&pr, "Disposed", &durable_reader_qos(Durability::Transient));
    std::thread::sleep(Duration::from_secs(1));
    assert_eq!(r.subscription_matched_status().current_count, 0);
    assert!(r.take().unwrap().is_empty());
}

#[test]
fn replayed_samples_name_the_original_writer() {
    // The late reader gets the samples from the stand-in only (the writer is gone), yet each names the
    // writer that wrote it, as `publication_handle` and `publication_guid`.
    let pw = participant(219);
    let w = writer::<ShapeType>(
        &pw,
        "Attributed",
        &durable_writer_qos(Durability::Transient, 2),
    );
    let (handle, guid) = (w.instance_handle(), w.guid());
    write_rounds(&w, 2);
    drop(w);
    std::thread::sleep(Duration::from_millis(300));
    let pr = participant(219);
    let r = reader::<ShapeType>(
        &pr,
        "Attributed",
        &durable_reader_qos(Durability::Transient),
    );
    assert!(wait_until(HISTORY_TIMEOUT, || r
        .subscription_matched_status()
        .current_count
        >= 1));
    assert!(r.wait_for_historical_data(HISTORY_TIMEOUT).unwrap());
    let mut infos = Vec::new();
    wait_until(HISTORY_TIMEOUT, || {
        infos.extend(
            r.take()
                .unwrap()
                .into_iter()
                .filter(|s| s.data.is_some())
                .map(|s| (s.info.publication_handle, s.info.publication_guid)),
        );
        infos.len() >= 4
    });
    assert_eq!(infos.len(), 4, "the four kept samples");
    assert!(
        infos.iter().all(|i| *i == (handle, guid)),
        "each names the original writer {guid:?}: {infos:?}"
    );
    let standin = r.matched_publications();
    assert!(
        !standin.contains(&handle),
        "the only matched writer is the stand-in"
    );
}

#[test]
fn late_joiner_gets_each_sample_once_while_the_writer_lives() {
    let pw = participant(142);
    let w = writer::<ShapeType>(&pw, "Both", &durable_writer_qos(Durability::Transient, 3));
    write_rounds(&w, 3);
    let pr = participant(142);
    let r = reader::<ShapeType>(&pr, "Both", &durable_reader_qos(Durability::Transient));
    assert!(wait_until(HISTORY_TIMEOUT, || r
        .subscription_matched_status()
        .current_count
        == 2));
    assert_eq!(
        take_all(&r, 6),
        expected(1, 3),
        "writer and stand-in: once each"
    );
    write_rounds(&w, 3);
    assert_eq!(take_all(&r, 6), expected(1, 3), "live samples once each");
}

/// What a late joiner holds per instance once everything arrived: the values of its samples and its
/// instance state (each sample's info shows the instance's current state).
fn by_instance(r: &DataReader<ShapeType>) -> Vec<(String, Vec<i32>, InstanceState)> {
    assert!(wait_until(HISTORY_TIMEOUT, || r
        .subscription_matched_status()
        .current_count
        >= 1));
    assert!(r.wait_for_historical_data(HISTORY_TIMEOUT).unwrap());
    std::thread::sleep(Duration::from_millis(500));
    let mut out: Vec<(String, Vec<i32>, InstanceState)> = Vec::new();
    for s in r.take().unwrap() {
        let Some(d) = s.data else { continue };
        match out.iter_mut().find(|(c, ..)| *c == d.color) {
            Some(e) => {
                e.1.push(d.x);
                e.2 = s.info.instance_state;
            }
            None => out.push((d.color, vec![d.x], s.info.instance_state)),
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// The service replays an instance's kept samples and then its final state, as a writer that stayed alive
/// would: the unregistration and the dispose do not evict the samples DURABILITY_SERVICE keeps (KEEP_LAST 2).
#[test]
fn a_late_joiner_gets_the_kept_samples_then_the_final_state() {
    let pw = participant(147);
    let mut wq = durable_writer_qos(Durability::Transient, 2);
    // RED, disposed and then without writer, stays for the delay (see the next test).
    wq.durability_service.service_cleanup_delay = Duration::from_secs(60);
    let w = writer::<ShapeType>(&pw, "Final", &wq);
    for x in 1..=3 {
        for color in ["BLUE", "GREEN", "RED"] {
            w.write(&shape(color, x)).unwrap();
        }
    }
    w.unregister_instance(&shape("BLUE", 0)).unwrap();
    w.dispose(&shape("RED", 0)).unwrap();
    // Deleting the writer unregisters GREEN (and RED, which stays disposed).
    drop(w);
    std::thread::sleep(Duration::from_millis(300));
    let pr = participant(147);
    let r = reader::<ShapeType>(&pr, "Final", &durable_reader_qos(Durability::Transient));
    let no_writers = InstanceState::NotAliveNoWriters;
    assert_eq!(
        by_instance(&r),
        vec![
            ("BLUE".to_string(), vec![2, 3], no_writers),
            ("GREEN".to_string(), vec![2, 3], no_writers),
            (
                "RED".to_string(),
                vec![2, 3],
                InstanceState::NotAliveDisposed
            ),
        ]
    );
}

/// `service_cleanup_delay` applies per instance: an instance disposed and without live writers is purged
/// after the delay, while the writer's other instances stay. (The writer is deleted first: a late joiner then
/// gets the instances from the stand-in alone.)
#[test]
fn a_disposed_instance_is_purged_after_the_cleanup_delay() {
    let pw = participant(140);
    let mut wq = durable_writer_qos(Durability::Transient, 1);
    wq.durability_service.service_cleanup_delay = Duration::from_secs(3);
    let w = writer::<ShapeType>(&pw, "Purged", &wq);
    write_rounds(&w, 1);
    w.dispose(&shape("RED", 0)).unwrap();
    drop(w);
    let pr = participant(140);
    let early = reader::<ShapeType>(&pr, "Purged", &durable_reader_qos(Durability::Transient));
    let early = by_instance(&early);
    std::thread::sleep(Duration::from_secs(4));
    let late = reader::<ShapeType>(&pr, "Purged", &durable_reader_qos(Durability::Transient));
    let late = by_instance(&late);
    let blue = (
        "BLUE".to_string(),
        vec![1],
        InstanceState::NotAliveNoWriters,
    );
    let red = ("RED".to_string(), vec![1], InstanceState::NotAliveDisposed);
    assert_eq!(early, vec![blue.clone(), red], "before the delay");
    assert_eq!(late, vec![blue], "after the delay");
}

/// Alignment: a domain-wide service started after the original writer is gone learns the writer's data
/// from the stand-in of the service that kept it, and keeps serving it after that service is gone too.
#[test]
fn a_late_domain_service_aligns_from_another_service() {
    let pw = participant(148);
    let w = writer::<ShapeType>(
        &pw,
        "Aligned",
        &durable_writer_qos(Durability::Transient, 2),
    );
    write_rounds(&w, 3);
    drop(w);
    // Only pw's own service (and its stand-in) holds the data now.
    let ps = participant_with(148, DurabilityServiceConfig::domain());
    let pr = participant(148);
    let stand_in_of = |p: &DomainParticipant| {
        let prefix = p.guid_prefix();
        pr.discovered_publications()
            .iter()
            .any(|d| d.topic_name == "Aligned" && d.key.prefix == prefix)
    };
    assert!(
        wait_until(HISTORY_TIMEOUT, || stand_in_of(&ps)),
        "no stand-in from the domain service"
    );
    // The stand-in exists once the service adopted the writer; give the history a moment to arrive.
    std::thread::sleep(Duration::from_millis(1000));
    drop(pw);
    assert!(wait_until(HISTORY_TIMEOUT, || !pr
        .discovered_publications()
        .iter()
        .any(
            |d| d.topic_name == "Aligned" && d.key.prefix != ps.guid_prefix()
        )));
    assert_eq!(late_transient_reader(&pr, "Aligned", 4), expected(2, 3));
}

#[test]
fn without_a_service_transient_is_transient_local() {
    let pw = participant_with(143, DurabilityServiceConfig::off());
    let w = writer::<ShapeType>(&pw, "Off", &durable_writer_qos(Durability::Transient, 2));
    write_rounds(&w, 2);
    drop(w);
    let pr = participant(143);
    let r = reader::<ShapeType>(&pr, "Off", &durable_reader_qos(Durability::Transient));
    std::thread::sleep(Duration::from_secs(1));
    assert_eq!(r.subscription_matched_status().current_count, 0);
    assert!(r.take().unwrap().is_empty());
}

#[test]
fn persistent_data_survives_a_restart_of_the_service() {
    let dir = std::env::temp_dir().join(format!("dds-durability-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let db = dir.join("store.redb");
    let _ = std::fs::remove_file(&db);
    let service = |db: &std::path::Path| {
        participant_with(144, DurabilityServiceConfig::domain().persistent_store(db))
    };
    let svc = service(&db);
    let pw = participant_with(144, DurabilityServiceConfig::off());
    let w = writer::<ShapeType>(
        &pw,
        "Persist",
        &durable_writer_qos(Durability::Persistent, 5),
    );
    assert!(wait_until(HISTORY_TIMEOUT, || w
        .publication_matched_status()
        .current_count
        == 1));
    write_rounds(&w, 4);
    w.wait_for_acknowledgments(HISTORY_TIMEOUT).unwrap();
    drop(w);
    drop(pw);
    drop(svc);
    std::thread::sleep(Duration::from_millis(300));
    let _svc = service(&db);
    let pr = participant(144);
    let r = reader::<ShapeType>(&pr, "Persist", &durable_reader_qos(Durability::Persistent));
    assert_eq!(take_all(&r, 8), expected(1, 4));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The participant's own durability service subscribes to its TRANSIENT writers and stands in for them, but
/// users never see those endpoints: a TRANSIENT writer alone matches no reader, and a reader of the same
/// participant matches exactly the one writer (OMG suite `Test_Durability_11` checked that the writer reports
/// the incompatible PERSISTENT reader before any match).
#[test]
fn the_service_endpoints_are_not_counted_in_user_statuses() {
    let p = participant(149);
    let w = writer::<ShapeType>(&p, "Hidden", &durable_writer_qos(Durability::Transient, 2));
    write_rounds(&w, 1);
    std::thread::sleep(Duration::from_millis(800));
    let st = w.publication_matched_status();
    assert_eq!(
        (st.total_count, st.current_count),
        (0, 0),
        "service reader counted"
    );
    assert!(w.matched_subscriptions().is_empty());

    let r = reader::<ShapeType>(&p, "Hidden", &durable_reader_qos(Durability::Transient));
    let persistent = reader::<ShapeType>(&p, "Hidden", &durable_reader_qos(Durability::Persistent));
    assert!(wait_until(HISTORY_TIMEOUT, || {
        w.publication_matched_status().current_count >= 1
            && persistent.requested_incompatible_qos_status().total_count >= 1
    }));
    assert_eq!(take_all(&r, 2), expected(1, 1), "each sample once");
    std::thread::sleep(Duration::from_millis(500));
    let st = w.publication_matched_status();
    assert_eq!((st.total_count, st.current_count), (1, 1));
    assert_eq!(w.matched_subscriptions().len(), 1);
    let st = r.subscription_matched_status();
    assert_eq!(
        (st.total_count, st.current_count),
        (1, 1),
        "stand-in counted"
    );
    assert_eq!(r.matched_publications().len(), 1);
    assert_eq!(w.offered_incompatible_qos_status().total_count, 1);
}

#[test]
fn durability_kinds_match_in_order() {
    let p1 = participant(145);
    let p2 = participant(145);
    let kinds = [
        Durability::Volatile,
        Durability::TransientLocal,
        Durability::Transient,
        Durability::Persistent,
    ];
    // Offered TRANSIENT: readers up to TRANSIENT match, PERSISTENT is incompatible.
    let w = writer::<ShapeType>(&p1, "Order", &durable_writer_qos(Durability::Transient, 1));
    let readers: Vec<DataReader<ShapeType>> = kinds
        .iter()
        .map(|k| reader::<ShapeType>(&p2, "Order", &durable_reader_qos(*k)))
        .collect();
    assert!(wait_until(HISTORY_TIMEOUT, || {
        readers[..3]
            .iter()
            .all(|r| r.subscription_matched_status().current_count >= 1)
            && readers[3].requested_incompatible_qos_status().total_count >= 1
            && w.offered_incompatible_qos_status().total_count >= 1
    }));
    let st = readers[3].requested_incompatible_qos_status();
    assert_eq!(st.last_policy_id, Some(QosPolicyId::Durability));
    assert!(w.offered_incompatible_qos_status().total_count >= 1);
    assert_eq!(
        w.offered_incompatible_qos_status().last_policy_id,
        Some(QosPolicyId::Durability)
    );
}
