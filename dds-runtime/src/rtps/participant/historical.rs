//! Queries for the durability service and `wait_for_historical_data`, and the hold a durability stand-in
//! keeps on the readers its original writer serves (`rtps/writer/stand_in.rs`).

use super::Participant;
use crate::rtps::discovery::matching::{match_endpoints_with, MatchResult};
use crate::rtps::discovery::ReaderData;
use crate::rtps::types::{EntityId, Guid, VendorId};
use crate::rtps::writer::Served;
use crate::xtypes::assign::{local_types, TypeResolver};
use crate::xtypes::typeobject::TypeIdentifier;

impl Participant {
    /// Whether the local reader `reader` received everything its matched reliable writers announced so far
    /// (see the DCPS `DataReader::wait_for_historical_data`). `true` for a reader without matched writers,
    /// `false` for an unknown reader.
    pub fn reader_caught_up(&self, reader: EntityId) -> bool {
        self.readers.get(&reader).is_some_and(|r| r.caught_up())
    }

    /// Whether the local writer `writer`, about to match the reader `rd` of an implementation `vendor`, is
    /// to hold it: it is a durability stand-in, the reader is another vendor's (ours drop repeats
    /// themselves, by the stand-in's USER_DATA marker), and the original writer is alive (known, and not a
    /// local writer that lingers after its deletion) and matches the reader, so it serves it.
    pub(super) fn original_serves(
        &self,
        writer: EntityId,
        rd: &ReaderData,
        vendor: VendorId,
    ) -> bool {
        if vendor == VendorId::THIS {
            return false;
        }
        let Some(original) = self.writers.get(&writer).and_then(|w| w.original()) else {
            return false;
        };
        let Some(od) = self.known_writers.get(&original) else {
            return false;
        };
        if original.prefix == self.config.guid_prefix
            && self
                .writers
                .get(&original.entity_id)
                .is_none_or(|w| w.linger_until.is_some())
        {
            return false;
        }
        let store = self.type_store();
        let types = |id: &TypeIdentifier| store.get(id).or_else(|| local_types().resolve(id));
        matches!(match_endpoints_with(od, rd, &types), MatchResult::Match)
    }

    /// The writer `original` is going (a local writer being deleted, or a known remote one forgotten):
    /// its stand-ins release the readers they held, with what it served them. A local writer tells from its
    /// readers' acknowledgements; a remote one that left while its participant is still known left cleanly
    /// (it lingered for its acknowledgements: everything); one whose participant was lost may have served
    /// a held reader nothing, which then gets everything from the stand-in. Only the stand-ins are looked
    /// at (a peer with thousands of endpoints that leaves calls this once for each).
    pub(super) fn original_gone(&mut self, original: Guid) {
        let local = (original.prefix == self.config.guid_prefix)
            .then(|| self.writers.get(&original.entity_id))
            .flatten();
        let clean = original.prefix == self.config.guid_prefix
            || self.participants.contains_key(&original.prefix);
        let mut released = Vec::new();
        let writers = &self.writers;
        self.stand_ins.retain(|id| writers.contains_key(id));
        for (id, w) in self
            .stand_ins
            .iter()
            .filter_map(|id| Some((id, writers.get(id)?)))
        {
            if w.original() == Some(original) {
                for r in w.held() {
                    let served = match local {
                        Some(o) => o.served_to(&r),
                        None if clean => Served::All,
                        None => Served::Nothing,
                    };
                    released.push((*id, r, served));
                }
            }
        }
        if released.is_empty() {
            return;
        }
        for (id, r, served) in released {
            if let Some(w) = self.writers.get_mut(&id) {
                w.release(&r, served, &mut self.events);
            }
        }
        self.timers_changed();
    }
}
