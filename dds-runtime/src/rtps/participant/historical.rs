//! Queries for the durability service and `wait_for_historical_data`, and what a durability stand-in
//! leaves to the original writer.

use super::Participant;
use crate::rtps::discovery::matching::{match_endpoints_with, MatchResult};
use crate::rtps::discovery::ReaderData;
use crate::rtps::types::EntityId;
use crate::xtypes::assign::{local_types, TypeResolver};
use crate::xtypes::typeobject::TypeIdentifier;

impl Participant {
    /// Whether the local reader `reader` received everything its matched reliable writers announced so far
    /// (see the DCPS `DataReader::wait_for_historical_data`). `true` for a reader without matched writers,
    /// `false` for an unknown reader.
    pub fn reader_caught_up(&self, reader: EntityId) -> bool {
        self.readers.get(&reader).is_some_and(|r| r.caught_up())
    }

    /// Whether the local writer `writer` is a durability stand-in whose original writer is alive and
    /// matches the reader `rd`: the original then serves that reader its history and every change it
    /// writes, so the stand-in sends it GAPs only (`ReaderProxy::suppressed`). Another vendor's reader
    /// cannot tell the stand-in's repeat from a new sample, so without this a TRANSIENT_LOCAL reader
    /// joining while the original lives would get each change twice.
    ///
    /// Decided once, at matching, and kept: the changes a stand-in republishes after its original went
    /// are the original's last ones, which such a reader already had from it. A reader that matches after
    /// the original went gets everything from the stand-in.
    pub(super) fn original_serves(&self, writer: EntityId, rd: &ReaderData) -> bool {
        let Some(original) = self.writers.get(&writer).and_then(|w| w.stands_in_for) else {
            return false;
        };
        let Some(od) = self.known_writers.get(&original) else {
            return false;
        };
        let store = self.type_store();
        let types = |id: &TypeIdentifier| store.get(id).or_else(|| local_types().resolve(id));
        matches!(match_endpoints_with(od, rd, &types), MatchResult::Match)
    }
}
