//! What the service keeps of one original writer, within that writer's DURABILITY_SERVICE QoS: history kind
//! and depth per instance, `max_samples`, `max_instances` and `max_samples_per_instance`, then each
//! instance's final state, and per-instance cleanup. Pure data: no I/O; the caller gives the time.

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::time::{Duration, Instant};

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

/// Non-alive changes kept after an instance's last sample: enough for a dispose and an unregistration.
const FINAL_STATE: usize = 2;

/// What is kept of one instance.
#[derive(Debug, Default)]
struct Instance {
    /// Its newest samples (alive changes), oldest first, at most the history depth.
    samples: VecDeque<i64>,
    /// The non-alive changes (dispose, unregister) since its last sample, oldest first: its final state,
    /// replayed after the samples and not counted in the depth.
    final_state: VecDeque<i64>,
    /// When it was disposed (since its last sample).
    disposed_at: Option<Instant>,
    /// When its writer unregistered it (since its last sample).
    unregistered_at: Option<Instant>,
}

impl Instance {
    fn is_empty(&self) -> bool {
        self.samples.is_empty() && self.final_state.is_empty()
    }
    fn seqs(&self) -> impl Iterator<Item = i64> + '_ {
        self.samples.iter().chain(&self.final_state).copied()
    }
    /// When its purge is due: disposed, with no live writer (unregistered, or its writer `gone` since),
    /// for `delay` (DDS 1.4 §2.2.3.5, `service_cleanup_delay`).
    fn purge_at(&self, gone: Option<Instant>, delay: Duration) -> Option<Instant> {
        let disposed = self.disposed_at?;
        let writerless = match (self.unregistered_at, gone) {
            (Some(u), Some(g)) => u.min(g),
            (u, g) => u.or(g)?,
        };
        disposed.max(writerless).checked_add(delay)
    }
}

/// The kept history of one original writer: per instance its newest samples within the DURABILITY_SERVICE
/// history and limits, then its final state (dispose, unregistration), as a writer that stayed alive would
/// give a late joiner.
#[derive(Debug)]
pub(crate) struct WriterHistory {
    limits: Limits,
    changes: BTreeMap<i64, StoredChange>,
    instances: HashMap<[u8; 16], Instance>,
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

    /// Keeps `ch` (received at `now`; a duplicate sequence number is ignored). A sample evicts the oldest
    /// sample of its instance beyond the depth and ends the instance's final state; a dispose or an
    /// unregistration joins the final state (its oldest beyond [`FINAL_STATE`] evicted). Beyond `max_samples`
    /// the writer's oldest change goes. A change of a new instance beyond `max_instances` is refused.
    pub(crate) fn insert(&mut self, ch: StoredChange, now: Instant) -> Inserted {
        let mut out = Inserted::default();
        if self.changes.contains_key(&ch.seq)
            || (!self.instances.contains_key(&ch.key_hash)
                && self.instances.len() >= self.limits.instances)
        {
            return out;
        }
        let inst = self.instances.entry(ch.key_hash).or_default();
        let (queue, bound) = if ch.kind == ChangeKind::Alive {
            out.evicted.extend(inst.final_state.drain(..));
            inst.disposed_at = None;
            inst.unregistered_at = None;
            (&mut inst.samples, self.limits.per_instance)
        } else {
            if matches!(ch.kind, ChangeKind::Dispose | ChangeKind::DisposeUnregister) {
                inst.disposed_at.get_or_insert(now);
            }
            if matches!(
                ch.kind,
                ChangeKind::Unregister | ChangeKind::DisposeUnregister
            ) {
                inst.unregistered_at.get_or_insert(now);
            }
            (&mut inst.final_state, FINAL_STATE)
        };
        let seq = ch.seq;
        queue.push_back(seq);
        while queue.len() > bound {
            out.evicted.extend(queue.pop_front());
        }
        for seq in &out.evicted {
            self.changes.remove(seq);
        }
        self.last_seq = self.last_seq.max(seq);
        self.changes.insert(seq, ch);
        while self.changes.len() > self.limits.total {
            if let Some((old, c)) = self.changes.pop_first() {
                self.forget(&c.key_hash, old);
                out.evicted.push(old);
            }
        }
        out.kept = self.changes.contains_key(&seq);
        out
    }

