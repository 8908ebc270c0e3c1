//! A durability service's stand-in writer (see docs/durability.md) and its hold on the readers that the
//! original writer serves.
//!
//! The stand-in's USER_DATA names the original writer: this prefix followed by its 16-byte GUID. Other
//! services skip such writers (no service replays another's replay), our readers use it to drop repeats
//! (`dcps/durability/dedup.rs`) and to report the original writer as the changes' publication.
//!
//! Another vendor's reader cannot tell the stand-in's repeat of a change from a new sample. While the
//! original writer lives and matches such a reader, the stand-in **holds** it: no DATA, no GAP, no
//! HEARTBEAT go to it, and its ACKNACKs are ignored (the proxy is treated as best-effort, so it holds back
//! neither flow control nor acknowledgement). Nothing is lost: everything stays in the stand-in's history.
//! When the original goes, the reader is **released** with what the original served it ([`Served`]): the
//! stand-in then answers its requests with GAP for that and DATA for the rest.

use std::collections::BTreeMap;
use std::time::Instant;

use super::CacheChange;
use crate::rtps::types::{Guid, Time};

const PREFIX: &[u8] = b"dds-rs durability stand-in for ";

/// The USER_DATA of a stand-in for `original`.
#[cfg(feature = "net")]
pub(crate) fn user_data(original: &Guid) -> Vec<u8> {
    let mut v = PREFIX.to_vec();
    v.extend_from_slice(&original.to_bytes());
    v
}

/// The original writer, when `user_data` is a stand-in's.
pub(crate) fn stand_in_for(user_data: &[u8]) -> Option<Guid> {
    let g: [u8; 16] = user_data.strip_prefix(PREFIX)?.try_into().ok()?;
    Some(Guid::from_bytes(g))
}

/// What the original writer served a reader before it went, as far as its departure tells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Served {
    /// Nothing known (the original was lost: its participant's lease expired): the stand-in sends all.
    Nothing,
    /// Every change with a source timestamp before this one (the first the reader had not acknowledged).
    Before(Time),
    /// Everything: the reader acknowledged all the original wrote, or the original left cleanly (a reliable
    /// writer lingers until its readers acknowledged).
    All,
}

/// The stand-in's state of a writer: the original it stands for, its held and released readers.
#[derive(Debug)]
pub(crate) struct StandIn {
    original: Guid,
    /// Held readers: their reliability (restored at release) and when they matched (a release arms their
    /// repair at that instant, so that it is due at once).
    held: BTreeMap<Guid, (bool, Instant)>,
    /// The reader about to be matched, when it is to be held (see [`super::Writer::hold_next`]).
    next: Option<Guid>,
    /// Released readers that had changes from the original: they get no new data pushed, and requests for
    /// what the original served them are answered with GAP.
    served: BTreeMap<Guid, Served>,
}

impl StandIn {
    /// Whether new data skips `g` (held, or released with what the original served it).
    pub(super) fn excludes(this: &Option<Box<StandIn>>, g: &Guid) -> bool {
        this.as_ref()
            .is_some_and(|s| s.held.contains_key(g) || s.served.contains_key(g))
    }

    /// Whether the original served `c` to `g`: the stand-in answers a request for it with GAP.
    pub(super) fn served(this: &Option<Box<StandIn>>, g: &Guid, c: &CacheChange) -> bool {
        match this.as_ref().and_then(|s| s.served.get(g)) {
            None | Some(Served::Nothing) => false,
            Some(Served::All) => true,
            Some(Served::Before(t)) => c.source_timestamp.is_some_and(|ts| ts < *t),
        }
    }
}

impl super::Writer {
    /// Makes this writer a stand-in for `original`.
    pub(crate) fn stand_in_for(&mut self, original: Guid) {
        self.stand_in = Some(Box::new(StandIn {
            original,
            held: BTreeMap::new(),
            next: None,
            served: BTreeMap::new(),
        }));
    }

