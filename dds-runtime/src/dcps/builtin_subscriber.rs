//! The built-in subscriber (`get_builtin_subscriber`, DDS 1.4 §2.2.5): a [`Subscriber`] with four
//! `DataReader`s, seeded with what discovery knows when it is first asked for, then fed by the core's
//! discovery events.

use std::any::Any;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use super::builtin::{
    topic_key, ParticipantBuiltinTopicData, PublicationBuiltinTopicData,
    SubscriptionBuiltinTopicData, TopicBuiltinTopicData,
};
use super::builtin_cdr::{guid_key_handle, topic_key_handle};
use super::data_on_readers::DataOnReadersBatch;
use super::driver::CoreObserver;
use super::error::DdsResult;
use super::participant::DomainParticipant;
use super::registry::BuiltinReaders;
use super::sample::InstanceHandle;
use super::subscriber::{BuiltinGroup, BuiltinReader, DataReader, Subscriber, UserReaderSpec};
use super::sync::lock;
use crate::cdr::DdsType;
use crate::rtps::discovery::{EndpointData, ParticipantData, TopicData};
use crate::rtps::{EntityId, Event, Guid, GuidPrefix};

/// The built-in subscriber of a participant: a [`Subscriber`] (it derefs to one: `lookup_datareader`,
/// `get_datareaders`, `set_listener` with DATA_ON_READERS, ...) holding one `DataReader` per built-in
/// topic. Every call of `get_builtin_subscriber` returns the same subscriber and readers.
#[derive(Clone, Debug)]
pub struct BuiltinSubscriber {
    subscriber: Subscriber,
    participants: DataReader<ParticipantBuiltinTopicData>,
    publications: DataReader<PublicationBuiltinTopicData>,
    subscriptions: DataReader<SubscriptionBuiltinTopicData>,
    topics: DataReader<TopicBuiltinTopicData>,
}

impl std::ops::Deref for BuiltinSubscriber {
    type Target = Subscriber;

    fn deref(&self) -> &Subscriber {
        &self.subscriber
    }
}

impl BuiltinSubscriber {
    /// The `DCPSParticipant` reader: the participants discovered through SPDP, and this one.
    pub fn participant_reader(&self) -> DataReader<ParticipantBuiltinTopicData> {
        self.participants.clone()
    }

    /// The `DCPSPublication` reader: the writers discovered through SEDP, and this participant's.
    pub fn publication_reader(&self) -> DataReader<PublicationBuiltinTopicData> {
        self.publications.clone()
    }

    /// The `DCPSSubscription` reader: the readers discovered through SEDP, and this participant's.
    pub fn subscription_reader(&self) -> DataReader<SubscriptionBuiltinTopicData> {
        self.subscriptions.clone()
    }

    /// The `DCPSTopic` reader: the topics announced in SEDP and those of the readers and writers
    /// discovered (see docs/dcps-api.md).
    pub fn topic_reader(&self) -> DataReader<TopicBuiltinTopicData> {
        self.topics.clone()
    }

    /// The subscriber itself.
    pub fn subscriber(&self) -> &Subscriber {
        &self.subscriber
    }
}

impl DomainParticipant {
    /// The built-in subscriber (`get_builtin_subscriber`): readers of `DCPSParticipant`,
    /// `DCPSPublication`, `DCPSSubscription` and `DCPSTopic`. Created on the first call with what
    /// discovery knows by then; every call returns the same subscriber and readers.
    pub fn get_builtin_subscriber(&self) -> DdsResult<BuiltinSubscriber> {
        self.driver().check_alive()?;
        let feed = {
            let mut slot = lock(&self.registry().builtin);
            match slot.clone().map(|f| f.as_any().downcast::<BuiltinFeed>()) {
                Some(Ok(feed)) => feed,
                _ => {
                    let (feed, s) = BuiltinFeed::start(self)?;
                    *slot = Some(feed);
                    return Ok(s);
                }
            }
        };
        // Outside the lock: making a reader's handle again runs the core, whose events may reach
        // listeners that ask for the built-in subscriber.
        feed.subscriber(self)
    }
}

/// What the participant keeps of its built-in subscriber: the readers' feeding side, which discovery
/// events go to (it holds nothing that keeps the participant alive).
pub(crate) struct BuiltinFeed {
    group: BuiltinGroup,
    /// Our participant's prefix (local endpoints that are deleted leave as remote ones do).
    prefix: GuidPrefix,
    /// The DCPSTopic key of each topic announced in SEDP, by the announcement's GUID.
    topic_guids: Mutex<HashMap<Guid, Vec<u8>>>,
    participants: BuiltinReader<ParticipantBuiltinTopicData>,
    publications: BuiltinReader<PublicationBuiltinTopicData>,
    subscriptions: BuiltinReader<SubscriptionBuiltinTopicData>,
    topics: BuiltinReader<TopicBuiltinTopicData>,
}

