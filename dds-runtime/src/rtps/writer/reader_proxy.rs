//! What a writer knows about one matched reader (§8.4.7.5).

use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;
use std::time::Instant;

use crate::rtps::types::*;

/// Bounds on what one remote reader can make us remember.
pub(crate) const MAX_REQUESTED: usize = 4096;
pub(crate) const MAX_REQUESTED_FRAG_SAMPLES: usize = 64;

#[derive(Debug, Clone)]
pub(crate) struct ReaderProxy {
    pub guid: Guid,
    /// Where to send; the first is used. Shared with the other proxies made from the same announcement (one
    /// list per remote participant for its builtin readers).
    pub locators: Arc<[Locator]>,
    /// A multicast locator the reader listens on, when multicast user data is on (see
    /// `ParticipantConfig::multicast_data`).
    pub multicast: Option<Locator>,
    /// New data (and the periodic heartbeat) goes to `multicast` instead of `locators`: set by the writer
    /// when another matched reader shares that multicast locator.
    pub via_multicast: bool,
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
    /// Send dispose/unregister (key-only changes) as DATA with only inline QoS (PID_KEY_HASH,
    /// PID_STATUS_INFO) and no serialized key. Set for Fast DDS readers: Fast DDS 2.9 copies a key payload of
    /// up to 16 bytes straight into its instance handle, as if it were the key hash.
    pub key_hash_only_disposes: bool,
}

impl ReaderProxy {
    pub(crate) fn new(guid: Guid, locators: impl Into<Arc<[Locator]>>, reliable: bool) -> Self {
        ReaderProxy {
            guid,
            locators: locators.into(),
            multicast: None,
            via_multicast: false,
            reliable,
            acked: SequenceNumber(1),
            floor: SequenceNumber(1),
            requested: BTreeSet::new(),
            requested_frags: BTreeMap::new(),
            last_acknack: None,
            last_nackfrag: None,
            repair_due: None,
            key_hash_only_disposes: false,
        }
    }

    /// Adapts the wire form to what the reader's implementation (its participant's vendor) understands.
    pub(crate) fn for_vendor(mut self, vendor: VendorId) -> Self {
        self.key_hash_only_disposes = vendor == VendorId::FASTDDS;
        self
    }

    /// Where to send what is for this reader alone (repairs, GAPs): its first unicast locator.
    pub(crate) fn destination(&self) -> &[Locator] {
        &self.locators[..self.locators.len().min(1)]
    }

    /// Where new data for this reader goes: the shared multicast locator when the writer chose it, else
    /// [`destination`](Self::destination).
    pub(crate) fn data_destination(&self) -> Option<Locator> {
        match self.multicast {
            Some(m) if self.via_multicast => Some(m),
            _ => self.destination().first().copied(),
        }
    }

    /// Gives the reader a multicast locator it can be reached on (none: unicast only).
    pub(crate) fn with_multicast(mut self, multicast: Option<Locator>) -> Self {
        self.multicast = multicast;
        self
    }
}
