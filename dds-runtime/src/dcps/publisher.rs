//! `Publisher` and `DataWriter<T>`.

use std::sync::{Arc, Mutex, MutexGuard, Weak};
use std::time::{Duration, Instant, SystemTime};

use foldhash::HashMap;

use crate::cdr::{self, ByteOrder, DdsType, XcdrVersion};
use crate::qos::{
    DataRepresentation, DataWriterQos, PublisherQos, Reliability, WriterQos,
    XCDR2_DATA_REPRESENTATION, XCDR_DATA_REPRESENTATION,
};
use crate::rtps::{
    ChangeKind, EntityId, Event, Guid, Payload, Time, WriteChange, WriteError, WriterSpec,
};

use super::condition::{StatusCondition, StatusCore};
use super::error::{DdsError, DdsResult};
use super::listener::DataWriterListener;
use super::participant::{DomainParticipant, Shared, WriterSink};
use super::sample::InstanceHandle;
use super::status::{
    DeadlineMissedStatus, IncompatibleQosStatus, PublicationMatchedStatus, StatusMask,
    WriterStatuses,
};
use super::topic::Topic;

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Groups writers; carries the partition and presentation QoS.
#[derive(Clone)]
pub struct Publisher {
    participant: DomainParticipant,
    qos: Arc<PublisherQos>,
}

impl std::fmt::Debug for Publisher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Publisher").field("qos", &self.qos).finish()
    }
}

/// The XCDR version a writer with `rep` uses, and the representation list it announces.
pub(crate) fn writer_version<T: DdsType>(
    rep: &DataRepresentation,
) -> (XcdrVersion, DataRepresentation) {
    if rep.ids().is_empty() {
        let v = T::DEFAULT_VERSION;
        let id = match v {
            XcdrVersion::Xcdr1 => XCDR_DATA_REPRESENTATION,
            XcdrVersion::Xcdr2 => XCDR2_DATA_REPRESENTATION,
        };
        (v, DataRepresentation::any_of([id]))
    } else if rep.offered() == XCDR2_DATA_REPRESENTATION {
        (XcdrVersion::Xcdr2, rep.clone())
    } else {
        (XcdrVersion::Xcdr1, rep.clone())
    }
}

impl Publisher {
    pub(crate) fn new(participant: DomainParticipant, qos: PublisherQos) -> Self {
        Publisher {
            participant,
            qos: Arc::new(qos),
        }
    }

    /// The publisher QoS.
    pub fn qos(&self) -> &PublisherQos {
        &self.qos
    }

    /// The participant.
    pub fn participant(&self) -> &DomainParticipant {
        &self.participant
    }

    /// Creates a writer. An empty `data_representation` means the type's default (XCDR1 for @final types
    /// without optional members, else XCDR2, as Cyclone DDS does).
    pub fn create_datawriter<T: DdsType>(
        &self,
        topic: &Topic<T>,
        qos: &DataWriterQos,
    ) -> DdsResult<DataWriter<T>> {
        let shared = self.participant.shared.clone();
        shared.check_alive()?;
        let (version, rep) = writer_version::<T>(&qos.data_representation);
        let mut wq = qos.clone();
        wq.data_representation = rep;
        if let crate::qos::History::KeepLast(0) = wq.history {
            return Err(DdsError::BadParameter("history depth 0".into()));
        }
        let spec = WriterSpec {
            topic_name: topic.name().to_string(),
            type_name: T::TYPE_NAME.to_string(),
            keyed: T::IS_KEYED,
            qos: WriterQos::new(wq.clone(), &self.qos, topic.qos()),
            type_information: None,
            entity_name: None,
        };
        let inner = Arc::new(WriterInner::<T> {
            shared: shared.clone(),
            id: Mutex::new(EntityId::UNKNOWN),
            qos: wq,
            version,
            instances: Mutex::new(WriterInstances::default()),
            statuses: Mutex::new(WriterStatuses::default()),
            status_core: Arc::new(StatusCore::default()),
            listener: Mutex::new(None),
            matched: Mutex::new(Vec::new()),
            handle: Mutex::new(Weak::new()),
        });
        // Register before the core can report matches for it; the id is known only after creation, so the
        // core lock is held across both (match events are only polled after `f` returns).
        let sink: Arc<dyn WriterSink> = inner.clone();
        let id = shared.with_core(|c, now| {
            let id = c.create_writer(now, spec)?;
            *lock(&inner.id) = id;
            shared.register_writer(id, sink);
            Ok::<_, crate::rtps::CoreError>(id)
        });
        let id = id.map_err(|e| DdsError::Core(e.to_string()))?;
        let handle = Arc::new(WriterHandle {
            inner: inner.clone(),
            participant: self.participant.clone(),
            topic: topic.clone(),
            publisher: self.clone(),
            id,
        });
        *lock(&inner.handle) = Arc::downgrade(&handle);
        tracing::info!(
            topic = topic.name(),
            type_name = T::TYPE_NAME,
            ?id,
            ?version,
            "writer created"
        );
        Ok(DataWriter { inner, handle })
    }
}

