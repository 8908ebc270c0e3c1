//! The writer history's changes by sequence number: a ring of slots indexed by `sn - base`, since a
//! writer numbers its changes consecutively and mostly drops the oldest. Unlike a B-tree it allocates
//! nothing per change once its ring has grown to the history's working size; a change removed from the
//! middle (KEEP_LAST replacing an instance's sample) leaves an empty slot until the ends pass it.

use std::collections::VecDeque;

use crate::rtps::types::SequenceNumber;

/// Values by sequence number, for numbers that are dense (a writer's own changes).
#[derive(Debug)]
pub(super) struct SnMap<V> {
    /// Sequence number of `slots[0]`.
    base: i64,
    /// Never starts or ends with `None`.
    slots: VecDeque<Option<V>>,
    len: usize,
}

impl<V> SnMap<V> {
    pub(super) fn new() -> Self {
        SnMap {
            base: 0,
            slots: VecDeque::new(),
            len: 0,
        }
    }

    pub(super) fn len(&self) -> usize {
        self.len
    }

    fn index(&self, sn: SequenceNumber) -> Option<usize> {
        usize::try_from(sn.0.checked_sub(self.base)?).ok()
    }

    pub(super) fn get(&self, sn: SequenceNumber) -> Option<&V> {
        self.slots.get(self.index(sn)?)?.as_ref()
    }

    pub(super) fn first(&self) -> Option<(SequenceNumber, &V)> {
        Some((SequenceNumber(self.base), self.slots.front()?.as_ref()?))
    }

    pub(super) fn last(&self) -> Option<(SequenceNumber, &V)> {
        let last = self.base + self.slots.len() as i64 - 1;
        Some((SequenceNumber(last), self.slots.back()?.as_ref()?))
    }

    /// Inserts (or replaces) the value of `sn`. Numbers are expected dense: a gap costs an empty slot per
    /// missing number.
    pub(super) fn insert(&mut self, sn: SequenceNumber, v: V) {
        if self.slots.is_empty() {
            self.base = sn.0;
        }
        // The common case, the next number: the value is written once, straight into its slot (a `None`
        // pushed and then replaced moved the whole value twice more, a tenth of a 16 B writer's time).
        if self.index(sn) == Some(self.slots.len()) {
            self.slots.push_back(Some(v));
            self.len += 1;
            return;
        }
        while sn.0 < self.base {
            self.slots.push_front(None);
            self.base -= 1;
        }
        let Some(i) = self.index(sn) else { return };
        while self.slots.len() <= i {
            self.slots.push_back(None);
        }
        if self.slots[i].replace(v).is_none() {
            self.len += 1;
        }
    }

    pub(super) fn remove(&mut self, sn: SequenceNumber) -> Option<V> {
        let i = self.index(sn)?;
        // The oldest (the common case) leaves the ring in one move.
        let v = if i == 0 {
            let v = self.slots.pop_front()??;
            self.base += 1;
            v
        } else {
            self.slots.get_mut(i)?.take()?
        };
        self.len -= 1;
        self.trim_front();
        while matches!(self.slots.back(), Some(None)) {
            self.slots.pop_back();
        }
        Some(v)
    }

    /// Drops the values below `to` where they lie, without moving them out of the ring; `each` sees every
    /// one of them first, in order.
    pub(super) fn drop_below(&mut self, to: SequenceNumber, mut each: impl FnMut(&V)) {
        let n = to.0.saturating_sub(self.base).max(0) as usize;
        let n = n.min(self.slots.len());
        if n == 0 {
            return;
        }
        let mut gone = 0;
        for v in self.slots.range(..n).flatten() {
            each(v);
            gone += 1;
        }
        self.len -= gone;
        self.slots.drain(..n);
        self.base += n as i64;
        self.trim_front();
    }

    /// Drops the empty slots at the front: the ring starts at its lowest value.
    fn trim_front(&mut self) {
        while matches!(self.slots.front(), Some(None)) {
            self.slots.pop_front();
            self.base += 1;
        }
    }

    /// The values at `from` and above, in order.
    pub(super) fn range_from(&self, from: SequenceNumber) -> impl Iterator<Item = &V> {
        let skip = from.0.saturating_sub(self.base).max(0) as usize;
        self.slots.iter().skip(skip).filter_map(Option::as_ref)
    }

    /// The values below `to`, in order.
    pub(super) fn range_below(&self, to: SequenceNumber) -> impl Iterator<Item = &V> {
        let take = to.0.saturating_sub(self.base).max(0) as usize;
        self.slots.iter().take(take).filter_map(Option::as_ref)
    }

    /// The sequence numbers held, in order.
    #[cfg(test)]
    pub(super) fn keys(&self) -> impl Iterator<Item = SequenceNumber> + '_ {
        self.slots
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_some())
            .map(|(i, _)| SequenceNumber(self.base + i as i64))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sn(n: i64) -> SequenceNumber {
        SequenceNumber(n)
    }

    #[test]
    fn dense_inserts_and_removals_at_both_ends_and_inside() {
        let mut m = SnMap::new();
        for n in 5..10 {
            m.insert(sn(n), n * 10);
        }
        assert_eq!(m.len(), 5);
        assert_eq!(m.get(sn(7)), Some(&70));
        assert_eq!(m.get(sn(4)), None);
        assert_eq!(m.remove(sn(7)), Some(70));
        assert_eq!(m.remove(sn(7)), None);
        assert_eq!(
            m.range_from(sn(6)).copied().collect::<Vec<_>>(),
            [60, 80, 90]
        );
        assert_eq!(
            m.range_below(sn(9)).copied().collect::<Vec<_>>(),
            [50, 60, 80]
        );
        assert_eq!(m.remove(sn(5)), Some(50));
        assert_eq!(m.remove(sn(6)), Some(60));
        assert_eq!(m.first(), Some((sn(8), &80)));
        assert_eq!(m.remove(sn(9)), Some(90));
        assert_eq!(m.last(), Some((sn(8), &80)));
        m.insert(sn(3), 30);
        assert_eq!(m.keys().collect::<Vec<_>>(), [sn(3), sn(8)]);
        assert_eq!(m.range_from(sn(-5)).count(), 2);
        assert_eq!(m.range_below(sn(-5)).count(), 0);
        m.remove(sn(3));
        m.remove(sn(8));
        assert_eq!((m.len(), m.first().is_none(), m.slots.len()), (0, true, 0));
    }

    #[test]
    fn drop_below_drops_in_place_and_skips_holes() {
        let mut m = SnMap::new();
        for n in 1..=6 {
            m.insert(sn(n), n);
        }
        m.remove(sn(2));
        m.remove(sn(5));
        let mut seen = Vec::new();
        m.drop_below(sn(5), |v| seen.push(*v));
        assert_eq!(seen, [1, 3, 4]);
        assert_eq!(
            (m.len(), m.first()),
            (1, Some((sn(6), &6))),
            "the hole at 5 went too"
        );
        m.drop_below(sn(0), |_| panic!("nothing below"));
        m.drop_below(sn(100), |v| seen.push(*v));
        assert_eq!((m.len(), m.first().is_none(), m.slots.len()), (0, true, 0));
        m.insert(sn(200), 7);
        assert_eq!(m.keys().collect::<Vec<_>>(), [sn(200)]);
    }
}
