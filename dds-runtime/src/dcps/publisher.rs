//! `Publisher` and `DataWriter<T>`.

mod events;
#[cfg(feature = "shm")]
mod loan;
mod ops;
mod shared;

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering as AtomicOrdering};
use std::sync::{Arc, Mutex, RwLock, Weak};
use std::time::{Duration, Instant, SystemTime};

use foldhash::HashMap;

use crate::cdr::{self, ByteOrder, DdsType, XcdrVersion};
use crate::qos::{
    DataRepresentation, DataWriterQos, PublisherQos, Reliability, WriterQos,
    XCDR2_DATA_REPRESENTATION,
};
use crate::rtps::{
    ChangeKind, EntityId, Event, Guid, Payload, Time, WriteChange, WriteError, WriterSpec,
};

use super::condition::StatusCondition;
use super::driver::{Endpoint, EndpointHandle};
use super::endpoint::{check_history, EndpointState};
use super::error::{DdsError, DdsResult};
use super::participant::DomainParticipant;
use super::presentation::CoherentGroup;
use super::registry::Registered;
use super::sample::InstanceHandle;
use super::status::{
    DeadlineMissedStatus, IncompatibleQosStatus, LivelinessLostStatus, PublicationMatchedStatus,
    StatusMask,
};
use super::sync::{lock, read};
use super::topic::Topic;
use super::writer_filter::WriterFilters;
use crate::rtps::pool::BufferPool;

pub(crate) use events::{
    check_offered_deadline, offers_deadline, on_writer_event, requested_qos, unregister_kind,
    writer_callbacks, WriterCallbacks, WriterState,
};
#[cfg(feature = "shm")]
pub use loan::{LoanError, SampleLoan};
pub(crate) use ops::register_writer;
pub use ops::PublisherListener;

/// Callbacks of a [`DataWriter`] (see [`crate::dcps::listener`]). Every method has an empty default.
#[allow(unused_variables)]
pub trait DataWriterListener<T: DdsType>: Send + Sync {
    /// A reader matched or unmatched.
    fn on_publication_matched(&self, writer: &DataWriter<T>, status: PublicationMatchedStatus) {}
    /// A reader was found with incompatible QoS.
    fn on_offered_incompatible_qos(&self, writer: &DataWriter<T>, status: IncompatibleQosStatus) {}
    /// The writer missed its offered deadline for an instance.
    fn on_offered_deadline_missed(&self, writer: &DataWriter<T>, status: DeadlineMissedStatus) {}
    /// The writer did not assert its manual liveliness within its lease.
    fn on_liveliness_lost(&self, writer: &DataWriter<T>, status: LivelinessLostStatus) {}
}

writer_callbacks!(@T: DdsType; dyn DataWriterListener<T>, DataWriter<T>);

/// Groups writers; carries the partition and presentation QoS.
#[derive(Clone)]
pub struct Publisher {
    participant: DomainParticipant,
    qos: Arc<PublisherQos>,
    group: Arc<CoherentGroup>,
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
        (v, v.into())
    } else if rep.offered() == XCDR2_DATA_REPRESENTATION {
        (XcdrVersion::Xcdr2, rep.clone())
    } else {
        (XcdrVersion::Xcdr1, rep.clone())
    }
}

impl DomainParticipant {
    /// Creates a publisher.
    pub fn create_publisher(&self, qos: &PublisherQos) -> DdsResult<Publisher> {
        self.driver().check_alive()?;
        let p = Publisher {
            participant: self.clone(),
            qos: Arc::new(qos.clone()),
            group: Arc::default(),
        };
        ops::register_publisher(&p);
        Ok(p)
    }
}

impl Publisher {
    /// The publisher QoS.
    pub fn qos(&self) -> &PublisherQos {
        &self.qos
    }

    /// The participant.
    pub fn participant(&self) -> &DomainParticipant {
        &self.participant
    }

