//! Changes a reliable reader holds out of order, until the changes before them arrive: a ring indexed by
//! sequence number, a map for numbers beyond the ring's reach, and a pool for the copies of their payloads.
//!
//! A held payload is copied out of its datagram into a reused buffer ([`BufferPool::compact`]) rather than
//! a new one, so that it does not pin the datagram and holding changes does not allocate a buffer each.
//!
//! The ring has one 4-byte entry per sequence number from the lowest held on (`base`): empty, irrelevant, or
//! the index of the held change in a slab. Holding and taking are O(1), with no search and nothing moved,
//! and neither allocates once the ring and the slab have grown to the span and the count held out of order
//! at once (the ring doubles up to [`RING_MAX`] entries, 128 KiB; the slab to the most changes held). A
//! number beyond the ring's reach (more than [`RING_MAX`] past the lowest held, or below it by more than
//! the room left) goes to a map, so a number far ahead still costs one entry: the count held is bounded by
//! the reader's `reorder_max_samples` (the caller checks it before holding), never by the span. Nothing is
//! allocated before the first change held out of order (the whole backlog of a writer proxy is made then).
//!
//! History: the changes were a `BTreeMap` by sequence number, which allocated a node every few changes held
//! (the most part of what was left of the reader's allocations with 10 000 samples in flight, session 24).
//! A sorted ring instead took no node allocations, but every look-up was a binary search over entries of
//! about 180 bytes and a change placed between held ones moved half of them: at 16 B the subscriber spent
//! more CPU per sample than with the map. Indexed by number, the ring needs neither.

use std::collections::BTreeMap;

use super::coherent::SetMark;
use crate::rtps::api::{ChangeKind, Payload};
use crate::rtps::pool::BufferPool;
use crate::rtps::types::{SequenceNumber, Time};

/// A received change waiting for its turn (or an irrelevant sequence number from a GAP).
#[derive(Debug, Clone)]
pub(crate) enum Slot {
    Change(PendingChange),
    Irrelevant,
}

impl Slot {
    /// Payload bytes the slot holds.
    pub(crate) fn size(&self) -> usize {
        match self {
            Slot::Change(c) => c.payload.len(),
            Slot::Irrelevant => 0,
        }
    }
}

#[derive(Debug, Clone)]
pub(crate) struct PendingChange {
    pub kind: ChangeKind,
    pub payload: Payload,
    pub key_hash: Option<[u8; 16]>,
    pub source_timestamp: Option<Time>,
    /// Membership in a coherent set (`PID_COHERENT_SET`).
    pub coherent: Option<SetMark>,
    /// `PID_GROUP_SEQ_NUM`, from members of a GROUP-scope publisher.
    pub group_seq: Option<SequenceNumber>,
}

/// Most copies of held payloads the pool keeps for reuse: as many as `reorder_max_samples` by default. A
/// copy stays out of the pool while it is held and then while it is in the reader's cache, so a reader
/// 10 000 deep that holds changes out of order has more than 10 000 out at once; with 1 024, each one
/// beyond cost two allocations (session 25). The pool only grows to what was out at once.
const POOL_BUFFERS: usize = 1 << 15;
/// Most capacity, in bytes, those copies keep in all.
const POOL_BYTES: usize = 1 << 20;

/// The changes held out of order for one writer, in sequence order.
#[derive(Debug)]
pub(crate) struct Reorder {
    /// By sequence number: the entry of `base + i` is at `(head + i) & (len - 1)` (a power of two long);
    /// [`EMPTY`], [`IRRELEVANT`] or a slab index plus [`FIRST_INDEX`]. Empty (unallocated) until the first
    /// change is held.
    ring: Vec<u32>,
    head: usize,
    /// The lowest sequence number in the ring (its entry is never [`EMPTY`]) while `in_ring > 0`.
    base: SequenceNumber,
    /// Numbers from `base` to the highest in the ring (0 when the ring holds nothing).
    span: usize,
    /// Entries in the ring that are not [`EMPTY`].
    in_ring: usize,
    /// The changes the ring refers to; a free one is `Slot::Irrelevant`, its index in `free`.
    slab: Vec<Slot>,
    free: Vec<u32>,
    /// Numbers the ring could not reach when they arrived.
    far: BTreeMap<SequenceNumber, Slot>,
    /// Payload bytes held.
    bytes: usize,
    /// Buffers for the copies of held payloads.
    pool: BufferPool,
    /// Trims ([`Reorder::trim_idle`]) in a row that found nothing held and nothing held since the last.
    idle_trims: u8,
}

