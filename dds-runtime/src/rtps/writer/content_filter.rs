//! Writer-side content filtering (RTPS 2.5 §8.7.3): what a writer knows of its matched readers' filters, and
//! which readers rejected a change. The writer never evaluates a filter itself (it holds serialized data
//! only): the layer that writes typed samples reads [`ReaderFilters`], evaluates each filter once per sample
//! and hands the readers that rejected it to `Writer::write_filtered`. Such a change goes to the other
//! readers as DATA and to a rejecting reliable reader as GAP, now and when it is repaired. Readers that
//! joined after the write have no verdict and get the DATA (and filter it themselves).

use std::collections::BTreeMap;

use crate::rtps::discovery::ContentFilterProperty;
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

    /// Changes whenever a matched reader's filter appears, changes or goes.
    pub(crate) fn generation(&self) -> u64 {
        self.generation
    }

    /// The matched readers that announced a filter.
    pub(crate) fn iter(&self) -> impl Iterator<Item = (&Guid, &ContentFilterProperty)> {
        self.by_reader.iter()
    }
}

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
