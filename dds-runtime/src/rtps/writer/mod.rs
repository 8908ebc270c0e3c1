//! Writers: history cache, per-reader state and the reliable/best-effort protocol (§8.4.7, §8.4.9).

mod bit_window;
mod coherent;
mod content_filter;
mod flow;
mod group;
mod history;
mod liveliness;
mod local;
mod multicast;
mod reader_proxy;
mod sn_map;
mod stand_in;

use coherent::CoherentState;
pub(crate) use coherent::Marks;
pub(crate) use content_filter::ReaderFilters;
pub(crate) use group::writer_set_digest;
pub use group::WriterGroup;
pub(crate) use history::{CacheChange, HistoryCache};
pub(crate) use liveliness::OwnLeases;
pub(crate) use reader_proxy::ReaderProxy;
#[cfg(feature = "net")]
pub(crate) use stand_in::user_data as stand_in_user_data;
use stand_in::StandIn;
pub(crate) use stand_in::{stand_in_for, Served};

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use crate::qos::{Durability, History, ResourceLimits};
use crate::rtps::api::{ChangeKind, Event, WriteChange, WriteError};
use crate::rtps::due::DueQueue;
use crate::rtps::messages::parameter::pid;
use crate::rtps::messages::{
    Data, DataFrag, Gap, Heartbeat, HeartbeatFrag, ParameterList, Submessage,
};
use crate::rtps::outbox::{Outbox, Ts};
use crate::rtps::proxy_map::ProxyMap;
use crate::rtps::types::*;
use bit_window::BitWindow;

/// Protocol parameters of one writer.
#[derive(Debug, Clone, Copy)]
pub(crate) struct WriterParams {
    pub reliable: bool,
    pub durability: Durability,
    pub history: History,
    pub limits: ResourceLimits,
    pub keyed: bool,
    pub heartbeat_period: Duration,
    pub nack_response_delay: Duration,
    pub fragment_size: usize,
    /// Largest sample sent whole, as one DATA; larger ones go as DATA_FRAGs of `fragment_size`. At least
    /// `fragment_size` (see [`whole_sample_max`]).
    pub whole_max: usize,
    /// Consecutive fragments carried by one DATA_FRAG (see [`fragments_per_submessage`]).
    pub frags_per_submessage: usize,
    pub high_watermark: usize,
    pub low_watermark: usize,
    pub max_repair_bytes: usize,
    /// Bytes written between piggy-backed heartbeats (0: one after every write).
    pub piggyback_heartbeat_bytes: usize,
    /// LIFESPAN: changes leave the history this long after they were written; `None`: never.
    pub lifespan: Option<Duration>,
}

/// A local writer's protocol state.
#[derive(Debug)]
pub(crate) struct Writer {
    pub guid: Guid,
    params: WriterParams,
    history: HistoryCache,
    next_sn: SequenceNumber,
    /// Sorted boxes (see `ProxyMap`, and `docs/performance.md`, "Footprint").
    proxies: ProxyMap<ReaderProxy>,
    /// One locator per matched reader, deduplicated: where new data goes.
    data_dest: Vec<Locator>,
    /// `data_dest` split for key-only changes: readers that want them without serialized key
    /// (`ReaderProxy::key_hash_only_disposes`), and the rest. `key_hash_dest` empty: no split needed.
    key_hash_dest: Vec<Locator>,
    full_key_dest: Vec<Locator>,
    /// Where the periodic heartbeat goes (kept for reuse).
    hb_dest: Vec<Locator>,
    hb_count: i32,
    /// HEARTBEAT_FRAG count: its own sequence, separate from HEARTBEAT's (§8.3.7.6).
    hbfrag_count: i32,
    hb_due: Option<Instant>,
    /// The proxies whose `repair_due` is armed, in deadline order.
    repair_queue: DueQueue,
    bytes_since_nonfinal_hb: usize,
    /// Changes written since the last non-final heartbeat: with a sample limit on the history, small
    /// samples fill it long before the bytes reach the watermark.
    changes_since_nonfinal_hb: usize,
    bytes_since_hb: usize,
    unacked_bytes: usize,
    blocked: bool,
    /// Flow control's watermarks, scaled to the sample size (see `flow.rs`).
    window: flow::Window,
    /// Set when deleted: lingers until acknowledged or this deadline.
    pub linger_until: Option<Instant>,
    /// The open coherent set, if any (see `coherent.rs`).
    coherent: CoherentState,
    /// The publisher group this writer is a member of (GROUP access scope).
    pub group: Option<WriterGroup>,
    /// The content filters of the matched readers that announced one.
    pub filters: ReaderFilters,
    /// The owner decides what the history keeps (see [`Writer::manage_history`]).
    managed: bool,
    /// Set when this is a durability service's stand-in (see `stand_in.rs`).
    stand_in: Option<Box<StandIn>>,
}

impl Writer {
    pub(crate) fn new(guid: Guid, params: WriterParams) -> Self {
        Writer {
            guid,
            history: HistoryCache::new(params.history, params.limits),
            params,
            next_sn: SequenceNumber(1),
            proxies: ProxyMap::new(),
            data_dest: Vec::new(),
            hb_dest: Vec::new(),
            key_hash_dest: Vec::new(),
            full_key_dest: Vec::new(),
            hb_count: 0,
            hbfrag_count: 0,
            hb_due: None,
            repair_queue: DueQueue::default(),
            bytes_since_nonfinal_hb: 0,
            changes_since_nonfinal_hb: 0,
            bytes_since_hb: 0,
            unacked_bytes: 0,
            blocked: false,
            window: flow::Window::new(params.high_watermark, params.low_watermark),
            linger_until: None,
            coherent: CoherentState::Off,
            group: None,
            filters: ReaderFilters::default(),
            managed: false,
            stand_in: None,
        }
    }

