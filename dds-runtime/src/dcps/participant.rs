//! `DomainParticipant`: owns the sans-I/O core, the transport and the timer thread, and routes the core's
//! events to the typed readers and writers.

use std::hash::{BuildHasher, Hasher};
use std::net::{IpAddr, SocketAddr, SocketAddrV4};
use std::sync::atomic::{AtomicBool, AtomicU16, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, RwLock, Weak};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime};

use foldhash::{HashMap, HashMapExt};

use crate::config::{Config, InterfaceSelection, ParticipantIndex, Peer};
use crate::qos::{PublisherQos, SubscriberQos, TopicQos};
use crate::rtps::{
    EntityId, Event, Guid, GuidPrefix, Locator, Participant, ParticipantConfig, Payload,
    ReceivedSample, Transmit,
};
use crate::transport::{Channel, Datagram, UdpTransport};

use super::condition::{StatusCondition, StatusCore};
use super::error::{DdsError, DdsResult};
use super::publisher::Publisher;
use super::sample::InstanceHandle;
use super::subscriber::Subscriber;
use super::topic::Topic;
use crate::cdr::DdsType;

/// What a reader cache is fed with, in the order the core produced it.
pub(crate) enum Pending {
    Sample(ReceivedSample),
    /// The writer unmatched (deleted, lost, or QoS changed).
    WriterGone(Guid),
}

/// The type-erased side of a typed reader that the participant drives.
pub(crate) trait ReaderSink: Send + Sync {
    /// Called with the core lock held: must only queue.
    fn enqueue(&self, item: Pending);
    /// Drains the queue into the cache and notifies; called without the core lock.
    fn process(self: Arc<Self>);
    /// A status event for this reader; called without the core lock.
    fn on_event(self: Arc<Self>, ev: &Event);
    /// Time-driven reader QoS.
    fn tick(self: Arc<Self>, now: Instant);
}

/// The type-erased side of a typed writer.
pub(crate) trait WriterSink: Send + Sync {
    fn on_event(self: Arc<Self>, ev: &Event);
    /// Time-driven writer QoS (offered deadline).
    fn tick(self: Arc<Self>, now: Instant);
}

/// What we learnt about a remote writer in SEDP that the reader-side QoS needs.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct RemoteWriterInfo {
    pub strength: i32,
    pub lifespan: Option<Duration>,
}

/// A participant discovered through SPDP.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DiscoveredParticipant {
    /// Its GUID prefix.
    pub guid_prefix: [u8; 12],
    /// Its handle.
    pub handle: InstanceHandle,
}

pub(crate) struct Shared {
    core: Mutex<Participant>,
    pub(crate) transport: UdpTransport,
    pub(crate) config: Config,
    pub(crate) guid_prefix: GuidPrefix,
    readers: RwLock<HashMap<EntityId, Arc<dyn ReaderSink>>>,
    writers: RwLock<HashMap<EntityId, Arc<dyn WriterSink>>>,
    remote_writers: Mutex<HashMap<Guid, RemoteWriterInfo>>,
    participants: Mutex<HashMap<GuidPrefix, DiscoveredParticipant>>,
    /// Bumped whenever the core processed input (acks may have arrived): flow control and
    /// wait_for_acknowledgments wait on it.
    progress: AtomicU64,
    /// Threads blocked on `progress_cv`: the notification (a futex syscall) is skipped when there are none.
    progress_waiters: AtomicUsize,
    progress_lock: Mutex<()>,
    progress_cv: Condvar,
    /// Bumped when the core's next timeout may have moved earlier than what the timer thread waits for.
    timer_gen: Mutex<TimerState>,
    timer_cv: Condvar,
    pub(crate) stopped: AtomicBool,
    timer_thread: Mutex<Option<JoinHandle<()>>>,
    pub(crate) status: Arc<StatusCore>,
    /// Payload buffers of sent datagrams, handed back to the core at the next `with_core`.
    spare_buffers: Mutex<Vec<Vec<u8>>>,
}

/// Most sent buffers kept for recycling.
const MAX_SPARE_BUFFERS: usize = 32;