/// One instance the writer knows (registered or written).
struct WriterInstance {
    key: Vec<u8>,
    /// `cdr::serialize_key` output, sent with dispose/unregister.
    key_payload: Payload,
    key_hash: Option<[u8; 16]>,
    /// Last write, for the offered deadline.
    last_write: Instant,
}

#[derive(Default)]
struct WriterInstances {
    by_key: HashMap<Vec<u8>, InstanceHandle>,
    by_handle: HashMap<InstanceHandle, WriterInstance>,
    next: u64,
    /// Last write of a keyless topic (its single instance), for the offered deadline.
    keyless_last_write: Option<Instant>,
}

struct WriterInner<T: DdsType> {
    shared: Arc<Shared>,
    id: Mutex<EntityId>,
    qos: DataWriterQos,
    version: XcdrVersion,
    instances: Mutex<WriterInstances>,
    statuses: Mutex<WriterStatuses>,
    status_core: Arc<StatusCore>,
    listener: Mutex<Option<Arc<dyn DataWriterListener<T>>>>,
    matched: Mutex<Vec<Guid>>,
    handle: Mutex<Weak<WriterHandle<T>>>,
}

struct WriterHandle<T: DdsType> {
    inner: Arc<WriterInner<T>>,
    participant: DomainParticipant,
    topic: Topic<T>,
    publisher: Publisher,
    id: EntityId,
}

impl<T: DdsType> Drop for WriterHandle<T> {
    fn drop(&mut self) {
        let shared = &self.participant.shared;
        shared.unregister_writer(self.id);
        if shared.check_alive().is_ok() {
            let id = self.id;
            // Like Cyclone: a deleted writer unregisters its instances (disposing them too with
            // autodispose_unregistered_instances), so readers see the state change, not just the unmatch.
            let kind = self.inner.unregister_kind();
            let ts = Some(wire_time(SystemTime::now()));
            let changes: Vec<WriteChange> = lock(&self.inner.instances)
                .by_handle
                .values()
                .map(|i| WriteChange {
                    kind,
                    payload: i.key_payload.clone(),
                    key_hash: i.key_hash,
                    source_timestamp: ts,
                })
                .collect();
            shared.with_core(|c, now| {
                for ch in changes {
                    if let Err(e) = c.write(now, id, ch) {
                        tracing::debug!(error = %e, "unregister on delete not sent");
                    }
                }
                c.delete_writer(now, id)
            });
        }
        tracing::debug!(id = ?self.id, "writer deleted");
    }
}

/// Writes samples of type `T`. Cheap to clone; the writer is deleted when the last clone is dropped (a
/// reliable writer lingers in the core until its data is acknowledged).
///
/// QoS enforced on the writer side by the RTPS core: reliability, durability (volatile, transient-local),
/// history, resource limits, partitions, ownership strength (announced). Here: writer data lifecycle
/// (autodispose on unregister and on deletion), offered deadline missed (checked every 50 ms per instance).
/// Lifespan is announced and applied by readers. Liveliness other than automatic is not implemented.
pub struct DataWriter<T: DdsType> {
    inner: Arc<WriterInner<T>>,
    handle: Arc<WriterHandle<T>>,
}

impl<T: DdsType> Clone for DataWriter<T> {
    fn clone(&self) -> Self {
        DataWriter {
            inner: self.inner.clone(),
            handle: self.handle.clone(),
        }
    }
}

impl<T: DdsType> std::fmt::Debug for DataWriter<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DataWriter")
            .field("topic", &self.handle.topic.name())
            .field("id", &self.handle.id)
            .finish()
    }
}

