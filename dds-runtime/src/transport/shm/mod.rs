//! Shared-memory channels between processes on one host, on [iceoryx2] (feature `shm`).
//!
//! A channel carries byte samples (serialized DDS samples, typically) from publishers to subscribers of the
//! same name, with no copy: a publisher loans a buffer from its shared-memory segment
//! ([`ShmPublisher::loan`]), the caller writes the sample into it in place and sends it; a subscriber gets a
//! [`ShmSample`] that reads the publisher's buffer in place, and the buffer returns to the publisher when
//! the last subscriber drops it.
//!
//! A process that dies (even by `SIGKILL`) while it holds loans or received samples leaves its node's
//! resources behind; [`remove_dead_nodes`] (also run whenever a [`ShmNode`] is created) frees them and
//! releases what it held. Nothing a dead process wrote half-way is ever delivered: only sent samples reach
//! subscribers.
//!
//! Discovery says which peers can use it ([`peer_can_use_shm`]: same host, same feature). DCPS uses one
//! channel per writer ([`crate::rtps::shm`] for the frames and the pairs, `dcps::shm` for the wiring; see
//! `docs/performance.md`, "Shared memory").
//!
//! [iceoryx2]: https://docs.rs/iceoryx2

mod discovery;

use std::mem::MaybeUninit;
use std::ops::{Deref, DerefMut};
use std::time::Duration;

use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::port::{BackpressureAction, BackpressureInfo};
use iceoryx2::prelude::*;
use iceoryx2::sample::Sample;
use iceoryx2::sample_mut::SampleMut;
use iceoryx2::sample_mut_uninit::SampleMutUninit;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory;
use iceoryx2::service::port_factory::PortFactory as _;

pub use discovery::{host_id, peer_can_use_shm, SHM_HOST_PROPERTY};

/// What can go wrong with a shared-memory channel (the iceoryx2 error, as text).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ShmError {
    /// The node, the service or a port could not be created or opened.
    #[error("shared-memory channel setup: {0}")]
    Setup(String),
    /// No buffer could be loaned (too many loans held, or out of shared memory).
    #[error("shared-memory loan: {0}")]
    Loan(String),
    /// A sample could not be sent or received.
    #[error("shared-memory transfer: {0}")]
    Transfer(String),
}

fn setup<E: std::fmt::Debug>(e: E) -> ShmError {
    ShmError::Setup(format!("{e:?}"))
}

/// Sizes of a channel: how many samples a subscriber queues and how many a publisher may loan at once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShmChannelConfig {
    /// Largest sample expected at first (the segment grows by powers of two beyond it).
    pub initial_max_sample: usize,
    /// Samples queued per subscriber before the publisher waits for it (back-pressure, no loss).
    pub queue_depth: usize,
    /// Most buffers a publisher may hold loaned at once.
    pub max_loans: usize,
    /// Most subscribers (readers on other processes) of one channel.
    pub max_subscribers: usize,
    /// How long a send waits for a subscriber whose queue is full before that subscriber misses the
    /// sample (`None`: it waits as long as it takes).
    pub delivery_timeout: Option<Duration>,
    /// Most publishers of one channel.
    pub max_publishers: usize,
    /// A full subscriber queue drops its oldest sample instead of making the publisher wait (for
    /// messages where only the latest matters, such as cumulative acknowledgements).
    pub latest_only: bool,
}

impl Default for ShmChannelConfig {
    fn default() -> Self {
        ShmChannelConfig {
            initial_max_sample: 64 * 1024,
            queue_depth: 16,
            max_loans: 4,
            max_subscribers: 16,
            delivery_timeout: None,
            max_publishers: 2,
            latest_only: false,
        }
    }
}

/// One process's (or participant's) presence in shared memory: channels are opened through it.
pub struct ShmNode {
    node: Node<ipc_threadsafe::Service>,
}

/// A channel's service.
type Service = PortFactory<ipc_threadsafe::Service, [u8], ()>;

/// An event channel's service.
type EventService = iceoryx2::service::port_factory::event::PortFactory<ipc_threadsafe::Service>;

/// Most notifiers of one event channel (processes that wake one listener).
const MAX_NOTIFIERS: usize = 64;

impl std::fmt::Debug for ShmNode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShmNode").finish_non_exhaustive()
    }
}

