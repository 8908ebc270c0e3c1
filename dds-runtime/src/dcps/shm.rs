//! The participant's shared-memory link (feature `shm`): the I/O side of the core's shared-memory pairs
//! (`rtps::shm`). One channel per writer: the driver sends each change the core queued for it
//! ([`Participant::poll_shm`]) as one frame written into a loaned buffer, and reads the channels of the
//! peers' writers its readers are matched with, giving each frame to the core in place
//! ([`Participant::receive_shm`]).
//!
//! What holds for a pair on shared memory: every change the writer sent reaches the reader's participant,
//! in order, unless that participant's queue stays full longer than [`DELIVERY_TIMEOUT`] (reliable
//! writers; best-effort writers drop at once for a full queue), or its subscriber is not connected within
//! [`CONNECT_TIMEOUT`] of the first send after the match. Nothing is repaired afterwards: iceoryx2's
//! delivery replaces RTPS acknowledgements for these pairs.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use foldhash::{HashMap, HashMapExt};

use super::driver::Driver;
use super::sync::lock;
use crate::rtps::shm::{shm_channel_name, ShmChange, SHM_HOST_PROPERTY, SHM_NODE_PROPERTY};
use crate::rtps::{EntityId, Guid, GuidPrefix, Participant, Payload};
use crate::transport::shm::{
    host_id, ShmChannelConfig, ShmError, ShmNode, ShmPublisher, ShmSubscriber,
};

/// How long a send waits for the subscribers of the readers' participants to connect to a new channel.
pub(crate) const CONNECT_TIMEOUT: Duration = Duration::from_secs(2);

/// How long a reliable writer's send waits for a subscriber whose queue is full.
pub(crate) const DELIVERY_TIMEOUT: Duration = Duration::from_secs(10);

/// Frames taken from one channel per pass (they stay borrowed until their readers decoded them).
const BATCH: usize = 8;

/// Longest sleep of the polling thread when no frame arrives.
const MAX_IDLE: Duration = Duration::from_millis(1);

/// One writer's channel, and the set of nodes last seen connected to it.
struct Outlet {
    publisher: ShmPublisher,
    connected: Option<Arc<[String]>>,
}

