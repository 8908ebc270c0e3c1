//! The writer side of the link: our writers' channels, the changes queued for them, and the
//! acknowledgements their reader participants send back.

use super::*;

/// A change written in a loaned buffer (`DataWriter::loan`), waiting for its turn in the channel.
pub(super) struct Parked {
    writer: EntityId,
    sequence: i64,
    loan: ShmLoan,
    /// Where the serialized sample is in the buffer.
    payload: std::ops::Range<usize>,
}

/// A loan of a writer's channel counted by [`ShmLink::reserve`], until dropped.
#[derive(Debug)]
pub(crate) struct LoanReservation(Arc<AtomicUsize>);

impl Drop for LoanReservation {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::Relaxed);
    }
}

/// What a flush collects, kept between flushes (empty) for the capacity of its collections.
#[derive(Default)]
pub(super) struct FlushScratch {
    /// Changes of a writer whose readers are not connected yet (or whose loaned buffer is not parked
    /// yet) wait, with those that follow them.
    held: VecDeque<ShmChange>,
    held_writers: Vec<EntityId>,
    /// The reader participants to wake.
    woken: Vec<Arc<[String]>>,
}

/// One writer's channel, the set of nodes last seen connected to it, and its acknowledgements.
pub(super) struct Outlet {
    publisher: ShmPublisher,
    connected: Option<Arc<[String]>>,
    /// Since when a change waits for its nodes to connect.
    waiting_since: Option<Instant>,
    acks: ShmSubscriber,
    /// By node: the highest sequence number sent while it was expected, and the highest it acknowledged.
    owed: HashMap<String, (i64, i64)>,
    /// The nodes that said (on the acknowledgement channel) that they are connected to the channel.
    greeted: Vec<String>,
    /// The awaited nodes found gone at the last liveness check, and when the next check is due: listing
    /// the host's nodes costs a scan of shared memory, so a flush repeats it at most every
    /// [`LIVENESS_CHECK`].
    gone: Vec<String>,
    next_check: Option<Instant>,
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

    /// How many of `nodes` are not connected yet. After waiting [`LIVENESS_CHECK`] for them, those whose
    /// process died are not counted (they never connect); the check itself runs at most every
    /// [`LIVENESS_CHECK`].
    fn missing(&mut self, nodes: &[String], waited: Duration, now: Instant) -> usize {
        let awaited = |n: &&String| !self.greeted.contains(n);
        if waited >= LIVENESS_CHECK && self.next_check.is_none_or(|t| now >= t) {
            self.gone = nodes
                .iter()
                .filter(awaited)
                .filter(|n| node_gone(n))
                .cloned()
                .collect();
            self.next_check = Some(now + LIVENESS_CHECK);
        }
        nodes
            .iter()
            .filter(awaited)
            .filter(|n| !self.gone.contains(n))
            .count()
    }
}

impl ShmLink {
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
    pub(super) fn try_flush(&self) {
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
        // Kept from flush to flush, empty, for their capacity (the outlets' lock is held): a flush
        // allocates nothing.
        let FlushScratch {
            mut held,
            mut held_writers,
            mut woken,
        } = std::mem::take(&mut *lock(&self.scratch));
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
        woken.clear();
        if !held.is_empty() {
            let mut pending = lock(&self.pending);
            while let Some(c) = held.pop_back() {
                pending.push_front(c);
            }
        }
        held_writers.clear();
        *lock(&self.scratch) = FlushScratch {
            held,
            held_writers,
            woken,
        };
    }