impl BuiltinReaders for BuiltinFeed {
    /// The handle of the built-in subscriber (not one of the participant's contained entities).
    fn group_handle(&self) -> InstanceHandle {
        self.group.handle()
    }

    fn as_any(self: Arc<Self>) -> Arc<dyn Any + Send + Sync> {
        self
    }

    fn add_user_reader(&self, spec: Box<dyn Any>) -> Option<DdsResult<Box<dyn Any>>> {
        self.user_reader(spec)
    }
}

impl BuiltinFeed {
    fn subscriber(&self, p: &DomainParticipant) -> DdsResult<BuiltinSubscriber> {
        let s = self.group.subscriber(p);
        Ok(BuiltinSubscriber {
            participants: self.participants.reader(&s)?,
            publications: self.publications.reader(&s)?,
            subscriptions: self.subscriptions.reader(&s)?,
            topics: self.topics.reader(&s)?,
            subscriber: s,
        })
    }

    /// Creates the readers, seeds them from the core and subscribes them to its discovery events.
    fn start(p: &DomainParticipant) -> DdsResult<(Arc<Self>, BuiltinSubscriber)> {
        let (group, s) = BuiltinGroup::new(p);
        let (participants, pr) = BuiltinReader::create(
            &s,
            "DCPSParticipant",
            (EntityId::SPDP_READER, EntityId::SPDP_WRITER),
            guid_key_handle,
        )?;
        let (publications, wr) = BuiltinReader::create(
            &s,
            "DCPSPublication",
            (
                EntityId::SEDP_PUBLICATIONS_READER,
                EntityId::SEDP_PUBLICATIONS_WRITER,
            ),
            guid_key_handle,
        )?;
        let (subscriptions, rr) = BuiltinReader::create(
            &s,
            "DCPSSubscription",
            (
                EntityId::SEDP_SUBSCRIPTIONS_READER,
                EntityId::SEDP_SUBSCRIPTIONS_WRITER,
            ),
            guid_key_handle,
        )?;
        let (topics, tr) = BuiltinReader::create(
            &s,
            "DCPSTopic",
            (EntityId::SEDP_TOPICS_READER, EntityId::SEDP_TOPICS_WRITER),
            topic_key_handle,
        )?;
        let feed = Arc::new(BuiltinFeed {
            group,
            prefix: p.guid_prefix(),
            topic_guids: Mutex::default(),
            participants,
            publications,
            subscriptions,
            topics,
        });
        let driver = p.driver();
        // Events from now on; what came before is seeded below (a repeat is only an update).
        driver.add_observer(feed.clone());
        let known = Known::now(p);
        for t in known.topics {
            feed.on_event(&Event::TopicDiscovered(Box::new(t)));
        }
        for p in &known.participants {
            feed.participant(p);
        }
        for w in &known.publications {
            feed.publication(w);
        }
        for r in &known.subscriptions {
            feed.subscription(r);
        }
        let s = BuiltinSubscriber {
            subscriber: s,
            participants: pr,
            publications: wr,
            subscriptions: rr,
            topics: tr,
        };
        Ok((feed, s))
    }

    fn participant(&self, p: &ParticipantData) {
        self.participants.upsert(p.into());
    }

    fn publication(&self, w: &EndpointData<crate::qos::WriterQos>) {
        self.topic(&w.topic_name, &w.type_name, &w.qos.topic_data.0);
        self.publications.upsert(w.into());
    }

    fn subscription(&self, r: &EndpointData<crate::qos::ReaderQos>) {
        self.topic(&r.topic_name, &r.type_name, &r.qos.topic_data.0);
        self.subscriptions.upsert(r.into());
    }

    /// A topic seen for the first time becomes an instance of DCPSTopic (later endpoints change nothing).
    fn topic(&self, name: &str, type_name: &str, topic_data: &[u8]) {
        if !self.topics.is_alive(&topic_key_bytes(name, type_name)) {
            let data = TopicBuiltinTopicData::new(name, type_name, topic_data.to_vec());
            self.topics.upsert(data);
        }
    }

    /// The local or remote writer `g` is gone.
    fn writer_gone(&self, g: Guid) {
        self.publications.dispose(g.to_bytes().to_vec());
    }

    /// The local or remote reader `g` is gone.
    fn reader_gone(&self, g: Guid) {
        self.subscriptions.dispose(g.to_bytes().to_vec());
    }
}

impl BuiltinFeed {
    /// [`BuiltinReaders::add_user_reader`]: the reader of the topic whose built-in type is the spec's,
    /// seeded with what discovery knows now.
    fn user_reader(&self, spec: Box<dyn Any>) -> Option<DdsResult<Box<dyn Any>>> {
        let mut spec = Some(spec);
        let all = |k: &Known| k.participants.iter().map(Into::into).collect();
        add_user(&self.participants, &mut spec, guid_key_handle, all)
            .or_else(|| {
                let all = |k: &Known| k.publications.iter().map(Into::into).collect();
                add_user(&self.publications, &mut spec, guid_key_handle, all)
            })
            .or_else(|| {
                let all = |k: &Known| k.subscriptions.iter().map(Into::into).collect();
                add_user(&self.subscriptions, &mut spec, guid_key_handle, all)
            })
            .or_else(|| add_user(&self.topics, &mut spec, topic_key_handle, Known::topic_data))
    }
}

