//! The reader side of the link: the channels of peers' writers our readers read, the frames they hold,
//! and our acknowledgements to those writers.

use super::*;

/// One peer writer's channel that our readers read, and where we acknowledge what it sent.
pub(super) struct Inlet {
    writer: Guid,
    subscriber: ShmSubscriber,
    acks: ShmPublisher,
    /// Until its first frame: since when it tells the writer, on the acknowledgement channel, that it is
    /// connected (an acknowledgement of 0) once it is. A writer sends nothing before that: iceoryx2
    /// skips a subscriber that is not connected yet once its queue is full, and the samples would be lost.
    greeting_since: Option<Instant>,
    /// Frames of this channel still held (decoding, or kept in place by readers, `dcps::InPlace`):
    /// those in `holders`.
    held: usize,
    /// The holders of the frames given to the core, reused once released ([`Inlet::release`]).
    holders: Vec<Arc<HeldFrame>>,
    /// Since when its readers hold [`MAX_HELD`] frames ([`Inlet::defer`]).
    full_since: Option<Instant>,
}

/// Most frames of one channel held at once; past it, frames are copied out of shared memory and given
/// back at once. iceoryx2 lends a subscriber at most the channel's queue depth of frames: readers that
/// keep samples in place must not take them all, or the channel would stall.
const MAX_HELD: usize = 12;

/// How long a channel's frames are left in its queue while its readers hold [`MAX_HELD`] frames, before
/// frames are copied out instead ([`Inlet::defer`]).
const HOLD_GRACE: Duration = Duration::from_millis(5);

/// Frames at least this long are given to the core one at a time ([`ShmLink::drain`]).
const ONE_BY_ONE: usize = 64 * 1024;

/// A holder of one frame read from a channel: the owner of the [`Payload`]s the core and the readers
/// share. Holders are pooled per channel ([`Inlet::payload`]): once no payload refers to a holder any more,
/// [`Inlet::release`] gives its frame back to the writer and keeps the holder for the next frame, so that
/// reading a frame allocates nothing.
pub(super) struct HeldFrame {
    frame: Option<ShmSample>,
}

impl AsRef<[u8]> for HeldFrame {
    fn as_ref(&self) -> &[u8] {
        self.frame.as_deref().unwrap_or_default()
    }
}

impl Inlet {
    /// The frame as a payload: shared in place, or copied when too many frames are held already.
    fn payload(&mut self, frame: ShmSample) -> Payload {
        if self.held >= MAX_HELD {
            self.release();
            if self.held >= MAX_HELD {
                return Payload::copy_from_slice(&frame);
            }
        }
        self.held += 1;
        // A free holder (its frame released), else a new one.
        let free = self
            .holders
            .iter_mut()
            .position(|h| Arc::get_mut(h).is_some_and(|h| h.frame.is_none()));
        let slot = match free {
            Some(i) => &mut self.holders[i],
            None => {
                self.holders.push(Arc::new(HeldFrame { frame: None }));
                self.holders.last_mut().expect("just pushed")
            }
        };
        if let Some(h) = Arc::get_mut(slot) {
            h.frame = Some(frame);
        }
        let owner: Arc<dyn AsRef<[u8]> + Send + Sync> = slot.clone();
        Payload::from_owner(owner)
    }

    /// Whether to leave this channel's frames in its queue for now: its readers hold [`MAX_HELD`] frames
    /// (samples not taken yet, typically: the reading application is behind its writer). For up to
    /// [`HOLD_GRACE`] the frames wait (a full queue then holds the writer back) rather than being copied
    /// out of shared memory, which cost a reader of 1 MiB samples read in place more CPU than everything
    /// else; past it frames are copied as before, so a reader that keeps samples in place holds its
    /// writer back [`HOLD_GRACE`] at most.
    fn defer(&mut self, now: Instant) -> bool {
        if self.held >= MAX_HELD {
            self.release();
        }
        if self.held < MAX_HELD {
            self.full_since = None;
            return false;
        }
        now - *self.full_since.get_or_insert(now) < HOLD_GRACE
    }

    /// Gives back to the writer the frames no payload refers to any more (their readers decoded them, or
    /// dropped what they kept in place).
    fn release(&mut self) {
        if self.held == 0 {
            return;
        }
        for h in &mut self.holders {
            if let Some(h) = Arc::get_mut(h) {
                if h.frame.take().is_some() {
                    self.held -= 1;
                }
            }
        }
    }
}

/// The channels our readers read, and the core generation they were set up for.
#[derive(Default)]
pub(super) struct Inlets {
    generation: u64,
    pub(super) channels: Vec<Inlet>,
    /// A drain pass's frames (by channel), and the highest sequence number read per channel (kept from
    /// pass to pass: a pass allocates nothing).
    frames: Vec<(usize, Guid, Payload)>,
    highest: Vec<i64>,
}

impl ShmLink {
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
        let Inlets {
            channels,
            frames,
            highest,
            ..
        } = &mut *inlets;
        highest.clear();
        highest.resize(channels.len(), 0);
        let mut greeting = false;
        let mut deferred = false;
        let now = Instant::now();
        for (i, inlet) in channels.iter_mut().enumerate() {
            inlet.release();
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
                if inlet.defer(now) {
                    deferred = true;
                    break;
                }
                match inlet.subscriber.receive() {
                    Ok(Some(s)) => {
                        if let Ok(h) = decode_header(&s) {
                            highest[i] = highest[i].max(h.sequence.0);
                        }
                        let payload = inlet.payload(s);
                        frames.push((i, inlet.writer, payload));
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
        self.deferring.store(deferred, Ordering::Release);
        let n = frames.len();
        if n > 0 {
            tracing::trace!(frames = n, "shared-memory frames drained");
            // Still under the inlets lock: two threads draining keep the channels' order. Our own
            // changes are not sent from here (see `poll_loop`).
            if frames.iter().any(|(_, _, f)| f.len() >= ONE_BY_ONE) {
                // Each large frame is decoded on its own and goes back to its writer at once: the
                // writer's next loan reuses the buffer given back last, still warm in the caches.
                for (i, writer, frame) in frames.drain(..) {
                    let mut frame = Some(frame);
                    driver.with_core_from_shm(&mut |c, now| {
                        if let Some(f) = frame.take() {
                            c.receive_shm(now, writer, f);
                        }
                    });
                    channels[i].release();
                }
            } else {
                driver.with_core_from_shm(&mut |c, now| {
                    for (_, writer, frame) in frames.drain(..) {
                        c.receive_shm(now, writer, frame);
                    }
                });
            }
            frames.clear();
            // They are in the readers' caches now: the frames decoded go back to their writers.
            for (inlet, &sn) in channels.iter_mut().zip(highest.iter()) {
                inlet.release();
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
    pub(super) fn count_pass(&self) {
        *lock(&self.passes) += 1;
        self.passed.notify_all();
    }

    fn acknowledge(&self, inlet: &Inlet, sn: i64) {
        let node = &self.node_id;
        let sent = inlet.acks.loan(8 + node.len()).and_then(|mut loan| {
            encode_ack(sn, node, &mut loan);
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
                        held: 0,
                        holders: Vec::new(),
                        full_since: None,
                    })
                });
            match opened {
                Ok(i) => inlets.channels.push(i),
                Err(e) => tracing::warn!(writer = ?w, error = %e, "cannot read a writer's channel"),
            }
        }
    }
}