#[derive(Default)]
struct TimerState {
    generation: u64,
    /// `Some(t)` while the timer thread sleeps until `t`; `None` while it works.
    waiting_until: Option<Instant>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

fn to_socket(l: &Locator) -> Option<SocketAddrV4> {
    match l.to_socket_addr()? {
        SocketAddr::V4(a) => Some(a),
        SocketAddr::V6(_) => None,
    }
}

fn locator(a: SocketAddrV4) -> Locator {
    Locator::udpv4(a.ip().octets(), a.port())
}

static PREFIX_COUNTER: AtomicU16 = AtomicU16::new(0);

/// Vendor id first (as Cyclone and Fast DDS do), then randomness, the process id and a counter.
fn new_guid_prefix() -> GuidPrefix {
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u128(
        SystemTime::now()
            .duration_since(SystemTime::UNIX_EPOCH)
            .unwrap_or_default()
            .as_nanos(),
    );
    let r = h.finish().to_be_bytes();
    let pid = std::process::id().to_be_bytes();
    let c = PREFIX_COUNTER.fetch_add(1, Ordering::Relaxed).to_be_bytes();
    let v = crate::rtps::VendorId::THIS.0;
    GuidPrefix([
        v[0], v[1], r[0], r[1], r[2], r[3], pid[0], pid[1], pid[2], pid[3], c[0], c[1],
    ])
}

impl Shared {
    /// Sends held batched writes; free when batching is off.
    pub(crate) fn flush(&self) {
        if self.config.write_batch_delay.is_some() {
            self.with_core(|c, _| c.flush());
        }
    }

    /// Runs `f` on the core, then (lock released) sends what it queued and dispatches its events.
    pub(crate) fn with_core<R>(&self, f: impl FnOnce(&mut Participant, Instant) -> R) -> R {
        let now = Instant::now();
        let mut batch: Vec<Transmit> = Vec::new();
        let mut deferred: Vec<Event> = Vec::new();
        let mut touched: Vec<(EntityId, Arc<dyn ReaderSink>)> = Vec::new();
        let (r, next_timeout) = {
            let mut core = lock(&self.core);
            // Sent datagram buffers go back to the core for reuse (saves an allocation per datagram).
            for buf in std::mem::take(&mut *lock(&self.spare_buffers)) {
                core.recycle(buf);
            }
            let r = f(&mut core, now);
            while let Some(t) = core.poll_transmit(now) {
                batch.push(t);
            }
            while let Some(ev) = core.poll_event() {
                self.route_locked(ev, &mut deferred, &mut touched);
            }
            (r, core.poll_timeout())
        };
        self.send_batch(&batch);
        {
            let mut spare = lock(&self.spare_buffers);
            for t in batch {
                if spare.len() < MAX_SPARE_BUFFERS {
                    spare.push(t.payload);
                }
            }
        }
        self.after_unlock(deferred, touched, next_timeout);
        r
    }

    /// Under the core lock: samples go to their reader's queue (keeps order); the rest is deferred.
    fn route_locked(
        &self,
        ev: Event,
        deferred: &mut Vec<Event>,
        touched: &mut Vec<(EntityId, Arc<dyn ReaderSink>)>,
    ) {
        let (reader, item) = match ev {
            Event::Sample(s) => (s.reader, Pending::Sample(s)),
            Event::SubscriptionMatched {
                reader,
                writer,
                matched: false,
            } => {
                deferred.push(Event::SubscriptionMatched {
                    reader,
                    writer,
                    matched: false,
                });
                (reader, Pending::WriterGone(writer))
            }
            other => {
                deferred.push(other);
                return;
            }
        };
        // Runs of samples for one reader (the common case) skip the registry lookup.
        if let Some((id, r)) = touched.last() {
            if *id == reader {
                r.enqueue(item);
                return;
            }
        }
        let readers = self.readers.read().unwrap_or_else(|e| e.into_inner());
        if let Some(r) = readers.get(&reader) {
            r.enqueue(item);
            if !touched.iter().any(|(id, _)| *id == reader) {
                touched.push((reader, r.clone()));
            }
        }
    }

    fn send_batch(&self, batch: &[Transmit]) {
        for t in batch {
            for d in &t.destinations {
                if let Some(a) = to_socket(d) {
                    self.transport.send_to(&t.payload, a);
                }
            }
        }
    }

