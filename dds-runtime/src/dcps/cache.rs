//! The reader's history cache: instances identified by their serialized key, samples with their states,
//! and the reader-side QoS (history, resource limits, ownership, time-based filter, lifespan, reader data
//! lifecycle, deadline). Pure data structure: no locking, no I/O, time comes in as arguments.

use std::collections::{BTreeMap, VecDeque};
use std::time::{Duration, Instant, SystemTime};

use foldhash::{HashMap, HashMapExt};

use crate::filter::{ContentFilter, FilterFields};
use crate::qos::{DataReaderQos, DestinationOrder, History, Ownership, INFINITE};
use crate::rtps::{ChangeKind, Guid};

use super::sample::{
    InstanceHandle, InstanceState, InstanceStateMask, Sample, SampleInfo, SampleState,
    SampleStateMask, ViewState, ViewStateMask,
};
use super::status::SampleRejectedReason;

mod order;
mod query;
mod single;
use query::read_query;
pub(crate) use query::SharedFilter;

/// One decoded change arriving from a writer.
pub(crate) struct Incoming<T> {
    pub(crate) writer: Guid,
    /// The writer `SampleInfo` names when it is not `writer`: a durability stand-in's original.
    pub(crate) attributed: Option<Guid>,
    pub(crate) kind: ChangeKind,
    pub(crate) data: Option<T>,
    /// Serialized key (`cdr::instance_key`), or the 16-byte key hash when nothing better is known.
    pub(crate) key: Vec<u8>,
    /// A sample holding (at least) the key values, for `get_key_value`.
    pub(crate) key_holder: Option<T>,
    pub(crate) source_timestamp: SystemTime,
    pub(crate) reception_timestamp: SystemTime,
    pub(crate) strength: i32,
    /// When the sample expires (writer's lifespan), if known.
    pub(crate) expires: Option<Instant>,
}

/// What happened to an incoming change.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Outcome {
    /// Stored (or the instance state changed): data is available.
    Accepted { handle: InstanceHandle },
    /// Dropped on purpose (filter, ownership, time-based filter, unknown instance for unregister).
    Filtered,
    /// Rejected by a resource limit.
    Rejected {
        reason: SampleRejectedReason,
        handle: InstanceHandle,
    },
}

struct Stored<T> {
    data: Option<T>,
    read: bool,
    source_timestamp: SystemTime,
    reception_timestamp: SystemTime,
    writer: Guid,
    disposed_gen: u32,
    no_writers_gen: u32,
    seq: u64,
    expires: Option<Instant>,
}

struct Instance<T> {
    key: Vec<u8>,
    key_holder: Option<T>,
    state: InstanceState,
    view: ViewState,
    disposed_gen: u32,
    no_writers_gen: u32,
    writers: HashMap<Guid, i32>,
    owner: Option<(Guid, i32)>,
    samples: VecDeque<Stored<T>>,
    /// The newest source timestamp accepted (DESTINATION_ORDER BY_SOURCE_TIMESTAMP).
    newest_source: Option<SystemTime>,
    last_accepted: Option<Instant>,
    last_data: Instant,
    not_alive_since: Option<Instant>,
}

impl<T> Instance<T> {
    /// A value from `inc` arrived: the instance is alive (a new generation when it was not) and `inc`'s
    /// writer one of its writers.
    fn revive(&mut self, inc: &Incoming<T>, now: Instant) {
        match self.state {
            InstanceState::Alive => {}
            InstanceState::NotAliveDisposed => {
                self.disposed_gen += 1;
                self.view = ViewState::New;
            }
            InstanceState::NotAliveNoWriters => {
                self.no_writers_gen += 1;
                self.view = ViewState::New;
            }
        }
        self.state = InstanceState::Alive;
        self.not_alive_since = None;
        self.writers.insert(inc.writer, inc.strength);
        self.last_accepted = Some(now);
        self.last_data = now;
        self.newest_source = Some(inc.source_timestamp);
    }

    /// Appends the sample `inc` numbered `seq`: with its data (`valid`), or as an invalid sample that
    /// carries a state change.
    fn push_sample(&mut self, seq: u64, inc: Incoming<T>, valid: bool) {
        let (data, expires) = if valid {
            (inc.data, inc.expires)
        } else {
            (None, None)
        };
        self.samples.push_back(Stored {
            data,
            read: false,
            source_timestamp: inc.source_timestamp,
            reception_timestamp: inc.reception_timestamp,
            writer: inc.attributed.unwrap_or(inc.writer),
            disposed_gen: self.disposed_gen,
            no_writers_gen: self.no_writers_gen,
            seq,
            expires,
        });
    }
}

/// Which samples a read/take returns.
#[derive(Debug, Clone, Default)]
pub(crate) struct Selection {
    pub(crate) max_samples: Option<usize>,
    pub(crate) sample_states: SampleStateMask,
    pub(crate) view_states: ViewStateMask,
    pub(crate) instance_states: InstanceStateMask,
    pub(crate) instance: Option<InstanceHandle>,
    /// A query condition's expression: only samples with data that it accepts, in its ORDER BY order.
    pub(crate) query: Option<SharedFilter>,
}

impl Selection {
    /// The samples in these states: no limit, instance or query.
    pub(crate) fn states(s: SampleStateMask, v: ViewStateMask, i: InstanceStateMask) -> Self {
        Selection {
            sample_states: s,
            view_states: v,
            instance_states: i,
            ..Selection::default()
        }
    }
}

type Filter<T> = Box<dyn Fn(&T) -> bool + Send + Sync>;

