//! [`DynamicWriter`]: its statuses, listener and status condition are the typed writer's
//! (`publisher::events`), and so are its instances (registered by serialized key, unregistered when it is
//! deleted), its QoS changes and its place under its publisher (listeners, coherent sets, registry).

use std::any::Any;
use std::sync::{Arc, Condvar, Mutex, RwLock, Weak};
use std::time::{Duration, Instant, SystemTime};

use crate::cdr::{ByteOrder, XcdrVersion};
use crate::qos::{DataWriterQos, Reliability, WriterQos, XCDR2_DATA_REPRESENTATION};
use crate::rtps::{ChangeKind, Event, Guid, Payload, Time, WriteChange, WriteError, WriterSpec};
use crate::xtypes::dynamic::{default_version, DynamicData};

use super::super::condition::StatusCondition;
use super::super::driver::{Endpoint, EndpointHandle};
use super::super::error::{DdsError, DdsResult};
use super::super::publisher::{
    check_offered_deadline, offers_deadline, on_writer_event, register_writer, requested_qos,
    writer_callbacks, Publisher, WriterInstances, WriterState,
};
use super::super::registry::Registered;
use super::super::sample::InstanceHandle;
use super::super::status::{
    DeadlineMissedStatus, IncompatibleQosStatus, LivelinessLostStatus, PublicationMatchedStatus,
    StatusMask,
};
use super::super::sync::{lock, read, write};
use super::DynamicTopic;

mod instances;

/// Callbacks of a [`DynamicWriter`], with the same statuses and the same delivery rules as the typed
/// writer's (see [`crate::dcps::listener`]). Every method has an empty default.
#[allow(unused_variables)]
pub trait DynamicWriterListener: Send + Sync {
    /// A reader matched or unmatched.
    fn on_publication_matched(&self, writer: &DynamicWriter, status: PublicationMatchedStatus) {}
    /// A reader was found with incompatible QoS.
    fn on_offered_incompatible_qos(&self, writer: &DynamicWriter, status: IncompatibleQosStatus) {}
    /// The writer missed its offered deadline for an instance.
    fn on_offered_deadline_missed(&self, writer: &DynamicWriter, status: DeadlineMissedStatus) {}
    /// The writer did not assert its manual liveliness within its lease.
    fn on_liveliness_lost(&self, writer: &DynamicWriter, status: LivelinessLostStatus) {}
}

writer_callbacks!(dyn DynamicWriterListener, DynamicWriter);

struct Owner {
    topic: DynamicTopic,
    publisher: Publisher,
}

struct Inner {
    version: XcdrVersion,
    max_block: Duration,
    /// The QoS in effect (changed by `set_qos`), with the data representation resolved.
    current: RwLock<DataWriterQos>,
    state: WriterState<dyn DynamicWriterListener, Owner>,
    /// The instances registered or written: for the offered deadline, dispose and unregister by handle, and
    /// the unregisters sent when the writer is deleted.
    instances: Mutex<WriterInstances>,
    /// Notified on every match change (`wait_for_readers`); guards nothing else.
    matched_lock: Mutex<()>,
    matched_cv: Condvar,
}

impl Inner {
    /// The public writer, for listeners.
    fn writer(self: &Arc<Self>) -> impl FnOnce(Arc<EndpointHandle<Owner>>) -> DynamicWriter {
        let inner = self.clone();
        move |handle| DynamicWriter { inner, handle }
    }
}

impl Endpoint for Inner {
    fn on_event(self: Arc<Self>, ev: &Event) {
        on_writer_event(&self.state, ev, || self.writer());
        if matches!(ev, Event::PublicationMatched { .. }) {
            let _g = lock(&self.matched_lock);
            self.matched_cv.notify_all();
        }
    }

    fn tick(self: Arc<Self>, now: Instant) {
        let period = read(&self.current).deadline.0;
        check_offered_deadline(&self.state, &self.instances, period, now, self.writer());
    }

    /// A deleted writer unregisters its instances, as a typed writer does.
    fn farewell(&self) -> Vec<WriteChange> {
        lock(&self.instances).farewell()
    }
}

