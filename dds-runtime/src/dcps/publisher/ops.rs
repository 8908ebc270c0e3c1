//! The rest of the `Publisher` and `DataWriter` operations (DDS 1.4 §2.2.2.4): QoS, listeners with masks,
//! explicit deletion, lookups, suspend/resume, the `_w_handle`/`_w_timestamp` variants, `get_key_value`
//! and the matched subscription data; and how publishers and writers enter the participant's registry.

use std::any::Any;
use std::sync::{Arc, Weak};
use std::time::{Duration, Instant, SystemTime};

use crate::cdr::{self, DdsType};
use crate::qos::{DataWriterQos, PublisherQos, TopicQos, WriterQos};
use crate::rtps::EntityId;

use super::super::builtin::SubscriptionBuiltinTopicData;
use super::super::chain::{ListenerNode, ParentListener, StatusChange};
use super::super::condition::StatusCondition;
use super::super::endpoint::check_history;
use super::super::error::{DdsError, DdsResult};
use super::super::participant::DomainParticipant;
use super::super::registry::{Child, EndpointEntry, Group, Registered};
use super::super::sample::InstanceHandle;
use super::super::status::*;
use super::super::sync::{lock, read, write};
use super::super::topic::Topic;
use super::{DataWriter, DataWriterListener, Publisher, WriterInner, WriterState};

/// Callbacks of a [`Publisher`] for the statuses of its writers that have no listener of their own
/// enabled for them (DDS 1.4 §2.2.4.1). Writers are identified by their instance handle. Every method has
/// an empty default.
#[allow(unused_variables)]
pub trait PublisherListener: Send + Sync {
    /// A writer matched or unmatched a reader.
    fn on_publication_matched(&self, writer: InstanceHandle, status: PublicationMatchedStatus) {}
    /// A writer found a reader with incompatible QoS.
    fn on_offered_incompatible_qos(&self, writer: InstanceHandle, status: IncompatibleQosStatus) {}
    /// A writer missed its offered deadline.
    fn on_offered_deadline_missed(&self, writer: InstanceHandle, status: DeadlineMissedStatus) {}
    /// A writer did not assert its manual liveliness within its lease.
    fn on_liveliness_lost(&self, writer: InstanceHandle, status: LivelinessLostStatus) {}
}

/// The publisher listener as a level of the chain.
struct PublisherLevel(Arc<dyn PublisherListener>);

impl ParentListener for PublisherLevel {
    fn on_status(&self, w: InstanceHandle, change: StatusChange) {
        match change {
            StatusChange::PublicationMatched(s) => self.0.on_publication_matched(w, s),
            StatusChange::OfferedIncompatibleQos(s) => self.0.on_offered_incompatible_qos(w, s),
            StatusChange::OfferedDeadlineMissed(s) => self.0.on_offered_deadline_missed(w, s),
            StatusChange::LivelinessLost(s) => self.0.on_liveliness_lost(w, s),
            _ => {}
        }
    }
    fn on_data_on_readers(&self, _subscriber: InstanceHandle) {}
}

/// Registers a new publisher in its participant.
pub(super) fn register_publisher(p: &Publisher) {
    let identity: Weak<dyn Any + Send + Sync> = Arc::downgrade(&p.qos) as Weak<PublisherQos>;
    let registry = p.participant.registry();
    let node = registry.add_group(identity, (*p.qos).clone());
    registry.created_by_participant(node.handle);
}

/// The publisher level of a new writer's listener chain; `AlreadyDeleted` for a deleted publisher.
/// Also `AlreadyDeleted` for a deleted topic.
pub(super) fn writer_parent<T: DdsType>(
    p: &Publisher,
    topic: &Topic<T>,
) -> DdsResult<Arc<ListenerNode>> {
    topic.check_alive()?;
    p.listener_node()
}

/// Registers a new writer of any kind (`entity`, with its status state `state`) in its participant, so
/// that its publisher counts it among its writers.
pub(crate) fn register_writer<L: ?Sized, O>(
    p: &Publisher,
    state: &WriterState<L, O>,
    entity: Weak<dyn Registered>,
    topic: &str,
) {
    let Some(group) = p.with_group(|g| g.node.handle).ok() else {
        return;
    };
    p.participant.registry().add_endpoint(
        true,
        EndpointEntry {
            group,
            topic: topic.to_string(),
            guid: state
                .handle()
                .map_or(crate::rtps::Guid::UNKNOWN, |h| h.guid()),
            deleted: Arc::downgrade(state.deleted_flag()),
            entity,
        },
    );
}

