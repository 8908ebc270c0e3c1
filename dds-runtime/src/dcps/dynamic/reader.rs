//! [`DynamicReader`]: the typed reader's cache (`dcps/cache.rs`) and decoding step (`dcps/decode.rs`) over
//! [`DynamicData`] samples, so instance states, sample and view states and read/take by state and instance
//! are the typed reader's.

use std::collections::VecDeque;
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant, SystemTime};

use foldhash::{HashMap, HashMapExt};

use crate::cdr::{DecodeError, EncodeError, XcdrVersion};
use crate::dcps::IncompatibleQosStatus;
use crate::qos::{DataReaderQos, DataRepresentation, ReaderQos};
use crate::rtps::{ChangeKind, Event, Guid, Payload, ReaderSpec, ReceivedSample};
use crate::xtypes::dynamic::{DynamicData, DynamicType};

use super::super::cache::{to_sample, ReaderCache, Selection, SharedFilter};
use super::super::condition::{QueryCondition, ReadCondition, ReadConditionSource, Signal};
use super::super::decode::{decode_change_with, SampleCodec};
use super::super::driver::{Driver, Endpoint, EndpointHandle, Pending};
use super::super::error::DdsResult;
use super::super::sample::{
    InstanceHandle, InstanceState, InstanceStateMask, Sample, SampleInfo, SampleStateMask,
    ViewStateMask,
};
use super::super::subscriber::Subscriber;
use super::super::sync::lock;
use super::DynamicTopic;

/// One received change, decoded (what [`DynamicReader::take`] returns).
#[derive(Debug, Clone)]
pub struct DynamicSample {
    /// The sample (`Alive`), or the instance's key with defaults elsewhere (dispose, unregister); `None`
    /// when a key-only change carried no key payload.
    pub data: Option<DynamicData>,
    /// What the change did to its instance: `Alive` for data, else the instance's state when it was taken
    /// (`Dispose` for NOT_ALIVE_DISPOSED, `Unregister` for NOT_ALIVE_NO_WRITERS).
    pub kind: ChangeKind,
    /// The writer.
    pub writer: Guid,
    /// The writer's source timestamp.
    pub source_timestamp: Option<SystemTime>,
    /// The sample's states, instance and ranks, as a typed reader gives them.
    pub info: SampleInfo,
}

impl From<Sample<DynamicData>> for DynamicSample {
    fn from(s: Sample<DynamicData>) -> Self {
        let kind = match (s.info.valid_data, s.info.instance_state) {
            (true, _) | (false, InstanceState::Alive) => ChangeKind::Alive,
            (false, InstanceState::NotAliveDisposed) => ChangeKind::Dispose,
            (false, InstanceState::NotAliveNoWriters) => ChangeKind::Unregister,
        };
        DynamicSample {
            data: s.data,
            kind,
            writer: s.info.publication_guid,
            source_timestamp: Some(s.info.source_timestamp),
            info: s.info,
        }
    }
}

/// A dynamic type decodes and identifies instances through its `DynamicType`.
impl SampleCodec<DynamicData> for DynamicType {
    fn keyed(&self) -> bool {
        self.is_keyed()
    }
    fn decode(&self, payload: &mut Payload) -> Result<DynamicData, DecodeError> {
        DynamicData::deserialize(self, payload)
    }
    fn decode_key(&self, payload: &[u8]) -> Result<DynamicData, DecodeError> {
        DynamicData::deserialize_key(self, payload)
    }
    fn instance_key(&self, v: &DynamicData, out: &mut Vec<u8>) -> Result<(), EncodeError> {
        v.instance_key(out)
    }
    fn key_hash(&self, v: &DynamicData, version: XcdrVersion) -> Result<[u8; 16], EncodeError> {
        v.key_hash(version)
    }
}

struct Owner {
    topic: DynamicTopic,
    _subscriber: Subscriber,
}

/// The cache and the key hashes seen (for key-hash-only disposes), under one lock.
struct CacheState {
    cache: ReaderCache<DynamicData>,
    by_hash: HashMap<[u8; 16], Vec<u8>>,
}

struct Inner {
    ty: DynamicType,
    driver: Arc<Driver>,
    /// Changes queued under the core lock, decoded and stored by `process`.
    pending: Mutex<VecDeque<Pending>>,
    cache: Mutex<CacheState>,
    data_cv: Condvar,
    /// Wakes the waitsets of this reader's read and query conditions.
    data_signal: Signal,
    matched: Mutex<Vec<Guid>>,
    incompatible: Mutex<IncompatibleQosStatus>,
}

impl Inner {
    /// Decodes and stores the queued changes; whether any changed the cache.
    fn store_pending(&self) -> bool {
        let queued: Vec<Pending> = lock(&self.pending).drain(..).collect();
        let (now, rx_time) = (Instant::now(), SystemTime::now());
        let mut st = lock(&self.cache);
        let mut any = false;
        for item in queued {
            match item {
                Pending::Sample(s) => any |= self.store(&mut st, s, now, rx_time),
                Pending::CoherentSet(set) => {
                    for s in set {
                        any |= self.store(&mut st, s, now, rx_time);
                    }
                }
                Pending::WriterGone(g) => any |= st.cache.writer_gone(g, now),
            }
        }
        any
    }

