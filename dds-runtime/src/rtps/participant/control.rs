//! Application control over discovery (DDS `ignore_*`) and changes to what a local endpoint or the
//! participant announces (DDS `set_qos`): the changed announcement is sent again and every match re-evaluated.

use std::time::Instant;

use foldhash::{HashSet, HashSetExt};

use super::discovery::Direction;
use super::Participant;
use crate::qos::{ReaderQos, WriterQos};
use crate::rtps::api::CoreError;
use crate::rtps::types::*;

/// Most ignored participants, endpoints and topics (each), so the lists stay bounded.
const MAX_IGNORED: usize = 65536;

/// What the application asked the participant to ignore (DDS 1.4 §2.2.2.2.1.14–17). Ignoring cannot be
/// undone: the entity stays ignored until the participant is deleted.
#[derive(Debug, Default)]
pub(super) struct Ignored {
    participants: HashSet<GuidPrefix>,
    endpoints: HashSet<Guid>,
    topics: HashSet<String>,
}

impl Ignored {
    pub(super) fn new() -> Self {
        Ignored {
            participants: HashSet::new(),
            endpoints: HashSet::new(),
            topics: HashSet::new(),
        }
    }

    /// Whether SPDP data of this participant is dropped.
    pub(super) fn participant(&self, prefix: &GuidPrefix) -> bool {
        self.participants.contains(prefix)
    }

    /// Whether SEDP data of this endpoint (on `topic`) is dropped.
    pub(super) fn endpoint(&self, guid: &Guid, topic: &str) -> bool {
        self.participants.contains(&guid.prefix)
            || self.endpoints.contains(guid)
            || self.topics.contains(topic)
    }
}

fn full<T>(set: &HashSet<T>) -> Result<(), CoreError> {
    if set.len() >= MAX_IGNORED {
        Err(CoreError::BadParameter("too many ignored entities"))
    } else {
        Ok(())
    }
}

impl Participant {
    /// Ignores a remote participant: it is dropped now (unmatching its endpoints) and its SPDP and SEDP data
    /// are dropped from then on.
    pub fn ignore_participant(&mut self, prefix: GuidPrefix) -> Result<(), CoreError> {
        if prefix == self.config.guid_prefix {
            return Err(CoreError::BadParameter(
                "cannot ignore the local participant",
            ));
        }
        full(&self.ignored.participants)?;
        self.timers_changed();
        self.ignored.participants.insert(prefix);
        self.remove_participant(prefix);
        Ok(())
    }

    /// Ignores a remote publication or subscription: it is unmatched now and its SEDP data dropped from
    /// then on.
    pub fn ignore_endpoint(&mut self, guid: Guid) -> Result<(), CoreError> {
        if guid.prefix == self.config.guid_prefix {
            return Err(CoreError::BadParameter("cannot ignore a local endpoint"));
        }
        full(&self.ignored.endpoints)?;
        self.timers_changed();
        self.ignored.endpoints.insert(guid);
        self.drop_remote_endpoint(guid);
        Ok(())
    }

    /// Ignores every remote endpoint on topic `name`, now and from then on.
    pub fn ignore_topic(&mut self, name: &str) -> Result<(), CoreError> {
        full(&self.ignored.topics)?;
        self.timers_changed();
        self.ignored.topics.insert(name.to_string());
        let own = self.config.guid_prefix;
        let remote: Vec<Guid> = self
            .known_writers
            .values()
            .filter(|d| d.topic_name == name && d.guid.prefix != own)
            .map(|d| d.guid)
            .chain(
                self.known_readers
                    .values()
                    .filter(|d| d.topic_name == name && d.guid.prefix != own)
                    .map(|d| d.guid),
            )
            .collect();
        for g in remote {
            self.drop_remote_endpoint(g);
        }
        Ok(())
    }

    fn drop_remote_endpoint(&mut self, guid: Guid) {
        if self.known_writers.contains_key(&guid) {
            self.forget_endpoint::<WriterQos>(guid);
            self.events
                .push_back(crate::rtps::api::Event::PublicationRemoved { guid });
        }
        if self.known_readers.contains_key(&guid) {
            self.forget_endpoint::<ReaderQos>(guid);
            self.events
                .push_back(crate::rtps::api::Event::SubscriptionRemoved { guid });
        }
    }

    /// Replaces the QoS a local writer announces (the caller checked that only changeable policies
    /// differ): SEDP announces it again and matches are re-evaluated (a partition change may match or
    /// unmatch readers).
    pub fn update_writer_qos(
        &mut self,
        now: Instant,
        writer: EntityId,
        mut qos: WriterQos,
    ) -> Result<(), CoreError> {
        super::local::inherit(&mut qos.writer.ignore_local, self.config.ignore_local);
        let Some(qos) = self.update_deferred_writer(writer, qos) else {
            return Ok(());
        };
        self.update_endpoint_qos(now, writer, qos)
    }

    /// Replaces the QoS a local reader announces, like [`Participant::update_writer_qos`].
    pub fn update_reader_qos(
        &mut self,
        now: Instant,
        reader: EntityId,
        mut qos: ReaderQos,
    ) -> Result<(), CoreError> {
        super::local::inherit(&mut qos.reader.ignore_local, self.config.ignore_local);
        let Some(qos) = self.update_deferred_reader(reader, qos) else {
            return Ok(());
        };
        self.update_endpoint_qos(now, reader, qos)
    }

    fn update_endpoint_qos<Q: Direction>(
        &mut self,
        now: Instant,
        id: EntityId,
        qos: Q,
    ) -> Result<(), CoreError> {
        let guid = Guid::new(self.config.guid_prefix, id);
        let Some(mut d) = Q::known(self).get(&guid).cloned() else {
            return Err(CoreError::UnknownEntity(id));
        };
        self.timers_changed();
        d.qos = qos.into();
        self.publish_endpoint(now, *d);
        Ok(())
    }

    /// Replaces the USER_DATA announced in SPDP and announces the participant again at once.
    pub fn set_user_data(&mut self, user_data: Vec<u8>) {
        self.timers_changed();
        self.config = self.config.to_builder().user_data(user_data).build();
        self.spdp_payload = self.participant_data().encode();
        self.send_spdp(None);
    }
}

impl Participant {
    /// Every known publication, remote and local (DCPSPublication).
    pub fn publications(&self) -> impl Iterator<Item = &crate::rtps::discovery::WriterData> {
        self.known_writers.values().map(Box::as_ref)
    }

    /// Every known subscription, remote and local (DCPSSubscription).
    pub fn subscriptions(&self) -> impl Iterator<Item = &crate::rtps::discovery::ReaderData> {
        self.known_readers.values().map(Box::as_ref)
    }
}