impl Registered for Inner {
    fn as_any(self: Arc<Self>) -> Arc<dyn Any + Send + Sync> {
        self
    }
    fn group_changed(self: Arc<Self>) {
        if let Some(handle) = self.state.handle() {
            let qos = read(&self.current).clone();
            if let Err(e) = (DynamicWriter {
                inner: self,
                handle,
            })
            .announce(qos)
            {
                tracing::debug!(error = %e, "dynamic writer QoS not announced again");
            }
        }
    }
    /// Dynamic writers are created enabled.
    fn enable(self: Arc<Self>) -> DdsResult<()> {
        Ok(())
    }
}

/// Writes [`DynamicData`] samples of a [`DynamicTopic`]. Cheap to clone; deleted with its last clone.
#[derive(Clone)]
pub struct DynamicWriter {
    inner: Arc<Inner>,
    handle: Arc<EndpointHandle<Owner>>,
}

impl std::fmt::Debug for DynamicWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DynamicWriter")
            .field("topic", &self.handle.owner().topic.name())
            .finish()
    }
}

impl Publisher {
    /// Creates a writer of a dynamic topic. An empty `data_representation` means the type's default (XCDR1 for
    /// @final types without optional members, else XCDR2), as for typed writers.
    pub fn create_dynamic_writer(
        &self,
        topic: &DynamicTopic,
        qos: &DataWriterQos,
    ) -> DdsResult<DynamicWriter> {
        self.create_dynamic_w(topic, qos, None)
    }

    /// Creates a writer of a dynamic topic with its listener installed first, enabled for the statuses in
    /// `mask`: the listener sees every status of the writer from its creation on, including the matches
    /// with readers already known.
    pub fn create_dynamic_writer_with_listener(
        &self,
        topic: &DynamicTopic,
        qos: &DataWriterQos,
        listener: Box<dyn DynamicWriterListener>,
        mask: StatusMask,
    ) -> DdsResult<DynamicWriter> {
        self.create_dynamic_w(topic, qos, Some((Arc::from(listener), mask)))
    }

    fn create_dynamic_w(
        &self,
        topic: &DynamicTopic,
        qos: &DataWriterQos,
        listener: Option<(Arc<dyn DynamicWriterListener>, StatusMask)>,
    ) -> DdsResult<DynamicWriter> {
        let driver = self.participant().driver().clone();
        let parent = self.listener_node()?;
        let group_qos = self.get_qos()?;
        let ty = topic.dynamic_type();
        let mut wq = qos.clone();
        let version = if wq.data_representation.ids().is_empty() {
            let v = default_version(ty);
            wq.data_representation = v.into();
            v
        } else if wq.data_representation.offered() == XCDR2_DATA_REPRESENTATION {
            XcdrVersion::Xcdr2
        } else {
            XcdrVersion::Xcdr1
        };
        super::super::endpoint::check_history(&wq.history)?;
        let max_block = match wq.reliability {
            Reliability::Reliable { max_blocking_time } => max_blocking_time,
            Reliability::BestEffort => Duration::ZERO,
        };
        let spec = WriterSpec {
            topic_name: topic.name().to_string(),
            type_name: topic.type_name(),
            keyed: ty.is_keyed(),
            qos: WriterQos::new(wq.clone(), &group_qos, topic.qos()),
            type_information: topic.type_information(),
            entity_name: None,
            content_filter: None,
            internal: false,
        };
        let inner = Arc::new(Inner {
            version,
            max_block,
            current: RwLock::new(wq),
            state: WriterState::new(driver),
            instances: Mutex::new(WriterInstances::default()),
            matched_lock: Mutex::new(()),
            matched_cv: Condvar::new(),
        });
        inner.state.set_parent(parent);
        if let Some((l, mask)) = listener {
            inner.state.set_listener_with_mask(Some(l), mask);
        }
        let owner = Owner {
            topic: topic.clone(),
            publisher: self.clone(),
        };
        let sink: Arc<dyn Endpoint> = inner.clone();
        let handle = inner.state.create(sink, owner, |c, now| {
            topic.register_types(c);
            c.create_writer(now, spec)
        })?;
        let entity: Weak<dyn Registered> = Arc::downgrade(&inner) as Weak<Inner>;
        register_writer(self, &inner.state, entity, topic.name());
        let id = handle.id();
        self.add_to_group(id, &group_qos.presentation);
        tracing::info!(topic = topic.name(), type_name = %topic.type_name(), ?id, ?version, "dynamic writer created");
        Ok(DynamicWriter { inner, handle })
    }
}