    /// Signals the reading threads of the participants of `nodes` (each once).
    fn wake_readers(&self, nodes: &[Arc<[String]>]) {
        if nodes.is_empty() {
            return;
        }
        let mut notifiers = lock(&self.notifiers);
        let all = || nodes.iter().flat_map(|n| n.iter());
        for (i, n) in all().enumerate() {
            // Each once (the lists are short: no set to allocate).
            if all().take(i).any(|m| m == n) {
                continue;
            }
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

    /// A buffer of `len` bytes from the channel of `writer` (reliable or not), for a sample written in
    /// place: [`park`](Self::park) it once the core has queued the change. `zeroed`: every byte 0;
    /// otherwise the bytes are unspecified ([`ShmPublisher::loan_unzeroed`]: an earlier frame's, or
    /// zeros). Take a [`reserve`](Self::reserve)ation first and keep it until the buffer is parked.
    pub(crate) fn loan(
        &self,
        writer: EntityId,
        reliable: bool,
        len: usize,
        zeroed: bool,
    ) -> Result<ShmLoan, ShmError> {
        let mut outlets = lock(&self.outlets);
        let publisher = &self.outlet(&mut outlets, writer, reliable)?.publisher;
        if zeroed {
            publisher.loan(len)
        } else {
            publisher.loan_unzeroed(len)
        }
    }

    /// [`loan`](Self::loan), not initialized (for a sample serialized into it).
    pub(crate) fn loan_uninit(
        &self,
        writer: EntityId,
        reliable: bool,
        len: usize,
    ) -> Result<ShmLoanUninit, ShmError> {
        self.outlet(&mut lock(&self.outlets), writer, reliable)?
            .publisher
            .loan_uninit(len)
    }

    /// The channel of `writer`, opened if it is not yet.
    fn outlet<'o>(
        &self,
        outlets: &'o mut HashMap<EntityId, Outlet>,
        writer: EntityId,
        reliable: bool,
    ) -> Result<&'o mut Outlet, ShmError> {
        Ok(match outlets.entry(writer) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(self.open_outlet(writer, reliable)?)
            }
        })
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

    /// Leave to loan a buffer of `writer`'s channel for a sample written in place (by the user,
    /// `DataWriter::loan`, or serialized into it, `DataWriter::write_direct`) that will wait there for its
    /// turn ([`park`](Self::park)); `None` when that would leave no loan free. Keep it until the buffer
    /// is parked or dropped. Parked and lent buffers are loans, and one loan must stay free for a change
    /// that is copied into the channel when its turn comes (an ordinary write, or a change queued before
    /// the parked ones): when every loan was parked, such a change found none (`ExceedsMaxLoans`) and was
    /// lost (the first sample of a burst written before the reader connected, the others loaned behind
    /// it); when a user held every loan, an ordinary write of the same writer was lost the same way.
    pub(crate) fn reserve(&self, writer: EntityId) -> Option<LoanReservation> {
        let mut lent = lock(&self.lent);
        let count = lent.entry(writer).or_default();
        let parked = lock(&self.parked)
            .iter()
            .filter(|p| p.writer == writer)
            .count();
        if count.load(Ordering::Relaxed) + parked + 1 >= channel_config(true).max_loans {
            return None;
        }
        count.fetch_add(1, Ordering::Relaxed);
        Some(LoanReservation(count.clone()))
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
            gone: Vec::new(),
            next_check: None,
        })
    }

    /// Sends `c`; `Ok(false)` when it must wait for its nodes to connect, or for its loaned buffer.
    fn send(
        &self,
        outlets: &mut HashMap<EntityId, Outlet>,
        c: &ShmChange,
    ) -> Result<bool, ShmError> {
        let out = self.outlet(outlets, c.writer, c.reliable)?;
        if !out
            .connected
            .as_ref()
            .is_some_and(|n| Arc::ptr_eq(n, &c.nodes))
        {
            out.read_acks();
            let now = Instant::now();
            let waited = now - *out.waiting_since.get_or_insert(now);
            let missing = out.missing(&c.nodes, waited, now);
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
            out.next_check = None;
            out.gone.clear();
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
                // A node's name is copied once, when it first gets a change.
                match out.owed.get_mut(n) {
                    Some(owed) => owed.0 = owed.0.max(c.sequence.0),
                    None => {
                        out.owed.insert(n.clone(), (c.sequence.0, 0));
                    }
                }
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
        lock(&self.lent).remove(&writer);
        lock(&self.outlets).remove(&writer);
    }
}