/// Runs `f` on a cleared per-thread buffer (a fresh one if the thread's is in use), so that serializing a
/// sample or its key allocates nothing once the buffer has grown.
fn with_scratch<R>(f: impl FnOnce(&mut Vec<u8>) -> R) -> R {
    thread_local! {
        static SCRATCH: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
    }
    SCRATCH.with(|cell| {
        let mut fresh = Vec::new();
        let mut guard = cell.try_borrow_mut().ok();
        let buf = guard.as_deref_mut().unwrap_or(&mut fresh);
        buf.clear();
        let r = f(buf);
        // Do not keep a huge buffer alive for the thread's lifetime after one large sample.
        if buf.capacity() > 1 << 20 {
            *buf = Vec::new();
        }
        r
    })
}

fn wire_time(t: SystemTime) -> Time {
    Time::from_unix(t.duration_since(SystemTime::UNIX_EPOCH).unwrap_or_default())
}

impl<T: DdsType> DataWriter<T> {
    fn id(&self) -> EntityId {
        self.handle.id
    }

    /// The writer's GUID.
    pub fn guid(&self) -> [u8; 16] {
        Guid::new(self.inner.shared.guid_prefix, self.id()).to_bytes()
    }

    /// The writer's handle (as readers see it in `SampleInfo::publication_handle`).
    pub fn instance_handle(&self) -> InstanceHandle {
        InstanceHandle::from_guid_bytes(&self.guid())
    }

    /// The topic.
    pub fn topic(&self) -> &Topic<T> {
        &self.handle.topic
    }

    /// The publisher.
    pub fn publisher(&self) -> &Publisher {
        &self.handle.publisher
    }

    /// The QoS in effect (with the data representation resolved).
    pub fn qos(&self) -> &DataWriterQos {
        &self.inner.qos
    }

    /// The XCDR version samples are written with.
    pub fn data_representation(&self) -> XcdrVersion {
        self.inner.version
    }

    /// Serializes into a per-thread scratch buffer and copies the bytes once into the shared payload: one
    /// allocation per sample instead of a growing `Vec` plus its conversion into an `Arc<[u8]>`.
    fn serialize(&self, sample: &T) -> DdsResult<Payload> {
        with_scratch(|buf| {
            cdr::serialize(sample, self.inner.version, ByteOrder::NATIVE, buf)?;
            Ok(Payload::copy_from_slice(buf))
        })
    }

    fn key_hash(&self, sample: &T) -> DdsResult<Option<[u8; 16]>> {
        if T::IS_KEYED {
            Ok(Some(cdr::key_hash(sample, self.inner.version)?))
        } else {
            Ok(None)
        }
    }

    /// Hands one change to the core, waiting up to max_blocking_time while flow control refuses it.
    fn submit(&self, change: WriteChange) -> DdsResult<()> {
        let shared = &self.inner.shared;
        shared.check_alive()?;
        let max_block = match self.inner.qos.reliability {
            Reliability::Reliable { max_blocking_time } => max_blocking_time,
            Reliability::BestEffort => Duration::ZERO,
        };
        // Only a refused write needs the clock.
        let mut deadline: Option<Option<Instant>> = None;
        let id = self.id();
        loop {
            let seen = shared.progress_generation();
            match shared.with_core(|c, now| c.write(now, id, change.clone())) {
                Ok(_) => return Ok(()),
                Err(WriteError::WouldBlock) => {
                    let now = Instant::now();
                    let deadline = *deadline.get_or_insert_with(|| now.checked_add(max_block));
                    match deadline {
                        Some(d) if now >= d => return Err(DdsError::Timeout),
                        Some(d) => shared.wait_progress_change(seen, d),
                        None => shared.wait_progress_change(seen, now + Duration::from_millis(20)),
                    }
                    shared.check_alive()?;
                }
                Err(WriteError::TooLarge(n)) => {
                    return Err(DdsError::BadParameter(format!(
                        "sample of {n} bytes is too large"
                    )))
                }
                Err(WriteError::Deleted) | Err(WriteError::UnknownWriter(_)) => {
                    return Err(DdsError::AlreadyDeleted)
                }
                Err(e) => return Err(DdsError::Core(e.to_string())),
            }
        }
    }

    /// Sends at once what write batching holds back; the participant's batches are shared by its writers,
    /// so this sends theirs too.
    pub fn flush(&self) {
        self.inner.shared.flush();
    }

