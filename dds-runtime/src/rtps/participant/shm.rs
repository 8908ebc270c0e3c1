//! Shared-memory pairs (see [`crate::rtps::shm`]): a user writer of ours and a user reader of a peer on
//! this host that can use shared memory match like intra-process pairs, without wire state (no proxy, no
//! datagram, no heartbeat or acknowledgement). The writer's changes are queued once per change for the
//! writer's channel ([`Participant::poll_shm`]); what a reader's participant reads from the channel comes
//! back through [`Participant::receive_shm`] and reaches each of its readers matched with the writer as an
//! [`Event::Sample`] sharing the frame (read in place).
//!
//! Both sides decide from the same discovery data (both participants' SPDP properties, both endpoints'
//! SEDP QoS), so a pair is on shared memory on both sides or on neither. A pair keeps the wire when the
//! writer's publisher has coherent access or the reader is reliable KEEP_ALL with `max_samples` (the same
//! rule as intra-process pairs, [`pair_qualifies`]), or when the publisher has GROUP-ordered access;
//! builtin endpoints keep it too.

use std::collections::VecDeque;
use std::sync::Arc;
use std::time::Instant;

use foldhash::HashMap;

use super::discovery::Local;
use super::local::pair_qualifies;
use super::Participant;
use crate::qos::Durability;
use crate::rtps::api::{Event, Payload, ReceivedSample, WriteChange, WriteError};
use crate::rtps::shm::{decode_header, shm_node, shm_peers, ShmChange};
use crate::rtps::types::{EntityId, Guid, SequenceNumber};

/// Most changes queued for the channels between two polls (a bound: the driver drains after each call).
const MAX_QUEUED: usize = 4096;

/// The pairs matched over shared memory, each side as it records its own match.
#[derive(Debug, Default)]
pub(super) struct ShmMatches {
    /// Writer side: our writer → the peers' readers it sends to through its channel.
    readers: HashMap<EntityId, Vec<Guid>>,
    /// Writer side: our writer → the shared-memory nodes of those readers' participants, and whether the
    /// writer is reliable.
    nodes: HashMap<EntityId, (Arc<[String]>, bool)>,
    /// Reader side: (peer's writer, our reader) → what the reader got.
    reader_side: HashMap<(Guid, EntityId), ReaderSide>,
    /// Changes for the writers' channels, in write order.
    out: VecDeque<ShmChange>,
    /// Changes whenever the set of channels our readers read changes.
    generation: u64,
}

/// A reader's side of a pair: what it got from the writer's channel.
#[derive(Debug, Clone, Copy)]
struct ReaderSide {
    /// The highest sequence number delivered.
    last: SequenceNumber,
    /// A durable reader of a durable writer waits for the history the writer replays to it (ended by a
    /// `history_end` frame): until then, changes for every reader are older than that end, and come again
    /// in the history (or are gone from it, as for any late joiner). Since when it waits.
    awaiting_history: Option<Instant>,
}

/// How long a reader waits for the history of a writer before taking its changes as they come.
const HISTORY_WAIT: std::time::Duration = std::time::Duration::from_secs(15);

impl Participant {
    /// Whether a durable reader of `writer` gets `writer`'s history: both durable, as both sides see it.
    fn shm_replays(&self, writer: &Guid, reader: &Guid) -> bool {
        let wd = self.known_writers.get(writer);
        let rd = self.known_readers.get(reader);
        wd.is_some_and(|w| w.qos.writer.durability >= Durability::TransientLocal)
            && rd.is_some_and(|r| r.qos.reader.durability >= Durability::TransientLocal)
    }

