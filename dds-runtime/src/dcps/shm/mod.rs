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

mod inlet;
mod outlet;

use inlet::Inlets;
pub(crate) use outlet::LoanReservation;
use outlet::{FlushScratch, Outlet, Parked};

use super::sync::lock;
use crate::rtps::shm::{
    decode_header, shm_channel_name, ShmChange, SHM_HOST_PROPERTY, SHM_NODE_PROPERTY,
};
use crate::rtps::{EntityId, Guid, GuidPrefix, Participant, Payload};
use crate::transport::shm::{
    host_id, node_status, NodeStatus, ShmChannelConfig, ShmError, ShmListener, ShmLoan,
    ShmLoanUninit, ShmNode, ShmNotifier, ShmPublisher, ShmSample, ShmSubscriber,
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

/// How often the reading thread looks again at channels whose frames it left queued because their
/// readers hold many already.
const DEFER_POLL: Duration = Duration::from_micros(100);

/// How often changes held for readers that are not connected yet are retried.
const HELD_RETRY: Duration = Duration::from_millis(1);

/// The event channel that wakes the reading thread of the participant whose node is `node`: writers
/// signal it after sending frames to that participant, and the participant itself when the channels it
/// reads change.
fn wake_channel(node: &str) -> String {
    format!("dds/n/{node}")
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

/// A participant's presence in shared memory.
pub(crate) struct ShmLink {
    node: ShmNode,
    /// `node`'s identity ([`ShmNode::id`]), which acknowledgements carry.
    node_id: String,
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
    /// What a flush collects (kept between flushes for its capacity).
    scratch: Mutex<FlushScratch>,
    /// Loaned changes the core queued, until their turn.
    parked: Mutex<Vec<Parked>>,
    /// By writer: buffers loaned from its channel for a sample written in place and not parked yet
    /// ([`ShmLink::reserve`]).
    lent: Mutex<HashMap<EntityId, Arc<AtomicUsize>>>,
    /// Whether a channel we read waits for its first frame and greets its writer (the reading thread
    /// then polls quickly: the writer waits for the greeting).
    greeting: AtomicBool,
    /// Whether a channel's frames were left in its queue at the last drain pass because its readers
    /// hold many already (the reading thread then polls every [`DEFER_POLL`]: a reader that drops
    /// samples does not signal).
    deferring: AtomicBool,
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
            node_id: node.id(),
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
            scratch: Mutex::new(FlushScratch::default()),
            parked: Mutex::new(Vec::new()),
            lent: Mutex::new(HashMap::new()),
            greeting: AtomicBool::new(false),
            deferring: AtomicBool::new(false),
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

    /// Wakes our own reading thread.
    fn wake(&self) {
        if let Some(w) = &self.wake_self {
            let _ = w.notify();
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
        let (n, held, deferring, listener) = match d.shm_link() {
            Some(link) if !link.stopped.load(Ordering::Acquire) => {
                let n = link.drain(&*d);
                link.count_pass();
                link.try_flush();
                let held = !lock(&link.pending).is_empty() || link.greeting.load(Ordering::Acquire);
                let deferring = link.deferring.load(Ordering::Acquire);
                (n, held, deferring, link.listener.clone())
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
                let timeout = match (deferring, held) {
                    (true, _) => DEFER_POLL,
                    (false, true) => HELD_RETRY,
                    (false, false) => MAX_IDLE,
                };
                if let Err(e) = l.wait(timeout) {
                    tracing::debug!(error = %e, "shared-memory wait failed");
                    std::thread::sleep(HELD_RETRY);
                }
            }
            None => {
                if held || deferring {
                    idle = Duration::from_micros(20);
                }
                std::thread::sleep(idle);
                idle = (idle * 2).min(HELD_RETRY);
            }
        }
    }
}
