//! Changes a reliable reader holds out of order, until the changes before them arrive: a ring of
//! `(sequence number, slot)` pairs kept sorted, and a pool for the copies of their payloads.
//!
//! Changes nearly always arrive in ascending order (a run after a lost one, repairs in order), so a new one
//! goes at the back and the oldest leaves at the front, both O(1); one that arrives between held ones is
//! placed by binary search. The ring keeps its room once it has grown, and a held payload is copied into a
//! reused buffer ([`BufferPool::compact`]), so holding changes allocates nothing once the working size is
//! reached. The ring holds only the changes themselves, never the span of sequence numbers between them:
//! a number far ahead costs one entry, and the count is bounded by the reader's `reorder_max_samples`
//! (the caller checks it before holding).

use std::collections::VecDeque;

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

/// Most copies of held payloads the pool keeps for reuse (the default `reorder_max_samples`).
const POOL_BUFFERS: usize = 1024;
/// Most capacity, in bytes, those copies keep in all.
const POOL_BYTES: usize = 1 << 20;

/// The changes held out of order for one writer, in sequence order.
#[derive(Debug)]
pub(crate) struct Reorder {
    held: VecDeque<(SequenceNumber, Slot)>,
    /// Payload bytes held.
    bytes: usize,
    /// Buffers for the copies of held payloads.
    pool: BufferPool,
}

impl Default for Reorder {
    fn default() -> Self {
        Reorder {
            held: VecDeque::new(),
            bytes: 0,
            pool: BufferPool::new(POOL_BUFFERS, POOL_BYTES),
        }
    }
}

impl Reorder {
    /// Changes (and irrelevant numbers) held.
    pub(crate) fn len(&self) -> usize {
        self.held.len()
    }

    /// Payload bytes held.
    pub(crate) fn bytes(&self) -> usize {
        self.bytes
    }

    /// Where `sn` is (`Ok`) or would go (`Err`).
    fn find(&self, sn: SequenceNumber) -> Result<usize, usize> {
        match self.held.back() {
            None => Err(0),
            Some((last, _)) if *last < sn => Err(self.held.len()),
            _ => self.held.binary_search_by_key(&sn, |(k, _)| *k),
        }
    }

    /// Whether something is held for `sn`.
    pub(crate) fn contains(&self, sn: SequenceNumber) -> bool {
        self.find(sn).is_ok()
    }

    /// Holds `slot` for `sn`, replacing what was held for it. A payload that is a slice of a larger buffer
    /// (the datagram it arrived in) is copied into a pooled buffer, so that it does not pin the datagram.
    pub(crate) fn hold(&mut self, sn: SequenceNumber, mut slot: Slot) {
        if let Slot::Change(c) = &mut slot {
            c.payload = self.pool.compact(std::mem::take(&mut c.payload));
        }
        self.bytes += slot.size();
        match self.find(sn) {
            Ok(i) => {
                let old = std::mem::replace(&mut self.held[i].1, slot);
                self.bytes -= old.size();
            }
            Err(i) => self.held.insert(i, (sn, slot)),
        }
    }

    /// Marks `sn` irrelevant unless something is held for it already.
    pub(crate) fn hold_irrelevant(&mut self, sn: SequenceNumber) {
        if let Err(i) = self.find(sn) {
            self.held.insert(i, (sn, Slot::Irrelevant));
        }
    }

    /// The lowest sequence number held, and its slot.
    pub(crate) fn first(&self) -> Option<(SequenceNumber, &Slot)> {
        self.held.front().map(|(sn, slot)| (*sn, slot))
    }

    /// Takes the lowest sequence number held, and its slot.
    pub(crate) fn pop_first(&mut self) -> Option<(SequenceNumber, Slot)> {
        let (sn, slot) = self.held.pop_front()?;
        self.bytes -= slot.size();
        Some((sn, slot))
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
        assert_eq!(r.len(), 3);
        assert!(r.held.capacity() < 64, "room for the entries, not the span");
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
}
