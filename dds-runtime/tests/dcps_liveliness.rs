//! Manual liveliness end to end: a reader sees a MANUAL_BY_TOPIC or MANUAL_BY_PARTICIPANT writer lose its
//! liveliness when its lease runs out, and regain it when the writer or its participant asserts it; the
//! writer's instances go NOT_ALIVE_NO_WRITERS meanwhile.
mod dcps_util;

use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

const LEASE: Duration = Duration::from_millis(400);

fn qos(kind: LivelinessKind) -> (DataWriterQos, DataReaderQos) {
    let l = Liveliness {
        kind,
        lease_duration: LEASE,
    };
    let w = DataWriterQos::builder()
        .reliability(reliable())
        .liveliness(l)
        .build();
    let r = DataReaderQos::builder()
        .reliability(reliable())
        .liveliness(l)
        .build();
    (w, r)
}

fn lost_and_regained(
    domain: u32,
    kind: LivelinessKind,
    assert: impl Fn(&DomainParticipant, &DataWriter<ShapeType>),
) {
    let pw = participant(domain);
    let pr = participant(domain);
    let (wq, rq) = qos(kind);
    let (w, r) = matched::<ShapeType>(&pw, &pr, "Lively", &wq, &rq);
    w.write(&shape("RED", 1)).unwrap();
    assert!(r.wait_for_data(Duration::from_secs(5)).unwrap());
    // No assertion for longer than the lease: lost.
    assert!(wait_until(Duration::from_secs(5), || {
        r.liveliness_changed_status().not_alive_count == 1
    }));
    let st = r.liveliness_changed_status();
    assert_eq!((st.alive_count, st.not_alive_count), (0, 1));
    assert!(wait_until(Duration::from_secs(2), || {
        r.read_instance_state_is_no_writers()
    }));
    // Asserted: alive again.
    assert(&pw, &w);
    assert!(wait_until(Duration::from_secs(2), || {
        r.liveliness_changed_status().alive_count == 1
    }));
    let st = r.liveliness_changed_status();
    assert_eq!((st.alive_count, st.not_alive_count), (1, 0));
}

trait NoWriters {
    fn read_instance_state_is_no_writers(&self) -> bool;
}

impl NoWriters for DataReader<ShapeType> {
    fn read_instance_state_is_no_writers(&self) -> bool {
        self.select()
            .instance_state(InstanceStateMask {
                alive: false,
                disposed: false,
                no_writers: true,
            })
            .read_with(|_, _| ())
            .map(|n| n > 0)
            .unwrap_or(false)
    }
}

#[test]
fn manual_by_topic_lost_and_regained_by_writer_assertion() {
    lost_and_regained(147, LivelinessKind::ManualByTopic, |_, w| {
        w.assert_liveliness().unwrap()
    });
}

#[test]
fn manual_by_participant_lost_and_regained_by_participant_assertion() {
    lost_and_regained(148, LivelinessKind::ManualByParticipant, |p, _| {
        p.assert_liveliness().unwrap()
    });
}

#[test]
fn writing_keeps_a_manual_writer_alive() {
    let pw = participant(149);
    let pr = participant(149);
    let (wq, rq) = qos(LivelinessKind::ManualByTopic);
    let (w, r) = matched::<ShapeType>(&pw, &pr, "Lively", &wq, &rq);
    for x in 0..10 {
        w.write(&shape("RED", x)).unwrap();
        std::thread::sleep(LEASE / 4);
    }
    assert_eq!(r.liveliness_changed_status().not_alive_count, 0);
}

/// Counts the writer's LIVELINESS_LOST callbacks.
struct LostCounter(std::sync::Arc<std::sync::atomic::AtomicU32>);

impl DataWriterListener<ShapeType> for LostCounter {
    fn on_liveliness_lost(&self, _w: &DataWriter<ShapeType>, s: LivelinessLostStatus) {
        self.0
            .fetch_add(s.total_count_change, std::sync::atomic::Ordering::SeqCst);
    }
}

fn writer_loses_liveliness(
    domain: u32,
    kind: LivelinessKind,
    assert: impl Fn(&DomainParticipant, &DataWriter<ShapeType>),
) {
    let pw = participant(domain);
    let pr = participant(domain);
    let (wq, rq) = qos(kind);
    let (w, r) = matched::<ShapeType>(&pw, &pr, "LivelyLost", &wq, &rq);
    // A matched writer is counted alive from the match on (true counts, not transitions).
    assert!(wait_until(Duration::from_secs(2), || {
        r.liveliness_changed_status().alive_count == 1
    }));
    let lost = std::sync::Arc::new(std::sync::atomic::AtomicU32::new(0));
    w.set_listener(Box::new(LostCounter(lost.clone())));
    // Kept alive by assertions for three leases: nothing lost.
    for _ in 0..6 {
        assert(&pw, &w);
        std::thread::sleep(LEASE / 2);
    }
    assert_eq!(lost.load(std::sync::atomic::Ordering::SeqCst), 0);
    // Silent: lost once per lapse, not once per lease period.
    assert!(wait_until(Duration::from_secs(3), || {
        lost.load(std::sync::atomic::Ordering::SeqCst) == 1
    }));
    std::thread::sleep(LEASE * 2);
    assert_eq!(lost.load(std::sync::atomic::Ordering::SeqCst), 1);
    let st = w.liveliness_lost_status();
    assert_eq!(st.total_count, 1);
    // Regained by asserting, lost again when silent.
    assert(&pw, &w);
    assert!(wait_until(Duration::from_secs(3), || {
        lost.load(std::sync::atomic::Ordering::SeqCst) == 2
    }));
    w.clear_listener();
    assert_eq!(w.liveliness_lost_status().total_count, 2);
    // The writer gone: it is no longer counted at all.
    drop(w);
    assert!(wait_until(Duration::from_secs(5), || {
        let s = r.liveliness_changed_status();
        (s.alive_count, s.not_alive_count) == (0, 0)
    }));
}

#[test]
fn manual_by_topic_writer_reports_liveliness_lost() {
    writer_loses_liveliness(221, LivelinessKind::ManualByTopic, |_, w| {
        w.assert_liveliness().unwrap()
    });
}

#[test]
fn manual_by_participant_writer_reports_liveliness_lost() {
    writer_loses_liveliness(222, LivelinessKind::ManualByParticipant, |p, _| {
        p.assert_liveliness().unwrap()
    });
}

#[test]
fn automatic_writer_never_loses_liveliness() {
    let pw = participant(223);
    let pr = participant(223);
    let (wq, rq) = qos(LivelinessKind::Automatic);
    let (w, r) = matched::<ShapeType>(&pw, &pr, "LivelyAuto", &wq, &rq);
    std::thread::sleep(LEASE * 3);
    assert_eq!(w.liveliness_lost_status().total_count, 0);
    let s = r.liveliness_changed_status();
    assert_eq!((s.alive_count, s.not_alive_count), (1, 0));
}
