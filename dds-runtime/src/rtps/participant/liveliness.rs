//! Liveliness in the participant: the leases of matched writers with manual liveliness (see
//! [`crate::rtps::liveliness`]) fed by what arrives, and our own assertions on the wire.

use std::time::{Duration, Instant};

use tracing::trace;

use super::Participant;
use crate::qos::Liveliness;
use crate::rtps::api::WriteChange;
use crate::rtps::discovery::builtin;
use crate::rtps::types::{EntityId, Guid, GuidPrefix, SequenceNumber};

/// Whether `id` is one of our participant-message endpoints: matched with a peer's on first use (see
/// [`Participant::match_messages`]), not at discovery.
pub(super) fn is_message_endpoint(id: EntityId) -> bool {
    id == EntityId::P2P_MESSAGE_WRITER || id == EntityId::P2P_MESSAGE_READER
}

/// [`Participant::match_messages`]: our participant-message reader with a peer's writer.
pub(super) const MESSAGES_IN: u8 = 1;
/// [`Participant::match_messages`]: our participant-message writer with a peer's reader.
pub(super) const MESSAGES_OUT: u8 = 2;

impl Participant {
    /// Something arrived from `writer` (DATA, or a HEARTBEAT with the liveliness flag): it is alive.
    pub(super) fn writer_asserted(&mut self, now: Instant, writer: Guid) {
        if self.leases.tracks(&writer) {
            self.leases.assert_writer(now, &writer, &mut self.events);
            self.timers_changed();
        }
    }

    /// A ParticipantMessageData arrived from `writer`'s participant with `kind`.
    pub(super) fn participant_message(&mut self, now: Instant, writer: Guid, kind: [u8; 4]) {
        if kind == builtin::PMD_KIND_MANUAL {
            self.leases
                .assert_participant(now, writer.prefix, &mut self.events);
            self.timers_changed();
        }
    }

    /// The local reader `reader` matched `writer` with `liveliness`.
    pub(super) fn track_liveliness(
        &mut self,
        now: Instant,
        writer: Guid,
        reader: EntityId,
        liveliness: &Liveliness,
    ) {
        self.leases.track(now, writer, reader, liveliness);
        self.timers_changed();
    }

    /// The local reader `reader` no longer matches `writer`.
    pub(super) fn untrack_liveliness(&mut self, writer: &Guid, reader: EntityId) {
        self.leases.untrack(writer, reader);
    }

    /// Our local writer `writer` became visible with `liveliness`: its lease starts now, and the automatic
    /// assertion comes often enough for it.
    pub(super) fn track_own_lease(
        &mut self,
        now: Instant,
        writer: EntityId,
        liveliness: &Liveliness,
    ) {
        self.own_leases.track(now, writer, liveliness);
        self.pmd_due = self.pmd_due.min(now + self.automatic_interval());
        self.timers_changed();
    }

    /// How often the participant asserts its automatic liveliness (ParticipantMessageData of kind
    /// AUTOMATIC): every SPDP interval, or 2/5 of the shortest lease of an AUTOMATIC writer when that is
    /// shorter, so that one late or lost assertion does not cost the writers their liveliness.
    pub(super) fn automatic_interval(&self) -> Duration {
        let floor = Duration::from_millis(1);
        match self.own_leases.shortest_automatic() {
            Some(lease) => self.config.spdp_interval.min(lease * 2 / 5).max(floor),
            None => self.config.spdp_interval,
        }
    }

    /// Leases that ran out.
    pub(super) fn expire_leases(&mut self, now: Instant) {
        self.leases.expire(now, &mut self.events);
        self.own_leases.expire(now, &mut self.events);
    }

    /// Asserts the liveliness of this participant's MANUAL_BY_PARTICIPANT writers (DDS
    /// `DomainParticipant::assert_liveliness`): a ParticipantMessageData of kind MANUAL to every participant.
    pub fn assert_liveliness(&mut self, now: Instant) {
        if self.own_leases.assert_participant(now) {
            self.timers_changed();
        }
        self.send_participant_message(now, builtin::PMD_KIND_MANUAL);
    }