/// Frees what processes that died left in shared memory (their nodes, ports, segments and the buffers
/// they held); returns how many dead nodes were removed.
pub fn remove_dead_nodes() -> usize {
    let mut dead = Vec::new();
    let listed = Node::<ipc_threadsafe::Service>::list(Config::global_config(), |state| {
        if let NodeState::Dead(view) = state {
            dead.push(view);
        }
        CallbackProgression::Continue
    });
    if let Err(e) = listed {
        tracing::warn!(error = ?e, "cannot list shared-memory nodes");
    }
    dead.into_iter()
        .filter(|view| match view.clone().try_remove_stale_resources() {
            Ok(()) => true,
            Err(e) => {
                tracing::warn!(error = ?e, "cannot remove a dead shared-memory node");
                false
            }
        })
        .count()
}

/// What shared memory lists of a node ([`node_status`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum NodeStatus {
    /// Its process runs.
    Alive,
    /// Its process died; its resources are still listed until [`remove_dead_nodes`] frees them.
    Dead,
    /// Listed, but its state cannot be read (no permission, or the node is being created or removed).
    Unknown,
    /// Not listed: never created here, or removed.
    Absent,
}

/// What shared memory lists of the node `id` ([`ShmNode::id`]).
pub fn node_status(id: &str) -> NodeStatus {
    use iceoryx2::node::NodeView;
    let mut status = NodeStatus::Absent;
    let listed = Node::<ipc_threadsafe::Service>::list(Config::global_config(), |state| {
        let (nid, s) = match &state {
            NodeState::Alive(v) => (*v.id(), NodeStatus::Alive),
            NodeState::Dead(v) => (*v.id(), NodeStatus::Dead),
            NodeState::Inaccessible(n) | NodeState::Undefined(n) => (*n, NodeStatus::Unknown),
        };
        if nid.to_string() == id {
            status = s;
            return CallbackProgression::Stop;
        }
        CallbackProgression::Continue
    });
    if let Err(e) = listed {
        tracing::warn!(error = ?e, "cannot list shared-memory nodes");
        return NodeStatus::Unknown;
    }
    status
}

impl ShmNode {
    /// Creates this process's node (removing dead nodes first).
    pub fn new() -> Result<Self, ShmError> {
        // iceoryx2 warns on stderr of what is expected here (no config file, a wake-up signal that finds
        // the listener's queue full: it wakes anyway); `IOX2_LOG_LEVEL` still overrides.
        static QUIET: std::sync::Once = std::sync::Once::new();
        QUIET.call_once(|| set_log_level_from_env_or(LogLevel::Error));
        let removed = remove_dead_nodes();
        if removed > 0 {
            tracing::info!(removed, "removed dead shared-memory nodes");
        }
        let node = NodeBuilder::new()
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc_threadsafe::Service>()
            .map_err(setup)?;
        Ok(ShmNode { node })
    }

    /// This node's identity (hexadecimal), as [`ShmPublisher::subscriber_nodes`] gives it.
    pub fn id(&self) -> String {
        self.node.id().to_string()
    }

    fn service(&self, channel: &str, c: &ShmChannelConfig) -> Result<Service, ShmError> {
        let name: ServiceName = channel.try_into().map_err(setup)?;
        self.node
            .service_builder(&name)
            .publish_subscribe::<[u8]>()
            .enable_safe_overflow(c.latest_only)
            .subscriber_max_buffer_size(c.queue_depth)
            .subscriber_max_borrowed_samples(c.queue_depth)
            .max_subscribers(c.max_subscribers)
            .max_publishers(c.max_publishers)
            .history_size(0)
            .open_or_create()
            .map_err(setup)
    }

    /// A publisher on `channel`.
    pub fn publisher(&self, channel: &str, c: &ShmChannelConfig) -> Result<ShmPublisher, ShmError> {
        let service = self.service(channel, c)?;
        let builder = service
            .publisher_builder()
            .initial_max_slice_len(c.initial_max_sample)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .max_loaned_samples(c.max_loans)
            .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered);
        let builder = match c.delivery_timeout {
            Some(limit) => builder.set_backpressure_handler(give_up_after(limit)),
            None => builder,
        };
        let publisher = builder.create().map_err(setup)?;
        Ok(ShmPublisher { publisher, service })
    }

    fn event_service(&self, name: &str) -> Result<EventService, ShmError> {
        let name: ServiceName = name.try_into().map_err(setup)?;
        self.node
            .service_builder(&name)
            .event()
            .max_notifiers(MAX_NOTIFIERS)
            .max_listeners(1)
            .open_or_create()
            .map_err(setup)
    }

    /// The listener of event channel `name` (one per channel): it wakes when a notifier of the channel
    /// signals.
    pub fn listener(&self, name: &str) -> Result<ShmListener, ShmError> {
        let service = self.event_service(name)?;
        let listener = service.listener_builder().create().map_err(setup)?;
        Ok(ShmListener {
            listener,
            _service: service,
        })
    }

    /// A notifier on event channel `name`.
    pub fn notifier(&self, name: &str) -> Result<ShmNotifier, ShmError> {
        let service = self.event_service(name)?;
        let notifier = service.notifier_builder().create().map_err(setup)?;
        Ok(ShmNotifier {
            notifier,
            _service: service,
        })
    }

    /// A subscriber on `channel`.
    pub fn subscriber(
        &self,
        channel: &str,
        c: &ShmChannelConfig,
    ) -> Result<ShmSubscriber, ShmError> {
        let service = self.service(channel, c)?;
        let subscriber = service.subscriber_builder().create().map_err(setup)?;
        Ok(ShmSubscriber {
            subscriber,
            service,
        })
    }
}