impl<T: DdsType> Registered for WriterInner<T> {
    fn as_any(self: Arc<Self>) -> Arc<dyn Any + Send + Sync> {
        self
    }
    fn group_changed(self: Arc<Self>) {
        if let Some(handle) = self.state.handle() {
            let qos = read(&self.current).clone();
            let w = DataWriter {
                inner: self,
                handle,
            };
            if let Err(e) = w.announce(qos) {
                tracing::debug!(error = %e, "writer QoS not announced again");
            }
        }
    }
    fn enable(self: Arc<Self>) -> DdsResult<()> {
        let handle = self.state.handle().ok_or(DdsError::AlreadyDeleted)?;
        DataWriter {
            inner: self,
            handle,
        }
        .enable()
    }
}

impl DomainParticipant {
    /// Deletes `publisher` (`delete_publisher`): `PreconditionNotMet` while it has writers. Its handles
    /// then return `AlreadyDeleted`.
    pub fn delete_publisher(&self, publisher: &Publisher) -> DdsResult<()> {
        self.driver().check_alive()?;
        self.registry()
            .delete_group::<PublisherQos>(Arc::as_ptr(&publisher.qos) as *const ())
    }
}

impl Publisher {
    /// This publisher's level of its writers' listener chain; `AlreadyDeleted` once deleted.
    pub(crate) fn listener_node(&self) -> DdsResult<Arc<ListenerNode>> {
        self.with_group(|g| g.node.clone())
    }

    /// Runs `f` on this publisher's registry entry; `AlreadyDeleted` once deleted.
    fn with_group<R>(
        &self,
        f: impl FnOnce(&mut Group<PublisherQos, DataWriterQos>) -> R,
    ) -> DdsResult<R> {
        self.participant.driver().check_alive()?;
        self.participant
            .registry()
            .with_group::<PublisherQos, R>(Arc::as_ptr(&self.qos) as *const (), f)
    }

    /// The writers of this publisher still alive.
    fn writers(&self) -> DdsResult<Vec<Child>> {
        let handle = self.instance_handle()?;
        Ok(self.participant.registry().children::<PublisherQos>(handle))
    }

    /// The publisher's handle (`get_instance_handle`).
    pub fn instance_handle(&self) -> DdsResult<InstanceHandle> {
        self.with_group(|g| g.node.handle)
    }

    /// The QoS in effect (`get_qos`).
    pub fn get_qos(&self) -> DdsResult<PublisherQos> {
        self.with_group(|g| g.qos.clone())
    }

    /// Changes the QoS (`set_qos`): PARTITION and GROUP_DATA may change, and every writer announces
    /// them again (matches follow the new partitions); PRESENTATION cannot (`ImmutablePolicy`).
    pub fn set_qos(&self, qos: &PublisherQos) -> DdsResult<()> {
        self.participant.driver().check_alive()?;
        let ptr = Arc::as_ptr(&self.qos) as *const ();
        for e in self.participant.registry().set_group_qos(ptr, qos)? {
            if let Some(e) = e.upgrade() {
                e.group_changed();
            }
        }
        Ok(())
    }

    /// Installs the publisher listener for the statuses in `mask` of its writers that have no listener of
    /// their own enabled for them (`set_listener`).
    pub fn set_listener(
        &self,
        listener: Box<dyn PublisherListener>,
        mask: StatusMask,
    ) -> DdsResult<()> {
        let l: Arc<dyn ParentListener> = Arc::new(PublisherLevel(Arc::from(listener)));
        self.with_group(|g| g.node.set_listener(Some((l, mask))))
    }

    /// Removes the publisher listener.
    pub fn clear_listener(&self) -> DdsResult<()> {
        self.with_group(|g| g.node.set_listener(None))
    }

