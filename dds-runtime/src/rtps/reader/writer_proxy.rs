//! What a reader knows about one matched writer (§8.4.10.4): ordering, gaps, fragments, acknowledgement.
//!
//! Slim by design: a participant keeps one proxy per remote builtin writer of every discovered participant
//! (see `docs/performance.md`, "Footprint"), and most of them never see a change out of order or in
//! fragments. What only those need (the reorder buffer, reassembly, NACK_FRAG state) is in a [`Backlog`]
//! allocated the first time it is needed, and the locators are shared with the participant's other proxies.

use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

use super::coherent::Assembler;
use super::defrag::Defrag;
use super::reorder::{Reorder, Slot};
use crate::rtps::types::*;

#[derive(Debug)]
pub(crate) struct WriterProxy {
    pub guid: Guid,
    /// Shared with the other proxies made from the same announcement (one list per remote participant for
    /// its builtin writers).
    pub locators: Arc<[Locator]>,
    /// Reliable protocol with this writer (both sides reliable).
    pub reliable: bool,
    /// Something (data, gap or heartbeat) was received from this writer.
    pub synced: bool,
    /// Every sequence number below this was delivered or skipped.
    pub next_expected: SequenceNumber,
    pub hb_last: SequenceNumber,
    pub last_hb_count: Option<i32>,
    pub acknack_due: Option<Instant>,
    /// The next ACKNACK asks for an answer even when nothing is missing (GROUP ordering waits to hear).
    pub want_heartbeat: bool,
    pub acknack_count: i32,
    /// Changes held out of order, fragments and a coherent set being assembled: `None` until the first
    /// one arrives.
    backlog: Option<Box<Backlog>>,
}

/// The part of a [`WriterProxy`] only used once changes arrive out of order, in fragments or in a coherent
/// set.
#[derive(Debug, Default)]
pub(crate) struct Backlog {
    /// The writer's coherent set being assembled.
    pub coherent: Assembler,
    /// Changes held out of order.
    pub reorder: Reorder,
    pub last_hbfrag_count: Option<i32>,
    /// Partly received samples a HEARTBEAT_FRAG asked about: sequence number -> last fragment the writer
    /// has. Answered with NACK_FRAG at `nackfrag_due` (bounded: samples held in `defrag`, at most
    /// `defrag_max_samples`).
    pub nackfrag_req: BTreeMap<SequenceNumber, u32>,
    pub nackfrag_due: Option<Instant>,
    pub nackfrag_count: i32,
    pub defrag: BTreeMap<SequenceNumber, Defrag>,
    pub defrag_bytes: usize,
}

impl WriterProxy {
    pub(crate) fn new(guid: Guid, locators: impl Into<Arc<[Locator]>>, reliable: bool) -> Self {
        WriterProxy {
            guid,
            locators: locators.into(),
            reliable,
            synced: false,
            next_expected: SequenceNumber(1),
            hb_last: SequenceNumber(0),
            last_hb_count: None,
            acknack_due: None,
            want_heartbeat: false,
            acknack_count: 0,
            backlog: None,
        }
    }

    pub(crate) fn destination(&self) -> &[Locator] {
        &self.locators[..self.locators.len().min(1)]
    }

    /// The backlog, if anything ever needed one.
    pub(crate) fn backlog(&self) -> Option<&Backlog> {
        self.backlog.as_deref()
    }

    /// The backlog for changes, if anything ever needed one.
    pub(crate) fn backlog_if_used_mut(&mut self) -> Option<&mut Backlog> {
        self.backlog.as_deref_mut()
    }

    /// The backlog, made on first use.
    pub(crate) fn backlog_mut(&mut self) -> &mut Backlog {
        self.backlog.get_or_insert_with(Box::default)
    }

    /// Periodic: gives back the reorder room of a backlog idle for a while ([`Reorder::trim_idle`]).
    pub(crate) fn trim_idle(&mut self) {
        if let Some(b) = self.backlog.as_deref_mut() {
            b.reorder.trim_idle();
        }
    }

    /// Whether a coherent set is being assembled.
    pub(crate) fn coherent_open(&self) -> bool {
        self.backlog().is_some_and(|b| b.coherent.is_open())
    }

    /// Changes held out of order.
    pub(crate) fn held(&self) -> usize {
        self.backlog().map_or(0, |b| b.reorder.len())
    }

    /// Payload bytes held out of order.
    pub(crate) fn held_bytes(&self) -> usize {
        self.backlog().map_or(0, |b| b.reorder.bytes())
    }

    /// Holds `slot` for `sn` until its turn (its payload copied out of the datagram it arrived in).
    pub(crate) fn hold(&mut self, sn: SequenceNumber, slot: Slot) {
        self.backlog_mut().reorder.hold(sn, slot);
    }

    /// Marks `sn` irrelevant unless something is held for it already.
    pub(crate) fn hold_irrelevant(&mut self, sn: SequenceNumber) {
        self.backlog_mut().reorder.hold_irrelevant(sn);
    }

    /// Takes the first held change when `take(sn, slot)` says so.
    pub(crate) fn take_first_if(
        &mut self,
        take: impl FnOnce(SequenceNumber, &Slot) -> bool,
    ) -> Option<(SequenceNumber, Slot)> {
        let b = self.backlog.as_deref_mut()?;
        let (sn, slot) = b.reorder.first()?;
        if !take(sn, slot) {
            return None;
        }
        b.reorder.pop_first()
    }

    /// The time the next NACK_FRAG answering a HEARTBEAT_FRAG is due.
    pub(crate) fn nackfrag_due(&self) -> Option<Instant> {
        self.backlog().and_then(|b| b.nackfrag_due)
    }

    /// Drops defragmentation state below `next_expected`.
    pub(crate) fn drop_stale_defrag(&mut self) {
        let next = self.next_expected;
        let Some(b) = self.backlog.as_deref_mut() else {
            return;
        };
        let keep = b.defrag.split_off(&next);
        for d in b.defrag.values() {
            b.defrag_bytes -= d.bytes;
        }
        b.defrag = keep;
    }

    /// Whether `sn` was delivered, skipped or is held (whole).
    pub(crate) fn has(&self, sn: SequenceNumber) -> bool {
        sn < self.next_expected || self.backlog().is_some_and(|b| b.reorder.contains(sn))
    }

    /// Whether `sn` is held whole or partly (fragments).
    pub(crate) fn holds_any_of(&self, sn: SequenceNumber) -> bool {
        self.backlog()
            .is_some_and(|b| b.reorder.contains(sn) || b.defrag.contains_key(&sn))
    }
}

impl crate::rtps::proxy_map::Keyed for WriterProxy {
    fn key(&self) -> &Guid {
        &self.guid
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One proxy per remote builtin writer of every discovered participant (see `docs/performance.md`,
    /// "Footprint"): 136 bytes on x86-64 before the coherent-set assembler held its limits in 32 bits and
    /// stopped keeping the closing marker's group set; 104 (a 112-byte allocation) before the assembler
    /// moved into the backlog, its limits into the open set.
    #[test]
    #[cfg(target_pointer_width = "64")]
    fn proxy_stays_small() {
        assert_eq!(std::mem::size_of::<Assembler>(), 8);
        assert_eq!(std::mem::size_of::<WriterProxy>(), 88);
    }
}
