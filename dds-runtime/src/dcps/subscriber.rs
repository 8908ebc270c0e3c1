//! `Subscriber` and `DataReader<T>`.

mod builtin;
mod kind;
mod ops;

use std::collections::VecDeque;
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering as AtomicOrdering};
use std::sync::{Arc, Condvar, Mutex};
use std::task::{Context, Poll, Waker};
use std::time::{Duration, Instant, SystemTime};

use crate::cdr::{self, DdsType};
use crate::qos::{DataReaderQos, DataRepresentation, ReaderQos, SubscriberQos};
use crate::rtps::{Event, Guid, ReaderSpec, ReceivedSample};

use super::cache::SharedFilter;
use super::cache::{to_sample, Outcome, ReaderCache, Selection};
use super::condition::{
    QueryCondition, ReadCondition, ReadConditionSource, Signal, StatusCondition,
};
use super::decode::{decode_change_with, Decoding};
use super::driver::{Endpoint, EndpointHandle, Pending, RemoteWriterInfo};
use super::endpoint::{check_history, EndpointState};
use super::error::{DdsError, DdsResult};
use super::participant::DomainParticipant;
use super::presentation::{
    group_ordered, group_scoped, instance_ordered, AccessMember, AccessScope,
};
use super::sample::{
    InstanceHandle, InstanceStateMask, Sample, SampleInfo, SampleStateMask, ViewStateMask,
};
use super::status::{
    DeadlineMissedStatus, IncompatibleQosStatus, LivelinessChangedStatus, ReaderStatuses,
    SampleLostStatus, SampleRejectedStatus, StatusMask, SubscriptionMatchedStatus,
};
use super::sync::{lock, recover};
use super::topic::{Topic, TopicDescription};
use crate::filter::ContentFilter;

pub(crate) use builtin::{BuiltinGroup, BuiltinReader, UserReaderSpec};
pub(crate) use kind::{reader_callbacks, KeyHolderFn, ReaderCallbacks, ReaderKind, Typed};
pub use ops::SubscriberListener;

/// Callbacks of a [`DataReader`] (see [`crate::dcps::listener`]). Every method has an empty default.
#[allow(unused_variables)]
pub trait DataReaderListener<T: DdsType>: Send + Sync {
    /// New samples (or instance state changes) are available.
    fn on_data_available(&self, reader: &DataReader<T>) {}
    /// A writer matched or unmatched.
    fn on_subscription_matched(&self, reader: &DataReader<T>, status: SubscriptionMatchedStatus) {}
    /// A writer was found with incompatible QoS.
    fn on_requested_incompatible_qos(&self, reader: &DataReader<T>, status: IncompatibleQosStatus) {
    }
    /// Samples were lost.
    fn on_sample_lost(&self, reader: &DataReader<T>, status: SampleLostStatus) {}
    /// A sample was rejected by a resource limit.
    fn on_sample_rejected(&self, reader: &DataReader<T>, status: SampleRejectedStatus) {}
    /// A matched writer's liveliness changed.
    fn on_liveliness_changed(&self, reader: &DataReader<T>, status: LivelinessChangedStatus) {}
    /// An instance missed its deadline.
    fn on_requested_deadline_missed(&self, reader: &DataReader<T>, status: DeadlineMissedStatus) {}
}

/// Groups readers; carries the partition and presentation QoS.
#[derive(Clone)]
pub struct Subscriber {
    participant: DomainParticipant,
    qos: Arc<SubscriberQos>,
    access: Arc<AccessScope>,
}

impl std::fmt::Debug for Subscriber {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Subscriber")
            .field("qos", &self.qos)
            .finish()
    }
}

impl DomainParticipant {
    /// Creates a subscriber.
    pub fn create_subscriber(&self, qos: &SubscriberQos) -> DdsResult<Subscriber> {
        self.driver().check_alive()?;
        let s = Subscriber {
            participant: self.clone(),
            qos: Arc::new(qos.clone()),
            access: Arc::default(),
        };
        ops::register_subscriber(&s);
        Ok(s)
    }
}

impl Subscriber {
    /// The subscriber QoS.
    pub fn qos(&self) -> &SubscriberQos {
        &self.qos
    }

    /// The participant.
    pub fn participant(&self) -> &DomainParticipant {
        &self.participant
    }

    /// Starts an access scope (DDS 1.4 §2.2.2.5.2.8) for reading coherent or ordered data across this
    /// subscriber's readers. Calls nest. Coherent sets become visible only whole (each writer's part of a
    /// set is stored at once), so reads inside and outside a scope never see part of a set.
    ///
    /// With GROUP access scope (coherent or ordered), the readers store what arrives all at once, and
    /// not at all while a scope is open: between `begin_access` and `end_access` their contents do not
    /// change, and a group set spanning several readers is in all of them or in none. What arrived
    /// meanwhile is stored by the outermost `end_access` (or, past 65 536 held changes, anyway).
    pub fn begin_access(&self) -> DdsResult<()> {
        self.participant.driver().check_alive()?;
        self.access.begin();
        Ok(())
    }

