//! What a writer gives a reader of its own participant matched for intra-process delivery (see
//! `participant/local.rs`): no proxy, only its history when the reader joins late.

use std::time::Instant;

use super::history::CacheChange;
use super::Writer;
use crate::rtps::types::{Guid, SequenceNumber};

impl Writer {
    /// Whether a change written now needs its serialized form here: the writer has readers on the wire
    /// (proxies), or keeps its history for late joiners. Otherwise only intra-process readers get it.
    pub(crate) fn needs_bytes(&self) -> bool {
        self.durable() || !self.proxies.is_empty()
    }

    /// Calls `f` on every change a durable `reader` that joins now gets from this writer's history, in
    /// order: none unless the writer is durable; expired changes and those `reader`'s filter rejected are
    /// skipped.
    pub(crate) fn for_each_historical(
        &mut self,
        now: Instant,
        reader: &Guid,
        mut f: impl FnMut(&CacheChange),
    ) {
        if !self.durable() {
            return;
        }
        self.expire(now);
        self.history
            .range(SequenceNumber(1))
            .filter(|c| !c.rejected.contains(reader))
            .for_each(&mut f);
    }
}