    /// Wakes `wait_for_data` and the waitsets of the reader's conditions.
    fn notify_data(&self) {
        self.data_cv.notify_all();
        self.data_signal.notify();
    }

    fn store(&self, st: &mut CacheState, s: ReceivedSample, now: Instant, rx: SystemTime) -> bool {
        let info = self.driver.remote_writer(&s.writer);
        let key = st.cache.take_key_buffer();
        let Some(inc) = decode_change_with(&self.ty, s, info, &mut st.by_hash, key, now, rx) else {
            return false;
        };
        matches!(
            st.cache.insert(inc, now),
            super::super::cache::Outcome::Accepted { .. }
        )
    }
}

impl ReadConditionSource for Inner {
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

impl Endpoint for Inner {
    fn enqueue(&self, item: Pending) {
        lock(&self.pending).push_back(item);
    }

    fn process(self: Arc<Self>) {
        if self.store_pending() {
            self.notify_data();
        }
    }

    fn on_event(self: Arc<Self>, ev: &Event) {
        match ev {
            Event::SubscriptionMatched {
                writer, matched, ..
            } => super::record_match(&self.matched, *writer, *matched),
            Event::RequestedIncompatibleQos { policy, .. } => {
                lock(&self.incompatible).record(*policy)
            }
            Event::LivelinessChanged {
                writer,
                alive: false,
                ..
            } if lock(&self.cache).cache.writer_gone(*writer, Instant::now()) => self.notify_data(),
            _ => {}
        }
    }

    fn tick(self: Arc<Self>, now: Instant) {
        lock(&self.cache).cache.tick(now);
    }
}

/// Takes [`DynamicData`] samples of a [`DynamicTopic`]. Cheap to clone; deleted with its last clone.
#[derive(Clone)]
pub struct DynamicReader {
    inner: Arc<Inner>,
    handle: Arc<EndpointHandle<Owner>>,
}

impl std::fmt::Debug for DynamicReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DynamicReader")
            .field("topic", &self.handle.owner().topic.name())
            .finish()
    }
}

impl Subscriber {
    /// Creates a reader of a dynamic topic. An empty `data_representation` accepts XCDR1 and XCDR2. Samples
    /// are kept per instance with the typed reader's cache: history, resource limits, instance and sample
    /// states, as [`DataReader`](crate::dcps::DataReader) keeps them.
    pub fn create_dynamic_reader(
        &self,
        topic: &DynamicTopic,
        qos: &DataReaderQos,
    ) -> DdsResult<DynamicReader> {
        let driver = self.participant().driver().clone();
        let mut rq = qos.clone();
        if rq.data_representation.ids().is_empty() {
            rq.data_representation = DataRepresentation::accept_both();
        }
        super::super::endpoint::check_history(&rq.history)?;
        let ty = topic.dynamic_type().clone();
        let spec = ReaderSpec {
            topic_name: topic.name().to_string(),
            type_name: topic.type_name(),
            keyed: ty.is_keyed(),
            qos: ReaderQos::new(rq.clone(), self.qos(), topic.qos()),
            type_information: topic.type_information(),
            entity_name: None,
            content_filter: None,
            internal: false,
        };
        let inner = Arc::new(Inner {
            driver: driver.clone(),
            pending: Mutex::new(VecDeque::new()),
            cache: Mutex::new(CacheState {
                cache: ReaderCache::new(rq, ty.is_keyed()),
                by_hash: HashMap::new(),
            }),
            ty,
            data_cv: Condvar::new(),
            data_signal: Signal::default(),
            matched: Mutex::new(Vec::new()),
            incompatible: Mutex::new(IncompatibleQosStatus::default()),
        });
        let sink: Arc<dyn Endpoint> = inner.clone();
        let id = driver.create_endpoint(sink, |c, now| {
            topic.register_types(c);
            c.create_reader(now, spec)
        })?;
        let owner = Owner {
            topic: topic.clone(),
            _subscriber: self.clone(),
        };
        tracing::info!(topic = topic.name(), type_name = %topic.type_name(), ?id, "dynamic reader created");
        Ok(DynamicReader {
            inner,
            handle: Arc::new(EndpointHandle::new(driver, id, owner)),
        })
    }
}

impl DynamicReader {
    /// The reader's GUID.
    pub fn guid(&self) -> Guid {
        self.handle.guid()
    }

    /// The topic.
    pub fn topic(&self) -> &DynamicTopic {
        &self.handle.owner().topic
    }

    /// The writers matched now.
    pub fn matched_writers(&self) -> Vec<Guid> {
        lock(&self.inner.matched).clone()
    }

