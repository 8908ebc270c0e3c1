//! [`DynamicReader`]: the typed reader's machinery (`dcps/subscriber.rs`: queue, decoding step, cache,
//! statuses, listener and status condition) over [`DynamicData`] samples, so instance states, sample and view
//! states, read/take by state and instance, listeners and status conditions are the typed reader's.

use std::sync::Arc;
use std::time::{Duration, SystemTime};

use crate::cdr::{ByteOrder, DecodeError, EncodeError, XcdrVersion};
use crate::qos::{DataReaderQos, DataRepresentation, ReaderQos};
use crate::rtps::{ChangeKind, Guid, Payload, ReaderSpec};
use crate::xtypes::dynamic::{DynamicData, DynamicType};

use super::super::cache::{to_sample, ReaderCache, Selection};
use super::super::condition::{QueryCondition, ReadCondition, StatusCondition};
use super::super::decode::SampleCodec;
use super::super::driver::{Endpoint, EndpointHandle};
use super::super::endpoint::check_history;
use super::super::error::{DdsError, DdsResult};
use super::super::sample::{
    InstanceHandle, InstanceState, InstanceStateMask, Sample, SampleInfo, SampleStateMask,
    ViewStateMask,
};
use super::super::status::{
    DeadlineMissedStatus, IncompatibleQosStatus, LivelinessChangedStatus, SampleLostStatus,
    SampleRejectedStatus, StatusMask, SubscriptionMatchedStatus,
};
use super::super::subscriber::{
    credit_limit, reader_callbacks, KeyHolderFn, ReaderInner, ReaderKind, Subscriber,
};
use super::super::sync::lock;
use super::DynamicTopic;