    /// The publisher's status condition: it triggers when a status of one of its writers changes.
    pub fn status_condition(&self) -> DdsResult<StatusCondition> {
        self.with_group(|g| StatusCondition {
            core: g.node.status.clone(),
        })
    }

    /// Enables the publisher (`enable`): `PreconditionNotMet` while its participant is disabled. With
    /// `autoenable_created_entities`, the writers it created disabled are enabled too.
    pub fn enable(&self) -> DdsResult<()> {
        self.participant.driver().check_alive()?;
        self.participant
            .registry()
            .enable_group::<PublisherQos>(Arc::as_ptr(&self.qos) as *const ())
    }

    /// Whether the publisher is enabled.
    pub fn is_enabled(&self) -> bool {
        let registry = self.participant.registry();
        self.instance_handle().is_ok_and(|h| registry.is_enabled(h))
    }

    /// Sets the QoS `create_datawriter` callers get from [`default_datawriter_qos`](Self::default_datawriter_qos)
    /// (`set_default_datawriter_qos`).
    pub fn set_default_datawriter_qos(&self, qos: &DataWriterQos) -> DdsResult<()> {
        self.with_group(|g| g.child_default = qos.clone())
    }

    /// The default writer QoS (`get_default_datawriter_qos`), to pass to `create_datawriter`.
    pub fn default_datawriter_qos(&self) -> DdsResult<DataWriterQos> {
        self.with_group(|g| g.child_default.clone())
    }

    /// `copy_from_topic_qos`: the topic's values for the policies writers and topics share.
    pub fn copy_from_topic_qos(&self, qos: &mut DataWriterQos, topic_qos: &TopicQos) {
        let own = (
            qos.user_data.clone(),
            qos.ownership_strength,
            qos.writer_data_lifecycle,
        );
        *qos = DataWriterQos::from_topic(topic_qos);
        (
            qos.user_data,
            qos.ownership_strength,
            qos.writer_data_lifecycle,
        ) = own;
    }

    /// Deletes `writer` (`delete_datawriter`): it unregisters its instances (without disposing
    /// them, as Cyclone does), leaves SEDP, and its handles return `AlreadyDeleted` from then on.
    /// `PreconditionNotMet` for a writer of another publisher.
    pub fn delete_datawriter<T: DdsType>(&self, writer: &DataWriter<T>) -> DdsResult<()> {
        if !Arc::ptr_eq(&writer.publisher().qos, &self.qos) {
            return Err(DdsError::PreconditionNotMet(
                "the writer belongs to another publisher",
            ));
        }
        writer.inner.state.delete()
    }

    /// A writer of this publisher on the topic `topic_name` (`lookup_datawriter`), `None` when there is
    /// none or it has another type.
    pub fn lookup_datawriter<T: DdsType>(
        &self,
        topic_name: &str,
    ) -> DdsResult<Option<DataWriter<T>>> {
        let handle = self.instance_handle()?;
        let inner = self
            .participant
            .registry()
            .find_child::<PublisherQos, WriterInner<T>>(handle, topic_name);
        Ok(inner.and_then(|inner| {
            let handle = inner.state.handle()?;
            Some(DataWriter { inner, handle })
        }))
    }

    /// Deletes every writer of this publisher (`delete_contained_entities`).
    pub fn delete_contained_entities(&self) -> DdsResult<()> {
        let handle = self.instance_handle()?;
        for id in self
            .participant
            .registry()
            .delete_children::<PublisherQos>(handle)
        {
            self.participant.driver().delete_endpoint(id);
        }
        Ok(())
    }

    /// Blocks until every writer of this publisher has its data acknowledged by every matched reliable
    /// reader, or `Timeout` (`wait_for_acknowledgments`).
    pub fn wait_for_acknowledgments(&self, timeout: Duration) -> DdsResult<()> {
        let ids: Vec<EntityId> = self.writers()?.into_iter().map(|w| w.id).collect();
        let driver = self.participant.driver();
        let deadline = Instant::now().checked_add(timeout);
        let done = || ids.iter().all(|id| driver.is_acknowledged(*id));
        if driver.wait_progress(deadline, done) {
            Ok(())
        } else {
            driver.check_alive()?;
            Err(DdsError::Timeout)
        }
    }

