//! What a writer knows about one matched reader (§8.4.7.5).
//!
//! Slim by design: a participant keeps one proxy per remote builtin reader of every discovered participant
//! (see `docs/performance.md`, "Footprint"), and most of them hold no request most of the time. The requested
//! changes and fragments are in a [`Repairs`] box made on the first request and dropped once served and
//! the reader has acknowledged every change (a reader that is behind keeps it, and its bitmaps' words, from
//! one repair round to the next).

use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

use super::bit_window::BitWindow;
use crate::rtps::types::*;

/// Bounds on what one remote reader can make us remember.
pub(crate) const MAX_REQUESTED: usize = 4096;
pub(crate) const MAX_REQUESTED_FRAG_SAMPLES: usize = 64;
/// The requested changes span at most this many sequence numbers (a bitmap of 1 KiB): twice what one
/// ACKNACK read past its bitmap asks for (`MAX_REQUESTED`, after its 256 bits).
pub(crate) const MAX_REQUESTED_SPAN: usize = 2 * MAX_REQUESTED;

#[derive(Debug, Clone)]
pub(crate) struct ReaderProxy {
    pub guid: Guid,
    /// Where to send: the reader's unicast locators (the first is used), then, when `multicast_last` is set,
    /// a multicast locator it listens on (when multicast user data is on, see
    /// `ParticipantConfig::multicast_data`). Shared with the other proxies made from the same announcement
    /// (one list per remote participant for its builtin readers). See [`unicast`](Self::unicast) and
    /// [`multicast`](Self::multicast).
    locators: Arc<[Locator]>,
    /// The last of `locators` is a multicast locator, not a unicast one. Kept in the list rather than in a
    /// slot of its own: the proxy then fits a 96-byte allocation (see `proxy_stays_small`).
    multicast_last: bool,
    /// New data (and the periodic heartbeat) goes to the multicast locator instead of the unicast one: set
    /// by the writer when another matched reader shares that multicast locator.
    pub via_multicast: bool,
    /// Reliable protocol with this reader (both sides reliable).
    pub reliable: bool,
    /// Every change below this is acknowledged.
    pub acked: SequenceNumber,
    /// Changes below this predate the match of a volatile reader: answered with GAP.
    pub floor: SequenceNumber,
    /// Changes and fragments the reader asked for: `None` while nothing is requested.
    repairs: Option<Box<Repairs>>,
    /// The count of the last ACKNACK taken (meaningful once `acknack_seen`).
    last_acknack: i32,
    /// The count of the last NACK_FRAG taken (meaningful once `nackfrag_seen`).
    last_nackfrag: i32,
    acknack_seen: bool,
    nackfrag_seen: bool,
    /// When to send requested repairs (and a heartbeat addressed to this reader).
    pub repair_due: Option<Instant>,
    /// Send dispose/unregister (key-only changes) as DATA with only inline QoS (PID_KEY_HASH,
    /// PID_STATUS_INFO) and no serialized key. Set for Fast DDS readers: Fast DDS 2.9 copies a key payload of
    /// up to 16 bytes straight into its instance handle, as if it were the key hash.
    pub key_hash_only_disposes: bool,
}

/// What a reader asked to be sent again: the part of a [`ReaderProxy`] only used between a request and its
/// repair.
#[derive(Debug, Clone, Default)]
pub(crate) struct Repairs {
    /// Whole changes by sequence number (at most [`MAX_REQUESTED`], within [`MAX_REQUESTED_SPAN`]).
    requested: BitWindow,
    /// Fragments of changes (at most [`MAX_REQUESTED_FRAG_SAMPLES`] changes).
    pub requested_frags: BTreeMap<SequenceNumber, BitWindow>,
}

impl Repairs {
    fn is_empty(&self) -> bool {
        self.requested.is_empty() && self.requested_frags.is_empty()
    }
}

impl ReaderProxy {
    pub(crate) fn new(guid: Guid, locators: impl Into<Arc<[Locator]>>, reliable: bool) -> Self {
        ReaderProxy {
            guid,
            locators: locators.into(),
            multicast_last: false,
            via_multicast: false,
            reliable,
            acked: SequenceNumber(1),
            floor: SequenceNumber(1),
            repairs: None,
            last_acknack: 0,
            last_nackfrag: 0,
            acknack_seen: false,
            nackfrag_seen: false,
            repair_due: None,
            key_hash_only_disposes: false,
        }
    }

