//! The rest of the `Subscriber` and `DataReader` operations (DDS 1.4 §2.2.2.5): QoS, listeners with masks
//! (DATA_ON_READERS before DATA_AVAILABLE), explicit deletion, lookups, `get_datareaders`,
//! `notify_datareaders`, `get_key_value` and the matched publication data; and how subscribers and readers
//! enter the participant's registry.

use std::any::Any;
use std::sync::{Arc, Weak};

use crate::cdr::{self, DdsType};
use crate::qos::{ChangeableQos, DataReaderQos, ReaderQos, SubscriberQos, TopicQos};

use super::super::builtin::PublicationBuiltinTopicData;
use super::super::cache::Selection;
use super::super::chain::{ListenerNode, ParentListener, StatusChange};
use super::super::condition::{ReadCondition, ReadConditionSource, StatusCondition};
use super::super::endpoint::check_history;
use super::super::error::{DdsError, DdsResult};
use super::super::participant::{DomainParticipant, WeakParticipant};
use super::super::presentation::group_ordered;
use super::super::registry::{Child, EndpointEntry, Group, Registered};
use super::super::sample::{InstanceHandle, InstanceStateMask, SampleStateMask, ViewStateMask};
use super::super::status::*;
use super::super::sync::lock;
use super::super::topic::Topic;
use super::{
    DataReader, DataReaderListener, ReaderCallbacks, ReaderInner, ReaderKind, Subscriber, Typed,
};
use crate::rtps::EntityId;

/// Callbacks of a [`Subscriber`] for its readers' statuses that have no listener of their own enabled for
/// them (DDS 1.4 §2.2.4.1). Readers are identified by their instance handle. Every method has an empty
/// default.
#[allow(unused_variables)]
pub trait SubscriberListener: Send + Sync {
    /// One of the subscriber's readers has new data. When enabled, it replaces the readers'
    /// `on_data_available`; [`Subscriber::notify_datareaders`] calls theirs.
    fn on_data_on_readers(&self, subscriber: &Subscriber) {}
    /// A reader has new data.
    fn on_data_available(&self, reader: InstanceHandle) {}
    /// A reader matched or unmatched a writer.
    fn on_subscription_matched(&self, reader: InstanceHandle, status: SubscriptionMatchedStatus) {}
    /// A reader found a writer with incompatible QoS.
    fn on_requested_incompatible_qos(&self, reader: InstanceHandle, status: IncompatibleQosStatus) {
    }
    /// A reader missed its requested deadline.
    fn on_requested_deadline_missed(&self, reader: InstanceHandle, status: DeadlineMissedStatus) {}
    /// A reader lost samples.
    fn on_sample_lost(&self, reader: InstanceHandle, status: SampleLostStatus) {}
    /// A reader rejected a sample.
    fn on_sample_rejected(&self, reader: InstanceHandle, status: SampleRejectedStatus) {}
    /// The liveliness of a writer matched by a reader changed.
    fn on_liveliness_changed(&self, reader: InstanceHandle, status: LivelinessChangedStatus) {}
}

/// The subscriber listener as a level of the chain; holds its subscriber weakly.
struct SubscriberLevel {
    listener: Arc<dyn SubscriberListener>,
    participant: WeakParticipant,
    qos: Weak<SubscriberQos>,
    access: Weak<super::AccessScope>,
}

impl ParentListener for SubscriberLevel {
    fn on_status(&self, r: InstanceHandle, change: StatusChange) {
        let l = &self.listener;
        match change {
            StatusChange::DataAvailable => l.on_data_available(r),
            StatusChange::SubscriptionMatched(s) => l.on_subscription_matched(r, s),
            StatusChange::RequestedIncompatibleQos(s) => l.on_requested_incompatible_qos(r, s),
            StatusChange::RequestedDeadlineMissed(s) => l.on_requested_deadline_missed(r, s),
            StatusChange::SampleLost(s) => l.on_sample_lost(r, s),
            StatusChange::SampleRejected(s) => l.on_sample_rejected(r, s),
            StatusChange::LivelinessChanged(s) => l.on_liveliness_changed(r, s),
            _ => {}
        }
    }
    fn on_data_on_readers(&self, _subscriber: InstanceHandle) {
        if let (Some(participant), Some(qos), Some(access)) = (
            self.participant.upgrade(),
            self.qos.upgrade(),
            self.access.upgrade(),
        ) {
            self.listener.on_data_on_readers(&Subscriber {
                participant,
                qos,
                access,
            });
        }
    }
}

