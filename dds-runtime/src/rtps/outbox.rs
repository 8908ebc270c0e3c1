//! Packs outgoing submessages into datagrams per destination list up to max_message_size.
//!
//! Submessages for several participants at one locator share a datagram: an INFO_DST switches the
//! destination participant between them, as RTPS allows (§8.3.7.7). A submessage for every participant
//! there (no INFO_DST) never follows one for a single participant in the same message: some receivers do
//! not take INFO_DST(UNKNOWN) back to "everyone", so such a submessage starts a message of its own.
//!
//! Open messages normally close at the next drain. Batched writes (`hold`) leave them open until they
//! fill up, an explicit flush, any unbatched traffic, or the batch delay runs out, so that a burst of small
//! samples travels in few datagrams.
//!
//! With gathering on ([`Outbox::gather_from`]), a large slice of a sample (the fragments of a DATA_FRAG)
//! is not copied into the datagram: the message keeps a share of the sample's buffer at that offset
//! ([`SharedPart`]) and the I/O layer sends the pieces with one scatter-gather call.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use super::api::Payload;
use super::messages::{
    append, octets_to_next_header, set_octets_to_next_header, Header, Submessage,
};
use super::transmit::{SharedPart, Transmit};
use super::types::*;

/// Whether a submessage depends on the INFO_TS in force.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Ts {
    /// Control submessage: whatever timestamp is in force does not matter.
    Any,
    /// DATA/DATA_FRAG: this timestamp (or none) must be in force.
    Set(Option<Time>),
}

#[derive(Debug)]
struct Pending {
    destinations: Vec<Locator>,
    dst: Option<GuidPrefix>,
    buf: Vec<u8>,
    /// The timestamp in force at the receiver after this message so far: `None` before any INFO_TS (a
    /// message starts without one) and after an invalidating INFO_TS alike.
    ts: Option<Time>,
    preamble: usize,
    /// Start of the last submessage, whose length grows when the next one needs alignment padding.
    last_header: Option<usize>,
    /// Slices of samples that go into the message uncopied, at their offsets in `buf`.
    shared: Vec<SharedPart>,
    /// Their total length.
    shared_len: usize,
}

impl Pending {
    /// The message's length on the wire so far.
    fn len(&self) -> usize {
        self.buf.len() + self.shared_len
    }

    /// Appends `part` to the submessage just written (its payload, left empty there) as a shared slice.
    /// The submessage ends 4-aligned and `part`'s length is a multiple of 4 ([`Outbox::gathers`]), so
    /// `buf`'s alignment stays that of the message and later padding is computed right.
    fn attach(&mut self, part: &Payload) {
        let Some(h) = self.last_header else {
            return;
        };
        // `gathers` keeps the sum within the field.
        let len = octets_to_next_header(&self.buf, h) + part.len();
        set_octets_to_next_header(&mut self.buf, h, len);
        self.shared.push(SharedPart {
            at: self.buf.len(),
            bytes: part.clone(),
        });
        self.shared_len += part.len();
    }
}

/// Shared slices must leave room for a submessage's other fields within its 16-bit length.
const MAX_SHARED: usize = u16::MAX as usize - 1024;

/// Datagram buffers kept for reuse. A pass that sends to hundreds of peers (discovery replies, heartbeats)
/// allocates beyond it; what it would keep is a fixed cost that stays for the participant's life (see
/// `docs/performance.md`, "Footprint"). Enough for a stream's datagrams in flight.
const POOLED: usize = 16;

/// Output queue: open messages being packed and finished datagrams.
#[derive(Debug)]
pub(crate) struct Outbox {
    header: Header,
    max: usize,
    pending: Vec<Pending>,
    ready: VecDeque<Transmit>,
    pool: Vec<Vec<u8>>,
    /// Lists of shared parts of sent datagrams, for reuse.
    shared_pool: Vec<Vec<SharedPart>>,
    /// Slices of at least this many bytes are shared, not copied (`None`: always copied).
    gather_min: Option<usize>,
    /// Destination lists of sent datagrams, for reuse.
    dest_pool: Vec<Vec<Locator>>,
    /// While set, pushes do not ask for the open messages to close at the next drain.
    holding: bool,
    /// The open messages must close at the next drain.
    flush_due: bool,
    /// When the oldest held submessage was queued.
    held_since: Option<Instant>,
}