    /// Starts a coherent set (DDS 1.4 §2.2.2.4.1.10): what every writer of this publisher writes until
    /// [`Publisher::end_coherent_changes`] reaches each matched reader as one whole, or not at all (a set
    /// cut short by the writer's deletion or loss is discarded). Calls nest; only the outermost pair
    /// counts. On the wire: `PID_COHERENT_SET` on every change and an end-of-set marker per writer.
    /// Readers hold each writer's part of the set until it is whole. With GROUP access scope the set is
    /// one group set across the writers (`PID_GROUP_COHERENT_SET`, `PID_WRITER_GROUP_INFO`): the
    /// subscribing participant delivers it once every writer's part arrived, or not at all.
    pub fn begin_coherent_changes(&self) -> DdsResult<()> {
        self.group.begin(self.participant.driver())
    }

    /// Ends the coherent set started by [`Publisher::begin_coherent_changes`]: every writer sends its
    /// end-of-set marker, waiting for flow control up to 1 s each (`Timeout` past it).
    /// `PreconditionNotMet` without a matching begin.
    pub fn end_coherent_changes(&self) -> DdsResult<()> {
        self.group
            .end(self.participant.driver(), Duration::from_secs(1))
    }

    /// Whether `other` is this publisher (a clone of it).
    pub(crate) fn is(&self, other: &Publisher) -> bool {
        Arc::ptr_eq(&self.qos, &other.qos)
    }

    /// Makes the new writer `id`, of any kind, take part in this publisher's coherent sets (and, with GROUP
    /// access scope, in its group).
    pub(crate) fn add_to_group(&self, id: EntityId, presentation: &crate::qos::Presentation) {
        self.group
            .add_writer(self.participant.driver(), id, presentation);
    }

    /// Creates a writer. An empty `data_representation` means the type's default (XCDR1 for @final types
    /// without optional members, else XCDR2, as Cyclone DDS does).
    pub fn create_datawriter<T: DdsType>(
        &self,
        topic: &Topic<T>,
        qos: &DataWriterQos,
    ) -> DdsResult<DataWriter<T>> {
        self.create_writer(topic, qos, None)
    }

    /// Creates a writer with its listener installed first, enabled for the statuses in `mask`
    /// (`create_datawriter` with a listener, DDS 1.4 §2.2.2.4.1.5): the listener gets every status of the
    /// writer from its creation on, including the matches with readers already known.
    pub fn create_datawriter_with_listener<T: DdsType>(
        &self,
        topic: &Topic<T>,
        qos: &DataWriterQos,
        listener: Box<dyn DataWriterListener<T>>,
        mask: StatusMask,
    ) -> DdsResult<DataWriter<T>> {
        self.create_writer(topic, qos, Some((Arc::from(listener), mask)))
    }