/// Registers a new subscriber in its participant.
pub(super) fn register_subscriber(s: &Subscriber) {
    let identity: Weak<dyn Any + Send + Sync> = Arc::downgrade(&s.qos) as Weak<SubscriberQos>;
    let registry = s.participant.registry();
    let node = registry.add_group(identity, (*s.qos).clone());
    registry.created_by_participant(node.handle);
}

/// The subscriber level of a new reader's listener chain; `AlreadyDeleted` for a deleted subscriber.
/// Also `AlreadyDeleted` for a deleted topic.
pub(super) fn reader_parent<T: DdsType>(
    s: &Subscriber,
    topic: &Topic<T>,
) -> DdsResult<Arc<ListenerNode>> {
    topic.check_alive()?;
    s.listener_node()
}

/// Registers a new reader of any kind in its participant.
pub(super) fn register_reader<K: ReaderKind>(
    s: &Subscriber,
    inner: &Arc<ReaderInner<K>>,
    topic: &str,
) {
    let Ok(group) = s.with_group(|g| g.node.handle) else {
        return;
    };
    if let Some(f) = K::key_holder() {
        lock(&inner.cache).cache.set_key_holder_fn(f);
    }
    let entity: Weak<dyn Registered> = Arc::downgrade(inner) as Weak<ReaderInner<K>>;
    s.participant.registry().add_endpoint(
        false,
        EndpointEntry {
            group,
            topic: topic.to_string(),
            guid: inner
                .state
                .handle()
                .map_or(crate::rtps::Guid::UNKNOWN, |h| h.guid()),
            deleted: Arc::downgrade(inner.state.deleted_flag()),
            entity,
        },
    );
}

/// A sample holding only the key of `data` (its other members defaulted), for `get_key_value`.
pub(super) fn key_holder<T: DdsType>(data: &T) -> Option<T> {
    let mut buf = Vec::new();
    cdr::serialize_key(
        data,
        cdr::XcdrVersion::Xcdr2,
        cdr::ByteOrder::NATIVE,
        &mut buf,
    )
    .ok()?;
    cdr::deserialize_key(&buf).ok()
}

impl<K: ReaderKind> Registered for ReaderInner<K> {
    fn as_any(self: Arc<Self>) -> Arc<dyn Any + Send + Sync> {
        self
    }
    fn group_changed(self: Arc<Self>) {
        if let Some(handle) = self.state.handle() {
            let qos = lock(&self.cache).cache.qos().clone();
            if let Err(e) = K::announce(&K::reader(self, handle), qos) {
                tracing::debug!(error = %e, "reader QoS not announced again");
            }
        }
    }
    fn has_samples(&self, s: SampleStateMask, v: ViewStateMask, i: InstanceStateMask) -> bool {
        self.has_matching(s, v, i, None)
    }
    fn sample_order(
        &self,
        s: SampleStateMask,
        v: ViewStateMask,
        i: InstanceStateMask,
        out: &mut Vec<u64>,
    ) {
        lock(&self.cache)
            .cache
            .matching_order(&Selection::states(s, v, i), out);
    }
    fn notify_data_available(self: Arc<Self>) {
        self.state
            .call_own_listener(self.reader(), |l, r| l.data_available(r));
    }
    fn enable(self: Arc<Self>) -> DdsResult<()> {
        let handle = self.state.handle().ok_or(DdsError::AlreadyDeleted)?;
        K::enable(K::reader(self, handle))
    }
}

