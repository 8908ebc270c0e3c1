//! What the service keeps of one original writer, within that writer's DURABILITY_SERVICE QoS: history kind
//! and depth per instance, `max_samples`, `max_instances` and `max_samples_per_instance`. Pure data: no
//! I/O, no clock.

use std::collections::{BTreeMap, HashMap, VecDeque};

use crate::qos::{DurabilityService, History};
use crate::rtps::{ChangeKind, Payload, Time, WriteChange};

/// One change of the original writer, as the service keeps (and persists) it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct StoredChange {
    /// The original writer's sequence number.
    pub(crate) seq: i64,
    /// What the change does to its instance.
    pub(crate) kind: ChangeKind,
    /// The instance's key hash (see [`instance_of`]).
    pub(crate) key_hash: [u8; 16],
    /// The original source timestamp.
    pub(crate) timestamp: Option<Time>,
    /// The serialized sample (or key).
    pub(crate) payload: Payload,
}

impl StoredChange {
    /// The change the service's writer republishes.
    pub(crate) fn to_write(&self, keyed: bool) -> WriteChange {
        let mut ch = WriteChange::alive(self.payload.clone()).with_kind(self.kind);
        if keyed {
            ch = ch.with_key_hash(self.key_hash);
        }
        if let Some(t) = self.timestamp {
            ch = ch.with_timestamp(t);
        }
        ch
    }
}

/// The instance a change belongs to: its PID_KEY_HASH, the single instance of a keyless topic, or, for a
/// keyed change sent without key hash (Cyclone sends none), a digest of its payload, so that such changes
/// are kept as instances of their own (bounded by the limits).
pub(crate) fn instance_of(keyed: bool, key_hash: Option<[u8; 16]>, payload: &[u8]) -> [u8; 16] {
    use md5::Digest;
    match (keyed, key_hash) {
        (false, _) => [0; 16],
        (true, Some(h)) => h,
        (true, None) => md5::Md5::digest(payload).into(),
    }
}

/// Limits of one writer's kept history.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Limits {
    /// Changes kept per instance.
    per_instance: usize,
    /// Changes kept in all.
    total: usize,
    /// Instances kept.
    instances: usize,
}

impl Limits {
    /// The limits of a DURABILITY_SERVICE QoS, capped at `cap` changes (the service's own bound, so that a
    /// writer announcing KEEP_ALL without limits cannot exhaust memory).
    pub(crate) fn new(ds: &DurabilityService, cap: usize) -> Self {
        let lim = |v: Option<u32>| v.map_or(usize::MAX, |n| n.max(1) as usize);
        let depth = match ds.history {
            History::KeepLast(n) => (n.max(1) as usize).min(lim(ds.max_samples_per_instance)),
            History::KeepAll => lim(ds.max_samples_per_instance),
        };
        Limits {
            per_instance: depth,
            total: lim(ds.max_samples).min(cap),
            instances: lim(ds.max_instances),
        }
    }
}

/// What insertion did.
#[derive(Debug, Default, PartialEq, Eq)]
pub(crate) struct Inserted {
    /// Whether the change was kept.
    pub(crate) kept: bool,
    /// Sequence numbers of the changes it evicted.
    pub(crate) evicted: Vec<i64>,
}

/// The kept history of one original writer.
#[derive(Debug)]
pub(crate) struct WriterHistory {
    limits: Limits,
    changes: BTreeMap<i64, StoredChange>,
    instances: HashMap<[u8; 16], VecDeque<i64>>,
    /// The highest sequence number ever kept.
    last_seq: i64,
}

impl WriterHistory {
    /// An empty history.
    pub(crate) fn new(limits: Limits) -> Self {
        WriterHistory {
            limits,
            changes: BTreeMap::new(),
            instances: HashMap::new(),
            last_seq: 0,
        }
    }

    /// A sequence number after every one kept so far (for changes learnt from another service, whose
    /// stand-in numbers them its own way).
    pub(crate) fn next_seq(&self) -> i64 {
        self.last_seq + 1
    }

