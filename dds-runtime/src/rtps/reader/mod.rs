//! Readers: per-writer proxies, reordering, duplicate suppression, defragmentation and acknowledgement
//! (§8.4.10, §8.4.12).

mod coherent;
mod defrag;
mod historical;
mod reorder;
mod writer_proxy;

pub(crate) use reorder::{PendingChange, Slot};
use writer_proxy::Backlog;
pub(crate) use writer_proxy::WriterProxy;

/// How long an ACKNACK that asks for nothing waits when it only serves discovery: a builtin reader's
/// acknowledgement and any reader's pre-emptive ACKNACK to a newly matched writer. The ACKNACKs that
/// fall due within this window leave in one pass of the participant, so those for one peer share a
/// datagram (RTPS 2.5 §8.4.12.1, heartbeatResponseDelay; Fast DDS waits 5 ms too). An ACKNACK that asks
/// for changes is not delayed by it: repair latency is unchanged.
pub(crate) const DISCOVERY_ACK_DELAY: Duration = Duration::from_millis(5);

/// How long a user reader's pre-emptive ACKNACK to a newly matched writer waits. A peer's endpoints are
/// matched one announcement at a time as they come; waiting lets the ACKNACKs of all our readers to one
/// peer leave together (the first one due takes the others along, `Reader::send_acknacks_along`). Fast
/// DDS waits 70 ms (`initial_acknack_delay`). Our volatile writers get none (see
/// `Participant::add_proxy`). A builtin reader's waits [`DISCOVERY_ACK_DELAY`], so that it leaves with the
/// acknowledgement of the peer's pushed announcements, which arrive at about the same time.
pub(crate) const PREEMPTIVE_ACK_DELAY: Duration = Duration::from_millis(20);

use std::time::{Duration, Instant};

use crate::rtps::api::{ChangeKind, Event, Payload, ReceivedSample};
use crate::rtps::due::DueQueue;
use crate::rtps::messages::{
    AckNack, Data, DataFrag, Gap, Heartbeat, HeartbeatFrag, NackFrag, Submessage,
};
use crate::rtps::outbox::{Outbox, Ts};
use crate::rtps::pool::BufferPool;
use crate::rtps::proxy_map::ProxyMap;
use crate::rtps::types::*;
use coherent::{group_set, SetLimits, SetMark};
use defrag::Defrag;

/// Whether every must-understand inline QoS parameter is one we know.
fn inline_qos_understood(q: Option<&crate::rtps::messages::ParameterList<'_>>) -> bool {
    q.is_none_or(|q| q.check_must_understand(understood_pid).is_ok())
}

/// The must-understand inline QoS parameters a reader knows.
fn understood_pid(id: u16) -> bool {
    use crate::rtps::messages::parameter::pid;
    matches!(
        id & !pid::MUST_UNDERSTAND,
        pid::KEY_HASH | pid::STATUS_INFO | pid::TOPIC_NAME
    )
}

/// The change a complete reassembly makes (`None` when its payload cannot be assembled).
fn assembled(df: Defrag, pool: &mut BufferPool) -> Option<Slot> {
    let kind = df
        .status_info
        .map_or(ChangeKind::Alive, ChangeKind::from_status_info);
    let key_hash = df.key_hash;
    let source_timestamp = df.source_timestamp;
    let group_seq = df.group_seq;
    let coherent = df.coherent_set.map(|set| SetMark {
        set,
        end: false,
        group: None,
        group_set: None,
    });
    let payload = df.assemble(pool)?;
    Some(Slot::Change(PendingChange {
        kind,
        payload,
        key_hash,
        source_timestamp,
        coherent,
        group_seq,
    }))
}

/// Protocol parameters of one reader.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ReaderParams {
    pub reliable: bool,
    /// Delay before an ACKNACK that asks for missing changes.
    pub heartbeat_response_delay: Duration,
    /// Delay before an ACKNACK that asks for nothing (a pure acknowledgement). For a builtin reader it is
    /// at least [`DISCOVERY_ACK_DELAY`].
    pub ack_delay: Duration,
    pub max_sample_size: usize,
    pub defrag_max_samples: usize,
    pub defrag_max_bytes: usize,
    pub reorder_max_samples: usize,
    pub reorder_max_bytes: usize,
}