impl DomainParticipant {
    /// Deletes `subscriber` (`delete_subscriber`): `PreconditionNotMet` while it has readers. Its handles
    /// then return `AlreadyDeleted`.
    pub fn delete_subscriber(&self, subscriber: &Subscriber) -> DdsResult<()> {
        self.driver().check_alive()?;
        self.registry()
            .delete_group::<SubscriberQos>(Arc::as_ptr(&subscriber.qos) as *const ())
    }
}

impl Subscriber {
    /// This subscriber's level of its readers' listener chain; `AlreadyDeleted` once deleted.
    pub(crate) fn listener_node(&self) -> DdsResult<Arc<ListenerNode>> {
        self.with_group(|g| g.node.clone())
    }

    /// Runs `f` on this subscriber's registry entry; `AlreadyDeleted` once deleted.
    fn with_group<R>(
        &self,
        f: impl FnOnce(&mut Group<SubscriberQos, DataReaderQos>) -> R,
    ) -> DdsResult<R> {
        self.participant.driver().check_alive()?;
        self.participant
            .registry()
            .with_group::<SubscriberQos, R>(Arc::as_ptr(&self.qos) as *const (), f)
    }

    /// The readers of this subscriber still alive.
    fn readers(&self) -> DdsResult<Vec<Child>> {
        let handle = self.instance_handle()?;
        Ok(self
            .participant
            .registry()
            .children::<SubscriberQos>(handle))
    }

    /// The subscriber's handle (`get_instance_handle`).
    pub fn instance_handle(&self) -> DdsResult<InstanceHandle> {
        self.with_group(|g| g.node.handle)
    }

    /// The QoS in effect (`get_qos`).
    pub fn get_qos(&self) -> DdsResult<SubscriberQos> {
        self.with_group(|g| g.qos.clone())
    }

    /// Changes the QoS (`set_qos`): PARTITION and GROUP_DATA may change, and every reader announces them
    /// again (matches follow the new partitions); PRESENTATION cannot (`ImmutablePolicy`).
    pub fn set_qos(&self, qos: &SubscriberQos) -> DdsResult<()> {
        self.participant.driver().check_alive()?;
        let ptr = Arc::as_ptr(&self.qos) as *const ();
        for e in self.participant.registry().set_group_qos(ptr, qos)? {
            if let Some(e) = e.upgrade() {
                e.group_changed();
            }
        }
        Ok(())
    }

    /// Installs the subscriber listener for the statuses in `mask` of its readers that have no listener of
    /// their own enabled for them, and for DATA_ON_READERS (`set_listener`).
    pub fn set_listener(
        &self,
        listener: Box<dyn SubscriberListener>,
        mask: StatusMask,
    ) -> DdsResult<()> {
        let l: Arc<dyn ParentListener> = Arc::new(SubscriberLevel {
            listener: Arc::from(listener),
            participant: self.participant.downgrade(),
            qos: Arc::downgrade(&self.qos),
            access: Arc::downgrade(&self.access),
        });
        self.with_group(|g| g.node.set_listener(Some((l, mask))))
    }

    /// Removes the subscriber listener.
    pub fn clear_listener(&self) -> DdsResult<()> {
        self.with_group(|g| g.node.set_listener(None))
    }

    /// The subscriber's status condition: DATA_ON_READERS, and the statuses of its readers.
    pub fn status_condition(&self) -> DdsResult<StatusCondition> {
        self.with_group(|g| StatusCondition {
            core: g.node.status.clone(),
        })
    }

    /// Enables the subscriber (`enable`): `PreconditionNotMet` while its participant is disabled. With
    /// `autoenable_created_entities`, the readers it created disabled are enabled too.
    pub fn enable(&self) -> DdsResult<()> {
        self.participant.driver().check_alive()?;
        self.participant
            .registry()
            .enable_group::<SubscriberQos>(Arc::as_ptr(&self.qos) as *const ())
    }

