//! Writer-side content filtering (RTPS 2.5 §8.7.3): what a writer knows of its matched readers' filters, and
//! which readers rejected a change. The writer never evaluates a filter itself (it holds serialized data
//! only): the layer that writes typed samples reads [`ReaderFilters`], evaluates each filter once per sample
//! and hands the readers that rejected it to `Writer::write_filtered`. Such a change goes to the other
//! readers as DATA and to a rejecting reliable reader as GAP, now and when it is repaired. Readers that
//! joined after the write have no verdict and get the DATA (and filter it themselves).
//!
//! A key-only change (dispose, unregister) is never filtered. A filter is on the data (DDS 1.4 §2.2.2.3.3),
//! and such a change has none: only the key. The reader must learn of the end of an instance whose earlier
//! samples passed its filter, and the writer does not track which reader got which instance. Readers that
//! filter themselves do the same (our reader applies its filter to samples with data only), so writer-side
//! filtering changes nothing a reader sees. It also keeps both wire forms of such a change alike: the
//! serialized key for most readers, and the key hash alone for Fast DDS readers
//! (`ReaderProxy::key_hash_only_disposes`). A reader that never had a sample of the instance may therefore
//! see its dispose (with our reader: a new instance, `NOT_ALIVE_DISPOSED`), as without writer-side filtering.

use std::collections::BTreeMap;

use crate::rtps::discovery::ContentFilterProperty;
use crate::rtps::messages::parameter::pid;
use crate::rtps::types::Guid;

/// The filters of a writer's matched readers, with a generation that changes whenever the set does.
#[derive(Debug, Default)]
pub(crate) struct ReaderFilters {
    by_reader: BTreeMap<Guid, ContentFilterProperty>,
    generation: u64,
}

impl ReaderFilters {
    /// Records (or forgets, with `None`) the filter of `reader`.
    pub(crate) fn set(&mut self, reader: Guid, filter: Option<ContentFilterProperty>) {
        let changed = match filter {
            Some(f) => self.by_reader.insert(reader, f.clone()).as_ref() != Some(&f),
            None => self.by_reader.remove(&reader).is_some(),
        };
        if changed {
            self.generation = self.generation.wrapping_add(1);
        }
    }

    /// Changes whenever a matched reader's filter appears, changes or goes; 0 until a first one appears
    /// (writers use that to skip filtering altogether).
    pub(crate) fn generation(&self) -> u64 {
        self.generation
    }

    /// The matched readers that announced a filter.
    pub(crate) fn iter(&self) -> impl Iterator<Item = (&Guid, &ContentFilterProperty)> {
        self.by_reader.iter()
    }

    /// PID_CONTENT_FILTER_INFO (§9.6.3.1) for a change evaluated against every filter here, `rejected` being
    /// the readers that refused it: the distinct filter signatures, and a bitmap with bit `i` (most
    /// significant first in each 32-bit word) set when filter `i` accepted the change. The whole parameter,
    /// little-endian, ready to append to the inline QoS; `None` without filters (or more than
    /// [`MAX_SIGNATURES`] of them: the parameter is optional).
    pub(crate) fn info(&self, rejected: &[Guid]) -> Option<Box<[u8]>> {
        let mut sigs: Vec<([u8; 16], bool)> = Vec::new();
        for (g, f) in &self.by_reader {
            let sig = f.signature();
            let passed = rejected.binary_search(g).is_err();
            if !sigs.iter().any(|(s, _)| *s == sig) {
                sigs.push((sig, passed));
            }
        }
        if sigs.is_empty() || sigs.len() > MAX_SIGNATURES {
            return None;
        }
        let words = sigs.len().div_ceil(32);
        let len = 4 + 4 * words + 4 + 16 * sigs.len();
        let mut out = Vec::with_capacity(4 + len);
        out.extend_from_slice(&pid::CONTENT_FILTER_INFO.to_le_bytes());
        out.extend_from_slice(&(len as u16).to_le_bytes());
        out.extend_from_slice(&(words as u32).to_le_bytes());
        for w in 0..words {
            let mut bits = 0u32;
            for (i, (_, passed)) in sigs.iter().enumerate().skip(32 * w).take(32) {
                if *passed {
                    bits |= 1 << (31 - (i % 32));
                }
            }
            out.extend_from_slice(&bits.to_le_bytes());
        }
        out.extend_from_slice(&(sigs.len() as u32).to_le_bytes());
        for (sig, _) in &sigs {
            out.extend_from_slice(sig);
        }
        Some(out.into_boxed_slice())
    }
}

/// Most filter signatures a change is marked with.
pub(crate) const MAX_SIGNATURES: usize = 32;

impl super::Writer {
    /// For a change some readers rejected: a GAP to each rejecting reliable reader, and the destinations of
    /// the others (one locator per reader, deduplicated). A reader sharing a locator with one that accepts
    /// also receives the DATA, and filters it itself.
    pub(super) fn send_rejections(
        &mut self,
        sn: crate::rtps::types::SequenceNumber,
        out: &mut crate::rtps::outbox::Outbox,
    ) -> Vec<crate::rtps::types::Locator> {
        use crate::rtps::types::SequenceNumberSet;
        let Some(c) = self.history.get(sn) else {
            return Vec::new();
        };
        let mut dest = Vec::new();
        for p in self.proxies.values() {
            if super::StandIn::excludes(&self.stand_in, &p.guid) {
                continue;
            }
            if c.rejected.binary_search(&p.guid).is_err() {
                dest.extend(p.destination().first().copied());
            } else if p.reliable {
                let gap = crate::rtps::messages::Submessage::Gap(crate::rtps::messages::Gap {
                    reader_id: p.guid.entity_id,
                    writer_id: self.guid.entity_id,
                    gap_start: sn,
                    gap_list: SequenceNumberSet::empty(sn.next()),
                });
                out.push(
                    p.destination(),
                    Some(p.guid.prefix),
                    crate::rtps::outbox::Ts::Any,
                    &gap,
                );
            }
        }
        dest.sort();
        dest.dedup();
        dest
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtps::messages::ParameterList;
    use crate::rtps::types::{EntityId, GuidPrefix};

    #[test]
    fn info_marks_each_distinct_filter_with_its_verdict() {
        let g = |i: u8| Guid::new(GuidPrefix([i; 12]), EntityId([0, 0, 1, 7]));
        let f = |e: &str| ContentFilterProperty::ddssql("T_f", "T", e, Vec::new());
        let mut rf = ReaderFilters::default();
        assert!(rf.info(&[]).is_none());
        rf.set(g(1), Some(f("x > 1")));
        rf.set(g(2), Some(f("x > 1")));
        rf.set(g(3), Some(f("x < 1")));
        let gen = rf.generation();
        rf.set(g(3), Some(f("x < 1")));
        assert_eq!(rf.generation(), gen, "the same filter again is no change");
        let info = rf.info(&[g(3)]).unwrap();
        let list = [&info[..], &[1, 0, 0, 0]].concat();
        let (pl, _) = ParameterList::parse(&list, true).unwrap();
        let v = pl.get(pid::CONTENT_FILTER_INFO).unwrap();
        assert_eq!(
            &v[..8],
            &[1, 0, 0, 0, 0, 0, 0, 0x80],
            "one word: filter 0 passed, 1 not"
        );
        assert_eq!(&v[8..12], &[2, 0, 0, 0]);
        assert_eq!(&v[12..28], &f("x > 1").signature());
        assert_eq!(&v[28..44], &f("x < 1").signature());
    }
}
