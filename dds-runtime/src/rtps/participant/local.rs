//! Intra-process delivery: a user writer and a user reader of this participant match without wire state
//! (no reader proxy, no writer proxy, no datagram, no acknowledgement). Each change the writer writes
//! reaches the reader as an [`Event::Sample`] sharing the writer's payload (no copy), in the same call; a
//! durable reader that joins late gets the writer's history the same way.
//!
//! A pair keeps the wire path when intra-process delivery is off, when the writer's publisher has coherent
//! access (coherent sets are assembled by the RTPS reader: test
//! `dcps_presentation::coherent_sets_are_all_or_nothing_within_one_participant`), or when the reader is
//! reliable KEEP_ALL with `max_samples` (its back-pressure is the RTPS reader's delivery credit).
//!
//! The IGNORE_LOCAL policy ([`IgnoreLocal`]) keeps endpoints of this participant, or of this process, from
//! matching at all: [`ignores_local`], with the process's participants in [`PROCESS_PARTICIPANTS`].

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, PoisonError};
use std::time::Instant;

use foldhash::{HashMap, HashSet};

use super::discovery::Local;
use super::Participant;
use crate::qos::{Durability, History, IgnoreLocal, Reliability};
use crate::rtps::api::{Event, ReceivedSample, WriteChange};
use crate::rtps::discovery::{ReaderData, WriterData};
use crate::rtps::types::{EntityId, Guid, GuidPrefix, SequenceNumber};

/// The local pairs matched for intra-process delivery. Each side records its own match, as each side of a
/// wire match has its own proxy: the writer's side (writer → its readers, what delivery reads) and the
/// reader's side.
#[derive(Debug, Default)]
pub(super) struct LocalMatches {
    readers: HashMap<EntityId, Vec<EntityId>>,
    reader_side: HashSet<(EntityId, EntityId)>,
    /// This participant's prefix in [`PROCESS_PARTICIPANTS`], removed on drop.
    member: Option<GuidPrefix>,
}

/// The prefixes of the participants alive in this process, for `IgnoreLocal::Process` (a prefix does not
/// say which process made it reliably: the process id in ours may repeat on another host).
static PROCESS_PARTICIPANTS: Mutex<Vec<GuidPrefix>> = Mutex::new(Vec::new());

fn process_participants() -> std::sync::MutexGuard<'static, Vec<GuidPrefix>> {
    PROCESS_PARTICIPANTS
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
}

/// The IGNORE_LOCAL policies other than `None` of the user endpoints of this process's participants. The
/// policy is not announced, so a participant learns another's endpoints' here: either side asking to be
/// ignored is enough, in both participants (as in Cyclone). An entry goes with its participant (entity
/// ids are not reused).
static PROCESS_POLICIES: Mutex<Vec<(Guid, IgnoreLocal)>> = Mutex::new(Vec::new());
/// Whether `PROCESS_POLICIES` ever held an entry (matching skips its lock until then).
static ANY_POLICY: AtomicBool = AtomicBool::new(false);

fn process_policies() -> std::sync::MutexGuard<'static, Vec<(Guid, IgnoreLocal)>> {
    PROCESS_POLICIES
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
}

/// An endpoint's IGNORE_LOCAL: its own, or the participant's default (`ParticipantConfig::ignore_local`)
/// when its own is `Inherit` (an explicit `None` stays).
pub(super) fn inherit(own: &mut IgnoreLocal, participant_default: IgnoreLocal) {
    *own = own.or_inherited(participant_default);
}

/// Records the IGNORE_LOCAL policy of this process's endpoint `guid` for the process's other participants.
pub(super) fn note_ignore_local(guid: Guid, policy: IgnoreLocal) {
    if policy != IgnoreLocal::None {
        process_policies().push((guid, policy));
        ANY_POLICY.store(true, Ordering::Release);
    }
}

/// The policy of endpoint `guid`: `announced` (its own, for this participant's), else what its participant
/// in this process recorded. A discovered endpoint's QoS says `Inherit` (no PID carries the policy).
fn policy_of(guid: Guid, announced: IgnoreLocal) -> IgnoreLocal {
    let announced = announced.or_inherited(IgnoreLocal::None);
    if announced != IgnoreLocal::None || !ANY_POLICY.load(Ordering::Acquire) {
        return announced;
    }
    let policies = process_policies();
    policies
        .iter()
        .find(|(g, _)| *g == guid)
        .map_or(IgnoreLocal::None, |(_, p)| *p)
}

impl Drop for LocalMatches {
    fn drop(&mut self) {
        if let Some(me) = self.member {
            process_participants().retain(|p| *p != me);
            if ANY_POLICY.load(Ordering::Acquire) {
                process_policies().retain(|(g, _)| g.prefix != me);
            }
        }
    }
}