/// Adds the reader `spec` describes to `reader` when it is a reader of `X`'s topic (`spec` is then taken),
/// seeded with `seed` of what its participant's discovery knows now.
fn add_user<X: DdsType + Clone>(
    reader: &BuiltinReader<X>,
    spec: &mut Option<Box<dyn Any>>,
    handle_of: fn(&[u8]) -> InstanceHandle,
    seed: impl FnOnce(&Known) -> Vec<X>,
) -> Option<DdsResult<Box<dyn Any>>> {
    let s = spec.take()?.downcast::<UserReaderSpec<X>>();
    match s {
        Ok(s) => {
            let data = seed(&Known::now(s.subscriber.participant()));
            Some(
                reader
                    .add_user_reader(*s, handle_of, data)
                    .map(|r| Box::new(r) as Box<dyn Any>),
            )
        }
        Err(other) => {
            *spec = Some(other);
            None
        }
    }
}

/// What discovery knows now: the participants (this one included), publications, subscriptions and
/// announced topics. Built-in readers start from it and follow the events after it.
struct Known {
    participants: Vec<ParticipantData>,
    publications: Vec<EndpointData<crate::qos::WriterQos>>,
    subscriptions: Vec<EndpointData<crate::qos::ReaderQos>>,
    topics: Vec<TopicData>,
}

impl Known {
    fn now(p: &DomainParticipant) -> Known {
        p.driver().query_core(|c| {
            let mut participants: Vec<ParticipantData> = c.discovered_participants().collect();
            participants.push(c.participant_data());
            Known {
                participants,
                publications: c.publications().cloned().collect(),
                subscriptions: c.subscriptions().cloned().collect(),
                topics: c.discovered_topic_announcements().cloned().collect(),
            }
        })
    }

    /// The DCPSTopic data: the announced topics, then those only endpoints name, each once (the rule of
    /// `BuiltinFeed::topic`).
    fn topic_data(&self) -> Vec<TopicBuiltinTopicData> {
        let mut ts: Vec<TopicBuiltinTopicData> = self
            .topics
            .iter()
            .map(|t| TopicBuiltinTopicData::new(&t.topic_name, &t.type_name, t.topic_data.clone()))
            .collect();
        let endpoints = self
            .publications
            .iter()
            .map(|w| (&w.topic_name, &w.type_name, &w.qos.topic_data.0))
            .chain(
                self.subscriptions
                    .iter()
                    .map(|r| (&r.topic_name, &r.type_name, &r.qos.topic_data.0)),
            );
        for (name, type_name, data) in endpoints {
            if !ts
                .iter()
                .any(|t| t.name == *name && t.type_name == *type_name)
            {
                ts.push(TopicBuiltinTopicData::new(name, type_name, data.clone()));
            }
        }
        ts
    }
}

/// The serialized key of the DCPSTopic instance of `name` with `type_name`.
fn topic_key_bytes(name: &str, type_name: &str) -> Vec<u8> {
    topic_key(name, type_name).0.to_be_bytes().to_vec()
}

impl CoreObserver for BuiltinFeed {
    fn on_event(&self, ev: &Event) {
        // DATA_ON_READERS once for what one event changed in several readers.
        let _batch = DataOnReadersBatch::start();
        match ev {
            Event::ParticipantDiscovered(p) => self.participant(p),
            Event::ParticipantLost { guid_prefix } => {
                let g = Guid::new(*guid_prefix, EntityId::PARTICIPANT);
                self.participants.dispose(g.to_bytes().to_vec());
            }
            Event::PublicationDiscovered(w) => self.publication(w),
            Event::SubscriptionDiscovered(r) => self.subscription(r),
            Event::PublicationRemoved { guid } => self.writer_gone(*guid),
            Event::SubscriptionRemoved { guid } => self.reader_gone(*guid),
            Event::WriterDeleted { writer } => self.writer_gone(Guid::new(self.prefix, *writer)),
            Event::ReaderDeleted { reader } => self.reader_gone(Guid::new(self.prefix, *reader)),
            Event::TopicDiscovered(t) => {
                let key = topic_key_bytes(&t.topic_name, &t.type_name);
                lock(&self.topic_guids).insert(t.guid, key);
                let data =
                    TopicBuiltinTopicData::new(&t.topic_name, &t.type_name, t.topic_data.clone());
                self.topics.upsert(data);
            }
            Event::TopicRemoved { guid } => {
                if let Some(key) = lock(&self.topic_guids).remove(guid) {
                    self.topics.dispose(key);
                }
            }
            _ => {}
        }
    }
}
