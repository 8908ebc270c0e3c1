//! What a reader knows about one matched writer (§8.4.10.4): ordering, gaps, fragments, acknowledgement.

use std::collections::BTreeMap;
use std::time::Instant;

use super::coherent::{Assembler, SetMark};
use super::defrag::Defrag;
use crate::rtps::api::{ChangeKind, Payload};
use crate::rtps::types::*;

/// A received change waiting for its turn (or an irrelevant sequence number from a GAP).
#[derive(Debug, Clone)]
pub(crate) enum Slot {
    Change(PendingChange),
    Irrelevant,
}

#[derive(Debug, Clone)]
pub(crate) struct PendingChange {
    pub kind: ChangeKind,
    pub payload: Payload,
    pub key_hash: Option<[u8; 16]>,
    pub source_timestamp: Option<Time>,
    /// Membership in a coherent set (`PID_COHERENT_SET`).
    pub coherent: Option<SetMark>,
}

#[derive(Debug)]
pub(crate) struct WriterProxy {
    pub guid: Guid,
    pub locators: Vec<Locator>,
    /// Reliable protocol with this writer (both sides reliable).
    pub reliable: bool,
    /// Every sequence number below this was delivered or skipped.
    pub next_expected: SequenceNumber,
    /// Something (data, gap or heartbeat) was received from this writer.
    pub synced: bool,
    pub reorder: BTreeMap<SequenceNumber, Slot>,
    /// Payload bytes held in `reorder`.
    pub reorder_bytes: usize,
    pub hb_last: SequenceNumber,
    pub last_hb_count: Option<i32>,
    pub last_hbfrag_count: Option<i32>,
    pub acknack_due: Option<Instant>,
    /// Partly received samples a HEARTBEAT_FRAG asked about: sequence number -> last fragment the writer
    /// has. Answered with NACK_FRAG at `nackfrag_due` (bounded: samples held in `defrag`, at most
    /// `defrag_max_samples`).
    pub nackfrag_req: BTreeMap<SequenceNumber, u32>,
    pub nackfrag_due: Option<Instant>,
    pub acknack_count: i32,
    pub nackfrag_count: i32,
    pub defrag: BTreeMap<SequenceNumber, Defrag>,
    pub defrag_bytes: usize,
    /// The writer's coherent set being assembled.
    pub coherent: Assembler,
}

impl WriterProxy {
    pub(crate) fn new(guid: Guid, locators: Vec<Locator>, reliable: bool) -> Self {
        WriterProxy {
            guid,
            locators,
            reliable,
            next_expected: SequenceNumber(1),
            synced: false,
            reorder: BTreeMap::new(),
            reorder_bytes: 0,
            hb_last: SequenceNumber(0),
            last_hb_count: None,
            last_hbfrag_count: None,
            acknack_due: None,
            nackfrag_req: BTreeMap::new(),
            nackfrag_due: None,
            acknack_count: 0,
            nackfrag_count: 0,
            defrag: BTreeMap::new(),
            defrag_bytes: 0,
            coherent: Assembler::default(),
        }
    }

    pub(crate) fn destination(&self) -> &[Locator] {
        &self.locators[..self.locators.len().min(1)]
    }

    /// Drops defragmentation state below `next_expected`.
    pub(crate) fn drop_stale_defrag(&mut self) {
        let keep = self.defrag.split_off(&self.next_expected);
        for d in self.defrag.values() {
            self.defrag_bytes -= d.bytes;
        }
        self.defrag = keep;
    }

    pub(crate) fn has(&self, sn: SequenceNumber) -> bool {
        sn < self.next_expected || self.reorder.contains_key(&sn)
    }
}
