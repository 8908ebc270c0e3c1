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