    fn after_unlock(
        &self,
        deferred: Vec<Event>,
        touched: Vec<(EntityId, Arc<dyn ReaderSink>)>,
        next_timeout: Option<Instant>,
    ) {
        self.bump_progress();
        {
            // Wake the timer thread only when it sleeps past the core's new deadline; when it is busy, the
            // generation bump makes it re-read the deadline before sleeping.
            let mut t = lock(&self.timer_gen);
            match (t.waiting_until, next_timeout) {
                (None, _) => t.generation = t.generation.wrapping_add(1),
                (Some(w), Some(n)) if n < w => {
                    t.generation = t.generation.wrapping_add(1);
                    self.timer_cv.notify_all();
                }
                _ => {}
            }
        }
        for ev in deferred {
            self.dispatch_event(ev);
        }
        for (_, r) in touched {
            r.process();
        }
    }

    fn dispatch_event(&self, ev: Event) {
        tracing::debug!(event = ?ev, "core event");
        let reader_of = |id: &EntityId| {
            self.readers
                .read()
                .unwrap_or_else(|e| e.into_inner())
                .get(id)
                .cloned()
        };
        let writer_of = |id: &EntityId| {
            self.writers
                .read()
                .unwrap_or_else(|e| e.into_inner())
                .get(id)
                .cloned()
        };
        match &ev {
            Event::PublicationMatched { writer, .. }
            | Event::OfferedIncompatibleQos { writer, .. } => {
                if let Some(w) = writer_of(writer) {
                    w.on_event(&ev);
                }
            }
            Event::SubscriptionMatched { reader, .. }
            | Event::RequestedIncompatibleQos { reader, .. }
            | Event::LivelinessChanged { reader, .. }
            | Event::SampleLost { reader, .. } => {
                if let Some(r) = reader_of(reader) {
                    r.on_event(&ev);
                }
            }
            Event::ParticipantDiscovered(p) => {
                let prefix = p.guid_prefix;
                let mut b = [0u8; 16];
                b[..12].copy_from_slice(&prefix.0);
                lock(&self.participants).insert(
                    prefix,
                    DiscoveredParticipant {
                        guid_prefix: prefix.0,
                        handle: InstanceHandle::from_guid_bytes(&b),
                    },
                );
                tracing::info!(peer = ?prefix, "participant discovered");
            }
            Event::ParticipantLost { guid_prefix } => {
                lock(&self.participants).remove(guid_prefix);
                tracing::info!(peer = ?guid_prefix, "participant lost");
            }
            Event::PublicationDiscovered(w) => {
                let (guid, info) = remote_writer_info(w);
                lock(&self.remote_writers).insert(guid, info);
            }
            Event::PublicationRemoved { guid } => {
                lock(&self.remote_writers).remove(guid);
            }
            _ => {}
        }
    }

    pub(crate) fn remote_writer(&self, g: &Guid) -> RemoteWriterInfo {
        lock(&self.remote_writers)
            .get(g)
            .copied()
            .unwrap_or_default()
    }

    pub(crate) fn register_reader(&self, id: EntityId, sink: Arc<dyn ReaderSink>) {
        self.readers
            .write()
            .unwrap_or_else(|e| e.into_inner())
            .insert(id, sink);
    }
    pub(crate) fn unregister_reader(&self, id: EntityId) {
        self.readers
            .write()
            .unwrap_or_else(|e| e.into_inner())
            .remove(&id);
    }
    pub(crate) fn register_writer(&self, id: EntityId, sink: Arc<dyn WriterSink>) {
        self.writers
            .write()
            .unwrap_or_else(|e| e.into_inner())
            .insert(id, sink);
    }
    pub(crate) fn unregister_writer(&self, id: EntityId) {
        self.writers
            .write()
            .unwrap_or_else(|e| e.into_inner())
            .remove(&id);
    }

    pub(crate) fn check_alive(&self) -> DdsResult<()> {
        if self.stopped.load(Ordering::Acquire) {
            Err(DdsError::AlreadyDeleted)
        } else {
            Ok(())
        }
    }

    /// Records core progress and wakes whoever waits for it (flow control, wait_for_acknowledgments).
    fn bump_progress(&self) {
        self.progress.fetch_add(1, Ordering::SeqCst);
        // A waiter registers (under `progress_lock`) before re-reading the generation, so either it sees the
        // new generation or we see it registered and notify it after it released the lock in `wait`.
        if self.progress_waiters.load(Ordering::SeqCst) > 0 {
            let _g = lock(&self.progress_lock);
            self.progress_cv.notify_all();
        }
    }

