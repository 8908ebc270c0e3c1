//! The participant's entity registry: the topics, publishers, subscribers, readers and writers it contains,
//! with what DDS keeps per entity beyond its handle (current QoS, default QoS of its children, its level
//! of the listener chain, whether it was deleted). It backs `delete_*`, `delete_contained_entities`,
//! `contains_entity`, `lookup_*`, `find_topic`, the default-QoS operations and INCONSISTENT_TOPIC.
//!
//! Entities refer to it, never the reverse: it holds weak references only, so it keeps nothing alive.
//! It knows no entity type; the entity modules downcast what they registered.

use std::any::Any;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Condvar, Mutex, Weak};
use std::time::Instant;

use foldhash::{HashMap, HashSet};

use crate::qos::{
    ChangeableQos, DataReaderQos, DataWriterQos, DomainParticipantQos, Interner, PublisherQos,
    SubscriberQos, TopicQos,
};
use crate::rtps::{EntityId, Event, Guid, GuidPrefix};

use super::chain::ListenerNode;
use super::condition::StatusCore;
use super::error::{DdsError, DdsResult};
use super::sample::{InstanceHandle, InstanceStateMask, SampleStateMask, ViewStateMask};
use super::status::{InconsistentTopicStatus, StatusMask};
use super::sync::{lock, recover};

/// Most remote topic names remembered for `find_topic`.
const MAX_REMOTE_TOPICS: usize = 4096;

/// RTPS entity kinds of the groups (publishers 0x08, subscribers 0x09) and of topics (0x0a), used for
/// their handles.
const KIND_WRITER_GROUP: u8 = 0x08;
const KIND_READER_GROUP: u8 = 0x09;
const KIND_TOPIC: u8 = 0x0a;

/// A publisher or subscriber: `Q` is its QoS, `C` the default QoS of its readers or writers.
pub(crate) struct Group<Q, C> {
    /// The entity's identity: the `Arc` its handles share.
    pub(crate) identity: Weak<dyn Any + Send + Sync>,
    pub(crate) node: Arc<ListenerNode>,
    pub(crate) qos: Q,
    pub(crate) child_default: C,
    /// `suspend_publications` nesting depth (publishers only).
    pub(crate) suspended: u32,
    pub(crate) deleted: bool,
}

/// A topic.
pub(crate) struct TopicEntry {
    pub(crate) identity: Weak<dyn Any + Send + Sync>,
    pub(crate) name: String,
    pub(crate) type_name: String,
    pub(crate) node: Arc<ListenerNode>,
    pub(crate) qos: TopicQos,
    pub(crate) inconsistent: InconsistentTopicStatus,
    pub(crate) deleted: bool,
    /// The GUID of its SEDP announcement (DCPSTopic), once announced.
    pub(crate) wire: Option<Guid>,
    /// A topic of the built-in subscriber (DCPSParticipant, ...): never announced, not counted among the
    /// participant's entities.
    pub(crate) builtin: bool,
}

/// A reader or writer.
pub(crate) struct EndpointEntry {
    /// The handle of its publisher or subscriber.
    pub(crate) group: InstanceHandle,
    pub(crate) topic: String,
    pub(crate) guid: Guid,
    /// Shared with the entity: set by an explicit delete. Dead once the entity is gone.
    pub(crate) deleted: Weak<AtomicBool>,
    /// The entity itself (its inner state), for the typed lookups and group QoS changes.
    pub(crate) entity: Weak<dyn Registered>,
}

/// The built-in subscriber's readers, as the registry keeps them (`dcps::builtin_subscriber`).
pub(crate) trait BuiltinReaders: Send + Sync {
    /// The handle of the built-in subscriber.
    fn group_handle(&self) -> InstanceHandle;
    /// The readers, for a downcast to their type.
    fn as_any(self: Arc<Self>) -> Arc<dyn Any + Send + Sync>;
    /// Creates the application's reader on a built-in topic: `spec` is a boxed
    /// `subscriber::UserReaderSpec<T>`, the result a boxed `DataReader<T>`; `None` when `T` is not the
    /// built-in type of a built-in topic.
    fn add_user_reader(&self, spec: Box<dyn Any>) -> Option<DdsResult<Box<dyn Any>>>;
}

