//! Coherent sets of user writers (RTPS 2.5 §8.7.6): the participant-level verbs DCPS's
//! `begin_coherent_changes`/`end_coherent_changes` drive. The protocol itself is in `writer/coherent.rs`
//! (sending) and `reader/coherent.rs` (assembling).

use std::time::Instant;

use super::{timers, Participant};
use crate::rtps::api::WriteError;
use crate::rtps::types::{EntityId, SequenceNumber};
use crate::rtps::writer::Writer;

impl Participant {
    /// Starts a coherent set on a user writer: every change it writes until
    /// [`Participant::end_coherent_set`] carries `PID_COHERENT_SET`, and readers deliver them all at once
    /// ([`crate::rtps::Event::CoherentSet`]) or not at all. Starting a set that is open does nothing.
    pub fn begin_coherent_set(&mut self, writer: EntityId) -> Result<(), WriteError> {
        self.user_writer(writer)?.begin_coherent();
        Ok(())
    }

    /// Ends the writer's coherent set: sends its end-of-set marker (a DATA without data carrying only
    /// `PID_COHERENT_SET`, with a sequence number of its own) when the set holds changes, and returns that
    /// number. `Err(WouldBlock)` as for [`Participant::write`]: the set stays open, call again. Ending when
    /// no set is open returns `Ok(None)`.
    pub fn end_coherent_set(
        &mut self,
        now: Instant,
        writer: EntityId,
    ) -> Result<Option<SequenceNumber>, WriteError> {
        self.user_writer(writer)?;
        // Found above; looked up again so that the outbox and the event queue can be borrowed beside it.
        let Some(w) = self.writers.get_mut(&writer) else {
            return Err(WriteError::UnknownWriter(writer));
        };
        let r = w.end_coherent(now, &mut self.out, &mut self.events);
        timers::lower_floor(&self.timer_floor, w.next_timeout());
        r
    }

    fn user_writer(&mut self, id: EntityId) -> Result<&mut Writer, WriteError> {
        if !self.user_writers.contains(&id) {
            return Err(WriteError::UnknownWriter(id));
        }
        self.writers
            .get_mut(&id)
            .ok_or(WriteError::UnknownWriter(id))
    }

    /// Whether the writer has a coherent set open.
    pub fn in_coherent_set(&self, writer: EntityId) -> bool {
        self.writers
            .get(&writer)
            .is_some_and(|w| w.in_coherent_set())
    }
}