/// A ring entry for a number nothing is held for.
const EMPTY: u32 = 0;
/// A ring entry for a number a GAP said is irrelevant.
const IRRELEVANT: u32 = 1;
/// A ring entry for a held change: its slab index plus this.
const FIRST_INDEX: u32 = 2;
/// The ring's first length (entries).
const RING_MIN: usize = 64;
/// The ring's longest (entries, 4 bytes each): the widest span of numbers it holds without the map.
const RING_MAX: usize = 1 << 15;

/// What `first` shows for an irrelevant number of the ring.
static IRRELEVANT_SLOT: Slot = Slot::Irrelevant;

impl Default for Reorder {
    fn default() -> Self {
        Reorder {
            ring: Vec::new(),
            head: 0,
            base: SequenceNumber(0),
            span: 0,
            in_ring: 0,
            slab: Vec::new(),
            free: Vec::new(),
            far: BTreeMap::new(),
            bytes: 0,
            pool: BufferPool::new(POOL_BUFFERS, POOL_BYTES),
            idle_trims: 0,
        }
    }
}

/// Trims in a row with nothing held after which [`Reorder::trim_idle`] gives the room back.
const IDLE_TRIMS: u8 = 2;

impl Reorder {
    /// Changes (and irrelevant numbers) held.
    pub(crate) fn len(&self) -> usize {
        self.in_ring + self.far.len()
    }

    /// Payload bytes held.
    pub(crate) fn bytes(&self) -> usize {
        self.bytes
    }

    /// Whether something is held for `sn`.
    pub(crate) fn contains(&self, sn: SequenceNumber) -> bool {
        self.ring_pos(sn).is_some_and(|i| self.ring[i] != EMPTY)
            || (!self.far.is_empty() && self.far.contains_key(&sn))
    }

    /// Holds `slot` for `sn`, replacing what was held for it. A payload that is a slice of a larger buffer
    /// (the datagram it arrived in) is copied into a pooled buffer, so that it does not pin the datagram.
    pub(crate) fn hold(&mut self, sn: SequenceNumber, mut slot: Slot) {
        self.idle_trims = 0;
        if let Slot::Change(c) = &mut slot {
            c.payload = self.pool.compact(std::mem::take(&mut c.payload));
        }
        self.bytes += slot.size();
        if let Some(old) = self.far.get_mut(&sn) {
            self.bytes -= old.size();
            *old = slot;
            return;
        }
        let Some(i) = self.make_room(sn) else {
            self.far.insert(sn, slot);
            return;
        };
        match self.ring[i] {
            EMPTY => self.in_ring += 1,
            IRRELEVANT => {}
            e => self.bytes -= self.release(e).size(),
        }
        self.ring[i] = match slot {
            Slot::Irrelevant => IRRELEVANT,
            change => self.store(change),
        };
    }

    /// Marks `sn` irrelevant unless something is held for it already.
    pub(crate) fn hold_irrelevant(&mut self, sn: SequenceNumber) {
        if !self.contains(sn) {
            self.hold(sn, Slot::Irrelevant);
        }
    }

    /// The lowest sequence number held, and its slot.
    pub(crate) fn first(&self) -> Option<(SequenceNumber, &Slot)> {
        let far = self.far.first_key_value();
        if self.in_ring > 0 && far.is_none_or(|(sn, _)| self.base < *sn) {
            let slot = match self.ring[self.head] {
                IRRELEVANT => &IRRELEVANT_SLOT,
                e => &self.slab[(e - FIRST_INDEX) as usize],
            };
            return Some((self.base, slot));
        }
        far.map(|(sn, slot)| (*sn, slot))
    }