    /// Sleeps until the progress generation differs from `seen` (or a notification / `left` passes).
    fn wait_progress_for(&self, seen: u64, left: Duration) {
        let g = lock(&self.progress_lock);
        self.progress_waiters.fetch_add(1, Ordering::SeqCst);
        if self.progress.load(Ordering::SeqCst) == seen && !self.stopped.load(Ordering::Acquire) {
            // Capped so that a missed notification costs at most a few milliseconds.
            let _g = self
                .progress_cv
                .wait_timeout(g, left.min(Duration::from_millis(20)))
                .unwrap_or_else(|e| e.into_inner());
        }
        self.progress_waiters.fetch_sub(1, Ordering::SeqCst);
    }

    /// Waits until `done` holds (re-checked after each core progress) or `deadline` passes.
    pub(crate) fn wait_progress(
        &self,
        deadline: Option<Instant>,
        mut done: impl FnMut() -> bool,
    ) -> bool {
        loop {
            let seen = self.progress.load(Ordering::SeqCst);
            if done() {
                return true;
            }
            if self.stopped.load(Ordering::Acquire) {
                return false;
            }
            let left = match deadline {
                Some(d) => match d.checked_duration_since(Instant::now()) {
                    Some(l) if !l.is_zero() => l,
                    _ => return done(),
                },
                None => Duration::from_millis(500),
            };
            self.wait_progress_for(seen, left);
        }
    }

    pub(crate) fn progress_generation(&self) -> u64 {
        self.progress.load(Ordering::SeqCst)
    }

    /// Waits until the core made progress after generation `seen`, or until `deadline`.
    pub(crate) fn wait_progress_change(&self, seen: u64, deadline: Instant) {
        let left = deadline.saturating_duration_since(Instant::now());
        self.wait_progress_for(seen, left);
    }

    fn timer_loop(self: Arc<Self>) {
        const READER_TICK: Duration = Duration::from_millis(50);
        let mut next_tick = Instant::now() + READER_TICK;
        while !self.stopped.load(Ordering::Acquire) {
            let seen = lock(&self.timer_gen).generation;
            let next_core = lock(&self.core).poll_timeout();
            let now = Instant::now();
            if next_core.is_some_and(|t| t <= now) {
                self.with_core(|c, now| c.handle_timeout(now));
                continue;
            }
            if now >= next_tick {
                next_tick = now + READER_TICK;
                let readers: Vec<Arc<dyn ReaderSink>> = self
                    .readers
                    .read()
                    .unwrap_or_else(|e| e.into_inner())
                    .values()
                    .cloned()
                    .collect();
                let writers: Vec<Arc<dyn WriterSink>> = self
                    .writers
                    .read()
                    .unwrap_or_else(|e| e.into_inner())
                    .values()
                    .cloned()
                    .collect();
                for w in writers {
                    w.tick(now);
                }
                for r in readers {
                    r.tick(now);
                }
                continue;
            }
            let until = next_core.map_or(next_tick, |t| t.min(next_tick));
            let mut g = lock(&self.timer_gen);
            if g.generation != seen {
                continue;
            }
            g.waiting_until = Some(until);
            let mut g = self
                .timer_cv
                .wait_timeout(g, until.saturating_duration_since(now))
                .unwrap_or_else(|e| e.into_inner())
                .0;
            g.waiting_until = None;
        }
    }