    /// Hands the history over to the writer's owner (a durability service's stand-in, which mirrors the
    /// history the service keeps): unregistered instances are no longer pruned once acknowledged, and the
    /// owner drops changes with [`Writer::remove_change`].
    pub(crate) fn manage_history(&mut self) {
        self.managed = true;
    }

    /// Drops change `sn` from the history; readers that still miss it get a GAP. Whether it was there.
    pub(crate) fn remove_change(&mut self, sn: SequenceNumber, ev: &mut VecDeque<Event>) -> bool {
        let removed = self.history.remove(sn).is_some();
        if removed {
            self.update_acked(ev);
        }
        removed
    }

    /// New parameters for a writer that has written nothing yet (a disabled writer whose QoS changed):
    /// its history and flow-control window are made anew; its group, coherent state and readers' filters
    /// stay.
    pub(crate) fn respecify(&mut self, params: WriterParams) {
        self.history = HistoryCache::new(params.history, params.limits);
        self.window = flow::Window::new(params.high_watermark, params.low_watermark);
        self.params = params;
    }

    fn fragmenting(&self) -> Fragmenting {
        Fragmenting {
            size: self.params.fragment_size,
            whole_max: self.params.whole_max,
            per_submessage: self.params.frags_per_submessage.max(1),
        }
    }

    fn durable(&self) -> bool {
        self.params.durability >= Durability::TransientLocal
    }
    pub(crate) fn last_sn(&self) -> SequenceNumber {
        SequenceNumber(self.next_sn.0 - 1)
    }
    pub(crate) fn unacked_bytes(&self) -> usize {
        self.unacked_bytes
    }
    pub(crate) fn matched(&self) -> impl Iterator<Item = &Guid> {
        self.proxies.keys()
    }
    pub(crate) fn has_proxy(&self, g: &Guid) -> bool {
        self.proxies.contains_key(g)
    }

    /// Every change acknowledged by every reliable reader.
    pub(crate) fn is_acknowledged(&self) -> bool {
        self.proxies
            .values()
            .filter(|p| p.reliable)
            .all(|p| p.acked >= self.next_sn)
    }

    fn acked_floor(&self) -> SequenceNumber {
        self.proxies
            .values()
            .filter(|p| p.reliable)
            .map(|p| p.acked)
            .min()
            .unwrap_or(self.next_sn)
    }

    fn has_reliable_proxy(&self) -> bool {
        self.params.reliable && self.proxies.values().any(|p| p.reliable)
    }

    /// The destinations of new data. Readers of our own participant come last: a datagram to ourselves
    /// costs the sending thread a pass through the receive path (loopback delivers in the sender's
    /// context), which would otherwise delay the remote readers' copy, e.g. the pong in a ping/pong.
    fn rebuild_dest(&mut self) {
        let own = self.guid.prefix;
        self.choose_multicast();
        let dest = |key_hash_only: Option<bool>| {
            let mut d: Vec<(bool, Locator)> = self
                .proxies
                .iter()
                .filter(|(_, p)| key_hash_only.is_none_or(|k| p.key_hash_only_disposes == k))
                .filter(|(g, _)| !StandIn::excludes(&self.stand_in, g))
                .filter_map(|(g, p)| Some((g.prefix == own, p.data_destination()?)))
                .collect();
            // Each locator once (a multicast group may serve our own and remote readers), remote ones first.
            d.sort_by_key(|&(own, l)| (l, own));
            d.dedup_by_key(|(_, l)| *l);
            d.sort_by_key(|&(own, _)| own);
            // Collected in place (the pairs' allocation is reused): kept as long as the readers are, so
            // without the spare room.
            let mut d: Vec<Locator> = d.into_iter().map(|(_, l)| l).collect();
            d.shrink_to_fit();
            d
        };
        self.data_dest = dest(None);
        self.key_hash_dest = dest(Some(true));
        self.full_key_dest = if self.key_hash_dest.is_empty() {
            Vec::new()
        } else {
            dest(Some(false))
        };
    }

