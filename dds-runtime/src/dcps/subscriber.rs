//! `Subscriber` and `DataReader<T>`.

use std::collections::VecDeque;
use std::pin::Pin;
use std::sync::atomic::{AtomicUsize, Ordering as AtomicOrdering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, Weak};
use std::task::{Context, Poll, Waker};
use std::time::{Duration, Instant, SystemTime};

use foldhash::{HashMap, HashMapExt};

use crate::cdr::{self, DdsType};
use crate::qos::{DataReaderQos, DataRepresentation, ReaderQos, SubscriberQos};
use crate::rtps::{ChangeKind, EntityId, Event, Guid, ReaderSpec, ReceivedSample};

use super::cache::{ChangeKindLocal, Incoming, Outcome, ReaderCache, Selection};
use super::condition::{ReadCondition, ReadConditionSource, Signal, StatusCondition, StatusCore};
use super::error::{DdsError, DdsResult};
use super::listener::DataReaderListener;
use super::participant::{DomainParticipant, Pending, ReaderSink, RemoteWriterInfo, Shared};
use super::sample::{
    InstanceHandle, InstanceStateMask, Sample, SampleInfo, SampleStateMask, ViewStateMask,
};
use super::status::{
    DeadlineMissedStatus, IncompatibleQosStatus, LivelinessChangedStatus, ReaderStatuses,
    SampleLostStatus, SampleRejectedStatus, StatusMask, SubscriptionMatchedStatus,
};
use super::topic::{Topic, TopicDescription};

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Groups readers; carries the partition and presentation QoS.
#[derive(Clone)]
pub struct Subscriber {
    participant: DomainParticipant,
    qos: Arc<SubscriberQos>,
}

impl std::fmt::Debug for Subscriber {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Subscriber")
            .field("qos", &self.qos)
            .finish()
    }
}

/// Most key hashes remembered per reader for mapping key-hash-only disposes to instances.
const MAX_REMEMBERED_HASHES: usize = 65536;

impl Subscriber {
    pub(crate) fn new(participant: DomainParticipant, qos: SubscriberQos) -> Self {
        Subscriber {
            participant,
            qos: Arc::new(qos),
        }
    }

    /// The subscriber QoS.
    pub fn qos(&self) -> &SubscriberQos {
        &self.qos
    }

    /// The participant.
    pub fn participant(&self) -> &DomainParticipant {
        &self.participant
    }

    /// Creates a reader on a topic or content-filtered topic. An empty `data_representation` accepts XCDR1
    /// and XCDR2.
    pub fn create_datareader<T: DdsType, D: TopicDescription<T>>(
        &self,
        topic: &D,
        qos: &DataReaderQos,
    ) -> DdsResult<DataReader<T>> {
        let shared = self.participant.shared.clone();
        shared.check_alive()?;
        let mut rq = qos.clone();
        if rq.data_representation.ids().is_empty() {
            rq.data_representation = DataRepresentation::accept_both();
        }
        if let crate::qos::History::KeepLast(0) = rq.history {
            return Err(DdsError::BadParameter("history depth 0".into()));
        }
        let t = topic.topic();
        let spec = ReaderSpec {
            topic_name: t.name().to_string(),
            type_name: T::TYPE_NAME.to_string(),
            keyed: T::IS_KEYED,
            qos: ReaderQos::new(rq.clone(), &self.qos, t.qos()),
            type_information: None,
            entity_name: None,
        };
        let credit_limit = match (&rq.reliability, &rq.history, rq.resource_limits.max_samples) {
            (crate::qos::Reliability::Reliable { .. }, crate::qos::History::KeepAll, Some(m)) => {
                Some(m as usize)
            }
            _ => None,
        };
        let mut cache = ReaderCache::new(rq.clone(), T::IS_KEYED);
        cache.set_filter(topic.sample_filter());
        let inner = Arc::new(ReaderInner::<T> {
            shared: shared.clone(),
            id: Mutex::new(EntityId::UNKNOWN),
            pending: Mutex::new(VecDeque::new()),
            cache: Mutex::new(CacheState {
                cache,
                by_hash: HashMap::new(),
                batch: VecDeque::new(),
            }),
            data_cv: Condvar::new(),
            data_waiters: AtomicUsize::new(0),
            wakers: Mutex::new(Vec::new()),
            statuses: Mutex::new(ReaderStatuses::default()),
            status_core: Arc::new(StatusCore::default()),
            data_signal: Signal::default(),
            listener: Mutex::new(None),
            matched: Mutex::new(Vec::new()),
            handle: Mutex::new(Weak::new()),
            credit_limit,
        });
        let sink: Arc<dyn ReaderSink> = inner.clone();
        let id = shared.with_core(|c, now| {
            let id = c.create_reader(now, spec)?;
            if credit_limit.is_some() {
                c.set_reader_credit(id, credit_limit);
            }
            *lock(&inner.id) = id;
            shared.register_reader(id, sink);
            Ok::<_, crate::rtps::CoreError>(id)
        });
        let id = id.map_err(|e| DdsError::Core(e.to_string()))?;
        let handle = Arc::new(ReaderHandle {
            participant: self.participant.clone(),
            topic: t.clone(),
            subscriber: self.clone(),
            id,
        });
        *lock(&inner.handle) = Arc::downgrade(&handle);
        tracing::info!(
            topic = t.name(),
            type_name = T::TYPE_NAME,
            ?id,
            "reader created"
        );
        Ok(DataReader { inner, handle })
    }
}