    /// Whether the subscriber is enabled.
    pub fn is_enabled(&self) -> bool {
        let registry = self.participant.registry();
        self.instance_handle().is_ok_and(|h| registry.is_enabled(h))
    }

    /// Sets the default reader QoS (`set_default_datareader_qos`).
    pub fn set_default_datareader_qos(&self, qos: &DataReaderQos) -> DdsResult<()> {
        self.with_group(|g| g.child_default = qos.clone())
    }

    /// The default reader QoS (`get_default_datareader_qos`), to pass to `create_datareader`.
    pub fn default_datareader_qos(&self) -> DdsResult<DataReaderQos> {
        self.with_group(|g| g.child_default.clone())
    }

    /// `copy_from_topic_qos`: the topic's values for the policies readers and topics share.
    pub fn copy_from_topic_qos(&self, qos: &mut DataReaderQos, topic_qos: &TopicQos) {
        let own = (
            qos.user_data.clone(),
            qos.time_based_filter,
            qos.reader_data_lifecycle,
        );
        *qos = DataReaderQos::from_topic(topic_qos);
        (
            qos.user_data,
            qos.time_based_filter,
            qos.reader_data_lifecycle,
        ) = own;
    }

    /// Deletes `reader` (`delete_datareader`): it leaves SEDP and its handles return `AlreadyDeleted`
    /// from then on. `PreconditionNotMet` for a reader of another subscriber.
    pub fn delete_datareader<T: DdsType>(&self, reader: &DataReader<T>) -> DdsResult<()> {
        if !Arc::ptr_eq(&reader.subscriber().qos, &self.qos) {
            return Err(DdsError::PreconditionNotMet(
                "the reader belongs to another subscriber",
            ));
        }
        reader.inner.state.delete()
    }

    /// A reader of this subscriber on the topic `topic_name` (`lookup_datareader`), `None` when there is
    /// none or it has another type.
    pub fn lookup_datareader<T: DdsType>(
        &self,
        topic_name: &str,
    ) -> DdsResult<Option<DataReader<T>>> {
        let handle = self.instance_handle()?;
        let inner = self
            .participant
            .registry()
            .find_child::<SubscriberQos, ReaderInner<Typed<T>>>(handle, topic_name);
        Ok(inner.and_then(|inner| {
            let handle = inner.state.handle()?;
            Some(DataReader { inner, handle })
        }))
    }

    /// Deletes every reader of this subscriber (`delete_contained_entities`).
    pub fn delete_contained_entities(&self) -> DdsResult<()> {
        let handle = self.instance_handle()?;
        for id in self
            .participant
            .registry()
            .delete_children::<SubscriberQos>(handle)
        {
            self.participant.driver().delete_endpoint(id);
        }
        Ok(())
    }

    /// The handles of the readers holding samples in these states (`get_datareaders`; readers are typed,
    /// so they are returned by handle: look them up with [`lookup_datareader`](Self::lookup_datareader)).
    pub fn get_datareaders(
        &self,
        samples: SampleStateMask,
        views: ViewStateMask,
        instances: InstanceStateMask,
    ) -> DdsResult<Vec<InstanceHandle>> {
        let prefix = self.participant.driver().guid_prefix;
        let handle = |id| InstanceHandle::from_guid(crate::rtps::Guid::new(prefix, id));
        let readers = self.readers()?;
        if group_ordered(&self.get_qos()?.presentation) {
            return Ok(group_order(&readers, samples, views, instances)
                .into_iter()
                .map(handle)
                .collect());
        }
        Ok(readers
            .into_iter()
            .filter(|r| {
                r.entity
                    .upgrade()
                    .is_some_and(|e| e.has_samples(samples, views, instances))
            })
            .map(|r| handle(r.id))
            .collect())
    }