/// A back-pressure handler that retries delivery to a full subscriber for `limit`, then skips it. It keeps
/// its own clock: the time iceoryx2 reports can be unavailable (`Duration::MAX`), which would skip at once.
fn give_up_after(limit: Duration) -> impl Fn(&BackpressureInfo) -> BackpressureAction + Send {
    let since = std::sync::Mutex::new(std::time::Instant::now());
    move |info: &BackpressureInfo| {
        let mut since = since
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if info.retries == 0 {
            *since = std::time::Instant::now();
        }
        if since.elapsed() < limit {
            // iceoryx2 yields between retries (10 000 times before it sleeps): past the first few,
            // sleep instead, so that a waiting writer leaves the processor to the reader it waits for.
            if info.retries > 64 {
                std::thread::sleep(Duration::from_micros(50));
            }
            BackpressureAction::Retry
        } else {
            tracing::warn!(
                ?limit,
                "shared-memory subscriber full too long: it misses a sample"
            );
            BackpressureAction::DiscardData
        }
    }
}

/// Sends samples on one channel.
pub struct ShmPublisher {
    publisher: Publisher<ipc_threadsafe::Service, [u8], ()>,
    service: Service,
}

impl std::fmt::Debug for ShmPublisher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShmPublisher").finish_non_exhaustive()
    }
}

impl ShmPublisher {
    /// Loans a zeroed buffer of `len` bytes in shared memory: write the sample into it, then
    /// [`ShmLoan::send`] it. Dropping the loan gives it back unsent. The loan keeps what it needs of the
    /// publisher alive: it may outlive this handle (it can then only be dropped or sent to nobody).
    pub fn loan(&self, len: usize) -> Result<ShmLoan, ShmError> {
        let sample = self
            .publisher
            .loan_slice(len)
            .map_err(|e| ShmError::Loan(format!("{e:?}")))?;
        Ok(ShmLoan { sample })
    }

    /// [`loan`](Self::loan) without zeroing: the buffer holds whatever its chunk of the segment holds,
    /// the bytes of an earlier sample of this publisher or the zeros of a fresh segment. Overwrite every
    /// byte that readers will look at. For a sample whose every byte is rewritten anyway (a plain-data
    /// sample written in place), this saves a `memset` of `len` bytes per sample.
    pub fn loan_unzeroed(&self, len: usize) -> Result<ShmLoan, ShmError> {
        let sample = self
            .publisher
            .loan_slice_uninit(len)
            .map_err(|e| ShmError::Loan(format!("{e:?}")))?;
        // SAFETY: the payload of a chunk is initialized memory. A segment is created as a file in
        // shared memory (`shm_open`, `ftruncate`: zero-filled pages) and mapped; afterwards only this
        // publisher writes its chunks' payloads (subscribers map it read-only), and it writes them only
        // as bytes: through `loan` (zeroed by iceoryx2, then `&mut [u8]`), through `loan_uninit`, whose
        // `assume_init` requires every byte to be written first, or through this function's `&mut [u8]`.
        // No value with padding or uninitialized bytes is ever stored in a payload, so every byte read
        // through the `&[u8]` is an initialized `u8` (and every `u8` value is valid).
        Ok(ShmLoan {
            sample: unsafe { sample.assume_init() },
        })
    }

    /// The nodes ([`ShmNode::id`]) of the channel's subscribers.
    pub fn subscriber_nodes(&self) -> Vec<String> {
        let mut nodes = Vec::new();
        self.service.dynamic_config().list_subscribers(|d| {
            nodes.push(d.node_id.to_string());
            CallbackProgression::Continue
        });
        nodes
    }

