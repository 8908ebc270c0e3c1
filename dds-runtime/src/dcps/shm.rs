//! The participant's shared-memory link (feature `shm`): the I/O side of the core's shared-memory pairs
//! (`rtps::shm`). One channel per writer: the driver sends each change the core queued for it
//! ([`Participant::poll_shm`]) as one frame written into a loaned buffer, and reads the channels of the
//! peers' writers its readers are matched with, giving each frame to the core in place
//! ([`Participant::receive_shm`]).
//!
//! What holds for a pair on shared memory: every change the writer sent reaches the reader's participant,
//! in order, unless that participant's queue stays full longer than [`DELIVERY_TIMEOUT`] (reliable
//! writers; best-effort writers drop at once for a full queue), or its subscriber is not connected within
//! [`CONNECT_TIMEOUT`] of the first change for it (changes wait for it meanwhile, in order). Nothing is
//! repaired afterwards: iceoryx2's delivery replaces RTPS repair for these pairs. Acknowledgements: once
//! a reader's participant has put a writer's changes into its readers' caches it says so on the writer's
//! acknowledgement channel (cumulative sequence numbers, latest only), which `wait_for_acknowledgments`
//! waits for like RTPS ACKNACKs.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use foldhash::{HashMap, HashMapExt};

use super::sync::lock;
use crate::rtps::shm::{
    decode_header, shm_channel_name, ShmChange, SHM_HOST_PROPERTY, SHM_NODE_PROPERTY,
};
use crate::rtps::{EntityId, Guid, GuidPrefix, Participant, Payload};
use crate::transport::shm::{
    host_id, node_status, NodeStatus, ShmChannelConfig, ShmError, ShmListener, ShmLoan, ShmNode,
    ShmNotifier, ShmPublisher, ShmSample, ShmSubscriber,
};

/// How long a writer's changes wait for the subscribers of its readers' participants to connect.
pub(crate) const CONNECT_TIMEOUT: Duration = Duration::from_secs(2);

/// Longest wait of a writer's deletion for its reader participants' acknowledgements ([`ShmLink::linger`]).
const LINGER: Duration = Duration::from_secs(2);

/// How often a lingering deletion looks for reader participants that died ([`ShmLink::linger`]).
const LIVENESS_CHECK: Duration = Duration::from_millis(20);

/// How long a reliable writer's send waits for a subscriber whose queue is full.
pub(crate) const DELIVERY_TIMEOUT: Duration = Duration::from_secs(10);

/// A long flush wakes its reader participants after this many frames (and at its end): half a queue.
const WAKE_EVERY: usize = 8;

/// Frames taken from one channel per pass (they stay borrowed until their readers decoded them).
const BATCH: usize = 8;

/// Longest sleep of the reading thread when no frame arrives and no writer signals (a safety net: writers
/// signal the reader participants they sent to, see [`wake_channel`]).
const MAX_IDLE: Duration = Duration::from_millis(100);

/// Longest wait of a receive thread for the reading thread ([`ShmLink::drain_first`]).
const DRAIN_WAIT: Duration = Duration::from_millis(100);

/// How often changes held for readers that are not connected yet are retried.
const HELD_RETRY: Duration = Duration::from_millis(1);

/// The event channel that wakes the reading thread of the participant whose node is `node`: writers
/// signal it after sending frames to that participant, and the participant itself when the channels it
/// reads change.
fn wake_channel(node: &str) -> String {
    format!("dds/n/{node}")
}

/// A change written in a loaned buffer (`DataWriter::loan`), waiting for its turn in the channel.
struct Parked {
    writer: EntityId,
    sequence: i64,
    loan: ShmLoan,
    /// Where the serialized sample is in the buffer.
    payload: std::ops::Range<usize>,
}

/// What the link needs of the participant's driver (which owns the link; the link does not know it).
pub(crate) trait ShmHost: Send + Sync + 'static {
    /// The driver's link.
    fn shm_link(&self) -> Option<&ShmLink>;
    /// Runs `f` on the core; changes of our own writers it queued are left for another thread to send
    /// (the shared-memory thread must never wait on a peer).
    fn with_core_from_shm(&self, f: &mut dyn FnMut(&mut Participant, Instant));
    /// Runs `f` on the core for a query.
    fn query_shm(&self, f: &mut dyn FnMut(&Participant));
}