struct CacheState<T> {
    cache: ReaderCache<T>,
    /// Key hash → serialized key, learnt from samples that carried both (for key-hash-only disposes).
    by_hash: HashMap<[u8; 16], Vec<u8>>,
    /// The queue being processed, swapped with `pending` (one lock round per batch, buffers reused).
    batch: VecDeque<Pending>,
}

struct ReaderInner<T: DdsType> {
    shared: Arc<Shared>,
    id: Mutex<EntityId>,
    pending: Mutex<VecDeque<Pending>>,
    cache: Mutex<CacheState<T>>,
    data_cv: Condvar,
    /// Threads in `wait_for_data`; registered under the cache lock so that `notify_data` (called after the
    /// change was made under that lock) skips the futex wake only when nobody can be sleeping.
    data_waiters: AtomicUsize,
    wakers: Mutex<Vec<Waker>>,
    statuses: Mutex<ReaderStatuses>,
    status_core: Arc<StatusCore>,
    data_signal: Signal,
    listener: Mutex<Option<Arc<dyn DataReaderListener<T>>>>,
    matched: Mutex<Vec<Guid>>,
    handle: Mutex<Weak<ReaderHandle<T>>>,
    /// Reliable KEEP_ALL with max_samples: the core delivers (and acknowledges) only what fits.
    credit_limit: Option<usize>,
}

struct ReaderHandle<T: DdsType> {
    participant: DomainParticipant,
    topic: Topic<T>,
    subscriber: Subscriber,
    id: EntityId,
}

impl<T: DdsType> Drop for ReaderHandle<T> {
    fn drop(&mut self) {
        let shared = &self.participant.shared;
        shared.unregister_reader(self.id);
        if shared.check_alive().is_ok() {
            let id = self.id;
            shared.with_core(|c, now| c.delete_reader(now, id));
        }
        tracing::debug!(id = ?self.id, "reader deleted");
    }
}

/// Reads samples of type `T`. Cheap to clone; the reader is deleted when the last clone (and the last
/// stream) is dropped.
///
/// Reader-side QoS enforced here: history (KEEP_LAST depth per instance, KEEP_ALL), resource limits
/// (max_samples, max_instances, max_samples_per_instance), exclusive ownership (strongest writer, ties to
/// the lowest GUID), time-based filter (per instance, no delayed delivery of the last filtered sample),
/// reader data lifecycle (both autopurge delays), lifespan (from the writer's announced lifespan, counted
/// from the source timestamp), requested deadline missed (checked every 50 ms).
/// Not enforced: destination order by source timestamp (reception order is used), presentation
/// (coherent/ordered access), liveliness kinds other than what the core reports.
pub struct DataReader<T: DdsType> {
    inner: Arc<ReaderInner<T>>,
    handle: Arc<ReaderHandle<T>>,
}

impl<T: DdsType> Clone for DataReader<T> {
    fn clone(&self) -> Self {
        DataReader {
            inner: self.inner.clone(),
            handle: self.handle.clone(),
        }
    }
}

impl<T: DdsType> std::fmt::Debug for DataReader<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DataReader")
            .field("topic", &self.handle.topic.name())
            .field("id", &self.handle.id)
            .finish()
    }
}

/// Chooses samples for a read or take: `reader.select().max_samples(10).instance_state(..).take()`.
pub struct Selector<'a, T: DdsType> {
    reader: &'a DataReader<T>,
    sel: Selection,
    next_after: Option<InstanceHandle>,
}

impl<'a, T: DdsType> Selector<'a, T> {
    /// At most `n` samples.
    pub fn max_samples(mut self, n: usize) -> Self {
        self.sel.max_samples = Some(n);
        self
    }
    /// Only samples in these sample states.
    pub fn sample_state(mut self, m: SampleStateMask) -> Self {
        self.sel.sample_states = m;
        self
    }
    /// Only instances in these view states.
    pub fn view_state(mut self, m: ViewStateMask) -> Self {
        self.sel.view_states = m;
        self
    }
    /// Only instances in these instance states.
    pub fn instance_state(mut self, m: InstanceStateMask) -> Self {
        self.sel.instance_states = m;
        self
    }
    /// Only this instance.
    pub fn instance(mut self, h: InstanceHandle) -> Self {
        self.sel.instance = Some(h);
        self
    }
    /// Only the next instance after `prev` (in handle order) that has matching samples.
    pub fn next_instance(mut self, prev: InstanceHandle) -> Self {
        self.next_after = Some(prev);
        self
    }
    /// Takes the selected samples.
    pub fn take(self) -> DdsResult<Vec<Sample<T>>> {
        self.reader.collect(self.sel, self.next_after, true, None)
    }
    /// Zero-copy read (a loan in callback form): calls `f` with a reference to each selected sample in the
    /// cache, marks them read and returns how many there were. The cache lock is held during the calls:
    /// keep `f` short and do not call back into this reader from it.
    pub fn read_with(self, mut f: impl FnMut(Option<&T>, &SampleInfo)) -> DdsResult<usize> {
        let mut n = 0;
        self.reader.visit(self.sel, self.next_after, |slot, info| {
            n += 1;
            f(slot.as_ref(), &info);
        })?;
        Ok(n)
    }

