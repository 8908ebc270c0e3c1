//! A writer's liveliness: asserting it on the wire (MANUAL_BY_TOPIC, RTPS 2.5 §8.4.13: a HEARTBEAT with the
//! liveliness flag to every matched reader), and the leases our own writers committed to, which raise
//! LIVELINESS_LOST when a writer fails to assert in time.

use std::collections::{BTreeMap, VecDeque};
use std::time::{Duration, Instant};

use super::Writer;
use crate::qos::{Liveliness, LivelinessKind, INFINITE};
use crate::rtps::api::Event;
use crate::rtps::messages::Submessage;
use crate::rtps::outbox::{Outbox, Ts};
use crate::rtps::types::{EntityId, Locator};

impl Writer {
    /// Sends a final HEARTBEAT with the liveliness flag set to each matched reader's locator.
    pub(crate) fn send_liveliness(&mut self, out: &mut Outbox) {
        let mut dest: Vec<Locator> = self
            .proxies
            .values()
            .filter_map(|p| p.destination().first().copied())
            .collect();
        dest.sort();
        dest.dedup();
        if dest.is_empty() {
            return;
        }
        let mut hb = self.heartbeat(EntityId::UNKNOWN, true);
        if let Submessage::Heartbeat(h) = &mut hb {
            h.liveliness_flag = true;
        }
        out.push(&dest, None, Ts::Any, &hb);
    }
}

/// The liveliness our own writers committed to (DDS 1.4 §2.2.3.11): one lease per local writer with a
/// finite lease duration.
/// - MANUAL_BY_TOPIC: a write or `assert_liveliness` of the writer renews it.
/// - MANUAL_BY_PARTICIPANT: those of every such writer of the participant, and the participant's
///   `assert_liveliness`, renew it.
/// - AUTOMATIC: the participant's own periodic assertion ([`OwnLeases::assert_automatic`], sent at a rate
///   that fits the shortest such lease) and the writer's writes renew it, so it runs out only when the
///   participant fails to assert in time (its timers ran late: a stalled process).
///
/// A lease that runs out reports [`Event::LivelinessLost`] once, until it is renewed. Sans-I/O: time comes
/// in as an argument.
#[derive(Debug, Default)]
pub(crate) struct OwnLeases {
    writers: BTreeMap<EntityId, OwnLease>,
}

#[derive(Debug)]
struct OwnLease {
    kind: LivelinessKind,
    duration: Duration,
    deadline: Instant,
    lost: bool,
}

impl OwnLeases {
    /// The local writer `writer` was created with `liveliness`; its lease starts now.
    pub(crate) fn track(&mut self, now: Instant, writer: EntityId, liveliness: &Liveliness) {
        if liveliness.lease_duration >= INFINITE {
            return;
        }
        let Some(deadline) = now.checked_add(liveliness.lease_duration) else {
            return;
        };
        self.writers.insert(
            writer,
            OwnLease {
                kind: liveliness.kind,
                duration: liveliness.lease_duration,
                deadline,
                lost: false,
            },
        );
    }

    /// The writer is gone.
    pub(crate) fn untrack(&mut self, writer: EntityId) {
        self.writers.remove(&writer);
    }

    /// The writer wrote or asserted its liveliness. Cheap when no writer is tracked (the write path).
    /// Returns whether a lease that had run out was revived (a timer to arm again).
    pub(crate) fn assert_writer(&mut self, now: Instant, writer: EntityId) -> bool {
        if self.writers.is_empty() {
            return false;
        }
        match self.writers.get_mut(&writer) {
            Some(l) if l.kind == LivelinessKind::ManualByParticipant => {
                self.assert_participant(now)
            }
            Some(l) => l.renew(now),
            None => false,
        }
    }

    /// The participant asserted its liveliness: renews every MANUAL_BY_PARTICIPANT writer. Returns whether
    /// a lease that had run out was revived.
    pub(crate) fn assert_participant(&mut self, now: Instant) -> bool {
        self.renew_kind(now, LivelinessKind::ManualByParticipant)
    }

    /// The participant sent its periodic automatic assertion: renews every AUTOMATIC writer. Returns
    /// whether a lease that had run out was revived.
    pub(crate) fn assert_automatic(&mut self, now: Instant) -> bool {
        self.renew_kind(now, LivelinessKind::Automatic)
    }

    fn renew_kind(&mut self, now: Instant, kind: LivelinessKind) -> bool {
        let mut revived = false;
        for l in self.writers.values_mut().filter(|l| l.kind == kind) {
            revived |= l.renew(now);
        }
        revived
    }

    /// The shortest lease of an AUTOMATIC writer: the participant asserts more often than that.
    pub(crate) fn shortest_automatic(&self) -> Option<Duration> {
        self.writers
            .values()
            .filter(|l| l.kind == LivelinessKind::Automatic)
            .map(|l| l.duration)
            .min()
    }