    /// Called periodically (once per SPDP period, with the participant's other trims): once it has found
    /// nothing held [`IDLE_TRIMS`] times in a row with nothing held in between, gives back the ring (up to
    /// 128 KiB), the slab and the pool of payload copies, which a burst out of order left at its size: a
    /// writer that once got thousands of changes ahead does not keep them for the life of the match. The
    /// next change held out of order makes them again. Whether the room is given back (now or before).
    pub(crate) fn trim_idle(&mut self) -> bool {
        if self.len() > 0 {
            self.idle_trims = 0;
            return false;
        }
        if self.ring.capacity() == 0 && self.slab.capacity() == 0 && self.pool.is_empty() {
            return true;
        }
        self.idle_trims = self.idle_trims.saturating_add(1);
        if self.idle_trims < IDLE_TRIMS {
            return false;
        }
        *self = Reorder::default();
        true
    }

    /// Takes the lowest sequence number held, and its slot.
    pub(crate) fn pop_first(&mut self) -> Option<(SequenceNumber, Slot)> {
        let far = self.far.first_key_value().map(|(sn, _)| *sn);
        let (sn, slot) = if self.in_ring > 0 && far.is_none_or(|sn| self.base < sn) {
            (self.base, self.pop_ring())
        } else {
            self.far.pop_first()?
        };
        self.bytes -= slot.size();
        Some((sn, slot))
    }

    /// Takes the ring's first entry (there is one) and moves `base` on to the next one held.
    fn pop_ring(&mut self) -> Slot {
        let e = std::mem::replace(&mut self.ring[self.head], EMPTY);
        self.in_ring -= 1;
        if self.in_ring == 0 {
            self.span = 0;
        } else {
            let mask = self.ring.len() - 1;
            loop {
                self.head = (self.head + 1) & mask;
                self.base = self.base.next();
                self.span -= 1;
                if self.ring[self.head] != EMPTY {
                    break;
                }
            }
        }
        match e {
            IRRELEVANT => Slot::Irrelevant,
            e => self.release(e),
        }
    }

    /// The ring index of `sn`, if it is within the ring's span.
    fn ring_pos(&self, sn: SequenceNumber) -> Option<usize> {
        let off = usize::try_from(sn.0.checked_sub(self.base.0)?).ok()?;
        (self.in_ring > 0 && off < self.span).then(|| (self.head + off) & (self.ring.len() - 1))
    }

    /// The ring index for `sn`, the ring grown or its base moved down as needed; `None` when `sn` is out
    /// of the ring's reach.
    fn make_room(&mut self, sn: SequenceNumber) -> Option<usize> {
        if self.in_ring == 0 {
            if self.ring.is_empty() {
                self.ring = vec![EMPTY; RING_MIN];
            }
            (self.base, self.span) = (sn, 1);
            return Some(self.head);
        }
        let below = sn < self.base;
        let dist = usize::try_from(sn.0.abs_diff(self.base.0)).ok()?;
        let span = if below {
            dist.checked_add(self.span)?
        } else {
            self.span.max(dist.checked_add(1)?)
        };
        if span > RING_MAX {
            return None;
        }
        if span > self.ring.len() {
            self.grow(span.next_power_of_two());
        }
        let mask = self.ring.len() - 1;
        if below {
            self.head = self.head.wrapping_sub(dist) & mask;
            self.base = sn;
        }
        self.span = span;
        Some((self.head + (sn.0 - self.base.0) as usize) & mask)
    }

    /// Moves the ring into one of `len` entries (a power of two), its first entry at 0.
    fn grow(&mut self, len: usize) {
        let mut ring = vec![EMPTY; len];
        let mask = self.ring.len() - 1;
        for (i, e) in ring.iter_mut().take(self.span).enumerate() {
            *e = self.ring[(self.head + i) & mask];
        }
        self.ring = ring;
        self.head = 0;
    }

    /// Puts `slot` in the slab: its ring entry.
    fn store(&mut self, slot: Slot) -> u32 {
        let i = match self.free.pop() {
            Some(i) => {
                self.slab[i as usize] = slot;
                i
            }
            None => {
                self.slab.push(slot);
                (self.slab.len() - 1) as u32
            }
        };
        i + FIRST_INDEX
    }