pub(crate) struct ReaderCache<T> {
    qos: DataReaderQos,
    keyed: bool,
    instances: BTreeMap<InstanceHandle, Instance<T>>,
    by_key: HashMap<Vec<u8>, InstanceHandle>,
    /// The serialized key of the instance a sample was last stored for, and its handle while it is known:
    /// a stream of one instance compares the key instead of hashing it.
    last: (Vec<u8>, Option<InstanceHandle>),
    /// The key buffer of the last sample of a known instance, for the next sample's key.
    spare_key: Vec<u8>,
    next_handle: u64,
    next_seq: u64,
    total: usize,
    filter: Option<Filter<T>>,
    /// Reads return samples grouped by instance (ordered access, INSTANCE scope) instead of in reception order.
    instance_order: bool,
    /// Makes the key holder of a new instance from its first data (`get_key_value`).
    key_of: Option<fn(&T) -> Option<T>>,
    /// Copies an instance's key holder into each sample without data (dispose, unregister) as it is read or
    /// taken (the dynamic reader's samples carry their key; a take may forget the instance right after).
    key_in_invalid: Option<fn(&T) -> T>,
    /// Derives an instance's handle from its key (the built-in readers: the entity's handle); else counted.
    handle_of: Option<fn(&[u8]) -> InstanceHandle>,
    /// At `max_instances`, a new instance evicts the instance longest not alive instead of being refused
    /// (the built-in readers: entities keep coming and going for the life of the participant).
    evict_not_alive: bool,
    /// `collect_with`'s working vectors, kept (empty) between calls so that a take allocates nothing.
    collect_scratch: (Vec<Touched>, Vec<(u64, usize, usize)>),
}

/// Marks sample `idx` of `inst` read and emits it; one without data is emitted with a copy of the instance's
/// key holder instead when `key_copy` is set (the sample itself keeps no data).
fn emit_sample<T>(
    inst: &mut Instance<T>,
    idx: usize,
    key_copy: Option<fn(&T) -> T>,
    info: SampleInfo,
    emit: &mut impl FnMut(&mut Option<T>, SampleInfo),
) {
    let s = &mut inst.samples[idx];
    s.read = true;
    match key_copy {
        Some(copy) if s.data.is_none() => emit(&mut inst.key_holder.as_ref().map(copy), info),
        _ => emit(&mut s.data, info),
    }
}

/// The sample a read (copying the data with `copy`, if any) or a take (moving it out) returns for `slot`.
pub(crate) fn to_sample<T>(
    slot: &mut Option<T>,
    info: SampleInfo,
    take: bool,
    copy: Option<fn(&T) -> T>,
) -> Sample<T> {
    let data = match (take, copy) {
        (true, _) => slot.take(),
        (false, Some(f)) => slot.as_ref().map(f),
        (false, None) => None,
    };
    Sample { data, info }
}

fn finite(d: Duration) -> Option<Duration> {
    (d != INFINITE && d < Duration::from_secs(100 * 365 * 86400)).then_some(d)
}

impl<T: FilterFields> ReaderCache<T> {
    pub(crate) fn new(qos: DataReaderQos, keyed: bool) -> Self {
        ReaderCache {
            qos,
            keyed,
            instances: BTreeMap::new(),
            by_key: HashMap::new(),
            last: (Vec::new(), None),
            spare_key: Vec::new(),
            next_handle: 1,
            next_seq: 0,
            total: 0,
            filter: None,
            instance_order: false,
            collect_scratch: (Vec::new(), Vec::new()),
            key_of: None,
            key_in_invalid: None,
            handle_of: None,
            evict_not_alive: false,
        }
    }

    /// At `max_instances`, make room by evicting the instance longest not alive (see `evict_not_alive`).
    pub(crate) fn set_evict_not_alive(&mut self, on: bool) {
        self.evict_not_alive = on;
    }

    /// Forgets the instance that has been not alive the longest, with its samples; false when every
    /// instance is alive.
    fn evict_oldest_not_alive(&mut self) -> bool {
        let oldest = self
            .instances
            .iter()
            .filter_map(|(h, i)| i.not_alive_since.map(|t| (t, *h)))
            .min();
        let Some((_, h)) = oldest else {
            return false;
        };
        if let Some(i) = self.forget_instance(h) {
            self.total -= i.samples.len();
        }
        true
    }

    /// Instance handles from now on derive from the key with `f` (a handle in use, or NIL, falls back to
    /// the counter).
    pub(crate) fn set_handle_fn(&mut self, f: fn(&[u8]) -> InstanceHandle) {
        self.handle_of = Some(f);
    }

    pub(crate) fn set_filter(&mut self, f: Option<Filter<T>>) {
        self.filter = f;
    }

    /// Numbers the next samples from `floor` on, if that is above the numbers given so far: readers that
    /// share one order (GROUP ordered access) number their samples from a counter they share.
    pub(crate) fn order_from(&mut self, floor: u64) {
        self.next_seq = self.next_seq.max(floor);
    }

    pub(crate) fn set_instance_order(&mut self, on: bool) {
        self.instance_order = on;
    }

    pub(crate) fn lookup(&self, key: &[u8]) -> Option<InstanceHandle> {
        self.by_key.get(key).copied()
    }

    pub(crate) fn len(&self) -> usize {
        self.total
    }

    pub(crate) fn instance_count(&self) -> usize {
        self.instances.len()
    }

    pub(crate) fn instance_state(&self, h: InstanceHandle) -> Option<InstanceState> {
        self.instances.get(&h).map(|i| i.state)
    }