    /// Leases that ran out by `now`: [`Event::LivelinessLost`] for each writer that had not lost it yet.
    pub(crate) fn expire(&mut self, now: Instant, out: &mut VecDeque<Event>) {
        for (id, l) in &mut self.writers {
            if !l.lost && now >= l.deadline {
                l.lost = true;
                out.push_back(Event::LivelinessLost { writer: *id });
            }
        }
    }

    /// When the next lease that has not run out yet runs out.
    pub(crate) fn next_deadline(&self) -> Option<Instant> {
        self.writers
            .values()
            .filter(|l| !l.lost)
            .map(|l| l.deadline)
            .min()
    }
}

impl OwnLease {
    /// Renews the lease; whether it had run out.
    fn renew(&mut self, now: Instant) -> bool {
        self.deadline = now.checked_add(self.duration).unwrap_or(self.deadline);
        std::mem::replace(&mut self.lost, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lease(kind: LivelinessKind, ms: u64) -> Liveliness {
        Liveliness {
            kind,
            lease_duration: Duration::from_millis(ms),
        }
    }

    fn lost(out: &mut VecDeque<Event>) -> Vec<EntityId> {
        out.drain(..)
            .filter_map(|e| match e {
                Event::LivelinessLost { writer } => Some(writer),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn by_topic_writer_loses_once_and_recovers_by_writing() {
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        let (w, other) = (EntityId([0, 0, 1, 2]), EntityId([0, 0, 2, 2]));
        let mut l = OwnLeases::default();
        let mut out = VecDeque::new();
        l.track(t0, w, &lease(LivelinessKind::ManualByTopic, 100));
        l.track(t0, other, &Liveliness::default());
        assert_eq!(l.next_deadline(), Some(t0 + ms(100)));
        assert!(!l.assert_writer(t0 + ms(90), w));
        l.expire(t0 + ms(150), &mut out);
        assert!(lost(&mut out).is_empty(), "renewed at 90 ms");
        // The participant's assertion does not count for a MANUAL_BY_TOPIC writer.
        assert!(!l.assert_participant(t0 + ms(180)));
        l.expire(t0 + ms(190), &mut out);
        l.expire(t0 + ms(300), &mut out);
        assert_eq!(lost(&mut out), vec![w], "reported once per lapse");
        assert_eq!(l.next_deadline(), None);
        assert!(l.assert_writer(t0 + ms(310), w), "revived");
        l.expire(t0 + ms(410), &mut out);
        assert_eq!(lost(&mut out), vec![w]);
        l.untrack(w);
        assert_eq!(l.next_deadline(), None);
    }

    #[test]
    fn by_participant_writers_are_renewed_together() {
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        let (a, b) = (EntityId([0, 0, 1, 2]), EntityId([0, 0, 2, 2]));
        let mut l = OwnLeases::default();
        let mut out = VecDeque::new();
        l.track(t0, a, &lease(LivelinessKind::ManualByParticipant, 100));
        l.track(t0, b, &lease(LivelinessKind::ManualByParticipant, 100));
        assert!(!l.assert_writer(t0 + ms(80), a));
        l.expire(t0 + ms(150), &mut out);
        assert!(lost(&mut out).is_empty(), "a's write renewed b");
        l.expire(t0 + ms(180), &mut out);
        assert_eq!(lost(&mut out), vec![a, b]);
        assert!(l.assert_participant(t0 + ms(200)));
        assert_eq!(l.next_deadline(), Some(t0 + ms(300)));
    }
}

#[cfg(test)]
mod automatic_tests {
    use super::*;

    #[test]
    fn automatic_writers_are_renewed_by_the_participants_assertion_and_by_writes() {
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        let (a, m) = (EntityId([0, 0, 1, 2]), EntityId([0, 0, 2, 2]));
        let mut l = OwnLeases::default();
        let mut out = VecDeque::new();
        let lease = |kind| Liveliness {
            kind,
            lease_duration: ms(100),
        };
        l.track(t0, a, &lease(LivelinessKind::Automatic));
        l.track(t0, m, &lease(LivelinessKind::ManualByParticipant));
        assert_eq!(l.shortest_automatic(), Some(ms(100)));
        assert!(!l.assert_automatic(t0 + ms(90)));
        l.expire(t0 + ms(150), &mut out);
        assert!(
            out.iter()
                .all(|e| matches!(e, Event::LivelinessLost { writer } if *writer == m)),
            "the automatic assertion renews AUTOMATIC writers only: {out:?}"
        );
        out.clear();
        assert!(!l.assert_writer(t0 + ms(180), a), "a write renews it too");
        l.expire(t0 + ms(250), &mut out);
        assert!(out.is_empty());
        l.expire(t0 + ms(400), &mut out);
        assert_eq!(out.len(), 1, "lost once when the assertion came late");
        assert!(l.assert_automatic(t0 + ms(410)), "revived");
    }
}