    /// Whether an ACKNACK numbered `count` is newer than the last one taken (counts wrap); if so it is
    /// taken: a repeated or reordered ACKNACK is ignored (§8.4.15.7).
    pub(crate) fn take_acknack_count(&mut self, count: i32) -> bool {
        let newer = !self.acknack_seen || count.wrapping_sub(self.last_acknack) > 0;
        if newer {
            (self.last_acknack, self.acknack_seen) = (count, true);
        }
        newer
    }

    /// Whether a NACK_FRAG numbered `count` is newer than the last one taken; if so it is taken (see
    /// [`take_acknack_count`](Self::take_acknack_count)).
    pub(crate) fn take_nackfrag_count(&mut self, count: i32) -> bool {
        let newer = !self.nackfrag_seen || count.wrapping_sub(self.last_nackfrag) > 0;
        if newer {
            (self.last_nackfrag, self.nackfrag_seen) = (count, true);
        }
        newer
    }

    /// The requests, made on first use.
    pub(crate) fn repairs_mut(&mut self) -> &mut Repairs {
        self.repairs.get_or_insert_with(Box::default)
    }

    /// Asks for the whole change `sn` unless [`MAX_REQUESTED`] are asked for already, or the requests would
    /// then span more than [`MAX_REQUESTED_SPAN`] sequence numbers; false when full (or `sn` is not a
    /// sequence number, below 1).
    pub(crate) fn request(&mut self, sn: SequenceNumber) -> bool {
        let Some(n) = sn_index(sn) else {
            return false;
        };
        let r = self.repairs_mut();
        r.requested.len() < MAX_REQUESTED && r.requested.insert(n, MAX_REQUESTED_SPAN.div_ceil(64))
    }

    /// Asks for the fragments `frags` of change `sn`, a sample of `total` fragments (numbers outside
    /// `1..=total` are ignored), unless fragments of [`MAX_REQUESTED_FRAG_SAMPLES`] other changes are asked
    /// for already.
    pub(crate) fn request_frags(
        &mut self,
        sn: SequenceNumber,
        frags: impl Iterator<Item = u32>,
        total: u32,
    ) {
        let mut frags = frags.filter(|f| (1..=total).contains(f)).peekable();
        if frags.peek().is_none() {
            return;
        }
        let all = &mut self.repairs_mut().requested_frags;
        if all.len() >= MAX_REQUESTED_FRAG_SAMPLES && !all.contains_key(&sn) {
            return;
        }
        let set = all.entry(sn).or_default();
        let words = (total as usize).div_ceil(64) + 1;
        for f in frags {
            set.insert(u64::from(f), words);
        }
    }

    /// Whether whole changes are requested.
    pub(crate) fn has_requested(&self) -> bool {
        self.repairs
            .as_ref()
            .is_some_and(|r| !r.requested.is_empty())
    }

    /// Whether anything (whole changes or fragments) is requested.
    pub(crate) fn has_requests(&self) -> bool {
        self.repairs.as_ref().is_some_and(|r| !r.is_empty())
    }

    /// Forgets the requests below `acked` (in place: nothing is allocated or freed but the box, see
    /// [`release_if_served`](Self::release_if_served)).
    pub(crate) fn drop_requests_below(
        &mut self,
        acked: SequenceNumber,
        writer_next: SequenceNumber,
    ) {
        if let Some(r) = self.repairs.as_deref_mut() {
            r.requested.remove_below(sn_index(acked).unwrap_or(0));
            while r
                .requested_frags
                .first_key_value()
                .is_some_and(|(&sn, _)| sn < acked)
            {
                r.requested_frags.pop_first();
            }
        }
        self.release_if_served(writer_next);
    }

    /// Takes the first requested whole change (and forgets fragments asked for it).
    pub(crate) fn pop_requested(&mut self) -> Option<SequenceNumber> {
        let r = self.repairs.as_deref_mut()?;
        let sn = SequenceNumber(r.requested.pop_first()? as i64);
        r.requested_frags.remove(&sn);
        Some(sn)
    }

