//! Manual liveliness of matched writers, as a reader sees it (DDS 1.4 §2.2.3.11, RTPS 2.5 §8.4.13): one lease
//! per writer with MANUAL_BY_PARTICIPANT or MANUAL_BY_TOPIC liveliness and a finite lease duration. A writer
//! asserts its liveliness by sending DATA or a HEARTBEAT with the liveliness flag; a participant asserts all
//! its MANUAL_BY_PARTICIPANT writers at once with a ParticipantMessageData of kind MANUAL (and any of those
//! writers asserting counts for all of them). AUTOMATIC writers live by their participant's lease, which
//! discovery tracks. Sans-I/O: time comes in as an argument.

use std::collections::{HashMap, VecDeque};
use std::time::Instant;

use crate::qos::{Liveliness, LivelinessKind, INFINITE};
use crate::rtps::api::Event;
use crate::rtps::types::{EntityId, Guid, GuidPrefix};

#[derive(Debug)]
struct Lease {
    by_participant: bool,
    duration: std::time::Duration,
    deadline: Instant,
    alive: bool,
    readers: Vec<EntityId>,
}

/// The leases of the matched writers with manual liveliness.
#[derive(Debug, Default)]
pub(crate) struct Leases {
    writers: HashMap<Guid, Lease>,
}

impl Leases {
    /// `reader` matched `writer` with `liveliness`: a manual kind with a finite lease is tracked, alive from
    /// now (the match itself is the first sign of life).
    pub(crate) fn track(
        &mut self,
        now: Instant,
        writer: Guid,
        reader: EntityId,
        liveliness: &Liveliness,
    ) {
        if liveliness.kind == LivelinessKind::Automatic || liveliness.lease_duration >= INFINITE {
            return;
        }
        let Some(deadline) = now.checked_add(liveliness.lease_duration) else {
            return;
        };
        let l = self.writers.entry(writer).or_insert_with(|| Lease {
            by_participant: liveliness.kind == LivelinessKind::ManualByParticipant,
            duration: liveliness.lease_duration,
            deadline,
            alive: true,
            readers: Vec::new(),
        });
        if !l.readers.contains(&reader) {
            l.readers.push(reader);
        }
    }

    /// `reader` no longer matches `writer`.
    pub(crate) fn untrack(&mut self, writer: &Guid, reader: EntityId) {
        if let Some(l) = self.writers.get_mut(writer) {
            l.readers.retain(|r| *r != reader);
            if l.readers.is_empty() {
                self.writers.remove(writer);
            }
        }
    }

    /// Whether `writer` is tracked (has manual liveliness).
    pub(crate) fn tracks(&self, writer: &Guid) -> bool {
        !self.writers.is_empty() && self.writers.contains_key(writer)
    }

    /// `writer` asserted its liveliness (DATA, or HEARTBEAT with the liveliness flag). For a
    /// MANUAL_BY_PARTICIPANT writer this asserts every such writer of its participant.
    pub(crate) fn assert_writer(&mut self, now: Instant, writer: &Guid, out: &mut VecDeque<Event>) {
        let Some(l) = self.writers.get(writer) else {
            return;
        };
        if l.by_participant {
            self.assert_participant(now, writer.prefix, out);
        } else if let Some(l) = self.writers.get_mut(writer) {
            Self::renew(now, *writer, l, out);
        }
    }

    /// The participant `prefix` asserted its liveliness (ParticipantMessageData of kind MANUAL): renews its
    /// MANUAL_BY_PARTICIPANT writers.
    pub(crate) fn assert_participant(
        &mut self,
        now: Instant,
        prefix: GuidPrefix,
        out: &mut VecDeque<Event>,
    ) {
        for (g, l) in self
            .writers
            .iter_mut()
            .filter(|(g, l)| g.prefix == prefix && l.by_participant)
        {
            Self::renew(now, *g, l, out);
        }
    }

    fn renew(now: Instant, writer: Guid, l: &mut Lease, out: &mut VecDeque<Event>) {
        l.deadline = now.checked_add(l.duration).unwrap_or(l.deadline);
        if !l.alive {
            l.alive = true;
            Self::report(writer, l, out);
        }
    }

    fn report(writer: Guid, l: &Lease, out: &mut VecDeque<Event>) {
        for r in &l.readers {
            out.push_back(Event::LivelinessChanged {
                reader: *r,
                writer,
                alive: l.alive,
            });
        }
    }