    /// A HEARTBEAT_FRAG telling that every fragment of `sn` is available (sent after a fragmented sample to
    /// reliable readers, so one that missed fragments asks for them with NACK_FRAG at once).
    fn heartbeat_frag(
        &mut self,
        reader_id: EntityId,
        sn: SequenceNumber,
        fragments: u32,
    ) -> Submessage<'static> {
        self.hbfrag_count = self.hbfrag_count.wrapping_add(1);
        Submessage::HeartbeatFrag(HeartbeatFrag {
            reader_id,
            writer_id: self.guid.entity_id,
            writer_sn: sn,
            last_fragment_num: fragments,
            count: self.hbfrag_count,
        })
    }

    /// After acknowledgements or a change of readers: drop what nobody needs, update flow control.
    fn update_acked(&mut self, ev: &mut VecDeque<Event>) {
        let floor = self.acked_floor();
        if !self.durable() {
            self.history.remove_below(floor);
        } else if !self.managed {
            self.history.prune_unregistered(floor);
        }
        self.unacked_bytes = if self.has_reliable_proxy() {
            self.history.bytes_from(floor)
        } else {
            0
        };
        if self.blocked && self.unacked_bytes <= self.window.low() {
            self.blocked = false;
            ev.push_back(Event::WriterUnblocked {
                writer: self.guid.entity_id,
            });
        }
    }

    /// Queues a change and sends it to every matched reader.
    pub(crate) fn write(
        &mut self,
        now: Instant,
        change: WriteChange,
        out: &mut Outbox,
        ev: &mut VecDeque<Event>,
    ) -> Result<SequenceNumber, WriteError> {
        self.write_filtered(now, change, Vec::new(), out, ev)
    }

    /// [`Writer::write`] of a change that the content filters of the `rejected` readers refused: they get a
    /// GAP for it (reliable ones), the others the DATA. A key-only change (dispose, unregister) passes every
    /// filter, in both of its wire forms (see `content_filter.rs`): `rejected` is ignored for it.
    pub(crate) fn write_filtered(
        &mut self,
        now: Instant,
        change: WriteChange,
        mut rejected: Vec<Guid>,
        out: &mut Outbox,
        ev: &mut VecDeque<Event>,
    ) -> Result<SequenceNumber, WriteError> {
        if change.kind != ChangeKind::Alive {
            rejected.clear();
        }
        rejected.sort_unstable();
        if self.linger_until.is_some() {
            return Err(WriteError::Deleted);
        }
        if self.params.keyed && change.key_hash.is_none() {
            return Err(WriteError::MissingKeyHash);
        }
        let len = change.payload.accounted_len();
        self.window.note(len);
        self.flow_admits(now, len, ev)?;
        self.expire(now);
        let key = change.key_hash.unwrap_or_default();
        if self.history.make_room(&key, self.acked_floor()).is_err() {
            self.solicit_acks(now);
            return Err(WriteError::WouldBlock);
        }
        let sn = self.next_sn;
        self.next_sn = sn.next();
        let cc = self.new_change(now, sn, change, rejected);
        let filtered = !cc.rejected.is_empty();
        self.history.add(cc);
        if !self.data_dest.is_empty() {
            self.send_written(sn, len, filtered, out);
        }
        if self.has_reliable_proxy() {
            self.unacked_bytes += len;
            self.hb_due
                .get_or_insert(now + self.params.heartbeat_period);
        } else if !self.durable() {
            self.history.remove_below(self.next_sn);
        }
        Ok(sn)
    }

    /// Flow control for a new change of `len` bytes: `WouldBlock` (and a heartbeat soon) while the
    /// unacknowledged bytes would pass the high watermark, until they fall to the low one.
    fn flow_admits(
        &mut self,
        now: Instant,
        len: usize,
        ev: &mut VecDeque<Event>,
    ) -> Result<(), WriteError> {
        if !self.has_reliable_proxy() {
            return Ok(());
        }
        if self.blocked {
            self.update_acked(ev);
            if self.blocked {
                self.solicit_acks(now);
                return Err(WriteError::WouldBlock);
            }
        }
        if self.unacked_bytes > 0 && self.unacked_bytes + len > self.window.high() {
            self.blocked = true;
            self.solicit_acks(now);
            return Err(WriteError::WouldBlock);
        }
        Ok(())
    }

    /// The history's form of a written change numbered `sn`.
    fn new_change(
        &mut self,
        now: Instant,
        sn: SequenceNumber,
        change: WriteChange,
        rejected: Vec<Guid>,
    ) -> CacheChange {
        CacheChange {
            sn,
            kind: change.kind,
            payload: change.payload,
            key_hash: change.key_hash,
            source_timestamp: change.source_timestamp,
            marks: self.marks(sn),
            filter_info: if change.kind == ChangeKind::Alive {
                self.filters.info(&rejected)
            } else {
                None
            },
            rejected,
            expires: self.params.lifespan.map(|l| now + l),
        }
    }

    /// Sends the new change `sn` (`len` bytes) to the matched readers, GAPs to those whose filter rejected
    /// it (`filtered`), and a piggy-backed heartbeat when one is due.
    fn send_written(&mut self, sn: SequenceNumber, len: usize, filtered: bool, out: &mut Outbox) {
        let dest = if filtered {
            self.send_rejections(sn, out)
        } else {
            std::mem::take(&mut self.data_dest)
        };
        self.send_new(sn, &dest, out);
        if self.has_reliable_proxy() {
            self.piggyback_heartbeat(len, &dest, out);
        }
        if !filtered {
            self.data_dest = dest;
        }
    }

    /// Counts a written change of `len` bytes towards the next heartbeat and sends one to `dest` when due.
    fn piggyback_heartbeat(&mut self, len: usize, dest: &[Locator], out: &mut Outbox) {
        self.bytes_since_nonfinal_hb += len;
        self.changes_since_nonfinal_hb += 1;
        self.bytes_since_hb += len;
        // Ask for acknowledgements every quarter of the high watermark (or of the history's sample
        // limit), so that flow control keeps moving without waiting for the periodic heartbeat (and
        // without an ACKNACK per datagram); otherwise the piggy-backed heartbeat only announces.
        let final_flag = self.bytes_since_nonfinal_hb < self.window.high() / 4
            && self
                .params
                .limits
                .max_samples
                .is_none_or(|m| self.changes_since_nonfinal_hb < (m as usize / 4).max(1));
        if !final_flag || self.bytes_since_hb >= self.params.piggyback_heartbeat_bytes {
            if !final_flag {
                self.bytes_since_nonfinal_hb = 0;
                self.changes_since_nonfinal_hb = 0;
            }
            self.bytes_since_hb = 0;
            let hb = self.heartbeat(EntityId::UNKNOWN, final_flag);
            out.push(dest, None, Ts::Any, &hb);
        }
    }

    /// Sends a new change to every matched reader (`dest`): one shared send, except that key-only changes go
    /// in their key-hash-only form to the readers that want it. A fragmented sample is followed by a
    /// HEARTBEAT_FRAG when reliable readers are matched.
    fn send_new(&mut self, sn: SequenceNumber, dest: &[Locator], out: &mut Outbox) {
        let wid = self.guid.entity_id;
        let frag = self.fragmenting();
        let Some(c) = self.history.get(sn) else {
            return;
        };
        let split = c.kind != ChangeKind::Alive && !self.key_hash_dest.is_empty();
        let (full, key_hash): (&[Locator], &[Locator]) = if split {
            (&self.full_key_dest, &self.key_hash_dest)
        } else {
            (dest, &[])
        };
        let rid = EntityId::UNKNOWN;
        let fragments = send_change(out, full, None, rid, wid, c, frag, None, false);
        send_change(out, key_hash, None, rid, wid, c, frag, None, true);
        if fragments > 0 && !full.is_empty() && self.has_reliable_proxy() {
            let hf = self.heartbeat_frag(rid, sn, fragments);
            // Borrowed again after the count's update (a copy of the list was an allocation per sample).
            let full = if split { &self.full_key_dest[..] } else { dest };
            out.push(full, None, Ts::Any, &hf);
        }
    }

    /// Whether flow control holds (or is about to hold) the application back: the unacknowledged bytes
    /// are past half the high watermark, or the history is past half its sample limit.
    fn under_pressure(&self) -> bool {
        self.blocked
            || self.unacked_bytes >= self.window.high() / 2
            || self
                .params
                .limits
                .max_samples
                .is_some_and(|m| self.history.len() >= (m as usize / 2).max(1))
    }

    /// The periodic heartbeat's interval: the configured period, but a twentieth of it (at least 1 ms)
    /// while flow control holds the writer back. A blocked writer writes nothing, so no piggy-backed
    /// heartbeat asks for the acknowledgements that would release it; on a lossy link, where a heartbeat
    /// or its ACKNACK is lost every other round trip at 30% loss each way, waiting a whole period per lost
    /// round trip is what made the stream collapse.
    fn heartbeat_interval(&self) -> Duration {
        if self.under_pressure() {
            (self.params.heartbeat_period / 20).max(Duration::from_millis(1))
        } else {
            self.params.heartbeat_period
        }
    }

    /// A write was refused by flow control: make sure a heartbeat asks for acknowledgements soon.
    fn solicit_acks(&mut self, now: Instant) {
        let soon = now + self.heartbeat_interval();
        if self.hb_due.is_none_or(|t| t > soon) {
            self.hb_due = Some(soon);
        }
    }

    fn heartbeat(&mut self, reader_id: EntityId, final_flag: bool) -> Submessage<'static> {
        self.hb_count = self.hb_count.wrapping_add(1);
        let (first_sn, last_sn) = (
            self.history.first_sn().unwrap_or(self.next_sn),
            self.last_sn(),
        );
        Submessage::Heartbeat(Heartbeat {
            reader_id,
            writer_id: self.guid.entity_id,
            first_sn,
            last_sn,
            count: self.hb_count,
            final_flag,
            liveliness_flag: false,
            group_info: self.group_info(first_sn, last_sn),
        })
    }

    /// Matches a reader. Durable writers serve their history to it; volatile ones answer older requests with GAP.
    pub(crate) fn add_proxy(
        &mut self,
        now: Instant,
        mut proxy: ReaderProxy,
        reader_durable: bool,
        ev: &mut VecDeque<Event>,
    ) {
        proxy.reliable &= self.params.reliable;
        self.expire(now);
        let held = self.hold_at_match(now, &mut proxy);
        if !(self.durable() && reader_durable) {
            proxy.floor = self.next_sn;
            proxy.acked = self.next_sn;
        } else if !held && !self.history.is_empty() {
            if proxy.reliable && !self.history_fits_one_push() {
                // Announce the history; the reader asks for what it lacks.
                proxy.repair_due = Some(now);
            } else {
                // Best effort, or a reliable reader that would ask for all of it: push the history once
                // (followed by a heartbeat), which saves the HEARTBEAT/ACKNACK round that would ask for it.
                for c in self.history.range(SequenceNumber(1)) {
                    if !proxy.request(c.sn) {
                        break;
                    }
                }
                proxy.repair_due = Some(now);
            }
        }
        let behind = proxy.reliable && proxy.acked < self.next_sn;
        self.repair_queue.arm(proxy.repair_due, proxy.guid);
        self.proxies.insert(Box::new(proxy));
        self.rebuild_dest();
        self.update_acked(ev);
        if behind {
            // Keep heartbeating until it has caught up, whatever happens to the first one.
            self.hb_due
                .get_or_insert(now + self.params.heartbeat_period);
        }
    }

    /// Whether a new reliable reader gets the history pushed at matching rather than announced: when it
    /// holds every change from 1 on (so a reader that has nothing would ask for all of it, and no GAP is
    /// needed) and fits in one repair round. A matched SEDP writer's announcements usually do; the cost
    /// of a reader that had them already (matched again) is one repair round, as for a NACK of everything.
    fn history_fits_one_push(&self) -> bool {
        self.history.first_sn() == Some(SequenceNumber(1))
            && self.history.len() as i64 == self.next_sn.0 - 1
            && self.history.len() <= reader_proxy::MAX_REQUESTED
            && self.history.bytes_from(SequenceNumber(1)) + 64 * self.history.len()
                <= self.params.max_repair_bytes
    }

    pub(crate) fn remove_proxy(&mut self, guid: &Guid, ev: &mut VecDeque<Event>) -> bool {
        self.filters.set(*guid, None);
        self.forget_held(guid);
        let had = self.proxies.remove(guid).is_some();
        if self.proxies.is_empty() {
            self.repair_queue.clear();
        }
        if had {
            self.rebuild_dest();
            self.update_acked(ev);
        }
        had
    }

    pub(crate) fn on_acknack(
        &mut self,
        now: Instant,
        reader: Guid,
        ack: &crate::rtps::messages::AckNack,
        ev: &mut VecDeque<Event>,
    ) {
        let next_sn = self.next_sn;
        let delay = self.params.nack_response_delay;
        let grouped = self.group.is_some();
        let Some(p) = self.proxies.get_mut(&reader) else {
            return;
        };
        if !p.reliable {
            return;
        }
        if !p.take_acknack_count(ack.count) {
            return;
        }
        let base = ack.reader_sn_state.base.min(next_sn);
        let progressed = base > p.acked;
        if progressed {
            p.acked = base;
        }
        for sn in ack.reader_sn_state.iter() {
            if sn >= p.acked && sn < next_sn && !p.request(sn) {
                break;
            }
        }
        let far_behind = request_past_bitmap(p, &ack.reader_sn_state, next_sn);
        p.drop_requests_below(p.acked, next_sn);
        // A request, or a reader that is behind without knowing it (e.g. a pre-emptive ACKNACK): answer soon.
        // A group member answers every non-final ACKNACK: its heartbeat tells where the group stands.
        // A reader far behind is answered at once: there is nothing to merge its request with, and each
        // delay would cost it a whole round of repairs (see `request_past_bitmap`).
        let due = now + if far_behind { Duration::ZERO } else { delay };
        if (p.has_requested()
            || (ack.reader_sn_state.num_bits == 0
                && (base < next_sn || grouped)
                && !ack.final_flag))
            && p.repair_due.is_none_or(|t| t > due)
        {
            p.repair_due = Some(due);
            self.repair_queue.arm(p.repair_due, reader);
        }
        if progressed {
            self.update_acked(ev);
            if self.is_acknowledged() {
                // hb_due stays armed: it lapses when it fires, rather than being re-armed (and the timer
                // thread woken) by every write of a ping-pong exchange.
                ev.push_back(Event::WriterAcknowledged {
                    writer: self.guid.entity_id,
                });
            }
        }
    }

    pub(crate) fn on_nack_frag(
        &mut self,
        now: Instant,
        reader: Guid,
        nf: &crate::rtps::messages::NackFrag,
    ) {
        let delay = self.params.nack_response_delay;
        let frag_size = self.params.fragment_size.max(1);
        let fragments = self
            .history
            .get(nf.writer_sn)
            .map(|c| c.payload.len().div_ceil(frag_size).min(u32::MAX as usize) as u32);
        let Some(p) = self.proxies.get_mut(&reader) else {
            return;
        };
        if !p.reliable || nf.writer_sn < p.acked {
            return;
        }
        if !p.take_nackfrag_count(nf.count) {
            return;
        }
        match fragments {
            Some(total) => p.request_frags(nf.writer_sn, nf.fragment_number_state.iter(), total),
            None => {
                p.request(nf.writer_sn);
            }
        }
        if p.repair_due.is_none() {
            p.repair_due = Some(now + delay);
            self.repair_queue.arm(p.repair_due, reader);
        }
    }

    /// Gives back the room a burst (many matches, many armed timers) left in the proxies and the timer
    /// queue (see `DueQueue::trim`).
    pub(crate) fn trim_room(&mut self) {
        self.repair_queue.trim(crate::rtps::due::KEPT_TIMER_ROOM);
        self.proxies.trim(crate::rtps::due::KEPT_TIMER_ROOM);
    }

    pub(crate) fn next_timeout(&self) -> Option<Instant> {
        match (self.repair_queue.next(), self.hb_due) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// Drops expired changes (LIFESPAN): they are never served to a late joiner nor repaired (a GAP
    /// answers requests for them).
    fn expire(&mut self, now: Instant) {
        if self.params.lifespan.is_some() {
            self.history.expire(now);
        }
    }

    pub(crate) fn on_timeout(&mut self, now: Instant, out: &mut Outbox) {
        self.expire(now);
        // Only the proxies whose repair is due are visited, earliest first; a stale entry (repair done
        // already, proxy gone) finds nothing due.
        while let Some(g) = self.repair_queue.pop_due(now) {
            if self
                .proxies
                .get(&g)
                .is_some_and(|p| p.repair_due.is_some_and(|t| t <= now))
            {
                self.repair(now, g, out);
            }
        }
        if self.hb_due.is_some_and(|t| t <= now) {
            if self.has_reliable_proxy() && !self.is_acknowledged() {
                // The list is kept: a heartbeat per period allocates nothing.
                let mut dest = std::mem::take(&mut self.hb_dest);
                self.heartbeat_destinations(&mut dest);
                let hb = self.heartbeat(EntityId::UNKNOWN, false);
                self.bytes_since_nonfinal_hb = 0;
                self.changes_since_nonfinal_hb = 0;
                out.push(&dest, None, Ts::Any, &hb);
                self.hb_dest = dest;
                self.hb_due = Some(now + self.heartbeat_interval());
            } else {
                self.hb_due = None;
            }
        }
    }

    /// Sends what one reader asked for (bounded per round), GAPs for what is gone, then a heartbeat to it.
    fn repair(&mut self, now: Instant, g: Guid, out: &mut Outbox) {
        self.expire(now);
        let frag = self.fragmenting();
        let Some(p) = self.proxies.get_mut(&g) else {
            return;
        };
        p.repair_due = None;
        let to = RepairTo {
            dest: p.destination().first().copied(),
            reader: g,
            writer: self.guid.entity_id,
            frag,
            key_hash_only: p.key_hash_only_disposes,
        };
        let served = to.serve(
            p,
            &self.history,
            &self.stand_in,
            self.params.max_repair_bytes,
            out,
        );
        let more = p.has_requests();
        p.release_if_served(self.next_sn);
        let (reliable, acked) = (p.reliable, p.acked);
        if more {
            // Cut short by the budget: the rest follows after a tenth of the NACK response delay (a reader
            // that lacks a whole window of small samples would otherwise get one budget per delay, slower
            // than the writer writes).
            p.repair_due =
                Some(now + self.params.nack_response_delay / REPAIR_CONTINUATION_DIVISOR);
            self.repair_queue.arm(p.repair_due, g);
        }
        let (dest, dst) = (to.dest.as_slice(), Some(g.prefix));
        if self.params.reliable && reliable {
            for &(sn, n) in &served.fragmented {
                let hf = self.heartbeat_frag(g.entity_id, sn, n);
                out.push(dest, dst, Ts::Any, &hf);
            }
        }
        send_gaps(out, dest, dst, g.entity_id, to.writer, &served.gaps);
        // A reader that acknowledged everything meanwhile (its ACKNACK crossed our push) needs no heartbeat,
        // unless the writer is a group member: its heartbeat's GroupInfo tells the reader where the group
        // stands (an ordered reader asks for it while it holds changes back).
        let caught_up = served.idle && acked >= self.next_sn;
        if reliable && (!caught_up || self.group.is_some()) {
            let hb = self.heartbeat(g.entity_id, false);
            out.push(dest, dst, Ts::Any, &hb);
        }
    }
}

