//! The participant's driver: owns the sans-I/O core, the transport and the timer thread, runs the core under
//! its lock, sends what it queued and routes its events to the endpoints (typed readers and writers) through
//! the type-erased [`Endpoint`] trait. The entity modules depend on this module, never on each other's
//! internals; the driver knows no entity type.

use std::hash::{BuildHasher, Hasher};
use std::net::{IpAddr, SocketAddr};
use std::sync::atomic::{AtomicBool, AtomicU16, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, OnceLock, RwLock, Weak};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime};

use foldhash::{HashMap, HashMapExt};

use crate::config::Config;
use crate::rtps::{
    CoreError, EntityId, Event, Guid, GuidPrefix, Locator, Participant, ParticipantConfig,
    ReceivedSample, Transmit, WriteChange,
};
use crate::transport::{with_run_pieces, Channel, Datagram, Pieces, UdpTransport, RUN};

use super::condition::StatusCore;
use super::error::{DdsError, DdsResult};
use super::sync::{lock, read, recover, write};

/// What a reader cache is fed with, in the order the core produced it.
pub(crate) enum Pending {
    /// A change from a matched writer.
    Sample(ReceivedSample),
    /// A whole coherent set from one writer: stored at once, so that no read sees part of it.
    CoherentSet(Vec<ReceivedSample>),
    /// The writer unmatched (deleted, lost, or QoS changed).
    WriterGone(Guid),
}

/// The type-erased side of a typed reader or writer that the driver calls. Readers and writers differ
/// where DDS makes them differ: only readers receive samples, only writers say goodbye with changes.
pub(crate) trait Endpoint: Send + Sync {
    /// Queues a change for this reader. Called with the core lock held: must only queue.
    fn enqueue(&self, _item: Pending) {}
    /// Queues `first`, then each change `more` yields until it yields `None`, in that order: a run of
    /// changes for this reader, which a reader queues under one lock. Called with the core lock held:
    /// must only queue.
    fn enqueue_run(&self, first: Pending, more: &mut dyn FnMut() -> Option<Pending>) {
        self.enqueue(first);
        while let Some(item) = more() {
            self.enqueue(item);
        }
    }
    /// Drains the queue into the cache and notifies; called without the core lock.
    fn process(self: Arc<Self>) {}
    /// A status event for this endpoint; called without the core lock.
    fn on_event(self: Arc<Self>, ev: &Event);
    /// Time-driven QoS (deadlines, lifespan, autopurge).
    fn tick(self: Arc<Self>, now: Instant);
    /// Changes the core sends before deleting the endpoint (a writer unregisters its instances).
    fn farewell(&self) -> Vec<WriteChange> {
        Vec::new()
    }
}

/// Watches the core for a service that lives beside the endpoints (the durability service and its
/// duplicate filter, `dcps::durability`): the driver knows no service type.
pub(crate) trait CoreObserver: Send + Sync {
    /// Under the core lock: whether `s` may reach its reader. Must be cheap and must not call the driver.
    fn admit(&self, _s: &ReceivedSample) -> bool {
        true
    }
    /// Under the core lock, before samples that follow it are admitted: an event other than a sample.
    /// Must be cheap and must not call the driver.
    fn observe_locked(&self, _ev: &Event) {}
    /// Without the core lock: an event of the core, after the endpoints had theirs.
    fn on_event(&self, _ev: &Event) {}
}

/// What we learnt about a remote writer in SEDP that the reader-side QoS needs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct RemoteWriterInfo {
    /// Its ownership strength.
    pub(crate) strength: i32,
    /// Its lifespan, when finite.
    pub(crate) lifespan: Option<Duration>,
    /// A durability stand-in: the writer it replays (named in its USER_DATA), which our readers report
    /// as the changes' publication.
    pub(crate) original: Option<Guid>,
}

/// Drives one participant: the core, its sockets, its timer thread and the registry of endpoints.
pub(crate) struct Driver {
    core: Mutex<Participant>,
    pub(crate) transport: UdpTransport,
    pub(crate) config: Config,
    pub(crate) guid_prefix: GuidPrefix,
    /// Readers and writers by entity id (the ids of the two kinds never collide).
    endpoints: RwLock<HashMap<EntityId, Arc<dyn Endpoint>>>,
    remote_writers: Mutex<HashMap<Guid, RemoteWriterInfo>>,
    /// Bumped (under `remote_writers`' lock) whenever `remote_writers` changes: a reader's remembered
    /// answer ([`Driver::remote_writer_via`]) holds while it stays.
    remote_writers_gen: AtomicU64,
    participants: Mutex<Vec<GuidPrefix>>,
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
    /// `TimerState::waiting_until`, readable without the lock (see [`SleepMark`]).
    timer_sleep: SleepMark,
    stopped: AtomicBool,
    timer_thread: Mutex<Option<JoinHandle<()>>>,
    /// The participant's status condition.
    pub(crate) status: Arc<StatusCore>,
    /// Sent datagrams (payload buffers and destination lists), handed back to the core at the next
    /// `with_core`.
    spare_buffers: Mutex<Vec<Transmit>>,
    /// Length of `spare_buffers` (a core call locks it only when it holds some).
    spare_count: AtomicUsize,
    /// Held from before the core lock is released until a batch is sent: batches leave in the order the
    /// core made them, so that a writer's datagrams sent from two threads (a write, and the receive
    /// thread releasing what flow control held) do not overtake each other and arrive out of order.
    send_order: Mutex<()>,
    /// Services watching the core (see [`CoreObserver`]); `has_observers` keeps the sample path free of
    /// the lock while there are none.
    observers: RwLock<Vec<Arc<dyn CoreObserver>>>,
    has_observers: AtomicBool,
    /// Told of every remote publication and subscription discovered (topics, INCONSISTENT_TOPIC).
    discovery_hook: OnceLock<DiscoveryHook>,
    /// Shared-memory channels with peers on this host (`None`: off, or not available).
    #[cfg(feature = "shm")]
    shm: Option<super::shm::ShmLink>,
}