/// A reader or writer as the registry sees it.
pub(crate) trait Registered: Send + Sync {
    /// The entity, for a downcast to its typed inner state.
    fn as_any(self: Arc<Self>) -> Arc<dyn Any + Send + Sync>;
    /// Its publisher's or subscriber's QoS (partition, group data) or its topic's (topic data) changed:
    /// announce again.
    fn group_changed(self: Arc<Self>);
    /// Whether a reader holds samples in these states (`get_datareaders`); false for writers.
    fn has_samples(&self, _s: SampleStateMask, _v: ViewStateMask, _i: InstanceStateMask) -> bool {
        false
    }
    /// Appends the numbers of a reader's samples in these states to `out`: with GROUP ordered access, their
    /// place in the subscriber's order (`get_datareaders`). Nothing for writers.
    fn sample_order(
        &self,
        _s: SampleStateMask,
        _v: ViewStateMask,
        _i: InstanceStateMask,
        _out: &mut Vec<u64>,
    ) {
    }
    /// Calls the reader's `on_data_available` (`notify_datareaders`); nothing for writers.
    fn notify_data_available(self: Arc<Self>) {}
    /// Enables the reader or writer (`enable`): `PreconditionNotMet` while its factory or topic is
    /// disabled.
    fn enable(self: Arc<Self>) -> DdsResult<()>;
}

impl EndpointEntry {
    /// Whether the entity still exists and was not deleted.
    pub(crate) fn alive(&self) -> bool {
        self.deleted
            .upgrade()
            .is_some_and(|d| !d.load(Ordering::Acquire))
    }
}

/// Everything the registry tracks, under one lock.
#[derive(Default)]
pub(crate) struct Entities {
    pub(crate) topics: Vec<TopicEntry>,
    pub(crate) publishers: Vec<Group<PublisherQos, DataWriterQos>>,
    pub(crate) subscribers: Vec<Group<SubscriberQos, DataReaderQos>>,
    pub(crate) writers: Vec<EndpointEntry>,
    pub(crate) readers: Vec<EndpointEntry>,
    /// Topic name → type name of remote endpoints (for `find_topic` and INCONSISTENT_TOPIC). The type names
    /// are shared (`type_names`): one entry costs a topic name, not two strings.
    pub(crate) remote_topics: HashMap<Box<str>, Arc<str>>,
    type_names: Interner<str>,
    /// Remote topics (participant, topic name) already counted in an INCONSISTENT_TOPIC status: a remote
    /// participant's topic counts once, whether learnt from its SEDP topic announcement or from its readers
    /// and writers (announced again on QoS changes).
    inconsistent_seen: HashSet<(GuidPrefix, String)>,
    pub(crate) participant_qos: DomainParticipantQos,
    pub(crate) default_publisher_qos: PublisherQos,
    pub(crate) default_subscriber_qos: SubscriberQos,
    pub(crate) default_topic_qos: TopicQos,
    /// The disabled participant, topics, publishers and subscribers (see `dcps::enable`).
    pub(crate) disabled: HashSet<InstanceHandle>,
}

impl Entities {
    /// Forgets entities that no handle refers to any more.
    fn prune(&mut self) {
        self.topics.retain(|t| t.identity.strong_count() > 0);
        self.publishers.retain(|g| g.identity.strong_count() > 0);
        self.subscribers.retain(|g| g.identity.strong_count() > 0);
        self.writers.retain(|e| e.deleted.strong_count() > 0);
        self.readers.retain(|e| e.deleted.strong_count() > 0);
    }
}

/// Whether `weak` and `ptr` designate the same allocation.
pub(crate) fn same(weak: &Weak<dyn Any + Send + Sync>, ptr: *const ()) -> bool {
    weak.as_ptr() as *const () == ptr
}

/// The registry of one participant.
pub(crate) struct Registry {
    prefix: GuidPrefix,
    next_key: AtomicU32,
    /// The participant's level of the listener chain (its status condition is the participant's).
    pub(crate) node: Arc<ListenerNode>,
    entities: Mutex<Entities>,
    /// Notified when a remote topic is discovered (`find_topic` waits on it).
    discovered: Condvar,
    /// The built-in subscriber's readers, created when first asked for.
    pub(crate) builtin: Mutex<Option<Arc<dyn BuiltinReaders>>>,
}