/// Where and how one repair round sends: to one reader, from one writer.
struct RepairTo {
    dest: Option<Locator>,
    reader: Guid,
    writer: EntityId,
    frag: Fragmenting,
    key_hash_only: bool,
}

/// What one repair round did besides sending changes.
struct RoundServed {
    /// Requested changes that are gone (or not for this reader): answered with GAP.
    gaps: Vec<SequenceNumber>,
    /// Fragmented samples sent, with their number of fragments: each is followed by a HEARTBEAT_FRAG.
    fragmented: Vec<(SequenceNumber, u32)>,
    /// Nothing was sent nor is gone.
    idle: bool,
}

impl RepairTo {
    /// Sends the changes, then the fragments, `p` asked for, up to about `max_bytes`.
    fn serve(
        &self,
        p: &mut ReaderProxy,
        history: &HistoryCache,
        stand_in: &Option<Box<StandIn>>,
        max_bytes: usize,
        out: &mut Outbox,
    ) -> RoundServed {
        let mut budget = max_bytes as isize;
        let mut served = RoundServed {
            gaps: Vec::new(),
            fragmented: Vec::new(),
            idle: false,
        };
        while budget > 0 {
            let Some(sn) = p.pop_requested() else {
                break;
            };
            match history.get(sn) {
                Some(c)
                    if sn >= p.floor
                        && c.rejected.binary_search(&self.reader).is_err()
                        && !StandIn::served(stand_in, &self.reader, c) =>
                {
                    self.resend(c, None, &mut served, out);
                    budget -= c.payload.len() as isize + 64;
                }
                _ => served.gaps.push(sn),
            }
        }
        while budget > 0 {
            let Some((sn, frags)) = p.pop_requested_frags() else {
                break;
            };
            if let Some(c) = history.get(sn) {
                self.resend(c, Some(&frags), &mut served, out);
                budget -= (frags.len() * self.frag.size) as isize;
            }
        }
        served.idle = budget == max_bytes as isize && served.gaps.is_empty();
        served
    }