impl Publisher {
    /// Deletes `writer` (`delete_datawriter` for a dynamic writer): it unregisters its instances (without
    /// disposing them), leaves SEDP, and its operations return `AlreadyDeleted` from then on.
    /// `PreconditionNotMet` for a writer of another publisher.
    pub fn delete_dynamic_writer(&self, writer: &DynamicWriter) -> DdsResult<()> {
        if !self.is(writer.publisher()) {
            return Err(DdsError::PreconditionNotMet(
                "the writer belongs to another publisher",
            ));
        }
        writer.inner.state.delete()
    }
}

fn wire_time(t: SystemTime) -> Time {
    Time::from_unix(t.duration_since(SystemTime::UNIX_EPOCH).unwrap_or_default())
}

impl DynamicWriter {
    /// The writer's GUID.
    pub fn guid(&self) -> Guid {
        self.handle.guid()
    }

    /// The topic.
    pub fn topic(&self) -> &DynamicTopic {
        &self.handle.owner().topic
    }

    /// The writer's handle (as readers see it in `SampleInfo::publication_handle`, and as its
    /// publisher's and participant's listeners name it).
    pub fn instance_handle(&self) -> InstanceHandle {
        InstanceHandle::from_guid(self.guid())
    }

    /// The publisher.
    pub fn publisher(&self) -> &Publisher {
        &self.handle.owner().publisher
    }

    /// The XCDR version samples are written with.
    pub fn data_representation(&self) -> XcdrVersion {
        self.inner.version
    }

    /// The readers matched now.
    pub fn matched_readers(&self) -> Vec<Guid> {
        self.inner.state.matched()
    }

    /// OFFERED_INCOMPATIBLE_QOS: readers on the topic not matched for a policy (`TypeConsistencyEnforcement`
    /// for a reader type not assignable from the writer's). Resets the change count.
    pub fn offered_incompatible_qos_status(&self) -> IncompatibleQosStatus {
        self.inner.state.offered_incompatible_qos_status()
    }

    /// PUBLICATION_MATCHED (resets the change counts).
    pub fn publication_matched_status(&self) -> PublicationMatchedStatus {
        self.inner.state.publication_matched_status()
    }

    /// OFFERED_DEADLINE_MISSED (resets the change count). Checked every 50 ms per written instance.
    pub fn offered_deadline_missed_status(&self) -> DeadlineMissedStatus {
        self.inner.state.offered_deadline_missed_status()
    }

    /// LIVELINESS_LOST (resets the change count).
    pub fn liveliness_lost_status(&self) -> LivelinessLostStatus {
        self.inner.state.liveliness_lost_status()
    }

    /// The writer's status condition (for a [`WaitSet`](crate::dcps::WaitSet)).
    pub fn status_condition(&self) -> StatusCondition {
        StatusCondition {
            core: self.inner.state.status_core().clone(),
        }
    }

    /// Installs a listener for every status (replacing any previous one).
    pub fn set_listener(&self, listener: Box<dyn DynamicWriterListener>) {
        self.inner.state.set_listener(Some(Arc::from(listener)));
    }

    /// Installs a listener enabled for the statuses in `mask` only (replacing any previous one).
    pub fn set_listener_with_mask(
        &self,
        listener: Box<dyn DynamicWriterListener>,
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

    /// Waits until at least `n` readers are matched; `false` on timeout.
    pub fn wait_for_readers(&self, n: usize, timeout: Duration) -> bool {
        let end = Instant::now() + timeout;
        let mut m = lock(&self.inner.matched_lock);
        while self.inner.state.matched().len() < n {
            let left = end.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return false;
            }
            m = self
                .inner
                .matched_cv
                .wait_timeout(m, left)
                .map_or_else(|e| e.into_inner().0, |r| r.0);
        }
        true
    }

    /// Waits until every matched reliable reader acknowledged everything written; `Timeout` past `timeout`.
    pub fn wait_for_acknowledgments(&self, timeout: Duration) -> DdsResult<()> {
        self.handle_driver()
            .wait_acknowledged(self.handle.id(), timeout)
    }

    fn check_type(&self, sample: &DynamicData) -> DdsResult<()> {
        if sample.dynamic_type() != self.topic().dynamic_type() {
            return Err(DdsError::BadParameter(format!(
                "a sample of {} for a writer of {}",
                sample.dynamic_type().name(),
                self.topic().type_name()
            )));
        }
        Ok(())
    }