    /// `suspend_publications`: a hint that many writes follow. Writes are not held back here (each write
    /// is sent as write batching decides); [`resume_publications`](Self::resume_publications) sends what
    /// write batching holds. Nests.
    pub fn suspend_publications(&self) -> DdsResult<()> {
        self.with_group(|g| g.suspended = g.suspended.saturating_add(1))
    }

    /// `resume_publications`: ends a [`suspend_publications`](Self::suspend_publications) and, at the
    /// outermost one, sends what write batching holds. `PreconditionNotMet` without a suspend.
    pub fn resume_publications(&self) -> DdsResult<()> {
        let outermost = self.with_group(|g| match g.suspended {
            0 => Err(DdsError::PreconditionNotMet(
                "publications are not suspended",
            )),
            n => {
                g.suspended = n - 1;
                Ok(n == 1)
            }
        })??;
        if outermost {
            self.participant.flush();
        }
        Ok(())
    }
}

impl<T: DdsType> DataWriter<T> {
    /// The QoS in effect, with the changes of [`set_qos`](Self::set_qos) (`get_qos`).
    pub fn get_qos(&self) -> DdsResult<DataWriterQos> {
        self.inner.state.check_alive()?;
        Ok(read(&self.inner.current).clone())
    }

    /// Changes the QoS (`set_qos`). DEADLINE, LATENCY_BUDGET, TRANSPORT_PRIORITY, LIFESPAN, USER_DATA,
    /// OWNERSHIP_STRENGTH and WRITER_DATA_LIFECYCLE may change: the writer applies them and announces them
    /// again in SEDP, so matched readers see the new strength and lifespan. The others cannot
    /// (`ImmutablePolicy`), unless the writer is still disabled: then every policy may change, and the
    /// writer is rebuilt with them (DDS 1.4 §2.2.2.1.1.7). An empty `data_representation` keeps the
    /// current one.
    pub fn set_qos(&self, qos: &DataWriterQos) -> DdsResult<()> {
        self.inner.state.check_alive()?;
        let (new, immutable) = super::requested_qos(&read(&self.inner.current), qos);
        if let Some(p) = immutable {
            if self.is_enabled() {
                return Err(DdsError::ImmutablePolicy(p));
            }
            return self.respecify(new);
        }
        *write(&self.inner.current) = new.clone();
        self.inner.set_deadline(&new);
        self.announce(new)
    }

    /// `set_qos` with immutable changes on a disabled writer: the core rebuilds the writer first (it
    /// refuses once the writer is enabled), then the write path takes the new version and blocking time.
    fn respecify(&self, new: DataWriterQos) -> DdsResult<()> {
        check_history(&new.history)?;
        let (version, rep) = super::writer_version::<T>(&new.data_representation);
        let new = DataWriterQos {
            data_representation: rep,
            ..new
        };
        let wq = WriterQos::new(
            new.clone(),
            &self.publisher().get_qos()?,
            &self.topic().get_qos()?,
        );
        let id = self.handle.id();
        self.inner
            .state
            .driver
            .with_core(|c, _| c.respecify_disabled_writer(id, wq))?;
        self.inner.fixed.set(version, &new.reliability);
        self.inner.set_deadline(&new);
        *write(&self.inner.current) = new;
        Ok(())
    }

    /// Announces `qos` with the publisher's and topic's current parts.
    fn announce(&self, qos: DataWriterQos) -> DdsResult<()> {
        let pq = self.publisher().get_qos()?;
        let tq = self.topic().get_qos()?;
        let id = self.handle.id();
        let wq = WriterQos::new(qos, &pq, &tq);
        self.inner
            .state
            .driver
            .with_core(|c, now| c.update_writer_qos(now, id, wq))?;
        Ok(())
    }

    /// Installs a listener enabled for the statuses in `mask` only (`set_listener` with a mask); the other
    /// statuses go to the publisher's or participant's listener.
    pub fn set_listener_with_mask(
        &self,
        listener: Box<dyn DataWriterListener<T>>,
        mask: StatusMask,
    ) {
        self.inner
            .state
            .set_listener_with_mask(Some(Arc::from(listener)), mask);
    }