    fn new_instance(
        &mut self,
        key: Vec<u8>,
        key_holder: Option<T>,
        now: Instant,
    ) -> Option<InstanceHandle> {
        if let Some(max) = self.qos.resource_limits.max_instances {
            if self.instances.len() >= max as usize
                && !(self.evict_not_alive && self.evict_oldest_not_alive())
            {
                return None;
            }
        }
        let h = match self.handle_of.map(|f| f(&key)) {
            Some(h) if h != InstanceHandle::NIL && !self.instances.contains_key(&h) => h,
            _ => {
                self.next_handle += 1;
                InstanceHandle(self.next_handle - 1)
            }
        };
        self.by_key.insert(key.clone(), h);
        self.instances.insert(
            h,
            Instance {
                key,
                key_holder,
                state: InstanceState::Alive,
                view: ViewState::New,
                disposed_gen: 0,
                no_writers_gen: 0,
                writers: HashMap::new(),
                owner: None,
                samples: VecDeque::new(),
                newest_source: None,
                last_accepted: None,
                last_data: now,
                not_alive_since: None,
            },
        );
        Some(h)
    }

    /// An empty buffer for the next sample's instance key (reusing the last one's allocation).
    pub(crate) fn take_key_buffer(&mut self) -> Vec<u8> {
        let mut k = std::mem::take(&mut self.spare_key);
        k.clear();
        k
    }

    /// Applies one change. `now` is the monotonic time of reception.
    pub(crate) fn insert(&mut self, mut inc: Incoming<T>, now: Instant) -> Outcome {
        let alive = inc.kind == ChangeKind::Alive;
        if alive {
            match (&inc.data, &self.filter) {
                (None, _) => return Outcome::Filtered,
                (Some(d), Some(f)) if !f(d) => return Outcome::Filtered,
                _ => {}
            }
        }
        let handle = match self.instance_of(&mut inc, now) {
            Ok(h) => h,
            Err(outcome) => return outcome,
        };
        let Some(inst) = self.instances.get_mut(&handle) else {
            return Outcome::Filtered;
        };
        if !admits(&self.qos, inst, &mut inc, now) {
            return Outcome::Filtered;
        }
        if alive {
            // The instance found once for both (where each looked it up).
            let counts = (&mut self.total, &mut self.next_seq);
            insert_alive(&self.qos, counts, inst, handle, inc, now)
        } else {
            self.insert_state_change(handle, inc, now)
        }
    }

    /// The instance of `inc`'s key, made when new; an unregister of an unknown instance is filtered, a new
    /// instance past the limit rejected.
    fn instance_of(
        &mut self,
        inc: &mut Incoming<T>,
        now: Instant,
    ) -> Result<InstanceHandle, Outcome> {
        let key = if self.keyed {
            std::mem::take(&mut inc.key)
        } else {
            Vec::new()
        };
        if let (k, Some(h)) = &self.last {
            if *k == key {
                let h = *h;
                self.spare_key = key;
                return Ok(h);
            }
        }
        match self.by_key.get(&key) {
            Some(h) => {
                let h = *h;
                self.spare_key = std::mem::replace(&mut self.last.0, key);
                self.last.1 = Some(h);
                Ok(h)
            }
            None if inc.kind == ChangeKind::Unregister => Err(Outcome::Filtered),
            None => {
                let holder = inc
                    .key_holder
                    .take()
                    .or_else(|| self.key_of.and_then(|f| inc.data.as_ref().and_then(f)));
                self.new_instance(key, holder, now)
                    .ok_or(Outcome::Rejected {
                        reason: SampleRejectedReason::ByInstancesLimit,
                        handle: InstanceHandle::NIL,
                    })
            }
        }
    }

    /// Dispose / unregister: a state change; visible through an invalid sample when no unread sample of the
    /// instance can carry it.
    fn insert_state_change(
        &mut self,
        handle: InstanceHandle,
        inc: Incoming<T>,
        now: Instant,
    ) -> Outcome {
        let Some(inst) = self.instances.get_mut(&handle) else {
            return Outcome::Filtered;
        };
        let before = inst.state;
        if matches!(
            inc.kind,
            ChangeKind::Dispose | ChangeKind::DisposeUnregister
        ) {
            if inst.state == InstanceState::NotAliveNoWriters {
                inst.no_writers_gen += 1;
            }
            inst.state = InstanceState::NotAliveDisposed;
            inst.newest_source = Some(inc.source_timestamp);
        }
        if matches!(
            inc.kind,
            ChangeKind::Unregister | ChangeKind::DisposeUnregister
        ) {
            inst.writers.remove(&inc.writer);
            if inst.owner.is_some_and(|(g, _)| g == inc.writer) {
                inst.owner = None;
            }
            if inst.writers.is_empty() && inst.state == InstanceState::Alive {
                inst.state = InstanceState::NotAliveNoWriters;
            }
        }
        if inst.state == before {
            return Outcome::Filtered;
        }
        inst.not_alive_since = Some(now);
        let has_unread = inst.samples.iter().any(|s| !s.read);
        if !has_unread {
            let seq = self.next_seq;
            self.next_seq += 1;
            inst.push_sample(seq, inc, false);
            self.total += 1;
        }
        Outcome::Accepted { handle }
    }

    /// A writer is gone (unmatched or lost): its instances lose it as if it had unregistered them.
    /// Returns whether any instance changed state.
    pub(crate) fn writer_gone(&mut self, writer: Guid, now: Instant) -> bool {
        let handles: Vec<InstanceHandle> = self
            .instances
            .iter()
            .filter(|(_, i)| i.writers.contains_key(&writer))
            .map(|(h, _)| *h)
            .collect();
        let mut changed = false;
        for h in handles {
            let Some(inst) = self.instances.get(&h) else {
                continue;
            };
            let key = inst.key.clone();
            let inc = Incoming {
                writer,
                attributed: None,
                kind: ChangeKind::Unregister,
                data: None,
                key,
                key_holder: None,
                source_timestamp: SystemTime::now(),
                reception_timestamp: SystemTime::now(),
                strength: i32::MIN,
                expires: None,
            };
            if let Outcome::Accepted { .. } = self.insert(inc, now) {
                changed = true;
            }
        }
        changed
    }