    fn create_writer<T: DdsType>(
        &self,
        topic: &Topic<T>,
        qos: &DataWriterQos,
        listener: Option<(Arc<dyn DataWriterListener<T>>, StatusMask)>,
    ) -> DdsResult<DataWriter<T>> {
        let driver = self.participant.driver().clone();
        let parent = ops::writer_parent(self, topic)?;
        let enabled = self
            .participant
            .registry()
            .group_creates_enabled::<PublisherQos>(Arc::as_ptr(&self.qos) as *const ())?;
        // The QoS in effect: a disabled publisher may have changed any policy since its creation.
        let group_qos = self.get_qos()?;
        let (version, rep) = writer_version::<T>(&qos.data_representation);
        let mut wq = qos.clone();
        wq.data_representation = rep;
        check_history(&wq.history)?;
        let spec = WriterSpec {
            topic_name: topic.name().to_string(),
            type_name: T::TYPE_NAME.to_string(),
            keyed: T::IS_KEYED,
            qos: WriterQos::new(wq.clone(), &group_qos, &topic.get_qos()?),
            type_information: crate::xtypes::announced_type_information_for(
                T::type_information(),
                T::type_mapping(),
            ),
            entity_name: None,
            content_filter: None,
            internal: false,
        };
        let fixed = WritePath::new(version, &wq.reliability);
        fixed.set_deadline(&wq);
        let inner = Arc::new(WriterInner::<T> {
            state: EndpointState::new(driver.clone()),
            current: RwLock::new(wq.clone()),
            fixed,
            instances: Mutex::new(WriterInstances::default()),
            filters: Mutex::new(WriterFilters::default()),
            payloads: Mutex::new(BufferPool::new(WRITER_POOL_BUFFERS, WRITER_POOL_BYTES)),
            bytes_needed: AtomicBool::new(true),
            #[cfg(feature = "shm")]
            direct_len: std::sync::atomic::AtomicUsize::new(0),
            #[cfg(feature = "shm")]
            direct_ok: AtomicBool::new(false),
        });
        let owner = WriterOwner {
            topic: topic.clone(),
            publisher: self.clone(),
        };
        inner.state.set_parent(parent);
        let sink: Arc<dyn Endpoint> = inner.clone();
        if !enabled {
            inner.state.set_created_disabled();
        }
        if let Some((l, mask)) = listener {
            inner.state.set_listener_with_mask(Some(l), mask);
        }
        let handle = inner.state.create(sink, owner, |c, now| {
            super::participant::register_local_types::<T>(c);
            if enabled {
                c.create_writer(now, spec)
            } else {
                c.create_writer_disabled(now, spec)
            }
        })?;
        let entity: Weak<dyn Registered> = Arc::downgrade(&inner) as Weak<WriterInner<T>>;
        ops::register_writer(self, &inner.state, entity, topic.name());
        let id = handle.id();
        self.add_to_group(id, &group_qos.presentation);
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

/// The write path's view of the writer's immutable policies: the XCDR version (DATA_REPRESENTATION) and
/// how long a write may block (RELIABILITY). Set at creation, and again by a `set_qos` while the writer is
/// disabled, when immutable policies may still change; atomics, so a write reads them without a lock.
struct WritePath {
    xcdr2: AtomicBool,
    max_block_nanos: AtomicU64,
    /// Whether an offered deadline is set (DEADLINE, changeable): only then does a write read the clock
    /// for its instance's last-write time.
    deadline: AtomicBool,
}

impl WritePath {
    fn new(version: XcdrVersion, reliability: &Reliability) -> Self {
        let p = WritePath {
            xcdr2: AtomicBool::new(false),
            max_block_nanos: AtomicU64::new(0),
            deadline: AtomicBool::new(false),
        };
        p.set(version, reliability);
        p
    }

    /// Records whether `qos` sets an offered deadline.
    fn set_deadline(&self, qos: &DataWriterQos) {
        let on = events::offers_deadline(qos);
        self.deadline.store(on, AtomicOrdering::Release);
    }

    fn has_deadline(&self) -> bool {
        self.deadline.load(AtomicOrdering::Acquire)
    }

    fn set(&self, version: XcdrVersion, reliability: &Reliability) {
        let block = match reliability {
            Reliability::Reliable { max_blocking_time } => *max_blocking_time,
            Reliability::BestEffort => Duration::ZERO,
        };
        let nanos = u64::try_from(block.as_nanos()).unwrap_or(u64::MAX);
        self.xcdr2
            .store(version == XcdrVersion::Xcdr2, AtomicOrdering::Relaxed);
        self.max_block_nanos.store(nanos, AtomicOrdering::Relaxed);
    }

    fn version(&self) -> XcdrVersion {
        if self.xcdr2.load(AtomicOrdering::Relaxed) {
            XcdrVersion::Xcdr2
        } else {
            XcdrVersion::Xcdr1
        }
    }

    fn max_block(&self) -> Duration {
        Duration::from_nanos(self.max_block_nanos.load(AtomicOrdering::Relaxed))
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

/// A writer's instance as a lookup by key finds it: its handle and key hash.
pub(crate) type FoundInstance = (InstanceHandle, Option<[u8; 16]>);

#[derive(Default)]
pub(crate) struct WriterInstances {
    /// Handle and key hash by serialized key: a write without an offered deadline looks here only.
    by_key: HashMap<Vec<u8>, FoundInstance>,
    /// The serialized key of the instance looked up last, and what `by_key` holds for it: a stream of one
    /// instance (a ping/pong) compares the key instead of hashing it. Forgotten with the instance.
    last: (Vec<u8>, Option<FoundInstance>),
    by_handle: HashMap<InstanceHandle, WriterInstance>,
    next: u64,
    /// Last write of a keyless topic (its single instance), for the offered deadline.
    keyless_last_write: Option<Instant>,
}

/// What a writer's handle keeps alive.
struct WriterOwner<T> {
    topic: Topic<T>,
    publisher: Publisher,
}

struct WriterInner<T: DdsType> {
    state: WriterState<dyn DataWriterListener<T>, WriterOwner<T>>,
    /// The QoS in effect (changed by `set_qos`).
    current: RwLock<DataWriterQos>,
    /// What the immutable policies fix for the write path.
    fixed: WritePath,
    instances: Mutex<WriterInstances>,
    /// Matched readers' content filters, for writer-side filtering.
    filters: Mutex<WriterFilters>,
    /// Serialized samples' buffers, reused once the history has let go of them.
    payloads: Mutex<BufferPool>,
    /// Whether the last typed write (`write_owned`, `write_shared`) needed the serialized form (readers
    /// beyond this participant, or a durable history): the next one serializes before taking the lock.
    bytes_needed: AtomicBool,
    /// The serialized length of the last large sample (0: none), for writing the next one straight into
    /// a shared-memory buffer of that size (`loan.rs`, `write_direct`).
    #[cfg(feature = "shm")]
    direct_len: std::sync::atomic::AtomicUsize,
    /// Whether the last loaned write found that the core needed no copy of the sample (`loan.rs`): the
    /// next `write_direct` then does not ask before loaning.
    #[cfg(feature = "shm")]
    direct_ok: AtomicBool,
}

/// Writes samples of type `T`. Cheap to clone; the writer is deleted when the last clone is dropped (a
/// reliable writer lingers in the core until its data is acknowledged).
///
/// QoS enforced on the writer side by the RTPS core: reliability, durability (volatile, transient-local),
/// history, resource limits, partitions, ownership strength (announced). Here: writer data lifecycle
/// (autodispose on unregister; a deleted writer only unregisters), offered deadline missed (checked every 50 ms per instance).
/// Lifespan is announced and applied by readers. Manual liveliness: see `assert_liveliness`; a writer that
/// fails to assert within its lease raises LIVELINESS_LOST.
pub struct DataWriter<T: DdsType> {
    inner: Arc<WriterInner<T>>,
    handle: Arc<EndpointHandle<WriterOwner<T>>>,
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
            .field("topic", &self.handle.owner().topic.name())
            .field("id", &self.handle.id())
            .finish()
    }
}

/// Buffers a writer's payload pool keeps: it grows to the most samples the writer had in flight at once,
/// up to 65 536 (the default 512 KiB window of 8-byte samples). With 4096 before, a writer further ahead
/// (a 16 B writer has about 26 000 samples in flight) allocated a buffer per write. A pool of 32 768 had
/// cost more CPU at 16 B in session 19 (a buffer reused 26 000 samples later is cold), so the pool now
/// prefetches a buffer's bytes one take ahead as well as its counts (`docs/performance.md`, "Allocations
/// per sample"). Measured again in session 21 against 4 096 in the same rounds: less CPU per sample at 16
/// and 64 B, not more.
const WRITER_POOL_BUFFERS: usize = 65_536;
/// Bytes of capacity a writer's payload pool keeps: the largest flow-control window (4 MiB) four times.
const WRITER_POOL_BYTES: usize = 16 << 20;

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
        self.handle.id()
    }

    /// The writer's GUID.
    pub fn guid(&self) -> Guid {
        self.handle.guid()
    }

    /// The writer's handle (as readers see it in `SampleInfo::publication_handle`).
    pub fn instance_handle(&self) -> InstanceHandle {
        InstanceHandle::from_guid(self.guid())
    }

    /// The topic.
    pub fn topic(&self) -> &Topic<T> {
        &self.handle.owner().topic
    }

    /// The publisher.
    pub fn publisher(&self) -> &Publisher {
        &self.handle.owner().publisher
    }

    /// The QoS in effect, with the data representation resolved (as [`get_qos`](Self::get_qos), for a
    /// writer not deleted).
    pub fn qos(&self) -> DataWriterQos {
        read(&self.inner.current).clone()
    }

    /// The XCDR version samples are written with.
    pub fn data_representation(&self) -> XcdrVersion {
        self.inner.fixed.version()
    }

    /// Serializes straight into a buffer of the writer's pool, which the payload shares: no copy, and
    /// no allocation once the pool holds the buffers the history has released.
    fn serialize(&self, sample: &T) -> DdsResult<Payload> {
        let version = self.inner.fixed.version();
        Ok(lock(&self.inner.payloads)
            .fill(|buf| cdr::serialize(sample, version, ByteOrder::NATIVE, buf))?)
    }

    fn key_hash(&self, sample: &T) -> DdsResult<Option<[u8; 16]>> {
        if T::IS_KEYED {
            Ok(Some(cdr::key_hash(sample, self.inner.fixed.version())?))
        } else {
            Ok(None)
        }
    }

    /// Hands one change to the core, waiting up to max_blocking_time while flow control refuses it. With the
    /// `sample`, the matched readers' content filters are evaluated on it (writer-side filtering).
    fn submit(&self, change: WriteChange, sample: Option<&T>) -> DdsResult<()> {
        let id = self.id();
        let mut attempt = |c: &mut crate::rtps::Participant, now| {
            let rejected = self.rejected_by_filters(c, sample);
            Some(c.write_filtered(now, id, change.clone(), rejected))
        };
        self.submit_with(&mut attempt, || Ok(())).map(drop)
    }

    /// The matched readers whose content filters reject `sample` (writer-side filtering).
    fn rejected_by_filters(&self, c: &crate::rtps::Participant, sample: Option<&T>) -> Vec<Guid> {
        let Some(s) = sample else {
            return Vec::new();
        };
        // Generation 0: no matched reader ever announced a filter (the common case), so no lock either.
        let generation = c.writer_filter_generation(self.id());
        if generation == 0 {
            return Vec::new();
        }
        lock(&self.inner.filters).rejected(c, self.id(), generation, s)
    }

    /// [`submit`](Self::submit) with the write done under the core's lock by `attempt`; when it does not
    /// write (`None`), `prepare` runs (lock released) and the write is tried again.
    fn submit_with<R>(
        &self,
        attempt: &mut impl FnMut(
            &mut crate::rtps::Participant,
            Instant,
        ) -> Option<Result<R, WriteError>>,
        mut prepare: impl FnMut() -> DdsResult<()>,
    ) -> DdsResult<R> {
        let driver = &self.inner.state.driver;
        self.inner.state.check_enabled()?;
        let max_block = self.inner.fixed.max_block();
        // Only a refused write needs the clock.
        let mut deadline: Option<Option<Instant>> = None;
        loop {
            let seen = driver.progress_generation();
            let Some(written) = driver.with_core_writing(|c, now| attempt(c, now)) else {
                prepare()?;
                continue;
            };
            match written {
                Ok(r) => return Ok(r),
                Err(WriteError::WouldBlock) => {
                    let now = Instant::now();
                    let deadline = *deadline.get_or_insert_with(|| now.checked_add(max_block));
                    match deadline {
                        Some(d) if now >= d => return Err(DdsError::Timeout),
                        Some(d) => driver.wait_progress_change(seen, d),
                        None => driver.wait_progress_change(seen, now + Duration::from_millis(20)),
                    }
                    driver.check_alive()?;
                }
                Err(WriteError::TooLarge(n)) => {
                    return Err(DdsError::BadParameter(format!(
                        "sample of {n} bytes is too large"
                    )))
                }
                Err(WriteError::Deleted) | Err(WriteError::UnknownWriter(_)) => {
                    return Err(DdsError::AlreadyDeleted)
                }
                Err(e) => return Err(DdsError::Write(e)),
            }
        }
    }

    /// Sends at once what write batching holds back; the participant's batches are shared by its writers,
    /// so this sends theirs too.
    pub fn flush(&self) {
        self.inner.state.driver.flush();
    }

    /// Publishes `sample` with the current time as source timestamp.
    pub fn write(&self, sample: &T) -> DdsResult<()> {
        self.write_w_timestamp(sample, SystemTime::now())
    }

    /// Publishes `sample` with the given source timestamp.
    pub fn write_w_timestamp(&self, sample: &T, timestamp: SystemTime) -> DdsResult<()> {
        #[cfg(feature = "shm")]
        if let Some(done) = self.write_direct(sample, timestamp) {
            return done;
        }
        let payload = self.serialize(sample)?;
        #[cfg(feature = "shm")]
        self.note_len(payload.len());
        let key_hash = self.written_instance(sample)?;
        let change = WriteChange {
            kind: ChangeKind::Alive,
            payload,
            key_hash,
            source_timestamp: Some(wire_time(timestamp)),
        };
        tracing::trace!(writer = ?self.id(), "write");
        self.submit(change, Some(sample))
    }

    /// Records a write of `sample`'s instance and gives its key hash (keyed writes register the instance,
    /// so that deleting the writer can unregister it).
    fn written_instance(&self, sample: &T) -> DdsResult<Option<[u8; 16]>> {
        if T::IS_KEYED {
            Ok(self.instance_of(sample, true, true)?.and_then(|(_, kh)| kh))
        } else {
            let mut inst = lock(&self.inner.instances);
            // Without an offered deadline only the first write reads the clock (whether it wrote).
            if self.inner.fixed.has_deadline() || inst.keyless_last_write.is_none() {
                inst.keyless_last_write = Some(Instant::now());
            }
            Ok(None)
        }
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
            // Only the offered deadline reads the last-write time: no clock read without one.
            let now = (written && self.inner.fixed.has_deadline()).then(Instant::now);
            Ok(lock(&self.inner.instances).lookup(key, now))
        })?;
        if found.is_some() || !create {
            return Ok(found);
        }
        let mut key = Vec::new();
        cdr::instance_key(sample, &mut key)?;
        let mut kp = Vec::new();
        cdr::serialize_key(
            sample,
            self.inner.fixed.version(),
            ByteOrder::NATIVE,
            &mut kp,
        )?;
        let kh = self.key_hash(sample)?;
        // Another thread may have registered it since the lookup above: `register` returns that one.
        let mut inst = lock(&self.inner.instances);
        Ok(Some(inst.register(
            key,
            Payload::from(kp),
            kh,
            Instant::now(),
        )))
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
        let change = lock(&self.inner.instances).key_change(h, kind, ts)?;
        self.submit(change, None)?;
        lock(&self.inner.instances).key_change_sent(h, kind);
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