/// One writer's channel, the set of nodes last seen connected to it, and its acknowledgements.
struct Outlet {
    publisher: ShmPublisher,
    connected: Option<Arc<[String]>>,
    /// Since when a change waits for its nodes to connect.
    waiting_since: Option<Instant>,
    acks: ShmSubscriber,
    /// By node: the highest sequence number sent while it was expected, and the highest it acknowledged.
    owed: HashMap<String, (i64, i64)>,
    /// The nodes that said (on the acknowledgement channel) that they are connected to the channel.
    greeted: Vec<String>,
}

impl Outlet {
    /// Takes the acknowledgements that arrived: what each node acknowledged, and that it is connected.
    fn read_acks(&mut self) {
        while let Ok(Some(ack)) = self.acks.receive() {
            let Some((sn, node)) = decode_ack(&ack) else {
                continue;
            };
            if let Some(owed) = self.owed.get_mut(node) {
                owed.1 = owed.1.max(sn);
            }
            if !self.greeted.iter().any(|g| g == node) {
                self.greeted.push(node.to_owned());
            }
        }
    }
}

/// One peer writer's channel that our readers read, and where we acknowledge what it sent.
struct Inlet {
    writer: Guid,
    subscriber: ShmSubscriber,
    acks: ShmPublisher,
    /// Until its first frame: since when it tells the writer, on the acknowledgement channel, that it is
    /// connected (an acknowledgement of 0) once it is. A writer sends nothing before that: iceoryx2
    /// skips a subscriber that is not connected yet once its queue is full, and the samples would be lost.
    greeting_since: Option<Instant>,
    /// Frames of this channel still held (decoding, or kept in place by readers, `dcps::InPlace`).
    held: Arc<AtomicUsize>,
}

/// Most frames of one channel held at once; past it, frames are copied out of shared memory and given
/// back at once. iceoryx2 lends a subscriber at most the channel's queue depth of frames: readers that
/// keep samples in place must not take them all, or the channel would stall.
const MAX_HELD: usize = 12;

/// A frame read from a channel, counted while it is held.
struct HeldFrame {
    frame: ShmSample,
    held: Arc<AtomicUsize>,
}

impl AsRef<[u8]> for HeldFrame {
    fn as_ref(&self) -> &[u8] {
        &self.frame
    }
}

impl Drop for HeldFrame {
    fn drop(&mut self) {
        self.held.fetch_sub(1, Ordering::AcqRel);
    }
}

impl Inlet {
    /// The frame as a payload: shared in place, or copied when too many frames are held already.
    fn payload(&self, frame: ShmSample) -> Payload {
        if self.held.fetch_add(1, Ordering::AcqRel) >= MAX_HELD {
            self.held.fetch_sub(1, Ordering::AcqRel);
            return Payload::copy_from_slice(&frame);
        }
        let held = self.held.clone();
        Payload::from_owner(Arc::new(HeldFrame { frame, held }))
    }
}

/// The channels our readers read, and the core generation they were set up for.
#[derive(Default)]
struct Inlets {
    generation: u64,
    channels: Vec<Inlet>,
}

/// A participant's presence in shared memory.
pub(crate) struct ShmLink {
    node: ShmNode,
    prefix: GuidPrefix,
    /// Changes taken from the core (under its lock), in write order, to send.
    pending: Mutex<VecDeque<ShmChange>>,
    /// The writers' channels; held while sending, so that sends keep the order of `pending`.
    outlets: Mutex<HashMap<EntityId, Outlet>>,
    inlets: Mutex<Inlets>,
    /// The core's `shm_generation`, as last seen under its lock.
    generation: AtomicU64,
    stopped: AtomicBool,
    thread: Mutex<Option<JoinHandle<()>>>,
    /// Where the reading thread sleeps (`None`: it polls).
    listener: Option<Arc<ShmListener>>,
    /// Wakes our own reading thread.
    wake_self: Option<ShmNotifier>,
    /// Wakes the reading threads of the participants we send to, by node.
    notifiers: Mutex<HashMap<String, ShmNotifier>>,
    /// Loaned changes the core queued, until their turn.
    parked: Mutex<Vec<Parked>>,
    /// Whether a channel we read waits for its first frame and greets its writer (the reading thread
    /// then polls quickly: the writer waits for the greeting).
    greeting: AtomicBool,
    /// Drain passes of the reading thread, for [`drain_first`](ShmLink::drain_first).
    passes: Mutex<u64>,
    passed: std::sync::Condvar,
}