impl Registry {
    /// The registry of the participant `prefix`, whose status condition is `status`.
    pub(crate) fn new(
        prefix: GuidPrefix,
        status: Arc<StatusCore>,
        qos: DomainParticipantQos,
    ) -> Self {
        let handle = InstanceHandle::from_guid(Guid::new(prefix, EntityId::PARTICIPANT));
        Registry {
            prefix,
            next_key: AtomicU32::new(1),
            node: Arc::new(ListenerNode::new(handle, status, None)),
            entities: Mutex::new(Entities {
                participant_qos: qos,
                ..Entities::default()
            }),
            discovered: Condvar::new(),
            builtin: Mutex::new(None),
        }
    }

    /// Runs `f` on the entities (pruned of the dead ones).
    pub(crate) fn with<R>(&self, f: impl FnOnce(&mut Entities) -> R) -> R {
        let mut e = lock(&self.entities);
        e.prune();
        f(&mut e)
    }

    /// A fresh handle for a local publisher, subscriber or topic (a GUID of the right entity kind).
    fn new_handle(&self, kind: u8) -> InstanceHandle {
        let k = self.next_key.fetch_add(1, Ordering::Relaxed).to_be_bytes();
        InstanceHandle::from_guid(Guid::new(self.prefix, EntityId([k[1], k[2], k[3], kind])))
    }

    /// Registers a publisher or subscriber with QoS `qos`; returns its level of the listener chain.
    pub(crate) fn add_group<Q: GroupQos>(
        &self,
        identity: Weak<dyn Any + Send + Sync>,
        qos: Q,
    ) -> Arc<ListenerNode> {
        let node = self.group_node(Q::KIND);
        self.with(|e| {
            Q::groups(e).push(Group {
                identity,
                node: node.clone(),
                qos,
                child_default: Q::Child::default(),
                suspended: 0,
                deleted: false,
            })
        });
        node
    }

    fn group_node(&self, kind: u8) -> Arc<ListenerNode> {
        Arc::new(ListenerNode::new(
            self.new_handle(kind),
            Arc::new(StatusCore::default()),
            Some(self.node.clone()),
        ))
    }

    /// Registers a topic; returns its handle.
    pub(crate) fn add_topic(
        &self,
        identity: Weak<dyn Any + Send + Sync>,
        name: &str,
        type_name: &str,
        qos: TopicQos,
        builtin: bool,
    ) -> InstanceHandle {
        let node = self.group_node(KIND_TOPIC);
        let handle = node.handle;
        let clash = self.with(|e| {
            let mut inconsistent = InconsistentTopicStatus::default();
            let clash = e.remote_topics.get(name).is_some_and(|t| &**t != type_name);
            if clash {
                inconsistent.record();
            }
            e.topics.push(TopicEntry {
                identity,
                name: name.to_string(),
                type_name: type_name.to_string(),
                node: node.clone(),
                qos,
                inconsistent,
                deleted: false,
                wire: None,
                builtin,
            });
            clash
        });
        if clash {
            // Known before the topic existed: the status is set, no listener can have been installed yet.
            node.raise_up(node.handle, StatusMask::INCONSISTENT_TOPIC);
        }
        handle
    }

    /// Takes the GUID of the SEDP announcement of the topic at `ptr` (to withdraw it). Works while the topic
    /// is being dropped: the entry is looked up before dead entries are pruned.
    pub(crate) fn take_topic_wire(&self, ptr: *const ()) -> Option<Guid> {
        lock(&self.entities)
            .topics
            .iter_mut()
            .find(|t| same(&t.identity, ptr))
            .and_then(|t| t.wire.take())
    }

    /// Registers a writer (`writer` true) or reader of the group `group` on `topic`.
    pub(crate) fn add_endpoint(&self, writer: bool, entry: EndpointEntry) {
        self.with(|e| {
            if writer {
                e.writers.push(entry)
            } else {
                e.readers.push(entry)
            }
        });
    }