    /// Asserts this writer's liveliness (MANUAL_BY_TOPIC or MANUAL_BY_PARTICIPANT): a HEARTBEAT with the
    /// liveliness flag to its matched readers. Writing a sample asserts it too.
    pub fn assert_liveliness(&self) -> DdsResult<()> {
        let driver = &self.inner.state.driver;
        self.inner.state.check_enabled()?;
        let id = self.id();
        driver.with_core(|c, now| c.assert_writer_liveliness(now, id));
        Ok(())
    }

    /// Blocks until every matched reliable reader acknowledged everything written, or `Timeout`.
    pub fn wait_for_acknowledgments(&self, timeout: Duration) -> DdsResult<()> {
        self.inner.state.check_enabled()?;
        self.inner
            .state
            .driver
            .wait_acknowledged(self.id(), timeout)
    }

    /// PUBLICATION_MATCHED (resets the change counts).
    pub fn publication_matched_status(&self) -> PublicationMatchedStatus {
        self.inner.state.publication_matched_status()
    }

    /// OFFERED_INCOMPATIBLE_QOS (resets the change count).
    pub fn offered_incompatible_qos_status(&self) -> IncompatibleQosStatus {
        self.inner.state.offered_incompatible_qos_status()
    }

    /// OFFERED_DEADLINE_MISSED (resets the change count). Checked every 50 ms per written instance.
    pub fn offered_deadline_missed_status(&self) -> DeadlineMissedStatus {
        self.inner.state.offered_deadline_missed_status()
    }

