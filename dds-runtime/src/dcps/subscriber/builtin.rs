//! The readers of the built-in subscriber (DDS 1.4 §2.2.5) as ordinary `DataReader<T>`s: the typed reader's
//! cache, states, conditions, listeners and subscriber, with no RTPS reader behind them. Discovery feeds
//! them ([`BuiltinReader::upsert`], [`BuiltinReader::dispose`]); their QoS is the one DDS sets for them
//! (RELIABLE, TRANSIENT_LOCAL, KEEP_LAST 1). A reader the application creates on a built-in topic
//! ([`BuiltinReader::add_user_reader`]) is fed the same changes, with its own QoS.

use std::any::Any;
use std::sync::{Arc, Mutex, Weak};
use std::time::{Instant, SystemTime};

use crate::cdr::{self, DdsType};
use crate::qos::{DataReaderQos, Durability, History, Reliability, ResourceLimits, SubscriberQos};
use crate::rtps::{ChangeKind, EntityId, Guid};

use super::super::status::StatusMask;

use super::super::cache::{Incoming, Outcome, ReaderCache};
use super::super::driver::Endpoint;
use super::super::error::DdsResult;
use super::super::participant::DomainParticipant;
use super::super::presentation::AccessScope;
use super::super::sample::{InstanceHandle, InstanceState};
use super::super::sync::lock;
use super::{
    ops, DataReader, DataReaderListener, ReaderInner, ReaderOwner, Stored, Subscriber, Typed,
};

/// Most instances one built-in reader keeps, so that hostile discovery data cannot grow it without bound.
/// At the limit a new entity evicts the one gone longest; only when every kept entity is alive is it
/// rejected (SAMPLE_REJECTED).
const MAX_INSTANCES: u32 = 16 * 1024;

/// The QoS of the built-in readers (DDS 1.4 §2.2.5).
fn builtin_qos() -> DataReaderQos {
    DataReaderQos::builder()
        .reliability(Reliability::Reliable {
            max_blocking_time: std::time::Duration::from_millis(100),
        })
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(1))
        .resource_limits(ResourceLimits {
            max_instances: Some(MAX_INSTANCES),
            ..ResourceLimits::default()
        })
        .build()
}

/// The built-in subscriber's identity, kept by the participant: not a `Subscriber` (which would keep the
/// participant alive), but what makes one.
pub(crate) struct BuiltinGroup {
    qos: Arc<SubscriberQos>,
    access: Arc<AccessScope>,
    handle: InstanceHandle,
}

impl BuiltinGroup {
    /// Registers the built-in subscriber of `p` (enabled, not counted among its entities).
    pub(crate) fn new(p: &DomainParticipant) -> (Self, Subscriber) {
        let s = Subscriber {
            participant: p.clone(),
            qos: Arc::new(SubscriberQos::default()),
            access: Arc::default(),
        };
        let identity: Weak<dyn Any + Send + Sync> = Arc::downgrade(&s.qos) as Weak<SubscriberQos>;
        let node = p.registry().add_group(identity, (*s.qos).clone());
        let g = BuiltinGroup {
            qos: s.qos.clone(),
            access: s.access.clone(),
            handle: node.handle,
        };
        (g, s)
    }

    /// The built-in subscriber of `p`.
    pub(crate) fn subscriber(&self, p: &DomainParticipant) -> Subscriber {
        Subscriber {
            participant: p.clone(),
            qos: self.qos.clone(),
            access: self.access.clone(),
        }
    }

    /// Its instance handle.
    pub(crate) fn handle(&self) -> InstanceHandle {
        self.handle
    }
}

/// The feeding side of one built-in reader. Holds the reader's state, not its handle: the handle (and
/// through it the participant) lives as long as the application holds the reader, and is made again
/// when it asks for the reader after dropping it.
pub(crate) struct BuiltinReader<T: DdsType> {
    inner: Arc<ReaderInner<Typed<T>>>,
    /// The reader's entity id: the participant's built-in reader of the topic.
    id: EntityId,
    topic_name: &'static str,
    /// The writer the reader's changes come from: the participant's built-in writer of the topic.
    writer: Guid,
    /// Readers the application created on the topic: fed the same changes while they exist.
    users: Mutex<Vec<Weak<ReaderInner<Typed<T>>>>>,
}