    /// Calls `on_data_available` of every reader of this subscriber that has unread data and a listener
    /// (`notify_datareaders`, for use in `on_data_on_readers`).
    pub fn notify_datareaders(&self) -> DdsResult<()> {
        for r in self.readers()? {
            if let Some(e) = r.entity.upgrade() {
                if e.has_samples(
                    SampleStateMask::NOT_READ,
                    ViewStateMask::ANY,
                    InstanceStateMask::ANY,
                ) {
                    e.notify_data_available();
                }
            }
        }
        Ok(())
    }
}

/// GROUP ordered access: the readers once per sample in these states, in the order the subscriber received
/// the samples (the readers number their samples from one counter).
fn group_order(
    readers: &[Child],
    samples: SampleStateMask,
    views: ViewStateMask,
    instances: InstanceStateMask,
) -> Vec<EntityId> {
    let mut order: Vec<(u64, EntityId)> = Vec::new();
    let mut seqs = Vec::new();
    for r in readers {
        if let Some(e) = r.entity.upgrade() {
            seqs.clear();
            e.sample_order(samples, views, instances, &mut seqs);
            order.extend(seqs.iter().map(|&n| (n, r.id)));
        }
    }
    order.sort_unstable_by_key(|&(n, _)| n);
    order.into_iter().map(|(_, id)| id).collect()
}

impl<T: DdsType> DataReader<T> {
    /// The QoS in effect, with the changes of [`set_qos`](Self::set_qos) (`get_qos`).
    pub fn get_qos(&self) -> DdsResult<DataReaderQos> {
        self.inner.state.check_alive()?;
        Ok(lock(&self.inner.cache).cache.qos().clone())
    }

    /// Changes the QoS (`set_qos`). DEADLINE, LATENCY_BUDGET, USER_DATA, TIME_BASED_FILTER and
    /// READER_DATA_LIFECYCLE may change: the reader applies them from the next sample or check, and
    /// announces them again in SEDP. The others cannot (`ImmutablePolicy`), unless the reader is still
    /// disabled: then every policy may change (DDS 1.4 §2.2.2.1.1.7). A time-based filter longer than the
    /// deadline is `InconsistentPolicy`. An empty `data_representation` keeps the current one.
    pub fn set_qos(&self, qos: &DataReaderQos) -> DdsResult<()> {
        self.inner.state.check_alive()?;
        let mut new = qos.clone();
        if new.time_based_filter.minimum_separation > new.deadline.0 {
            return Err(DdsError::InconsistentPolicy(
                "time-based filter separation longer than the deadline",
            ));
        }
        let current = lock(&self.inner.cache).cache.qos().clone();
        if new.data_representation.ids().is_empty() {
            new.data_representation = current.data_representation.clone();
        }
        // The core is called without the cache lock (the core lock comes first, as in `refresh_credit`).
        match current.immutable_change(&new) {
            Some(p) if self.is_enabled() => return Err(DdsError::ImmutablePolicy(p)),
            // A disabled reader has received nothing: its cache takes the new history and limits as is.
            Some(_) => self.respecify(&new)?,
            None => self.announce(new.clone())?,
        }
        lock(&self.inner.cache).cache.set_qos(new);
        Ok(())
    }

    /// `set_qos` with immutable changes on a disabled reader: the core rebuilds the reader (it refuses
    /// once the reader is enabled) and is given the new credit.
    fn respecify(&self, new: &DataReaderQos) -> DdsResult<()> {
        check_history(&new.history)?;
        let rq = ReaderQos::new(
            new.clone(),
            &self.subscriber().get_qos()?,
            &self.topic().get_qos()?,
        );
        let id = self.handle.id();
        let credit = super::credit_limit(new);
        self.inner.state.driver.with_core(|c, _| {
            c.respecify_disabled_reader(id, rq)?;
            c.set_reader_credit(id, credit);
            Ok::<_, crate::rtps::CoreError>(())
        })?;
        self.inner.credit_limit.store(
            credit.unwrap_or(super::NO_CREDIT_LIMIT),
            std::sync::atomic::Ordering::Relaxed,
        );
        Ok(())
    }

