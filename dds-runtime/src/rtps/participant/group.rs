//! Group coherent sets on the reader side (GROUP access scope, RTPS 2.5 §8.7.6): each writer's part of a
//! group set arrives whole from its reader (`reader/coherent.rs`); here the parts wait until every writer of
//! the set delivered its part, then go to the application together, in the order written across the
//! writers (group sequence numbers; a part is cut in pieces where another writer wrote in between), sets in
//! the order written.
//!
//! A part names its set by the group sequence number of the set's first change and the digest of the set's
//! writers (both from the writer's end-of-set marker). The set is complete when the digest of the writers
//! whose parts arrived equals it, or would equal it with writers of that participant that none of our
//! readers match (their parts can never come; at most [`MAX_UNMATCHED`] such writers are tried).
//!
//! A set is discarded (its held parts counted lost) when a part of it is known lost (the reader saw a hole
//! in it), when a writer that may belong to it goes away (before or after its other parts arrive: the
//! last writers gone are remembered), when its participant goes away, when more than
//! [`MAX_PENDING`] sets of one participant wait (the oldest first), and, for best-effort readers (which
//! get no repairs), when a later set of the same participant completes. A complete set waits for the
//! earlier sets of its participant to be delivered or discarded.

use std::collections::{BTreeMap, BTreeSet, VecDeque};

use super::Participant;
use crate::rtps::api::{Event, GroupSetId, ReceivedSample};
use crate::rtps::types::{EntityId, Guid, GuidPrefix, SequenceNumber};
use crate::rtps::writer::writer_set_digest;

/// Group sets waiting per remote participant.
const MAX_PENDING: usize = 16;
/// Unmatched writers of a participant tried as members of a set we cannot see whole.
const MAX_UNMATCHED: usize = 8;
/// Released sets remembered per participant (parts for another local reader may follow).
const MAX_DONE: usize = 16;

#[derive(Debug, Default)]
struct PendingSet {
    /// The digest of the set's writers, once a part brought it.
    digest: Option<[u8; 4]>,
    writers: BTreeSet<EntityId>,
    parts: Vec<Event>,
    complete: bool,
    dead: bool,
}

#[derive(Debug, Default)]
struct Publisher {
    pending: BTreeMap<SequenceNumber, PendingSet>,
    done: VecDeque<SequenceNumber>,
    /// The first change of the latest set released or discarded: a part of an earlier set comes too late.
    released: Option<SequenceNumber>,
    /// Writers of this participant that went away lately: a set naming one of them never completes.
    gone: VecDeque<EntityId>,
}

impl Publisher {
    /// Delivers the complete sets at the front, and discards dead ones there.
    fn flush(&mut self, out: &mut VecDeque<Event>) {
        while let Some(e) = self.pending.first_entry() {
            if !(e.get().dead || e.get().complete) {
                break;
            }
            let set = *e.key();
            let s = e.remove();
            self.released = Some(set);
            if s.dead {
                discard(s, out);
                continue;
            }
            interleave(s.parts, out);
            if self.done.len() >= MAX_DONE {
                self.done.pop_front();
            }
            self.done.push_back(set);
        }
    }
}

/// The group sets being assembled, per remote participant.
#[derive(Debug, Default)]
pub(crate) struct GroupSets {
    by_prefix: BTreeMap<GuidPrefix, Publisher>,
}

/// One writer's part of a group set, as the reader delivered it.
struct Part {
    writer: Guid,
    id: GroupSetId,
    /// The `Event::CoherentSet`; its samples are empty when the part is known lost.
    ev: Event,
    lost: bool,
    /// The part's reader is best effort.
    best_effort: bool,
}

