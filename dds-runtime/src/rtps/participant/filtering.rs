//! Writer-side content filtering at the participant's API: the filters of a writer's matched readers, and
//! writes that some of them rejected (see `writer::content_filter`).

use std::time::Instant;

use super::{timers, Participant};
use crate::rtps::api::{WriteChange, WriteError};
use crate::rtps::discovery::{ContentFilterProperty, ReaderData};
use crate::rtps::types::{EntityId, Guid, SequenceNumber};

/// The filter of a discovered reader that a writer of its topic can apply: class `DDSSQL`, on this topic.
pub(super) fn usable_filter(rd: &ReaderData) -> Option<ContentFilterProperty> {
    rd.content_filter
        .as_deref()
        .filter(|f| {
            f.filter_class_name == ContentFilterProperty::DDSSQL
                && f.related_topic_name == rd.topic_name
        })
        .cloned()
}

impl Participant {
    /// [`Participant::write`] of a change that the content filters of the `rejected` readers refused (as
    /// evaluated by the caller on the sample, see [`Participant::writer_reader_filters`]): the change goes
    /// to the other readers as DATA and to the rejecting reliable ones as GAP, now and on repair.
    /// Readers of this participant matched for intra-process delivery get it as an event; readers of peers
    /// matched over shared memory get it through the writer's channel (all of them: they filter it).
    pub fn write_filtered(
        &mut self,
        now: Instant,
        writer: EntityId,
        change: WriteChange,
        rejected: Vec<Guid>,
    ) -> Result<SequenceNumber, WriteError> {
        self.write_delivering(now, writer, change, rejected, false)
    }

    /// [`write_filtered`](Self::write_filtered); `loaned`: the sample is in a buffer of the writer's
    /// shared-memory channel (see `Participant::write_loaned`).
    pub(super) fn write_delivering(
        &mut self,
        now: Instant,
        writer: EntityId,
        change: WriteChange,
        rejected: Vec<Guid>,
        loaned: bool,
    ) -> Result<SequenceNumber, WriteError> {
        let shm = self.has_shm_readers(writer);
        if self.local_readers(writer).is_empty() && !shm {
            return self.write_wire(now, writer, change, rejected);
        }
        let (local, local_rejected) = (change.clone(), rejected.clone());
        let sn = self.write_wire(now, writer, change, rejected)?;
        if shm {
            self.deliver_shm(writer, sn, &local, loaned);
        }
        self.deliver_local(now, writer, sn, local, &local_rejected);
        Ok(sn)
    }

    /// Writes a change to the writer's history and its readers on the wire.
    pub(super) fn write_wire(
        &mut self,
        now: Instant,
        writer: EntityId,
        change: WriteChange,
        rejected: Vec<Guid>,
    ) -> Result<SequenceNumber, WriteError> {
        if !self.user_writers.contains(&writer) {
            return Err(WriteError::UnknownWriter(writer));
        }
        let Some(w) = self.writers.get_mut(&writer) else {
            return Err(WriteError::UnknownWriter(writer));
        };
        let events = &mut self.events;
        let r = if self.config.write_batch_delay.is_some() {
            self.out.hold(now, |out| {
                w.write_filtered(now, change, rejected, out, events)
            })
        } else {
            w.write_filtered(now, change, rejected, &mut self.out, events)
        };
        timers::lower_floor(&self.timer_floor, w.next_timeout());
        if r.is_ok() && self.own_leases.assert_writer(now, writer) {
            self.timers_changed();
        }
        r
    }

    /// A number that changes whenever a filter of the writer's matched readers appears, changes or goes
    /// (0 for unknown writers, and for writers none of whose matched readers ever announced a filter, which
    /// need no filtering): compare it before calling [`Participant::writer_reader_filters`] again.
    pub fn writer_filter_generation(&self, writer: EntityId) -> u64 {
        self.writers
            .get(&writer)
            .map_or(0, |w| w.filters.generation())
    }

    /// Changes the content filter a local reader announces (new expression parameters, typically) and
    /// announces it again in SEDP; matched writers, local and remote, learn it from the announcement.
    /// Unknown readers are ignored.
    pub fn set_reader_content_filter(
        &mut self,
        now: Instant,
        reader: EntityId,
        filter: Option<ContentFilterProperty>,
    ) {
        if !self.user_readers.contains(&reader) {
            return;
        }
        let guid = Guid::new(self.config.guid_prefix, reader);
        let Some(mut d) = self.known_readers.get(&guid).cloned() else {
            return;
        };
        d.content_filter = filter.map(Box::new);
        self.publish_endpoint(now, *d);
    }

    /// A matched reader announced again: the writer takes its (possibly changed) filter.
    pub(super) fn refresh_reader_filter(&mut self, id: EntityId, remote: Guid) {
        let filter = self
            .known_readers
            .get(&remote)
            .and_then(|d| usable_filter(d));
        if let Some(w) = self.writers.get_mut(&id) {
            w.filters.set(remote, filter);
        }
    }

    /// The DDSSQL content filters of the writer's matched readers, by reader.
    pub fn writer_reader_filters(&self, writer: EntityId) -> Vec<(Guid, ContentFilterProperty)> {
        self.writers
            .get(&writer)
            .map(|w| w.filters.iter().map(|(g, f)| (*g, f.clone())).collect())
            .unwrap_or_default()
    }
}