    /// Ends the access scope started by [`Subscriber::begin_access`]; `PreconditionNotMet` without one.
    pub fn end_access(&self) -> DdsResult<()> {
        self.access.end(self.participant.driver())
    }

    /// Whether an access scope is open.
    pub fn in_access(&self) -> bool {
        self.access.is_open()
    }

    /// Creates a reader on a topic or content-filtered topic. An empty `data_representation` accepts XCDR1
    /// and XCDR2.
    pub fn create_datareader<T: DdsType, D: TopicDescription<T>>(
        &self,
        topic: &D,
        qos: &DataReaderQos,
    ) -> DdsResult<DataReader<T>> {
        self.create_reader(topic, qos, None)
    }

    /// Creates a reader with its listener installed first, enabled for the statuses in `mask`
    /// (`create_datareader` with a listener, DDS 1.4 §2.2.2.5.2.5): the listener gets every status of the
    /// reader from its creation on, including the matches with writers already known and the history a
    /// TRANSIENT_LOCAL writer of the same participant hands over at once.
    pub fn create_datareader_with_listener<T: DdsType, D: TopicDescription<T>>(
        &self,
        topic: &D,
        qos: &DataReaderQos,
        listener: Box<dyn DataReaderListener<T>>,
        mask: StatusMask,
    ) -> DdsResult<DataReader<T>> {
        self.create_reader(topic, qos, Some((Arc::from(listener), mask)))
    }

    fn create_reader<T: DdsType, D: TopicDescription<T>>(
        &self,
        topic: &D,
        qos: &DataReaderQos,
        listener: Option<(Arc<dyn DataReaderListener<T>>, StatusMask)>,
    ) -> DdsResult<DataReader<T>> {
        if let Some(r) = builtin::user_builtin_reader(self, topic.topic(), qos, listener.clone())? {
            return Ok(r);
        }
        let parent = ops::reader_parent(self, topic.topic())?;
        let enabled = self
            .participant
            .registry()
            .group_creates_enabled::<SubscriberQos>(Arc::as_ptr(&self.qos) as *const ())?;
        // The QoS in effect: a disabled subscriber may have changed any policy since its creation.
        let group_qos = self.get_qos()?;
        let mut rq = qos.clone();
        if rq.data_representation.ids().is_empty() {
            rq.data_representation = DataRepresentation::accept_both();
        }
        check_history(&rq.history)?;
        let t = topic.topic();
        let spec = ReaderSpec {
            topic_name: t.name().to_string(),
            type_name: T::TYPE_NAME.to_string(),
            keyed: T::IS_KEYED,
            qos: ReaderQos::new(rq.clone(), &group_qos, &t.get_qos()?),
            type_information: crate::xtypes::announced_type_information_for(
                T::type_information(),
                T::type_mapping(),
            ),
            entity_name: None,
            content_filter: topic.content_filter_property(),
            internal: false,
        };
        let credit_limit = credit_limit(&rq);
        let mut cache = ReaderCache::new(rq.clone(), T::IS_KEYED);
        cache.set_filter(topic.sample_filter());
        let inner = self.reader_inner::<Typed<T>>(
            super::decode::Derived,
            cache,
            &group_qos.presentation,
            credit_limit,
            parent,
        );
        let owner = ReaderOwner {
            topic: t.clone(),
            subscriber: self.clone(),
        };
        let sink: Arc<dyn Endpoint> = inner.clone();
        if !enabled {
            inner.state.set_created_disabled();
        }
        if let Some((l, mask)) = listener {
            inner.state.set_listener_with_mask(Some(l), mask);
        }
        let handle = inner.state.create(sink, owner, |c, now| {
            super::participant::register_local_types::<T>(c);
            let id = if enabled {
                c.create_reader(now, spec)?
            } else {
                c.create_reader_disabled(now, spec)?
            };
            if credit_limit.is_some() {
                c.set_reader_credit(id, credit_limit);
            }
            Ok(id)
        })?;
        self.reader_created(&inner, t.name());
        let id = handle.id();
        topic.reader_created(id);
        tracing::info!(
            topic = t.name(),
            type_name = T::TYPE_NAME,
            ?id,
            "reader created"
        );
        Ok(DataReader { inner, handle })
    }
}

impl Subscriber {
    /// The state of a new reader of this subscriber, of any kind, under the subscriber's level `parent` of
    /// the listener chain: `presentation` (the subscriber's) orders its cache by instance and gives it its
    /// place in the subscriber's order (GROUP ordered access) and access scope (GROUP coherent access).
    pub(crate) fn reader_inner<K: ReaderKind>(
        &self,
        codec: K::Codec,
        mut cache: ReaderCache<K::Data>,
        presentation: &crate::qos::Presentation,
        credit_limit: Option<usize>,
        parent: Arc<super::chain::ListenerNode>,
    ) -> Arc<ReaderInner<K>> {
        cache.set_instance_order(instance_ordered(presentation));
        let inner = Arc::new(ReaderInner::<K>::new(
            codec,
            self.participant.driver().clone(),
            cache,
            group_ordered(presentation).then(|| self.access.order()),
            group_scoped(presentation).then(|| self.access.clone()),
            credit_limit,
        ));
        inner.state.set_parent(parent);
        inner
    }