    /// Notes a remote publication or subscription: remembers its topic and returns the handles of the
    /// local topics of that name with another type (INCONSISTENT_TOPIC), with their status after the
    /// change.
    pub(crate) fn on_discovery(
        &self,
        ev: &Event,
    ) -> Vec<(Arc<ListenerNode>, InconsistentTopicStatus)> {
        let (guid, topic, type_name) = match ev {
            Event::PublicationDiscovered(w) => (w.guid, &w.topic_name, &w.type_name),
            Event::SubscriptionDiscovered(r) => (r.guid, &r.topic_name, &r.type_name),
            Event::TopicDiscovered(t) => (t.guid, &t.topic_name, &t.type_name),
            _ => return Vec::new(),
        };
        let out = self.with(|e| {
            if e.remote_topics.len() < MAX_REMOTE_TOPICS || e.remote_topics.contains_key(&**topic) {
                let t = e.type_names.intern(Arc::from(type_name.as_str()));
                e.remote_topics.insert(topic.as_str().into(), t);
            }
            let inconsistent = e
                .topics
                .iter()
                .any(|t| !t.deleted && t.name == *topic && t.type_name != *type_name);
            if !inconsistent || e.inconsistent_seen.len() >= MAX_REMOTE_TOPICS {
                return Vec::new();
            }
            if !e.inconsistent_seen.insert((guid.prefix, topic.clone())) {
                return Vec::new();
            }
            e.topics
                .iter_mut()
                .filter(|t| !t.deleted && t.name == *topic && t.type_name != *type_name)
                .map(|t| {
                    t.inconsistent.record();
                    (t.node.clone(), t.inconsistent.clone())
                })
                .collect()
        });
        self.discovered.notify_all();
        out
    }

    /// Waits until `f` returns `Some` (re-evaluated whenever a remote topic is discovered) or `deadline`.
    pub(crate) fn wait_for<R>(
        &self,
        deadline: Option<Instant>,
        mut f: impl FnMut(&mut Entities) -> Option<R>,
    ) -> Option<R> {
        let mut e = lock(&self.entities);
        loop {
            e.prune();
            if let Some(r) = f(&mut e) {
                return Some(r);
            }
            let left = match deadline {
                Some(d) => d.checked_duration_since(Instant::now())?,
                None => std::time::Duration::from_millis(500),
            };
            e = recover(self.discovered.wait_timeout(e, left)).0;
        }
    }
}

/// Publishers and subscribers, told apart by their QoS type.
pub(crate) trait GroupQos: ChangeableQos + Sized + Clone {
    /// The QoS of their readers or writers.
    type Child: Clone + Default;
    /// The RTPS entity kind used for their handles.
    const KIND: u8;
    /// Whether `new` changes what their readers or writers announce (partition, group data).
    fn announced_change(&self, new: &Self) -> bool;
    /// ENTITY_FACTORY.autoenable_created_entities.
    fn autoenable(&self) -> bool;
    /// The registered groups of this kind.
    fn groups(e: &mut Entities) -> &mut Vec<Group<Self, Self::Child>>;
    /// The readers or writers.
    fn children(e: &mut Entities) -> &mut Vec<EndpointEntry>;
}

impl GroupQos for PublisherQos {
    type Child = DataWriterQos;
    const KIND: u8 = KIND_WRITER_GROUP;
    fn announced_change(&self, new: &Self) -> bool {
        self.partition != new.partition || self.group_data != new.group_data
    }
    fn autoenable(&self) -> bool {
        self.autoenable_created_entities
    }
    fn groups(e: &mut Entities) -> &mut Vec<Group<Self, Self::Child>> {
        &mut e.publishers
    }
    fn children(e: &mut Entities) -> &mut Vec<EndpointEntry> {
        &mut e.writers
    }
}

impl GroupQos for SubscriberQos {
    type Child = DataReaderQos;
    const KIND: u8 = KIND_READER_GROUP;
    fn announced_change(&self, new: &Self) -> bool {
        self.partition != new.partition || self.group_data != new.group_data
    }
    fn autoenable(&self) -> bool {
        self.autoenable_created_entities
    }
    fn groups(e: &mut Entities) -> &mut Vec<Group<Self, Self::Child>> {
        &mut e.subscribers
    }
    fn children(e: &mut Entities) -> &mut Vec<EndpointEntry> {
        &mut e.readers
    }
}

/// A reader or writer of a group, as the group operations see it.
pub(crate) struct Child {
    pub(crate) id: EntityId,
    pub(crate) topic: String,
    pub(crate) entity: Weak<dyn Registered>,
}