    /// Loans a buffer of `len` bytes in shared memory, not initialized (no zeroing): fill every byte,
    /// then [`ShmLoanUninit::assume_init`] and send it.
    pub fn loan_uninit(&self, len: usize) -> Result<ShmLoanUninit, ShmError> {
        let sample = self
            .publisher
            .loan_slice_uninit(len)
            .map_err(|e| ShmError::Loan(format!("{e:?}")))?;
        Ok(ShmLoanUninit { sample })
    }

    /// Sends `parts`, one after the other, as one sample: each is copied once into a loaned buffer, which
    /// is not zeroed first. How many subscribers got it.
    pub fn send_parts(&self, parts: &[&[u8]]) -> Result<usize, ShmError> {
        let len = parts.iter().map(|p| p.len()).sum();
        let mut loan = self.loan_uninit(len)?;
        let mut at = 0;
        for p in parts {
            let dst = &mut loan.buf()[at..at + p.len()];
            // SAFETY: `dst` and `p` have the same length and do not overlap (`dst` is a loaned buffer);
            // `MaybeUninit<u8>` has the layout of `u8`.
            unsafe {
                std::ptr::copy_nonoverlapping(p.as_ptr(), dst.as_mut_ptr().cast::<u8>(), p.len())
            };
            at += p.len();
        }
        // SAFETY: the loop above wrote all `len` bytes of the payload.
        unsafe { loan.assume_init() }.send()
    }

    /// Connects subscribers that appeared since the last send (sending does it too).
    pub fn update_connections(&self) -> Result<(), ShmError> {
        self.publisher
            .update_connections()
            .map_err(|e| ShmError::Transfer(format!("{e:?}")))
    }
}

/// A buffer loaned from a publisher's segment, written in place. `Send`: it may be written on one thread
/// and sent from another.
pub struct ShmLoan {
    sample: SampleMut<ipc_threadsafe::Service, [u8], ()>,
}

impl std::fmt::Debug for ShmLoan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ShmLoan({} bytes)", self.len())
    }
}

impl ShmLoan {
    /// Sends the buffer to every subscriber; how many got it.
    pub fn send(self) -> Result<usize, ShmError> {
        self.sample
            .send()
            .map_err(|e| ShmError::Transfer(format!("{e:?}")))
    }
}

/// A buffer loaned from a publisher's segment, not initialized yet ([`ShmPublisher::loan_uninit`]).
pub struct ShmLoanUninit {
    sample: SampleMutUninit<ipc_threadsafe::Service, [MaybeUninit<u8>], ()>,
}

impl std::fmt::Debug for ShmLoanUninit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ShmLoanUninit({} bytes)", self.sample.payload().len())
    }
}

impl ShmLoanUninit {
    /// The buffer, to fill.
    pub fn buf(&mut self) -> &mut [MaybeUninit<u8>] {
        self.sample.payload_mut()
    }

    /// The filled buffer, to send.
    ///
    /// # Safety
    /// Every byte of [`buf`](Self::buf) must have been written.
    pub unsafe fn assume_init(self) -> ShmLoan {
        // SAFETY: as the caller guarantees.
        ShmLoan {
            sample: unsafe { self.sample.assume_init() },
        }
    }
}

impl Deref for ShmLoan {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        self.sample.payload()
    }
}

impl DerefMut for ShmLoan {
    fn deref_mut(&mut self) -> &mut [u8] {
        self.sample.payload_mut()
    }
}

/// Receives samples on one channel.
pub struct ShmSubscriber {
    subscriber: Subscriber<ipc_threadsafe::Service, [u8], ()>,
    service: Service,
}

impl std::fmt::Debug for ShmSubscriber {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShmSubscriber").finish_non_exhaustive()
    }
}

impl ShmSubscriber {
    /// Whether a sample is queued.
    pub fn has_samples(&self) -> bool {
        self.subscriber.has_samples().unwrap_or(false)
    }

    /// Connects to the channel's publishers, and whether it has any: samples they send from now on reach
    /// this subscriber. (A publisher that fills a subscriber's queue before the subscriber connected to
    /// it skips that subscriber, so a sender should learn of the connection before sending much.)
    pub fn connect(&self) -> bool {
        // Listed first, then connected: every publisher counted is connected.
        let listed = self.service.dynamic_config().number_of_publishers() > 0;
        let connected = self.subscriber.update_connections().is_ok();
        listed && connected
    }

    /// The next sample, if one is queued (never blocks).
    pub fn receive(&self) -> Result<Option<ShmSample>, ShmError> {
        self.subscriber
            .receive()
            .map(|s| s.map(|sample| ShmSample { sample }))
            .map_err(|e| ShmError::Transfer(format!("{e:?}")))
    }
}