    /// Leases that ran out by `now` lose their writer's liveliness.
    pub(crate) fn expire(&mut self, now: Instant, out: &mut VecDeque<Event>) {
        for (g, l) in self.writers.iter_mut() {
            if l.alive && now >= l.deadline {
                l.alive = false;
                Self::report(*g, l, out);
            }
        }
    }

    /// When the next live lease runs out.
    pub(crate) fn next_deadline(&self) -> Option<Instant> {
        self.writers
            .values()
            .filter(|l| l.alive)
            .map(|l| l.deadline)
            .min()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn guid(p: u8, e: u8) -> Guid {
        Guid::new(GuidPrefix([p; 12]), EntityId([0, 0, e, 2]))
    }

    fn manual(kind: LivelinessKind, ms: u64) -> Liveliness {
        Liveliness {
            kind,
            lease_duration: Duration::from_millis(ms),
        }
    }

    fn changes(out: &mut VecDeque<Event>) -> Vec<(Guid, bool)> {
        out.drain(..)
            .filter_map(|e| match e {
                Event::LivelinessChanged { writer, alive, .. } => Some((writer, alive)),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn by_topic_lease_lost_and_regained() {
        let t0 = Instant::now();
        let (w, r) = (guid(1, 1), EntityId([0, 0, 9, 7]));
        let mut l = Leases::default();
        let mut out = VecDeque::new();
        l.track(t0, w, r, &manual(LivelinessKind::ManualByTopic, 100));
        assert_eq!(l.next_deadline(), Some(t0 + Duration::from_millis(100)));
        l.assert_writer(t0 + Duration::from_millis(80), &w, &mut out);
        l.expire(t0 + Duration::from_millis(150), &mut out);
        assert!(changes(&mut out).is_empty(), "renewed at 80 ms");
        l.expire(t0 + Duration::from_millis(180), &mut out);
        assert_eq!(changes(&mut out), vec![(w, false)]);
        assert_eq!(l.next_deadline(), None);
        // A participant message does not assert a MANUAL_BY_TOPIC writer.
        l.assert_participant(t0 + Duration::from_millis(200), w.prefix, &mut out);
        assert!(changes(&mut out).is_empty());
        l.assert_writer(t0 + Duration::from_millis(210), &w, &mut out);
        assert_eq!(changes(&mut out), vec![(w, true)]);
    }

    #[test]
    fn by_participant_writers_live_together() {
        let t0 = Instant::now();
        let (a, b, other) = (guid(1, 1), guid(1, 2), guid(2, 1));
        let r = EntityId([0, 0, 9, 7]);
        let mut l = Leases::default();
        let mut out = VecDeque::new();
        for w in [a, b, other] {
            l.track(t0, w, r, &manual(LivelinessKind::ManualByParticipant, 100));
        }
        l.expire(t0 + Duration::from_millis(100), &mut out);
        assert_eq!(changes(&mut out).len(), 3);
        l.assert_participant(t0 + Duration::from_millis(120), a.prefix, &mut out);
        let mut got = changes(&mut out);
        got.sort_by_key(|(g, _)| g.entity_id.0);
        assert_eq!(got, vec![(a, true), (b, true)]);
        // One writer asserting renews its siblings too.
        l.assert_writer(t0 + Duration::from_millis(200), &b, &mut out);
        l.expire(t0 + Duration::from_millis(250), &mut out);
        assert!(changes(&mut out).is_empty());
    }

    #[test]
    fn automatic_and_infinite_are_not_tracked() {
        let t0 = Instant::now();
        let mut l = Leases::default();
        let r = EntityId([0, 0, 9, 7]);
        l.track(t0, guid(1, 1), r, &Liveliness::default());
        l.track(
            t0,
            guid(1, 2),
            r,
            &Liveliness {
                kind: LivelinessKind::ManualByTopic,
                lease_duration: INFINITE,
            },
        );
        assert!(!l.tracks(&guid(1, 1)) && !l.tracks(&guid(1, 2)));
        l.track(
            t0,
            guid(1, 3),
            r,
            &manual(LivelinessKind::ManualByTopic, 10),
        );
        l.untrack(&guid(1, 3), r);
        assert!(!l.tracks(&guid(1, 3)));
    }
}
