//! AUTOMATIC liveliness of our own writers in the simulator: the participant asserts often enough for the
//! shortest AUTOMATIC lease (even one shorter than the SPDP interval), so an idle writer keeps its
//! liveliness while the participant's timers run on time, and loses it (LIVELINESS_LOST, once) when they
//! run late past the lease, as a stalled process would.

mod rtps_support;

use std::time::Duration;

use dds_runtime::qos::*;
use dds_runtime::rtps::*;
use rtps_support::*;

fn automatic(ms: u64) -> Liveliness {
    Liveliness {
        kind: LivelinessKind::Automatic,
        lease_duration: Duration::from_millis(ms),
    }
}

fn lost(events: &[Event], writer: EntityId) -> usize {
    events
        .iter()
        .filter(|e| **e == Event::LivelinessLost { writer })
        .count()
}

#[test]
fn automatic_writer_keeps_its_liveliness_on_time_and_loses_it_when_the_timers_run_late() {
    let wq = DataWriterQos::builder().liveliness(automatic(200)).build();
    let rq = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .liveliness(automatic(200))
        .build();
    // SPDP every 500 ms (rtps_support::config), more than twice the lease.
    let (mut sim, w, _r) = Sim::writer_and_reader(7, Faults::NONE, wq, rq);
    let before = sim.datagrams_sent;
    sim.run_for(Duration::from_secs(2));
    assert_eq!(lost(&sim.nodes[0].events, w), 0, "lost while on time");
    // At least one automatic assertion per 2/5 of the lease (80 ms): 25 in 2 s, to one peer.
    assert!(
        sim.datagrams_sent - before >= 25,
        "{} datagrams in 2 s",
        sim.datagrams_sent - before
    );
    // The participant's timers stall for 500 ms.
    sim.now += Duration::from_millis(500);
    let now = sim.now;
    sim.nodes[0].p.handle_timeout(now);
    let mut events = Vec::new();
    while let Some(e) = sim.nodes[0].p.poll_event() {
        events.push(e);
    }
    assert_eq!(lost(&events, w), 1, "not lost after a stall: {events:?}");
    sim.run_for(Duration::from_secs(1));
    assert_eq!(lost(&sim.nodes[0].events, w), 0, "lost again once on time");
}