fn channel_config(reliable: bool) -> ShmChannelConfig {
    ShmChannelConfig {
        delivery_timeout: Some(if reliable {
            DELIVERY_TIMEOUT
        } else {
            Duration::ZERO
        }),
        ..ShmChannelConfig::default()
    }
}

/// A writer's acknowledgement channel: many publishers (one per reader participant), small messages,
/// only the latest matters.
fn ack_config() -> ShmChannelConfig {
    let c = ShmChannelConfig::default();
    ShmChannelConfig {
        initial_max_sample: 64,
        max_publishers: c.max_subscribers,
        latest_only: true,
        ..c
    }
}

/// Whether the reader participant of node `n` is gone: its process died (its node is listed dead, or
/// already removed by whoever cleaned up first), so it will never connect or acknowledge.
fn node_gone(n: &str) -> bool {
    matches!(node_status(n), NodeStatus::Dead | NodeStatus::Absent)
}

/// The acknowledgement channel of the writer whose data channel is `data`.
fn ack_channel(data: &str) -> String {
    format!("{data}/ack")
}

/// An acknowledgement: the sequence number, then the acknowledging node.
fn encode_ack(sn: i64, node: &str, out: &mut [u8]) {
    out[..8].copy_from_slice(&sn.to_le_bytes());
    out[8..].copy_from_slice(node.as_bytes());
}

fn decode_ack(b: &[u8]) -> Option<(i64, &str)> {
    let sn = i64::from_le_bytes(b.get(..8)?.try_into().ok()?);
    Some((sn, std::str::from_utf8(&b[8..]).ok()?))
}

impl ShmLink {
    /// The link of participant `prefix`, and the SPDP properties that tell peers on this host to use it;
    /// `None` (every peer on UDP) when this host has no identity or shared memory cannot be set up.
    pub(crate) fn new(prefix: GuidPrefix) -> Option<(ShmLink, Vec<(String, String)>)> {
        let host = host_id()?;
        let node = ShmNode::new()
            .map_err(|e| tracing::warn!(error = %e, "no shared memory: every peer gets UDP"))
            .ok()?;
        let props = vec![
            (SHM_HOST_PROPERTY.to_owned(), host),
            (SHM_NODE_PROPERTY.to_owned(), node.id()),
        ];
        let wake = wake_channel(&node.id());
        // `DDS_SHM_WAKE=poll`: the reading thread polls (diagnostic: the behaviour before wake-ups).
        let poll = std::env::var("DDS_SHM_WAKE").is_ok_and(|v| v == "poll");
        let listener = (!poll)
            .then(|| node.listener(&wake))
            .transpose()
            .map_err(|e| tracing::warn!(error = %e, "no shared-memory wake-up: the reader polls"))
            .ok()
            .flatten();
        let wake_self = listener.as_ref().and_then(|_| node.notifier(&wake).ok());
        let link = ShmLink {
            node,
            prefix,
            pending: Mutex::new(VecDeque::new()),
            outlets: Mutex::new(HashMap::new()),
            inlets: Mutex::new(Inlets::default()),
            generation: AtomicU64::new(0),
            stopped: AtomicBool::new(false),
            thread: Mutex::new(None),
            listener: listener.map(Arc::new),
            wake_self,
            notifiers: Mutex::new(HashMap::new()),
            parked: Mutex::new(Vec::new()),
            greeting: AtomicBool::new(false),
            passes: Mutex::new(0),
            passed: std::sync::Condvar::new(),
        };
        Some((link, props))
    }

    /// Starts the thread that reads the channels.
    pub(crate) fn start<H: ShmHost>(&self, driver: Weak<H>) -> std::io::Result<()> {
        let h = std::thread::Builder::new()
            .name("dds-shm".into())
            .stack_size(crate::transport::DELIVERY_STACK)
            .spawn(move || poll_loop(driver))?;
        *lock(&self.thread) = Some(h);
        Ok(())
    }