    /// Whether `other` is this subscriber (a clone of it).
    pub(crate) fn is(&self, other: &Subscriber) -> bool {
        Arc::ptr_eq(&self.qos, &other.qos)
    }

    /// A reader of any kind was created in the core: it joins the subscriber's access scope (GROUP access)
    /// and the participant's registry (`get_datareaders`, `notify_datareaders`, deletion).
    pub(crate) fn reader_created<K: ReaderKind>(&self, inner: &Arc<ReaderInner<K>>, topic: &str) {
        if inner.access.is_some() {
            let member: Arc<dyn AccessMember> = inner.clone();
            self.access.join(Arc::downgrade(&member));
        }
        ops::register_reader(self, inner, topic);
    }
}

/// `ReaderInner::credit_limit` when the reader has none.
const NO_CREDIT_LIMIT: usize = usize::MAX;

/// The credit a reader gives the core: reliable KEEP_ALL with `max_samples` delivers (and acknowledges)
/// only what fits in the cache.
pub(crate) fn credit_limit(q: &DataReaderQos) -> Option<usize> {
    match (&q.reliability, &q.history, q.resource_limits.max_samples) {
        (crate::qos::Reliability::Reliable { .. }, crate::qos::History::KeepAll, Some(m)) => {
            Some(m as usize)
        }
        _ => None,
    }
}

pub(crate) struct CacheState<T> {
    pub(crate) cache: ReaderCache<T>,
    /// What decoding keeps between changes: key hashes, values given back to decode into.
    decoding: Decoding<T>,
    /// The queue being processed, swapped with `pending` (one lock round per batch, buffers reused).
    batch: VecDeque<(u64, Pending)>,
    /// The QoS of the writer of the last change stored, as [`super::driver::Driver::remote_writer_via`] remembers it.
    writer_info: Option<(u64, Guid, RemoteWriterInfo)>,
}

/// One pass of `process` over a reader's queue.
struct Pass {
    now: Instant,
    rx_time: SystemTime,
    stored: Stored,
}

/// What storing a reader's queue did, for the statuses it raises.
#[derive(Default)]
struct Stored {
    /// Something was stored or changed state.
    any: bool,
    rejected: Vec<(super::status::SampleRejectedReason, InstanceHandle)>,
}

/// What a typed reader's handle keeps alive.
pub(crate) struct ReaderOwner<T> {
    topic: Topic<T>,
    subscriber: Subscriber,
}

/// A reader's state behind its public handle, typed or dynamic ([`ReaderKind`]).
pub(crate) struct ReaderInner<K: ReaderKind> {
    /// Decodes the samples.
    codec: K::Codec,
    pub(crate) state: EndpointState<ReaderStatuses, K::Listener, K::Owner>,
    /// Queued changes, each with its place in the subscriber's order (GROUP ordered access; else 0).
    pending: Mutex<VecDeque<(u64, Pending)>>,
    /// GROUP ordered access: the subscriber's counter, which places each change as the core delivers it.
    group_order: Option<Arc<AtomicU64>>,
    /// GROUP access scope: the subscriber's scope, which stores the queues of all its readers at once.
    access: Option<Arc<AccessScope>>,
    /// What the access scope set aside from `pending` (see [`AccessMember`]).
    staged: Mutex<VecDeque<(u64, Pending)>>,
    /// What the access scope stored, for `announce`.
    committed: Mutex<Stored>,
    pub(crate) cache: Mutex<CacheState<K::Data>>,
    data_cv: Condvar,
    /// Threads in `wait_for_data`; registered under the cache lock so that `notify_data` (called after the
    /// change was made under that lock) skips the futex wake only when nobody can be sleeping.
    data_waiters: AtomicUsize,
    wakers: Mutex<Vec<Waker>>,
    /// Set (for good) when a `SampleStream` first registers a waker, before its second take: `notify_data`
    /// (after the change, made under the cache lock) skips the wakers' lock while it is clear, as with
    /// `data_waiters`.
    has_wakers: AtomicBool,
    data_signal: Signal,
    /// Reliable KEEP_ALL with max_samples: the core delivers (and acknowledges) only what fits
    /// ([`NO_CREDIT_LIMIT`] otherwise). Changes only while the reader is disabled.
    credit_limit: AtomicUsize,
}

