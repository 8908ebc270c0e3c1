//! Coherent sets of user writers (RTPS 2.5 §8.7.6): the participant-level verbs DCPS's
//! `begin_coherent_changes`/`end_coherent_changes` drive. The protocol itself is in `writer/coherent.rs`
//! (sending) and `reader/coherent.rs` (assembling).

use std::time::Instant;

use super::enable::Deferred;
use super::{timers, Participant};
use crate::rtps::api::WriteError;
use crate::rtps::types::{entity_kind, EntityId, Guid, SequenceNumber};
use crate::rtps::writer::{Writer, WriterGroup};

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

    /// Makes a user writer a member of a publisher's group (GROUP access scope): from now on its changes
    /// carry `PID_GROUP_SEQ_NUM` from the group's counter, and while the group has a coherent set open
    /// ([`Participant::begin_group_set`]) `PID_GROUP_COHERENT_SET`; its end-of-set markers then carry
    /// `PID_WRITER_GROUP_INFO`, the digest of the writers of the set. Its heartbeats carry GroupInfo, and
    /// its SEDP announcement (sent again now when it was sent already) names the group
    /// (`PID_GROUP_ENTITYID`), so that readers can order the group's changes by group sequence number.
    pub fn join_writer_group(
        &mut self,
        now: Instant,
        writer: EntityId,
        group: &WriterGroup,
    ) -> Result<(), WriteError> {
        self.user_writer(writer)?;
        let fresh = match group.entity() {
            Some(_) => None,
            None => self.alloc_entity(entity_kind::USER_WRITER_GROUP).ok(),
        };
        let entity = group.join(writer, fresh);
        self.user_writer(writer)?.group = Some(group.clone());
        let Some(entity) = entity else {
            return Ok(());
        };
        let guid = Guid::new(self.config.guid_prefix, entity);
        if let Some(Deferred::Writer(d)) = self.deferred.get_mut(&writer) {
            d.group = Some(guid);
            return Ok(());
        }
        let me = Guid::new(self.config.guid_prefix, writer);
        if let Some(d) = self
            .known_writers
            .get(&me)
            .filter(|d| d.group != Some(guid))
        {
            let mut d = (**d).clone();
            d.group = Some(guid);
            self.timers_changed();
            self.publish_endpoint(now, d);
        }
        Ok(())
    }

    /// Opens a group coherent set: call before [`Participant::begin_coherent_set`] on its members. The
    /// set spans every member that writes before [`Participant::end_group_set`].
    pub fn begin_group_set(&mut self, group: &WriterGroup) {
        group.begin_set();
    }

    /// Closes the group coherent set, once every member's [`Participant::end_coherent_set`] succeeded.
    pub fn end_group_set(&mut self, group: &WriterGroup) {
        group.end_set();
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