    /// Reads (copies) the selected samples.
    pub fn read(self) -> DdsResult<Vec<Sample<T>>>
    where
        T: Clone,
    {
        self.reader
            .collect(self.sel, self.next_after, false, Some(T::clone))
    }
}

impl<T: DdsType> DataReader<T> {
    fn visit(
        &self,
        mut sel: Selection,
        next_after: Option<InstanceHandle>,
        emit: impl FnMut(&mut Option<T>, SampleInfo),
    ) -> DdsResult<()> {
        self.inner.shared.check_alive()?;
        {
            let mut st = lock(&self.inner.cache);
            if let Some(prev) = next_after {
                sel.instance = None;
                match st.cache.next_instance(prev, &sel) {
                    Some(h) => sel.instance = Some(h),
                    None => return Ok(()),
                }
            }
            st.cache.collect_with(&sel, false, emit);
            let unread = Selection {
                sample_states: SampleStateMask::NOT_READ,
                ..Selection::default()
            };
            if !st.cache.has_matching(&unread) {
                self.inner.status_core.clear(StatusMask::DATA_AVAILABLE);
            }
        }
        self.inner.data_signal.notify();
        Ok(())
    }

    /// Zero-copy read of all samples, see [`Selector::read_with`].
    pub fn read_with(&self, f: impl FnMut(Option<&T>, &SampleInfo)) -> DdsResult<usize> {
        self.select().read_with(f)
    }

    fn collect(
        &self,
        mut sel: Selection,
        next_after: Option<InstanceHandle>,
        take: bool,
        copy: Option<fn(&T) -> T>,
    ) -> DdsResult<Vec<Sample<T>>> {
        self.inner.shared.check_alive()?;
        let out = {
            let mut st = lock(&self.inner.cache);
            if let Some(prev) = next_after {
                sel.instance = None;
                match st.cache.next_instance(prev, &sel) {
                    Some(h) => sel.instance = Some(h),
                    None => return Ok(Vec::new()),
                }
            }
            let out = st.cache.collect(&sel, take, copy);
            let unread = Selection {
                sample_states: SampleStateMask::NOT_READ,
                ..Selection::default()
            };
            if !st.cache.has_matching(&unread) {
                self.inner.status_core.clear(StatusMask::DATA_AVAILABLE);
            }
            out
        };
        if take && !out.is_empty() {
            self.inner.refresh_credit();
        }
        // Read conditions may have stopped triggering.
        self.inner.data_signal.notify();
        Ok(out)
    }

