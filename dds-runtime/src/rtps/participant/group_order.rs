//! GROUP ordered access on the reader side (DDS 1.4 §2.2.3.6, RTPS 2.5 §8.7.5): what a subscriber's readers
//! receive from the writers of one remote publisher goes to the application in the order of the changes'
//! group sequence numbers (`PID_GROUP_SEQ_NUM`), across writers and topics, also when a repair brings one
//! writer's change after a later change of another.
//!
//! Each reliable reader delivers its writer's changes in order, so a change with group sequence number `g`
//! can go once no other writer of the publisher that our group-ordered readers match may still send one
//! numbered below `g`. What we know of each such (reader, writer) pair is `through`: every change of that
//! writer numbered up to it reached the reader. It grows with each change the reader delivers (its number),
//! and with each HEARTBEAT carrying GroupInfo that finds the reader holding every change up to the
//! heartbeat's `lastSN` (its `currentGSN`: the writer wrote nothing else numbered up to there). A held change
//! goes when it follows the last one handed over without a gap in the numbers, or when every pair's
//! `through` reached the number below it. Numbers no pair will ever deliver (changes of the publisher's
//! writers we do not match) are skipped by the second rule, so they cost a wait for the other writers'
//! next heartbeat.
//!
//! Which writers share a publisher: the group each announces in SEDP (`PID_GROUP_ENTITYID` or
//! `PID_GROUP_GUID`). Writers that announce none, send no group sequence numbers (every other vendor's) or
//! heartbeats without GroupInfo are not waited for. Bounded: a change is held at most [`MAX_HOLD`], and at
//! most [`MAX_HELD`] per publisher (beyond, the oldest goes); a writer that unmatches, or whose participant
//! goes, is no longer waited for.

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::time::{Duration, Instant};

use super::{timers, Participant};
use crate::qos::PresentationAccessScope;
use crate::rtps::api::Event;
use crate::rtps::messages::Heartbeat;
use crate::rtps::types::{EntityId, Guid, GuidPrefix, SequenceNumber};

/// Longest a change waits for an earlier group sequence number (a safety net: a writer that stays silent
/// that long is lost to its lease soon).
pub(crate) const MAX_HOLD: Duration = Duration::from_secs(10);
/// While a change waits, how often the writers it waits for are asked where they stand.
pub(crate) const POLL: Duration = Duration::from_millis(20);
/// Most changes held per remote publisher.
pub(crate) const MAX_HELD: usize = 4096;

/// A (local reader, remote writer) pair.
type Pair = (EntityId, EntityId);

#[derive(Debug, Default, Clone, Copy)]
struct Member {
    /// Every change of the writer numbered up to here reached the reader.
    through: Option<SequenceNumber>,
    /// The writer sends heartbeats without GroupInfo: it is not waited for.
    silent: bool,
}

/// One remote publisher, as our group-ordered readers see it.
#[derive(Debug, Default)]
struct Group {
    members: BTreeMap<Pair, Member>,
    /// Held changes by (group sequence number, reader), with when they arrived.
    held: BTreeMap<(SequenceNumber, EntityId), (Instant, Event)>,
    /// Every number up to here was handed over, or will never reach our readers.
    released: Option<SequenceNumber>,
    /// While changes wait: when to ask the writers they wait for.
    poll_due: Option<Instant>,
}

impl Group {
    /// The lowest `through` of the pairs waited for: `Err` when one is still unknown.
    fn floor(&self, pairs: &[Pair]) -> Result<Option<SequenceNumber>, ()> {
        let mut floor: Option<SequenceNumber> = None;
        for p in pairs {
            let m = self.members.get(p).copied().unwrap_or_default();
            if m.silent {
                continue;
            }
            let t = m.through.ok_or(())?;
            floor = Some(floor.map_or(t, |f| f.min(t)));
        }
        Ok(floor)
    }