    /// Whether `local` (ours) and `remote` (a peer's) qualify for a shared-memory pair.
    fn shm_qualifies(&self, local: Local, remote: Guid) -> bool {
        let (id, ours) = match local {
            Local::Writer(w) => (w, self.user_writers.contains(&w)),
            Local::Reader(r) => (r, self.user_readers.contains(&r)),
        };
        // Service-internal endpoints are ordinary ones to peers, so they qualify like user endpoints.
        if !ours || remote.entity_id.is_builtin() {
            return false;
        }
        let Some(peer) = self.participants.get(&remote.prefix) else {
            return false;
        };
        if !shm_peers(
            self.config.properties(),
            &peer.data(remote.prefix).properties,
        ) {
            return false;
        }
        let own = Guid::new(self.config.guid_prefix, id);
        let (wd, rd) = match local {
            Local::Writer(_) => (
                self.known_writers.get(&own),
                self.known_readers.get(&remote),
            ),
            Local::Reader(_) => (
                self.known_writers.get(&remote),
                self.known_readers.get(&own),
            ),
        };
        // GROUP-ordered access orders the changes of the publisher's writers among themselves: one
        // channel per writer, drained channel by channel, would not keep that order.
        let group_ordered = |p: &crate::qos::Presentation| {
            p.ordered_access && p.access_scope == crate::qos::PresentationAccessScope::Group
        };
        matches!((wd, rd), (Some(wd), Some(rd))
            if pair_qualifies(wd, rd) && !group_ordered(&wd.qos.presentation))
    }

    /// Whether `local` and `remote` are matched over shared memory.
    pub(super) fn has_shm_match(&self, local: Local, remote: Guid) -> bool {
        match local {
            Local::Writer(w) => self
                .shm
                .readers
                .get(&w)
                .is_some_and(|rs| rs.contains(&remote)),
            Local::Reader(r) => self.shm.reader_side.contains_key(&(remote, r)),
        }
    }

    /// Matches `local` with `remote` over shared memory when the pair qualifies; a durable reader of a
    /// durable writer gets the writer's history through the channel. False: use a proxy.
    pub(super) fn add_shm_match(&mut self, now: Instant, local: Local, remote: Guid) -> bool {
        if !self.shm_qualifies(local, remote) {
            return false;
        }
        match local {
            Local::Reader(r) => {
                let own = Guid::new(self.config.guid_prefix, r);
                let side = ReaderSide {
                    last: SequenceNumber(0),
                    awaiting_history: self.shm_replays(&remote, &own).then_some(now),
                };
                self.shm.reader_side.insert((remote, r), side);
                self.shm.generation += 1;
                if let Some(wd) = self.known_writers.get(&remote) {
                    let liveliness = wd.qos.writer.liveliness;
                    self.track_liveliness(now, remote, r, &liveliness);
                }
            }
            Local::Writer(w) => {
                self.shm.readers.entry(w).or_default().push(remote);
                self.refresh_shm_nodes(w);
                let own = Guid::new(self.config.guid_prefix, w);
                if self.shm_replays(&own, &remote) {
                    self.replay_history_shm(now, w, remote);
                }
            }
        }
        tracing::debug!(?local, ?remote, "matched over shared memory");
        true
    }

    /// Unmatches a shared-memory pair; whether it was one.
    pub(super) fn remove_shm_match(&mut self, local: Local, remote: Guid) -> bool {
        match local {
            Local::Reader(r) => {
                if self.shm.reader_side.remove(&(remote, r)).is_none() {
                    return false;
                }
                self.shm.generation += 1;
                self.untrack_liveliness(&remote, r);
            }
            Local::Writer(w) => {
                let Some(rs) = self.shm.readers.get_mut(&w) else {
                    return false;
                };
                let before = rs.len();
                rs.retain(|g| *g != remote);
                if rs.len() == before {
                    return false;
                }
                self.refresh_shm_nodes(w);
            }
        }
        true
    }

    /// A local endpoint is deleted: its shared-memory pairs end (unmatch events).
    pub(super) fn forget_shm_endpoint(&mut self, id: EntityId) {
        if let Some(rs) = self.shm.readers.remove(&id) {
            self.shm.nodes.remove(&id);
            for reader in rs {
                self.events.push_back(Event::PublicationMatched {
                    writer: id,
                    reader,
                    matched: false,
                });
            }
        }
        let writers: Vec<Guid> = self
            .shm
            .reader_side
            .keys()
            .filter(|(_, r)| *r == id)
            .map(|(w, _)| *w)
            .collect();
        for writer in writers {
            self.remove_shm_match(Local::Reader(id), writer);
            self.events.push_back(Event::SubscriptionMatched {
                reader: id,
                writer,
                matched: false,
            });
        }
    }