impl Outbox {
    pub(crate) fn new(header: Header, max_message_size: usize) -> Self {
        Outbox {
            header,
            max: max_message_size.max(128),
            pending: Vec::new(),
            ready: VecDeque::new(),
            pool: Vec::new(),
            shared_pool: Vec::new(),
            gather_min: None,
            dest_pool: Vec::new(),
            holding: false,
            flush_due: false,
            held_since: None,
        }
    }

    /// Shares slices of samples of at least `min` bytes with the datagrams instead of copying them
    /// (`None`: copies everything, the default).
    pub(crate) fn gather_from(&mut self, min: Option<usize>) {
        self.gather_min = min;
    }

    /// Whether `n` bytes of `sample` go into a datagram shared ([`Outbox::push_shared`]) rather than
    /// copied: gathering is on and they are enough, a multiple of 4 (the message's alignment stays that
    /// of its own bytes), within a submessage's length, and of a buffer (a local sample serializes on
    /// demand and cannot be sliced).
    pub(crate) fn gathers(&self, sample: &Payload, n: usize) -> bool {
        self.gather_min.is_some_and(|min| {
            n >= min && n.is_multiple_of(4) && n <= MAX_SHARED && !sample.is_local()
        })
    }

    /// Runs `f` with its pushes held back for batching: they leave at the latest `delay` after `now`.
    pub(crate) fn hold<R>(&mut self, now: Instant, f: impl FnOnce(&mut Outbox) -> R) -> R {
        let before = self.holding;
        self.holding = true;
        let r = f(self);
        self.holding = before;
        if self.pending.iter().any(|p| p.buf.len() > p.preamble) {
            self.held_since.get_or_insert(now);
        }
        r
    }

    /// The participants that open messages to a single locator are addressed to (INFO_DST in force), and
    /// that locator, into `into` (cleared first): traffic to them may join those messages.
    pub(crate) fn open_participants(&self, into: &mut Vec<(GuidPrefix, Locator)>) {
        into.clear();
        into.extend(
            self.pending
                .iter()
                .filter_map(|p| match (p.dst, &p.destinations[..]) {
                    (Some(d), [l]) => Some((d, *l)),
                    _ => None,
                }),
        );
    }

    /// Asks for every open message to be closed at the next drain.
    pub(crate) fn request_flush(&mut self) {
        self.flush_due = true;
    }

    /// When held messages must leave, for a batch delay of `delay`.
    pub(crate) fn hold_deadline(&self, delay: Duration) -> Option<Instant> {
        self.held_since.map(|t| t + delay)
    }

    /// The message a submessage for (`destinations`, `dst`) joins: the last one opened for `destinations`
    /// (so that what goes to one locator keeps its order) when its INFO_DST is `dst` or may switch to it;
    /// else a new one.
    fn open(&mut self, destinations: &[Locator], dst: Option<GuidPrefix>) -> usize {
        let last = self
            .pending
            .iter()
            .rposition(|p| p.destinations == destinations);
        if let Some(i) = last.filter(|&i| dst.is_some() || self.pending[i].dst.is_none()) {
            return i;
        }
        self.fresh(destinations, dst)
    }

    /// A new message for (`destinations`, `dst`).
    fn fresh(&mut self, destinations: &[Locator], dst: Option<GuidPrefix>) -> usize {
        let mut buf = self.pool.pop().unwrap_or_default();
        buf.clear();
        self.header.write(&mut buf);
        let mut last_header = None;
        if let Some(d) = dst {
            append(&mut buf, &mut last_header, &Submessage::InfoDst(d), true);
        }
        let preamble = buf.len();
        let mut dests = self.dest_pool.pop().unwrap_or_default();
        dests.clear();
        dests.extend_from_slice(destinations);
        let shared = self.shared_pool.pop().unwrap_or_default();
        self.pending.push(Pending {
            destinations: dests,
            dst,
            buf,
            ts: None,
            preamble,
            last_header,
            shared,
            shared_len: 0,
        });
        self.pending.len() - 1
    }

