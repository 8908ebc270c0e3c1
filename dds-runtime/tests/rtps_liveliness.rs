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

/// Participant-message endpoints are matched on first use, not at discovery (docs/performance.md,
/// "Footprint"): quiet peers have no proxies for them; a participant that asserts its liveliness matches
/// its writer with every peer first (and they match their readers with it as its message arrives), and
/// then with each peer it discovers later; a reader is matched only with a writer that sent.
#[test]
fn participant_message_endpoints_are_matched_on_first_use() {
    let (pw, pr) = (EntityId::P2P_MESSAGE_WRITER, EntityId::P2P_MESSAGE_READER);
    let mut sim = Sim::with_participants(3, Faults::NONE, 2);
    sim.run_for(Duration::from_secs(2));
    for n in 0..2 {
        let p = &sim.nodes[n].p;
        assert_eq!(
            p.builtin_matches(EntityId::SEDP_PUBLICATIONS_WRITER).len(),
            1
        );
        assert!(p.builtin_matches(pw).is_empty() && p.builtin_matches(pr).is_empty());
    }
    let now = sim.now;
    sim.nodes[0].p.assert_liveliness(now);
    sim.run_for(Duration::from_secs(1));
    assert_eq!(sim.nodes[0].p.builtin_matches(pw), [sim.guid(1, pr)]);
    assert_eq!(sim.nodes[1].p.builtin_matches(pr), [sim.guid(0, pw)]);
    assert!(
        sim.nodes[0].p.builtin_matches(pr).is_empty(),
        "node 1 wrote nothing"
    );
    let late = sim.add(config(2));
    sim.run_for(Duration::from_secs(2));
    let mut to = sim.nodes[0].p.builtin_matches(pw);
    to.sort();
    assert_eq!(to, [sim.guid(1, pr), sim.guid(late, pr)]);
    assert_eq!(
        sim.nodes[late].p.builtin_matches(pr),
        [sim.guid(0, pw)],
        "the kept message reached it"
    );
    assert!(sim.nodes[late].p.builtin_matches(pw).is_empty());
    assert!(
        sim.nodes[1].p.builtin_matches(pr).len() == 1,
        "nodes 1 and 2 exchanged none"
    );
}