/// A local reader's protocol state.
#[derive(Debug)]
pub(crate) struct Reader {
    pub guid: Guid,
    params: ReaderParams,
    /// Sorted boxes (see `ProxyMap`, and `docs/performance.md`, "Footprint").
    proxies: ProxyMap<WriterProxy>,
    /// The proxies whose `acknack_due` or `nackfrag_due` is armed, in deadline order.
    due: DueQueue,
    /// Back-pressure: how many more changes reliable proxies may deliver (`None`: no limit). A change
    /// refused for lack of credit is not stored, so it stays missing and is NACKed, never acknowledged.
    credit: std::cell::Cell<Option<usize>>,
}

impl Reader {
    pub(crate) fn new(guid: Guid, mut params: ReaderParams) -> Self {
        if guid.entity_id.is_builtin() {
            params.ack_delay = params.ack_delay.max(DISCOVERY_ACK_DELAY);
        }
        Reader {
            guid,
            params,
            proxies: ProxyMap::new(),
            due: DueQueue::default(),
            credit: std::cell::Cell::new(None),
        }
    }

    /// Sets the delivery credit and delivers what reliable proxies hold in order within it.
    pub(crate) fn set_credit(&mut self, credit: Option<usize>, out: &mut Vec<Event>) {
        self.credit.set(credit);
        let rid = self.guid.entity_id;
        let to = (rid, self.set_limits());
        for p in self.proxies.values_mut() {
            if p.reliable {
                Self::drain(to, p, &self.credit, out);
            }
        }
    }

    /// Consumes one unit of credit; false when none is left.
    fn take_credit(credit: &std::cell::Cell<Option<usize>>) -> bool {
        match credit.get() {
            None => true,
            Some(0) => false,
            Some(n) => {
                credit.set(Some(n - 1));
                true
            }
        }
    }

    /// Whether the reader is reliable.
    pub(crate) fn is_reliable(&self) -> bool {
        self.params.reliable
    }

    pub(crate) fn matched(&self) -> impl Iterator<Item = &Guid> {
        self.proxies.keys()
    }
    pub(crate) fn has_proxy(&self, g: &Guid) -> bool {
        self.proxies.contains_key(g)
    }

    /// Asks `writer` to say soon where it stands: the next ACKNACK, due now, is not final.
    pub(crate) fn solicit_heartbeat(&mut self, now: Instant, writer: &Guid) {
        if let Some(p) = self.proxies.get_mut(writer).filter(|p| p.reliable) {
            p.want_heartbeat = true;
            let due = p.acknack_due.map_or(now, |d| d.min(now));
            p.acknack_due = Some(due);
            self.due.arm(p.acknack_due, *writer);
        }
    }

    /// A reliable proxy's in-order point: every change of `writer` up to the result reached this reader.
    pub(crate) fn delivered_through(&self, writer: &Guid) -> Option<SequenceNumber> {
        let p = self.proxies.get(writer).filter(|p| p.reliable)?;
        Some(SequenceNumber(p.next_expected.0 - 1))
    }

    /// Matches a writer; a reliable one gets a pre-emptive ACKNACK.
    pub(crate) fn add_proxy(&mut self, now: Instant, proxy: WriterProxy) {
        self.add_proxy_with(now, proxy, true);
    }

    /// Matches a writer, with or without a pre-emptive ACKNACK. Without: the reader waits for the writer's
    /// DATA or HEARTBEAT, which is enough with a writer that owes a new reader nothing (volatile) or that
    /// announces its history to it on matching (ours).
    pub(crate) fn add_proxy_with(
        &mut self,
        now: Instant,
        mut proxy: WriterProxy,
        preemptive: bool,
    ) {
        proxy.reliable &= self.params.reliable;
        if proxy.reliable && preemptive {
            // Pre-emptive ACKNACK: prompts the writer to tell us what it has. Matches come in bursts
            // (a peer's announcements), so it waits for the others to the same peer.
            let wait = if self.guid.entity_id.is_builtin() {
                DISCOVERY_ACK_DELAY
            } else {
                PREEMPTIVE_ACK_DELAY
            };
            proxy.acknack_due = Some(now + wait);
        }
        self.due.arm(proxy.acknack_due, proxy.guid);
        self.proxies.insert(Box::new(proxy));
    }