    /// Hands over, in order, the held changes nothing can precede any more (and overdue ones).
    fn release(&mut self, now: Instant, pairs: &[Pair], out: &mut VecDeque<Event>) {
        self.members.retain(|k, _| pairs.contains(k));
        let floor = self.floor(pairs);
        if let Ok(Some(f)) = floor {
            self.released = Some(self.released.map_or(f, |r| r.max(f)));
        }
        loop {
            let crowded = self.held.len() > MAX_HELD;
            let Some(e) = self.held.first_entry() else {
                break;
            };
            let (g, _) = *e.key();
            let next = self.released.map_or(g.0 == 1, |r| g.0 <= r.0 + 1) || floor == Ok(None);
            let overdue = crowded || e.get().0 + MAX_HOLD <= now;
            if !(next || overdue) {
                break;
            }
            if !next {
                tracing::debug!(
                    gsn = g.0,
                    "group order: gave up waiting for an earlier change"
                );
            }
            let (_, ev) = e.remove();
            self.released = Some(self.released.map_or(g, |r| r.max(g)));
            out.push_back(ev);
        }
    }

    fn deadline(&self) -> Option<Instant> {
        let oldest = self.held.values().map(|(t, _)| *t + MAX_HOLD).min()?;
        Some(self.poll_due.map_or(oldest, |p| p.min(oldest)))
    }

    /// The pairs the first held change waits for.
    fn blocking(&self, pairs: &[Pair]) -> Vec<Pair> {
        let Some(&(g, _)) = self.held.keys().next() else {
            return Vec::new();
        };
        pairs
            .iter()
            .filter(|p| {
                let m = self.members.get(p).copied().unwrap_or_default();
                !m.silent && m.through.is_none_or(|t| t.0 < g.0 - 1)
            })
            .copied()
            .collect()
    }
}

/// The remote publishers our group-ordered readers receive from.
#[derive(Debug, Default)]
pub(crate) struct GroupOrder {
    groups: HashMap<Guid, Group>,
    /// The latest time the participant was called with.
    now: Option<Instant>,
}

impl GroupOrder {
    /// Records the participant's clock.
    pub(crate) fn tick(&mut self, now: Instant) {
        self.now = Some(self.now.map_or(now, |n| n.max(now)));
    }

    /// The participant's clock as last seen.
    pub(crate) fn clock(&self) -> Option<Instant> {
        self.now
    }

    /// When the oldest held change is due.
    pub(crate) fn deadline(&self) -> Option<Instant> {
        self.groups.values().filter_map(Group::deadline).min()
    }
}

impl Participant {
    /// Routes a change for the application: one with a group sequence number, for a group-ordered reader,
    /// waits until no earlier change of its publisher can still come. `Some(ev)` back for all others.
    pub(super) fn order_by_group(&mut self, ev: Event) -> Option<Event> {
        let Event::Sample(s) = &ev else {
            return Some(ev);
        };
        let Some(gsn) = s.group_sequence else {
            return Some(ev);
        };
        let Some(group) = self.writer_group(&s.writer) else {
            return Some(ev);
        };
        if !self.group_ordered_reader(s.reader) {
            return Some(ev);
        }
        let pair = (s.reader, s.writer.entity_id);
        let pairs = self.group_pairs(group);
        let now = self.group_order.now.unwrap_or(self.last_full_scan);
        let g = self.group_order.groups.entry(group).or_default();
        let m = g.members.entry(pair).or_default();
        m.through = Some(m.through.map_or(gsn, |t| t.max(gsn)));
        m.silent = false;
        if g.released.is_some_and(|r| gsn <= r) {
            // Too late to be ordered (its writer matched late, or we gave up waiting for it).
            return Some(ev);
        }
        g.held.insert((gsn, pair.0), (now, ev));
        g.release(now, &pairs, &mut self.events);
        if !g.held.is_empty() {
            g.poll_due.get_or_insert(now + POLL);
        }
        timers::lower_floor(&self.timer_floor, self.group_order.deadline());
        None
    }