    /// Sends change `c` again (`only` these fragments of it).
    fn resend(
        &self,
        c: &CacheChange,
        only: Option<&BitWindow>,
        served: &mut RoundServed,
        out: &mut Outbox,
    ) {
        let n = send_change(
            out,
            self.dest.as_slice(),
            Some(self.reader.prefix),
            self.reader.entity_id,
            self.writer,
            c,
            self.frag,
            only,
            self.key_hash_only,
        );
        if n > 0 {
            served.fragmented.push((c.sn, n));
        }
    }
}

/// Room for the inline QoS of one change: coherent set (12), group marks, key hash (20), status info (8).
const INLINE_QOS_MAX: usize = 40 + group::GROUP_QOS_MAX;

/// SEQUENCE_NUMBER_SET bits: what one ACKNACK can ask for.
const BITMAP_BITS: u32 = 256;

/// A repair round cut short by `max_repair_bytes` goes on after this fraction of the NACK response delay
/// (0.5 ms by default: 256 KiB per 0.5 ms, about 500 MB/s, against 50 MB/s when each round waited the whole
/// delay).
const REPAIR_CONTINUATION_DIVISOR: u32 = 10;

/// A reader that lacks the last sequence number its bitmap can name is further behind than one ACKNACK
/// says: it lacks at least a full bitmap in a row. Waiting for its next ACKNACK after every 256 repairs
/// (each round a NACK response delay apart) makes a reader that fell 10 000 small samples behind trail
/// forever at 256 samples per round while new data overflows its reorder window. So the request is read
/// as running on past the bitmap, up to the writer's last change and `MAX_REQUESTED`; the repair budget
/// per round still bounds what goes out, and a sample the reader does hold comes twice at worst.
/// Returns whether the reader is that far behind.
fn request_past_bitmap(
    p: &mut ReaderProxy,
    set: &SequenceNumberSet,
    next_sn: SequenceNumber,
) -> bool {
    if set.num_bits < BITMAP_BITS || !set.contains_offset(BITMAP_BITS - 1) {
        return false;
    }
    let mut sn = set.base + i64::from(BITMAP_BITS);
    while sn < next_sn && p.request(sn) {
        sn = sn.next();
    }
    true
}