    /// Under the core lock: takes what the core queued for the channels.
    pub(crate) fn take_from(&self, core: &mut Participant) {
        let generation = core.shm_generation();
        if self.generation.swap(generation, Ordering::AcqRel) != generation {
            // The channels to read changed: the reading thread (re)subscribes now.
            self.wake();
        }
        let mut pending = None;
        while let Some(c) = core.poll_shm() {
            pending
                .get_or_insert_with(|| lock(&self.pending))
                .push_back(c);
        }
    }

    /// Sends what was taken, in order (without the core lock); may wait for a full reader queue.
    pub(crate) fn flush(&self) {
        if lock(&self.pending).is_empty() {
            return;
        }
        self.flush_with(&mut lock(&self.outlets));
    }

    /// [`flush`](Self::flush) unless another thread is sending (it sends what is pending too).
    fn try_flush(&self) {
        if lock(&self.pending).is_empty() {
            return;
        }
        let mut guard = match self.outlets.try_lock() {
            Ok(g) => g,
            Err(std::sync::TryLockError::Poisoned(p)) => p.into_inner(),
            Err(std::sync::TryLockError::WouldBlock) => return,
        };
        self.flush_with(&mut guard);
    }

    fn flush_with(&self, outlets: &mut HashMap<EntityId, Outlet>) {
        // Changes of a writer whose readers are not connected yet wait, with those that follow them.
        let mut held = VecDeque::new();
        let mut held_writers: Vec<EntityId> = Vec::new();
        let mut woken: Vec<Arc<[String]>> = Vec::new();
        let mut sent = 0usize;
        loop {
            let Some(c) = lock(&self.pending).pop_front() else {
                break;
            };
            if held_writers.contains(&c.writer) {
                held.push_back(c);
                continue;
            }
            match self.send(outlets, &c) {
                Ok(true) => {
                    if !woken.iter().any(|n| Arc::ptr_eq(n, &c.nodes)) {
                        woken.push(c.nodes.clone());
                    }
                    // Readers drain while more is sent: a full queue would wait for them.
                    sent += 1;
                    if sent.is_multiple_of(WAKE_EVERY) {
                        self.wake_readers(&woken);
                        woken.clear();
                    }
                }
                Ok(false) => {
                    held_writers.push(c.writer);
                    held.push_back(c);
                }
                Err(e) => {
                    tracing::warn!(writer = ?c.writer, error = %e, "shared-memory send failed")
                }
            }
        }
        self.wake_readers(&woken);
        if !held.is_empty() {
            let mut pending = lock(&self.pending);
            while let Some(c) = held.pop_back() {
                pending.push_front(c);
            }
        }
    }

    /// Signals the reading threads of the participants of `nodes` (each once).
    fn wake_readers(&self, nodes: &[Arc<[String]>]) {
        if nodes.is_empty() {
            return;
        }
        let mut notifiers = lock(&self.notifiers);
        let mut done: Vec<&str> = Vec::new();
        for n in nodes.iter().flat_map(|n| n.iter()) {
            if done.contains(&n.as_str()) {
                continue;
            }
            done.push(n);
            if !notifiers.contains_key(n) {
                match self.node.notifier(&wake_channel(n)) {
                    Ok(x) => {
                        notifiers.insert(n.clone(), x);
                    }
                    Err(e) => {
                        tracing::debug!(node = n, error = %e, "no wake-up for a reader participant");
                        continue;
                    }
                }
            }
            if let Some(Err(e)) = notifiers.get(n).map(ShmNotifier::notify) {
                tracing::debug!(node = n, error = %e, "reader participant not woken");
                notifiers.remove(n);
            }
        }
    }

    /// Wakes our own reading thread.
    fn wake(&self) {
        if let Some(w) = &self.wake_self {
            let _ = w.notify();
        }
    }