    /// Enables the writer (`enable`): it is announced in SEDP and matched from now on.
    /// `PreconditionNotMet` while its publisher or topic is disabled; nothing when enabled already.
    pub fn enable(&self) -> DdsResult<()> {
        let (group, topic) = (self.publisher(), self.topic());
        let registry = group.participant().registry();
        self.inner.state.enable_under(registry, || {
            Ok([group.instance_handle()?, topic.instance_handle()?])
        })
    }

    /// Whether the writer is enabled.
    pub fn is_enabled(&self) -> bool {
        self.inner.state.check_enabled().is_ok()
    }

    /// Writes `sample` as an instance of `handle` (`write_w_handle`); `NIL` looks the instance up from the
    /// sample. `PreconditionNotMet` when the handle is not the sample's instance.
    pub fn write_w_handle(&self, sample: &T, handle: InstanceHandle) -> DdsResult<()> {
        self.check_handle(sample, handle)?;
        self.write(sample)
    }

    /// Writes `sample` with `timestamp` as an instance of `handle` (`write_w_timestamp` with a handle).
    pub fn write_w_handle_timestamp(
        &self,
        sample: &T,
        handle: InstanceHandle,
        timestamp: SystemTime,
    ) -> DdsResult<()> {
        self.check_handle(sample, handle)?;
        self.write_w_timestamp(sample, timestamp)
    }

    fn check_handle(&self, sample: &T, handle: InstanceHandle) -> DdsResult<()> {
        if handle.is_nil() || !T::IS_KEYED {
            return Ok(());
        }
        match self.lookup_instance(sample)? {
            Some(h) if h == handle => Ok(()),
            _ => Err(DdsError::PreconditionNotMet(
                "the handle is not the instance of the sample",
            )),
        }
    }

    /// Registers the instance of `sample` (`register_instance_w_timestamp`). Registration sends nothing,
    /// so the timestamp is not used.
    pub fn register_instance_w_timestamp(
        &self,
        sample: &T,
        _timestamp: SystemTime,
    ) -> DdsResult<InstanceHandle> {
        self.register_instance(sample)
    }

    /// Unregisters the instance of `sample` with `timestamp` as the source timestamp
    /// (`unregister_instance_w_timestamp`); disposed too with `autodispose_unregistered_instances`.
    pub fn unregister_instance_w_timestamp(
        &self,
        sample: &T,
        timestamp: SystemTime,
    ) -> DdsResult<()> {
        let kind = self.inner.unregister_kind();
        self.key_change(kind, Some(sample), InstanceHandle::NIL, timestamp)
    }

    /// Unregisters the instance `handle` with `timestamp` as the source timestamp.
    pub fn unregister_instance_w_handle_timestamp(
        &self,
        handle: InstanceHandle,
        timestamp: SystemTime,
    ) -> DdsResult<()> {
        let kind = self.inner.unregister_kind();
        self.key_change(kind, None, handle, timestamp)
    }

    /// The key of the instance `handle` (`get_key_value`): a sample whose key members are set and whose
    /// other members have their default values. `BadParameter` for an unknown handle.
    pub fn get_key_value(&self, handle: InstanceHandle) -> DdsResult<T> {
        self.inner.state.check_alive()?;
        let payload = lock(&self.inner.instances).key_payload(handle)?;
        Ok(cdr::deserialize_key::<T>(&payload)?)
    }

    /// What discovery announced about the matched reader `handle` (`get_matched_subscription_data`);
    /// `BadParameter` when it is not matched.
    pub fn get_matched_subscription_data(
        &self,
        handle: InstanceHandle,
    ) -> DdsResult<SubscriptionBuiltinTopicData> {
        self.inner.state.check_alive()?;
        let guid = self
            .matched_subscription_guids()
            .into_iter()
            .find(|g| InstanceHandle::from_guid(*g) == handle)
            .ok_or_else(|| DdsError::BadParameter(format!("no matched reader {handle:?}")))?;
        self.inner
            .state
            .driver
            .with_core(|c, _| {
                c.subscription(&guid)
                    .map(SubscriptionBuiltinTopicData::from)
            })
            .ok_or_else(|| DdsError::BadParameter(format!("no matched reader {handle:?}")))
    }
}