/// Whether IGNORE_LOCAL keeps `wd` and `rd` from matching: either side excludes the other's participant
/// (`Participant` or `Process` on the same prefix) or process (`Process` on a participant of this process).
/// The policy of an endpoint of another participant of this process is the one it recorded
/// ([`note_ignore_local`]); a peer's in another process is not announced: it counts as `None`.
pub(super) fn ignores_local(wd: &WriterData, rd: &ReaderData) -> bool {
    let wp = policy_of(wd.guid, wd.qos.writer.ignore_local);
    let rp = policy_of(rd.guid, rd.qos.reader.ignore_local);
    if wp == IgnoreLocal::None && rp == IgnoreLocal::None {
        return false;
    }
    let (a, b) = (wd.guid.prefix, rd.guid.prefix);
    if a == b {
        return true;
    }
    let process = wp == IgnoreLocal::Process || rp == IgnoreLocal::Process;
    process && {
        let members = process_participants();
        members.contains(&a) && members.contains(&b)
    }
}

impl LocalMatches {
    /// Records this participant as one of the process's (see [`ignores_local`]).
    pub(super) fn join_process(&mut self, prefix: GuidPrefix) {
        process_participants().push(prefix);
        self.member = Some(prefix);
    }

    fn has(&self, side: Local, writer: EntityId, reader: EntityId) -> bool {
        match side {
            Local::Writer(_) => self
                .readers
                .get(&writer)
                .is_some_and(|rs| rs.contains(&reader)),
            Local::Reader(_) => self.reader_side.contains(&(writer, reader)),
        }
    }

    fn remove(&mut self, side: Local, writer: EntityId, reader: EntityId) -> bool {
        if let Local::Reader(_) = side {
            return self.reader_side.remove(&(writer, reader));
        }
        let Some(rs) = self.readers.get_mut(&writer) else {
            return false;
        };
        let before = rs.len();
        rs.retain(|r| *r != reader);
        let removed = rs.len() != before;
        if rs.is_empty() {
            self.readers.remove(&writer);
        }
        removed
    }
}

/// Whether a writer and a reader may be matched without wire state (intra-process or over shared memory):
/// not when the writer's publisher has coherent access (coherent sets are assembled by the RTPS reader),
/// nor when the reader is reliable KEEP_ALL with `max_samples` (its back-pressure is the RTPS reader's
/// delivery credit).
pub(super) fn pair_qualifies(wd: &WriterData, rd: &ReaderData) -> bool {
    let rq = &rd.qos.reader;
    let credit = matches!(rq.reliability, Reliability::Reliable { .. })
        && matches!(rq.history, History::KeepAll)
        && rq.resource_limits.max_samples.is_some();
    !wd.qos.presentation.coherent_access && !credit
}

/// The (writer, reader) entity ids of `local` and `remote`, when `remote` is an endpoint of this participant.
fn pair(own: GuidPrefix, local: Local, remote: Guid) -> Option<(EntityId, EntityId)> {
    if remote.prefix != own {
        return None;
    }
    Some(match local {
        Local::Writer(w) => (w, remote.entity_id),
        Local::Reader(r) => (remote.entity_id, r),
    })
}

impl Participant {
    fn own_guid(&self, id: EntityId) -> Guid {
        Guid::new(self.config.guid_prefix, id)
    }

    /// Whether `local` and `remote` are matched for intra-process delivery.
    /// (Or, with a peer's endpoint, over shared memory: see `shm.rs`.)
    pub(super) fn has_local_match(&self, local: Local, remote: Guid) -> bool {
        match pair(self.config.guid_prefix, local, remote) {
            Some((w, r)) => self.local.has(local, w, r),
            None => self.has_shm_match(local, remote),
        }
    }

    /// Whether this pair of user endpoints of ours is delivered intra-process (see the module doc).
    fn delivers_locally(&self, writer: EntityId, reader: EntityId) -> bool {
        if !self.config.intra_process
            || !self.user_writers.contains(&writer)
            || !self.user_readers.contains(&reader)
        {
            return false;
        }
        let (Some(wd), Some(rd)) = (
            self.known_writers.get(&self.own_guid(writer)),
            self.known_readers.get(&self.own_guid(reader)),
        ) else {
            return false;
        };
        pair_qualifies(wd, rd)
    }