    /// Takes the first change fragments are requested of.
    pub(crate) fn pop_requested_frags(&mut self) -> Option<(SequenceNumber, BitWindow)> {
        self.repairs.as_deref_mut()?.requested_frags.pop_first()
    }

    /// Drops the requests' box once nothing is left in it and the reader needs no more repairs: it
    /// acknowledged every change up to `writer_next` (or is best effort). A reader that is behind keeps it
    /// for its next requests.
    pub(crate) fn release_if_served(&mut self, writer_next: SequenceNumber) {
        let done = !self.reliable || self.acked >= writer_next;
        if done && self.repairs.as_ref().is_some_and(|r| r.is_empty()) {
            self.repairs = None;
        }
    }

    /// Adapts the wire form to what the reader's implementation (its participant's vendor) understands.
    pub(crate) fn for_vendor(mut self, vendor: VendorId) -> Self {
        self.key_hash_only_disposes = vendor == VendorId::FASTDDS;
        self
    }

    /// The reader's unicast locators.
    pub(crate) fn unicast(&self) -> &[Locator] {
        let n = self.locators.len() - usize::from(self.multicast_last && !self.locators.is_empty());
        &self.locators[..n]
    }

    /// The multicast locator the reader can be reached on, if any.
    pub(crate) fn multicast(&self) -> Option<Locator> {
        self.multicast_last
            .then(|| self.locators.last().copied())
            .flatten()
    }

    /// Where to send what is for this reader alone (repairs, GAPs): its first unicast locator.
    pub(crate) fn destination(&self) -> &[Locator] {
        let unicast = self.unicast();
        &unicast[..unicast.len().min(1)]
    }

    /// Where new data for this reader goes: the shared multicast locator when the writer chose it, else
    /// [`destination`](Self::destination).
    pub(crate) fn data_destination(&self) -> Option<Locator> {
        match self.multicast() {
            Some(m) if self.via_multicast => Some(m),
            _ => self.destination().first().copied(),
        }
    }

    /// Gives the reader a multicast locator it can be reached on (none: unicast only): the locator list
    /// is copied with it appended. Proxies that share a list use
    /// [`with_multicast_last`](Self::with_multicast_last) instead.
    pub(crate) fn with_multicast(self, multicast: Option<Locator>) -> Self {
        match multicast {
            Some(m) => {
                let list = locators_with_multicast(self.unicast(), Some(m));
                ReaderProxy {
                    locators: list,
                    multicast_last: true,
                    ..self
                }
            }
            None => self,
        }
    }

    /// Says that the last of the locators the proxy was made with is a multicast locator the reader can be
    /// reached on (a list made by [`locators_with_multicast`], shared by several proxies).
    pub(crate) fn with_multicast_last(mut self, multicast_last: bool) -> Self {
        self.multicast_last = multicast_last && !self.locators.is_empty();
        self
    }
}

/// A proxy's locator list: `unicast`, then `multicast` if any (see [`ReaderProxy::with_multicast_last`]).
fn locators_with_multicast(unicast: &[Locator], multicast: Option<Locator>) -> Arc<[Locator]> {
    unicast.iter().copied().chain(multicast).collect()
}

impl crate::rtps::proxy_map::Keyed for ReaderProxy {
    fn key(&self) -> &Guid {
        &self.guid
    }
}