    fn matches(inst: &Instance<T>, s: &Stored<T>, sel: &Selection) -> bool {
        sel.sample_states.contains(if s.read {
            SampleState::Read
        } else {
            SampleState::NotRead
        }) && sel.view_states.contains(inst.view)
            && sel.instance_states.contains(inst.state)
    }

    /// Whether some sample matches the masks (ReadCondition trigger, DATA_AVAILABLE).
    pub(crate) fn has_matching(&self, sel: &Selection) -> bool {
        // Asked after every take, which usually leaves nothing: then no instance needs a look.
        if self.total == 0 {
            return false;
        }
        let q = read_query(sel);
        self.instances.values().any(|i| {
            i.samples
                .iter()
                .any(|s| Self::selected(i, s, sel, q.as_deref()))
        })
    }

    /// Appends the number (the order of reception, see [`ReaderCache::order_from`]) of every selected
    /// sample to `out`.
    pub(crate) fn matching_order(&self, sel: &Selection, out: &mut Vec<u64>) {
        let q = read_query(sel);
        for i in self.instances.values() {
            out.extend(
                i.samples
                    .iter()
                    .filter(|s| Self::selected(i, s, sel, q.as_deref()))
                    .map(|s| s.seq),
            );
        }
    }

    /// The smallest instance handle above `prev` that has a matching sample.
    pub(crate) fn next_instance(
        &self,
        prev: InstanceHandle,
        sel: &Selection,
    ) -> Option<InstanceHandle> {
        use std::ops::Bound::{Excluded, Unbounded};
        let q = read_query(sel);
        self.instances
            .range((Excluded(prev), Unbounded))
            .find(|(_, i)| {
                i.samples
                    .iter()
                    .any(|s| Self::selected(i, s, sel, q.as_deref()))
            })
            .map(|(h, _)| *h)
    }

    /// Reads (`take == false`, data cloned by `copy`) or takes the selected samples, in reception order.
    #[cfg(test)]
    fn collect(
        &mut self,
        sel: &Selection,
        take: bool,
        copy: Option<fn(&T) -> T>,
    ) -> Vec<Sample<T>> {
        let mut out = Vec::new();
        self.collect_with(sel, take, |slot, info| {
            out.push(to_sample(slot, info, take, copy))
        });
        out
    }

    /// Core of read/take: calls `emit` with each selected sample's data slot and info, in reception order;
    /// with `take` the samples are removed afterwards (whatever `emit` left in the slot is dropped).
    pub(crate) fn collect_with(
        &mut self,
        sel: &Selection,
        take: bool,
        mut emit: impl FnMut(&mut Option<T>, SampleInfo),
    ) {
        if self.collect_single(sel, take, &mut emit) {
            return;
        }
        let limit = sel.max_samples.unwrap_or(usize::MAX);
        let q = read_query(sel);
        let q = q.as_deref();
        // Instances with a selected sample, and the selection as (seq, instance ordinal, index in instance).
        let (mut touched, mut picked) = std::mem::take(&mut self.collect_scratch);
        touched.clear();
        picked.clear();
        self.gather(sel, q, &mut touched, &mut picked);
        // Gathered instance by instance, each in reception order: grouped by instance as it is. Otherwise, in
        // reception order; without ORDER BY only the first `limit` are wanted: select them, then sort just those.
        let ordered_by_query = q.is_some_and(|q| q.has_order_by());
        if !self.instance_order {
            if !ordered_by_query && picked.len() > limit && limit > 0 {
                picked.select_nth_unstable_by_key(limit - 1, |p| p.0);
                picked.truncate(limit);
            }
            picked.sort_unstable_by_key(|p| p.0);
        }
        self.order_by(q, &mut picked, &touched);
        picked.truncate(limit);
        self.emit_picked(&picked, &mut touched, &mut emit);
        // View state becomes NOT_NEW for every instance touched.
        for t in touched.iter().filter(|t| t.count > 0) {
            if let Some(inst) = self.instances.get_mut(&t.handle) {
                inst.view = ViewState::NotNew;
            }
        }
        if take {
            self.remove_picked(&mut picked, &touched);
        }
        touched.clear();
        picked.clear();
        self.collect_scratch = (touched, picked);
    }

    /// Lists the selected samples as `(seq, touched index, sample index)` in `picked`, and the instances
    /// that have one in `touched`: instance by instance, each in reception order.
    fn gather(
        &self,
        sel: &Selection,
        q: Option<&ContentFilter>,
        touched: &mut Vec<Touched>,
        picked: &mut Vec<(u64, usize, usize)>,
    ) {
        let mut gather = |h: InstanceHandle, inst: &Instance<T>| {
            let before = picked.len();
            for (i, s) in inst.samples.iter().enumerate() {
                if Self::selected(inst, s, sel, q) {
                    picked.push((s.seq, touched.len(), i));
                }
            }
            if picked.len() > before {
                touched.push(Touched {
                    handle: h,
                    count: 0,
                    emitted: 0,
                    last_index: 0,
                });
            }
        };
        match sel.instance {
            Some(h) => {
                if let Some(inst) = self.instances.get(&h) {
                    gather(h, inst);
                }
            }
            None => self.instances.iter().for_each(|(h, inst)| gather(*h, inst)),
        }
    }

    /// Calls `emit` with each picked sample, in `picked`'s order, and marks it read.
    fn emit_picked(
        &mut self,
        picked: &[(u64, usize, usize)],
        touched: &mut [Touched],
        emit: &mut impl FnMut(&mut Option<T>, SampleInfo),
    ) {
        // Ranks count the samples of the same instance later in the collection; the last one (in reception
        // order) is the instance's most recent sample in the collection.
        for &(_, t, idx) in picked {
            touched[t].count += 1;
            touched[t].last_index = idx;
        }
        for &(_, t, idx) in picked {
            let tc = &mut touched[t];
            let Some(inst) = self.instances.get_mut(&tc.handle) else {
                continue;
            };
            tc.emitted += 1;
            let sample_rank = (tc.count - tc.emitted) as u32;
            // The generation of the instance's most recent sample in the collection.
            let mrs_gen = inst
                .samples
                .get(tc.last_index)
                .map_or(0, |s| s.disposed_gen + s.no_writers_gen);
            let info = sample_info(inst, &inst.samples[idx], tc.handle, sample_rank, mrs_gen);
            emit_sample(inst, idx, self.key_in_invalid, info, emit);
        }
    }