    /// A selector for read/take with masks and limits.
    pub fn select(&self) -> Selector<'_, T> {
        Selector {
            reader: self,
            sel: Selection::default(),
            next_after: None,
        }
    }

    /// Reads (copies) all samples; they stay in the cache, marked read.
    pub fn read(&self) -> DdsResult<Vec<Sample<T>>>
    where
        T: Clone,
    {
        self.select().read()
    }

    /// Takes all samples out of the cache.
    pub fn take(&self) -> DdsResult<Vec<Sample<T>>> {
        self.select().take()
    }

    /// Reads the oldest not-read sample.
    pub fn read_next_sample(&self) -> DdsResult<Option<Sample<T>>>
    where
        T: Clone,
    {
        Ok(self
            .select()
            .sample_state(SampleStateMask::NOT_READ)
            .max_samples(1)
            .read()?
            .pop())
    }

    /// Takes the oldest not-read sample.
    pub fn take_next_sample(&self) -> DdsResult<Option<Sample<T>>> {
        Ok(self
            .select()
            .sample_state(SampleStateMask::NOT_READ)
            .max_samples(1)
            .take()?
            .pop())
    }

    /// Reads the samples of one instance.
    pub fn read_instance(&self, h: InstanceHandle) -> DdsResult<Vec<Sample<T>>>
    where
        T: Clone,
    {
        self.check_instance(h)?;
        self.select().instance(h).read()
    }

    /// Takes the samples of one instance.
    pub fn take_instance(&self, h: InstanceHandle) -> DdsResult<Vec<Sample<T>>> {
        self.check_instance(h)?;
        self.select().instance(h).take()
    }

    fn check_instance(&self, h: InstanceHandle) -> DdsResult<()> {
        if lock(&self.inner.cache).cache.instance_state(h).is_none() {
            return Err(DdsError::BadParameter(format!("unknown instance {h:?}")));
        }
        Ok(())
    }

    /// Reads the samples of the next instance after `prev` (`InstanceHandle::NIL` for the first).
    pub fn read_next_instance(&self, prev: InstanceHandle) -> DdsResult<Vec<Sample<T>>>
    where
        T: Clone,
    {
        self.select().next_instance(prev).read()
    }

    /// Takes the samples of the next instance after `prev`.
    pub fn take_next_instance(&self, prev: InstanceHandle) -> DdsResult<Vec<Sample<T>>> {
        self.select().next_instance(prev).take()
    }

    /// Reads with a read condition's masks.
    pub fn read_w_condition(&self, c: &ReadCondition) -> DdsResult<Vec<Sample<T>>>
    where
        T: Clone,
    {
        self.select()
            .sample_state(c.sample_states)
            .view_state(c.view_states)
            .instance_state(c.instance_states)
            .read()
    }

    /// Takes with a read condition's masks.
    pub fn take_w_condition(&self, c: &ReadCondition) -> DdsResult<Vec<Sample<T>>> {
        self.select()
            .sample_state(c.sample_states)
            .view_state(c.view_states)
            .instance_state(c.instance_states)
            .take()
    }

    /// The handle of the instance whose key equals the key of `key_sample` (other members are ignored).
    pub fn lookup_instance(&self, key_sample: &T) -> Option<InstanceHandle> {
        let key = if T::IS_KEYED {
            let mut k = Vec::new();
            cdr::instance_key(key_sample, &mut k).ok()?;
            k
        } else {
            Vec::new()
        };
        lock(&self.inner.cache).cache.lookup(&key)
    }

    /// Number of instances held.
    pub fn instance_count(&self) -> usize {
        lock(&self.inner.cache).cache.instance_count()
    }

    /// Number of samples held.
    pub fn sample_count(&self) -> usize {
        lock(&self.inner.cache).cache.len()
    }

    /// Blocks until a not-read sample is available (`Ok(true)`) or `timeout` passes (`Ok(false)`).
    pub fn wait_for_data(&self, timeout: Duration) -> DdsResult<bool> {
        let deadline = Instant::now().checked_add(timeout);
        let unread = Selection {
            sample_states: SampleStateMask::NOT_READ,
            ..Selection::default()
        };
        let mut st = lock(&self.inner.cache);
        loop {
            if st.cache.has_matching(&unread) {
                return Ok(true);
            }
            self.inner.shared.check_alive()?;
            let left = match deadline {
                Some(d) => match d.checked_duration_since(Instant::now()) {
                    Some(l) if !l.is_zero() => l,
                    _ => return Ok(false),
                },
                None => Duration::from_secs(1),
            };
            self.inner.data_waiters.fetch_add(1, AtomicOrdering::SeqCst);
            st = self
                .inner
                .data_cv
                .wait_timeout(st, left.min(Duration::from_secs(1)))
                .unwrap_or_else(|e| e.into_inner())
                .0;
            self.inner.data_waiters.fetch_sub(1, AtomicOrdering::SeqCst);
        }
    }

    /// An async stream of samples (each taken, oldest first). Runtime-agnostic: it registers the task's
    /// waker and is woken by the receive thread. Ends when the participant shuts down.
    pub fn stream(&self) -> SampleStream<T> {
        SampleStream {
            reader: self.clone(),
        }
    }

    /// A read condition on this reader.
    pub fn create_readcondition(
        &self,
        sample_states: SampleStateMask,
        view_states: ViewStateMask,
        instance_states: InstanceStateMask,
    ) -> ReadCondition {
        ReadCondition {
            source: self.inner.clone(),
            sample_states,
            view_states,
            instance_states,
        }
    }

    /// The reader's status condition.
    pub fn status_condition(&self) -> StatusCondition {
        StatusCondition {
            core: self.inner.status_core.clone(),
        }
    }

    /// Installs a listener (replacing any previous one).
    pub fn set_listener(&self, listener: Box<dyn DataReaderListener<T>>) {
        *lock(&self.inner.listener) = Some(Arc::from(listener));
    }

    /// Removes the listener.
    pub fn clear_listener(&self) {
        *lock(&self.inner.listener) = None;
    }

    /// The topic.
    pub fn topic(&self) -> &Topic<T> {
        &self.handle.topic
    }

    /// The subscriber.
    pub fn subscriber(&self) -> &Subscriber {
        &self.handle.subscriber
    }

    /// The reader's GUID.
    pub fn guid(&self) -> [u8; 16] {
        Guid::new(self.inner.shared.guid_prefix, self.handle.id).to_bytes()
    }

    /// Handles of the matched writers.
    pub fn matched_publications(&self) -> Vec<InstanceHandle> {
        lock(&self.inner.matched)
            .iter()
            .map(|g| InstanceHandle::from_guid_bytes(&g.to_bytes()))
            .collect()
    }

    /// SUBSCRIPTION_MATCHED (resets the change counts).
    pub fn subscription_matched_status(&self) -> SubscriptionMatchedStatus {
        let mut st = lock(&self.inner.statuses);
        let s = st.subscription_matched.clone();
        st.subscription_matched.total_count_change = 0;
        st.subscription_matched.current_count_change = 0;
        self.inner
            .status_core
            .clear(StatusMask::SUBSCRIPTION_MATCHED);
        s
    }

    /// REQUESTED_INCOMPATIBLE_QOS (resets the change count).
    pub fn requested_incompatible_qos_status(&self) -> IncompatibleQosStatus {
        let mut st = lock(&self.inner.statuses);
        let s = st.requested_incompatible_qos.clone();
        st.requested_incompatible_qos.total_count_change = 0;
        self.inner
            .status_core
            .clear(StatusMask::REQUESTED_INCOMPATIBLE_QOS);
        s
    }

    /// SAMPLE_LOST (resets the change count).
    pub fn sample_lost_status(&self) -> SampleLostStatus {
        let mut st = lock(&self.inner.statuses);
        let s = st.sample_lost.clone();
        st.sample_lost.total_count_change = 0;
        self.inner.status_core.clear(StatusMask::SAMPLE_LOST);
        s
    }

    /// SAMPLE_REJECTED (resets the change count).
    pub fn sample_rejected_status(&self) -> SampleRejectedStatus {
        let mut st = lock(&self.inner.statuses);
        let s = st.sample_rejected.clone();
        st.sample_rejected.total_count_change = 0;
        self.inner.status_core.clear(StatusMask::SAMPLE_REJECTED);
        s
    }

    /// LIVELINESS_CHANGED (resets the change counts).
    pub fn liveliness_changed_status(&self) -> LivelinessChangedStatus {
        let mut st = lock(&self.inner.statuses);
        let s = st.liveliness_changed.clone();
        st.liveliness_changed.alive_count_change = 0;
        st.liveliness_changed.not_alive_count_change = 0;
        self.inner.status_core.clear(StatusMask::LIVELINESS_CHANGED);
        s
    }

    /// REQUESTED_DEADLINE_MISSED (resets the change count).
    pub fn requested_deadline_missed_status(&self) -> DeadlineMissedStatus {
        let mut st = lock(&self.inner.statuses);
        let s = st.requested_deadline_missed.clone();
        st.requested_deadline_missed.total_count_change = 0;
        self.inner
            .status_core
            .clear(StatusMask::REQUESTED_DEADLINE_MISSED);
        s
    }
}