    pub(crate) fn remove_proxy(&mut self, g: &Guid) -> bool {
        let had = self.proxies.remove(g).is_some();
        if self.proxies.is_empty() {
            self.due.clear();
        }
        had
    }

    /// What one writer's coherent set may hold.
    fn set_limits(&self) -> SetLimits {
        SetLimits {
            max_samples: self.params.reorder_max_samples,
            max_bytes: self.params.reorder_max_bytes,
        }
    }

    fn deliver(
        (reader, limits): (EntityId, SetLimits),
        p: &mut WriterProxy,
        sn: SequenceNumber,
        slot: Slot,
        out: &mut Vec<Event>,
    ) {
        if let Slot::Change(c) = slot {
            let s = ReceivedSample {
                reader,
                writer: p.guid,
                sequence: sn,
                kind: c.kind,
                payload: c.payload,
                key_hash: c.key_hash,
                source_timestamp: c.source_timestamp,
                group_sequence: c.group_seq,
            };
            if c.coherent.is_none() && !p.coherent_open() {
                out.push(Event::Sample(s));
            } else {
                let coherent = &mut p.backlog_mut().coherent;
                coherent.offer(sn, c.coherent, s, limits, out);
            }
        }
    }

    fn drain(
        reader: (EntityId, SetLimits),
        p: &mut WriterProxy,
        credit: &std::cell::Cell<Option<usize>>,
        out: &mut Vec<Event>,
    ) {
        loop {
            let next = p.next_expected;
            let Some((sn, slot)) = p.take_first_if(|sn, slot| {
                sn < next
                    || (sn == next
                        && (!matches!(slot, Slot::Change(_)) || Self::take_credit(credit)))
            }) else {
                break;
            };
            if sn == p.next_expected {
                Self::deliver(reader, p, sn, slot, out);
                p.next_expected = sn.next();
            }
        }
    }

    /// Puts one received change (or irrelevant number) into sequence.
    fn accept(&self, p: &mut WriterProxy, sn: SequenceNumber, slot: Slot, out: &mut Vec<Event>) {
        let rid = self.guid.entity_id;
        let to = (rid, self.set_limits());
        if p.reliable {
            if p.has(sn) {
                return;
            }
            p.synced = true;
            if sn == p.next_expected {
                if matches!(slot, Slot::Change(_)) && !Self::take_credit(&self.credit) {
                    // No room downstream: treat it as not received, so it is NACKed again later.
                    return;
                }
                Self::deliver(to, p, sn, slot, out);
                p.next_expected = sn.next();
                Self::drain(to, p, &self.credit, out);
            } else {
                if p.held() < self.params.reorder_max_samples
                    && p.held_bytes() + slot.size() <= self.params.reorder_max_bytes
                {
                    p.hold(sn, slot);
                }
            }
        } else {
            if sn < p.next_expected {
                return;
            }
            if p.synced && sn > p.next_expected {
                out.push(Event::SampleLost {
                    reader: rid,
                    writer: p.guid,
                    count: (sn.0 - p.next_expected.0) as u64,
                });
            }
            p.synced = true;
            Self::deliver(to, p, sn, slot, out);
            p.next_expected = sn.next();
        }
        p.drop_stale_defrag();
    }

    /// A DATA from `writer`. `datagram`, when given, is the shared buffer `d` was parsed from: the sample's
    /// payload then shares it instead of being copied.
    pub(crate) fn on_data(
        &mut self,
        writer: Guid,
        d: &Data<'_>,
        ts: Option<Time>,
        datagram: Option<&Payload>,
        out: &mut Vec<Event>,
    ) {
        self.with_proxy(writer, |r, p| r.data(p, writer, d, ts, datagram, out));
    }

    /// Runs `f` on the proxy of `writer`, with the rest of the reader borrowed shared (`accept` borrows
    /// `self`). The map is taken out (O(1)) rather than the proxy removed and re-inserted, and put back
    /// without dropping the empty map that stood in for it: that drop (when it was a `BTreeMap`, its
    /// `IntoIter`, even empty) was 5% of a 4 MiB subscriber's time, once per fragment.
    fn with_proxy(&mut self, writer: Guid, f: impl FnOnce(&Self, &mut WriterProxy)) {
        let mut proxies = std::mem::take(&mut self.proxies);
        if let Some(p) = proxies.get_mut(&writer) {
            f(self, p);
        }
        let stand_in = std::mem::replace(&mut self.proxies, proxies);
        debug_assert!(stand_in.is_empty());
        // An empty map owns no allocation: forgetting it leaks nothing.
        std::mem::forget(stand_in);
    }