    /// Removes the picked samples (taken), and the instances left with nothing to remember.
    fn remove_picked(&mut self, picked: &mut [(u64, usize, usize)], touched: &[Touched]) {
        // Per instance, ascending index, each instance's samples removed in one pass.
        picked.sort_unstable_by_key(|p| (p.1, p.2));
        for group in picked.chunk_by(|a, b| a.1 == b.1) {
            if let Some(inst) = self.instances.get_mut(&touched[group[0].1].handle) {
                remove_indices(&mut inst.samples, group.iter().map(|p| p.2));
            }
        }
        self.total -= picked.len();
        for t in touched.iter().filter(|t| t.count > 0) {
            self.maybe_drop_instance(t.handle);
        }
    }

    /// An instance with no samples, no writers and not alive is forgotten.
    fn maybe_drop_instance(&mut self, h: InstanceHandle) {
        let drop_it = self.instances.get(&h).is_some_and(single::forgettable);
        if drop_it {
            self.forget_instance(h);
        }
    }

    /// Removes the instance `h` (returned, with its samples) and its key.
    fn forget_instance(&mut self, h: InstanceHandle) -> Option<Instance<T>> {
        let i = self.instances.remove(&h)?;
        self.by_key.remove(&i.key);
        if self.last.1 == Some(h) {
            self.last.1 = None;
        }
        Some(i)
    }

    /// Time-driven QoS: lifespan expiry, autopurge, deadline. Returns the instances whose deadline was missed.
    pub(crate) fn tick(&mut self, now: Instant) -> Vec<InstanceHandle> {
        let lc = self.qos.reader_data_lifecycle;
        let nowriter = finite(lc.autopurge_nowriter_samples_delay);
        let disposed = finite(lc.autopurge_disposed_samples_delay);
        let deadline = finite(self.qos.deadline.0);
        let mut missed = Vec::new();
        let mut purge = Vec::new();
        let mut removed = 0;
        for (h, inst) in self.instances.iter_mut() {
            let before = inst.samples.len();
            inst.samples.retain(|s| s.expires.is_none_or(|e| e > now));
            removed += before - inst.samples.len();
            if let Some(since) = inst.not_alive_since {
                let delay = match inst.state {
                    InstanceState::NotAliveDisposed => disposed,
                    InstanceState::NotAliveNoWriters => nowriter,
                    InstanceState::Alive => None,
                };
                if delay.is_some_and(|d| now.saturating_duration_since(since) >= d) {
                    removed += inst.samples.len();
                    inst.samples.clear();
                    purge.push(*h);
                }
            }
            if let Some(d) = deadline {
                if inst.state == InstanceState::Alive
                    && now.saturating_duration_since(inst.last_data) >= d
                {
                    inst.last_data = now;
                    // The owner missed its deadline: the next strongest writer may take over.
                    inst.owner = None;
                    missed.push(*h);
                }
            }
        }
        self.total -= removed;
        for h in purge {
            if let Some(i) = self.instances.get_mut(&h) {
                i.writers.clear();
            }
            self.maybe_drop_instance(h);
        }
        missed
    }
}

/// An instance with samples in a read/take collection.
struct Touched {
    handle: InstanceHandle,
    /// Its samples in the collection, and how many of them were emitted so far.
    count: usize,
    emitted: usize,
    /// Index (in the instance) of its last sample in the collection.
    last_index: usize,
}

/// The `SampleInfo` of `s`, a sample of `inst` (`handle`) with `sample_rank` samples of its instance after
/// it in the collection, whose most recent one there has generation `mrs_gen` (DDS 1.4 §2.2.2.5.5).
fn sample_info<T>(
    inst: &Instance<T>,
    s: &Stored<T>,
    handle: InstanceHandle,
    sample_rank: u32,
    mrs_gen: u32,
) -> SampleInfo {
    let gen = s.disposed_gen + s.no_writers_gen;
    SampleInfo {
        sample_state: if s.read {
            SampleState::Read
        } else {
            SampleState::NotRead
        },
        view_state: inst.view,
        instance_state: inst.state,
        source_timestamp: s.source_timestamp,
        reception_timestamp: s.reception_timestamp,
        instance_handle: handle,
        publication_handle: InstanceHandle::from_guid(s.writer),
        publication_guid: s.writer,
        disposed_generation_count: s.disposed_gen,
        no_writers_generation_count: s.no_writers_gen,
        sample_rank,
        generation_rank: mrs_gen.saturating_sub(gen),
        absolute_generation_rank: (inst.disposed_gen + inst.no_writers_gen).saturating_sub(gen),
        valid_data: s.data.is_some(),
    }
}

