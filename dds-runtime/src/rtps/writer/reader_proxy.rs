//! What a writer knows about one matched reader (§8.4.7.5).

use std::collections::{BTreeMap, BTreeSet};
use std::time::Instant;

use crate::rtps::types::*;

/// Bounds on what one remote reader can make us remember.
pub(crate) const MAX_REQUESTED: usize = 4096;
pub(crate) const MAX_REQUESTED_FRAG_SAMPLES: usize = 64;

#[derive(Debug, Clone)]
pub struct ReaderProxy {
    pub guid: Guid,
    /// Where to send; the first is used.
    pub locators: Vec<Locator>,
    /// Reliable protocol with this reader (both sides reliable).
    pub reliable: bool,
    /// Every change below this is acknowledged.
    pub acked: SequenceNumber,
    /// Changes below this predate the match of a volatile reader: answered with GAP.
    pub floor: SequenceNumber,
    pub requested: BTreeSet<SequenceNumber>,
    pub requested_frags: BTreeMap<SequenceNumber, BTreeSet<u32>>,
    pub last_acknack: Option<i32>,
    pub last_nackfrag: Option<i32>,
    /// When to send requested repairs (and a heartbeat addressed to this reader).
    pub repair_due: Option<Instant>,
}

impl ReaderProxy {
    pub fn new(guid: Guid, locators: Vec<Locator>, reliable: bool) -> Self {
        ReaderProxy {
            guid,
            locators,
            reliable,
            acked: SequenceNumber(1),
            floor: SequenceNumber(1),
            requested: BTreeSet::new(),
            requested_frags: BTreeMap::new(),
            last_acknack: None,
            last_nackfrag: None,
            repair_due: None,
        }
    }

    pub fn destination(&self) -> &[Locator] {
        &self.locators[..self.locators.len().min(1)]
    }
}