/// Runs of consecutive sequence numbers as GAP submessages.
fn send_gaps(
    out: &mut Outbox,
    dest: &[Locator],
    dst: Option<GuidPrefix>,
    rid: EntityId,
    wid: EntityId,
    gaps: &[SequenceNumber],
) {
    let mut i = 0;
    while i < gaps.len() {
        let start = gaps[i];
        let mut end = start;
        while i + 1 < gaps.len() && gaps[i + 1] == end.next() {
            i += 1;
            end = gaps[i];
        }
        i += 1;
        let gap = Submessage::Gap(Gap {
            reader_id: rid,
            writer_id: wid,
            gap_start: start,
            gap_list: SequenceNumberSet::empty(end.next()),
        });
        out.push(dest, dst, Ts::Any, &gap);
    }
}

/// Inline QoS for a change: key hash when keyed, status info when not alive, the coherent set when in one
/// (an end-of-set marker carries only that). Built on the stack.
fn inline_qos(c: &CacheChange, buf: &mut [u8; INLINE_QOS_MAX]) -> usize {
    let mut n = 0;
    n += coherent::put_marks(&c.marks, buf);
    if c.marks.is_marker() {
        return n;
    }
    if let Some(k) = &c.key_hash {
        buf[n..n + 2].copy_from_slice(&pid::KEY_HASH.to_le_bytes());
        buf[n + 2..n + 4].copy_from_slice(&16u16.to_le_bytes());
        buf[n + 4..n + 20].copy_from_slice(k);
        n += 20;
    }
    if c.kind != ChangeKind::Alive {
        buf[n..n + 2].copy_from_slice(&pid::STATUS_INFO.to_le_bytes());
        buf[n + 2..n + 4].copy_from_slice(&4u16.to_le_bytes());
        buf[n + 4..n + 8].copy_from_slice(&[0, 0, 0, c.kind.status_info()]);
        n += 8;
    }
    n
}