    /// A buffer of `len` bytes from the channel of `writer` (reliable or not), for a sample written in
    /// place: [`park`](Self::park) it once the core has queued the change.
    pub(crate) fn loan(
        &self,
        writer: EntityId,
        reliable: bool,
        len: usize,
    ) -> Result<ShmLoan, ShmError> {
        let mut outlets = lock(&self.outlets);
        let out = match outlets.entry(writer) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(self.open_outlet(writer, reliable)?)
            }
        };
        out.publisher.loan(len)
    }

    /// Under the core lock, right after `Participant::write_loaned` queued change `sequence` of `writer`:
    /// the buffer that holds its sample (at `payload`), sent in the change's turn.
    pub(crate) fn park(
        &self,
        writer: EntityId,
        sequence: i64,
        loan: ShmLoan,
        payload: std::ops::Range<usize>,
    ) {
        lock(&self.parked).push(Parked {
            writer,
            sequence,
            loan,
            payload,
        });
    }

    fn open_outlet(&self, writer: EntityId, reliable: bool) -> Result<Outlet, ShmError> {
        let name = shm_channel_name(&Guid::new(self.prefix, writer));
        Ok(Outlet {
            publisher: self.node.publisher(&name, &channel_config(reliable))?,
            connected: None,
            waiting_since: None,
            acks: self.node.subscriber(&ack_channel(&name), &ack_config())?,
            owed: HashMap::new(),
            greeted: Vec::new(),
        })
    }

    /// Sends `c`; `Ok(false)` when it must wait for its nodes to connect, or for its loaned buffer.
    fn send(
        &self,
        outlets: &mut HashMap<EntityId, Outlet>,
        c: &ShmChange,
    ) -> Result<bool, ShmError> {
        let out = match outlets.entry(c.writer) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(self.open_outlet(c.writer, c.reliable)?)
            }
        };
        if !out
            .connected
            .as_ref()
            .is_some_and(|n| Arc::ptr_eq(n, &c.nodes))
        {
            out.read_acks();
            let mut missing = c.nodes.iter().filter(|n| !out.greeted.contains(n)).count();
            let since = *out.waiting_since.get_or_insert_with(Instant::now);
            let waited = since.elapsed();
            if missing > 0 && waited >= LIVENESS_CHECK {
                // A reader participant that died never connects: do not wait for it.
                missing = c
                    .nodes
                    .iter()
                    .filter(|n| !out.greeted.contains(n) && !node_gone(n))
                    .count();
            }
            if missing > 0 && waited < CONNECT_TIMEOUT {
                return Ok(false);
            }
            if missing > 0 {
                tracing::warn!(
                    missing,
                    "shared-memory readers not connected in time: they miss changes"
                );
            }
            let _ = out.publisher.update_connections();
            out.connected = Some(c.nodes.clone());
            out.waiting_since = None;
        }
        if c.loaned {
            let mut parked = lock(&self.parked);
            let at = parked
                .iter()
                .position(|p| p.writer == c.writer && p.sequence == c.sequence.0);
            // The core queues the change before its writer parks the buffer: until then it waits.
            let Some(mut p) = at.map(|i| parked.swap_remove(i)) else {
                return Ok(false);
            };
            drop(parked);
            c.write_header_with(&mut p.loan[..], Some(p.payload));
            p.loan.send()?;
        } else {
            let mut header = [0u8; ShmChange::HEADER_LEN];
            c.write_header(&mut header);
            out.publisher.send_parts(&[&header, &c.change.payload])?;
        }
        if !c.liveliness {
            for n in c.nodes.iter() {
                let owed = out.owed.entry(n.clone()).or_insert((0, 0));
                owed.0 = owed.0.max(c.sequence.0);
            }
        }
        Ok(true)
    }

    /// Whether every reader participant in `nodes` acknowledged all that `writer` sent it (true when
    /// nothing was sent on shared memory).
    pub(crate) fn acknowledged(&self, writer: EntityId, nodes: &[String]) -> bool {
        if lock(&self.pending).iter().any(|c| c.writer == writer) {
            return false;
        }
        let mut outlets = lock(&self.outlets);
        let Some(out) = outlets.get_mut(&writer) else {
            return true;
        };
        out.read_acks();
        nodes
            .iter()
            .all(|n| out.owed.get(n).is_none_or(|(sent, acked)| acked >= sent))
    }

    /// Before `writer` is deleted: sends what is pending, then waits (at most [`LINGER`]) until the
    /// reader participants in `nodes` acknowledged it. The deletion's SEDP announcement unmatches the
    /// writer's readers, and a reader participant closes the channel then, with what it has not drained
    /// yet: the writer's last changes (a benchmark's end marker, under load) were lost that way. A reader
    /// participant whose process died is not waited for ([`node_gone`]).
    pub(crate) fn linger(&self, writer: EntityId, nodes: &[String]) {
        if nodes.is_empty() {
            return;
        }
        self.flush();
        let mut waiting = nodes.to_vec();
        let start = Instant::now();
        let mut next_check = start;
        while !self.acknowledged(writer, &waiting) {
            let now = Instant::now();
            if now >= start + LINGER {
                tracing::debug!(
                    ?writer,
                    "shared-memory readers did not acknowledge before deletion"
                );
                return;
            }
            if now >= next_check {
                waiting.retain(|n| !node_gone(n));
                next_check = now + LIVENESS_CHECK;
            }
            std::thread::sleep(Duration::from_millis(1));
            // Changes held for a reader that turned out dead go now.
            self.flush();
        }
    }

    /// The writer was deleted: its channel closes (after what it sent).
    pub(crate) fn close_writer(&self, writer: EntityId) {
        self.flush();
        lock(&self.parked).retain(|p| p.writer != writer);
        lock(&self.outlets).remove(&writer);
    }

    /// Reads what arrived on the channels our readers read and gives it to the core; how many frames.
    /// Also opens and closes channels as the core's pairs changed.
    pub(crate) fn drain(&self, driver: &dyn ShmHost) -> usize {
        let mut inlets = lock(&self.inlets);
        let generation = self.generation.load(Ordering::Acquire);
        if generation != inlets.generation {
            inlets.generation = generation;
            let mut wanted = Vec::new();
            driver.query_shm(&mut |c| wanted = c.shm_subscriptions());
            self.resubscribe(&mut inlets, &wanted);
        }
        if inlets.channels.is_empty() {
            return 0;
        }
        let mut frames: Vec<(Guid, Payload)> = Vec::new();
        let mut highest = vec![0i64; inlets.channels.len()];
        let mut greeting = false;
        for (i, inlet) in inlets.channels.iter_mut().enumerate() {
            if let Some(since) = inlet.greeting_since {
                if inlet.subscriber.has_samples() {
                    inlet.greeting_since = None;
                } else if inlet.subscriber.connect() {
                    tracing::trace!(writer = ?inlet.writer, "connected to a writer's channel: greeting it");
                    self.acknowledge(inlet, 0);
                }
                greeting |= since.elapsed() < CONNECT_TIMEOUT;
            }
            for _ in 0..BATCH {
                match inlet.subscriber.receive() {
                    Ok(Some(s)) => {
                        if let Ok(h) = decode_header(&s) {
                            highest[i] = highest[i].max(h.sequence.0);
                        }
                        frames.push((inlet.writer, inlet.payload(s)));
                    }
                    Ok(None) => break,
                    Err(e) => {
                        tracing::warn!(writer = ?inlet.writer, error = %e, "shared-memory receive failed");
                        break;
                    }
                }
            }
        }
        self.greeting.store(greeting, Ordering::Release);
        let n = frames.len();
        if n > 0 {
            tracing::trace!(frames = n, "shared-memory frames drained");
            // Still under the inlets lock: two threads draining keep the channels' order. Our own
            // changes are not sent from here (see `poll_loop`).
            let mut frames = Some(frames);
            driver.with_core_from_shm(&mut |c, now| {
                for (writer, frame) in frames.take().into_iter().flatten() {
                    c.receive_shm(now, writer, frame);
                }
            });
            // They are in the readers' caches now.
            for (inlet, sn) in inlets.channels.iter().zip(highest) {
                if sn > 0 {
                    self.acknowledge(inlet, sn);
                }
            }
        }
        n
    }

    /// Before a receive thread handles datagrams: what arrived on the channels before them reaches the
    /// readers first (a writer's last changes before the announcement of its deletion, typically). The
    /// reading thread drains them (it decodes samples on its large stack; plain-data samples can be
    /// large arrays decoded by value) while this thread waits, at most [`DRAIN_WAIT`]. Free when nothing
    /// is queued. Without a reading-thread wake-up, drains here.
    pub(crate) fn drain_first(&self, driver: &dyn ShmHost) {
        let queued = lock(&self.inlets)
            .channels
            .iter()
            .any(|i| i.subscriber.has_samples());
        if !queued || self.stopped.load(Ordering::Acquire) {
            return;
        }
        if self.listener.is_none() {
            self.drain(driver);
            return;
        }
        let mut passes = lock(&self.passes);
        // A pass already under way may have read the channels before the frames came.
        let target = *passes + 2;
        self.wake();
        let deadline = Instant::now() + DRAIN_WAIT;
        while *passes < target {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() || self.stopped.load(Ordering::Acquire) {
                break;
            }
            passes = self
                .passed
                .wait_timeout(passes, left)
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .0;
        }
    }

    /// The reading thread finished a drain pass.
    fn count_pass(&self) {
        *lock(&self.passes) += 1;
        self.passed.notify_all();
    }

    fn acknowledge(&self, inlet: &Inlet, sn: i64) {
        let node = self.node.id();
        let sent = inlet.acks.loan(8 + node.len()).and_then(|mut loan| {
            encode_ack(sn, &node, &mut loan);
            loan.send()
        });
        if let Err(e) = sent {
            tracing::debug!(writer = ?inlet.writer, error = %e, "shared-memory acknowledgement not sent");
        }
    }

    fn resubscribe(&self, inlets: &mut Inlets, wanted: &[Guid]) {
        inlets.channels.retain(|i| wanted.contains(&i.writer));
        for w in wanted {
            if inlets.channels.iter().any(|i| i.writer == *w) {
                continue;
            }
            let name = shm_channel_name(w);
            let opened = self
                .node
                .subscriber(&name, &ShmChannelConfig::default())
                .and_then(|subscriber| {
                    Ok(Inlet {
                        writer: *w,
                        subscriber,
                        acks: self.node.publisher(&ack_channel(&name), &ack_config())?,
                        greeting_since: Some(Instant::now()),
                        held: Arc::new(AtomicUsize::new(0)),
                    })
                });
            match opened {
                Ok(i) => inlets.channels.push(i),
                Err(e) => tracing::warn!(writer = ?w, error = %e, "cannot read a writer's channel"),
            }
        }
    }

    /// Stops the polling thread and closes every channel.
    pub(crate) fn shutdown(&self) {
        self.stopped.store(true, Ordering::Release);
        self.wake();
        if let Some(h) = lock(&self.thread).take() {
            if h.thread().id() != std::thread::current().id() {
                let _ = h.join();
            }
        }
        lock(&self.parked).clear();
        lock(&self.outlets).clear();
        lock(&self.inlets).channels.clear();
        lock(&self.notifiers).clear();
    }
}

