//! Periodic work: SPDP announcements, liveliness messages, leases, writer and reader timers, lingering.

use std::cell::Cell;
use std::time::{Duration, Instant};

use tracing::debug;

use super::Participant;
use crate::rtps::api::ChangeKind;
use crate::rtps::discovery::builtin;
use crate::rtps::messages::parameter::{pid, ParameterWriter};
use crate::rtps::messages::{Data, ParameterList, Submessage};
use crate::rtps::outbox::Ts;
use crate::rtps::reader::{Reader, DISCOVERY_ACK_DELAY};
use crate::rtps::types::*;

/// Longest the cached timer floor goes without a full pass over the endpoints (a safety net: every path
/// that arms a timer also lowers or clears the floor).
const FULL_SCAN_INTERVAL: Duration = Duration::from_millis(100);

/// The room (in events) the participant's queues keep after a burst; see `Participant::trim_queues`.
pub(crate) const KEPT_QUEUE_ROOM: usize = 64;
/// The datagram buffers the outbox keeps for reuse after a burst (it holds up to 16), and the room each
/// keeps: a discovery datagram's (a stream of large samples regrows them, once per SPDP period).
const KEPT_DATAGRAMS: usize = 8;
const KEPT_DATAGRAM_BYTES: usize = 1024;

/// Lowers a known timer floor to `t`; an unknown floor stays unknown (it is rescanned anyway).
pub(super) fn lower_floor(floor: &Cell<Option<Instant>>, t: Option<Instant>) {
    if let (Some(f), Some(t)) = (floor.get(), t) {
        if t < f {
            floor.set(Some(t));
        }
    }
}

impl Participant {
    /// When `handle_timeout` must be called next.
    pub fn poll_timeout(&self) -> Option<Instant> {
        if !self.enabled {
            return None;
        }
        let t = match self.timer_floor.get() {
            Some(t) => t,
            None => {
                let t = self.scan_timers();
                self.timer_floor.set(Some(t));
                t
            }
        };
        let held = self
            .config
            .write_batch_delay
            .and_then(|d| self.out.hold_deadline(d));
        Some(held.map_or(t, |h| h.min(t)))
    }

    /// The earliest timer of the participant and every endpoint, capped so that a full pass runs at least
    /// every [`FULL_SCAN_INTERVAL`].
    fn scan_timers(&self) -> Instant {
        let mut t = self
            .spdp_due
            .min(self.pmd_due)
            .min(self.last_full_scan + FULL_SCAN_INTERVAL);
        for p in self.participants.values() {
            t = t.min(p.lease_deadline);
        }
        if let Some(x) = self.leases.next_deadline() {
            t = t.min(x);
        }
        if let Some(x) = self.own_leases.next_deadline() {
            t = t.min(x);
        }
        if let Some(x) = self.type_lookup_due() {
            t = t.min(x);
        }
        for w in self.writers.values() {
            if let Some(x) = w.next_timeout() {
                t = t.min(x);
            }
            if let Some(x) = w.linger_until {
                t = t.min(x);
            }
        }
        for r in self.readers.values() {
            if let Some(x) = r.next_timeout() {
                t = t.min(x);
            }
        }
        if let Some(x) = self.group_order.deadline() {
            t = t.min(x);
        }
        t
    }

    /// Timers may have been armed anywhere: the next `poll_timeout` rescans.
    pub(super) fn timers_changed(&self) {
        self.timer_floor.set(None);
    }

    /// Runs everything due at `now`.
    pub(super) fn service(&mut self, now: Instant) {
        if !self.enabled || self.timer_floor.get().is_some_and(|floor| now < floor) {
            return;
        }
        // Leases first: an AUTOMATIC writer whose assertion below comes too late has lost its liveliness.
        self.expire_leases(now);
        if now >= self.spdp_due {
            self.send_spdp(None);
            self.spdp_due = now + self.config.spdp_interval;
            self.trim_queues();
        }
        if now >= self.pmd_due {
            // Automatic liveliness: one ParticipantMessageData per interval renews our AUTOMATIC writers'
            // leases at peers that track them by these messages (Fast DDS). Only writers with a finite lease
            // need it: the participant's own lease is kept by SPDP, sent as often. Without such a writer
            // nothing is sent, as Cyclone does: each message costs an ACKNACK from every matched peer
            // (docs/performance.md, "Scale").
            if self.own_leases.shortest_automatic().is_some() {
                self.send_participant_message(now, builtin::PMD_KIND_AUTOMATIC);
            }
            self.own_leases.assert_automatic(now);
            self.pmd_due = now + self.automatic_interval();
        }
        self.type_lookup_timeout(now);
        self.group_order_timeout(now);
        let expired: Vec<GuidPrefix> = self
            .participants
            .iter()
            .filter(|(_, p)| p.lease_deadline <= now)
            .map(|(k, _)| *k)
            .collect();
        for prefix in expired {
            debug!(participant = ?prefix, "lease expired");
            self.remove_participant(prefix);
        }
        let lingering: Vec<EntityId> = self
            .writers
            .iter()
            .filter(|(_, w)| {
                w.linger_until
                    .is_some_and(|t| t <= now || w.is_acknowledged())
            })
            .map(|(k, _)| *k)
            .collect();
        for id in lingering {
            self.finish_writer(now, id);
        }
        for w in self.writers.values_mut() {
            if w.next_timeout().is_some_and(|t| t <= now) {
                w.on_timeout(now, &mut self.out);
            }
        }
        self.reader_timeouts(now);
        self.last_full_scan = now;
        self.timers_changed();
    }