/// Room left in a datagram of `max_message_size` for the headers around one DATA: RTPS header,
/// INFO_DST, INFO_TS, the DATA submessage header with its inline QoS, and a piggy-backed HEARTBEAT.
const WHOLE_HEADROOM: usize = 256;

/// The largest sample a user writer sends whole, as one DATA: two such samples fit one datagram of
/// `max_message_size` (never less than `fragment_size`). Larger samples go as DATA_FRAGs of
/// `fragment_size`. A sample of a few KiB sent whole saves, per fragment, a submessage at both ends, and
/// per sample the reassembly and a HEARTBEAT_FRAG. Above half a datagram the fragments win: those of
/// consecutive samples fill datagrams, where whole samples would go one per datagram (at 8 KiB, 1.17
/// datagrams per sample, both ways, instead of 0.77, and more kernel time than the fragments saved; see
/// `docs/performance.md`, "Session 20: 4 KiB").
pub(crate) fn whole_sample_max(max_message_size: usize, fragment_size: usize) -> usize {
    (max_message_size.saturating_sub(WHOLE_HEADROOM) / 2).max(fragment_size)
}

/// How many consecutive fragments of `fragment_size` one DATA_FRAG carries: as many as fill a datagram of
/// `max_message_size` with the headers around them, within a submessage's 16-bit length. One fragment per
/// submessage made a 4 MiB sample 3 121 DATA_FRAGs, each decoded, looked up and reassembled on its own; ten
/// per submessage (Cyclone's defaults, 14 720 and 1 344 bytes) make 313. Every reader takes any count
/// (DDSI-RTPS 2.5, 8.3.7.3).
pub(crate) fn fragments_per_submessage(max_message_size: usize, fragment_size: usize) -> usize {
    let room = max_message_size
        .min(usize::from(u16::MAX))
        .saturating_sub(WHOLE_HEADROOM);
    (room / fragment_size.max(1)).clamp(1, usize::from(u16::MAX))
}

/// How a writer cuts a sample: whole up to `whole_max` bytes, else in fragments of `size`, sent
/// `per_submessage` consecutive ones to a DATA_FRAG.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Fragmenting {
    pub size: usize,
    pub whole_max: usize,
    pub per_submessage: usize,
}

