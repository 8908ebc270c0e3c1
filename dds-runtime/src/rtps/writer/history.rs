//! The writer history cache: changes by sequence number, with KEEP_LAST per instance and resource limits.

use std::collections::VecDeque;
use std::time::Instant;

use foldhash::{HashMap, HashMapExt};

use crate::qos::{History, ResourceLimits};
use crate::rtps::api::{ChangeKind, Payload};
use crate::rtps::types::*;

use super::sn_map::SnMap;

/// Largest instance queue (in sequence numbers) kept for reuse when its instance empties.
const SPARE_QUEUE_MAX: usize = 1 << 16;

/// One change in the history.
#[derive(Debug, Clone)]
pub(crate) struct CacheChange {
    pub sn: SequenceNumber,
    pub kind: ChangeKind,
    pub payload: Payload,
    pub key_hash: Option<[u8; 16]>,
    pub source_timestamp: Option<Time>,
    /// Membership in a coherent set, sent again with every repair.
    pub marks: super::Marks,
    /// Readers whose content filter rejected this change (sorted; empty for most changes).
    pub rejected: Vec<Guid>,
    /// PID_CONTENT_FILTER_INFO to send with it, when matched readers filter.
    pub filter_info: Option<Box<[u8]>>,
    /// When the change expires (the writer's LIFESPAN); `None`: never.
    pub expires: Option<Instant>,
}

/// Why a change cannot be added now.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum HistoryFull {
    /// KEEP_ALL (or max_samples) limit reached by changes that may not be dropped yet.
    Full,
}

#[derive(Debug)]
pub(crate) struct HistoryCache {
    changes: SnMap<CacheChange>,
    instances: HashMap<[u8; 16], VecDeque<SequenceNumber>>,
    history: History,
    limits: ResourceLimits,
    bytes: usize,
    /// The queue of the last instance that emptied, kept for the next new instance (a writer whose
    /// history drains after every acknowledgement would otherwise allocate one per sample).
    spare_queue: Option<VecDeque<SequenceNumber>>,
}