/// The channels our readers read, and the core generation they were set up for.
#[derive(Default)]
struct Inlets {
    generation: u64,
    subscribers: Vec<(Guid, ShmSubscriber)>,
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
        let link = ShmLink {
            node,
            prefix,
            pending: Mutex::new(VecDeque::new()),
            outlets: Mutex::new(HashMap::new()),
            inlets: Mutex::new(Inlets::default()),
            generation: AtomicU64::new(0),
            stopped: AtomicBool::new(false),
            thread: Mutex::new(None),
        };
        Some((link, props))
    }

    /// Starts the thread that reads the channels.
    pub(crate) fn start(&self, driver: Weak<Driver>) -> std::io::Result<()> {
        let h = std::thread::Builder::new()
            .name("dds-shm".into())
            .spawn(move || poll_loop(driver))?;
        *lock(&self.thread) = Some(h);
        Ok(())
    }

    /// Under the core lock: takes what the core queued for the channels.
    pub(crate) fn take_from(&self, core: &mut Participant) {
        self.generation
            .store(core.shm_generation(), Ordering::Release);
        let mut pending = None;
        while let Some(c) = core.poll_shm() {
            pending
                .get_or_insert_with(|| lock(&self.pending))
                .push_back(c);
        }
    }

    /// Sends what was taken, in order (without the core lock).
    pub(crate) fn flush(&self) {
        if lock(&self.pending).is_empty() {
            return;
        }
        let mut outlets = lock(&self.outlets);
        loop {
            let Some(c) = lock(&self.pending).pop_front() else {
                break;
            };
            let writer = c.writer;
            if let Err(e) = self.send(&mut outlets, c) {
                tracing::warn!(?writer, error = %e, "shared-memory send failed");
            }
        }
    }

    fn send(&self, outlets: &mut HashMap<EntityId, Outlet>, c: ShmChange) -> Result<(), ShmError> {
        let out = match outlets.entry(c.writer) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                let name = shm_channel_name(&Guid::new(self.prefix, c.writer));
                let publisher = self.node.publisher(&name, &channel_config(c.reliable))?;
                e.insert(Outlet {
                    publisher,
                    connected: None,
                })
            }
        };
        if !out
            .connected
            .as_ref()
            .is_some_and(|n| Arc::ptr_eq(n, &c.nodes))
        {
            wait_connected(&out.publisher, &c.nodes);
            out.connected = Some(c.nodes.clone());
        }
        let mut loan = out.publisher.loan(c.frame_len())?;
        c.write_frame(&mut loan);
        loan.send()?;
        Ok(())
    }

    /// The writer was deleted: its channel closes (after what it sent).
    pub(crate) fn close_writer(&self, writer: EntityId) {
        self.flush();
        lock(&self.outlets).remove(&writer);
    }

    /// Reads what arrived on the channels our readers read and gives it to the core; how many frames.
    /// Also opens and closes channels as the core's pairs changed.
    pub(crate) fn drain(&self, driver: &Driver) -> usize {
        let mut inlets = lock(&self.inlets);
        let generation = self.generation.load(Ordering::Acquire);
        if generation != inlets.generation {
            inlets.generation = generation;
            let wanted = driver.query_core(Participant::shm_subscriptions);
            self.resubscribe(&mut inlets, &wanted);
        }
        if inlets.subscribers.is_empty() {
            return 0;
        }
        let mut frames: Vec<(Guid, Payload)> = Vec::new();
        for (writer, sub) in &inlets.subscribers {
            for _ in 0..BATCH {
                match sub.receive() {
                    Ok(Some(s)) => frames.push((*writer, Payload::from_owner(Arc::new(s)))),
                    Ok(None) => break,
                    Err(e) => {
                        tracing::warn!(?writer, error = %e, "shared-memory receive failed");
                        break;
                    }
                }
            }
        }
        let n = frames.len();
        if n > 0 {
            // Still under the inlets lock: two threads draining keep the channels' order.
            driver.with_core(|c, now| {
                for (writer, frame) in frames {
                    c.receive_shm(now, writer, frame);
                }
            });
        }
        n
    }

    fn resubscribe(&self, inlets: &mut Inlets, wanted: &[Guid]) {
        inlets.subscribers.retain(|(w, _)| wanted.contains(w));
        for w in wanted {
            if inlets.subscribers.iter().any(|(g, _)| g == w) {
                continue;
            }
            match self
                .node
                .subscriber(&shm_channel_name(w), &ShmChannelConfig::default())
            {
                Ok(s) => inlets.subscribers.push((*w, s)),
                Err(e) => tracing::warn!(writer = ?w, error = %e, "cannot read a writer's channel"),
            }
        }
    }

    /// Stops the polling thread and closes every channel.
    pub(crate) fn shutdown(&self) {
        self.stopped.store(true, Ordering::Release);
        if let Some(h) = lock(&self.thread).take() {
            if h.thread().id() != std::thread::current().id() {
                let _ = h.join();
            }
        }
        lock(&self.outlets).clear();
        lock(&self.inlets).subscribers.clear();
    }
}

/// Waits (at most [`CONNECT_TIMEOUT`]) until a subscriber of every node in `nodes` is on the channel.
fn wait_connected(publisher: &ShmPublisher, nodes: &[String]) {
    let deadline = Instant::now() + CONNECT_TIMEOUT;
    loop {
        let subs = publisher.subscriber_nodes();
        if nodes.iter().all(|n| subs.contains(n)) {
            let _ = publisher.update_connections();
            return;
        }
        if Instant::now() >= deadline {
            tracing::warn!(
                missing = nodes.iter().filter(|n| !subs.contains(n)).count(),
                "shared-memory readers not connected in time: they miss what is sent before they connect"
            );
            return;
        }
        std::thread::sleep(Duration::from_micros(200));
    }
}

/// The polling thread: drains the channels, sleeping longer (up to [`MAX_IDLE`]) while nothing arrives.
fn poll_loop(driver: Weak<Driver>) {
    let mut idle = Duration::from_micros(20);
    loop {
        let Some(d) = driver.upgrade() else {
            return;
        };
        let n = match d.shm_link() {
            Some(link) if !link.stopped.load(Ordering::Acquire) => link.drain(&d),
            _ => return,
        };
        drop(d);
        if n > 0 {
            idle = Duration::from_micros(20);
            continue;
        }
        std::thread::sleep(idle);
        idle = (idle * 2).min(MAX_IDLE);
    }
}