    fn shutdown(&self) {
        if self.stopped.swap(true, Ordering::AcqRel) {
            return;
        }
        tracing::info!(prefix = ?self.guid_prefix, "participant shutting down");
        // Tell peers we leave (SPDP dispose) while the sockets are still open.
        self.with_core(|c, now| c.shutdown(now));
        {
            let mut g = lock(&self.timer_gen);
            g.generation = g.generation.wrapping_add(1);
            self.timer_cv.notify_all();
        }
        self.bump_progress();
        if let Some(h) = lock(&self.timer_thread).take() {
            if h.thread().id() != std::thread::current().id() {
                let _ = h.join();
            }
        }
        self.transport.shutdown();
        // Readers and writers point back at us: forget them to break the cycle.
        self.readers
            .write()
            .unwrap_or_else(|e| e.into_inner())
            .clear();
        self.writers
            .write()
            .unwrap_or_else(|e| e.into_inner())
            .clear();
    }
}

fn remote_writer_info(w: &crate::rtps::discovery::WriterData) -> (Guid, RemoteWriterInfo) {
    let q = &w.qos.writer;
    let lifespan = (q.lifespan.0 != crate::qos::INFINITE).then_some(q.lifespan.0);
    (
        w.guid,
        RemoteWriterInfo {
            strength: q.ownership_strength.0,
            lifespan,
        },
    )
}

/// Stops the participant's threads when the last `DomainParticipant` handle goes away.
struct Guard(Arc<Shared>);

impl Drop for Guard {
    fn drop(&mut self) {
        self.0.shutdown();
    }
}

/// The entry point: one participant in one DDS domain. Cheap to clone. Topics, publishers, subscribers,
/// readers and writers keep their participant alive; when the last of these handles is dropped the
/// participant stops its threads and closes its sockets.
#[derive(Clone)]
pub struct DomainParticipant {
    pub(crate) shared: Arc<Shared>,
    _guard: Arc<Guard>,
}

impl std::fmt::Debug for DomainParticipant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DomainParticipant")
            .field("domain_id", &self.shared.config.domain_id)
            .field("guid_prefix", &self.shared.guid_prefix)
            .field("transport", &self.shared.transport)
            .finish()
    }
}

/// Builds a [`DomainParticipant`]: configuration from the environment (see [`crate::config`]) with the
/// builder's settings on top.
#[derive(Debug, Clone, Default)]
pub struct DomainParticipantBuilder {
    domain_id: Option<u32>,
    interface: Option<InterfaceSelection>,
    multicast: Option<bool>,
    peers: Option<Vec<Peer>>,
    participant_index: Option<ParticipantIndex>,
    spdp_interval: Option<Duration>,
    lease_duration: Option<Duration>,
    fragment_size: Option<usize>,
    max_message_size: Option<usize>,
    write_batch_delay: Option<Option<Duration>>,
    config: Option<Config>,
    ignore_env: bool,
    user_data: Vec<u8>,
    name: Option<String>,
}

impl DomainParticipantBuilder {
    /// Domain id (overrides `DDS_DOMAIN_ID`).
    pub fn domain_id(mut self, d: u32) -> Self {
        self.domain_id = Some(d);
        self
    }
    /// Interface by name (`"lo"`) or address (`"127.0.0.1"`) (overrides `DDS_INTERFACE`).
    pub fn interface(mut self, s: &str) -> Self {
        self.interface = Some(InterfaceSelection::parse(s));
        self
    }
    /// Multicast discovery on or off (overrides `DDS_MULTICAST`).
    pub fn multicast(mut self, on: bool) -> Self {
        self.multicast = Some(on);
        self
    }
    /// Unicast discovery peers, `"127.0.0.1"` or `"127.0.0.1:7410"` (overrides `DDS_PEERS`).
    pub fn peers<S: AsRef<str>>(mut self, peers: impl IntoIterator<Item = S>) -> DdsResult<Self> {
        self.peers = Some(
            peers
                .into_iter()
                .map(|p| Peer::parse(p.as_ref()))
                .collect::<Result<_, _>>()?,
        );
        Ok(self)
    }
    /// Participant index choice (overrides `DDS_PARTICIPANT_INDEX`).
    pub fn participant_index(mut self, i: ParticipantIndex) -> Self {
        self.participant_index = Some(i);
        self
    }
    /// SPDP announcement period.
    pub fn spdp_interval(mut self, d: Duration) -> Self {
        self.spdp_interval = Some(d);
        self
    }
    /// Participant lease duration.
    pub fn lease_duration(mut self, d: Duration) -> Self {
        self.lease_duration = Some(d);
        self
    }
    /// DATA_FRAG fragment size.
    pub fn fragment_size(mut self, n: usize) -> Self {
        self.fragment_size = Some(n);
        self
    }
    /// Largest datagram sent.
    pub fn max_message_size(mut self, n: usize) -> Self {
        self.max_message_size = Some(n);
        self
    }
    /// Write batching (overrides `DDS_WRITE_BATCH`): with `Some(delay)`, written samples wait up to `delay`
    /// for others to share their datagram; [`DomainParticipant::flush`] and [`DataWriter::flush`] send them at
    /// once. `None` sends every write immediately.
    ///
    /// [`DataWriter::flush`]: crate::dcps::DataWriter::flush
    pub fn write_batching(mut self, delay: Option<Duration>) -> Self {
        self.write_batch_delay = Some(delay);
        self
    }
    /// Starts from this configuration instead of the environment.
    pub fn config(mut self, c: Config) -> Self {
        self.config = Some(c);
        self
    }
    /// Ignores the `DDS_*` environment variables.
    pub fn ignore_env(mut self) -> Self {
        self.ignore_env = true;
        self
    }
    /// USER_DATA announced in SPDP.
    pub fn user_data(mut self, d: Vec<u8>) -> Self {
        self.user_data = d;
        self
    }
    /// Entity name announced in SPDP.
    pub fn name(mut self, n: impl Into<String>) -> Self {
        self.name = Some(n.into());
        self
    }

