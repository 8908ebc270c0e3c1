//! Liveliness in the participant: the leases of matched writers with manual liveliness (see
//! [`crate::rtps::liveliness`]) fed by what arrives, and our own assertions on the wire.

use std::time::{Duration, Instant};

use super::Participant;
use crate::qos::Liveliness;
use crate::rtps::api::WriteChange;
use crate::rtps::discovery::builtin;
use crate::rtps::types::{EntityId, Guid};

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
}