fn system_time(t: Option<crate::rtps::Time>) -> Option<SystemTime> {
    t.and_then(|t| t.to_unix())
        .map(|d| SystemTime::UNIX_EPOCH + d)
}

impl<T: DdsType> ReaderInner<T> {
    fn reader_handle(self: &Arc<Self>) -> Option<DataReader<T>> {
        let handle = lock(&self.handle).upgrade()?;
        Some(DataReader {
            inner: self.clone(),
            handle,
        })
    }

    /// Gives the core back the room freed by a take. Under the core lock every delivered sample is either
    /// queued in `pending` or in the cache, so the credit is exact.
    fn refresh_credit(&self) {
        let Some(limit) = self.credit_limit else {
            return;
        };
        let id = *lock(&self.id);
        self.shared.with_core(|c, _| {
            let held = lock(&self.cache).cache.len() + lock(&self.pending).len();
            c.set_reader_credit(id, Some(limit.saturating_sub(held)));
        });
    }

    fn notify_data(self: &Arc<Self>) {
        if self.data_waiters.load(AtomicOrdering::SeqCst) > 0 {
            self.data_cv.notify_all();
        }
        let wakers = std::mem::take(&mut *lock(&self.wakers));
        for w in wakers {
            w.wake();
        }
        self.status_core.raise(StatusMask::DATA_AVAILABLE);
        self.data_signal.notify();
        let listener = lock(&self.listener).clone();
        if let (Some(l), Some(r)) = (listener, self.reader_handle()) {
            l.on_data_available(&r);
        }
    }
}