    fn data(
        &self,
        p: &mut WriterProxy,
        writer: Guid,
        d: &Data<'_>,
        ts: Option<Time>,
        datagram: Option<&Payload>,
        out: &mut Vec<Event>,
    ) {
        // One pass over the inline QoS.
        let q = d
            .inline_qos
            .map(|q| q.data_params(understood_pid))
            .unwrap_or_default();
        if q.not_understood.is_some() {
            // §9.4.2.11: a sample with a must-understand parameter we do not know is dropped; the sequence
            // number is consumed so a reliable stream does not stall on it.
            self.accept(p, d.writer_sn, Slot::Irrelevant, out);
            return;
        }
        let status = q.status_info;
        let kind = status.map_or(ChangeKind::Alive, ChangeKind::from_status_info);
        let key_hash = q.key_hash;
        let coherent = q.coherent_set.map(|set| {
            // The end-of-set marker: no data, no key, no status.
            let end = d.payload.is_none() && status.is_none();
            SetMark {
                set,
                end,
                group: end.then(|| group_set(d.inline_qos.as_ref())).flatten(),
                group_set: d.inline_qos.and_then(|q| q.group_coherent_set()),
            }
        });
        let slot = match d.payload {
            Some(b) if b.len() > self.params.max_sample_size => {
                out.push(Event::SampleLost {
                    reader: self.guid.entity_id,
                    writer,
                    count: 1,
                });
                Slot::Irrelevant
            }
            // Alive data needs a payload; a dispose/unregister may come with only inline QoS.
            None if kind == ChangeKind::Alive && !coherent.is_some_and(|c| c.end) => {
                Slot::Irrelevant
            }
            b => Slot::Change(PendingChange {
                kind,
                payload: b
                    .map(|b| Payload::share_or_copy(datagram, b))
                    .unwrap_or_default(),
                key_hash,
                source_timestamp: ts,
                coherent,
                group_seq: q.group_seq_num,
            }),
        };
        self.accept(p, d.writer_sn, slot, out);
    }

    pub(crate) fn on_data_frag(
        &mut self,
        writer: Guid,
        d: &DataFrag<'_>,
        ts: Option<Time>,
        pool: &mut BufferPool,
        out: &mut Vec<Event>,
    ) {
        self.with_proxy(writer, |r, p| r.data_frag(p, d, ts, pool, out));
    }

    fn data_frag(
        &self,
        p: &mut WriterProxy,
        d: &DataFrag<'_>,
        ts: Option<Time>,
        pool: &mut BufferPool,
        out: &mut Vec<Event>,
    ) {
        let sn = d.writer_sn;
        if p.has(sn) {
            return;
        }
        if !inline_qos_understood(d.inline_qos.as_ref()) {
            self.accept(p, sn, Slot::Irrelevant, out);
            return;
        }
        if d.sample_size as usize > self.params.max_sample_size {
            out.push(Event::SampleLost {
                reader: self.guid.entity_id,
                writer: p.guid,
                count: 1,
            });
            self.accept(p, sn, Slot::Irrelevant, out);
            return;
        }
        let reliable = p.reliable;
        let b = p.backlog_mut();
        let Some(df) = self.reassembly(b, reliable, d, pool) else {
            return;
        };
        if df.source_timestamp.is_none() {
            df.source_timestamp = ts;
        }
        let fs = d.fragment_size as usize;
        for (i, chunk) in d.payload.chunks(fs).enumerate() {
            df.add(d.fragment_starting_num.saturating_add(i as u32), chunk);
        }
        if df.is_complete() {
            let Some(df) = b.defrag.remove(&sn) else {
                return;
            };
            b.defrag_bytes -= df.bytes;
            if let Some(slot) = assembled(df, pool) {
                self.accept(p, sn, slot, out);
            }
        }
    }