    /// Announces `qos` with the subscriber's and topic's current parts. A reader of a built-in topic
    /// (the built-in subscriber's, or one the application created) has no RTPS reader and is announced
    /// nowhere: its cache alone takes the new QoS.
    pub(super) fn announce(&self, qos: DataReaderQos) -> DdsResult<()> {
        let id = self.handle.id();
        if id.is_builtin() {
            return Ok(());
        }
        let sq = self.subscriber().get_qos()?;
        let tq = self.topic().get_qos()?;
        let rq = ReaderQos::new(qos, &sq, &tq);
        self.inner
            .state
            .driver
            .with_core(|c, now| c.update_reader_qos(now, id, rq))?;
        Ok(())
    }

    /// Installs a listener enabled for the statuses in `mask` only (`set_listener` with a mask); the other
    /// statuses go to the subscriber's or participant's listener.
    pub fn set_listener_with_mask(
        &self,
        listener: Box<dyn DataReaderListener<T>>,
        mask: StatusMask,
    ) {
        self.inner
            .state
            .set_listener_with_mask(Some(Arc::from(listener)), mask);
    }

    /// Enables the reader (`enable`): it is announced in SEDP and matched from now on.
    /// `PreconditionNotMet` while its subscriber or topic is disabled; nothing when enabled already.
    pub fn enable(&self) -> DdsResult<()> {
        let (group, topic) = (self.subscriber(), self.topic());
        let registry = group.participant().registry();
        self.inner.state.enable_under(registry, || {
            Ok([group.instance_handle()?, topic.instance_handle()?])
        })
    }

    /// Whether the reader is enabled.
    pub fn is_enabled(&self) -> bool {
        self.inner.state.check_enabled().is_ok()
    }

    /// The key of the instance `handle` (`get_key_value`): a sample whose key members are the instance's
    /// and whose other members are defaulted. `BadParameter` for an unknown handle.
    pub fn get_key_value(&self, handle: InstanceHandle) -> DdsResult<T> {
        self.inner.state.check_alive()?;
        lock(&self.inner.cache)
            .cache
            .key_holder(handle)
            .and_then(key_holder)
            .ok_or_else(|| DdsError::BadParameter(format!("unknown instance handle {handle:?}")))
    }

    /// What discovery announced about the matched writer `handle` (`get_matched_publication_data`);
    /// `BadParameter` when it is not matched.
    pub fn get_matched_publication_data(
        &self,
        handle: InstanceHandle,
    ) -> DdsResult<PublicationBuiltinTopicData> {
        self.inner.state.check_alive()?;
        let guid = self
            .matched_publication_guids()
            .into_iter()
            .find(|g| InstanceHandle::from_guid(*g) == handle)
            .ok_or_else(|| DdsError::BadParameter(format!("no matched writer {handle:?}")))?;
        self.inner
            .state
            .driver
            .with_core(|c, _| c.publication(&guid).map(PublicationBuiltinTopicData::from))
            .ok_or_else(|| DdsError::BadParameter(format!("no matched writer {handle:?}")))
    }

    /// `delete_contained_entities` of a reader: its read conditions hold no resources here, so there is
    /// nothing to delete; `AlreadyDeleted` once the reader was deleted.
    pub fn delete_contained_entities(&self) -> DdsResult<()> {
        self.inner.state.check_alive()
    }

    /// Deletes a read condition of this reader (`delete_readcondition`): conditions hold no resources
    /// here, so this only checks that `condition` is this reader's (`PreconditionNotMet` otherwise).
    pub fn delete_readcondition(&self, condition: &ReadCondition) -> DdsResult<()> {
        let ours = Arc::as_ptr(&self.inner) as *const ();
        if Arc::as_ptr(&condition.source) as *const () == ours {
            Ok(())
        } else {
            Err(DdsError::PreconditionNotMet(
                "the condition belongs to another reader",
            ))
        }
    }
}