impl HistoryCache {
    pub(crate) fn new(history: History, limits: ResourceLimits) -> Self {
        HistoryCache {
            changes: SnMap::new(),
            instances: HashMap::new(),
            history,
            limits,
            bytes: 0,
            spare_queue: None,
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.changes.len()
    }
    pub(crate) fn is_empty(&self) -> bool {
        self.changes.len() == 0
    }
    #[cfg(test)]
    pub(crate) fn bytes(&self) -> usize {
        self.bytes
    }
    pub(crate) fn get(&self, sn: SequenceNumber) -> Option<&CacheChange> {
        self.changes.get(sn)
    }
    pub(crate) fn first_sn(&self) -> Option<SequenceNumber> {
        self.changes.first().map(|(sn, _)| sn)
    }
    pub(crate) fn range(&self, from: SequenceNumber) -> impl Iterator<Item = &CacheChange> {
        self.changes.range_from(from)
    }

    /// Whether adding a change for `key` needs room that only acknowledged changes below `acked` could give.
    /// Returns the sequence numbers that must be dropped to make room, or Full.
    pub(crate) fn make_room(
        &mut self,
        key: &[u8; 16],
        acked: SequenceNumber,
    ) -> Result<(), HistoryFull> {
        let max_total = self.limits.max_samples.map(|m| m.max(1) as usize);
        let per_instance = match self.history {
            History::KeepLast(d) => Some(d.max(1) as usize),
            History::KeepAll => self
                .limits
                .max_samples_per_instance
                .map(|m| m.max(1) as usize),
        };
        let keep_last = matches!(self.history, History::KeepLast(_));
        if let Some(limit) = per_instance {
            // One lookup of the instance's queue for the check and the replacement.
            if let Some(q) = self.instances.get_mut(key).filter(|q| q.len() >= limit) {
                match q.front().copied() {
                    // KEEP_LAST replaces the oldest sample of the instance, acknowledged or not; the
                    // instance's queue stays for the change that replaces it.
                    Some(sn) if keep_last || sn < acked => {
                        if let Some(c) = self.changes.remove(sn) {
                            self.bytes -= c.payload.accounted_len();
                            q.pop_front();
                        }
                    }
                    Some(_) => return Err(HistoryFull::Full),
                    None => {}
                }
            }
        }
        if let Some(limit) = max_total {
            if self.changes.len() >= limit {
                let oldest = self.first_sn();
                match oldest {
                    Some(sn) if keep_last || sn < acked => {
                        self.remove(sn);
                    }
                    _ => {
                        // No change replaces the one the instance gave up: its queue goes, as `remove`'s.
                        if self.instances.get(key).is_some_and(|q| q.is_empty()) {
                            self.instances.remove(key);
                        }
                        return Err(HistoryFull::Full);
                    }
                }
            }
        }
        Ok(())
    }

    /// Adds a change (call [`make_room`](Self::make_room) first).
    pub(crate) fn add(&mut self, change: CacheChange) {
        let key = change.key_hash.unwrap_or_default();
        self.bytes += change.payload.accounted_len();
        // The instance is most often there already (`make_room` just looked it up): no entry's room check.
        match self.instances.get_mut(&key) {
            Some(q) => q.push_back(change.sn),
            None => {
                let mut q = self.spare_queue.take().unwrap_or_default();
                q.push_back(change.sn);
                self.instances.insert(key, q);
            }
        }
        self.changes.insert(change.sn, change);
    }

    pub(crate) fn remove(&mut self, sn: SequenceNumber) -> Option<CacheChange> {
        let c = self.changes.remove(sn)?;
        self.bytes -= c.payload.accounted_len();
        forget(&mut self.instances, &mut self.spare_queue, &c);
        Some(c)
    }

    /// Drops the changes whose lifespan ended at `now`; returns how many. Changes expire in the order they
    /// were written (one lifespan per writer), so only the expired front of the history is visited.
    pub(crate) fn expire(&mut self, now: Instant) -> usize {
        let mut n = 0;
        while let Some((sn, c)) = self.changes.first() {
            if c.expires.is_none_or(|e| e > now) {
                break;
            }
            self.remove(sn);
            n += 1;
        }
        n
    }

    /// Drops every change below `sn` (volatile writers, once acknowledged by all), where they lie in the
    /// ring: moving each ~200-byte change out to drop it was a tenth of a 16 B writer's time.
    /// Their payloads' reference counts were last touched when they were sent, so each run of changes has
    /// its payloads prefetched before it is dropped.
    pub(crate) fn remove_below(&mut self, sn: SequenceNumber) {
        const RUN: i64 = 32;
        while let Some(first) = self.first_sn() {
            if first >= sn {
                break;
            }
            let to = SequenceNumber(first.0.saturating_add(RUN).min(sn.0));
            self.changes
                .range_below(to)
                .for_each(|c| c.payload.prefetch());
            let (bytes, instances, spare) =
                (&mut self.bytes, &mut self.instances, &mut self.spare_queue);
            self.changes.drop_below(to, |c| {
                *bytes -= c.payload.accounted_len();
                forget(instances, spare, c);
            });
        }
    }

    /// Bytes of the changes at or above `sn`.
    /// Called after every acknowledgement: walks only the smaller side of `sn` (the total is kept), so a
    /// volatile writer, whose history starts at the acknowledged floor, pays nothing.
    pub(crate) fn bytes_from(&self, sn: SequenceNumber) -> usize {
        let (Some((first, _)), Some((last, _))) = (self.changes.first(), self.changes.last())
        else {
            return 0;
        };
        if sn <= first {
            return self.bytes;
        }
        if sn > last {
            return 0;
        }
        if sn.0 - first.0 <= last.0 - sn.0 {
            let below: usize = self
                .changes
                .range_below(sn)
                .map(|c| c.payload.accounted_len())
                .sum();
            self.bytes - below
        } else {
            self.changes
                .range_from(sn)
                .map(|c| c.payload.accounted_len())
                .sum()
        }
    }

    /// Drops disposed+unregistered instances' history beyond their last change (keeps memory bounded for
    /// transient-local writers whose instances come and go).
    pub(crate) fn prune_unregistered(&mut self, acked: SequenceNumber) {
        let dead: Vec<SequenceNumber> = self
            .instances
            .values()
            .filter_map(|q| {
                let last = *q.back()?;
                let c = self.changes.get(last)?;
                (matches!(
                    c.kind,
                    ChangeKind::Unregister | ChangeKind::DisposeUnregister
                ) && last < acked)
                    .then(|| q.iter().copied().collect::<Vec<_>>())
            })
            .flatten()
            .collect();
        for sn in dead {
            self.remove(sn);
        }
    }
}

/// Takes `c` out of its instance's queue; an emptied queue is dropped, and kept as the spare unless huge
/// (the queue of an unkeyed writer that drains now and then has grown to the samples in flight, and
/// regrowing it would cost a dozen allocations).
fn forget(
    instances: &mut HashMap<[u8; 16], VecDeque<SequenceNumber>>,
    spare: &mut Option<VecDeque<SequenceNumber>>,
    c: &CacheChange,
) {
    let key = c.key_hash.unwrap_or_default();
    let Some(q) = instances.get_mut(&key) else {
        return;
    };
    // Changes mostly go oldest first: the front.
    if q.front() == Some(&c.sn) {
        q.pop_front();
    } else if let Some(pos) = q.iter().position(|s| *s == c.sn) {
        q.remove(pos);
    }
    if q.is_empty() {
        if let Some(q) = instances.remove(&key) {
            if q.capacity() <= SPARE_QUEUE_MAX {
                *spare = Some(q);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ch(sn: i64, key: u8) -> CacheChange {
        CacheChange {
            sn: SequenceNumber(sn),
            kind: ChangeKind::Alive,
            payload: vec![0u8; 10].into(),
            key_hash: Some([key; 16]),
            source_timestamp: None,
            marks: Default::default(),
            rejected: Vec::new(),
            filter_info: None,
            expires: None,
        }
    }

    #[test]
    fn expire_drops_the_expired_front() {
        let t0 = Instant::now();
        let mut h = HistoryCache::new(History::KeepAll, ResourceLimits::default());
        for sn in 1..=4 {
            let mut c = ch(sn, 0);
            c.expires = Some(t0 + std::time::Duration::from_millis(sn as u64 * 10));
            h.add(c);
        }
        assert_eq!(h.expire(t0), 0);
        assert_eq!(h.expire(t0 + std::time::Duration::from_millis(20)), 2);
        assert_eq!(h.first_sn(), Some(SequenceNumber(3)));
        assert_eq!(h.bytes(), 20);
    }

    #[test]
    fn remove_below_keeps_bytes_and_instances_right() {
        let mut h = HistoryCache::new(History::KeepLast(2), ResourceLimits::default());
        // Instance 1 gets 1, 3, 4 (KEEP_LAST 2 drops 1: a hole), instance 2 gets 2 and 100 more.
        for (sn, k) in [(1, 1), (2, 2), (3, 1), (4, 1)] {
            h.make_room(&[k; 16], SequenceNumber(1)).unwrap();
            h.add(ch(sn, k));
        }
        for sn in 5..105 {
            h.make_room(&[2; 16], SequenceNumber(1)).unwrap();
            h.add(ch(sn, 2));
        }
        h.remove_below(SequenceNumber(104));
        assert_eq!(h.changes.keys().map(|s| s.0).collect::<Vec<_>>(), [104]);
        assert_eq!((h.len(), h.bytes()), (1, 10));
        assert!(!h.instances.contains_key(&[1; 16]), "instance 1 emptied");
        assert_eq!(
            h.instances[&[2; 16]]
                .iter()
                .map(|s| s.0)
                .collect::<Vec<_>>(),
            [104]
        );
        h.remove_below(SequenceNumber(1000));
        assert!(h.is_empty() && h.instances.is_empty() && h.spare_queue.is_some());
        assert_eq!(h.bytes(), 0);
    }

    #[test]
    fn keep_last_per_instance() {
        let mut h = HistoryCache::new(History::KeepLast(2), ResourceLimits::default());
        for (sn, k) in [(1, 1), (2, 2), (3, 1), (4, 1)] {
            h.make_room(&[k; 16], SequenceNumber(1)).unwrap();
            h.add(ch(sn, k));
        }
        assert_eq!(
            h.changes.keys().map(|s| s.0).collect::<Vec<_>>(),
            vec![2, 3, 4]
        );
        assert_eq!(h.bytes(), 30);
        let queue = |h: &HistoryCache, k: u8| {
            h.instances[&[k; 16]]
                .iter()
                .map(|s| s.0)
                .collect::<Vec<_>>()
        };
        assert_eq!((queue(&h, 1), queue(&h, 2)), (vec![3, 4], vec![2]));
        // KEEP_LAST 1: each write replaces the last in place.
        let mut h = HistoryCache::new(History::KeepLast(1), ResourceLimits::default());
        for sn in 1..5 {
            h.make_room(&[1; 16], SequenceNumber(1)).unwrap();
            h.add(ch(sn, 1));
            assert_eq!((h.len(), queue(&h, 1)), (1, vec![sn]));
        }
    }

    #[test]
    fn bytes_from_matches_a_full_walk() {
        let mut h = HistoryCache::new(History::KeepAll, ResourceLimits::default());
        for sn in 3..40 {
            h.make_room(&[0; 16], SequenceNumber(1)).unwrap();
            let mut c = ch(sn, 0);
            c.payload = vec![0u8; sn as usize].into();
            h.add(c);
        }
        for sn in 0..45 {
            let walk: usize = h
                .changes
                .range_from(SequenceNumber(sn))
                .map(|c| c.payload.accounted_len())
                .sum();
            assert_eq!(h.bytes_from(SequenceNumber(sn)), walk, "from {sn}");
        }
        assert_eq!(
            HistoryCache::new(History::KeepAll, ResourceLimits::default())
                .bytes_from(SequenceNumber(1)),
            0
        );
    }

    #[test]
    fn keep_all_limit() {
        let mut h = HistoryCache::new(
            History::KeepAll,
            ResourceLimits {
                max_samples: Some(2),
                max_instances: None,
                max_samples_per_instance: None,
            },
        );
        h.make_room(&[0; 16], SequenceNumber(1)).unwrap();
        h.add(ch(1, 0));
        h.make_room(&[0; 16], SequenceNumber(1)).unwrap();
        h.add(ch(2, 0));
        assert_eq!(
            h.make_room(&[0; 16], SequenceNumber(1)),
            Err(HistoryFull::Full)
        );
        // Once 1 is acknowledged it can go.
        assert_eq!(h.make_room(&[0; 16], SequenceNumber(2)), Ok(()));
        assert_eq!(h.len(), 1);
    }
}
