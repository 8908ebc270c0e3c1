//! Reassembly of DATA_FRAG samples. Memory is what was received, never what a sender claims.

use std::collections::BTreeMap;

use crate::rtps::api::Payload;
use crate::rtps::types::SequenceNumber;

/// What one stored fragment costs beyond its bytes (map node, vector header), charged against the limits so
/// that tiny fragments cannot make us hold far more memory than their payload suggests.
pub(super) const FRAGMENT_OVERHEAD: usize = 64;

/// One sample being reassembled.
#[derive(Debug)]
pub(crate) struct Defrag {
    pub sample_size: u32,
    pub fragment_size: u16,
    /// Fragments received, by 1-based number.
    frags: BTreeMap<u32, Vec<u8>>,
    pub bytes: usize,
    /// Inline QoS of the first fragment seen: (status info, key hash).
    pub status_info: Option<u8>,
    pub key_hash: Option<[u8; 16]>,
    pub key_flag: bool,
    /// `PID_COHERENT_SET` of the sample, if it is in a coherent set.
    pub coherent_set: Option<SequenceNumber>,
    /// Source timestamp in force for the first fragment that carried one.
    pub source_timestamp: Option<crate::rtps::types::Time>,
}

impl Defrag {
    pub(crate) fn new(sample_size: u32, fragment_size: u16) -> Self {
        Defrag {
            sample_size,
            fragment_size,
            frags: BTreeMap::new(),
            bytes: 0,
            status_info: None,
            key_hash: None,
            key_flag: false,
            coherent_set: None,
            source_timestamp: None,
        }
    }

    pub(crate) fn total(&self) -> u32 {
        self.sample_size.div_ceil(self.fragment_size as u32)
    }

    /// Adds fragment `num` (its bytes); returns the memory newly held (bytes plus overhead). Inconsistent
    /// fragments are ignored.
    pub(crate) fn add(&mut self, num: u32, data: &[u8]) -> usize {
        if num == 0 || num > self.total() || self.frags.contains_key(&num) {
            return 0;
        }
        let start = (num as u64 - 1) * self.fragment_size as u64;
        let expect = (self.sample_size as u64 - start).min(self.fragment_size as u64) as usize;
        if data.len() != expect {
            return 0;
        }
        self.frags.insert(num, data.to_vec());
        let cost = data.len() + FRAGMENT_OVERHEAD;
        self.bytes += cost;
        cost
    }

    pub(crate) fn is_complete(&self) -> bool {
        self.frags.len() as u64 == self.total() as u64
    }

    /// The missing fragment numbers up to `last` (at most 256, from the first missing one).
    pub(crate) fn missing(&self, last: u32) -> Vec<u32> {
        let last = last.min(self.total());
        let mut v = Vec::new();
        let mut n = 1;
        while n <= last && v.len() < 256 {
            if !self.frags.contains_key(&n) {
                if let Some(&first) = v.first() {
                    if n - first >= 256 {
                        break;
                    }
                }
                v.push(n);
            }
            n += 1;
        }
        v
    }

    /// Concatenates the fragments (only call when complete).
    pub(crate) fn assemble(self) -> Payload {
        let mut v = Vec::with_capacity(self.sample_size as usize);
        for f in self.frags.into_values() {
            v.extend_from_slice(&f);
        }
        Payload::from(v)
    }
}