/// A sequence number as a bit's number in the requests' window (`None` below 1: no change has it).
fn sn_index(sn: SequenceNumber) -> Option<u64> {
    u64::try_from(sn.0).ok().filter(|&n| n > 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn proxy() -> ReaderProxy {
        ReaderProxy::new(Guid::default(), Vec::<Locator>::new(), true)
    }

    /// One proxy per remote builtin reader of every discovered participant: the requests' sets are boxed
    /// (160 bytes on x86-64 before), the multicast locator is in the shared list and the counts are plain
    /// (120 bytes before, a 128-byte allocation; 88 takes 96).
    #[test]
    #[cfg(target_pointer_width = "64")]
    fn proxy_stays_small() {
        assert_eq!(std::mem::size_of::<ReaderProxy>(), 88);
    }

    fn loc(port: u16) -> Locator {
        Locator::udpv4([127, 0, 0, 1], port)
    }

    #[test]
    fn the_multicast_locator_is_last_in_the_list() {
        let mc = Locator::udpv4([239, 255, 0, 1], 7400);
        let p = proxy().with_multicast(Some(mc));
        assert_eq!((p.unicast(), p.destination()), (&[][..], &[][..]));
        assert_eq!((p.multicast(), p.data_destination()), (Some(mc), None));
        let list = locators_with_multicast(&[loc(1), loc(2)], Some(mc));
        let mut p = ReaderProxy::new(Guid::default(), list.clone(), true).with_multicast_last(true);
        assert_eq!(p.unicast(), [loc(1), loc(2)]);
        assert_eq!((p.destination(), p.multicast()), (&[loc(1)][..], Some(mc)));
        assert_eq!(p.data_destination(), Some(loc(1)));
        p.via_multicast = true;
        assert_eq!(p.data_destination(), Some(mc));
        let p = ReaderProxy::new(Guid::default(), list, true).with_multicast(None);
        assert_eq!((p.unicast().len(), p.multicast()), (3, None));
        let p = proxy().with_multicast_last(true);
        assert_eq!((p.unicast(), p.multicast()), (&[][..], None));
    }

    #[test]
    fn repeated_and_older_counts_are_ignored_and_counts_wrap() {
        let mut p = proxy();
        assert!(p.take_acknack_count(-7), "any first count is taken");
        assert!(!p.take_acknack_count(-7) && !p.take_acknack_count(-8));
        assert!(p.take_acknack_count(-6));
        assert!(p.take_nackfrag_count(i32::MAX) && p.take_nackfrag_count(i32::MIN));
        assert!(!p.take_nackfrag_count(i32::MAX));
    }

    #[test]
    fn requests_are_boxed_on_first_use_and_dropped_once_served() {
        let mut p = proxy();
        assert!(p.repairs.is_none() && !p.has_requests());
        assert!(p.request(SequenceNumber(3)) && p.request(SequenceNumber(5)));
        p.request_frags(SequenceNumber(7), [1, 9].into_iter(), 4);
        let next = SequenceNumber(20);
        p.drop_requests_below(SequenceNumber(4), next);
        assert_eq!(p.pop_requested(), Some(SequenceNumber(5)));
        assert!(p.has_requests() && !p.has_requested());
        let (sn, frags) = p.pop_requested_frags().unwrap();
        assert_eq!(
            (sn, frags.iter().collect::<Vec<_>>()),
            (SequenceNumber(7), vec![1])
        );
        p.release_if_served(next);
        assert!(p.repairs.is_some(), "a reader that is behind keeps the box");
        p.acked = next;
        p.release_if_served(next);
        assert!(p.repairs.is_none());
        p.request(SequenceNumber(9));
        p.acked = SequenceNumber(10);
        p.drop_requests_below(SequenceNumber(10), SequenceNumber(10));
        assert!(p.repairs.is_none(), "acknowledged requests free the box");
    }

    /// A hostile reader's requests cannot make the bitmap grow: far apart, or fragments the sample lacks.
    #[test]
    fn requests_span_a_bounded_window() {
        let mut p = proxy();
        assert!(p.request(SequenceNumber(1_000)));
        assert!(!p.request(SequenceNumber(1_000 + MAX_REQUESTED_SPAN as i64)));
        assert!(!p.request(SequenceNumber(-5)) && !p.request(SequenceNumber(0)));
        p.request_frags(SequenceNumber(1_000), [0, 3, 5, u32::MAX].into_iter(), 4);
        let (_, frags) = p.pop_requested_frags().unwrap();
        assert_eq!(frags.iter().collect::<Vec<_>>(), [3]);
        p.request_frags(SequenceNumber(1_001), [9].into_iter(), 4);
        assert!(
            p.pop_requested_frags().is_none(),
            "nothing valid, nothing asked"
        );
    }

    #[test]
    fn requests_are_bounded() {
        let mut p = proxy();
        for sn in 1..=MAX_REQUESTED as i64 {
            assert!(p.request(SequenceNumber(sn)));
        }
        assert!(!p.request(SequenceNumber(MAX_REQUESTED as i64 + 1)));
    }
}
