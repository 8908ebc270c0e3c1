//! SEDP topic announcements in the participant (see [`crate::rtps::discovery::topics`]): our topics
//! announced on the builtin topics writer, remote ones read from the topics reader and reported as
//! [`Event::TopicDiscovered`] / [`Event::TopicRemoved`].

use std::time::Instant;

use tracing::{debug, trace};

use super::Participant;
use crate::rtps::api::{ChangeKind, CoreError, Event, ReceivedSample};
use crate::rtps::discovery::topics::{
    TopicData, TOPIC_ENTITY_KIND, TOPIC_READER_PAIR, TOPIC_WRITER_PAIR,
};
use crate::rtps::reader::WriterProxy;
use crate::rtps::types::{EntityId, Guid, GuidPrefix, Locator};
use crate::rtps::writer::ReaderProxy;

/// Most remote topics remembered, so that discovery traffic cannot exhaust memory.
const MAX_TOPICS: usize = 16384;

impl Participant {
    /// Announces a local topic in SEDP (DCPSTopic); returns the topic's GUID (for
    /// [`Participant::withdraw_topic`]).
    pub fn announce_topic(
        &mut self,
        now: Instant,
        topic_name: &str,
        type_name: &str,
        topic_data: Vec<u8>,
    ) -> Result<Guid, CoreError> {
        if topic_name.is_empty() || type_name.is_empty() {
            return Err(CoreError::BadParameter("empty topic or type name"));
        }
        let guid = Guid::new(
            self.config.guid_prefix,
            self.alloc_entity(TOPIC_ENTITY_KIND)?,
        );
        let d = TopicData {
            guid,
            topic_name: topic_name.to_string(),
            type_name: type_name.to_string(),
            topic_data,
        };
        self.announce(
            now,
            EntityId::SEDP_TOPICS_WRITER,
            guid,
            ChangeKind::Alive,
            d.encode(),
        );
        self.timers_changed();
        Ok(guid)
    }

    /// Withdraws a topic announced by [`Participant::announce_topic`] (an SEDP dispose).
    pub fn withdraw_topic(&mut self, now: Instant, guid: Guid) {
        self.announce(
            now,
            EntityId::SEDP_TOPICS_WRITER,
            guid,
            ChangeKind::DisposeUnregister,
            Vec::new(),
        );
        self.timers_changed();
    }

    /// The remote topics announced in SEDP.
    pub fn discovered_topic_announcements(&self) -> impl Iterator<Item = &TopicData> {
        self.known_topics.values()
    }

    /// Creates the builtin topics writer and reader.
    pub(super) fn add_topic_builtins(&mut self) {
        let prefix = self.config.guid_prefix;
        let wp = super::builtin_writer_params(&self.config);
        self.writers.insert(
            TOPIC_WRITER_PAIR.0,
            crate::rtps::writer::Writer::new(Guid::new(prefix, TOPIC_WRITER_PAIR.0), wp),
        );
        let rp = super::reader_params(&self.config, true);
        self.readers.insert(
            TOPIC_READER_PAIR.0,
            crate::rtps::reader::Reader::new(Guid::new(prefix, TOPIC_READER_PAIR.0), rp),
        );
    }

    /// A participant announcing the builtin-endpoint-set `bits` at `meta` (with `group` last when there is
    /// one) was discovered: pairs our topic endpoints with its own.
    pub(super) fn match_topic_builtins(
        &mut self,
        now: Instant,
        prefix: GuidPrefix,
        bits: u32,
        meta: &std::sync::Arc<[Locator]>,
        group: Option<Locator>,
    ) {
        let (ours, theirs, bit) = TOPIC_WRITER_PAIR;
        if bits & bit != 0 {
            if let Some(w) = self.writers.get_mut(&ours) {
                let proxy = ReaderProxy::new(Guid::new(prefix, theirs), meta.clone(), true)
                    .with_multicast_last(group.is_some());
                w.add_proxy(now, proxy, true, &mut self.events);
            }
        }
        let (ours, theirs, bit) = TOPIC_READER_PAIR;
        if bits & bit != 0 {
            if let Some(r) = self.readers.get_mut(&ours) {
                r.add_proxy(
                    now,
                    WriterProxy::new(Guid::new(prefix, theirs), meta.clone(), true),
                );
                self.readers_by_writer.clear();
            }
        }
    }

    /// A participant left: its topic endpoints and topics go.
    pub(super) fn forget_topics_of(&mut self, prefix: GuidPrefix) {
        let (ours, theirs, _) = TOPIC_WRITER_PAIR;
        if let Some(w) = self.writers.get_mut(&ours) {
            w.remove_proxy(&Guid::new(prefix, theirs), &mut self.events);
        }
        let (ours, theirs, _) = TOPIC_READER_PAIR;
        if let Some(r) = self.readers.get_mut(&ours) {
            r.remove_proxy(&Guid::new(prefix, theirs));
        }
        let gone: Vec<Guid> = self
            .known_topics
            .keys()
            .filter(|g| g.prefix == prefix)
            .copied()
            .collect();
        for guid in gone {
            self.known_topics.remove(&guid);
            self.events.push_back(Event::TopicRemoved { guid });
        }
    }

    /// A sample of the SEDP topics reader: a topic announced, changed or withdrawn.
    pub(super) fn on_sedp_topic(&mut self, s: &ReceivedSample) {
        if s.kind != ChangeKind::Alive {
            let guid = s
                .key_hash
                .map(Guid::from_bytes)
                .or_else(|| crate::rtps::discovery::endpoint_guid_of(&s.payload));
            if let Some(g) = guid.filter(|g| g.prefix == s.writer.prefix) {
                if self.known_topics.remove(&g).is_some() {
                    self.events.push_back(Event::TopicRemoved { guid: g });
                }
            }
            return;
        }
        match TopicData::decode(&s.payload) {
            Ok(d) if self.ignored.endpoint(&d.guid, &d.topic_name) => {
                trace!(topic = %d.topic_name, "ignored SEDP topic dropped");
            }
            Ok(d) if d.guid.prefix == s.writer.prefix => {
                let new = !self.known_topics.contains_key(&d.guid);
                if (new && self.known_topics.len() >= MAX_TOPICS)
                    || self.known_topics.get(&d.guid) == Some(&d)
                {
                    return;
                }
                self.known_topics.insert(d.guid, d.clone());
                self.events.push_back(Event::TopicDiscovered(Box::new(d)));
            }
            Ok(_) => debug!("SEDP topic for another participant ignored"),
            Err(e) => debug!(error = %e, "dropping SEDP topic announcement"),
        }
    }
}