/// Whether `inc` counts for its instance `inst` under exclusive ownership and destination order. Records
/// the writer's strength and the instance's owner.
fn admits<T>(
    qos: &DataReaderQos,
    inst: &mut Instance<T>,
    inc: &mut Incoming<T>,
    now: Instant,
) -> bool {
    let exclusive = qos.ownership == Ownership::Exclusive;
    let by_source = qos.destination_order == DestinationOrder::BySourceTimestamp;
    let deadline = finite(qos.deadline.0);
    if inst.key_holder.is_none() {
        inst.key_holder = inc.key_holder.take();
    }

    // Exclusive ownership: only the strongest alive writer's changes count (ties: lowest GUID); an
    // owner that missed the requested deadline of the instance hands it over.
    if exclusive {
        inst.writers.insert(inc.writer, inc.strength);
        let stale = deadline.is_some_and(|d| now.saturating_duration_since(inst.last_data) >= d);
        if !order::owner_accepts(inst.owner, &inst.writers, inc.writer, inc.strength, stale) {
            if matches!(
                inc.kind,
                ChangeKind::Unregister | ChangeKind::DisposeUnregister
            ) {
                inst.writers.remove(&inc.writer);
            }
            return false;
        }
        inst.owner = Some((inc.writer, inc.strength));
    }

    // Destination order by source timestamp: a value or dispose older than the newest accepted one
    // of the instance is dropped (DDS 1.4 §2.2.3.17); unregisters always count.
    let ordered = matches!(inc.kind, ChangeKind::Alive | ChangeKind::Dispose);
    !(by_source && ordered && !order::in_source_order(inst.newest_source, inc.source_timestamp))
}

/// Stores a value: subject to the time-based filter and the history and resource limits; revives a
/// not-alive instance.
fn insert_alive<T>(
    qos: &DataReaderQos,
    (total, next_seq): (&mut usize, &mut u64),
    inst: &mut Instance<T>,
    handle: InstanceHandle,
    inc: Incoming<T>,
    now: Instant,
) -> Outcome {
    let min_sep = qos.time_based_filter.minimum_separation;
    let history = qos.history;
    let limits = qos.resource_limits;
    if !min_sep.is_zero()
        && inst
            .last_accepted
            .is_some_and(|t| now.saturating_duration_since(t) < min_sep)
    {
        return Outcome::Filtered;
    }
    let per_instance = inst.samples.len();
    if let History::KeepAll = history {
        if limits
            .max_samples_per_instance
            .is_some_and(|m| per_instance >= m as usize)
        {
            return Outcome::Rejected {
                reason: SampleRejectedReason::BySamplesPerInstanceLimit,
                handle,
            };
        }
    }
    let evict = matches!(history, History::KeepLast(d) if per_instance >= d.max(1) as usize);
    if !evict && limits.max_samples.is_some_and(|m| *total >= m as usize) {
        return Outcome::Rejected {
            reason: SampleRejectedReason::BySamplesLimit,
            handle,
        };
    }
    inst.revive(&inc, now);
    if evict {
        if let Some(old) = inst.samples.pop_front() {
            drop(old);
            *total -= 1;
        }
    }
    let seq = *next_seq;
    *next_seq += 1;
    inst.push_sample(seq, inc, true);
    *total += 1;
    Outcome::Accepted { handle }
}

/// Removes the samples at `indices` (ascending, distinct) from `q`: a prefix (the usual take of the oldest)
/// with one drain, anything else in one pass over the queue; never an element shift per removed sample.
fn remove_indices<S>(q: &mut VecDeque<S>, indices: impl ExactSizeIterator<Item = usize> + Clone) {
    let n = indices.len();
    if indices.clone().enumerate().all(|(k, i)| k == i) {
        q.drain(..n);
        return;
    }
    let mut next = indices.peekable();
    let mut i = 0usize;
    q.retain(|_| {
        let drop_it = next.next_if_eq(&i).is_some();
        i += 1;
        !drop_it
    });
}

/// What `DataReader::get_qos`/`set_qos` and `get_key_value` need.
impl<T> ReaderCache<T> {
    /// The QoS the cache applies.
    pub(crate) fn qos(&self) -> &DataReaderQos {
        &self.qos
    }

    /// Replaces the QoS (`set_qos` checked that only changeable policies differ: deadline, time-based
    /// filter, reader data lifecycle, ...); applies from the next sample or tick.
    pub(crate) fn set_qos(&mut self, qos: DataReaderQos) {
        self.qos = qos;
    }

    /// Gives new instances of received data a key holder made with `f` (once per instance).
    pub(crate) fn set_key_holder_fn(&mut self, f: fn(&T) -> Option<T>) {
        self.key_of = Some(f);
    }

    /// Gives each sample without data a copy (made with `f`) of its instance's key holder when it is read or
    /// taken.
    pub(crate) fn set_key_in_invalid_fn(&mut self, f: fn(&T) -> T) {
        self.key_in_invalid = Some(f);
    }