    fn forget(&mut self, key: &[u8; 16], seq: i64) {
        if let Some(inst) = self.instances.get_mut(key) {
            inst.samples.retain(|s| *s != seq);
            inst.final_state.retain(|s| *s != seq);
            if inst.is_empty() {
                self.instances.remove(key);
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

    /// Whether nothing is kept.
    pub(crate) fn is_empty(&self) -> bool {
        self.changes.is_empty()
    }

    /// Purges every instance that has been disposed, with no live writer, for `delay` by `now` (the original
    /// writer `gone` since then, or the instance unregistered); returns the purged changes' sequence numbers.
    pub(crate) fn purge(
        &mut self,
        now: Instant,
        gone: Option<Instant>,
        delay: Duration,
    ) -> Vec<i64> {
        let due: Vec<[u8; 16]> = self
            .instances
            .iter()
            .filter(|(_, i)| i.purge_at(gone, delay).is_some_and(|t| now >= t))
            .map(|(k, _)| *k)
            .collect();
        let mut purged = Vec::new();
        for key in due {
            if let Some(inst) = self.instances.remove(&key) {
                purged.extend(inst.seqs());
            }
        }
        for seq in &purged {
            self.changes.remove(seq);
        }
        purged
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

    fn seqs(h: &WriterHistory) -> Vec<i64> {
        h.changes().map(|c| c.seq).collect()
    }

    #[test]
    fn keep_last_per_instance() {
        let now = Instant::now();
        let mut h = WriterHistory::new(Limits::new(&ds(History::KeepLast(2)), 1000));
        for seq in 1..=5 {
            assert!(
                h.insert(ch(seq, (seq % 2) as u8, ChangeKind::Alive), now)
                    .kept
            );
        }
        assert_eq!(seqs(&h), vec![2, 3, 4, 5]);
        assert!(
            !h.insert(ch(5, 1, ChangeKind::Alive), now).kept,
            "duplicate"
        );
    }

    #[test]
    fn totals_and_instances_are_bounded() {
        let now = Instant::now();
        let mut d = ds(History::KeepAll);
        d.max_samples = Some(3);
        d.max_instances = Some(2);
        let mut h = WriterHistory::new(Limits::new(&d, 1000));
        for seq in 1..=4 {
            h.insert(ch(seq, 1, ChangeKind::Alive), now);
        }
        assert_eq!(h.len(), 3);
        assert!(h.insert(ch(5, 2, ChangeKind::Alive), now).kept);
        assert!(
            !h.insert(ch(6, 3, ChangeKind::Alive), now).kept,
            "third instance"
        );
        let capped = Limits::new(&ds(History::KeepAll), 10);
        let mut h = WriterHistory::new(capped);
        for seq in 1..=50 {
            h.insert(ch(seq, seq as u8, ChangeKind::Alive), now);
        }
        assert_eq!(h.len(), 10, "the service's cap bounds KEEP_ALL");
        let ins = h.insert(ch(1, 60, ChangeKind::Alive), now);
        assert_eq!((ins.kept, ins.evicted), (false, vec![1]), "older than all");
    }

    /// KEEP_LAST 1: the unregistration and the dispose follow the instance's last sample instead of
    /// evicting it; a new sample ends that final state.
    #[test]
    fn the_final_state_follows_the_kept_samples() {
        let now = Instant::now();
        let mut h = WriterHistory::new(Limits::new(&ds(History::KeepLast(1)), 100));
        h.insert(ch(1, 1, ChangeKind::Alive), now);
        h.insert(ch(2, 1, ChangeKind::Alive), now);
        assert!(h
            .insert(ch(3, 1, ChangeKind::Dispose), now)
            .evicted
            .is_empty());
        assert!(h
            .insert(ch(4, 1, ChangeKind::Unregister), now)
            .evicted
            .is_empty());
        assert_eq!(seqs(&h), vec![2, 3, 4]);
        assert_eq!(
            h.insert(ch(5, 1, ChangeKind::Unregister), now).evicted,
            vec![3]
        );
        assert_eq!(
            h.insert(ch(6, 1, ChangeKind::Alive), now).evicted,
            vec![4, 5, 2]
        );
        assert_eq!(seqs(&h), vec![6]);
    }

    #[test]
    fn disposed_instances_are_purged_after_the_delay_once_writerless() {
        let t0 = Instant::now();
        let delay = Duration::from_secs(5);
        let at = |s: u64| t0 + Duration::from_secs(s);
        let mut h = WriterHistory::new(Limits::new(&ds(History::KeepLast(1)), 100));
        h.insert(ch(1, 1, ChangeKind::Alive), t0);
        h.insert(ch(2, 2, ChangeKind::Alive), t0);
        h.insert(ch(3, 3, ChangeKind::Alive), t0);
        // 1: disposed and unregistered at 1 s; 2: disposed at 2 s, its writer gone at 4 s; 3: unregistered only.
        h.insert(ch(4, 1, ChangeKind::DisposeUnregister), at(1));
        h.insert(ch(5, 2, ChangeKind::Dispose), at(2));
        h.insert(ch(6, 3, ChangeKind::Unregister), at(2));
        assert!(h.purge(at(5), None, delay).is_empty());
        let mut purged = h.purge(at(6), None, delay);
        purged.sort();
        assert_eq!(purged, vec![1, 4]);
        assert!(h.purge(at(8), Some(at(4)), delay).is_empty(), "gone at 4 s");
        assert_eq!(h.purge(at(9), Some(at(4)), delay), vec![2, 5]);
        assert!(
            h.purge(at(100), Some(at(4)), delay).is_empty(),
            "not disposed"
        );
        assert_eq!(seqs(&h), vec![3, 6]);
        assert!(!h.is_empty());
    }

    #[test]
    fn instance_without_key_hash() {
        assert_eq!(instance_of(false, None, b"x"), [0; 16]);
        assert_eq!(instance_of(true, Some([7; 16]), b"x"), [7; 16]);
        assert_ne!(instance_of(true, None, b"x"), instance_of(true, None, b"y"));
    }
}