impl GroupSets {
    /// Takes one writer's part of a group set; pushes what becomes deliverable (and what is discarded, as
    /// `SampleLost`) to `out`. `unmatched`: writers of the part's participant no local reader matches.
    fn offer(&mut self, part: Part, unmatched: &[EntityId], out: &mut VecDeque<Event>) {
        let p = self.by_prefix.entry(part.writer.prefix).or_default();
        let set = part.id.set;
        if p.done.contains(&set) {
            if !part.lost {
                out.push_back(part.ev);
            }
            return;
        }
        if p.released.is_some_and(|r| set <= r) {
            discard_parts(vec![part.ev], out);
            return;
        }
        let s = p.pending.entry(set).or_default();
        if part.lost {
            s.dead = true;
        } else {
            s.digest = Some(part.id.writers);
            s.writers.insert(part.writer.entity_id);
            s.parts.push(part.ev);
            s.complete = complete(&s.writers, part.id.writers, unmatched);
            if !s.complete && !p.gone.is_empty() {
                let either: Vec<EntityId> = unmatched.iter().chain(&p.gone).copied().collect();
                s.dead = complete(&s.writers, part.id.writers, &either);
            }
        }
        if part.best_effort && s.complete {
            p.pending.range_mut(..set).for_each(|(_, s)| s.dead = true);
        }
        if p.pending.len() > MAX_PENDING {
            if let Some(mut e) = p.pending.first_entry() {
                e.get_mut().dead = true;
            }
        }
        p.flush(out);
    }

    /// A writer went away (or no longer matches): the sets it may belong to can never complete.
    fn writer_gone(&mut self, writer: Guid, unmatched: &[EntityId], out: &mut VecDeque<Event>) {
        let p = self.by_prefix.entry(writer.prefix).or_default();
        if p.gone.len() >= MAX_DONE {
            p.gone.pop_front();
        }
        p.gone.push_back(writer.entity_id);
        for s in p.pending.values_mut() {
            if s.complete || s.writers.contains(&writer.entity_id) {
                continue;
            }
            let with: BTreeSet<EntityId> = s
                .writers
                .iter()
                .copied()
                .chain([writer.entity_id])
                .collect();
            // Unknown digest (only a lost part seen): the writer may be in it.
            s.dead |= s.digest.is_none_or(|d| complete(&with, d, unmatched));
        }
        p.flush(out);
    }

    /// Forgets a remote participant, discarding its waiting sets.
    fn forget(&mut self, prefix: &GuidPrefix, out: &mut VecDeque<Event>) {
        if let Some(p) = self.by_prefix.remove(prefix) {
            p.pending.into_values().for_each(|s| discard(s, out));
        }
    }
}

/// Whether `writers` (plus some of `unmatched`) are the writers the digest names.
fn complete(writers: &BTreeSet<EntityId>, digest: [u8; 4], unmatched: &[EntityId]) -> bool {
    if writer_set_digest(writers) == digest {
        return true;
    }
    let extra: Vec<&EntityId> = unmatched
        .iter()
        .filter(|w| !writers.contains(w))
        .take(MAX_UNMATCHED)
        .collect();
    (1u32..(1 << extra.len())).any(|mask| {
        let with = extra
            .iter()
            .enumerate()
            .filter(|(i, _)| mask & (1 << i) != 0)
            .map(|(_, w)| *w);
        writer_set_digest(writers.iter().chain(with)) == digest
    })
}

/// Hands a complete group set over in the order written across its writers: its parts cut into runs of
/// consecutive group sequence numbers of one part, the runs in group sequence order (a part in several
/// pieces when another writer wrote in between). The pieces go out together, so a reader still stores its
/// whole part in one go, and a GROUP-ordered subscriber, which numbers samples in the order handed over,
/// sees the set in the publisher's write order. Parts with a change lacking a group sequence number go
/// out as they are.
fn interleave(parts: Vec<Event>, out: &mut VecDeque<Event>) {
    let numbered = |e: &Event| match e {
        Event::CoherentSet { samples, .. } => samples.iter().all(|s| s.group_sequence.is_some()),
        _ => false,
    };
    if parts.len() < 2 || !parts.iter().all(numbered) {
        out.extend(parts);
        return;
    }
    let mut heads = Vec::with_capacity(parts.len());
    let mut all = Vec::new();
    for (i, part) in parts.into_iter().enumerate() {
        if let Event::CoherentSet {
            reader,
            writer,
            samples,
            group,
        } = part
        {
            heads.push((reader, writer, group));
            all.extend(samples.into_iter().map(|s| (s.group_sequence, i, s)));
        }
    }
    all.sort_by_key(|&(g, i, _)| (g, i));
    let mut run: Option<(usize, Vec<ReceivedSample>)> = None;
    let mut emit = |(i, samples): (usize, Vec<ReceivedSample>)| {
        let (reader, writer, group) = heads[i];
        out.push_back(Event::CoherentSet {
            reader,
            writer,
            samples,
            group,
        });
    };
    for (_, i, s) in all {
        match &mut run {
            Some((j, v)) if *j == i => v.push(s),
            _ => {
                if let Some(r) = run.replace((i, vec![s])) {
                    emit(r);
                }
            }
        }
    }
    if let Some(r) = run {
        emit(r);
    }
}