    /// Takes the change of ring entry `e` out of the slab.
    fn release(&mut self, e: u32) -> Slot {
        let i = e - FIRST_INDEX;
        self.free.push(i);
        std::mem::replace(&mut self.slab[i as usize], Slot::Irrelevant)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn change(payload: Payload) -> Slot {
        Slot::Change(PendingChange {
            kind: ChangeKind::Alive,
            payload,
            key_hash: None,
            source_timestamp: None,
            coherent: None,
            group_seq: None,
        })
    }

    fn order(r: &mut Reorder) -> Vec<(i64, usize)> {
        std::iter::from_fn(|| r.pop_first())
            .map(|(sn, slot)| (sn.0, slot.size()))
            .collect()
    }

    #[test]
    fn held_in_sequence_order_whatever_the_arrival() {
        let mut r = Reorder::default();
        for (sn, len) in [(5, 1), (9, 2), (7, 3), (2, 4), (9, 5)] {
            r.hold(SequenceNumber(sn), change(Payload::from(vec![0u8; len])));
        }
        r.hold_irrelevant(SequenceNumber(3));
        r.hold_irrelevant(SequenceNumber(7));
        assert_eq!((r.len(), r.bytes()), (5, 1 + 5 + 3 + 4));
        assert!(r.contains(SequenceNumber(3)) && !r.contains(SequenceNumber(4)));
        assert_eq!(r.first().map(|(sn, _)| sn), Some(SequenceNumber(2)));
        assert_eq!(
            order(&mut r),
            [(2, 4), (3, 0), (5, 1), (7, 3), (9, 5)],
            "a change replaces what was held for its number; an irrelevant mark does not"
        );
        assert_eq!(r.bytes(), 0);
    }

    #[test]
    fn a_number_far_ahead_costs_one_entry() {
        let mut r = Reorder::default();
        r.hold(SequenceNumber(2), change(Payload::from(vec![1u8])));
        r.hold(
            SequenceNumber(i64::MAX - 1),
            change(Payload::from(vec![2u8])),
        );
        r.hold_irrelevant(SequenceNumber(1 << 40));
        r.hold_irrelevant(SequenceNumber(2 + RING_MAX as i64));
        assert_eq!(r.len(), 4, "entries, not the span");
        assert_eq!(
            (r.ring.len(), r.far.len()),
            (RING_MIN, 3),
            "beyond the ring: the map"
        );
        assert!(r.contains(SequenceNumber(1 << 40)) && !r.contains(SequenceNumber(3)));
        r.hold(SequenceNumber(1 << 40), change(Payload::from(vec![3u8; 3])));
        assert_eq!((r.len(), r.bytes()), (4, 5), "replaced in the map");
        let got: Vec<i64> = order(&mut r).into_iter().map(|(sn, _)| sn).collect();
        assert_eq!(got, [2, 2 + RING_MAX as i64, 1 << 40, i64::MAX - 1]);
    }

    #[test]
    fn in_order_and_out_of_order_through_the_ring() {
        let mut r = Reorder::default();
        assert!(
            r.ring.is_empty() && r.first().is_none(),
            "nothing allocated before"
        );
        // Held around a missing 10: above it, then below the first held (the ring's base moves down).
        for sn in [12, 11, 15, 14, 13] {
            r.hold(
                SequenceNumber(sn),
                change(Payload::from(vec![0u8; sn as usize])),
            );
        }
        assert_eq!((r.base, r.span, r.in_ring), (SequenceNumber(11), 5, 5));
        assert_eq!(r.first().map(|(sn, _)| sn), Some(SequenceNumber(11)));
        let got: Vec<i64> = order(&mut r).into_iter().map(|(sn, _)| sn).collect();
        assert_eq!(got, [11, 12, 13, 14, 15]);
        assert_eq!((r.len(), r.bytes(), r.span), (0, 0, 0));
        // Once emptied, the next held number is the new base wherever it is.
        r.hold(SequenceNumber(3), change(Payload::from(vec![0u8; 2])));
        assert_eq!(
            r.first().map(|(sn, s)| (sn, s.size())),
            Some((SequenceNumber(3), 2))
        );
    }

    #[test]
    fn gaps_and_irrelevant_numbers_are_skipped_over() {
        let mut r = Reorder::default();
        r.hold(SequenceNumber(20), change(Payload::from(vec![0u8; 4])));
        r.hold(SequenceNumber(40), change(Payload::from(vec![0u8; 5])));
        for sn in 25..30 {
            r.hold_irrelevant(SequenceNumber(sn));
        }
        r.hold_irrelevant(SequenceNumber(40));
        r.hold(SequenceNumber(27), change(Payload::from(vec![0u8; 6])));
        assert_eq!((r.len(), r.bytes()), (7, 15));
        assert!(!r.contains(SequenceNumber(21)) && r.contains(SequenceNumber(26)));
        assert_eq!(
            order(&mut r),
            [
                (20, 4),
                (25, 0),
                (26, 0),
                (27, 6),
                (28, 0),
                (29, 0),
                (40, 5)
            ]
        );
    }

    #[test]
    fn the_ring_wraps_around_and_grows_to_the_span_once() {
        let mut r = Reorder::default();
        // A missing number every 50: the held run slides along the ring, around its end many times.
        let mut next = 1;
        for round in 0..100i64 {
            let missing = round * 50 + 1;
            for sn in missing + 1..missing + 50 {
                r.hold(SequenceNumber(sn), change(Payload::from(vec![0u8; 8])));
            }
            assert_eq!(r.len(), 49);
            for (sn, _) in order(&mut r) {
                assert_eq!(sn, next + 1);
                next += 1;
            }
            next += 1;
        }
        assert_eq!(r.ring.len(), RING_MIN, "a span of 49 fits the first ring");
        assert_eq!(r.slab.len(), 49, "the slab grew to the most held at once");
        // A wider span grows it, keeping the held entries in order across the old end.
        r.hold(SequenceNumber(10_000), change(Payload::from(vec![0u8; 1])));
        r.hold(SequenceNumber(10_040), change(Payload::from(vec![0u8; 1])));
        r.hold(SequenceNumber(10_300), change(Payload::from(vec![0u8; 1])));
        r.hold(SequenceNumber(9_990), change(Payload::from(vec![0u8; 1])));
        assert_eq!((r.ring.len(), r.far.len()), (512, 0));
        let got: Vec<i64> = order(&mut r).into_iter().map(|(sn, _)| sn).collect();
        assert_eq!(got, [9_990, 10_000, 10_040, 10_300]);
    }

    #[test]
    fn a_number_below_the_ring_out_of_reach_goes_to_the_map() {
        let mut r = Reorder::default();
        r.hold(SequenceNumber(100_000), change(Payload::from(vec![0u8; 1])));
        r.hold(SequenceNumber(100_001), change(Payload::from(vec![0u8; 1])));
        r.hold(SequenceNumber(5), change(Payload::from(vec![0u8; 2])));
        assert_eq!(r.far.len(), 1);
        assert_eq!(
            r.first().map(|(sn, s)| (sn, s.size())),
            Some((SequenceNumber(5), 2))
        );
        let got: Vec<i64> = order(&mut r).into_iter().map(|(sn, _)| sn).collect();
        assert_eq!(got, [5, 100_000, 100_001]);
    }

    #[test]
    fn held_payloads_stop_pinning_their_datagram_and_reuse_buffers() {
        let mut r = Reorder::default();
        let datagram = Payload::from(vec![3u8; 1000]);
        r.hold(SequenceNumber(4), change(datagram.slice(100..144)));
        let Some((_, Slot::Change(c))) = r.pop_first() else {
            panic!("held change");
        };
        assert_eq!(&c.payload[..], &[3u8; 44]);
        assert!(!c.payload.is_part(), "a copy of its own");
        let ptr = c.payload.as_ptr();
        drop(c);
        r.hold(SequenceNumber(5), change(datagram.slice(200..244)));
        let Some((_, Slot::Change(c))) = r.pop_first() else {
            panic!("held change");
        };
        assert_eq!(c.payload.as_ptr(), ptr, "the same buffer, reused");
    }

    #[test]
    fn idle_room_is_given_back_after_two_idle_trims() {
        let mut r = Reorder::default();
        let datagram = Payload::from(vec![7u8; 64 * 1024]);
        // A burst out of order: 20 000 numbers ahead of the first, copies of slices of a datagram.
        for i in (2..20_002).rev() {
            r.hold(SequenceNumber(i), change(datagram.slice(0..32)));
        }
        r.hold(SequenceNumber(1), change(datagram.slice(0..32)));
        assert!(r.ring.capacity() >= 20_001 && r.slab.capacity() >= 20_001);
        // Held: nothing is given back.
        assert!(!r.trim_idle() && !r.trim_idle() && !r.trim_idle());
        while r.pop_first().is_some() {}
        assert!(!r.pool.is_empty());
        // Drained: the first trim counts, a change held in between starts over, the second in a row frees.
        assert!(!r.trim_idle());
        r.hold(SequenceNumber(30_000), change(datagram.slice(0..32)));
        r.pop_first();
        assert!(!r.trim_idle());
        assert!(r.ring.capacity() > 0, "held since the last trim: kept");
        assert!(r.trim_idle());
        assert_eq!(
            (r.ring.capacity(), r.slab.capacity(), r.free.capacity()),
            (0, 0, 0)
        );
        assert!(r.pool.is_empty());
        assert!(r.trim_idle(), "already empty-cheap");
        // And it works again afterwards.
        r.hold(SequenceNumber(30_002), change(datagram.slice(0..4)));
        r.hold(SequenceNumber(30_001), change(datagram.slice(0..4)));
        let got: Vec<i64> = order(&mut r).into_iter().map(|(sn, _)| sn).collect();
        assert_eq!(got, [30_001, 30_002]);
    }

    /// What the reorder buffer was before the ring: a map by number.
    #[derive(Default)]
    struct Model(BTreeMap<i64, usize>);

    proptest::proptest! {
        /// Against the map: the same numbers held, in the same order, with the same sizes, whatever the
        /// arrival (close together, around a moving base, far ahead, irrelevant marks, partial drains).
        #[test]
        fn behaves_as_a_map(ops in proptest::collection::vec(
            (0u8..10, 0i64..200, 0usize..5), 1..300))
        {
            let mut r = Reorder::default();
            let mut m = Model::default();
            let mut floor = 1i64;
            for (op, n, len) in ops {
                let sn = match op {
                    0 => floor + n * 1000,
                    1 => floor + RING_MAX as i64 - 100 + n,
                    _ => floor + n,
                };
                match op {
                    2 | 3 => {
                        m.0.entry(sn).or_insert(0);
                        r.hold_irrelevant(SequenceNumber(sn));
                    }
                    4 => {
                        for _ in 0..len {
                            let got = r.pop_first().map(|(sn, s)| (sn.0, s.size()));
                            proptest::prop_assert_eq!(got, m.0.pop_first());
                            if let Some((sn, _)) = got {
                                floor = floor.max(sn + 1);
                            }
                        }
                    }
                    _ => {
                        m.0.insert(sn, len);
                        r.hold(SequenceNumber(sn), change(Payload::from(vec![7u8; len])));
                    }
                }
                proptest::prop_assert_eq!(r.len(), m.0.len());
                proptest::prop_assert_eq!(r.bytes(), m.0.values().sum::<usize>());
                proptest::prop_assert_eq!(
                    r.first().map(|(sn, s)| (sn.0, s.size())),
                    m.0.first_key_value().map(|(k, v)| (*k, *v))
                );
                proptest::prop_assert_eq!(r.contains(SequenceNumber(sn)), m.0.contains_key(&sn));
            }
            let rest: Vec<(i64, usize)> = order(&mut r);
            proptest::prop_assert_eq!(rest, m.0.into_iter().collect::<Vec<_>>());
        }
    }
}