/// Turns a received change into a cache input; `None` (logged) when it cannot be decoded or mapped to an
/// instance. Instances are identified by `cdr::instance_key`; a key-only change without a decodable key
/// payload is mapped through its key hash to an instance seen before with the same hash.
fn decode_change<T: DdsType>(
    s: ReceivedSample,
    info: RemoteWriterInfo,
    by_hash: &mut HashMap<[u8; 16], Vec<u8>>,
    mut key: Vec<u8>,
    now: Instant,
    rx_time: SystemTime,
) -> Option<Incoming<T>> {
    let source_timestamp = system_time(s.source_timestamp);
    let kind = match s.kind {
        ChangeKind::Alive => ChangeKindLocal::Alive,
        ChangeKind::Dispose => ChangeKindLocal::Dispose,
        ChangeKind::Unregister => ChangeKindLocal::Unregister,
        ChangeKind::DisposeUnregister => ChangeKindLocal::DisposeUnregister,
    };
    key.clear();
    let mut data = None;
    let mut key_holder = None;
    if kind == ChangeKindLocal::Alive {
        let d = match cdr::deserialize::<T>(&s.payload) {
            Ok(d) => d,
            Err(e) => {
                tracing::warn!(writer = ?s.writer, seq = s.sequence.0, error = %e, "dropping undecodable sample");
                return None;
            }
        };
        if T::IS_KEYED {
            if let Err(e) = cdr::instance_key(&d, &mut key) {
                tracing::warn!(error = %e, "cannot compute the instance key");
                return None;
            }
            // Index the key hashes a peer may later send alone (dispose/unregister without payload,
            // e.g. Fast DDS): the one it sent, else the ones we compute for either representation.
            let hashes = match s.key_hash {
                Some(kh) => [Some(kh), None],
                None => [
                    cdr::key_hash(&d, cdr::XcdrVersion::Xcdr1).ok(),
                    cdr::key_hash(&d, cdr::XcdrVersion::Xcdr2).ok(),
                ],
            };
            for kh in hashes.into_iter().flatten() {
                if by_hash.len() >= MAX_REMEMBERED_HASHES {
                    by_hash.clear();
                }
                by_hash.entry(kh).or_insert_with(|| key.clone());
            }
        }
        data = Some(d);
    } else if T::IS_KEYED {
        if !s.payload.is_empty() {
            match cdr::deserialize_key::<T>(&s.payload) {
                Ok(k) => {
                    if let Err(e) = cdr::instance_key(&k, &mut key) {
                        tracing::warn!(error = %e, "cannot compute the instance key");
                        return None;
                    }
                    key_holder = Some(k);
                }
                Err(e) => {
                    tracing::debug!(error = %e, "undecodable key payload; trying the key hash")
                }
            }
        }
        if key_holder.is_none() {
            match s.key_hash.and_then(|kh| by_hash.get(&kh).cloned()) {
                Some(k) => key = k,
                None => {
                    tracing::debug!(writer = ?s.writer, kind = ?s.kind, "key-only change for an unknown instance");
                    return None;
                }
            }
        }
    }
    Some(Incoming {
        writer: s.writer.to_bytes(),
        kind,
        data,
        key,
        key_holder,
        source_timestamp: source_timestamp.unwrap_or(rx_time),
        reception_timestamp: rx_time,
        strength: info.strength,
        expires: info.lifespan.and_then(|l| {
            // Lifespan counts from the source timestamp; its age so far is spent already.
            let age = source_timestamp
                .and_then(|t| rx_time.duration_since(t).ok())
                .unwrap_or_default();
            now.checked_add(l.saturating_sub(age))
        }),
    })
}

impl<T: DdsType> ReaderSink for ReaderInner<T> {
    fn enqueue(&self, item: Pending) {
        lock(&self.pending).push_back(item);
    }

    fn process(self: Arc<Self>) {
        let now = Instant::now();
        let rx_time = SystemTime::now();
        let mut any = false;
        let mut rejected = Vec::new();
        {
            let mut guard = lock(&self.cache);
            let st = &mut *guard;
            // Taking the queue under the cache lock keeps the core's order even with several receive threads.
            let mut batch = std::mem::take(&mut st.batch);
            std::mem::swap(&mut batch, &mut *lock(&self.pending));
            // Consecutive samples mostly come from one writer: look its QoS up once per run.
            let mut writer_info: Option<(Guid, RemoteWriterInfo)> = None;
            for item in batch.drain(..) {
                match item {
                    Pending::Sample(s) => {
                        let info = match writer_info {
                            Some((g, info)) if g == s.writer => info,
                            _ => {
                                let info = self.shared.remote_writer(&s.writer);
                                writer_info = Some((s.writer, info));
                                info
                            }
                        };
                        let key = st.cache.take_key_buffer();
                        let Some(inc) =
                            decode_change::<T>(s, info, &mut st.by_hash, key, now, rx_time)
                        else {
                            continue;
                        };
                        match st.cache.insert(inc, now) {
                            Outcome::Accepted { .. } => any = true,
                            Outcome::Filtered => {}
                            Outcome::Rejected { reason, handle } => rejected.push((reason, handle)),
                        }
                    }
                    Pending::WriterGone(g) => any |= st.cache.writer_gone(g.to_bytes(), now),
                }
            }
            st.batch = batch;
        }
        if !rejected.is_empty() {
            let status = {
                let mut st = lock(&self.statuses);
                for (reason, handle) in &rejected {
                    let sr = &mut st.sample_rejected;
                    sr.total_count += 1;
                    sr.total_count_change += 1;
                    sr.last_reason = *reason;
                    sr.last_instance_handle = *handle;
                }
                st.sample_rejected.clone()
            };
            tracing::debug!(
                count = rejected.len(),
                "samples rejected by resource limits"
            );
            self.status_core.raise(StatusMask::SAMPLE_REJECTED);
            let listener = lock(&self.listener).clone();
            if let (Some(l), Some(r)) = (listener, self.reader_handle()) {
                l.on_sample_rejected(&r, status);
            }
        }
        if any {
            self.notify_data();
        }
    }