    fn refresh_shm_nodes(&mut self, w: EntityId) {
        let mut nodes: Vec<String> = self.shm.readers.get(&w).map_or(Vec::new(), |rs| {
            rs.iter()
                .filter_map(|g| Some((g.prefix, self.participants.get(&g.prefix)?)))
                .filter_map(|(k, p)| shm_node(&p.data(k).properties).map(str::to_owned))
                .collect()
        });
        nodes.sort();
        nodes.dedup();
        if nodes.is_empty() {
            self.shm.readers.remove(&w);
            self.shm.nodes.remove(&w);
        } else {
            let reliable = self
                .known_writers
                .get(&Guid::new(self.config.guid_prefix, w))
                .is_some_and(|d| d.qos.writer.reliability.is_reliable());
            self.shm.nodes.insert(w, (nodes.into(), reliable));
        }
    }

    /// A durable reader `reader` that joins durable writer `w` gets its history through the channel,
    /// addressed to it alone, then a `history_end` frame (also when the history is empty).
    fn replay_history_shm(&mut self, now: Instant, w: EntityId, reader: Guid) {
        let Some((nodes, reliable)) = self.shm.nodes.get(&w).cloned() else {
            return;
        };
        let Some(wr) = self.writers.get_mut(&w) else {
            return;
        };
        let out = &mut self.shm.out;
        let mut end = SequenceNumber(0);
        wr.for_each_historical(now, &reader, |c| {
            let change = WriteChange {
                kind: c.kind,
                payload: c.payload.clone(),
                key_hash: c.key_hash,
                source_timestamp: c.source_timestamp,
            };
            let mut sc = ShmChange::new(w, c.sn, change, nodes.clone(), reliable);
            sc.target = Some(reader);
            end = end.max(c.sn);
            out.push_back(sc);
        });
        let mut sc = ShmChange::new(
            w,
            end,
            WriteChange::alive(Payload::default()),
            nodes,
            reliable,
        );
        sc.target = Some(reader);
        sc.history_end = true;
        out.push_back(sc);
    }

    /// Queues a change just written as `sn` for the writer's channel, when it has readers there
    /// (`loaned`: the sample is in a buffer of the channel that the driver holds, see
    /// [`ShmChange::loaned`]).
    pub(super) fn deliver_shm(
        &mut self,
        writer: EntityId,
        sn: SequenceNumber,
        change: &WriteChange,
        loaned: bool,
    ) {
        let Some((nodes, reliable)) = self.shm.nodes.get(&writer) else {
            return;
        };
        if self.shm.out.len() >= MAX_QUEUED {
            tracing::warn!(?writer, "shared-memory queue full: change dropped");
            return;
        }
        let mut c = ShmChange::new(writer, sn, change.clone(), nodes.clone(), *reliable);
        c.loaned = loaned;
        self.shm.out.push_back(c);
    }

    /// `DataWriter::assert_liveliness` of `writer`: its readers over shared memory are told through its
    /// channel (on the wire it is a HEARTBEAT with the liveliness flag).
    pub(super) fn assert_liveliness_shm(&mut self, writer: EntityId) {
        let Some((nodes, reliable)) = self.shm.nodes.get(&writer) else {
            return;
        };
        let mut c = ShmChange::new(
            writer,
            SequenceNumber(0),
            WriteChange::alive(Payload::default()),
            nodes.clone(),
            *reliable,
        );
        c.liveliness = true;
        self.shm.out.push_back(c);
    }

    /// The shared-memory nodes (participants) of `writer`'s readers over shared memory.
    pub fn shm_nodes(&self, writer: EntityId) -> Vec<String> {
        self.shm
            .nodes
            .get(&writer)
            .map_or(Vec::new(), |(n, _)| n.to_vec())
    }

    /// Whether `writer` has readers over shared memory.
    pub fn has_shm_readers(&self, writer: EntityId) -> bool {
        self.shm.nodes.contains_key(&writer)
    }

    /// The next change to send on a writer's channel (in write order): write its frame into a buffer of
    /// the channel ([`ShmChange::write_frame`]) and send it to the subscribers of `nodes`.
    pub fn poll_shm(&mut self) -> Option<ShmChange> {
        self.shm.out.pop_front()
    }

    /// A number that changes whenever [`shm_subscriptions`](Self::shm_subscriptions) may have changed.
    pub fn shm_generation(&self) -> u64 {
        self.shm.generation
    }

