//! Queries for the durability service and `wait_for_historical_data`.

use super::Participant;
use crate::rtps::types::EntityId;

impl Participant {
    /// Whether the local reader `reader` received everything its matched reliable writers announced so far
    /// (see the DCPS `DataReader::wait_for_historical_data`). `true` for a reader without matched writers,
    /// `false` for an unknown reader.
    pub fn reader_caught_up(&self, reader: EntityId) -> bool {
        self.readers.get(&reader).is_some_and(|r| r.caught_up())
    }
}