    fn on_event(self: Arc<Self>, ev: &Event) {
        let listener = lock(&self.listener).clone();
        let me = self.reader_handle();
        match ev {
            Event::SubscriptionMatched {
                writer, matched, ..
            } => {
                let status = {
                    let mut m = lock(&self.matched);
                    let mut st = lock(&self.statuses);
                    let sm = &mut st.subscription_matched;
                    if *matched {
                        if !m.contains(writer) {
                            m.push(*writer);
                            sm.total_count += 1;
                            sm.total_count_change += 1;
                            sm.current_count_change += 1;
                        }
                    } else if let Some(p) = m.iter().position(|g| g == writer) {
                        m.remove(p);
                        sm.current_count_change -= 1;
                    }
                    sm.current_count = m.len() as u32;
                    sm.last_publication_handle =
                        InstanceHandle::from_guid_bytes(&writer.to_bytes());
                    let out = sm.clone();
                    // A listener consumes the status (DDS 2.2.4.2.1): reset the changes so the next
                    // callback reports only what happened since this one.
                    if listener.is_some() && me.is_some() {
                        sm.total_count_change = 0;
                        sm.current_count_change = 0;
                    }
                    out
                };
                tracing::info!(reader = ?lock(&self.id), ?writer, matched, "subscription matched");
                self.status_core.raise(StatusMask::SUBSCRIPTION_MATCHED);
                if let (Some(l), Some(r)) = (listener, me) {
                    l.on_subscription_matched(&r, status);
                }
            }
            Event::RequestedIncompatibleQos { policy, writer, .. } => {
                let status = {
                    let mut st = lock(&self.statuses);
                    st.requested_incompatible_qos.record(*policy);
                    st.requested_incompatible_qos.clone()
                };
                tracing::warn!(reader = ?lock(&self.id), ?writer, ?policy, "requested incompatible QoS");
                self.status_core
                    .raise(StatusMask::REQUESTED_INCOMPATIBLE_QOS);
                if let (Some(l), Some(r)) = (listener, me) {
                    l.on_requested_incompatible_qos(&r, status);
                }
            }
            Event::LivelinessChanged { writer, alive, .. } => {
                let status = {
                    let mut st = lock(&self.statuses);
                    let lc = &mut st.liveliness_changed;
                    if *alive {
                        lc.alive_count += 1;
                        lc.alive_count_change += 1;
                        if lc.not_alive_count > 0 {
                            lc.not_alive_count -= 1;
                            lc.not_alive_count_change -= 1;
                        }
                    } else {
                        lc.not_alive_count += 1;
                        lc.not_alive_count_change += 1;
                        if lc.alive_count > 0 {
                            lc.alive_count -= 1;
                            lc.alive_count_change -= 1;
                        }
                    }
                    lc.last_publication_handle =
                        InstanceHandle::from_guid_bytes(&writer.to_bytes());
                    lc.clone()
                };
                if !*alive {
                    let changed = lock(&self.cache)
                        .cache
                        .writer_gone(writer.to_bytes(), Instant::now());
                    if changed {
                        self.notify_data();
                    }
                }
                self.status_core.raise(StatusMask::LIVELINESS_CHANGED);
                if let (Some(l), Some(r)) = (listener, me) {
                    l.on_liveliness_changed(&r, status);
                }
            }
            Event::SampleLost { count, .. } => {
                let status = {
                    let mut st = lock(&self.statuses);
                    let n = u32::try_from(*count).unwrap_or(u32::MAX);
                    st.sample_lost.total_count = st.sample_lost.total_count.saturating_add(n);
                    st.sample_lost.total_count_change =
                        st.sample_lost.total_count_change.saturating_add(n);
                    st.sample_lost.clone()
                };
                self.status_core.raise(StatusMask::SAMPLE_LOST);
                if let (Some(l), Some(r)) = (listener, me) {
                    l.on_sample_lost(&r, status);
                }
            }
            _ => {}
        }
    }

    fn tick(self: Arc<Self>, now: Instant) {
        let missed = lock(&self.cache).cache.tick(now);
        if missed.is_empty() {
            return;
        }
        let status = {
            let mut st = lock(&self.statuses);
            let dm = &mut st.requested_deadline_missed;
            dm.total_count += missed.len() as u32;
            dm.total_count_change += missed.len() as u32;
            dm.last_instance_handle = *missed.last().unwrap_or(&InstanceHandle::NIL);
            dm.clone()
        };
        self.status_core
            .raise(StatusMask::REQUESTED_DEADLINE_MISSED);
        let listener = lock(&self.listener).clone();
        if let (Some(l), Some(r)) = (listener, self.reader_handle()) {
            l.on_requested_deadline_missed(&r, status);
        }
    }
}

impl<T: DdsType> ReadConditionSource for ReaderInner<T> {
    fn has_matching(&self, s: SampleStateMask, v: ViewStateMask, i: InstanceStateMask) -> bool {
        let sel = Selection {
            sample_states: s,
            view_states: v,
            instance_states: i,
            ..Selection::default()
        };
        lock(&self.cache).cache.has_matching(&sel)
    }
    fn data_signal(&self) -> &Signal {
        &self.data_signal
    }
}

