//! Changes a reliable reader holds out of order, until the changes before them arrive: a map by sequence
//! number, and a pool for the copies of their payloads.
//!
//! A held payload is copied out of its datagram into a reused buffer ([`BufferPool::compact`]) rather than
//! a new one, so that it does not pin the datagram and holding changes does not allocate a buffer each.
//! The map holds only the changes themselves, never the span of sequence numbers between them: a number
//! far ahead costs one entry, and the count is bounded by the reader's `reorder_max_samples` (the caller
//! checks it before holding). (A sorted ring instead of the map took no node allocations, but every
//! look-up was a binary search over entries of about 180 bytes and a change placed between held ones
//! moved half of them: at 16 B the subscriber spent more CPU per sample than with the map.)

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

/// Most copies of held payloads the pool keeps for reuse.
const POOL_BUFFERS: usize = 1024;
/// Most capacity, in bytes, those copies keep in all.
const POOL_BYTES: usize = 1 << 20;

/// The changes held out of order for one writer, in sequence order.
#[derive(Debug)]
pub(crate) struct Reorder {
    held: BTreeMap<SequenceNumber, Slot>,
    /// Payload bytes held.
    bytes: usize,
    /// Buffers for the copies of held payloads.
    pool: BufferPool,
}

impl Default for Reorder {
    fn default() -> Self {
        Reorder {
            held: BTreeMap::new(),
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

    /// Whether something is held for `sn`.
    pub(crate) fn contains(&self, sn: SequenceNumber) -> bool {
        self.held.contains_key(&sn)
    }

    /// Holds `slot` for `sn`, replacing what was held for it. A payload that is a slice of a larger buffer
    /// (the datagram it arrived in) is copied into a pooled buffer, so that it does not pin the datagram.
    pub(crate) fn hold(&mut self, sn: SequenceNumber, mut slot: Slot) {
        if let Slot::Change(c) = &mut slot {
            c.payload = self.pool.compact(std::mem::take(&mut c.payload));
        }
        self.bytes += slot.size();
        if let Some(old) = self.held.insert(sn, slot) {
            self.bytes -= old.size();
        }
    }

    /// Marks `sn` irrelevant unless something is held for it already.
    pub(crate) fn hold_irrelevant(&mut self, sn: SequenceNumber) {
        self.held.entry(sn).or_insert(Slot::Irrelevant);
    }

    /// The lowest sequence number held, and its slot.
    pub(crate) fn first(&self) -> Option<(SequenceNumber, &Slot)> {
        self.held.first_key_value().map(|(sn, slot)| (*sn, slot))
    }

    /// Takes the lowest sequence number held, and its slot.
    pub(crate) fn pop_first(&mut self) -> Option<(SequenceNumber, Slot)> {
        let (sn, slot) = self.held.pop_first()?;
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
        assert_eq!(r.len(), 3, "entries, not the span");
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