/// Reads samples of type `T`. Cheap to clone; the reader is deleted when the last clone (and the last
/// stream) is dropped.
///
/// Reader-side QoS enforced here: history (KEEP_LAST depth per instance, KEEP_ALL), resource limits
/// (max_samples, max_instances, max_samples_per_instance), exclusive ownership (strongest writer, ties to
/// the lowest GUID), time-based filter (per instance, no delayed delivery of the last filtered sample),
/// reader data lifecycle (both autopurge delays), lifespan (from the writer's announced lifespan, counted
/// from the source timestamp), requested deadline missed (checked every 50 ms),
/// destination order by source timestamp (a change older than the instance's newest is dropped).
/// Coherent sets are stored whole or not at all; ordered access with INSTANCE scope groups reads by
/// instance; with GROUP scope the subscriber's readers share one order (see `Subscriber::get_datareaders`).
pub struct DataReader<T: DdsType> {
    inner: Arc<ReaderInner<Typed<T>>>,
    handle: Arc<EndpointHandle<ReaderOwner<T>>>,
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
            .field("topic", &self.handle.owner().topic.name())
            .field("id", &self.handle.id())
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
    /// Takes the selected samples, appending them to `out`; returns how many. A vector the caller keeps
    /// and clears between calls makes the take allocate nothing once it has grown to the usual batch.
    pub fn take_into(self, out: &mut Vec<Sample<T>>) -> DdsResult<usize> {
        self.reader
            .visit(self.sel, self.next_after, true, |slot, info| {
                out.push(to_sample(slot, info, true, None))
            })
    }
    /// Zero-copy read (a loan in callback form): calls `f` with a reference to each selected sample in the
    /// cache, marks them read and returns how many there were. The cache lock is held during the calls:
    /// keep `f` short and do not call back into this reader from it.
    pub fn read_with(self, mut f: impl FnMut(Option<&T>, &SampleInfo)) -> DdsResult<usize> {
        self.reader
            .visit(self.sel, self.next_after, false, |slot, info| {
                f(slot.as_ref(), &info)
            })
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
    /// See [`ReaderInner::visit`].
    fn visit(
        &self,
        sel: Selection,
        next_after: Option<InstanceHandle>,
        take: bool,
        emit: impl FnMut(&mut Option<T>, SampleInfo),
    ) -> DdsResult<usize> {
        self.inner.visit(sel, next_after, take, emit)
    }

    /// Zero-copy read of all samples, see [`Selector::read_with`].
    pub fn read_with(&self, f: impl FnMut(Option<&T>, &SampleInfo)) -> DdsResult<usize> {
        self.select().read_with(f)
    }

    /// Read or take into samples; a read copies the data with `copy`.
    fn collect(
        &self,
        sel: Selection,
        next_after: Option<InstanceHandle>,
        take: bool,
        copy: Option<fn(&T) -> T>,
    ) -> DdsResult<Vec<Sample<T>>> {
        let mut out = Vec::new();
        self.visit(sel, next_after, take, |slot, info| {
            out.push(to_sample(slot, info, take, copy))
        })?;
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

    /// Takes all samples out of the cache, appending them to `out` (see [`Selector::take_into`]); returns
    /// how many.
    ///
    /// ```no_run
    /// # use dds_runtime::prelude::*;
    /// # fn f<T: DdsType>(reader: &DataReader<T>) -> dds_runtime::dcps::DdsResult<()> {
    /// let mut batch = Vec::new();
    /// loop {
    ///     batch.clear();
    ///     reader.take_into(&mut batch)?;
    ///     for s in &batch { /* ... */ }
    /// #   break;
    /// }
    /// # Ok(())
    /// # }
    /// ```
    pub fn take_into(&self, out: &mut Vec<Sample<T>>) -> DdsResult<usize> {
        self.select().take_into(out)
    }

    /// Gives taken samples back to the reader, which decodes later samples into their values: strings and
    /// sequences keep their buffers, so a loop of [`take_into`](Self::take_into) and `recycle` over large
    /// samples allocates nothing per sample, and a multi-megabyte sample is decoded into memory already
    /// mapped. The reader keeps up to 1024 values (the rest are dropped, as are samples without data) until
    /// it decodes into them or is deleted: give back only as many as the memory they hold is worth keeping
    /// (`reader.recycle(batch.drain(..).take(n))`). Samples of another reader of the same type serve as well.
    ///
    /// ```no_run
    /// # use dds_runtime::prelude::*;
    /// # fn f<T: DdsType>(reader: &DataReader<T>) -> dds_runtime::dcps::DdsResult<()> {
    /// let mut batch = Vec::new();
    /// loop {
    ///     reader.take_into(&mut batch)?;
    ///     for s in &batch { /* ... */ }
    ///     reader.recycle(batch.drain(..));
    /// #   break;
    /// }
    /// # Ok(())
    /// # }
    /// ```
    pub fn recycle(&self, samples: impl IntoIterator<Item = Sample<T>>) {
        let mut rest = samples.into_iter();
        let mut held = Vec::new();
        {
            let mut st = lock(&self.inner.cache);
            while st.decoding.has_room() {
                let Some(s) = rest.next() else { break };
                match s.data {
                    Some(v) if !v.holds_received_buffer() => st.decoding.keep(v),
                    // Read in place: its buffer goes back to the sender, outside the lock.
                    Some(v) => held.push(v),
                    None => {}
                }
            }
        }
        // What is not kept is dropped outside the lock.
        drop(held);
        drop(rest);
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

    /// Reads with a read condition's masks (and a [`QueryCondition`]'s query and ORDER BY).
    pub fn read_w_condition(&self, c: &ReadCondition) -> DdsResult<Vec<Sample<T>>>
    where
        T: Clone,
    {
        self.select_w_condition(c).read()
    }

    /// Takes with a read condition's masks (and a [`QueryCondition`]'s query and ORDER BY).
    pub fn take_w_condition(&self, c: &ReadCondition) -> DdsResult<Vec<Sample<T>>> {
        self.select_w_condition(c).take()
    }

    fn select_w_condition(&self, c: &ReadCondition) -> Selector<'_, T> {
        let mut s = self
            .select()
            .sample_state(c.sample_states)
            .view_state(c.view_states)
            .instance_state(c.instance_states);
        s.sel.query = c.query.clone();
        s
    }

    /// The handle of the instance whose key equals the key of `key_sample` (other members are ignored);
    /// `None` when the reader holds no such instance.
    pub fn lookup_instance(&self, key_sample: &T) -> DdsResult<Option<InstanceHandle>> {
        let mut key = Vec::new();
        if T::IS_KEYED {
            cdr::instance_key(key_sample, &mut key)?;
        }
        Ok(lock(&self.inner.cache).cache.lookup(&key))
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
        self.inner.wait_for_data(timeout)
    }

    /// Blocks until every matched reliable writer's announced data (the history of TRANSIENT_LOCAL writers
    /// and of durability services' stand-ins included) has arrived (`Ok(true)`), or `timeout` passes
    /// (`Ok(false)`). Returns at once when no writer is matched yet. See docs/durability.md.
    pub fn wait_for_historical_data(&self, timeout: Duration) -> DdsResult<bool> {
        super::durability::wait_for_historical_data(
            &self.inner.state.driver,
            self.handle.id(),
            timeout,
        )
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
        ReadCondition::on(
            self.inner.clone(),
            sample_states,
            view_states,
            instance_states,
        )
    }

    /// A query condition on this reader: a read condition whose samples must also satisfy `expression` (the
    /// Annex B subset, optionally ending in `ORDER BY`), with `%n` bound to `params[n]`.
    pub fn create_querycondition<S: AsRef<str>>(
        &self,
        sample_states: SampleStateMask,
        view_states: ViewStateMask,
        instance_states: InstanceStateMask,
        expression: &str,
        params: &[S],
    ) -> DdsResult<QueryCondition> {
        let query = ContentFilter::query(expression, params)?;
        let read = self.create_readcondition(sample_states, view_states, instance_states);
        Ok(QueryCondition::new(read, query))
    }

    /// The reader's status condition.
    pub fn status_condition(&self) -> StatusCondition {
        StatusCondition {
            core: self.inner.state.status_core().clone(),
        }
    }

    /// Installs a listener (replacing any previous one).
    pub fn set_listener(&self, listener: Box<dyn DataReaderListener<T>>) {
        self.inner.state.set_listener(Some(Arc::from(listener)));
    }

    /// Removes the listener.
    pub fn clear_listener(&self) {
        self.inner.state.set_listener(None);
    }

    /// The topic.
    pub fn topic(&self) -> &Topic<T> {
        &self.handle.owner().topic
    }

    /// The subscriber.
    pub fn subscriber(&self) -> &Subscriber {
        &self.handle.owner().subscriber
    }

    /// The reader's GUID.
    pub fn guid(&self) -> Guid {
        self.handle.guid()
    }

    /// The reader's handle (as writers see it in their matched subscriptions).
    pub fn instance_handle(&self) -> InstanceHandle {
        InstanceHandle::from_guid(self.guid())
    }

    /// Handles of the matched writers.
    pub fn matched_publications(&self) -> Vec<InstanceHandle> {
        self.inner
            .state
            .matched()
            .into_iter()
            .map(InstanceHandle::from_guid)
            .collect()
    }

    /// GUIDs of the matched writers.
    pub fn matched_publication_guids(&self) -> Vec<Guid> {
        self.inner.state.matched()
    }

    /// SUBSCRIPTION_MATCHED (resets the change counts).
    pub fn subscription_matched_status(&self) -> SubscriptionMatchedStatus {
        self.inner.subscription_matched_status()
    }

    /// REQUESTED_INCOMPATIBLE_QOS (resets the change count).
    pub fn requested_incompatible_qos_status(&self) -> IncompatibleQosStatus {
        self.inner.requested_incompatible_qos_status()
    }

    /// SAMPLE_LOST (resets the change count).
    pub fn sample_lost_status(&self) -> SampleLostStatus {
        self.inner.sample_lost_status()
    }

    /// SAMPLE_REJECTED (resets the change count).
    pub fn sample_rejected_status(&self) -> SampleRejectedStatus {
        self.inner.sample_rejected_status()
    }

    /// LIVELINESS_CHANGED (resets the change counts).
    pub fn liveliness_changed_status(&self) -> LivelinessChangedStatus {
        self.inner.liveliness_changed_status()
    }

    /// REQUESTED_DEADLINE_MISSED (resets the change count).
    pub fn requested_deadline_missed_status(&self) -> DeadlineMissedStatus {
        self.inner.requested_deadline_missed_status()
    }
}

impl<K: ReaderKind> ReaderInner<K> {
    // The reader's statuses, read by the application (each resets its change counts), for both kinds.
    pub(crate) fn subscription_matched_status(&self) -> SubscriptionMatchedStatus {
        self.state
            .take_status(StatusMask::SUBSCRIPTION_MATCHED, |s| {
                &mut s.subscription_matched
            })
    }

    pub(crate) fn requested_incompatible_qos_status(&self) -> IncompatibleQosStatus {
        self.state
            .take_status(StatusMask::REQUESTED_INCOMPATIBLE_QOS, |s| {
                &mut s.requested_incompatible_qos
            })
    }

    pub(crate) fn sample_lost_status(&self) -> SampleLostStatus {
        self.state
            .take_status(StatusMask::SAMPLE_LOST, |s| &mut s.sample_lost)
    }

    pub(crate) fn sample_rejected_status(&self) -> SampleRejectedStatus {
        self.state
            .take_status(StatusMask::SAMPLE_REJECTED, |s| &mut s.sample_rejected)
    }

    pub(crate) fn liveliness_changed_status(&self) -> LivelinessChangedStatus {
        self.state.take_status(StatusMask::LIVELINESS_CHANGED, |s| {
            &mut s.liveliness_changed
        })
    }

    pub(crate) fn requested_deadline_missed_status(&self) -> DeadlineMissedStatus {
        self.state
            .take_status(StatusMask::REQUESTED_DEADLINE_MISSED, |s| {
                &mut s.requested_deadline_missed
            })
    }

    /// The state of a new reader with `cache`, not yet created in the core.
    pub(crate) fn new(
        codec: K::Codec,
        driver: Arc<super::driver::Driver>,
        cache: ReaderCache<K::Data>,
        group_order: Option<Arc<AtomicU64>>,
        access: Option<Arc<AccessScope>>,
        credit_limit: Option<usize>,
    ) -> Self {
        ReaderInner {
            codec,
            state: EndpointState::new(driver),
            pending: Mutex::new(VecDeque::new()),
            group_order,
            access,
            staged: Mutex::new(VecDeque::new()),
            committed: Mutex::default(),
            cache: Mutex::new(CacheState {
                cache,
                decoding: Decoding::new(),
                batch: VecDeque::new(),
                writer_info: None,
            }),
            data_cv: Condvar::new(),
            data_waiters: AtomicUsize::new(0),
            wakers: Mutex::new(Vec::new()),
            has_wakers: AtomicBool::new(false),
            data_signal: Signal::default(),
            credit_limit: AtomicUsize::new(credit_limit.unwrap_or(NO_CREDIT_LIMIT)),
        }
    }

    /// The public reader, for listeners.
    fn reader(self: &Arc<Self>) -> impl FnOnce(Arc<EndpointHandle<K::Owner>>) -> K::Reader {
        let inner = self.clone();
        move |handle| K::reader(inner, handle)
    }

    /// Core of read and take: calls `emit` with each selected sample's data slot and info (with `take` the
    /// samples leave the cache), then updates DATA_AVAILABLE, the read conditions and the reader's credit.
    pub(crate) fn visit(
        &self,
        mut sel: Selection,
        next_after: Option<InstanceHandle>,
        take: bool,
        mut emit: impl FnMut(&mut Option<K::Data>, SampleInfo),
    ) -> DdsResult<usize> {
        self.state.check_enabled()?;
        self.state.data_read();
        let mut n = 0;
        {
            let mut st = lock(&self.cache);
            if let Some(prev) = next_after {
                sel.instance = None;
                match st.cache.next_instance(prev, &sel) {
                    Some(h) => sel.instance = Some(h),
                    None => return Ok(0),
                }
            }
            st.cache.collect_with(&sel, take, |slot, info| {
                n += 1;
                emit(slot, info);
            });
            let unread = Selection {
                sample_states: SampleStateMask::NOT_READ,
                ..Selection::default()
            };
            if !st.cache.has_matching(&unread) {
                self.state.status_core().clear(StatusMask::DATA_AVAILABLE);
            }
        }
        if take && n > 0 {
            self.refresh_credit();
        }
        // Read conditions may have stopped triggering.
        self.data_signal.notify();
        Ok(n)
    }

    /// Blocks until a not-read sample is available (`Ok(true)`) or `timeout` passes (`Ok(false)`).
    pub(crate) fn wait_for_data(&self, timeout: Duration) -> DdsResult<bool> {
        self.state.check_enabled()?;
        let deadline = Instant::now().checked_add(timeout);
        let unread = Selection {
            sample_states: SampleStateMask::NOT_READ,
            ..Selection::default()
        };
        let mut st = lock(&self.cache);
        loop {
            if st.cache.has_matching(&unread) {
                return Ok(true);
            }
            self.state.driver.check_alive()?;
            let left = match deadline {
                Some(d) => match d.checked_duration_since(Instant::now()) {
                    Some(l) if !l.is_zero() => l,
                    _ => return Ok(false),
                },
                None => Duration::from_secs(1),
            };
            self.data_waiters.fetch_add(1, AtomicOrdering::SeqCst);
            st = recover(
                self.data_cv
                    .wait_timeout(st, left.min(Duration::from_secs(1))),
            )
            .0;
            self.data_waiters.fetch_sub(1, AtomicOrdering::SeqCst);
        }
    }

    /// `writer` became alive (`Some(true)`), not alive (`Some(false)`) or unmatched (`None`): LIVELINESS_CHANGED
    /// when that changed the counts. A liveliness change (`matched_only`) of a writer that is no longer matched
    /// (it can trail the unmatch) changes nothing: only matched writers are counted.
    fn liveliness(self: &Arc<Self>, writer: Guid, to: Option<bool>, matched_only: bool) {
        self.state.signal_if(
            StatusMask::LIVELINESS_CHANGED,
            |st| {
                if matched_only && !st.writers_alive.contains_key(&writer) {
                    return None;
                }
                st.liveliness_changed
                    .record(&mut st.writers_alive, writer, to)
                    .then_some(&mut st.liveliness_changed)
            },
            self.reader(),
            |l, r, s| l.liveliness_changed(r, s),
        );
    }

    /// Gives the core back the room freed by a take. Under the core lock every delivered sample is either
    /// queued in `pending` or in the cache, so the credit is exact.
    fn refresh_credit(&self) {
        let limit = self.credit_limit.load(AtomicOrdering::Relaxed);
        if limit == NO_CREDIT_LIMIT {
            return;
        }
        let id = self.state.id();
        self.state.driver.with_core(|c, _| {
            let held = lock(&self.cache).cache.len() + lock(&self.pending).len();
            c.set_reader_credit(id, Some(limit.saturating_sub(held)));
        });
    }

    /// Decodes one received change and stores it in the cache.
    fn store(&self, st: &mut CacheState<K::Data>, s: ReceivedSample, pass: &mut Pass) {
        let info = self
            .state
            .driver
            .remote_writer_via(&s.writer, &mut st.writer_info);
        let key = st.cache.take_key_buffer();
        let Some(inc) = decode_change_with(
            &self.codec,
            s,
            info,
            &mut st.decoding,
            key,
            pass.now,
            pass.rx_time,
        ) else {
            return;
        };
        match st.cache.insert(inc, pass.now) {
            Outcome::Accepted { .. } => pass.stored.any = true,
            Outcome::Filtered => {}
            Outcome::Rejected { reason, handle } => pass.stored.rejected.push((reason, handle)),
        }
    }

    /// Stores the changes of `queue` (the core's queue, or what the access scope set aside).
    fn store_queued(&self, queue: &Mutex<VecDeque<(u64, Pending)>>) -> Stored {
        let mut pass = Pass {
            now: Instant::now(),
            rx_time: SystemTime::now(),
            stored: Stored::default(),
        };
        let mut guard = lock(&self.cache);
        let st = &mut *guard;
        // Taking the queue under the cache lock keeps the core's order even with several receive threads.
        let mut batch = std::mem::take(&mut st.batch);
        std::mem::swap(&mut batch, &mut *lock(queue));
        // Popped from the front (a drain's set-up and drop cost more for the one or two items of a batch).
        while let Some((place, item)) = batch.pop_front() {
            st.cache.order_from(place);
            match item {
                Pending::Sample(s) => self.store(st, s, &mut pass),
                // Under one lock hold: a read sees all of the set or none of it.
                Pending::CoherentSet(set) => {
                    for s in set {
                        self.store(st, s, &mut pass);
                    }
                }
                Pending::WriterGone(g) => pass.stored.any |= st.cache.writer_gone(g, pass.now),
            }
        }
        st.batch = batch;
        pass.stored
    }

    /// Raises SAMPLE_REJECTED and DATA_AVAILABLE for what [`ReaderInner::store_queued`] stored.
    fn announce_stored(self: &Arc<Self>, stored: Stored) {
        let Stored { any, rejected } = stored;
        if !rejected.is_empty() {
            tracing::debug!(
                count = rejected.len(),
                "samples rejected by resource limits"
            );
            self.state.signal(
                StatusMask::SAMPLE_REJECTED,
                |st| {
                    for (reason, handle) in &rejected {
                        st.sample_rejected.record(*reason, *handle);
                    }
                    &mut st.sample_rejected
                },
                self.reader(),
                |l, r, s| l.sample_rejected(r, s),
            );
        }
        if any {
            self.notify_data();
        }
    }

    fn notify_data(self: &Arc<Self>) {
        if self.data_waiters.load(AtomicOrdering::SeqCst) > 0 {
            self.data_cv.notify_all();
        }
        if self.has_wakers.load(AtomicOrdering::SeqCst) {
            let wakers = std::mem::take(&mut *lock(&self.wakers));
            for w in wakers {
                w.wake();
            }
        }
        self.state.status_core().raise(StatusMask::DATA_AVAILABLE);
        self.data_signal.notify();
        self.state
            .call_listener(self.reader(), |l, r| l.data_available(r));
    }
}

impl<K: ReaderKind> ReaderInner<K> {
    /// A queued change's place in the subscriber's order (GROUP ordered access; else 0). Numbered when
    /// queued, under the core lock, in the core's order across the subscriber's readers (they store their
    /// queues one after the other).
    fn place(&self, item: &Pending) -> u64 {
        self.group_order.as_ref().map_or(0, |c| {
            let n = match item {
                Pending::CoherentSet(set) => set.len() as u64,
                _ => 1,
            };
            c.fetch_add(n, AtomicOrdering::Relaxed)
        })
    }
}

impl<K: ReaderKind> Endpoint for ReaderInner<K> {
    fn enqueue(&self, item: Pending) {
        let place = self.place(&item);
        lock(&self.pending).push_back((place, item));
    }

    fn enqueue_run(&self, first: Pending, more: &mut dyn FnMut() -> Option<Pending>) {
        // Each sample moves once, into the queue (an `Option` around the first was one move more).
        let mut queue = lock(&self.pending);
        queue.push_back((self.place(&first), first));
        while let Some(it) = more() {
            queue.push_back((self.place(&it), it));
        }
    }

    fn process(self: Arc<Self>) {
        if let Some(scope) = &self.access {
            return scope.deliver(&self.state.driver);
        }
        let stored = self.store_queued(&self.pending);
        self.announce_stored(stored);
    }

    fn on_event(self: Arc<Self>, ev: &Event) {
        let id = self.state.id();
        match ev {
            Event::SubscriptionMatched {
                writer, matched, ..
            } => {
                tracing::info!(reader = ?id, ?writer, matched, "subscription matched");
                self.state.record_match(
                    StatusMask::SUBSCRIPTION_MATCHED,
                    |st| &mut st.subscription_matched,
                    (*writer, *matched),
                    self.reader(),
                    |l, r, s| l.subscription_matched(r, s),
                );
                // A writer matched is alive until its lease says otherwise; an unmatched one is no longer
                // counted.
                self.liveliness(*writer, matched.then_some(true), false);
            }
            Event::RequestedIncompatibleQos { policy, writer, .. } => {
                tracing::warn!(reader = ?id, ?writer, ?policy, "requested incompatible QoS");
                self.state.signal(
                    StatusMask::REQUESTED_INCOMPATIBLE_QOS,
                    |st| {
                        st.requested_incompatible_qos.record(*policy);
                        &mut st.requested_incompatible_qos
                    },
                    self.reader(),
                    |l, r, s| l.requested_incompatible_qos(r, s),
                );
            }
            Event::LivelinessChanged { writer, alive, .. } => {
                if !*alive {
                    let changed = lock(&self.cache).cache.writer_gone(*writer, Instant::now());
                    if changed {
                        self.notify_data();
                    }
                }
                self.liveliness(*writer, Some(*alive), true);
            }
            Event::SampleLost { count, .. } => {
                self.state.signal(
                    StatusMask::SAMPLE_LOST,
                    |st| {
                        st.sample_lost.record(*count);
                        &mut st.sample_lost
                    },
                    self.reader(),
                    |l, r, s| l.sample_lost(r, s),
                );
            }
            _ => {}
        }
    }

    fn tick(self: Arc<Self>, now: Instant) {
        let missed = lock(&self.cache).cache.tick(now);
        if missed.is_empty() {
            return;
        }
        self.state.signal_consumed(
            StatusMask::REQUESTED_DEADLINE_MISSED,
            |st| {
                st.requested_deadline_missed.record(&missed);
                &mut st.requested_deadline_missed
            },
            self.reader(),
            |l, r, s| l.requested_deadline_missed(r, s),
        );
    }
}

impl<K: ReaderKind> AccessMember for ReaderInner<K> {
    fn stage(&self) {
        let mut queued = lock(&self.pending);
        lock(&self.staged).append(&mut queued);
    }

    fn held(&self) -> usize {
        lock(&self.pending).len()
    }

    fn commit(&self) {
        let s = self.store_queued(&self.staged);
        let mut c = lock(&self.committed);
        c.any |= s.any;
        c.rejected.extend(s.rejected);
    }

    fn announce(self: Arc<Self>) {
        let stored = std::mem::take(&mut *lock(&self.committed));
        self.announce_stored(stored);
    }
}

impl<K: ReaderKind> ReadConditionSource for ReaderInner<K> {
    fn has_matching(
        &self,
        s: SampleStateMask,
        v: ViewStateMask,
        i: InstanceStateMask,
        query: Option<&SharedFilter>,
    ) -> bool {
        let sel = Selection {
            query: query.cloned(),
            ..Selection::states(s, v, i)
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
        if r.inner.state.driver.check_alive().is_err() {
            return Poll::Ready(None);
        }
        {
            let mut w = lock(&r.inner.wakers);
            if !w.iter().any(|x| x.will_wake(cx.waker())) {
                w.push(cx.waker().clone());
            }
            r.inner.has_wakers.store(true, AtomicOrdering::SeqCst);
        }
        // A sample may have arrived between the first check and the registration.
        match take() {
            Some(s) => Poll::Ready(Some(s)),
            None => Poll::Pending,
        }
    }
}