    /// The reassembly of the sample `d` is a fragment of: the one under way, or a new one when the limits
    /// (`defrag_max_samples`, `defrag_max_bytes`) allow. `None` when they do not, or when `d` disagrees with
    /// the reassembly under way on the sample's or the fragments' size.
    fn reassembly<'b>(
        &self,
        b: &'b mut Backlog,
        reliable: bool,
        d: &DataFrag<'_>,
        pool: &mut BufferPool,
    ) -> Option<&'b mut Defrag> {
        let sn = d.writer_sn;
        if !b.defrag.contains_key(&sn) {
            if b.defrag.len() >= self.params.defrag_max_samples {
                // Reliable: keep the oldest (they unblock delivery); best effort: keep the newest.
                let victim = if reliable {
                    b.defrag.last_key_value()
                } else {
                    b.defrag.first_key_value()
                };
                let (&v, _) = victim?;
                if reliable && v < sn {
                    return None;
                }
                if let Some(old) = b.defrag.remove(&v) {
                    b.defrag_bytes -= old.bytes;
                }
            }
            let cost = defrag::cost(d.sample_size, d.fragment_size);
            if b.defrag_bytes + cost > self.params.defrag_max_bytes {
                return None;
            }
            let mut df = Defrag::new(d.sample_size, d.fragment_size, pool.take());
            b.defrag_bytes += df.bytes;
            df.status_info = d.inline_qos.and_then(|q| q.status_info());
            df.key_hash = d.inline_qos.and_then(|q| q.key_hash());
            df.key_flag = d.key_flag;
            df.coherent_set = d.inline_qos.and_then(|q| q.coherent_set());
            df.group_seq = d.inline_qos.and_then(|q| q.group_seq_num());
            b.defrag.insert(sn, df);
        }
        let df = b.defrag.get_mut(&sn)?;
        (df.sample_size == d.sample_size && df.fragment_size == d.fragment_size).then_some(df)
    }

    pub(crate) fn on_gap(&mut self, writer: Guid, g: &Gap, out: &mut Vec<Event>) {
        let rid = self.guid.entity_id;
        let to = (rid, self.set_limits());
        let cap = self.params.reorder_max_samples;
        let Some(p) = self.proxies.get_mut(&writer) else {
            return;
        };
        p.synced = true;
        let base = g.gap_list.base;
        if g.gap_start <= p.next_expected && base > p.next_expected {
            // Nothing below base will come any more. What we already hold of it was published and is delivered
            // in order; the rest is irrelevant (not lost).
            while let Some((sn, slot)) = p.take_first_if(|sn, _| sn < base) {
                Self::deliver(to, p, sn, slot, out);
            }
            p.next_expected = base;
        } else if g.gap_start > p.next_expected && base.0 - g.gap_start.0 <= 256 {
            let mut sn = g.gap_start;
            while sn < base && p.held() < cap {
                p.hold_irrelevant(sn);
                sn = sn.next();
            }
        }
        for sn in g.gap_list.iter() {
            if sn >= p.next_expected && p.held() < cap {
                p.hold_irrelevant(sn);
            }
        }
        Self::drain(to, p, &self.credit, out);
        p.drop_stale_defrag();
    }

    pub(crate) fn on_heartbeat(
        &mut self,
        now: Instant,
        writer: Guid,
        hb: &Heartbeat,
        out: &mut Vec<Event>,
    ) {
        let rid = self.guid.entity_id;
        let to = (rid, self.set_limits());
        let (delay, ack_delay) = (self.params.heartbeat_response_delay, self.params.ack_delay);
        let Some(p) = self.proxies.get_mut(&writer) else {
            return;
        };
        if !p.reliable {
            return;
        }
        if p.last_hb_count
            .is_some_and(|c| hb.count.wrapping_sub(c) <= 0)
        {
            return;
        }
        p.last_hb_count = Some(hb.count);
        p.hb_last = p.hb_last.max(hb.last_sn);
        if hb.first_sn > p.next_expected {
            // The writer no longer has [next_expected, first): deliver what we hold of it, count the rest lost.
            let mut lost = 0u64;
            let mut sn = p.next_expected;
            while let Some((k, slot)) = p.take_first_if(|k, _| k < hb.first_sn) {
                if matches!(slot, Slot::Change(_)) {
                    lost += (k.0 - sn.0) as u64;
                    Self::deliver(to, p, k, slot, out);
                    sn = k.next();
                }
            }
            lost += (hb.first_sn.0 - sn.0).max(0) as u64;
            if p.synced && lost > 0 {
                out.push(Event::SampleLost {
                    reader: rid,
                    writer,
                    count: lost,
                });
            }
            p.next_expected = hb.first_sn;
            Self::drain(to, p, &self.credit, out);
            p.drop_stale_defrag();
        }
        p.synced = true;
        let missing = p.hb_last >= p.next_expected;
        if !hb.final_flag || missing {
            // Asking for changes goes soon; a pure acknowledgement may wait for others to share its datagram.
            let due = now + if missing { delay } else { ack_delay };
            if p.acknack_due.is_none_or(|t| t > due) {
                p.acknack_due = Some(due);
                self.due.arm(p.acknack_due, writer);
            }
        }
    }

    /// HEARTBEAT_FRAG (§8.3.7.6): the writer has fragments 1..=last of one sample. Answered with a NACK_FRAG
    /// for the fragments we lack of a sample we are reassembling. A sample we have (or have skipped) needs
    /// nothing; one we hold no fragment of is left to the HEARTBEAT/ACKNACK exchange, which asks for whole
    /// samples. It says nothing about other sequence numbers, so it neither moves `hb_last` nor prompts an
    /// ACKNACK; its count is its own, apart from HEARTBEAT's.
    pub(crate) fn on_heartbeat_frag(&mut self, now: Instant, writer: Guid, hf: &HeartbeatFrag) {
        let delay = self.params.heartbeat_response_delay;
        let Some(p) = self.proxies.get_mut(&writer) else {
            return;
        };
        if !p.reliable
            || p.backlog()
                .and_then(|b| b.last_hbfrag_count)
                .is_some_and(|c| hf.count.wrapping_sub(c) <= 0)
        {
            return;
        }
        let sn = hf.writer_sn;
        let known = p.has(sn);
        let b = p.backlog_mut();
        b.last_hbfrag_count = Some(hf.count);
        if known || hf.last_fragment_num == 0 {
            return;
        }
        let Some(d) = b.defrag.get(&sn) else {
            return;
        };
        if d.missing(hf.last_fragment_num).is_empty()
            || (b.nackfrag_req.len() >= self.params.defrag_max_samples.max(1)
                && !b.nackfrag_req.contains_key(&sn))
        {
            return;
        }
        let last = b.nackfrag_req.entry(sn).or_insert(0);
        *last = (*last).max(hf.last_fragment_num);
        if b.nackfrag_due.is_none() {
            b.nackfrag_due = Some(now + delay);
            self.due.arm(b.nackfrag_due, writer);
        }
    }

    /// Gives back the room a burst (many matches, many armed timers) left in the proxies and the timer
    /// queue (see `DueQueue::trim`).
    pub(crate) fn trim_room(&mut self) {
        self.due.trim(crate::rtps::due::KEPT_TIMER_ROOM);
        self.proxies.trim(crate::rtps::due::KEPT_TIMER_ROOM);
        self.proxies.values_mut().for_each(WriterProxy::trim_idle);
    }

    pub(crate) fn next_timeout(&self) -> Option<Instant> {
        self.due.next()
    }

    /// Sends the ACKNACKs (and NACK_FRAGs for partly received samples), and NACK_FRAGs answering
    /// HEARTBEAT_FRAGs, due by `until`: the participant passes a time a little after now once something
    /// is due, so that what would fall due shortly leaves in the same pass (and shares datagrams).
    /// Only the proxies whose timer is due are visited (in deadline order), not every proxy.
    pub(crate) fn on_timeout(&mut self, until: Instant, out: &mut Outbox) {
        let rid = self.guid.entity_id;
        while let Some(g) = self.due.pop_due(until) {
            // A stale entry (timer cleared, proxy gone) finds nothing due.
            let Some(p) = self.proxies.get_mut(&g) else {
                continue;
            };
            if p.acknack_due.is_some_and(|t| t <= until) {
                Self::send_acknack(rid, p, out);
            }
            if p.nackfrag_due().is_some_and(|t| t <= until) {
                Self::send_requested_nackfrags(rid, p, out);
            }
        }
    }

    /// Sends now the armed ACKNACKs to the writers of participant `prefix` reached at `to`: a message to
    /// that locator is leaving anyway, and they share it. Visits only that participant's proxies. The
    /// pre-emptive ACKNACK to a builtin writer we have heard nothing from keeps waiting: that writer
    /// pushes its history at matching, and an ACKNACK sent after the push acknowledges it, where one sent
    /// now would cross it and ask for another heartbeat.
    pub(crate) fn send_acknacks_along(
        &mut self,
        prefix: GuidPrefix,
        to: Locator,
        out: &mut Outbox,
    ) {
        let rid = self.guid.entity_id;
        let first = Guid::new(prefix, EntityId([0; 4]));
        let last = Guid::new(prefix, EntityId([0xff; 4]));
        for p in self.proxies.range_mut(first..=last) {
            let may = p.synced || !p.guid.entity_id.is_builtin();
            if may && p.acknack_due.is_some() && p.destination() == [to] {
                Self::send_acknack(rid, p, out);
            }
        }
    }

    /// An ACKNACK for what is missing up to the last heartbeat, and a NACK_FRAG per partly received sample.
    fn send_acknack(rid: EntityId, p: &mut WriterProxy, out: &mut Outbox) {
        p.acknack_due = None;
        let base = p.next_expected;
        let mut set = SequenceNumberSet::empty(base);
        let upper = p.hb_last.min(base + 255);
        let mut sn = base;
        while sn <= upper {
            if !p.holds_any_of(sn) {
                set.insert(sn);
            }
            sn = sn.next();
        }
        p.acknack_count = p.acknack_count.wrapping_add(1);
        // At most one locator: kept by value, so no allocation per ACKNACK.
        let dest = p.destination().first().copied();
        let dst = Some(p.guid.prefix);
        let ack = Submessage::AckNack(AckNack {
            reader_id: rid,
            writer_id: p.guid.entity_id,
            reader_sn_state: set,
            count: p.acknack_count,
            final_flag: set.num_bits == 0 && p.synced && !std::mem::take(&mut p.want_heartbeat),
        });
        out.push(dest.as_slice(), dst, Ts::Any, &ack);
        let (writer, hb_last) = (p.guid, p.hb_last);
        let Some(b) = p.backlog_if_used_mut() else {
            return;
        };
        for (sn, d) in b.defrag.range(base..) {
            if *sn > hb_last {
                break;
            }
            let Some(nf) = nack_frag(
                rid,
                writer,
                &mut b.nackfrag_count,
                *sn,
                &d.missing(d.total()),
            ) else {
                continue;
            };
            out.push(dest.as_slice(), dst, Ts::Any, &nf);
            // Already asked for all it lacks: a pending HEARTBEAT_FRAG answer for it is redundant.
            b.nackfrag_req.remove(sn);
        }
    }

    /// One NACK_FRAG per sample a HEARTBEAT_FRAG asked about and still partly received: the fragments we lack
    /// up to the last one the writer has.
    fn send_requested_nackfrags(rid: EntityId, p: &mut WriterProxy, out: &mut Outbox) {
        let dest = p.destination().first().copied();
        let (writer, dst) = (p.guid, Some(p.guid.prefix));
        let b = p.backlog_mut();
        b.nackfrag_due = None;
        let req = std::mem::take(&mut b.nackfrag_req);
        for (sn, last) in req {
            let Some(d) = b.defrag.get(&sn) else {
                continue;
            };
            if let Some(nf) = nack_frag(rid, writer, &mut b.nackfrag_count, sn, &d.missing(last)) {
                out.push(dest.as_slice(), dst, Ts::Any, &nf);
            }
        }
    }
}

/// A NACK_FRAG asking `writer` for the `missing` fragments of `sn` (counted), or `None` when none is missing.
fn nack_frag(
    rid: EntityId,
    writer: Guid,
    count: &mut i32,
    sn: SequenceNumber,
    missing: &[u32],
) -> Option<Submessage<'static>> {
    let (&first, _) = missing.split_first()?;
    let mut fs = FragmentNumberSet::empty(first);
    missing.iter().for_each(|&f| {
        fs.insert(f);
    });
    *count = count.wrapping_add(1);
    Some(Submessage::NackFrag(NackFrag {
        reader_id: rid,
        writer_id: writer.entity_id,
        writer_sn: sn,
        fragment_number_state: fs,
        count: *count,
    }))
}