    /// A sample holding the key of instance `h`, if one was received.
    pub(crate) fn key_holder(&self, h: InstanceHandle) -> Option<&T> {
        self.instances.get(&h)?.key_holder.as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::qos::{ReaderDataLifecycle, ResourceLimits, TimeBasedFilter};

    fn inc(w: u8, kind: ChangeKind, key: u8, v: i32) -> Incoming<i32> {
        Incoming {
            writer: Guid::from_bytes([w; 16]),
            attributed: None,
            kind,
            data: (kind == ChangeKind::Alive).then_some(v),
            key: vec![key],
            key_holder: None,
            source_timestamp: SystemTime::now(),
            reception_timestamp: SystemTime::now(),
            strength: i32::from(w),
            expires: None,
        }
    }

    fn cp(x: &i32) -> i32 {
        *x
    }
    const CP: Option<fn(&i32) -> i32> = Some(cp);

    fn all() -> Selection {
        Selection::default()
    }

    #[test]
    fn one_sample_is_read_and_taken_as_among_many() {
        let mut c = ReaderCache::new(DataReaderQos::default(), true);
        let now = Instant::now();
        c.insert(inc(1, ChangeKind::Alive, 1, 10), now);
        c.insert(inc(1, ChangeKind::Alive, 2, 20), now);
        let (h1, h2) = (c.lookup(&[1]).unwrap(), c.lookup(&[2]).unwrap());
        let of = |h| Selection {
            instance: Some(h),
            ..all()
        };
        assert_eq!(c.collect(&of(h1), true, CP).len(), 1);
        // From here on the cache holds one sample (the one-sample path).
        assert!(c.collect(&of(h1), false, CP).is_empty(), "another instance");
        let none = Selection {
            max_samples: Some(0),
            ..all()
        };
        assert!(c.collect(&none, false, CP).is_empty());
        let r = c.collect(&all(), false, CP);
        assert_eq!(r.len(), 1);
        let i = &r[0].info;
        assert_eq!((r[0].data, i.instance_handle), (Some(20), h2));
        assert_eq!(
            (i.sample_state, i.view_state),
            (SampleState::NotRead, ViewState::New)
        );
        assert_eq!(
            (i.sample_rank, i.generation_rank, i.absolute_generation_rank),
            (0, 0, 0)
        );
        let unread = Selection {
            sample_states: SampleStateMask::NOT_READ,
            ..all()
        };
        assert!(c.collect(&unread, true, CP).is_empty(), "read already");
        assert_eq!(c.len(), 1);
        let r = c.collect(&of(h2), true, CP);
        assert_eq!(r[0].info.sample_state, SampleState::Read);
        assert_eq!(r[0].info.view_state, ViewState::NotNew);
        assert_eq!(c.len(), 0);
        assert!(c.collect(&all(), true, CP).is_empty());
        assert_eq!(c.lookup(&[2]), Some(h2), "an alive instance stays");
    }

    #[test]
    fn keep_last_per_instance_and_states() {
        let qos = DataReaderQos {
            history: History::KeepLast(2),
            ..Default::default()
        };
        let mut c = ReaderCache::new(qos, true);
        let now = Instant::now();
        for v in 0..5 {
            c.insert(inc(1, ChangeKind::Alive, 1, v), now);
        }
        c.insert(inc(1, ChangeKind::Alive, 2, 100), now);
        assert_eq!(c.len(), 3);
        let r = c.collect(&all(), false, CP);
        assert_eq!(
            r.iter().map(|s| s.data.unwrap()).collect::<Vec<_>>(),
            vec![3, 4, 100]
        );
        assert_eq!(r[0].info.sample_rank, 1);
        assert_eq!(r[1].info.sample_rank, 0);
        assert!(r.iter().all(|s| s.info.view_state == ViewState::New));
        let r = c.collect(&all(), false, CP);
        assert!(r.iter().all(|s| s.info.sample_state == SampleState::Read));
        assert!(r.iter().all(|s| s.info.view_state == ViewState::NotNew));
        // Dispose key 1: state visible on the retained samples.
        c.insert(inc(1, ChangeKind::Dispose, 1, 0), now);
        let h1 = c.lookup(&[1]).unwrap();
        let r = c.collect(
            &Selection {
                instance: Some(h1),
                ..all()
            },
            true,
            CP,
        );
        assert_eq!(r.len(), 3, "two read samples + invalid sample");
        assert!(r
            .iter()
            .all(|s| s.info.instance_state == InstanceState::NotAliveDisposed));
        assert!(!r[2].info.valid_data);
        // Rebirth: new generation, view NEW again.
        c.insert(inc(1, ChangeKind::Alive, 1, 7), now);
        let r = c.collect(
            &Selection {
                instance: Some(h1),
                ..all()
            },
            true,
            CP,
        );
        assert_eq!(r[0].info.disposed_generation_count, 1);
        assert_eq!(r[0].info.view_state, ViewState::New);
        // Unregister by the only writer: NOT_ALIVE_NO_WRITERS, then forgotten once taken.
        c.insert(inc(1, ChangeKind::Unregister, 1, 0), now);
        let r = c.collect(
            &Selection {
                instance: Some(h1),
                ..all()
            },
            true,
            CP,
        );
        assert_eq!(r[0].info.instance_state, InstanceState::NotAliveNoWriters);
        assert!(c.lookup(&[1]).is_none());
    }

    #[test]
    fn exclusive_ownership_keeps_strongest() {
        let qos = DataReaderQos {
            ownership: Ownership::Exclusive,
            history: History::KeepLast(10),
            ..Default::default()
        };
        let mut c = ReaderCache::new(qos, true);
        let now = Instant::now();
        c.insert(inc(5, ChangeKind::Alive, 1, 1), now);
        assert_eq!(
            c.insert(inc(2, ChangeKind::Alive, 1, 2), now),
            Outcome::Filtered
        );
        assert!(matches!(
            c.insert(inc(9, ChangeKind::Alive, 1, 3), now),
            Outcome::Accepted { .. }
        ));
        assert_eq!(
            c.insert(inc(5, ChangeKind::Alive, 1, 4), now),
            Outcome::Filtered
        );
        c.insert(inc(9, ChangeKind::Unregister, 1, 0), now);
        assert!(matches!(
            c.insert(inc(5, ChangeKind::Alive, 1, 5), now),
            Outcome::Accepted { .. }
        ));
        let r: Vec<i32> = c
            .collect(&all(), true, CP)
            .into_iter()
            .filter_map(|s| s.data)
            .collect();
        assert_eq!(r, vec![1, 3, 5]);
    }

    #[test]
    fn exclusive_owner_missing_its_deadline_hands_over() {
        let qos = DataReaderQos {
            ownership: Ownership::Exclusive,
            deadline: crate::qos::Deadline(Duration::from_millis(100)),
            history: History::KeepLast(10),
            ..Default::default()
        };
        let mut c = ReaderCache::new(qos, true);
        let t0 = Instant::now();
        let ms = |n| t0 + Duration::from_millis(n);
        assert!(matches!(
            c.insert(inc(9, ChangeKind::Alive, 1, 1), t0),
            Outcome::Accepted { .. }
        ));
        assert_eq!(
            c.insert(inc(2, ChangeKind::Alive, 1, 2), ms(50)),
            Outcome::Filtered
        );
        // The owner is silent for a deadline: the weaker writer takes over, then 9 takes back.
        assert!(matches!(
            c.insert(inc(2, ChangeKind::Alive, 1, 3), ms(120)),
            Outcome::Accepted { .. }
        ));
        assert!(matches!(
            c.insert(inc(9, ChangeKind::Alive, 1, 4), ms(130)),
            Outcome::Accepted { .. }
        ));
        assert_eq!(
            c.insert(inc(2, ChangeKind::Alive, 1, 5), ms(140)),
            Outcome::Filtered
        );
        // The same through the deadline tick.
        assert_eq!(c.tick(ms(240)).len(), 1);
        assert!(matches!(
            c.insert(inc(2, ChangeKind::Alive, 1, 6), ms(245)),
            Outcome::Accepted { .. }
        ));
    }

    #[test]
    fn at_the_instance_limit_the_instance_longest_not_alive_makes_room() {
        let qos = DataReaderQos {
            resource_limits: ResourceLimits {
                max_samples: None,
                max_instances: Some(2),
                max_samples_per_instance: None,
            },
            ..Default::default()
        };
        let mut c = ReaderCache::new(qos, true);
        c.set_evict_not_alive(true);
        let t = Instant::now();
        let ms = |n| t + Duration::from_millis(n);
        c.insert(inc(1, ChangeKind::Alive, 1, 1), ms(0));
        c.insert(inc(1, ChangeKind::Alive, 2, 2), ms(0));
        // Every instance alive: a third is refused.
        assert!(matches!(
            c.insert(inc(1, ChangeKind::Alive, 3, 3), ms(1)),
            Outcome::Rejected {
                reason: SampleRejectedReason::ByInstancesLimit,
                ..
            }
        ));
        // Key 2 disposed, then key 1: key 2 has been gone longer and makes room for key 3.
        c.insert(inc(1, ChangeKind::Dispose, 2, 0), ms(2));
        c.insert(inc(1, ChangeKind::Dispose, 1, 0), ms(3));
        assert!(matches!(
            c.insert(inc(1, ChangeKind::Alive, 3, 3), ms(4)),
            Outcome::Accepted { .. }
        ));
        assert_eq!(c.instance_count(), 2);
        assert!(c.lookup(&[2]).is_none());
        assert!(c.lookup(&[1]).is_some() && c.lookup(&[3]).is_some());
        assert_eq!(
            c.len(),
            2,
            "key 1's sample and key 3's; key 2's went with it"
        );
    }

    #[test]
    fn limits_filter_and_autopurge() {
        let qos = DataReaderQos {
            history: History::KeepAll,
            resource_limits: ResourceLimits {
                max_samples: Some(3),
                max_instances: Some(2),
                max_samples_per_instance: None,
            },
            time_based_filter: TimeBasedFilter {
                minimum_separation: Duration::from_millis(0),
            },
            reader_data_lifecycle: ReaderDataLifecycle {
                autopurge_nowriter_samples_delay: Duration::from_millis(10),
                autopurge_disposed_samples_delay: INFINITE,
            },
            ..Default::default()
        };
        let mut c = ReaderCache::new(qos, true);
        let now = Instant::now();
        c.insert(inc(1, ChangeKind::Alive, 1, 1), now);
        c.insert(inc(1, ChangeKind::Alive, 2, 2), now);
        assert!(matches!(
            c.insert(inc(1, ChangeKind::Alive, 3, 3), now),
            Outcome::Rejected {
                reason: SampleRejectedReason::ByInstancesLimit,
                ..
            }
        ));
        c.insert(inc(1, ChangeKind::Alive, 2, 3), now);
        assert!(matches!(
            c.insert(inc(1, ChangeKind::Alive, 2, 4), now),
            Outcome::Rejected {
                reason: SampleRejectedReason::BySamplesLimit,
                ..
            }
        ));
        c.set_filter(Some(Box::new(|x: &i32| *x > 10)));
        assert_eq!(
            c.insert(inc(1, ChangeKind::Alive, 1, 5), now),
            Outcome::Filtered
        );
        assert!(c.writer_gone(Guid::from_bytes([1; 16]), now));
        c.tick(now + Duration::from_millis(20));
        assert_eq!(c.len(), 0);
        assert_eq!(c.instance_count(), 0);
    }

    #[test]
    fn time_based_filter_and_deadline() {
        let qos = DataReaderQos {
            history: History::KeepLast(10),
            time_based_filter: TimeBasedFilter {
                minimum_separation: Duration::from_millis(100),
            },
            deadline: crate::qos::Deadline(Duration::from_millis(50)),
            ..Default::default()
        };
        let mut c = ReaderCache::new(qos, true);
        let t0 = Instant::now();
        c.insert(inc(1, ChangeKind::Alive, 1, 1), t0);
        assert_eq!(
            c.insert(
                inc(1, ChangeKind::Alive, 1, 2),
                t0 + Duration::from_millis(50)
            ),
            Outcome::Filtered
        );
        assert!(matches!(
            c.insert(
                inc(1, ChangeKind::Alive, 1, 3),
                t0 + Duration::from_millis(150)
            ),
            Outcome::Accepted { .. }
        ));
        assert_eq!(c.tick(t0 + Duration::from_millis(160)).len(), 0);
        assert_eq!(c.tick(t0 + Duration::from_millis(210)).len(), 1);
    }

    #[test]
    fn remove_indices_prefix_and_scattered() {
        let mut q: VecDeque<u32> = (0..10).collect();
        remove_indices(&mut q, [0usize, 1, 2].into_iter());
        assert_eq!(q, (3..10).collect::<VecDeque<_>>());
        remove_indices(&mut q, [1usize, 4, 6].into_iter());
        assert_eq!(q, VecDeque::from([3, 5, 6, 8]));
        remove_indices(&mut q, std::iter::empty());
        assert_eq!(q.len(), 4);
    }
}