    /// Matches `local` with `remote` for intra-process delivery when both are ours and the pair qualifies;
    /// a durable reader of a durable writer gets the writer's history at once. A peer's endpoint may match
    /// over shared memory instead (`shm.rs`). False: use a proxy.
    pub(super) fn add_local_match(&mut self, now: Instant, local: Local, remote: Guid) -> bool {
        let Some((w, r)) = pair(self.config.guid_prefix, local, remote) else {
            return self.add_shm_match(now, local, remote);
        };
        if !self.delivers_locally(w, r) {
            return false;
        }
        let wguid = self.own_guid(w);
        if let Local::Reader(_) = local {
            self.local.reader_side.insert((w, r));
            if let Some(wd) = self.known_writers.get(&wguid) {
                let liveliness = wd.qos.writer.liveliness;
                self.track_liveliness(now, wguid, r, &liveliness);
            }
            return true;
        }
        self.local.readers.entry(w).or_default().push(r);
        self.refresh_reader_filter(w, self.own_guid(r));
        let durable = self
            .known_readers
            .get(&self.own_guid(r))
            .is_some_and(|rd| rd.qos.reader.durability >= Durability::TransientLocal);
        if durable {
            self.replay_history(now, w, r);
        }
        tracing::debug!(writer = ?w, reader = ?r, "matched for intra-process delivery");
        true
    }

    /// Unmatches an intra-process (or shared-memory) pair; whether it was one.
    pub(super) fn remove_local_match(&mut self, local: Local, remote: Guid) -> bool {
        let Some((w, r)) = pair(self.config.guid_prefix, local, remote) else {
            return self.remove_shm_match(local, remote);
        };
        if !self.local.remove(local, w, r) {
            return false;
        }
        // A deleted endpoint has no side left to unmatch: drop its side with the other one.
        if !self.user_readers.contains(&r) {
            self.local.reader_side.remove(&(w, r));
        }
        if !self.user_writers.contains(&w) {
            self.local.remove(Local::Writer(w), w, r);
        }
        if let Local::Reader(_) = local {
            self.untrack_liveliness(&self.own_guid(w), r);
            return true;
        }
        let rguid = self.own_guid(r);
        if let Some(wr) = self.writers.get_mut(&w) {
            wr.filters.set(rguid, None);
        }
        true
    }

    /// A durable reader `r` that joins durable writer `w` gets its history as events.
    fn replay_history(&mut self, now: Instant, w: EntityId, r: EntityId) {
        let wguid = self.own_guid(w);
        let rguid = self.own_guid(r);
        let Some(wr) = self.writers.get_mut(&w) else {
            return;
        };
        let events = &mut self.events;
        wr.for_each_historical(now, &rguid, |c| {
            events.push_back(Event::Sample(ReceivedSample {
                reader: r,
                writer: wguid,
                sequence: c.sn,
                kind: c.kind,
                payload: c.payload.clone(),
                key_hash: c.key_hash,
                source_timestamp: c.source_timestamp,
                group_sequence: None,
            }));
        });
    }

    /// The writers of this participant that deliver to `reader` intra-process.
    pub(super) fn local_writers_of(&self, reader: EntityId) -> impl Iterator<Item = EntityId> + '_ {
        self.local
            .reader_side
            .iter()
            .filter(move |(_, r)| *r == reader)
            .map(|(w, _)| *w)
    }

    /// The readers of this participant that `writer` delivers to intra-process (empty for most writers).
    pub fn local_readers(&self, writer: EntityId) -> &[EntityId] {
        self.local.readers.get(&writer).map_or(&[], Vec::as_slice)
    }

    /// Whether a change `writer` writes now needs its serialized form: it has readers on the wire or on
    /// shared memory, or keeps its history for late joiners (true for unknown writers). When false, a
    /// typed sample may be written unserialized ([`Payload::local`](crate::rtps::Payload::local) with
    /// length 0): only this participant's readers get it. Decide under the same lock as the write.
    pub fn writer_needs_bytes(&self, writer: EntityId) -> bool {
        self.has_shm_readers(writer) || self.writers.get(&writer).is_none_or(|w| w.needs_bytes())
    }

    /// Gives a change just written as `sn` to the writer's intra-process readers, as events (the
    /// serialized form: for writes that do not come with a typed sample).
    pub(super) fn deliver_local(
        &mut self,
        now: Instant,
        writer: EntityId,
        sn: SequenceNumber,
        change: WriteChange,
        rejected: &[Guid],
    ) {
        let wguid = self.own_guid(writer);
        let Some(readers) = self.local.readers.get(&writer) else {
            return;
        };
        for &r in readers {
            if rejected.contains(&Guid::new(wguid.prefix, r)) {
                continue;
            }
            self.events.push_back(Event::Sample(ReceivedSample {
                reader: r,
                writer: wguid,
                sequence: sn,
                kind: change.kind,
                payload: change.payload.clone(),
                key_hash: change.key_hash,
                source_timestamp: change.source_timestamp,
                group_sequence: None,
            }));
        }
        self.writer_asserted(now, wguid);
    }
}