    /// Sends the readers' due ACKNACKs. Once one is due, those due within [`DISCOVERY_ACK_DELAY`] leave
    /// with it: the acknowledgements of all our readers to one peer then share a datagram, where each
    /// would otherwise leave alone as the heartbeats it answers came in one by one.
    /// Armed ACKNACKs to a participant that a message of this pass goes to anyway leave in it.
    fn reader_timeouts(&mut self, now: Instant) {
        let mut open = std::mem::take(&mut self.open_scratch);
        self.out.open_participants(&mut open);
        for &(prefix, to) in &open {
            for r in self.readers.values_mut() {
                r.send_acknacks_along(prefix, to, &mut self.out);
            }
        }
        self.open_scratch = open;
        let due = |r: &Reader, t: Instant| r.next_timeout().is_some_and(|x| x <= t);
        if !self.readers.values().any(|r| due(r, now)) {
            return;
        }
        let until = now + DISCOVERY_ACK_DELAY;
        for r in self.readers.values_mut() {
            if due(r, until) {
                r.on_timeout(until, &mut self.out);
            }
        }
    }

    /// Gives back the room a burst left in the event queues (thousands of SEDP samples arrive in one pass
    /// when a peer with many endpoints appears): done once per SPDP period, so a steady stream does not
    /// shrink and regrow them.
    fn trim_queues(&mut self) {
        self.scratch.shrink_to(KEPT_QUEUE_ROOM);
        self.events.shrink_to(KEPT_QUEUE_ROOM);
        self.out.trim(KEPT_DATAGRAMS, KEPT_DATAGRAM_BYTES);
        self.writers.values_mut().for_each(|w| w.trim_room());
        self.readers.values_mut().for_each(|r| r.trim_room());
    }

    /// Sends our SPDP announcement to the SPDP multicast locators and initial peers, or to `to` only.
    pub(super) fn send_spdp(&mut self, to: Option<Vec<Locator>>) {
        let dest: &[Locator] = match &to {
            Some(to) => to,
            None => {
                // Rebuilt in a kept vector: the periodic announcement allocates nothing.
                let d = &mut self.spdp_dest;
                d.clear();
                d.extend_from_slice(&self.config.metatraffic_multicast);
                d.extend(self.config.initial_peers.iter().copied());
                d.sort();
                d.dedup();
                d
            }
        };
        let sn = self.spdp_sn;
        self.spdp_sn = sn.next();
        let data = Submessage::Data(Data {
            reader_id: EntityId::SPDP_READER,
            writer_id: EntityId::SPDP_WRITER,
            writer_sn: sn,
            inline_qos: None,
            payload: Some(&self.spdp_payload),
            key_flag: false,
            non_standard_flag: false,
        });
        self.out.push(dest, None, Ts::Set(None), &data);
    }

    pub(super) fn send_spdp_dispose(&mut self) {
        let guid = Guid::new(self.config.guid_prefix, EntityId::PARTICIPANT);
        let mut qos = Vec::with_capacity(32);
        let mut w = ParameterWriter::new(&mut qos, true);
        w.raw(pid::KEY_HASH, &guid.to_bytes());
        w.raw(
            pid::STATUS_INFO,
            &[0, 0, 0, ChangeKind::DisposeUnregister.status_info()],
        );
        w.without_sentinel();
        let mut key = crate::rtps::discovery::PL_CDR_LE.to_vec();
        let mut kw = ParameterWriter::new(&mut key, true);
        kw.guid(pid::PARTICIPANT_GUID, &guid);
        kw.finish();
        let mut dest = self.config.metatraffic_multicast.clone();
        dest.extend(self.config.initial_peers.iter().copied());
        for p in self.participants.values() {
            // Its first metatraffic unicast locator, from the list kept decoded (which holds its multicast
            // ones instead when it announced no unicast one): no decoding of its announcement per period.
            dest.extend(p.metatraffic.first().filter(|l| !l.is_multicast()).copied());
        }
        dest.sort();
        dest.dedup();
        let sn = self.spdp_sn;
        self.spdp_sn = sn.next();
        let data = Submessage::Data(Data {
            reader_id: EntityId::SPDP_READER,
            writer_id: EntityId::SPDP_WRITER,
            writer_sn: sn,
            inline_qos: Some(ParameterList {
                data: &qos,
                little_endian: true,
            }),
            payload: Some(&key),
            key_flag: true,
            non_standard_flag: false,
        });
        self.out.push(&dest, None, Ts::Set(None), &data);
    }
}