/// A thread's reusable vectors for `Driver::run_core`: the datagrams it sent last (kept for reuse), and what
/// it routed (events to dispatch, the readers given samples). Borrowed in place for a call: a nested call (a
/// listener's write, during `after_unlock`) finds the batch free again and the routed pair in use, and
/// takes fresh vectors for the latter, which allocate only if it routes something.
struct ThreadBufs {
    batch: std::cell::RefCell<Vec<Transmit>>,
    routed: std::cell::RefCell<Routed>,
}

thread_local! {
    static THREAD_BUFS: ThreadBufs = const {
        ThreadBufs {
            batch: std::cell::RefCell::new(Vec::new()),
            routed: std::cell::RefCell::new((Vec::new(), Vec::new())),
        }
    };
}

/// Events to dispatch after the core's lock is released, and the readers to process then.
type Routed = (Vec<Event>, Vec<(EntityId, Arc<dyn Endpoint>)>);

/// See [`Driver::set_discovery_hook`].
type DiscoveryHook = Box<dyn Fn(&Event) + Send + Sync>;

/// Most sent buffers kept for recycling in the shared list.
const MAX_SPARE_BUFFERS: usize = 32;
/// Sent buffers a thread keeps for its next core call.
const THREAD_SPARE_BUFFERS: usize = 4;

/// Period of the endpoints' time-driven QoS checks.
const ENDPOINT_TICK: Duration = Duration::from_millis(50);

/// The instant the timer thread sleeps until, mirrored from [`TimerState::waiting_until`] (written under
/// its lock) so that a core call whose deadline is no earlier skips the lock: two lock round trips per
/// ping/pong round trip. The time since [`sleep_epoch`] ([`encode_instant`]); 0 while the timer thread works.
struct SleepMark {
    until: AtomicU64,
}

/// The process's origin for [`SleepMark`]s (one for every participant: a thread's last encoding serves all).
fn sleep_epoch() -> Instant {
    static EPOCH: OnceLock<Instant> = OnceLock::new();
    *EPOCH.get_or_init(Instant::now)
}

/// `t` as a number ordered as the instants are: seconds since [`sleep_epoch`] above bit 30, nanoseconds
/// below (no multiplication), plus one; 1 for every instant up to the epoch (the first participant's
/// creation, before any core's deadline). A thread's last answer is kept: a core's deadline mostly stays from
/// one call to the next, and the subtraction of instants costs more than the comparison.
fn encode_instant(t: Instant) -> u64 {
    thread_local! {
        static LAST: std::cell::Cell<Option<(Instant, u64)>> = const { std::cell::Cell::new(None) };
    }
    LAST.with(|last| match last.get() {
        Some((at, e)) if at == t => e,
        _ => {
            let d = t.saturating_duration_since(sleep_epoch());
            let e = ((d.as_secs().min(u64::MAX >> 31) << 30) | u64::from(d.subsec_nanos())) + 1;
            last.set(Some((t, e)));
            e
        }
    })
}

impl SleepMark {
    fn new() -> Self {
        sleep_epoch();
        SleepMark {
            until: AtomicU64::new(0),
        }
    }

    /// Called with the timer state's lock held, whenever `waiting_until` changes.
    fn set(&self, until: Option<Instant>) {
        let v = until.map_or(0, encode_instant);
        self.until.store(v, Ordering::SeqCst);
    }

    /// Whether the timer thread sleeps until no later than `next` (or sleeps, and there is no `next`): it
    /// needs neither a generation bump nor a wake-up. When this reads a stale sleep the thread has woken
    /// since, and it reads the core's deadline (which `next` came from, under the core lock) again before
    /// sleeping.
    fn covers(&self, next: Option<Instant>) -> bool {
        let w = self.until.load(Ordering::SeqCst);
        // An instant up to the epoch (encoded as 1) is never taken as covered.
        w != 0
            && next.is_none_or(|n| {
                let e = encode_instant(n);
                e > 1 && e >= w
            })
    }
}