/// The four built-in topics.
const BUILTIN_TOPICS: [&str; 4] = [
    "DCPSParticipant",
    "DCPSPublication",
    "DCPSSubscription",
    "DCPSTopic",
];

/// Creates the application's reader on a built-in topic (`create_datareader` on `DCPSParticipant`,
/// `DCPSPublication`, `DCPSSubscription` or `DCPSTopic` with its built-in type): fed by discovery like the
/// built-in subscriber's reader of the topic (`dcps::builtin_subscriber`), seeded with what discovery
/// knows now. `None` when `topic` is not a built-in topic of type `T` (an ordinary reader is made then).
pub(crate) fn user_builtin_reader<T: DdsType>(
    s: &Subscriber,
    topic: &super::Topic<T>,
    qos: &DataReaderQos,
    listener: Option<(Arc<dyn DataReaderListener<T>>, StatusMask)>,
) -> DdsResult<Option<DataReader<T>>> {
    if !BUILTIN_TOPICS.contains(&topic.name()) {
        return Ok(None);
    }
    let p = s.participant();
    p.get_builtin_subscriber()?;
    let Some(feed) = lock(&p.registry().builtin).clone() else {
        return Ok(None);
    };
    let spec: Box<dyn Any> = Box::new(UserReaderSpec {
        subscriber: s.clone(),
        topic: topic.clone(),
        qos: qos.clone(),
        listener,
    });
    match feed.add_user_reader(spec) {
        None => Ok(None),
        Some(r) => Ok(r?.downcast::<DataReader<T>>().ok().map(|r| *r)),
    }
}

/// A reader the application creates on a built-in topic: its subscriber, topic, QoS and listener. No RTPS
/// reader is behind it; its entity id only names it (instance handle, the driver's endpoint table), from
/// `Participant::alloc_local_reader_id`.
pub(crate) struct UserReaderSpec<T: DdsType> {
    pub subscriber: Subscriber,
    pub topic: super::Topic<T>,
    pub qos: DataReaderQos,
    pub listener: Option<(Arc<dyn DataReaderListener<T>>, StatusMask)>,
}

impl<T: DdsType + Clone> BuiltinReader<T> {
    /// Creates the reader of `topic_name` in the built-in subscriber `s`, with entity id `id`; changes
    /// come from the writer `writer` of this participant, instance handles from `handle_of` (the key).
    pub(crate) fn create(
        s: &Subscriber,
        topic_name: &'static str,
        (id, writer): (EntityId, EntityId),
        handle_of: fn(&[u8]) -> InstanceHandle,
    ) -> DdsResult<(Self, DataReader<T>)> {
        let p = &s.participant;
        let inner = fed_reader(p, builtin_qos(), handle_of);
        let topic = p.builtin_topic::<T>(topic_name)?;
        inner.state.set_parent(ops::reader_parent(s, &topic)?);
        let r = BuiltinReader {
            inner,
            id,
            topic_name,
            writer: Guid::new(p.driver().guid_prefix, writer),
            users: Mutex::default(),
        };
        let reader = r.attach(s, topic)?;
        ops::register_reader(s, &r.inner, topic_name);
        Ok((r, reader))
    }

    /// A new handle of the reader, owning `topic` and `s`.
    fn attach(&self, s: &Subscriber, topic: super::Topic<T>) -> DdsResult<DataReader<T>> {
        let sink: Arc<dyn Endpoint> = self.inner.clone();
        let owner = ReaderOwner {
            topic,
            subscriber: s.clone(),
        };
        let id = self.id;
        let handle = self.inner.state.create(sink, owner, move |_, _| Ok(id))?;
        Ok(DataReader {
            inner: self.inner.clone(),
            handle,
        })
    }

    /// The reader, in the built-in subscriber `s`.
    pub(crate) fn reader(&self, s: &Subscriber) -> DdsResult<DataReader<T>> {
        if let Some(handle) = self.inner.state.handle() {
            return Ok(DataReader {
                inner: self.inner.clone(),
                handle,
            });
        }
        let topic = s.participant.builtin_topic::<T>(self.topic_name)?;
        self.attach(s, topic)
    }

    /// Discovery learnt new or changed data of an entity.
    pub(crate) fn upsert(&self, data: T) {
        let mut key = Vec::new();
        match cdr::instance_key(&data, &mut key) {
            Ok(()) => self.apply(ChangeKind::Alive, Some(data), key),
            Err(e) => tracing::debug!(error = %e, "built-in sample without a key"),
        }
    }