    /// Appends `sub` to the message for (destinations, dst); starts a new datagram when it would not fit.
    pub(crate) fn push(
        &mut self,
        destinations: &[Locator],
        dst: Option<GuidPrefix>,
        ts: Ts,
        sub: &Submessage<'_>,
    ) {
        self.push_part(destinations, dst, ts, sub, None);
    }

    /// Like [`push`](Outbox::push) for a DATA_FRAG written with an empty payload, whose payload is
    /// `part` (one that [`gathers`](Outbox::gathers)), shared with the datagram instead of copied.
    pub(crate) fn push_shared(
        &mut self,
        destinations: &[Locator],
        dst: Option<GuidPrefix>,
        ts: Ts,
        sub: &Submessage<'_>,
        part: &Payload,
    ) {
        self.push_part(destinations, dst, ts, sub, Some(part));
    }

    fn push_part(
        &mut self,
        destinations: &[Locator],
        dst: Option<GuidPrefix>,
        ts: Ts,
        sub: &Submessage<'_>,
        part: Option<&Payload>,
    ) {
        if destinations.is_empty() {
            return;
        }
        if !self.holding {
            self.flush_due = true;
        }
        let i = self.open(destinations, dst);
        let p = &mut self.pending[i];
        let (before, before_len) = (p.buf.len(), p.len());
        let (shared_before, shared_len_before) = (p.shared.len(), p.shared_len);
        let (ts_before, header_before, dst_before) = (p.ts, p.last_header, p.dst);
        let saved_len = header_before.map(|h| (h, [p.buf[h + 2], p.buf[h + 3]]));
        write_dst(p, dst);
        write_ts(p, ts);
        append(&mut p.buf, &mut p.last_header, sub, true);
        if let Some(part) = part {
            p.attach(part);
        }
        if p.len() > self.max && before > p.preamble {
            // Did not fit: close the message without it (undoing the alignment padding of the previous
            // submessage) and put it first in a fresh one.
            let spill = p.len() - before_len;
            p.buf.truncate(before);
            p.shared.truncate(shared_before);
            p.shared_len = shared_len_before;
            if let Some((h, len)) = saved_len {
                p.buf[h + 2..h + 4].copy_from_slice(&len);
            }
            p.ts = ts_before;
            p.last_header = header_before;
            p.dst = dst_before;
            let done = self.pending.swap_remove(i);
            self.ready.push_back(Transmit {
                destinations: done.destinations,
                payload: done.buf,
                shared: done.shared,
            });
            let i = self.fresh(destinations, dst);
            let p = &mut self.pending[i];
            if part.is_none() {
                // A run of submessages that fill datagrams (the fragments of a large sample): room for a
                // full one and the submessage that will not fit, so that the buffer never regrows (and
                // copies itself) step by step.
                p.buf
                    .reserve((self.max + spill).saturating_sub(p.buf.len()));
            }
            write_ts(p, ts);
            append(&mut p.buf, &mut p.last_header, sub, true);
            if let Some(part) = part {
                p.attach(part);
            }
        }
    }

    /// Closes every open message.
    pub(crate) fn flush(&mut self) {
        self.flush_due = false;
        self.held_since = None;
        for p in self.pending.drain(..) {
            if p.buf.len() > p.preamble {
                self.ready.push_back(Transmit {
                    destinations: p.destinations,
                    payload: p.buf,
                    shared: p.shared,
                });
            } else {
                self.pool.push(p.buf);
                self.shared_pool.push(p.shared);
            }
        }
    }

    /// The next finished datagram. Open messages close first when a flush is due or the held ones have
    /// waited `batch_delay`.
    pub(crate) fn pop(&mut self, now: Instant, batch_delay: Duration) -> Option<Transmit> {
        if self.ready.is_empty()
            && (self.flush_due || self.hold_deadline(batch_delay).is_some_and(|t| t <= now))
        {
            self.flush();
        }
        self.ready.pop_front()
    }

    /// Returns a datagram buffer for reuse.
    pub(crate) fn recycle(&mut self, buf: Vec<u8>) {
        if self.pool.len() < POOLED {
            self.pool.push(buf);
        }
    }

    /// Returns a datagram's list of shared parts for reuse (the shares themselves are dropped).
    pub(crate) fn recycle_shared(&mut self, mut shared: Vec<SharedPart>) {
        shared.clear();
        if shared.capacity() > 0 && self.shared_pool.len() < POOLED {
            self.shared_pool.push(shared);
        }
    }