    /// Publishes `sample` (of the topic's type) with the current time as source timestamp.
    pub fn write(&self, sample: &DynamicData) -> DdsResult<()> {
        self.write_w_timestamp(sample, SystemTime::now())
    }

    /// Publishes `sample` with the given source timestamp. Writing a sample of a keyed type registers its
    /// instance.
    pub fn write_w_timestamp(&self, sample: &DynamicData, timestamp: SystemTime) -> DdsResult<()> {
        self.check_type(sample)?;
        let mut buf = Vec::new();
        sample.serialize(self.inner.version, ByteOrder::NATIVE, &mut buf)?;
        let key_hash = if self.keyed() {
            self.instance_of(sample, true, true)?.and_then(|(_, kh)| kh)
        } else {
            lock(&self.inner.instances).keyless_written(Instant::now());
            None
        };
        self.submit(WriteChange {
            kind: ChangeKind::Alive,
            payload: Payload::from(buf),
            key_hash,
            source_timestamp: Some(wire_time(timestamp)),
        })
    }

    fn keyed(&self) -> bool {
        self.topic().dynamic_type().is_keyed()
    }

    /// Asserts this writer's liveliness (MANUAL_BY_TOPIC or MANUAL_BY_PARTICIPANT): a HEARTBEAT with the
    /// liveliness flag to its matched readers. Writing a sample asserts it too.
    pub fn assert_liveliness(&self) -> DdsResult<()> {
        self.inner.state.check_alive()?;
        let driver = self.handle_driver();
        let id = self.handle.id();
        driver.with_core(|c, now| c.assert_writer_liveliness(now, id));
        Ok(())
    }

    /// The QoS in effect, with the changes of [`set_qos`](Self::set_qos) and the data representation
    /// resolved.
    pub fn qos(&self) -> DataWriterQos {
        read(&self.inner.current).clone()
    }

    /// Changes the QoS, as [`DataWriter::set_qos`](crate::dcps::DataWriter::set_qos) does for an enabled
    /// writer: DEADLINE, LATENCY_BUDGET, TRANSPORT_PRIORITY, LIFESPAN, USER_DATA, OWNERSHIP_STRENGTH and
    /// WRITER_DATA_LIFECYCLE may change; the writer applies them and announces them again in SEDP. A
    /// change of any other policy is refused with [`DdsError::ImmutablePolicy`]. An empty
    /// `data_representation` keeps the current one. A deadline set where there was none counts from now.
    pub fn set_qos(&self, qos: &DataWriterQos) -> DdsResult<()> {
        self.inner.state.check_alive()?;
        let (new, immutable) = requested_qos(&read(&self.inner.current), qos);
        if let Some(p) = immutable {
            return Err(DdsError::ImmutablePolicy(p));
        }
        let old = std::mem::replace(&mut *write(&self.inner.current), new.clone());
        if !offers_deadline(&old) {
            lock(&self.inner.instances).restart_deadlines(Instant::now());
        }
        self.announce(new)
    }

    /// Announces `qos` with the publisher's current QoS and the topic's.
    fn announce(&self, qos: DataWriterQos) -> DdsResult<()> {
        let wq = WriterQos::new(qos, &self.publisher().get_qos()?, self.topic().qos());
        let id = self.handle.id();
        self.handle_driver()
            .with_core(|c, now| c.update_writer_qos(now, id, wq))?;
        Ok(())
    }

    /// Hands one change to the core, waiting up to max_blocking_time while flow control refuses it.
    fn submit(&self, change: WriteChange) -> DdsResult<()> {
        let driver = &self.handle_driver();
        let id = self.handle.id();
        let deadline = Instant::now() + self.inner.max_block;
        loop {
            self.inner.state.check_alive()?;
            let seen = driver.progress_generation();
            match driver.with_core_writing(|c, now| c.write(now, id, change.clone())) {
                Ok(_) => return Ok(()),
                Err(WriteError::WouldBlock) if Instant::now() < deadline => {
                    driver.wait_progress_change(seen, deadline)
                }
                Err(WriteError::WouldBlock) => return Err(DdsError::Timeout),
                Err(WriteError::Deleted) | Err(WriteError::UnknownWriter(_)) => {
                    return Err(DdsError::AlreadyDeleted)
                }
                Err(e) => return Err(DdsError::Write(e)),
            }
        }
    }

    fn handle_driver(&self) -> Arc<super::super::driver::Driver> {
        self.handle.owner().topic.participant().driver().clone()
    }
}