    /// Publishes `sample` with the current time as source timestamp.
    pub fn write(&self, sample: &T) -> DdsResult<()> {
        self.write_w_timestamp(sample, SystemTime::now())
    }

    /// Publishes `sample` with the given source timestamp.
    pub fn write_w_timestamp(&self, sample: &T, timestamp: SystemTime) -> DdsResult<()> {
        let payload = self.serialize(sample)?;
        // Keyed writes register the instance, so that deleting the writer can unregister it.
        let key_hash = if T::IS_KEYED {
            self.instance_of(sample, true, false)?
                .and_then(|(_, kh)| kh)
        } else {
            None
        };
        let change = WriteChange {
            kind: ChangeKind::Alive,
            payload,
            key_hash,
            source_timestamp: Some(wire_time(timestamp)),
        };
        tracing::trace!(writer = ?self.id(), "write");
        self.submit(change)
    }

    /// The instance of `sample` (by serialized key) and its key hash; registers it when `create`, and
    /// records a write when `written`.
    fn instance_of(
        &self,
        sample: &T,
        create: bool,
        written: bool,
    ) -> DdsResult<Option<(InstanceHandle, Option<[u8; 16]>)>> {
        let found = with_scratch(|key| -> DdsResult<_> {
            cdr::instance_key(sample, key)?;
            let mut inst = lock(&self.inner.instances);
            let Some(h) = inst.by_key.get(key.as_slice()).copied() else {
                return Ok(None);
            };
            let Some(i) = inst.by_handle.get_mut(&h) else {
                return Ok(None);
            };
            if written {
                i.last_write = Instant::now();
            }
            Ok(Some((h, i.key_hash)))
        })?;
        if found.is_some() || !create {
            return Ok(found);
        }
        let mut key = Vec::new();
        cdr::instance_key(sample, &mut key)?;
        let now = Instant::now();
        let mut inst = lock(&self.inner.instances);
        // Another thread may have registered it since the lookup above.
        if let Some(h) = inst.by_key.get(&key).copied() {
            if let Some(i) = inst.by_handle.get(&h) {
                return Ok(Some((h, i.key_hash)));
            }
        }
        let mut kp = Vec::new();
        cdr::serialize_key(sample, self.inner.version, ByteOrder::NATIVE, &mut kp)?;
        let kh = self.key_hash(sample)?;
        inst.next += 1;
        let h = InstanceHandle(inst.next);
        inst.by_key.insert(key.clone(), h);
        inst.by_handle.insert(
            h,
            WriterInstance {
                key,
                key_payload: Payload::from(kp),
                key_hash: kh,
                last_write: now,
            },
        );
        Ok(Some((h, kh)))
    }

    /// Registers the instance of `sample` and returns its handle (nothing is sent).
    pub fn register_instance(&self, sample: &T) -> DdsResult<InstanceHandle> {
        if !T::IS_KEYED {
            return Ok(InstanceHandle::NIL);
        }
        Ok(self
            .instance_of(sample, true, false)?
            .map_or(InstanceHandle::NIL, |(h, _)| h))
    }

    /// The handle of the instance of `sample`, if registered (or written through a handle operation).
    pub fn lookup_instance(&self, sample: &T) -> DdsResult<Option<InstanceHandle>> {
        Ok(self.instance_of(sample, false, false)?.map(|(h, _)| h))
    }

    fn key_change(
        &self,
        kind: ChangeKind,
        sample: Option<&T>,
        handle: InstanceHandle,
        ts: SystemTime,
    ) -> DdsResult<()> {
        if !T::IS_KEYED {
            return Err(DdsError::PreconditionNotMet("the topic type has no key"));
        }
        let h = match sample {
            Some(s) => self
                .instance_of(s, true, false)?
                .map_or(InstanceHandle::NIL, |(h, _)| h),
            None => handle,
        };
        let (payload, key_hash) = {
            let inst = lock(&self.inner.instances);
            match inst.by_handle.get(&h) {
                Some(i) => (i.key_payload.clone(), i.key_hash),
                None => {
                    return Err(DdsError::BadParameter(format!(
                        "unknown instance handle {h:?}"
                    )))
                }
            }
        };
        let change = WriteChange {
            kind,
            payload,
            key_hash,
            source_timestamp: Some(wire_time(ts)),
        };
        self.submit(change)?;
        if matches!(kind, ChangeKind::Unregister | ChangeKind::DisposeUnregister) {
            let mut inst = lock(&self.inner.instances);
            if let Some(i) = inst.by_handle.remove(&h) {
                inst.by_key.remove(&i.key);
            }
        }
        Ok(())
    }