/// A received sample, read in place in the publisher's shared memory; released when dropped.
pub struct ShmSample {
    sample: Sample<ipc_threadsafe::Service, [u8], ()>,
}

impl Deref for ShmSample {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        self.sample.payload()
    }
}

impl AsRef<[u8]> for ShmSample {
    fn as_ref(&self) -> &[u8] {
        self
    }
}

// SAFETY: through `&ShmSample` only `Sample::payload` is reached (`Deref`, `AsRef`), which reads the sent
// chunk: shared memory that nobody writes while the sample is held (a publisher only writes loaned chunks,
// and a sent chunk is not loaned again before every holder released it). Releasing it (`Drop`) takes the
// sample by value, so it happens once, on one thread. `Sample` is already `Send` for this service type.
unsafe impl Sync for ShmSample {}

impl std::fmt::Debug for ShmSample {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ShmSample({} bytes)", self.len())
    }
}

/// Waits for signals on an event channel ([`ShmNode::listener`]): a thread sleeps in
/// [`wait`](Self::wait) instead of polling.
pub struct ShmListener {
    listener: iceoryx2::port::listener::Listener<ipc_threadsafe::Service>,
    _service: EventService,
}

impl std::fmt::Debug for ShmListener {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShmListener").finish_non_exhaustive()
    }
}

impl ShmListener {
    /// Waits until a notifier signals or `timeout` passes; whether it was signalled. Signals sent since
    /// the last wait are kept, so a signal sent before the wait starts is not missed.
    ///
    /// The listener is a socket: the wait is a `poll(2)` on it, then the signals are taken without
    /// waiting (iceoryx2's own timed wait formats an error text, an allocation, on every call).
    pub fn wait(&self, timeout: Duration) -> Result<bool, ShmError> {
        let mut woken = false;
        let take = |woken: &mut bool| {
            self.listener
                .try_wait_all(|_| *woken = true)
                .map_err(|e| ShmError::Transfer(format!("{e:?}")))
        };
        take(&mut woken)?;
        if woken {
            return Ok(true);
        }
        #[cfg(unix)]
        {
            // SAFETY: the descriptor belongs to the listener, which outlives this call; it is only read.
            let fd = unsafe { self.listener.file_descriptor().native_handle() };
            poll_readable(fd, timeout)?;
        }
        #[cfg(not(unix))]
        self.listener
            .timed_wait_all(|_| woken = true, timeout)
            .map_err(|e| ShmError::Transfer(format!("{e:?}")))?;
        take(&mut woken)?;
        Ok(woken)
    }
}

/// Waits until `fd` is readable or `timeout` passes (`poll(2)`; an interrupted wait counts as done).
#[cfg(unix)]
fn poll_readable(fd: i32, timeout: Duration) -> Result<(), ShmError> {
    let mut p = libc::pollfd {
        fd,
        events: libc::POLLIN,
        revents: 0,
    };
    // On Linux `ppoll`, to the microsecond; elsewhere `poll`, rounded up to whole milliseconds.
    #[cfg(target_os = "linux")]
    let r = {
        let t = libc::timespec {
            tv_sec: timeout.as_secs().min(i32::MAX as u64) as libc::time_t,
            tv_nsec: libc::c_long::from(timeout.subsec_nanos() as i32),
        };
        // SAFETY: `p` is one valid `pollfd`, as the count says; `t` is a valid `timespec`; no signal mask.
        unsafe { libc::ppoll(&mut p, 1, &t, std::ptr::null()) }
    };
    #[cfg(not(target_os = "linux"))]
    // SAFETY: `p` is one valid `pollfd`, as the count says.
    let r = unsafe {
        let ms = timeout.as_micros().div_ceil(1000).min(i32::MAX as u128) as i32;
        libc::poll(&mut p, 1, ms)
    };
    if r < 0 {
        let e = std::io::Error::last_os_error();
        if e.kind() != std::io::ErrorKind::Interrupted {
            return Err(ShmError::Transfer(format!("poll: {e}")));
        }
    }
    Ok(())
}

/// Signals the listener of an event channel ([`ShmNode::notifier`]).
pub struct ShmNotifier {
    notifier: iceoryx2::port::notifier::Notifier<ipc_threadsafe::Service>,
    _service: EventService,
}

impl std::fmt::Debug for ShmNotifier {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShmNotifier").finish_non_exhaustive()
    }
}

impl ShmNotifier {
    /// Wakes the channel's listener; how many listeners were signalled (0 when none exists yet).
    pub fn notify(&self) -> Result<usize, ShmError> {
        self.notifier
            .notify()
            .map_err(|e| ShmError::Transfer(format!("{e:?}")))
    }
}
