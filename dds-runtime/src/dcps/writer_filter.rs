//! Writer-side content filtering for a typed writer: the compiled filters of its matched readers (refreshed
//! when the core reports a change in them), evaluated once per sample inside the core lock, so that the core
//! skips the readers that reject the sample (`Participant::write_filtered`).

use crate::filter::{ContentFilter, FilterFields};
use crate::rtps::{EntityId, Guid, Participant};

/// The compiled filters of one writer's matched readers.
#[derive(Debug, Default)]
pub(crate) struct WriterFilters {
    /// The core's filter generation these were compiled at (`None`: never).
    generation: Option<u64>,
    /// Readers with a filter this writer can evaluate (one that does not compile is not applied here; its
    /// reader still filters what arrives).
    readers: Vec<(Guid, ContentFilter)>,
}

impl WriterFilters {
    /// The matched readers whose filter rejects `sample` (no allocation while none does); `generation` is
    /// the core's filter generation of `writer` (`Participant::writer_filter_generation`).
    pub(crate) fn rejected<T: FilterFields>(
        &mut self,
        core: &Participant,
        writer: EntityId,
        generation: u64,
        sample: &T,
    ) -> Vec<Guid> {
        if self.generation != Some(generation) {
            self.generation = Some(generation);
            self.readers = core
                .writer_reader_filters(writer)
                .into_iter()
                .filter_map(|(g, f)| {
                    match ContentFilter::new(&f.filter_expression, &f.expression_parameters) {
                        Ok(c) => Some((g, c)),
                        Err(e) => {
                            tracing::debug!(reader = ?g, error = %e, "reader's filter not applied by the writer");
                            None
                        }
                    }
                })
                .collect();
        }
        self.readers
            .iter()
            .filter(|(_, f)| !f.matches(sample))
            .map(|(g, _)| *g)
            .collect()
    }
}