    /// Keeps `ch` (a duplicate sequence number is ignored), evicting the oldest change of its instance beyond
    /// the depth and the oldest change of the writer beyond `max_samples`. A change of a new instance beyond
    /// `max_instances` is refused.
    pub(crate) fn insert(&mut self, ch: StoredChange) -> Inserted {
        let mut out = Inserted::default();
        if self.changes.contains_key(&ch.seq)
            || (!self.instances.contains_key(&ch.key_hash)
                && self.instances.len() >= self.limits.instances)
        {
            return out;
        }
        let q = self.instances.entry(ch.key_hash).or_default();
        q.push_back(ch.seq);
        while q.len() > self.limits.per_instance {
            if let Some(old) = q.pop_front() {
                self.changes.remove(&old);
                out.evicted.push(old);
            }
        }
        self.last_seq = self.last_seq.max(ch.seq);
        self.changes.insert(ch.seq, ch);
        while self.changes.len() > self.limits.total {
            if let Some((old, c)) = self.changes.pop_first() {
                self.forget(&c.key_hash, old);
                out.evicted.push(old);
            }
        }
        out.kept = true;
        out
    }

    fn forget(&mut self, instance: &[u8; 16], seq: i64) {
        if let Some(q) = self.instances.get_mut(instance) {
            q.retain(|s| *s != seq);
            if q.is_empty() {
                self.instances.remove(instance);
            }
        }
    }

    /// The kept changes, oldest first.
    pub(crate) fn changes(&self) -> impl Iterator<Item = &StoredChange> {
        self.changes.values()
    }

    /// How many changes are kept.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.changes.len()
    }

    /// Every instance's newest change disposes it (or nothing is kept): what `service_cleanup_delay` waits
    /// for before the service forgets the writer.
    pub(crate) fn all_disposed(&self) -> bool {
        self.instances.values().all(|q| {
            q.back().and_then(|s| self.changes.get(s)).is_some_and(|c| {
                matches!(c.kind, ChangeKind::Dispose | ChangeKind::DisposeUnregister)
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ch(seq: i64, instance: u8, kind: ChangeKind) -> StoredChange {
        StoredChange {
            seq,
            kind,
            key_hash: [instance; 16],
            timestamp: None,
            payload: Payload::from(vec![instance]),
        }
    }

    fn ds(history: History) -> DurabilityService {
        DurabilityService {
            history,
            ..DurabilityService::default()
        }
    }

    #[test]
    fn keep_last_per_instance() {
        let mut h = WriterHistory::new(Limits::new(&ds(History::KeepLast(2)), 1000));
        for seq in 1..=5 {
            assert!(h.insert(ch(seq, (seq % 2) as u8, ChangeKind::Alive)).kept);
        }
        let kept: Vec<i64> = h.changes().map(|c| c.seq).collect();
        assert_eq!(kept, vec![2, 3, 4, 5]);
        assert!(!h.insert(ch(5, 1, ChangeKind::Alive)).kept, "duplicate");
    }

    #[test]
    fn totals_and_instances_are_bounded() {
        let mut d = ds(History::KeepAll);
        d.max_samples = Some(3);
        d.max_instances = Some(2);
        let mut h = WriterHistory::new(Limits::new(&d, 1000));
        for seq in 1..=4 {
            h.insert(ch(seq, 1, ChangeKind::Alive));
        }
        assert_eq!(h.len(), 3);
        assert!(h.insert(ch(5, 2, ChangeKind::Alive)).kept);
        assert!(
            !h.insert(ch(6, 3, ChangeKind::Alive)).kept,
            "third instance"
        );
        let capped = Limits::new(&ds(History::KeepAll), 10);
        let mut h = WriterHistory::new(capped);
        for seq in 1..=50 {
            h.insert(ch(seq, seq as u8, ChangeKind::Alive));
        }
        assert_eq!(h.len(), 10, "the service's cap bounds KEEP_ALL");
    }

    #[test]
    fn disposed_instances() {
        let mut h = WriterHistory::new(Limits::new(&ds(History::KeepLast(1)), 100));
        h.insert(ch(1, 1, ChangeKind::Alive));
        h.insert(ch(2, 2, ChangeKind::Alive));
        h.insert(ch(3, 1, ChangeKind::Dispose));
        assert!(!h.all_disposed());
        h.insert(ch(4, 2, ChangeKind::DisposeUnregister));
        assert!(h.all_disposed());
    }

    #[test]
    fn instance_without_key_hash() {
        assert_eq!(instance_of(false, None, b"x"), [0; 16]);
        assert_eq!(instance_of(true, Some([7; 16]), b"x"), [7; 16]);
        assert_ne!(instance_of(true, None, b"x"), instance_of(true, None, b"y"));
    }
}