#[derive(Default)]
struct TimerState {
    generation: u64,
    /// `Some(t)` while the timer thread sleeps until `t`; `None` while it works.
    waiting_until: Option<Instant>,
}

fn to_socket(l: &Locator) -> Option<SocketAddr> {
    l.to_socket_addr()
}

fn locator(a: SocketAddr) -> Locator {
    Locator::from_socket_addr(a)
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

/// The core's configuration for a participant on `transport`.
fn core_config(
    config: &Config,
    transport: &UdpTransport,
    prefix: GuidPrefix,
    user_data: Vec<u8>,
    name: Option<String>,
    extra_properties: Vec<(String, String)>,
) -> DdsResult<ParticipantConfig> {
    // IPv6: the builder's IPv4 locators are all replaced below.
    let ip = match transport.interface().addr {
        IpAddr::V4(a) => a.octets(),
        IpAddr::V6(_) => [127, 0, 0, 1],
    };
    let pc = ParticipantConfig::builder(
        config.domain_id,
        transport.participant_index().unwrap_or(0),
        prefix,
        ip,
    )
    .map_err(crate::config::ConfigError::from)?
    .metatraffic_unicast(vec![locator(transport.metatraffic_unicast())])
    .default_unicast(vec![locator(transport.user_unicast())])
    .metatraffic_multicast(
        transport
            .spdp_multicast()
            .map(locator)
            .into_iter()
            .collect::<Vec<_>>(),
    )
    // Our readers announce the user-data group when multicast data is on (and we joined it); our writers
    // then also send to groups their readers share.
    .default_multicast(
        transport
            .user_multicast()
            .map(locator)
            .into_iter()
            .collect::<Vec<_>>(),
    )
    .multicast_data(transport.user_multicast().is_some())
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
    .intra_process(config.intra_process)
    .ignore_local(config.ignore_local)
    .user_data(user_data)
    .properties(
        super::process_info::properties()
            .into_iter()
            .chain(extra_properties)
            .collect::<Vec<_>>(),
    )
    .entity_name(name)
    .build();
    Ok(pc)
}

impl Driver {
    /// Binds the sockets, starts the receive and timer threads and begins SPDP.
    pub(crate) fn start(
        config: Config,
        user_data: Vec<u8>,
        name: Option<String>,
        enabled: bool,
    ) -> DdsResult<Arc<Driver>> {
        let transport = UdpTransport::bind(&config)?;
        let prefix = new_guid_prefix();
        #[cfg(feature = "shm")]
        let (shm, shm_properties) = match config.shm {
            true => {
                super::shm::ShmLink::new(prefix).map_or((None, Vec::new()), |(l, p)| (Some(l), p))
            }
            false => (None, Vec::new()),
        };
        #[cfg(not(feature = "shm"))]
        let shm_properties = Vec::new();
        let pc = core_config(&config, &transport, prefix, user_data, name, shm_properties)?;
        let mut core = Participant::new(pc, Instant::now());
        // Fragments of large samples leave from the samples' own buffers (`send_batch`).
        core.gather_sends(config.gather_min);
        if !enabled {
            // Created disabled: nothing is sent, not even the first SPDP announcement, until `enable`.
            core.set_enabled(Instant::now(), false);
        }
        let driver = Arc::new(Driver {
            core: Mutex::new(core),
            transport,
            config,
            guid_prefix: prefix,
            endpoints: RwLock::new(HashMap::new()),
            remote_writers: Mutex::new(HashMap::new()),
            remote_writers_gen: AtomicU64::new(0),
            participants: Mutex::new(Vec::new()),
            progress: AtomicU64::new(0),
            progress_waiters: AtomicUsize::new(0),
            progress_lock: Mutex::new(()),
            progress_cv: Condvar::new(),
            timer_gen: Mutex::new(TimerState::default()),
            timer_cv: Condvar::new(),
            timer_sleep: SleepMark::new(),
            stopped: AtomicBool::new(false),
            timer_thread: Mutex::new(None),
            status: Arc::new(StatusCore::default()),
            spare_buffers: Mutex::new(Vec::new()),
            spare_count: AtomicUsize::new(0),
            send_order: Mutex::new(()),
            observers: RwLock::new(Vec::new()),
            has_observers: AtomicBool::new(false),
            discovery_hook: OnceLock::new(),
            #[cfg(feature = "shm")]
            shm,
        });
        let weak: Weak<Driver> = Arc::downgrade(&driver);
        let rx = Arc::new(move |_ch: Channel, batch: &[Datagram<'_>]| {
            if let Some(d) = weak.upgrade() {
                d.receive(batch);
            }
        });
        driver.transport.start(rx)?;
        #[cfg(feature = "shm")]
        if let Some(link) = &driver.shm {
            link.start(Arc::downgrade(&driver))?;
        }
        let d2 = driver.clone();
        let h = std::thread::Builder::new()
            .name("dds-timer".into())
            .stack_size(crate::transport::DELIVERY_STACK)
            .spawn(move || d2.timer_loop())?;
        *lock(&driver.timer_thread) = Some(h);
        // The first SPDP announcement goes out now rather than at the first timeout.
        driver.with_core(|c, now| c.handle_timeout(now));
        tracing::info!(prefix = ?prefix, domain = driver.config.domain_id, "participant created");
        Ok(driver)
    }

    /// Feeds a batch of received datagrams to the core (on a receive thread).
    fn receive(&self, batch: &[Datagram<'_>]) {
        if self.stopped.load(Ordering::Acquire) {
            return;
        }
        // What a peer sent over shared memory before this datagram is taken first (a writer's last samples
        // before the announcement of its deletion, typically).
        #[cfg(feature = "shm")]
        if let Some(link) = &self.shm {
            link.drain_first(self);
        }
        // A datagram with DATA is copied once out of the reusable receive buffers, and its samples share
        // the copy; fragments are copied straight into their reassembly buffers.
        self.with_core(|c, now| {
            for d in batch {
                c.handle_datagram_sharing(now, d.data);
            }
        });
    }

    /// Sends held batched writes; free when batching is off.
    pub(crate) fn flush(&self) {
        if self.config.write_batch_delay.is_some() {
            self.with_core(|c, _| c.flush());
        }
    }

    /// Runs `f` on the core, then (lock released) sends what it queued and dispatches its events.
    pub(crate) fn with_core<R>(&self, f: impl FnOnce(&mut Participant, Instant) -> R) -> R {
        self.run_core(f, true, true)
    }

    /// [`with_core`](Self::with_core) for a write: it does not count as progress. A write never gives room
    /// to another, and a writer refused by flow control waits for progress made after its attempt: were
    /// its own attempt progress, it would retry at once, spinning (at 64 KiB this was a fifth of the
    /// publisher's CPU, taken from the subscriber on a two-core machine).
    pub(crate) fn with_core_writing<R>(&self, f: impl FnOnce(&mut Participant, Instant) -> R) -> R {
        self.run_core(f, false, true)
    }

    fn run_core<R>(
        &self,
        f: impl FnOnce(&mut Participant, Instant) -> R,
        progress: bool,
        send_shm: bool,
    ) -> R {
        let now = Instant::now();
        // One thread-local access per call, the vectors used where they are (taking them out and putting
        // them back was four accesses and eight vector moves, a tenth of the driver's work per hop).
        THREAD_BUFS.with(|bufs| {
            let mut routed = bufs.routed.try_borrow_mut().ok();
            let mut fresh: Routed = (Vec::new(), Vec::new());
            let (deferred, touched) = routed.as_deref_mut().unwrap_or(&mut fresh);
            let (r, next_timeout) = {
                let mut batch = bufs.batch.try_borrow_mut().ok();
                let mut fresh_batch = Vec::new();
                let batch = batch.as_deref_mut().unwrap_or(&mut fresh_batch);
                self.core_and_send(f, now, batch, deferred, touched, send_shm)
            };
            self.after_unlock(deferred, touched, next_timeout, progress);
            // Only non-sample events are deferred: a discovery burst must not pin its room for good.
            deferred.shrink_to(crate::rtps::KEPT_QUEUE_ROOM);
            r
        })
    }

    /// [`run_core`](Self::run_core) up to the sends: runs `f` on the core, routes its events and sends
    /// what it queued. Returns `f`'s result and the core's next deadline.
    fn core_and_send<R>(
        &self,
        f: impl FnOnce(&mut Participant, Instant) -> R,
        now: Instant,
        batch: &mut Vec<Transmit>,
        deferred: &mut Vec<Event>,
        touched: &mut Vec<(EntityId, Arc<dyn Endpoint>)>,
        send_shm: bool,
    ) -> (R, Option<Instant>) {
        let (r, next_timeout, order) = {
            let mut core = lock(&self.core);
            // Sent datagrams go back to the core for reuse (saves allocations per datagram): this thread's
            // own without a lock, the shared list's when other threads left some there. Popped (their order
            // does not matter): cheaper than a drain.
            while let Some(t) = batch.pop() {
                core.recycle_transmit(t);
            }
            if self.spare_count.load(Ordering::Acquire) > 0 {
                let mut spare = lock(&self.spare_buffers);
                self.spare_count.store(0, Ordering::Release);
                for t in spare.drain(..) {
                    core.recycle_transmit(t);
                }
            }
            let r = f(&mut core, now);
            while let Some(t) = core.poll_transmit(now) {
                batch.push(t);
            }
            let mut next = core.poll_event();
            while let Some(ev) = next {
                next = self.route_locked(ev, &mut core, deferred, touched);
            }
            #[cfg(feature = "shm")]
            if let Some(link) = &self.shm {
                link.take_from(&mut core);
            }
            // Taken before the core lock is released: the next batch the core makes waits for this one.
            let order = (!batch.is_empty()).then(|| lock(&self.send_order));
            (r, core.poll_timeout(), order)
        };
        // Shared memory first: what a writer sent there precedes what follows it on the wire (the
        // announcement of its deletion after its last changes, typically).
        #[cfg(feature = "shm")]
        if let (Some(link), true) = (&self.shm, send_shm) {
            link.flush();
        }
        #[cfg(not(feature = "shm"))]
        let _ = send_shm;
        self.send_batch(batch);
        drop(order);
        // The shares of samples go now: a pooled sample buffer returns to its pool at once.
        for t in batch.iter_mut() {
            t.shared.clear();
        }
        self.keep_sent(batch);
        (r, next_timeout)
    }

    /// Keeps the datagrams just sent for reuse: a few in `batch`, which stays with the thread (a write
    /// takes no lock for them), the rest in the shared list, up to its bound.
    fn keep_sent(&self, batch: &mut Vec<Transmit>) {
        if batch.len() <= THREAD_SPARE_BUFFERS {
            return;
        }
        let mut spare = lock(&self.spare_buffers);
        for t in batch.drain(THREAD_SPARE_BUFFERS..) {
            if spare.len() < MAX_SPARE_BUFFERS {
                spare.push(t);
            }
        }
        self.spare_count.store(spare.len(), Ordering::Release);
    }

    /// Under the core lock: samples go to their reader's queue (keeps order); the rest is deferred. A
    /// sample starts a run: the samples for the same reader that the core has next join its queue at once
    /// (one lock and one call for the run). Returns the core's next event, if the run read it.
    fn route_locked(
        &self,
        ev: Event,
        core: &mut Participant,
        deferred: &mut Vec<Event>,
        touched: &mut Vec<(EntityId, Arc<dyn Endpoint>)>,
    ) -> Option<Event> {
        let (reader, item) = match ev {
            Event::Sample(s) if !self.admit(&s) => return core.poll_event(),
            // A sample is moved once more, into its reader's queue.
            Event::Sample(s) => {
                let reader = s.reader;
                let Some(r) = self.touch(reader, touched) else {
                    return core.poll_event();
                };
                let mut after = None;
                r.enqueue_run(Pending::Sample(s), &mut || {
                    self.next_in_run(core, reader, &mut after)
                });
                return after;
            }
            Event::CoherentSet {
                reader, samples, ..
            } => (reader, Pending::CoherentSet(samples)),
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
                if self.has_observers.load(Ordering::Acquire) {
                    read(&self.observers)
                        .iter()
                        .for_each(|o| o.observe_locked(&other));
                }
                deferred.push(other);
                return core.poll_event();
            }
        };
        let Some(r) = self.touch(reader, touched) else {
            return core.poll_event();
        };
        r.enqueue(item);
        core.poll_event()
    }

    /// The next sample of a run for `reader` (see [`Driver::route_locked`]): the core's next event when it
    /// is one; a sample an observer does not admit is dropped on the way. Anything else ends the run and is
    /// left in `after`.
    fn next_in_run(
        &self,
        core: &mut Participant,
        reader: EntityId,
        after: &mut Option<Event>,
    ) -> Option<Pending> {
        loop {
            match core.poll_event()? {
                Event::Sample(s) if s.reader == reader => {
                    if self.admit(&s) {
                        return Some(Pending::Sample(s));
                    }
                }
                other => {
                    *after = Some(other);
                    return None;
                }
            }
        }
    }

    /// The endpoint `reader`, noted in `touched` (processed once the core lock is released); `None` (the
    /// event is dropped) when it is not registered. Runs of events for one reader (the common case) skip
    /// the registry lookup.
    fn touch(
        &self,
        reader: EntityId,
        touched: &mut Vec<(EntityId, Arc<dyn Endpoint>)>,
    ) -> Option<Arc<dyn Endpoint>> {
        if let Some((_, r)) = touched.iter().rev().find(|(id, _)| *id == reader) {
            return Some(r.clone());
        }
        let Some(r) = self.endpoint(reader) else {
            tracing::trace!(?reader, "event for an endpoint not registered: dropped");
            return None;
        };
        touched.push((reader, r.clone()));
        Some(r)
    }

    /// Sends the datagrams in order; consecutive ones for the same destinations (a fragmented sample's)
    /// go to each destination as one run, which the transport may send in one system call. Datagrams
    /// that share slices of samples ([`Transmit::shared`]) go in pieces, gathered by the kernel.
    fn send_batch(&self, batch: &[Transmit]) {
        let mut rest = batch;
        while let Some(first) = rest.first() {
            let mut n = rest
                .iter()
                .take(RUN)
                .take_while(|t| t.destinations == first.destinations)
                .count();
            let run = &rest[..n];
            if run.iter().all(|t| t.shared.is_empty()) {
                let mut bufs: [&[u8]; RUN] = [&[]; RUN];
                for (b, t) in bufs.iter_mut().zip(run) {
                    *b = &t.payload;
                }
                self.send_run(&bufs[..n], &first.destinations);
            } else {
                // Gathered on the stack (no allocation per large sample); a run whose pieces do not all fit
                // is sent in parts.
                n = with_run_pieces(run, |grams| self.send_run(grams, &first.destinations));
            }
            rest = &rest[n..];
        }
    }

    /// Sends a run of datagrams to each of `destinations`.
    fn send_run<P: Pieces>(&self, run: &[P], destinations: &[Locator]) {
        for d in destinations {
            if let Some(a) = to_socket(d) {
                self.transport.send_run(run, a);
            }
        }
    }

    fn after_unlock(
        &self,
        deferred: &mut Vec<Event>,
        touched: &mut Vec<(EntityId, Arc<dyn Endpoint>)>,
        next_timeout: Option<Instant>,
        progress: bool,
    ) {
        if progress {
            self.bump_progress();
        }
        if !self.timer_sleep.covers(next_timeout) {
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
        for ev in deferred.drain(..) {
            self.dispatch_event(ev);
        }
        // Most calls (a write, a datagram without samples) touch no reader: no batch.
        if touched.is_empty() {
            return;
        }
        let _batch = super::data_on_readers::DataOnReadersBatch::start();
        for (_, r) in touched.drain(..) {
            r.process();
        }
    }

    fn endpoint(&self, id: EntityId) -> Option<Arc<dyn Endpoint>> {
        read(&self.endpoints).get(&id).cloned()
    }

    fn dispatch_event(&self, ev: Event) {
        tracing::debug!(event = ?ev, "core event");
        self.dispatch_endpoint_event(&ev);
        if self.has_observers.load(Ordering::Acquire) {
            let observers = read(&self.observers).clone();
            for o in observers {
                o.on_event(&ev);
            }
        }
    }

    /// Whether every observer lets `s` reach its reader.
    fn admit(&self, s: &ReceivedSample) -> bool {
        !self.has_observers.load(Ordering::Acquire)
            || read(&self.observers).iter().all(|o| o.admit(s))
    }

    /// Registers a service that watches the core (until shutdown).
    pub(crate) fn add_observer(&self, o: Arc<dyn CoreObserver>) {
        write(&self.observers).push(o);
        self.has_observers.store(true, Ordering::Release);
    }

    /// Runs `f` on the core for a query: no event is polled and no datagram sent.
    pub(crate) fn query_core<R>(&self, f: impl FnOnce(&Participant) -> R) -> R {
        f(&lock(&self.core))
    }

    fn dispatch_endpoint_event(&self, ev: &Event) {
        match ev {
            Event::PublicationMatched { writer: id, .. }
            | Event::OfferedIncompatibleQos { writer: id, .. }
            | Event::LivelinessLost { writer: id }
            | Event::SubscriptionMatched { reader: id, .. }
            | Event::RequestedIncompatibleQos { reader: id, .. }
            | Event::LivelinessChanged { reader: id, .. }
            | Event::SampleLost { reader: id, .. } => {
                if let Some(e) = self.endpoint(*id) {
                    e.on_event(ev);
                }
            }
            Event::ParticipantDiscovered(p) => {
                let prefix = p.guid_prefix;
                let mut known = lock(&self.participants);
                if !known.contains(&prefix) {
                    known.push(prefix);
                }
                tracing::info!(peer = ?prefix, "participant discovered");
            }
            Event::ParticipantLost { guid_prefix } => {
                lock(&self.participants).retain(|p| p != guid_prefix);
                tracing::info!(peer = ?guid_prefix, "participant lost");
            }
            Event::PublicationDiscovered(w) => {
                // Only what differs from the default is kept: most writers cost nothing here.
                let (guid, info) = remote_writer_info(w);
                let mut known = lock(&self.remote_writers);
                if info == RemoteWriterInfo::default() {
                    known.remove(&guid);
                } else {
                    known.insert(guid, info);
                }
                self.remote_writers_gen.fetch_add(1, Ordering::Release);
                drop(known);
                self.discovered(ev);
            }
            Event::SubscriptionDiscovered(_) | Event::TopicDiscovered(_) => self.discovered(ev),
            Event::PublicationRemoved { guid } => {
                let mut known = lock(&self.remote_writers);
                known.remove(guid);
                self.remote_writers_gen.fetch_add(1, Ordering::Release);
            }
            _ => {}
        }
    }

    /// Installs the function told of every remote publication and subscription discovered (once).
    pub(crate) fn set_discovery_hook(&self, hook: DiscoveryHook) {
        let _ = self.discovery_hook.set(hook);
    }

    fn discovered(&self, ev: &Event) {
        if let Some(h) = self.discovery_hook.get() {
            h(ev);
        }
    }

    /// The GUID prefixes of the remote participants currently known through SPDP.
    pub(crate) fn discovered_participants(&self) -> Vec<GuidPrefix> {
        lock(&self.participants).clone()
    }

    /// [`remote_writer`](Self::remote_writer) through `last`, the last answer for some writer: looked up
    /// again only for another writer or after a change of what is known (a reader's samples mostly come
    /// from one writer; the lookup was a lock and a hash per batch).
    pub(crate) fn remote_writer_via(
        &self,
        g: &Guid,
        last: &mut Option<(u64, Guid, RemoteWriterInfo)>,
    ) -> RemoteWriterInfo {
        // Read before the map: an answer remembered with this generation is at least as new as it.
        let generation = self.remote_writers_gen.load(Ordering::Acquire);
        if let Some((lg, lw, info)) = last {
            if *lg == generation && lw == g {
                return *info;
            }
        }
        let info = self.remote_writer(g);
        *last = Some((generation, *g, info));
        info
    }

    /// The reader-side QoS a remote writer announced.
    pub(crate) fn remote_writer(&self, g: &Guid) -> RemoteWriterInfo {
        lock(&self.remote_writers)
            .get(g)
            .copied()
            .unwrap_or_default()
    }

    /// Creates an endpoint in the core with `create` and registers `sink` for it. Registration happens
    /// before the core can report matches for it: the core lock is held across both (match events are
    /// only polled after `create` returns).
    pub(crate) fn create_endpoint(
        &self,
        sink: Arc<dyn Endpoint>,
        create: impl FnOnce(&mut Participant, Instant) -> Result<EntityId, CoreError>,
    ) -> DdsResult<EntityId> {
        self.check_alive()?;
        let id = self.with_core(|c, now| {
            let id = create(c, now)?;
            write(&self.endpoints).insert(id, sink);
            Ok::<_, CoreError>(id)
        })?;
        Ok(id)
    }

    /// Forgets the endpoint and, while the participant runs, sends its farewell changes and deletes it in
    /// the core (a reliable writer lingers there until its data is acknowledged).
    pub(crate) fn delete_endpoint(&self, id: EntityId) {
        let sink = write(&self.endpoints).remove(&id);
        if self.check_alive().is_err() {
            return;
        }
        let farewell = sink.map(|s| s.farewell()).unwrap_or_default();
        self.with_core(|c, now| {
            for ch in farewell {
                if let Err(e) = c.write(now, id, ch) {
                    tracing::debug!(error = %e, "farewell change not sent");
                }
            }
        });
        // Readers on shared memory get what it sent before they learn of its deletion.
        #[cfg(feature = "shm")]
        if let (Some(link), true) = (&self.shm, id.is_writer()) {
            link.linger(id, &self.query_core(|c| c.shm_nodes(id)));
        }
        self.with_core(|c, now| {
            if id.is_writer() {
                c.delete_writer(now, id);
            } else {
                c.delete_reader(now, id);
            }
        });
        #[cfg(feature = "shm")]
        if let (Some(link), true) = (&self.shm, id.is_writer()) {
            link.close_writer(id);
        }
        tracing::debug!(?id, "endpoint deleted");
    }

    /// Whether every reliable reader of `writer` acknowledged all it wrote: on the wire, and on shared
    /// memory.
    pub(crate) fn is_acknowledged(&self, writer: EntityId) -> bool {
        self.with_core(|c, _| c.is_acknowledged(writer)) && self.shm_acknowledged(writer)
    }

    /// Whether the readers of `writer` on shared memory acknowledged all it sent them.
    fn shm_acknowledged(&self, _writer: EntityId) -> bool {
        #[cfg(feature = "shm")]
        if let Some(link) = &self.shm {
            let nodes = self.query_core(|c| c.shm_nodes(_writer));
            return link.acknowledged(_writer, &nodes);
        }
        true
    }

    /// `Err(AlreadyDeleted)` once the participant shut down.
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
            let _g = recover(
                self.progress_cv
                    .wait_timeout(g, left.min(Duration::from_millis(20))),
            );
        }
        self.progress_waiters.fetch_sub(1, Ordering::SeqCst);
    }

    /// Waits until every reliable reader matched with `writer` acknowledged everything it wrote; `Timeout`
    /// past `timeout`.
    pub(crate) fn wait_acknowledged(&self, writer: EntityId, timeout: Duration) -> DdsResult<()> {
        self.check_alive()?;
        let deadline = Instant::now().checked_add(timeout);
        if self.wait_progress(deadline, || self.is_acknowledged(writer)) {
            Ok(())
        } else {
            self.check_alive()?;
            Err(DdsError::Timeout)
        }
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

    /// The current progress generation (see [`Driver::wait_progress_change`]).
    pub(crate) fn progress_generation(&self) -> u64 {
        self.progress.load(Ordering::SeqCst)
    }

    /// Waits until the core made progress after generation `seen`, or until `deadline`.
    pub(crate) fn wait_progress_change(&self, seen: u64, deadline: Instant) {
        let left = deadline.saturating_duration_since(Instant::now());
        self.wait_progress_for(seen, left);
    }

    fn timer_loop(self: Arc<Self>) {
        let mut next_tick = Instant::now() + ENDPOINT_TICK;
        let mut ticked: Vec<Arc<dyn Endpoint>> = Vec::new();
        while !self.stopped.load(Ordering::Acquire) {
            let seen = lock(&self.timer_gen).generation;
            let next_core = lock(&self.core).poll_timeout();
            let now = Instant::now();
            if next_core.is_some_and(|t| t <= now) {
                self.with_core(|c, now| c.handle_timeout(now));
                continue;
            }
            if now >= next_tick {
                next_tick = now + ENDPOINT_TICK;
                // Copied out (the lock is not held across the ticks) into a vector kept between ticks.
                ticked.extend(read(&self.endpoints).values().cloned());
                for e in ticked.drain(..) {
                    e.tick(now);
                }
                continue;
            }
            let until = next_core.map_or(next_tick, |t| t.min(next_tick));
            let mut g = lock(&self.timer_gen);
            if g.generation != seen {
                continue;
            }
            g.waiting_until = Some(until);
            self.timer_sleep.set(Some(until));
            let mut g = recover(
                self.timer_cv
                    .wait_timeout(g, until.saturating_duration_since(now)),
            )
            .0;
            g.waiting_until = None;
            self.timer_sleep.set(None);
        }
    }

    /// Announces the departure, stops the threads and closes the sockets (once).
    pub(crate) fn shutdown(&self) {
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
        #[cfg(feature = "shm")]
        if let Some(link) = &self.shm {
            link.shutdown();
        }
        // Readers, writers and observers point back at us: forget them to break the cycle.
        write(&self.endpoints).clear();
        self.has_observers.store(false, Ordering::Release);
        write(&self.observers).clear();
    }
}

#[cfg(feature = "shm")]
impl super::shm::ShmHost for Driver {
    fn shm_link(&self) -> Option<&super::shm::ShmLink> {
        self.shm.as_ref()
    }

    fn with_core_from_shm(&self, f: &mut dyn FnMut(&mut Participant, Instant)) {
        self.run_core(f, true, false);
    }

    fn query_shm(&self, f: &mut dyn FnMut(&Participant)) {
        f(&lock(&self.core));
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
            original: super::stand_in::stand_in_for(&q.user_data.0),
        },
    )
}