    /// The entity whose serialized key is `key` left: its instance is disposed.
    pub(crate) fn dispose(&self, key: Vec<u8>) {
        self.apply(ChangeKind::DisposeUnregister, None, key);
    }

    /// Whether the instance of serialized key `key` is known and alive.
    pub(crate) fn is_alive(&self, key: &[u8]) -> bool {
        let st = lock(&self.inner.cache);
        st.cache
            .lookup(key)
            .and_then(|h| st.cache.instance_state(h))
            == Some(InstanceState::Alive)
    }

    /// Creates a reader of the application on this reader's topic, seeded with `seed` (what discovery
    /// knows now) and fed from then on like this one. Its QoS is the application's: history, resource
    /// limits, time-based filter, ... apply as for any reader.
    pub(crate) fn add_user_reader(
        &self,
        spec: UserReaderSpec<T>,
        handle_of: fn(&[u8]) -> InstanceHandle,
        seed: Vec<T>,
    ) -> DdsResult<DataReader<T>> {
        let s = &spec.subscriber;
        let mut qos = spec.qos;
        // Bounded as the built-in subscriber's readers are, whatever the application asked for.
        let limit = qos.resource_limits.max_instances.unwrap_or(MAX_INSTANCES);
        qos.resource_limits.max_instances = Some(limit.min(MAX_INSTANCES));
        let inner = fed_reader(&s.participant, qos, handle_of);
        inner.state.set_parent(ops::reader_parent(s, &spec.topic)?);
        if let Some((l, mask)) = spec.listener {
            inner.state.set_listener_with_mask(Some(l), mask);
        }
        let sink: Arc<dyn Endpoint> = inner.clone();
        let owner = ReaderOwner {
            topic: spec.topic,
            subscriber: s.clone(),
        };
        let handle = inner
            .state
            .create(sink, owner, |c, _| c.alloc_local_reader_id())?;
        ops::register_reader(&spec.subscriber, &inner, self.topic_name);
        for data in seed {
            let mut key = Vec::new();
            if cdr::instance_key(&data, &mut key).is_ok() {
                self.store(&inner, ChangeKind::Alive, Some(data), key);
            }
        }
        let mut users = lock(&self.users);
        users.retain(|u| u.strong_count() > 0);
        users.push(Arc::downgrade(&inner));
        Ok(DataReader { inner, handle })
    }

    fn apply(&self, kind: ChangeKind, data: Option<T>, key: Vec<u8>) {
        let users: Vec<_> = lock(&self.users).iter().filter_map(Weak::upgrade).collect();
        for u in users {
            self.store(&u, kind, data.clone(), key.clone());
        }
        self.store(&self.inner, kind, data, key);
    }

    /// Stores one change in `inner` and announces it.
    fn store(
        &self,
        inner: &Arc<ReaderInner<Typed<T>>>,
        kind: ChangeKind,
        data: Option<T>,
        key: Vec<u8>,
    ) {
        let now = SystemTime::now();
        let inc = Incoming {
            writer: self.writer,
            attributed: None,
            kind,
            data,
            key,
            key_holder: None,
            source_timestamp: now,
            reception_timestamp: now,
            strength: 0,
            expires: None,
        };
        let mut stored = Stored::default();
        match lock(&inner.cache).cache.insert(inc, Instant::now()) {
            Outcome::Accepted { .. } => stored.any = true,
            Outcome::Filtered => {}
            Outcome::Rejected { reason, handle } => stored.rejected.push((reason, handle)),
        }
        inner.announce_stored(stored);
    }
}

/// A reader with no RTPS reader behind it, fed by discovery: instances by `handle_of`, disposed ones
/// evicted.
fn fed_reader<T: DdsType>(
    p: &DomainParticipant,
    qos: DataReaderQos,
    handle_of: fn(&[u8]) -> InstanceHandle,
) -> Arc<ReaderInner<Typed<T>>> {
    let mut cache = ReaderCache::new(qos, true);
    cache.set_handle_fn(handle_of);
    cache.set_evict_not_alive(true);
    Arc::new(ReaderInner::new(
        super::super::decode::Derived,
        p.driver().clone(),
        cache,
        None,
        None,
        None,
    ))
}