    /// The effective configuration.
    pub fn resolve_config(&self) -> DdsResult<Config> {
        let mut c = match &self.config {
            Some(c) => c.clone(),
            None if self.ignore_env => Config::default(),
            None => Config::from_env()?,
        };
        if let Some(d) = self.domain_id {
            c.domain_id = d;
        }
        if let Some(i) = &self.interface {
            c.interface = i.clone();
        }
        if let Some(m) = self.multicast {
            c.multicast = m;
        }
        if let Some(p) = &self.peers {
            c.peers = p.clone();
        }
        if let Some(i) = self.participant_index {
            c.participant_index = i;
        }
        if let Some(d) = self.spdp_interval {
            c.spdp_interval = d;
        }
        if let Some(d) = self.lease_duration {
            c.lease_duration = d;
        }
        if let Some(n) = self.fragment_size {
            c.fragment_size = n;
        }
        if let Some(n) = self.max_message_size {
            c.max_message_size = n;
        }
        if let Some(d) = self.write_batch_delay {
            c.write_batch_delay = d;
        }
        c.validate()?;
        Ok(c)
    }

    /// Binds the sockets, starts the receive and timer threads and begins SPDP.
    pub fn build(self) -> DdsResult<DomainParticipant> {
        let config = self.resolve_config()?;
        let transport = UdpTransport::bind(&config)?;
        let prefix = new_guid_prefix();
        let ip = match IpAddr::V4(transport.interface().addr) {
            IpAddr::V4(a) => a.octets(),
            IpAddr::V6(_) => [127, 0, 0, 1],
        };
        let pc = ParticipantConfig::builder(
            config.domain_id,
            transport.participant_index().unwrap_or(0),
            prefix,
            ip,
        )
        .metatraffic_unicast(vec![locator(transport.metatraffic_unicast())])
        .default_unicast(vec![locator(transport.user_unicast())])
        .metatraffic_multicast(
            transport
                .spdp_multicast()
                .map(locator)
                .into_iter()
                .collect::<Vec<_>>(),
        )
        // We do not listen on the user multicast port: peers send user data unicast.
        .default_multicast(Vec::new())
        .initial_peers(
            transport
                .spdp_peers()
                .iter()
                .copied()
                .map(locator)
                .collect::<Vec<_>>(),
        )
        .spdp_interval(config.spdp_interval)
        .lease_duration(config.lease_duration)
        .max_message_size(config.max_message_size)
        .fragment_size(config.fragment_size)
        .write_batch_delay(config.write_batch_delay)
        .user_data(self.user_data)
        .entity_name(self.name)
        .build();

        let core = Participant::new(pc, Instant::now());
        let shared = Arc::new(Shared {
            core: Mutex::new(core),
            transport,
            config,
            guid_prefix: prefix,
            readers: RwLock::new(HashMap::new()),
            writers: RwLock::new(HashMap::new()),
            remote_writers: Mutex::new(HashMap::new()),
            participants: Mutex::new(HashMap::new()),
            progress: AtomicU64::new(0),
            progress_waiters: AtomicUsize::new(0),
            progress_lock: Mutex::new(()),
            progress_cv: Condvar::new(),
            timer_gen: Mutex::new(TimerState::default()),
            timer_cv: Condvar::new(),
            stopped: AtomicBool::new(false),
            timer_thread: Mutex::new(None),
            status: Arc::new(StatusCore::default()),
            spare_buffers: Mutex::new(Vec::new()),
        });
        let weak: Weak<Shared> = Arc::downgrade(&shared);
        let rx = Arc::new(move |_ch: Channel, batch: &[Datagram<'_>]| {
            if let Some(s) = weak.upgrade() {
                if !s.stopped.load(Ordering::Acquire) {
                    // One copy per datagram out of the reusable receive buffers; samples share it.
                    let shared: Vec<Payload> = batch
                        .iter()
                        .map(|d| Payload::copy_from_slice(d.data))
                        .collect();
                    s.with_core(|c, now| {
                        for d in &shared {
                            c.handle_shared_datagram(now, d);
                        }
                    });
                }
            }
        });
        shared.transport.start(rx)?;
        let s2 = shared.clone();
        let h = std::thread::Builder::new()
            .name("dds-timer".into())
            .spawn(move || s2.timer_loop())?;
        *lock(&shared.timer_thread) = Some(h);
        // The first SPDP announcement goes out now rather than at the first timeout.
        shared.with_core(|c, now| c.handle_timeout(now));
        tracing::info!(prefix = ?prefix, domain = shared.config.domain_id, "participant created");
        Ok(DomainParticipant {
            shared: shared.clone(),
            _guard: Arc::new(Guard(shared)),
        })
    }
}