/// Deletes its endpoint when dropped: the last clone of a `DataWriter` or `DataReader` (and of its
/// streams) holds the last `Arc` of it. `owner` keeps what the entity refers to (topic, publisher or
/// subscriber, and through them the participant) alive until the endpoint is deleted.
pub(crate) struct EndpointHandle<O> {
    driver: Arc<Driver>,
    id: EntityId,
    owner: O,
}

impl<O> EndpointHandle<O> {
    /// A handle of the endpoint `id`.
    pub(crate) fn new(driver: Arc<Driver>, id: EntityId, owner: O) -> Self {
        EndpointHandle { driver, id, owner }
    }
    /// The endpoint's entity id.
    pub(crate) fn id(&self) -> EntityId {
        self.id
    }
    /// The endpoint's GUID.
    pub(crate) fn guid(&self) -> Guid {
        Guid::new(self.driver.guid_prefix, self.id)
    }
    /// What the entity refers to.
    pub(crate) fn owner(&self) -> &O {
        &self.owner
    }
}

impl<O> Drop for EndpointHandle<O> {
    fn drop(&mut self) {
        self.driver.delete_endpoint(self.id);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encoded_instants_order_as_the_instants() {
        let before = Instant::now();
        let mark = SleepMark::new();
        let t = Instant::now() + Duration::from_nanos(1);
        let steps = [
            Duration::ZERO,
            Duration::from_nanos(1),
            Duration::from_nanos(999_999_999),
            Duration::from_secs(1),
            Duration::from_millis(1_500),
            Duration::from_secs(3_600),
        ];
        let coded: Vec<u64> = steps.iter().map(|d| encode_instant(t + *d)).collect();
        assert!(coded.windows(2).all(|w| w[0] < w[1]), "{coded:?}");
        // The thread's kept answer is for the same instant only.
        assert_eq!(encode_instant(t), coded[0]);
        assert!(coded[0] > 0, "0 means no sleep");
        assert!(!mark.covers(None), "a working timer thread is not covered");
        mark.set(Some(t + Duration::from_secs(1)));
        assert!(mark.covers(None));
        assert!(mark.covers(Some(t + Duration::from_secs(2))));
        assert!(!mark.covers(Some(t)));
        // An instant up to the epoch (all encoded alike) is not taken as covered (the epoch is the process's:
        // a test run in one process may have set it before `before`).
        if encode_instant(before) == 1 {
            mark.set(Some(before));
            assert!(!mark.covers(Some(before)));
        }
        mark.set(None);
        assert!(!mark.covers(Some(t + Duration::from_secs(2))));
    }
}