    /// REQUESTED_INCOMPATIBLE_QOS: writers on the topic not matched for a policy (`TypeConsistencyEnforcement`
    /// for a type not assignable to the reader's). Resets the change count.
    pub fn requested_incompatible_qos_status(&self) -> IncompatibleQosStatus {
        super::take_incompatible(&self.inner.incompatible)
    }

    /// Waits until a sample (or an instance state change) not read yet is in the cache; `false` on timeout.
    pub fn wait_for_data(&self, timeout: Duration) -> bool {
        let end = Instant::now() + timeout;
        let unread = Selection::states(
            SampleStateMask::NOT_READ,
            ViewStateMask::ANY,
            InstanceStateMask::ANY,
        );
        let mut st = lock(&self.inner.cache);
        while !st.cache.has_matching(&unread) {
            let left = end.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return false;
            }
            st = self
                .inner
                .data_cv
                .wait_timeout(st, left)
                .map_or_else(|e| e.into_inner().0, |r| r.0);
        }
        true
    }

    /// Takes every sample in the cache, oldest first, with the change each made to its instance. A payload
    /// that does not decode as the topic's type is dropped (and logged).
    pub fn take(&self) -> Vec<DynamicSample> {
        let any = Selection::states(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ANY,
        );
        self.collect(&any, true)
            .into_iter()
            .map(DynamicSample::from)
            .collect()
    }

    /// Reads (copies, leaving them in the cache, now READ) the samples in these states.
    pub fn read_states(
        &self,
        sample: SampleStateMask,
        view: ViewStateMask,
        instance: InstanceStateMask,
    ) -> Vec<Sample<DynamicData>> {
        self.collect(&Selection::states(sample, view, instance), false)
    }

    /// Takes (removes from the cache) the samples in these states.
    pub fn take_states(
        &self,
        sample: SampleStateMask,
        view: ViewStateMask,
        instance: InstanceStateMask,
    ) -> Vec<Sample<DynamicData>> {
        self.collect(&Selection::states(sample, view, instance), true)
    }

    /// Reads the samples of one instance.
    pub fn read_instance(&self, h: InstanceHandle) -> Vec<Sample<DynamicData>> {
        self.collect(&Self::of_instance(h), false)
    }

    /// Takes the samples of one instance.
    pub fn take_instance(&self, h: InstanceHandle) -> Vec<Sample<DynamicData>> {
        self.collect(&Self::of_instance(h), true)
    }

    /// The handle of the instance whose key `key_sample` holds, if the reader knows it.
    pub fn lookup_instance(&self, key_sample: &DynamicData) -> Option<InstanceHandle> {
        let mut key = Vec::new();
        key_sample.instance_key(&mut key).ok()?;
        lock(&self.inner.cache).cache.lookup(&key)
    }

    /// A read condition on this reader (for a [`WaitSet`](crate::dcps::WaitSet)): triggers while it holds a
    /// sample in these states.
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
        let query = crate::filter::ContentFilter::query(expression, params)?;
        let read = self.create_readcondition(sample_states, view_states, instance_states);
        Ok(QueryCondition::new(read, query))
    }

    /// Reads with a read condition's states (and a query condition's query and ORDER BY).
    pub fn read_w_condition(&self, c: &ReadCondition) -> Vec<Sample<DynamicData>> {
        self.collect(&Self::of_condition(c), false)
    }

    /// Takes with a read condition's states (and a query condition's query and ORDER BY).
    pub fn take_w_condition(&self, c: &ReadCondition) -> Vec<Sample<DynamicData>> {
        self.collect(&Self::of_condition(c), true)
    }

    fn of_condition(c: &ReadCondition) -> Selection {
        Selection {
            query: c.query.clone(),
            ..Selection::states(c.sample_states, c.view_states, c.instance_states)
        }
    }

    /// The state of an instance the reader knows.
    pub fn instance_state(&self, h: InstanceHandle) -> Option<InstanceState> {
        lock(&self.inner.cache).cache.instance_state(h)
    }

    /// Instances in the cache.
    pub fn instance_count(&self) -> usize {
        lock(&self.inner.cache).cache.instance_count()
    }

    fn of_instance(h: InstanceHandle) -> Selection {
        Selection {
            instance: Some(h),
            ..Selection::states(
                SampleStateMask::ANY,
                ViewStateMask::ANY,
                InstanceStateMask::ANY,
            )
        }
    }

    /// The selected samples; those without data (dispose, unregister) carry the instance's key values when
    /// the reader knows them.
    fn collect(&self, sel: &Selection, take: bool) -> Vec<Sample<DynamicData>> {
        self.inner.store_pending();
        let mut out = Vec::new();
        let mut st = lock(&self.inner.cache);
        st.cache.collect_with(sel, take, |slot, info| {
            out.push(to_sample(slot, info, take, Some(DynamicData::clone)));
        });
        for s in out.iter_mut().filter(|s| s.data.is_none()) {
            s.data = st.cache.key_holder(s.info.instance_handle).cloned();
        }
        out
    }
}