impl DomainParticipant {
    /// A participant in `domain_id` with the configuration from the environment.
    pub fn new(domain_id: u32) -> DdsResult<Self> {
        Self::builder().domain_id(domain_id).build()
    }

    /// A builder.
    pub fn builder() -> DomainParticipantBuilder {
        DomainParticipantBuilder::default()
    }

    /// The domain id.
    pub fn domain_id(&self) -> u32 {
        self.shared.config.domain_id
    }

    /// Sends the samples that write batching holds back (see
    /// [`DomainParticipantBuilder::write_batching`]); without batching there is nothing to send.
    pub fn flush(&self) {
        self.shared.flush();
    }

    /// The effective configuration.
    pub fn config(&self) -> &Config {
        &self.shared.config
    }

    /// The RTPS GUID prefix.
    pub fn guid_prefix(&self) -> [u8; 12] {
        self.shared.guid_prefix.0
    }

    /// The participant's own handle.
    pub fn instance_handle(&self) -> InstanceHandle {
        let mut b = [0u8; 16];
        b[..12].copy_from_slice(&self.shared.guid_prefix.0);
        b[12..].copy_from_slice(&EntityId::PARTICIPANT.0);
        InstanceHandle::from_guid_bytes(&b)
    }

    /// The transport (chosen interface, participant index, bound ports, counters).
    pub fn transport(&self) -> &UdpTransport {
        &self.shared.transport
    }

    /// Remote participants currently known through SPDP.
    pub fn discovered_participants(&self) -> Vec<DiscoveredParticipant> {
        lock(&self.shared.participants).values().cloned().collect()
    }

    /// Creates a topic of type `T`.
    pub fn create_topic<T: DdsType>(&self, name: &str, qos: &TopicQos) -> DdsResult<Topic<T>> {
        self.shared.check_alive()?;
        if name.is_empty() || name.len() > 256 {
            return Err(DdsError::BadParameter(format!("topic name {name:?}")));
        }
        Ok(Topic::new(self.clone(), name, qos.clone()))
    }

    /// Creates a publisher.
    pub fn create_publisher(&self, qos: &PublisherQos) -> DdsResult<Publisher> {
        self.shared.check_alive()?;
        Ok(Publisher::new(self.clone(), qos.clone()))
    }

    /// Creates a subscriber.
    pub fn create_subscriber(&self, qos: &SubscriberQos) -> DdsResult<Subscriber> {
        self.shared.check_alive()?;
        Ok(Subscriber::new(self.clone(), qos.clone()))
    }

    /// The participant's status condition.
    pub fn status_condition(&self) -> StatusCondition {
        StatusCondition {
            core: self.shared.status.clone(),
        }
    }
}
