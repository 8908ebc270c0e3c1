//! The built-in subscriber (`get_builtin_subscriber`, DDS 1.4 §2.2.5): its four readers, seeded with what
//! discovery knows when it is first asked for, then fed by the core's discovery events.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use super::builtin::{
    topic_key, ParticipantBuiltinTopicData, PublicationBuiltinTopicData,
    SubscriptionBuiltinTopicData, TopicBuiltinTopicData,
};
use super::builtin_reader::BuiltinDataReader;
use super::driver::{CoreObserver, Driver};
use super::sample::InstanceHandle;
use super::sync::lock;
use crate::rtps::discovery::{EndpointData, ParticipantData, TopicData};
use crate::rtps::{EntityId, Event, Guid, GuidPrefix};

/// The built-in subscriber of a participant: one reader per built-in topic. Cheap to clone; every call of
/// `get_builtin_subscriber` returns the same readers.
#[derive(Clone, Debug)]
pub struct BuiltinSubscriber {
    /// Our participant's prefix (local endpoints that are deleted leave as remote ones do).
    prefix: GuidPrefix,
    /// The DCPSTopic instance of each topic announced in SEDP, by the announcement's GUID.
    topic_guids: Arc<Mutex<HashMap<Guid, InstanceHandle>>>,
    participants: BuiltinDataReader<ParticipantBuiltinTopicData>,
    publications: BuiltinDataReader<PublicationBuiltinTopicData>,
    subscriptions: BuiltinDataReader<SubscriptionBuiltinTopicData>,
    topics: BuiltinDataReader<TopicBuiltinTopicData>,
}

impl BuiltinSubscriber {
    /// The `DCPSParticipant` reader: the participants discovered through SPDP, and this one.
    pub fn participant_reader(&self) -> BuiltinDataReader<ParticipantBuiltinTopicData> {
        self.participants.clone()
    }

    /// The `DCPSPublication` reader: the writers discovered through SEDP, and this participant's.
    pub fn publication_reader(&self) -> BuiltinDataReader<PublicationBuiltinTopicData> {
        self.publications.clone()
    }

    /// The `DCPSSubscription` reader: the readers discovered through SEDP, and this participant's.
    pub fn subscription_reader(&self) -> BuiltinDataReader<SubscriptionBuiltinTopicData> {
        self.subscriptions.clone()
    }

    /// The `DCPSTopic` reader: the topics of the readers and writers discovered (see docs/dcps-api.md).
    pub fn topic_reader(&self) -> BuiltinDataReader<TopicBuiltinTopicData> {
        self.topics.clone()
    }

    /// Creates the readers, seeds them from the core and subscribes them to its discovery events.
    pub(crate) fn start(driver: &Driver) -> Self {
        let s = BuiltinSubscriber {
            prefix: driver.guid_prefix,
            topic_guids: Arc::default(),
            participants: BuiltinDataReader::new("DCPSParticipant"),
            publications: BuiltinDataReader::new("DCPSPublication"),
            subscriptions: BuiltinDataReader::new("DCPSSubscription"),
            topics: BuiltinDataReader::new("DCPSTopic"),
        };
        // Events from now on; what came before is seeded below (a repeat is only an update).
        driver.add_observer(Arc::new(s.clone()));
        let (participants, writers, readers, topics) = driver.query_core(|c| {
            let mut ps: Vec<ParticipantData> = c.discovered_participants().cloned().collect();
            ps.push(c.participant_data());
            let ws: Vec<EndpointData<_>> = c.publications().cloned().collect();
            let rs: Vec<EndpointData<_>> = c.subscriptions().cloned().collect();
            let ts: Vec<TopicData> = c.discovered_topic_announcements().cloned().collect();
            (ps, ws, rs, ts)
        });
        for t in topics {
            s.on_event(&Event::TopicDiscovered(Box::new(t)));
        }
        for p in &participants {
            s.participant(p);
        }
        for w in &writers {
            s.publication(w);
        }
        for r in &readers {
            s.subscription(r);
        }
        s
    }

    fn participant(&self, p: &ParticipantData) {
        self.participants
            .upsert(participant_handle(p.guid_prefix), p.into());
    }

    fn publication(&self, w: &EndpointData<crate::qos::WriterQos>) {
        self.topic(&w.topic_name, &w.type_name, &w.qos.topic_data.0);
        self.publications
            .upsert(InstanceHandle::from_guid(w.guid), w.into());
    }

    fn subscription(&self, r: &EndpointData<crate::qos::ReaderQos>) {
        self.topic(&r.topic_name, &r.type_name, &r.qos.topic_data.0);
        self.subscriptions
            .upsert(InstanceHandle::from_guid(r.guid), r.into());
    }

    /// A topic seen for the first time becomes an instance of DCPSTopic (later endpoints change nothing).
    fn topic(&self, name: &str, type_name: &str, topic_data: &[u8]) {
        let key = topic_key(name, type_name);
        if !self.topics.has_alive_instance(key) {
            self.topics.upsert(
                key,
                TopicBuiltinTopicData::new(name, type_name, topic_data.to_vec()),
            );
        }
    }
}

fn participant_handle(p: GuidPrefix) -> InstanceHandle {
    InstanceHandle::from_guid(Guid::new(p, EntityId::PARTICIPANT))
}

impl CoreObserver for BuiltinSubscriber {
    fn on_event(&self, ev: &Event) {
        match ev {
            Event::ParticipantDiscovered(p) => self.participant(p),
            Event::ParticipantLost { guid_prefix } => {
                self.participants.dispose(participant_handle(*guid_prefix));
            }
            Event::PublicationDiscovered(w) => self.publication(w),
            Event::PublicationRemoved { guid } => {
                self.publications.dispose(InstanceHandle::from_guid(*guid));
            }
            Event::SubscriptionDiscovered(r) => self.subscription(r),
            Event::SubscriptionRemoved { guid } => {
                self.subscriptions.dispose(InstanceHandle::from_guid(*guid));
            }
            Event::WriterDeleted { writer } => {
                let g = Guid::new(self.prefix, *writer);
                self.publications.dispose(InstanceHandle::from_guid(g));
            }
            Event::TopicDiscovered(t) => {
                let key = topic_key(&t.topic_name, &t.type_name);
                lock(&self.topic_guids).insert(t.guid, key);
                let data =
                    TopicBuiltinTopicData::new(&t.topic_name, &t.type_name, t.topic_data.clone());
                self.topics.upsert(key, data);
            }
            Event::TopicRemoved { guid } => {
                if let Some(key) = lock(&self.topic_guids).remove(guid) {
                    self.topics.dispose(key);
                }
            }
            Event::ReaderDeleted { reader } => {
                let g = Guid::new(self.prefix, *reader);
                self.subscriptions.dispose(InstanceHandle::from_guid(g));
            }
            _ => {}
        }
    }
}