/// Sends one change as DATA, or as DATA_FRAGs (all, or the listed fragments) when larger than
/// `frag.whole_max`.
/// With `key_hash_only`, a key-only change (dispose/unregister) goes as DATA carrying only its inline QoS
/// (key hash, status info): no serialized key, neither D nor K flag; the key hash identifies the instance.
/// Returns the sample's number of fragments when it went as DATA_FRAGs, else 0.
#[allow(clippy::too_many_arguments)]
pub(crate) fn send_change(
    out: &mut Outbox,
    dest: &[Locator],
    dst: Option<GuidPrefix>,
    rid: EntityId,
    wid: EntityId,
    c: &CacheChange,
    frag: Fragmenting,
    only: Option<&BitWindow>,
    key_hash_only: bool,
) -> u32 {
    if dest.is_empty() {
        return 0;
    }
    let mut qbuf = [0u8; INLINE_QOS_MAX];
    let qn = inline_qos(c, &mut qbuf);
    // Only changes evaluated by content filters carry more: the filter info, after the fixed part.
    let with_info: Vec<u8>;
    let qos: &[u8] = match &c.filter_info {
        Some(info) => {
            with_info = [&qbuf[..qn], info].concat();
            &with_info
        }
        None => &qbuf[..qn],
    };
    let inline_qos = (!qos.is_empty()).then_some(ParameterList {
        data: qos,
        little_endian: true,
    });
    let ts = Ts::Set(c.source_timestamp);
    let len = c.payload.len();
    let alive = c.kind == ChangeKind::Alive;
    if len <= frag.whole_max || frag.size == 0 || (key_hash_only && !alive) {
        let marker = c.marks.is_marker();
        let payload = (!marker && (alive || (len > 0 && !key_hash_only))).then_some(&c.payload[..]);
        let d = Submessage::Data(Data {
            reader_id: rid,
            writer_id: wid,
            writer_sn: c.sn,
            inline_qos,
            payload,
            key_flag: !alive && payload.is_some(),
            non_standard_flag: false,
        });
        out.push(dest, dst, ts, &d);
        return 0;
    }
    let (per, frag) = (frag.per_submessage as u32, frag.size);
    let total = len.div_ceil(frag) as u32;
    // `n` fragments from `f` (both checked against the sample) in one DATA_FRAG.
    let send = |f: u32, n: u32| {
        let start = (f as usize - 1) * frag;
        let end = (start + n as usize * frag).min(len);
        // Large slices go uncopied (the I/O layer gathers them), small ones into the datagram.
        let shared = out.gathers(&c.payload, end - start);
        let d = Submessage::DataFrag(DataFrag {
            reader_id: rid,
            writer_id: wid,
            writer_sn: c.sn,
            fragment_starting_num: f,
            fragments_in_submessage: n as u16,
            fragment_size: frag as u16,
            sample_size: len as u32,
            inline_qos,
            payload: if shared { &[] } else { &c.payload[start..end] },
            key_flag: c.kind != ChangeKind::Alive,
            non_standard_flag: false,
        });
        if shared {
            out.push_shared(dest, dst, ts, &d, &c.payload.slice(start..end));
        } else {
            out.push(dest, dst, ts, &d);
        }
    };
    let requested = only.map(|set| {
        set.iter()
            .filter_map(|f| u32::try_from(f).ok())
            .filter(|&f| f >= 1 && f <= total)
    });
    match requested {
        Some(fs) => for_runs(fs, per, send),
        None => for_runs(1..=total, per, send),
    }
    total
}

/// Calls `f(first, count)` for each run of consecutive numbers in the ascending `nums`, runs cut at `max`.
fn for_runs(nums: impl Iterator<Item = u32>, max: u32, mut f: impl FnMut(u32, u32)) {
    let mut run: Option<(u32, u32)> = None;
    for x in nums {
        match run {
            Some((first, n)) if x == first + n && n < max => run = Some((first, n + 1)),
            _ => {
                if let Some((first, n)) = run {
                    f(first, n);
                }
                run = Some((x, 1));
            }
        }
    }
    if let Some((first, n)) = run {
        f(first, n);
    }
}

#[cfg(test)]
mod tests {
    use super::{for_runs, fragments_per_submessage};

    fn runs(nums: &[u32], max: u32) -> Vec<(u32, u32)> {
        let mut v = Vec::new();
        for_runs(nums.iter().copied(), max, |f, n| v.push((f, n)));
        v
    }

    #[test]
    fn requested_fragments_go_in_runs_of_consecutive_numbers() {
        assert_eq!(runs(&[], 10), []);
        assert_eq!(runs(&[3, 5], 10), [(3, 1), (5, 1)]);
        assert_eq!(runs(&[1, 2, 3, 7, 8], 10), [(1, 3), (7, 2)]);
        assert_eq!(runs(&[1, 2, 3, 4, 5], 2), [(1, 2), (3, 2), (5, 1)]);
    }

    #[test]
    fn a_data_frag_fills_a_datagram_within_a_submessage_length() {
        // Cyclone's defaults: 14 720-byte datagrams, 1 344-byte fragments.
        assert_eq!(fragments_per_submessage(14_720, 1_344), 10);
        // Fragments larger than a datagram still go, one each.
        assert_eq!(fragments_per_submessage(1_000, 1_344), 1);
        // A datagram beyond 64 KiB: the submessage's 16-bit length bounds the run.
        assert_eq!(fragments_per_submessage(1 << 20, 1_000), 65);
    }
}