    /// Unregisters the instance of `sample`; with `autodispose_unregistered_instances` (the default) it is
    /// disposed too.
    pub fn unregister_instance(&self, sample: &T) -> DdsResult<()> {
        self.key_change(
            self.inner.unregister_kind(),
            Some(sample),
            InstanceHandle::NIL,
            SystemTime::now(),
        )
    }

    /// Unregisters by handle.
    pub fn unregister_instance_w_handle(&self, handle: InstanceHandle) -> DdsResult<()> {
        self.key_change(
            self.inner.unregister_kind(),
            None,
            handle,
            SystemTime::now(),
        )
    }

    /// Disposes the instance of `sample`.
    pub fn dispose(&self, sample: &T) -> DdsResult<()> {
        self.key_change(
            ChangeKind::Dispose,
            Some(sample),
            InstanceHandle::NIL,
            SystemTime::now(),
        )
    }

    /// Disposes by handle.
    pub fn dispose_w_handle(&self, handle: InstanceHandle) -> DdsResult<()> {
        self.key_change(ChangeKind::Dispose, None, handle, SystemTime::now())
    }

    /// Disposes with an explicit source timestamp.
    pub fn dispose_w_timestamp(&self, sample: &T, ts: SystemTime) -> DdsResult<()> {
        self.key_change(ChangeKind::Dispose, Some(sample), InstanceHandle::NIL, ts)
    }

    /// Blocks until every matched reliable reader acknowledged everything written, or `Timeout`.
    pub fn wait_for_acknowledgments(&self, timeout: Duration) -> DdsResult<()> {
        let shared = &self.inner.shared;
        shared.check_alive()?;
        let id = self.id();
        let deadline = Instant::now().checked_add(timeout);
        if shared.wait_progress(deadline, || shared.with_core(|c, _| c.is_acknowledged(id))) {
            Ok(())
        } else {
            shared.check_alive()?;
            Err(DdsError::Timeout)
        }
    }

    /// PUBLICATION_MATCHED (resets the change counts).
    pub fn publication_matched_status(&self) -> PublicationMatchedStatus {
        let mut st = lock(&self.inner.statuses);
        let s = st.publication_matched.clone();
        st.publication_matched.total_count_change = 0;
        st.publication_matched.current_count_change = 0;
        self.inner
            .status_core
            .clear(StatusMask::PUBLICATION_MATCHED);
        s
    }

    /// OFFERED_INCOMPATIBLE_QOS (resets the change count).
    pub fn offered_incompatible_qos_status(&self) -> IncompatibleQosStatus {
        let mut st = lock(&self.inner.statuses);
        let s = st.offered_incompatible_qos.clone();
        st.offered_incompatible_qos.total_count_change = 0;
        self.inner
            .status_core
            .clear(StatusMask::OFFERED_INCOMPATIBLE_QOS);
        s
    }

    /// OFFERED_DEADLINE_MISSED (resets the change count). Checked every 50 ms per written instance.
    pub fn offered_deadline_missed_status(&self) -> DeadlineMissedStatus {
        let mut st = lock(&self.inner.statuses);
        let s = st.offered_deadline_missed.clone();
        st.offered_deadline_missed.total_count_change = 0;
        self.inner
            .status_core
            .clear(StatusMask::OFFERED_DEADLINE_MISSED);
        s
    }

    /// Handles of the matched readers.
    pub fn matched_subscriptions(&self) -> Vec<InstanceHandle> {
        lock(&self.inner.matched)
            .iter()
            .map(|g| InstanceHandle::from_guid_bytes(&g.to_bytes()))
            .collect()
    }

    /// GUIDs of the matched readers.
    pub fn matched_subscription_guids(&self) -> Vec<[u8; 16]> {
        lock(&self.inner.matched)
            .iter()
            .map(|g| g.to_bytes())
            .collect()
    }

    /// Installs a listener (replacing any previous one).
    pub fn set_listener(&self, listener: Box<dyn DataWriterListener<T>>) {
        *lock(&self.inner.listener) = Some(Arc::from(listener));
    }