    /// Writes a ParticipantMessageData of `kind` (no data) on the builtin participant-message writer.
    pub(super) fn send_participant_message(&mut self, now: Instant, kind: [u8; 4]) {
        self.match_messages_all(now);
        let prefix = self.config.guid_prefix;
        let change = WriteChange::alive(builtin::encode_participant_message(&prefix, kind, &[]))
            .with_key_hash(builtin::participant_message_key(&prefix, kind));
        if let Some(w) = self.writers.get_mut(&EntityId::P2P_MESSAGE_WRITER) {
            let _ = w.write(now, change, &mut self.out, &mut self.events);
        }
    }

    /// Asserts the liveliness of the local writer `writer` (DDS `DataWriter::assert_liveliness`): a HEARTBEAT
    /// with the liveliness flag to its matched readers.
    pub fn assert_writer_liveliness(&mut self, now: Instant, writer: EntityId) {
        if !self.user_writers.contains(&writer) {
            return;
        }
        if self.own_leases.assert_writer(now, writer) {
            self.timers_changed();
        }
        if let Some(w) = self.writers.get_mut(&writer) {
            w.send_liveliness(&mut self.out);
        }
        self.assert_liveliness_shm(writer);
    }

    /// Matches our participant-message reader (`which` holds [`MESSAGES_IN`]) or writer ([`MESSAGES_OUT`])
    /// with the participant `prefix`'s, unless done already. A participant writes such a message only for
    /// writers with an AUTOMATIC lease (ours write none otherwise) or MANUAL_BY_PARTICIPANT liveliness, so
    /// many peers never send one, and we often never write one: each proxy is made on first use. Our
    /// reader's when the peer's writer first sends (DATA, or a HEARTBEAT announcing changes, before it is
    /// handled); our writer's with every peer before we first write, and at discovery once we have
    /// written (our writer keeps the last message of each kind for late joiners). See
    /// `docs/performance.md`, "Footprint".
    pub(super) fn match_messages(&mut self, now: Instant, prefix: GuidPrefix, which: u8) {
        let Some(p) = self.participants.get_mut(&prefix) else {
            return;
        };
        let todo = which & !p.messages_matched;
        if todo == 0 {
            return;
        }
        p.messages_matched |= todo;
        let (bits, meta) = (p.builtin_endpoints, p.metatraffic.clone());
        let group = self.metatraffic_group(&meta);
        trace!(participant = ?prefix, todo, "participant-message endpoints matched");
        let ours = move |id: EntityId| match id {
            EntityId::P2P_MESSAGE_READER => todo & MESSAGES_IN != 0,
            EntityId::P2P_MESSAGE_WRITER => todo & MESSAGES_OUT != 0,
            _ => false,
        };
        self.match_builtin_pairs(now, prefix, bits, &meta, group, ours);
    }

    /// The remote endpoints our builtin endpoint `id` is matched with (discovery, participant message,
    /// TypeLookup: see `docs/performance.md`, "Footprint", for which are matched when).
    pub fn builtin_matches(&self, id: EntityId) -> Vec<Guid> {
        if !id.is_builtin() {
            return Vec::new();
        }
        let writer = self.writers.get(&id).map(|w| w.matched().copied());
        let reader = self.readers.get(&id).map(|r| r.matched().copied());
        writer
            .into_iter()
            .flatten()
            .chain(reader.into_iter().flatten())
            .collect()
    }

    /// Whether we ever wrote a participant message.
    pub(super) fn messages_written(&self) -> bool {
        self.writers
            .get(&EntityId::P2P_MESSAGE_WRITER)
            .is_some_and(|w| w.last_sn() > SequenceNumber(0))
    }

    /// Matches our participant-message writer with every discovered participant's reader: what we write
    /// goes to all of them.
    fn match_messages_all(&mut self, now: Instant) {
        let pending: Vec<GuidPrefix> = self
            .participants
            .iter()
            .filter(|(_, p)| p.messages_matched & MESSAGES_OUT == 0)
            .map(|(prefix, _)| *prefix)
            .collect();
        for prefix in pending {
            self.match_messages(now, prefix, MESSAGES_OUT);
        }
    }
}