/// One received change, decoded (what [`DynamicReader::take`] returns).
#[derive(Debug, Clone)]
pub struct DynamicSample {
    /// The sample (`Alive`), or the instance's key with defaults elsewhere (dispose, unregister; also for
    /// an instance the reader never had data of, from the change's key payload); `None` for an unkeyed
    /// type's unregister.
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
    fn decode(
        &self,
        payload: &mut Payload,
        _spare: &mut Vec<DynamicData>,
    ) -> Result<DynamicData, DecodeError> {
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

/// Callbacks of a [`DynamicReader`], as [`DataReaderListener`](crate::dcps::DataReaderListener) is for a
/// typed reader (see [`crate::dcps::listener`]). Every method has an empty default.
#[allow(unused_variables)]
pub trait DynamicReaderListener: Send + Sync {
    /// New samples (or instance state changes) are available.
    fn on_data_available(&self, reader: &DynamicReader) {}
    /// A writer matched or unmatched.
    fn on_subscription_matched(&self, reader: &DynamicReader, status: SubscriptionMatchedStatus) {}
    /// A writer was found with incompatible QoS (or a type not assignable to the reader's).
    fn on_requested_incompatible_qos(&self, reader: &DynamicReader, status: IncompatibleQosStatus) {
    }
    /// Samples were lost.
    fn on_sample_lost(&self, reader: &DynamicReader, status: SampleLostStatus) {}
    /// A sample was rejected by a resource limit.
    fn on_sample_rejected(&self, reader: &DynamicReader, status: SampleRejectedStatus) {}
    /// A matched writer's liveliness changed.
    fn on_liveliness_changed(&self, reader: &DynamicReader, status: LivelinessChangedStatus) {}
    /// An instance missed its deadline.
    fn on_requested_deadline_missed(&self, reader: &DynamicReader, status: DeadlineMissedStatus) {}
}

reader_callbacks!(dyn DynamicReaderListener, DynamicReader);

/// What a dynamic reader's handle keeps alive.
pub(crate) struct Owner {
    topic: DynamicTopic,
    subscriber: Subscriber,
}

/// The dynamic flavour of the reader machinery: [`DynamicData`] samples decoded by their [`DynamicType`].
pub(crate) struct Dynamic;

impl ReaderKind for Dynamic {
    type Data = DynamicData;
    type Codec = DynamicType;
    type Listener = dyn DynamicReaderListener;
    type Owner = Owner;
    type Reader = DynamicReader;
    fn reader(
        inner: Arc<ReaderInner<Dynamic>>,
        handle: Arc<EndpointHandle<Owner>>,
    ) -> DynamicReader {
        DynamicReader { inner, handle }
    }
    fn announce(reader: &DynamicReader, qos: DataReaderQos) -> DdsResult<()> {
        let rq = ReaderQos::new(qos, &reader.subscriber().get_qos()?, reader.topic().qos());
        let id = reader.handle.id();
        reader
            .inner
            .state
            .driver
            .with_core(|c, now| c.update_reader_qos(now, id, rq))?;
        Ok(())
    }
    /// Dynamic readers are created enabled.
    fn enable(_: DynamicReader) -> DdsResult<()> {
        Ok(())
    }
    fn key_holder() -> Option<KeyHolderFn<DynamicData>> {
        Some(key_holder)
    }
}

/// The key holder of `d`'s instance: its key members, the others defaulted (through a key-only payload);
/// `None` for an unkeyed type.
fn key_holder(d: &DynamicData) -> Option<DynamicData> {
    let ty = d.dynamic_type();
    if !ty.is_keyed() {
        return None;
    }
    let mut key = Vec::new();
    d.serialize_key(XcdrVersion::Xcdr2, ByteOrder::LittleEndian, &mut key)
        .ok()?;
    DynamicData::deserialize_key(ty, &key).ok()
}

/// Takes [`DynamicData`] samples of a [`DynamicTopic`]. Cheap to clone; deleted with its last clone.
///
/// It runs on the typed reader's machinery (queue, decoding, cache, statuses, listener, status condition):
/// what [`DataReader`](crate::dcps::DataReader) documents of its QoS holds here too. It is one of its
/// subscriber's readers as a typed reader is: the statuses its own listener does not take go to the
/// subscriber's and participant's listeners (DATA_ON_READERS first), it takes part in the subscriber's
/// GROUP presentation (`begin_access`, ordered access) and `get_datareaders` lists it.
#[derive(Clone)]
pub struct DynamicReader {
    inner: Arc<ReaderInner<Dynamic>>,
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
        self.create_dynamic(topic, qos, None)
    }

    /// Creates a reader of a dynamic topic with its listener installed first, enabled for the statuses in
    /// `mask`: the listener sees every status of the reader from its creation on.
    pub fn create_dynamic_reader_with_listener(
        &self,
        topic: &DynamicTopic,
        qos: &DataReaderQos,
        listener: Box<dyn DynamicReaderListener>,
        mask: StatusMask,
    ) -> DdsResult<DynamicReader> {
        self.create_dynamic(topic, qos, Some((Arc::from(listener), mask)))
    }

    fn create_dynamic(
        &self,
        topic: &DynamicTopic,
        qos: &DataReaderQos,
        listener: Option<(Arc<dyn DynamicReaderListener>, StatusMask)>,
    ) -> DdsResult<DynamicReader> {
        let parent = self.listener_node()?;
        // The QoS in effect: the subscriber's may have changed since its creation.
        let group_qos = self.get_qos()?;
        let mut rq = qos.clone();
        if rq.data_representation.ids().is_empty() {
            rq.data_representation = DataRepresentation::accept_both();
        }
        check_history(&rq.history)?;
        let ty = topic.dynamic_type().clone();
        let spec = ReaderSpec {
            topic_name: topic.name().to_string(),
            type_name: topic.type_name(),
            keyed: ty.is_keyed(),
            qos: ReaderQos::new(rq.clone(), &group_qos, topic.qos()),
            type_information: topic.type_information(),
            entity_name: None,
            content_filter: None,
            internal: false,
        };
        let credit = credit_limit(&rq);
        let mut cache = ReaderCache::new(rq, ty.is_keyed());
        // A dispose or unregister carries its instance's key (`DynamicSample::data`).
        cache.set_key_in_invalid_fn(DynamicData::clone);
        let inner =
            self.reader_inner::<Dynamic>(ty, cache, &group_qos.presentation, credit, parent);
        if let Some((l, mask)) = listener {
            inner.state.set_listener_with_mask(Some(l), mask);
        }
        let owner = Owner {
            topic: topic.clone(),
            subscriber: self.clone(),
        };
        let sink: Arc<dyn Endpoint> = inner.clone();
        let handle = inner.state.create(sink, owner, |c, now| {
            topic.register_types(c);
            let id = c.create_reader(now, spec)?;
            if credit.is_some() {
                c.set_reader_credit(id, credit);
            }
            Ok(id)
        })?;
        self.reader_created(&inner, topic.name());
        tracing::info!(topic = topic.name(), type_name = %topic.type_name(), id = ?handle.id(), "dynamic reader created");
        Ok(DynamicReader { inner, handle })
    }
}

impl Subscriber {
    /// Deletes `reader` (`delete_datareader` for a dynamic reader): it leaves SEDP, and reads return nothing
    /// from then on. `PreconditionNotMet` for a reader of another subscriber.
    pub fn delete_dynamic_reader(&self, reader: &DynamicReader) -> DdsResult<()> {
        if !self.is(reader.subscriber()) {
            return Err(DdsError::PreconditionNotMet(
                "the reader belongs to another subscriber",
            ));
        }
        reader.inner.state.delete()
    }
}

impl DynamicReader {
    /// The reader's GUID.
    pub fn guid(&self) -> Guid {
        self.handle.guid()
    }