    /// Removes the listener.
    pub fn clear_listener(&self) {
        *lock(&self.inner.listener) = None;
    }

    /// The writer's status condition.
    pub fn status_condition(&self) -> StatusCondition {
        StatusCondition {
            core: self.inner.status_core.clone(),
        }
    }
}

impl<T: DdsType> WriterInner<T> {
    fn unregister_kind(&self) -> ChangeKind {
        if self
            .qos
            .writer_data_lifecycle
            .autodispose_unregistered_instances
        {
            ChangeKind::DisposeUnregister
        } else {
            ChangeKind::Unregister
        }
    }

    fn writer_handle(self: &Arc<Self>) -> Option<DataWriter<T>> {
        let handle = lock(&self.handle).upgrade()?;
        Some(DataWriter {
            inner: self.clone(),
            handle,
        })
    }
}

impl<T: DdsType> WriterSink for WriterInner<T> {
    fn tick(self: Arc<Self>, now: Instant) {
        let period = self.qos.deadline.0;
        if period == crate::qos::INFINITE || period.is_zero() {
            return;
        }
        let mut missed = Vec::new();
        {
            let mut inst = lock(&self.instances);
            for (h, i) in inst.by_handle.iter_mut() {
                if now.saturating_duration_since(i.last_write) >= period {
                    i.last_write = now;
                    missed.push(*h);
                }
            }
            if let Some(t) = inst.keyless_last_write.as_mut() {
                if now.saturating_duration_since(*t) >= period {
                    *t = now;
                    missed.push(InstanceHandle::NIL);
                }
            }
        }
        if missed.is_empty() {
            return;
        }
        let status = {
            let mut st = lock(&self.statuses);
            let dm = &mut st.offered_deadline_missed;
            dm.total_count += missed.len() as u32;
            dm.total_count_change += missed.len() as u32;
            dm.last_instance_handle = *missed.last().unwrap_or(&InstanceHandle::NIL);
            dm.clone()
        };
        self.status_core.raise(StatusMask::OFFERED_DEADLINE_MISSED);
        let listener = lock(&self.listener).clone();
        if let (Some(l), Some(w)) = (listener, self.writer_handle()) {
            l.on_offered_deadline_missed(&w, status);
        }
    }

    fn on_event(self: Arc<Self>, ev: &Event) {
        let listener = lock(&self.listener).clone();
        match ev {
            Event::PublicationMatched {
                reader, matched, ..
            } => {
                let status = {
                    let mut m = lock(&self.matched);
                    let mut st = lock(&self.statuses);
                    let pm = &mut st.publication_matched;
                    if *matched {
                        if !m.contains(reader) {
                            m.push(*reader);
                            pm.total_count += 1;
                            pm.total_count_change += 1;
                            pm.current_count_change += 1;
                        }
                    } else if let Some(p) = m.iter().position(|g| g == reader) {
                        m.remove(p);
                        pm.current_count_change -= 1;
                    }
                    pm.current_count = m.len() as u32;
                    pm.last_subscription_handle =
                        InstanceHandle::from_guid_bytes(&reader.to_bytes());
                    let out = pm.clone();
                    // A listener consumes the status: the next callback reports only newer changes.
                    if listener.is_some() {
                        pm.total_count_change = 0;
                        pm.current_count_change = 0;
                    }
                    out
                };
                tracing::info!(writer = ?lock(&self.id), ?reader, matched, "publication matched");
                self.status_core.raise(StatusMask::PUBLICATION_MATCHED);
                if let (Some(l), Some(w)) = (listener, self.writer_handle()) {
                    l.on_publication_matched(&w, status);
                }
            }
            Event::OfferedIncompatibleQos { policy, reader, .. } => {
                let status = {
                    let mut st = lock(&self.statuses);
                    st.offered_incompatible_qos.record(*policy);
                    st.offered_incompatible_qos.clone()
                };
                tracing::warn!(writer = ?lock(&self.id), ?reader, ?policy, "offered incompatible QoS");
                self.status_core.raise(StatusMask::OFFERED_INCOMPATIBLE_QOS);
                if let (Some(l), Some(w)) = (listener, self.writer_handle()) {
                    l.on_offered_incompatible_qos(&w, status);
                }
            }
            _ => {}
        }
    }
}