impl Registry {
    /// Runs `f` on the group whose identity is at `ptr`; `AlreadyDeleted` once deleted.
    pub(crate) fn with_group<Q: GroupQos, R>(
        &self,
        ptr: *const (),
        f: impl FnOnce(&mut Group<Q, Q::Child>) -> R,
    ) -> DdsResult<R> {
        self.with(|e| {
            Q::groups(e)
                .iter_mut()
                .find(|g| !g.deleted && same(&g.identity, ptr))
                .map(f)
                .ok_or(DdsError::AlreadyDeleted)
        })
    }

    /// The live readers or writers of the group `handle`.
    pub(crate) fn children<Q: GroupQos>(&self, handle: InstanceHandle) -> Vec<Child> {
        self.with(|e| {
            Q::children(e)
                .iter()
                .filter(|w| w.group == handle && w.alive())
                .map(|w| Child {
                    id: w.guid.entity_id,
                    topic: w.topic.clone(),
                    entity: w.entity.clone(),
                })
                .collect()
        })
    }

    /// Deletes the group at `ptr` (`delete_publisher`, `delete_subscriber`): `PreconditionNotMet` while it
    /// has readers or writers.
    pub(crate) fn delete_group<Q: GroupQos>(&self, ptr: *const ()) -> DdsResult<()> {
        self.with(|e| {
            let Some(handle) = Q::groups(e)
                .iter()
                .find(|g| !g.deleted && same(&g.identity, ptr))
                .map(|g| g.node.handle)
            else {
                return Err(DdsError::AlreadyDeleted);
            };
            if Q::children(e)
                .iter()
                .any(|w| w.group == handle && w.alive())
            {
                return Err(DdsError::PreconditionNotMet(
                    "the publisher or subscriber still has readers or writers",
                ));
            }
            for g in Q::groups(e).iter_mut().filter(|g| same(&g.identity, ptr)) {
                g.deleted = true;
            }
            Ok(())
        })
    }

    /// Changes the QoS of the group at `ptr` (`set_qos`); returns its readers or writers when what they
    /// announce changed (they must announce again).
    pub(crate) fn set_group_qos<Q: GroupQos>(
        &self,
        ptr: *const (),
        qos: &Q,
    ) -> DdsResult<Vec<Weak<dyn Registered>>> {
        // A disabled group takes every policy (DDS 1.4 §2.2.2.1.1.7); its readers or writers (disabled
        // too) announce the new ones when enabled.
        let enabled = self.is_enabled(self.with_group::<Q, _>(ptr, |g| g.node.handle)?);
        let (handle, changed) = self.with_group::<Q, _>(ptr, |g| {
            let immutable = g.qos.immutable_change(qos);
            if let (Some(p), true) = (immutable, enabled) {
                return Err(DdsError::ImmutablePolicy(p));
            }
            let changed = g.qos.announced_change(qos) || immutable.is_some();
            g.qos = qos.clone();
            Ok((g.node.handle, changed))
        })??;
        if !changed {
            return Ok(Vec::new());
        }
        Ok(self
            .children::<Q>(handle)
            .into_iter()
            .map(|c| c.entity)
            .collect())
    }

    /// The reader or writer of the group `handle` on `topic` whose inner state is an `E`.
    pub(crate) fn find_child<Q: GroupQos, E: Any + Send + Sync>(
        &self,
        handle: InstanceHandle,
        topic: &str,
    ) -> Option<Arc<E>> {
        self.children::<Q>(handle)
            .into_iter()
            .filter(|c| c.topic == topic)
            .find_map(|c| c.entity.upgrade()?.as_any().downcast::<E>().ok())
    }

    /// Marks every reader or writer of the group `handle` deleted; returns their ids (to delete in the
    /// core).
    pub(crate) fn delete_children<Q: GroupQos>(&self, handle: InstanceHandle) -> Vec<EntityId> {
        let ids: Vec<EntityId> = self
            .children::<Q>(handle)
            .into_iter()
            .map(|c| c.id)
            .collect();
        self.mark_deleted(&ids)
    }

    /// Marks the readers and writers `ids` deleted; returns those that were not yet (to delete in the core).
    pub(crate) fn mark_deleted(&self, ids: &[EntityId]) -> Vec<EntityId> {
        self.with(|e| {
            e.writers
                .iter()
                .chain(e.readers.iter())
                .filter(|w| ids.contains(&w.guid.entity_id))
                .filter_map(|w| {
                    let d = w.deleted.upgrade()?;
                    (!d.swap(true, Ordering::AcqRel)).then_some(w.guid.entity_id)
                })
                .collect()
        })
    }
}