    /// The reader's handle (as writers see it in their matched subscriptions).
    pub fn instance_handle(&self) -> InstanceHandle {
        InstanceHandle::from_guid(self.guid())
    }

    /// The topic.
    pub fn topic(&self) -> &DynamicTopic {
        &self.handle.owner().topic
    }

    /// The subscriber.
    pub fn subscriber(&self) -> &Subscriber {
        &self.handle.owner().subscriber
    }

    /// The writers matched now.
    pub fn matched_writers(&self) -> Vec<Guid> {
        self.inner.state.matched()
    }

    /// The reader's status condition (for a [`WaitSet`](crate::dcps::WaitSet)).
    pub fn status_condition(&self) -> StatusCondition {
        StatusCondition {
            core: self.inner.state.status_core().clone(),
        }
    }

    /// Installs a listener for every status (replacing any previous one).
    pub fn set_listener(&self, listener: Box<dyn DynamicReaderListener>) {
        self.inner.state.set_listener(Some(Arc::from(listener)));
    }

    /// Installs a listener enabled for the statuses in `mask` only (replacing any previous one).
    pub fn set_listener_with_mask(
        &self,
        listener: Box<dyn DynamicReaderListener>,
        mask: StatusMask,
    ) {
        self.inner
            .state
            .set_listener_with_mask(Some(Arc::from(listener)), mask);
    }

    /// Removes the listener.
    pub fn clear_listener(&self) {
        self.inner.state.set_listener(None);
    }

    /// SUBSCRIPTION_MATCHED (resets the change counts).
    pub fn subscription_matched_status(&self) -> SubscriptionMatchedStatus {
        self.inner.subscription_matched_status()
    }

    /// REQUESTED_INCOMPATIBLE_QOS: writers on the topic not matched for a policy (`TypeConsistencyEnforcement`
    /// for a type not assignable to the reader's). Resets the change count.
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

    /// Waits until a sample (or an instance state change) not read yet is in the cache; `false` on timeout
    /// (or once the participant is gone).
    pub fn wait_for_data(&self, timeout: Duration) -> bool {
        self.inner.wait_for_data(timeout).unwrap_or(false)
    }

    /// Takes every sample in the cache, oldest first, with the change each made to its instance. A payload
    /// that does not decode as the topic's type is dropped (and logged).
    pub fn take(&self) -> Vec<DynamicSample> {
        let any = Selection::states(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ANY,
        );
        self.collect(any, true)
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
        self.collect(Selection::states(sample, view, instance), false)
    }

    /// Takes (removes from the cache) the samples in these states.
    pub fn take_states(
        &self,
        sample: SampleStateMask,
        view: ViewStateMask,
        instance: InstanceStateMask,
    ) -> Vec<Sample<DynamicData>> {
        self.collect(Selection::states(sample, view, instance), true)
    }

    /// Reads the samples of one instance.
    pub fn read_instance(&self, h: InstanceHandle) -> Vec<Sample<DynamicData>> {
        self.collect(Self::of_instance(h), false)
    }

    /// Takes the samples of one instance.
    pub fn take_instance(&self, h: InstanceHandle) -> Vec<Sample<DynamicData>> {
        self.collect(Self::of_instance(h), true)
    }

    /// The key of instance `h` (DDS `get_key_value`): its key members, the others defaulted; `None` when
    /// the reader does not know the instance (any more: a take of the last sample of an instance that is not
    /// alive and has no writers forgets it, but the samples taken carry the key in their `data`).
    pub fn get_key_value(&self, h: InstanceHandle) -> Option<DynamicData> {
        lock(&self.inner.cache).cache.key_holder(h).cloned()
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
        self.collect(Self::of_condition(c), false)
    }

    /// Takes with a read condition's states (and a query condition's query and ORDER BY).
    pub fn take_w_condition(&self, c: &ReadCondition) -> Vec<Sample<DynamicData>> {
        self.collect(Self::of_condition(c), true)
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

    /// The selected samples; those without data (dispose, unregister) carry the instance's key values
    /// (`valid_data` false), which the cache adds as it emits them: a take may forget the instance at once.
    /// Empty once the participant is gone.
    fn collect(&self, sel: Selection, take: bool) -> Vec<Sample<DynamicData>> {
        let mut out = Vec::new();
        let visited = self.inner.visit(sel, None, take, |slot, info| {
            out.push(to_sample(slot, info, take, Some(DynamicData::clone)));
        });
        if visited.is_err() {
            return Vec::new();
        }
        out
    }
}