    /// A HEARTBEAT from `writer`, once its readers took it: with GroupInfo, a reader that holds all the
    /// writer's changes up to `lastSN` knows it has all of them numbered up to `currentGSN`; without, the
    /// writer is not waited for.
    pub(super) fn on_group_heartbeat(&mut self, writer: Guid, hb: &Heartbeat) {
        let Some(group) = self.writer_group(&writer) else {
            return;
        };
        let pairs = self.group_pairs(group);
        let mine: Vec<(Pair, bool)> = pairs
            .iter()
            .filter(|(_, w)| *w == writer.entity_id)
            .map(|&(r, w)| {
                let whole = self
                    .readers
                    .get(&r)
                    .and_then(|x| x.delivered_through(&writer))
                    .is_some_and(|d| d >= hb.last_sn);
                ((r, w), whole)
            })
            .collect();
        if mine.is_empty() {
            return;
        }
        let now = self.group_order.now.unwrap_or(self.last_full_scan);
        let g = self.group_order.groups.entry(group).or_default();
        for (pair, whole) in mine {
            let m = g.members.entry(pair).or_default();
            match hb.group_info {
                None => m.silent = true,
                Some(gi) if whole => {
                    m.silent = false;
                    m.through = Some(m.through.map_or(gi.current_gsn, |t| t.max(gi.current_gsn)));
                }
                Some(_) => m.silent = false,
            }
        }
        g.release(now, &pairs, &mut self.events);
    }

    /// Hands over what waited too long, re-examines publishers after matches changed, and asks the writers
    /// that changes wait for where they stand (a non-final ACKNACK, which a group member answers with a
    /// heartbeat).
    pub(super) fn group_order_timeout(&mut self, now: Instant) {
        self.group_order.tick(now);
        if self.group_order.groups.is_empty() {
            return;
        }
        let groups: Vec<Guid> = self.group_order.groups.keys().copied().collect();
        for group in groups {
            let pairs = self.group_pairs(group);
            let Some(g) = self.group_order.groups.get_mut(&group) else {
                continue;
            };
            g.release(now, &pairs, &mut self.events);
            if g.held.is_empty() {
                g.poll_due = None;
                if pairs.is_empty() {
                    self.group_order.groups.remove(&group);
                }
                continue;
            }
            if g.poll_due.is_some_and(|t| t > now) {
                continue;
            }
            g.poll_due = Some(now + POLL);
            let writer = |w| Guid::new(group.prefix, w);
            for (r, w) in g.blocking(&pairs) {
                if let Some(reader) = self.readers.get_mut(&r) {
                    reader.solicit_heartbeat(now, &writer(w));
                    timers::lower_floor(&self.timer_floor, reader.next_timeout());
                }
            }
        }
    }

    /// The participant's clock as last seen.
    pub(super) fn group_order_clock(&self) -> Option<Instant> {
        self.group_order.clock()
    }

    /// A remote participant is gone: what its publishers' changes waited for will not come.
    pub(super) fn forget_group_order(&mut self, prefix: &GuidPrefix) {
        let now = self.group_order.now.unwrap_or(self.last_full_scan);
        let gone: Vec<Guid> = self
            .group_order
            .groups
            .keys()
            .filter(|g| g.prefix == *prefix)
            .copied()
            .collect();
        for group in gone {
            if let Some(mut g) = self.group_order.groups.remove(&group) {
                g.release(now, &[], &mut self.events);
            }
        }
    }

    /// The publisher a remote writer announced.
    fn writer_group(&self, writer: &Guid) -> Option<Guid> {
        self.known_writers.get(writer)?.group
    }

    /// Whether a local reader orders by group (its subscriber has GROUP access scope and ordered access)
    /// and is reliable (a best-effort reader gets no repairs: it keeps the order of reception).
    fn group_ordered_reader(&self, reader: EntityId) -> bool {
        let guid = Guid::new(self.config.guid_prefix, reader);
        self.readers.get(&reader).is_some_and(|r| r.is_reliable())
            && self.known_readers.get(&guid).is_some_and(|d| {
                d.qos.presentation.ordered_access
                    && d.qos.presentation.access_scope == PresentationAccessScope::Group
            })
    }

    /// The (group-ordered local reader, writer) pairs through which a remote publisher's changes come.
    fn group_pairs(&self, group: Guid) -> Vec<Pair> {
        let mut pairs = Vec::new();
        for &r in &self.user_readers {
            if !self.group_ordered_reader(r) {
                continue;
            }
            let Some(reader) = self.readers.get(&r) else {
                continue;
            };
            for w in reader.matched() {
                if w.prefix == group.prefix && self.writer_group(w) == Some(group) {
                    pairs.push((r, w.entity_id));
                }
            }
        }
        pairs
    }
}
