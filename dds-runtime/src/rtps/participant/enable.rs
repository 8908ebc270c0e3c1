//! Disabled entities (DDS 1.4 §2.2.2.1.1.7, ENTITY_FACTORY.autoenable_created_entities): a participant that
//! neither sends nor receives until enabled, and local readers and writers that exist (their entity ids
//! are allocated) but are neither announced in SEDP nor matched until enabled.

use std::time::Instant;

use foldhash::HashMap;

use super::Participant;
use crate::qos::{ReaderQos, WriterQos};
use crate::rtps::api::{CoreError, ReaderSpec, WriterSpec};
use crate::rtps::discovery::{ReaderData, WriterData};
use crate::rtps::reader::Reader;
use crate::rtps::types::{entity_kind, EntityId};

/// A local endpoint created disabled: what it will announce once enabled.
#[derive(Debug)]
pub(super) enum Deferred {
    Writer(WriterData),
    Reader(ReaderData),
}

/// The local endpoints created disabled, by entity id.
pub(super) type DeferredEndpoints = HashMap<EntityId, Deferred>;

impl Participant {
    /// Whether the participant is enabled (sends and receives). A participant starts enabled.
    pub fn is_enabled(&self) -> bool {
        self.enabled
    }

    /// Disables (`false`) or enables the participant. A disabled participant drops what it received and
    /// sends nothing (what was queued is discarded: a participant created disabled announces nothing);
    /// enabling it sends its SPDP announcement at once.
    pub fn set_enabled(&mut self, now: Instant, enabled: bool) {
        self.timers_changed();
        self.enabled = enabled;
        if enabled {
            self.spdp_due = now;
            self.pmd_due = now;
            self.service(now);
        } else {
            while let Some(t) = self.poll_transmit(now) {
                self.recycle_transmit(t);
            }
        }
    }

    /// Creates a local writer as [`Participant::create_writer`] does, but disabled: not announced and not
    /// matched until [`Participant::enable_endpoint`].
    pub fn create_writer_disabled(
        &mut self,
        _now: Instant,
        spec: WriterSpec,
    ) -> Result<EntityId, CoreError> {
        let data = self.add_writer(spec)?;
        let id = data.guid.entity_id;
        self.deferred.insert(id, Deferred::Writer(data));
        Ok(id)
    }

    /// Creates a local reader as [`Participant::create_reader`] does, but disabled: not announced and not
    /// matched until [`Participant::enable_endpoint`].
    pub fn create_reader_disabled(
        &mut self,
        _now: Instant,
        spec: ReaderSpec,
    ) -> Result<EntityId, CoreError> {
        let data = self.add_reader(spec)?;
        let id = data.guid.entity_id;
        self.deferred.insert(id, Deferred::Reader(data));
        Ok(id)
    }

    /// Enables a reader or writer created disabled: announces it in SEDP and matches it. Nothing for an
    /// endpoint that is enabled already or unknown.
    pub fn enable_endpoint(&mut self, now: Instant, id: EntityId) {
        match self.deferred.remove(&id) {
            Some(Deferred::Writer(d)) => {
                // A writer's liveliness lease starts when it becomes visible.
                self.track_own_lease(now, id, &d.qos.writer.liveliness);
                self.publish_endpoint(now, d);
            }
            Some(Deferred::Reader(d)) => self.publish_endpoint(now, d),
            None => {}
        }
    }

    /// A disabled writer's new QoS is kept for its announcement (`None`); `Some(qos)` back for others.
    pub(super) fn update_deferred_writer(
        &mut self,
        id: EntityId,
        qos: WriterQos,
    ) -> Option<WriterQos> {
        match self.deferred.get_mut(&id) {
            Some(Deferred::Writer(d)) => {
                d.qos = qos.into();
                None
            }
            _ => Some(qos),
        }
    }

    /// A disabled reader's new QoS is kept for its announcement (`None`); `Some(qos)` back for others.
    pub(super) fn update_deferred_reader(
        &mut self,
        id: EntityId,
        qos: ReaderQos,
    ) -> Option<ReaderQos> {
        match self.deferred.get_mut(&id) {
            Some(Deferred::Reader(d)) => {
                d.qos = qos.into();
                None
            }
            _ => Some(qos),
        }
    }

    /// Replaces every policy of a disabled writer, immutable ones included (DDS 1.4 §2.2.2.1.1.7: they may
    /// change until the entity is enabled). Its protocol state takes the new QoS (history, limits,
    /// reliability, durability, lifespan; its group and coherent state stay); nothing was written or
    /// matched yet, so nothing is lost.
    /// `BadParameter` once the writer is enabled, `UnknownEntity` for no local writer.
    pub fn respecify_disabled_writer(
        &mut self,
        id: EntityId,
        qos: WriterQos,
    ) -> Result<(), CoreError> {
        self.timers_changed();
        let Some(Deferred::Writer(d)) = self.deferred.get_mut(&id) else {
            return Err(self.not_deferred(id));
        };
        let keyed = id.kind() == entity_kind::USER_WRITER_WITH_KEY;
        let params = super::user_writer_params(&self.config, &qos.writer, keyed);
        d.qos = qos.into();
        if let Some(w) = self.writers.get_mut(&id) {
            w.respecify(params);
        }
        Ok(())
    }

    /// [`Participant::respecify_disabled_writer`] for a reader (its reliability may change). A credit set
    /// with [`Participant::set_reader_credit`] must be set again.
    pub fn respecify_disabled_reader(
        &mut self,
        id: EntityId,
        qos: ReaderQos,
    ) -> Result<(), CoreError> {
        self.timers_changed();
        let Some(Deferred::Reader(d)) = self.deferred.get_mut(&id) else {
            return Err(self.not_deferred(id));
        };
        let params = super::reader_params(&self.config, qos.reader.reliability.is_reliable());
        d.qos = qos.into();
        self.readers.insert(id, Reader::new(d.guid, params));
        Ok(())
    }

    fn not_deferred(&self, id: EntityId) -> CoreError {
        if self.user_writers.contains(&id) || self.user_readers.contains(&id) {
            CoreError::BadParameter("the endpoint is enabled already")
        } else {
            CoreError::UnknownEntity(id)
        }
    }

    /// Forgets a disabled endpoint that is deleted (it was never announced). Whether it was one.
    pub(super) fn drop_deferred(&mut self, id: EntityId) -> bool {
        if self.deferred.remove(&id).is_none() {
            return false;
        }
        self.own_leases.untrack(id);
        self.writers.remove(&id);
        self.readers.remove(&id);
        self.user_writers.remove(&id);
        self.user_readers.remove(&id);
        true
    }
}