    /// LIVELINESS_LOST (resets the change count): how often this writer failed to assert its manual
    /// liveliness within its lease.
    pub fn liveliness_lost_status(&self) -> LivelinessLostStatus {
        self.inner.state.liveliness_lost_status()
    }

    /// Handles of the matched readers.
    pub fn matched_subscriptions(&self) -> Vec<InstanceHandle> {
        self.inner
            .state
            .matched()
            .into_iter()
            .map(InstanceHandle::from_guid)
            .collect()
    }

    /// GUIDs of the matched readers.
    pub fn matched_subscription_guids(&self) -> Vec<Guid> {
        self.inner.state.matched()
    }

    /// Installs a listener (replacing any previous one).
    pub fn set_listener(&self, listener: Box<dyn DataWriterListener<T>>) {
        self.inner.state.set_listener(Some(Arc::from(listener)));
    }

    /// Removes the listener.
    pub fn clear_listener(&self) {
        self.inner.state.set_listener(None);
    }

    /// The writer's status condition.
    pub fn status_condition(&self) -> StatusCondition {
        StatusCondition {
            core: self.inner.state.status_core().clone(),
        }
    }
}

impl<T: DdsType> WriterInner<T> {
    /// Applies `qos`'s offered deadline to the write path. Writes made without one did not record their
    /// time, so a deadline set now counts from now for every instance written so far.
    fn set_deadline(&self, qos: &DataWriterQos) {
        if !self.fixed.has_deadline() {
            lock(&self.instances).restart_deadlines(Instant::now());
        }
        self.fixed.set_deadline(qos);
    }

    fn unregister_kind(&self) -> ChangeKind {
        events::unregister_kind(&read(&self.current))
    }

    /// The public writer, for listeners.
    fn writer(
        self: &Arc<Self>,
    ) -> impl FnOnce(Arc<EndpointHandle<WriterOwner<T>>>) -> DataWriter<T> {
        let inner = self.clone();
        move |handle| DataWriter { inner, handle }
    }
}

impl<T: DdsType> Endpoint for WriterInner<T> {
    fn tick(self: Arc<Self>, now: Instant) {
        let period = read(&self.current).deadline.0;
        check_offered_deadline(&self.state, &self.instances, period, now, self.writer());
    }

    fn on_event(self: Arc<Self>, ev: &Event) {
        on_writer_event(&self.state, ev, || self.writer());
    }

    /// A deleted writer unregisters its instances, so readers see the state change, not just the unmatch
    /// ([`WriterInstances::farewell`]; the OMG suite's `Test_FinalInstanceState_2` expects
    /// NOT_ALIVE_NO_WRITERS from a publisher that simply ends).
    fn farewell(&self) -> Vec<WriteChange> {
        lock(&self.instances).farewell()
    }
}