    /// The peers' writers whose channels our readers read (each once).
    pub fn shm_subscriptions(&self) -> Vec<Guid> {
        let mut ws: Vec<Guid> = self.shm.reader_side.keys().map(|(w, _)| *w).collect();
        ws.sort();
        ws.dedup();
        ws
    }

    /// The peers' readers `writer` delivers to over shared memory.
    pub(super) fn shm_readers(&self, writer: EntityId) -> &[Guid] {
        self.shm.readers.get(&writer).map_or(&[], Vec::as_slice)
    }

    /// The writers of peers that deliver to `reader` over shared memory.
    pub(super) fn shm_writers_of(&self, reader: EntityId) -> impl Iterator<Item = Guid> + '_ {
        self.shm
            .reader_side
            .keys()
            .filter(move |(_, r)| *r == reader)
            .map(|(w, _)| *w)
    }

    /// Whether a change of `writer` written in a buffer of its channel (`DataWriter::loan`) must also be
    /// given to the core with its payload: when the writer has no readers on shared memory, or another
    /// use for it (a reader on the wire or in this participant, a durable history). Otherwise the core
    /// gets an empty payload and the sample goes in the loaned buffer alone.
    pub fn loan_needs_payload(&self, writer: EntityId) -> bool {
        let durable = self
            .known_writers
            .get(&Guid::new(self.config.guid_prefix, writer))
            .is_none_or(|d| d.qos.writer.durability >= Durability::TransientLocal);
        !self.has_shm_readers(writer)
            || durable
            || !self.local_readers(writer).is_empty()
            || self
                .writers
                .get(&writer)
                .is_none_or(|w| w.matched().next().is_some())
    }

    /// [`Participant::write_filtered`] of a change written in a buffer loaned from the writer's channel:
    /// when the writer has readers on shared memory the driver sends that buffer (its sequence number is
    /// the one returned; whether it was queued for the channel is the `bool`). Give the change its payload
    /// when [`loan_needs_payload`](Self::loan_needs_payload) says so.
    pub fn write_loaned(
        &mut self,
        now: Instant,
        writer: EntityId,
        change: WriteChange,
        rejected: Vec<Guid>,
    ) -> Result<(SequenceNumber, bool), WriteError> {
        if !self.has_shm_readers(writer) {
            return self
                .write_filtered(now, writer, change, rejected)
                .map(|sn| (sn, false));
        }
        self.write_delivering(now, writer, change, rejected, true)
            .map(|sn| (sn, true))
    }

    /// A frame read from `writer`'s channel (shared, typically read in place): each of our readers matched
    /// with it over shared memory gets the change as an event, once (a change addressed to one reader
    /// reaches only that one; one at or below what a reader already got is skipped; a durable reader
    /// waiting for the writer's history takes only that history until its end). Anything that is not a
    /// frame is dropped.
    pub fn receive_shm(&mut self, now: Instant, writer: Guid, frame: Payload) {
        let h = match decode_header(&frame) {
            Ok(h) => h,
            Err(e) => {
                tracing::debug!(?writer, error = %e, "not a shared-memory frame");
                return;
            }
        };
        if h.liveliness {
            self.writer_asserted(now, writer);
            return;
        }
        let payload = frame.slice(h.payload.clone());
        let own = self.config.guid_prefix;
        let mut any = false;
        for ((w, r), side) in self.shm.reader_side.iter_mut() {
            if *w != writer || h.target.is_some_and(|t| t != Guid::new(own, *r)) {
                continue;
            }
            if h.history_end {
                side.awaiting_history = None;
                side.last = side.last.max(h.sequence);
                continue;
            }
            let waiting = side
                .awaiting_history
                .is_some_and(|since| now.saturating_duration_since(since) < HISTORY_WAIT);
            if (waiting && h.target.is_none()) || h.sequence <= side.last {
                continue;
            }
            side.last = h.sequence;
            any = true;
            self.events.push_back(Event::Sample(ReceivedSample {
                reader: *r,
                writer,
                sequence: h.sequence,
                kind: h.kind,
                payload: payload.clone(),
                key_hash: h.key_hash,
                source_timestamp: h.source_timestamp,
                group_sequence: None,
            }));
        }
        if any {
            self.writer_asserted(now, writer);
        } else {
            tracing::trace!(
                ?writer,
                sequence = h.sequence.0,
                "shared-memory frame for no reader"
            );
        }
    }
}