    /// Gives back what a burst left in the reuse pools and queues beyond `keep` entries each (a burst of
    /// discovery replies to a few hundred peers fills the datagram pool to its bound, [`POOLED`]), and
    /// the room beyond `keep_bytes` of each datagram buffer kept (a few large datagrams leave their
    /// buffers that large; a stream of them regrows a few buffers once per trim).
    pub(crate) fn trim(&mut self, keep: usize, keep_bytes: usize) {
        self.pool.truncate(keep);
        self.pool.shrink_to(keep);
        for b in &mut self.pool {
            b.clear();
            b.shrink_to(keep_bytes);
        }
        self.dest_pool.truncate(keep);
        self.dest_pool.shrink_to(keep);
        self.shared_pool.truncate(keep);
        self.shared_pool.shrink_to(keep);
        self.pending.shrink_to(keep);
        self.ready.shrink_to(keep);
    }

    /// Takes back a sent datagram's destination list for reuse.
    pub(crate) fn recycle_destinations(&mut self, dests: Vec<Locator>) {
        if self.dest_pool.len() < 64 && dests.capacity() <= 64 {
            self.dest_pool.push(dests);
        }
    }
}

/// Switches the message's destination participant to `dst` (`open` only joins a `Some` to another).
fn write_dst(p: &mut Pending, dst: Option<GuidPrefix>) {
    if let (Some(d), true) = (dst, p.dst != dst) {
        append(
            &mut p.buf,
            &mut p.last_header,
            &Submessage::InfoDst(d),
            true,
        );
        p.dst = dst;
    }
}