/// The reading thread: drains the channels, then sleeps until a writer signals that it sent frames to
/// this participant (or the channels to read changed), at most [`MAX_IDLE`]; without an event channel it
/// polls, sleeping longer (up to 1 ms) while nothing arrives.
fn poll_loop<H: ShmHost>(driver: Weak<H>) {
    let mut idle = Duration::from_micros(20);
    loop {
        let Some(d) = driver.upgrade() else {
            return;
        };
        // The thread never waits to send (a peer's queue may be full while its own thread waits on
        // ours): it only sends when no other thread is sending, changes held for connecting readers
        // typically.
        let (n, held, listener) = match d.shm_link() {
            Some(link) if !link.stopped.load(Ordering::Acquire) => {
                let n = link.drain(&*d);
                link.count_pass();
                link.try_flush();
                let held = !lock(&link.pending).is_empty() || link.greeting.load(Ordering::Acquire);
                (n, held, link.listener.clone())
            }
            _ => return,
        };
        drop(d);
        if n > 0 {
            idle = Duration::from_micros(20);
            continue;
        }
        match listener {
            Some(l) => {
                let timeout = if held { HELD_RETRY } else { MAX_IDLE };
                if let Err(e) = l.wait(timeout) {
                    tracing::debug!(error = %e, "shared-memory wait failed");
                    std::thread::sleep(HELD_RETRY);
                }
            }
            None => {
                if held {
                    idle = Duration::from_micros(20);
                }
                std::thread::sleep(idle);
                idle = (idle * 2).min(HELD_RETRY);
            }
        }
    }
}