/// Reports a waiting set's parts lost.
fn discard(set: PendingSet, out: &mut VecDeque<Event>) {
    discard_parts(set.parts, out);
}

fn discard_parts(parts: Vec<Event>, out: &mut VecDeque<Event>) {
    for part in parts {
        if let Event::CoherentSet {
            reader,
            writer,
            samples,
            group,
        } = part
        {
            if samples.is_empty() {
                continue;
            }
            tracing::debug!(?writer, ?group, "incomplete group coherent set discarded");
            out.push_back(Event::SampleLost {
                reader,
                writer,
                count: samples.len() as u64,
            });
        }
    }
}

impl Participant {
    /// Routes an event for the application: a part of a group coherent set waits for the rest of its set.
    /// A sample outside group ordering (nearly every one) is queued as it is, without a trip through the
    /// group ordering's checks and back (inlined for that check: it runs for every delivered sample).
    #[inline]
    pub(super) fn push_delivery(&mut self, ev: Event) {
        if matches!(&ev, Event::Sample(s) if s.group_sequence.is_none()) {
            self.events.push_back(ev);
        } else {
            self.push_ordered(ev);
        }
    }

    /// [`push_delivery`](Self::push_delivery) of an event group ordering or group coherent sets may hold.
    fn push_ordered(&mut self, ev: Event) {
        let Some(ev) = self.order_by_group(ev) else {
            return;
        };
        let Event::CoherentSet {
            reader,
            writer,
            samples,
            group: Some(id),
        } = &ev
        else {
            self.events.push_back(ev);
            return;
        };
        let part = Part {
            writer: *writer,
            id: *id,
            lost: samples.is_empty(),
            best_effort: self.readers.get(reader).is_some_and(|r| !r.is_reliable()),
            ev,
        };
        let unmatched = self.unmatched_writers(part.writer.prefix);
        self.group_sets.offer(part, &unmatched, &mut self.events);
    }

    /// Called for each event the application takes: a writer that unmatched may leave group sets
    /// incomplete forever.
    pub(super) fn note_polled(&mut self, ev: &Event) {
        if let Event::SubscriptionMatched {
            writer,
            matched: false,
            ..
        } = ev
        {
            let unmatched = self.unmatched_writers(writer.prefix);
            let unmatched: Vec<EntityId> = unmatched
                .into_iter()
                .filter(|w| *w != writer.entity_id)
                .collect();
            self.group_sets
                .writer_gone(*writer, &unmatched, &mut self.events);
            if let Some(now) = self.group_order_clock() {
                self.group_order_timeout(now);
            }
        }
    }

    /// Discards the group sets still waiting for writers of a participant that is gone.
    pub(super) fn forget_group_sets(&mut self, prefix: &GuidPrefix) {
        self.group_sets.forget(prefix, &mut self.events);
    }

    /// Known writers of a remote participant that no local user reader matches.
    fn unmatched_writers(&self, prefix: GuidPrefix) -> Vec<EntityId> {
        self.known_writers
            .keys()
            .filter(|g| g.prefix == prefix)
            .filter(|g| {
                !self
                    .user_readers
                    .iter()
                    .filter_map(|r| self.readers.get(r))
                    .any(|r| r.has_proxy(g))
            })
            .map(|g| g.entity_id)
            .collect()
    }
}