fn write_ts(p: &mut Pending, ts: Ts) {
    if let Ts::Set(t) = ts {
        if p.ts != t {
            append(&mut p.buf, &mut p.last_header, &Submessage::InfoTs(t), true);
            p.ts = t;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtps::messages::{Gap, MessageIter};

    fn gap(n: i64) -> Submessage<'static> {
        Submessage::Gap(Gap {
            reader_id: EntityId::UNKNOWN,
            writer_id: EntityId::SEDP_PUBLICATIONS_WRITER,
            gap_start: SequenceNumber(n),
            gap_list: SequenceNumberSet::empty(SequenceNumber(n + 1)),
        })
    }

    fn outbox() -> Outbox {
        let header = Header {
            version: ProtocolVersion::V2_5,
            vendor_id: VendorId::THIS,
            guid_prefix: GuidPrefix([9; 12]),
        };
        Outbox::new(header, 14720)
    }

    /// Each datagram as (INFO_DST in force, gap start) per submessage.
    fn sent(o: &mut Outbox) -> Vec<Vec<(Option<GuidPrefix>, i64)>> {
        let mut all = Vec::new();
        while let Some(t) = o.pop(Instant::now(), Duration::ZERO) {
            let (_, it) = MessageIter::parse(&t.payload).unwrap();
            let mut dst = None;
            let mut subs = Vec::new();
            for s in it.flatten() {
                match s {
                    Submessage::InfoDst(d) => dst = Some(d),
                    Submessage::Gap(g) => subs.push((dst, g.gap_start.0)),
                    _ => {}
                }
            }
            all.push(subs);
        }
        all
    }

    #[test]
    fn submessages_for_several_participants_at_one_locator_share_a_datagram() {
        let l = [Locator::udpv4([10, 0, 0, 1], 7410)];
        let (a, b) = (Some(GuidPrefix([1; 12])), Some(GuidPrefix([2; 12])));
        let mut o = outbox();
        o.push(&l, None, Ts::Any, &gap(1));
        o.push(&l, a, Ts::Any, &gap(2));
        o.push(&l, b, Ts::Any, &gap(3));
        o.push(&l, b, Ts::Any, &gap(4));
        // For everyone again: not after an INFO_DST, so a message of its own.
        o.push(&l, None, Ts::Any, &gap(5));
        o.push(&l, a, Ts::Any, &gap(6));
        assert_eq!(
            sent(&mut o),
            vec![
                vec![(None, 1), (a, 2), (b, 3), (b, 4)],
                vec![(None, 5), (a, 6)]
            ]
        );
    }

    /// The fragments of a sample in DATA_FRAGs of `per` fragments (the writer's way), then a GAP, to two
    /// participants at one locator; slices that [`Outbox::gathers`] go shared when `share`.
    fn fragment_runs(o: &mut Outbox, sample: &Payload, per: usize, share: bool) -> Vec<Transmit> {
        use crate::rtps::messages::DataFrag;
        let l = [Locator::udpv4([10, 0, 0, 1], 7410)];
        let frag = 1344;
        let firsts = (0..sample.len().div_ceil(frag)).step_by(per);
        for (k, first) in firsts.enumerate() {
            let (start, end) = (first * frag, ((first + per) * frag).min(sample.len()));
            let shared = share && o.gathers(sample, end - start);
            let d = Submessage::DataFrag(DataFrag {
                reader_id: EntityId::UNKNOWN,
                writer_id: EntityId::SEDP_PUBLICATIONS_WRITER,
                writer_sn: SequenceNumber(1),
                fragment_starting_num: first as u32 + 1,
                fragments_in_submessage: (end - start).div_ceil(frag) as u16,
                fragment_size: frag as u16,
                sample_size: sample.len() as u32,
                inline_qos: None,
                payload: if shared { &[] } else { &sample[start..end] },
                key_flag: false,
                non_standard_flag: false,
            });
            let dst = Some(GuidPrefix([1 + (k % 2) as u8; 12]));
            let ts = Ts::Set(Some(Time {
                seconds: 5,
                fraction: 0,
            }));
            match shared {
                true => o.push_shared(&l, dst, ts, &d, &sample.slice(start..end)),
                false => o.push(&l, dst, ts, &d),
            }
        }
        o.push(&l, None, Ts::Any, &gap(9));
        std::iter::from_fn(|| o.pop(Instant::now(), Duration::ZERO)).collect()
    }

    #[test]
    fn shared_fragments_make_the_same_datagrams_as_copied_ones() {
        // A last fragment of 3 bytes (not a multiple of 4: copied), runs of 1 and of 10 fragments.
        let sample = Payload::new((0..40_323u32).map(|i| i as u8).collect::<Vec<u8>>());
        for (per, max) in [(10, 14_720), (1, 14_720), (3, 14_720), (10, 1_500)] {
            let mut copied = outbox();
            copied.max = max;
            let mut gathered = outbox();
            gathered.max = max;
            gathered.gather_from(Some(1_000));
            let want = fragment_runs(&mut copied, &sample, per, false);
            let got = fragment_runs(&mut gathered, &sample, per, true);
            assert!(want.iter().all(|t| t.shared.is_empty()));
            if max > 1_500 {
                assert!(got.iter().any(|t| !t.shared.is_empty()), "{per}");
            }
            let bytes =
                |ts: &[Transmit]| ts.iter().map(|t| t.datagram().to_vec()).collect::<Vec<_>>();
            assert_eq!(bytes(&got), bytes(&want), "{per} per DATA_FRAG, max {max}");
        }
    }

    #[test]
    fn a_burst_fills_the_pool_and_trim_gives_it_back() {
        let mut o = outbox();
        for port in 0..100u16 {
            o.push(
                &[Locator::udpv4([10, 0, 0, 1], 7410 + port)],
                None,
                Ts::Any,
                &gap(1),
            );
        }
        while let Some(t) = o.pop(Instant::now(), Duration::ZERO) {
            o.recycle(t.payload);
            o.recycle_destinations(t.destinations);
        }
        assert_eq!((o.pool.len(), o.dest_pool.len()), (POOLED, 64));
        o.pool[0].reserve(65_536);
        o.trim(8, 512);
        assert_eq!((o.pool.len(), o.dest_pool.len()), (8, 8));
        assert!(o.pool.capacity() <= 8 && o.ready.capacity() <= 8);
        assert!(o.pool.iter().all(|b| b.is_empty() && b.capacity() <= 512));
        // It still works.
        o.push(
            &[Locator::udpv4([10, 0, 0, 1], 7410)],
            None,
            Ts::Any,
            &gap(2),
        );
        assert_eq!(sent(&mut o), vec![vec![(None, 2)]]);
    }
}