    /// The original writer, when this is a stand-in.
    pub(crate) fn original(&self) -> Option<Guid> {
        self.stand_in.as_ref().map(|s| s.original)
    }

    /// The readers this stand-in holds.
    pub(crate) fn held(&self) -> Vec<Guid> {
        self.stand_in
            .as_ref()
            .map_or_else(Vec::new, |s| s.held.keys().copied().collect())
    }

    /// The next reader matched ([`super::Writer::add_proxy`]) is `reader`, to be held.
    pub(crate) fn hold_next(&mut self, reader: Guid) {
        if let Some(s) = self.stand_in.as_deref_mut() {
            s.next = Some(reader);
        }
    }

    /// At matching: holds `proxy` if announced by [`Self::hold_next`]. A held proxy is best-effort (and no
    /// history is pushed to it) until released. Whether it is held.
    pub(super) fn hold_at_match(&mut self, now: Instant, proxy: &mut super::ReaderProxy) -> bool {
        let Some(s) = self.stand_in.as_deref_mut() else {
            return false;
        };
        if s.next.take() != Some(proxy.guid) {
            return false;
        }
        s.held.insert(proxy.guid, (proxy.reliable, now));
        proxy.reliable = false;
        true
    }

    /// Releases the held reader `reader` after the original went, having served it `served`. It is
    /// reliable again and gets a HEARTBEAT at once; it then asks for what it lacks.
    pub(crate) fn release(
        &mut self,
        reader: &Guid,
        served: Served,
        ev: &mut std::collections::VecDeque<crate::rtps::api::Event>,
    ) {
        let Some(s) = self.stand_in.as_deref_mut() else {
            return;
        };
        let Some((reliable, since)) = s.held.remove(reader) else {
            return;
        };
        if served != Served::Nothing {
            s.served.insert(*reader, served);
        }
        tracing::debug!(writer = ?self.guid, ?reader, ?served, "stand-in releases a reader");
        if let Some(p) = self.proxies.get_mut(reader) {
            p.reliable = reliable && self.params.reliable;
            if !p.reliable {
                // Best effort: the history is pushed once, as at matching (what was served goes as GAP).
                for c in self.history.range(p.floor) {
                    if !p.request(c.sn) {
                        break;
                    }
                }
            }
            p.repair_due = Some(since);
            self.repair_queue.arm(p.repair_due, *reader);
            if p.reliable {
                self.hb_due.get_or_insert(since);
            }
        }
        self.rebuild_dest();
        self.update_acked(ev);
    }

    /// What this writer (an original that is going) served `reader`, from its acknowledgements.
    pub(crate) fn served_to(&self, reader: &Guid) -> Served {
        let Some(p) = self.proxies.get(reader).filter(|p| p.reliable) else {
            return Served::Nothing;
        };
        match self.history.range(p.acked).next() {
            Some(c) => c.source_timestamp.map_or(Served::Nothing, Served::Before),
            // Nothing left it lacks: what it did not acknowledge is gone from the history (it gets GAPs).
            None => Served::All,
        }
    }

    /// Forgets `reader` (unmatched).
    pub(super) fn forget_held(&mut self, reader: &Guid) {
        if let Some(s) = self.stand_in.as_deref_mut() {
            s.held.remove(reader);
            s.served.remove(reader);
            if s.next == Some(*reader) {
                s.next = None;
            }
        }
    }
}

#[cfg(all(test, feature = "net"))]
mod tests {
    use super::*;
    use crate::rtps::{EntityId, GuidPrefix};

    #[test]
    fn round_trip() {
        let g = Guid::new(GuidPrefix([1; 12]), EntityId([0, 0, 1, 2]));
        assert_eq!(stand_in_for(&user_data(&g)), Some(g));
        assert_eq!(stand_in_for(b"other"), None);
        assert_eq!(stand_in_for(&user_data(&g)[..20]), None);
    }
}