/// The stream returned by [`DataReader::stream`].
pub struct SampleStream<T: DdsType> {
    reader: DataReader<T>,
}

impl<T: DdsType> SampleStream<T> {
    /// The reader this stream takes from.
    pub fn reader(&self) -> &DataReader<T> {
        &self.reader
    }
}

impl<T: DdsType> futures_core::Stream for SampleStream<T> {
    type Item = Sample<T>;

    fn poll_next(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Option<Self::Item>> {
        let r = &self.reader;
        let take = || r.take_next_sample().ok().flatten();
        if let Some(s) = take() {
            return Poll::Ready(Some(s));
        }
        if r.inner.shared.check_alive().is_err() {
            return Poll::Ready(None);
        }
        {
            let mut w = lock(&r.inner.wakers);
            if !w.iter().any(|x| x.will_wake(cx.waker())) {
                w.push(cx.waker().clone());
            }
        }
        // A sample may have arrived between the first check and the registration.
        match take() {
            Some(s) => Poll::Ready(Some(s)),
            None => Poll::Pending,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cdr::{ByteOrder, XcdrVersion};
    use crate::rtps::{GuidPrefix, Payload, SequenceNumber};

    #[derive(dds_macros::DdsType, Debug, Clone, PartialEq, Default)]
    #[dds(name = "test::K", appendable)]
    struct K {
        #[dds(key)]
        id: String,
        v: i32,
    }

    fn rs(kind: ChangeKind, payload: Vec<u8>, key_hash: Option<[u8; 16]>) -> ReceivedSample {
        ReceivedSample {
            reader: EntityId([0, 0, 1, 7]),
            writer: Guid::new(GuidPrefix([1; 12]), EntityId([0, 0, 1, 2])),
            sequence: SequenceNumber(1),
            kind,
            payload: Payload::from(payload),
            key_hash,
            source_timestamp: None,
        }
    }

    /// `decode_change` from a writer with default QoS, now.
    fn decode(s: ReceivedSample, by_hash: &mut HashMap<[u8; 16], Vec<u8>>) -> Option<Incoming<K>> {
        let now = Instant::now();
        decode_change::<K>(
            s,
            RemoteWriterInfo::default(),
            by_hash,
            Vec::new(),
            now,
            SystemTime::now(),
        )
    }

    #[test]
    fn key_only_changes_map_by_key_payload_or_known_hash() {
        let mut by_hash = HashMap::new();
        let s = K {
            id: "a".into(),
            v: 1,
        };
        let mut buf = Vec::new();
        cdr::serialize(&s, XcdrVersion::Xcdr2, ByteOrder::NATIVE, &mut buf).unwrap();
        let kh = cdr::key_hash(&s, XcdrVersion::Xcdr2).unwrap();
        let alive = decode(rs(ChangeKind::Alive, buf, Some(kh)), &mut by_hash).unwrap();
        assert_eq!(alive.data.as_ref(), Some(&s));
        let mut expected = Vec::new();
        cdr::instance_key(&s, &mut expected).unwrap();
        assert_eq!(alive.key, expected);

        let mut kp = Vec::new();
        cdr::serialize_key(&s, XcdrVersion::Xcdr2, ByteOrder::NATIVE, &mut kp).unwrap();
        let d = decode(rs(ChangeKind::Dispose, kp, None), &mut by_hash).unwrap();
        assert_eq!(d.key, expected, "by key payload");
        assert_eq!(d.kind, ChangeKindLocal::Dispose);

        let u = decode(
            rs(ChangeKind::Unregister, Vec::new(), Some(kh)),
            &mut by_hash,
        )
        .unwrap();
        assert_eq!(u.key, expected, "by a key hash seen before");

        let unknown = rs(ChangeKind::Dispose, Vec::new(), Some([9; 16]));
        assert!(decode(unknown, &mut by_hash).is_none());
        let garbage = rs(
            ChangeKind::Alive,
            vec![0, 7, 0, 0, 0xff, 0xff, 0xff, 0x7f],
            None,
        );
        assert!(decode(garbage, &mut by_hash).is_none());
    }

    /// Fast DDS disposes with only PID_KEY_HASH; the alive samples before may have come without one.
    #[test]
    fn key_hash_only_dispose_maps_to_instance_seen_without_hash() {
        let s = K {
            id: "a-rather-long-key-beyond-16-bytes".into(),
            v: 1,
        };
        let mut expected = Vec::new();
        cdr::instance_key(&s, &mut expected).unwrap();
        for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
            let mut by_hash = HashMap::new();
            let mut buf = Vec::new();
            cdr::serialize(&s, version, ByteOrder::NATIVE, &mut buf).unwrap();
            decode(rs(ChangeKind::Alive, buf, None), &mut by_hash).unwrap();
            let kh = cdr::key_hash(&s, version).unwrap();
            let d = decode(rs(ChangeKind::Dispose, Vec::new(), Some(kh)), &mut by_hash)
                .expect("dispose mapped through the computed key hash");
            assert_eq!(d.key, expected);
            assert_eq!(d.kind, ChangeKindLocal::Dispose);
        }
    }
}
