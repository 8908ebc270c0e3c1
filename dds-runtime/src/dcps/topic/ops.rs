//! The rest of the topic operations (DDS 1.4 §2.2.2.3): QoS, the topic listener and INCONSISTENT_TOPIC,
//! `delete_topic`, `lookup_topicdescription` and `find_topic`; and how topics enter the registry.

use std::any::Any;
use std::sync::{Arc, Weak};
use std::time::{Duration, Instant};

use crate::cdr::DdsType;
use crate::qos::{ChangeableQos, TopicQos};

use super::super::chain::{ParentListener, StatusChange};
use super::super::condition::StatusCondition;
use super::super::error::{DdsError, DdsResult};
use super::super::participant::DomainParticipant;
use super::super::registry::{same, TopicEntry};
use super::super::sample::InstanceHandle;
use super::super::status::{InconsistentTopicStatus, StatusMask};
use super::{Topic, TopicInner};

/// Callbacks of a [`Topic`]. Every method has an empty default.
#[allow(unused_variables)]
pub trait TopicListener: Send + Sync {
    /// A remote endpoint on a topic of this name with another type was discovered.
    fn on_inconsistent_topic(&self, topic: InstanceHandle, status: InconsistentTopicStatus) {}
}

struct TopicLevel(Arc<dyn TopicListener>);

impl ParentListener for TopicLevel {
    fn on_status(&self, topic: InstanceHandle, change: StatusChange) {
        if let StatusChange::InconsistentTopic(s) = change {
            self.0.on_inconsistent_topic(topic, s);
        }
    }
    fn on_data_on_readers(&self, _subscriber: InstanceHandle) {}
}

/// Registers a new topic in its participant.
pub(super) fn register_topic<T: DdsType>(t: &Topic<T>) {
    let identity: Weak<dyn Any + Send + Sync> = Arc::downgrade(&t.inner) as Weak<TopicInner>;
    let registry = t.inner.participant.registry();
    let handle = registry.add_topic(
        identity,
        &t.inner.name,
        T::TYPE_NAME,
        t.inner.qos.clone(),
        false,
    );
    registry.created_by_participant(handle);
    registry.announce_topics(t.inner.participant.driver());
}

impl DomainParticipant {
    /// The topic `name` of a built-in reader (DCPSParticipant, ...): the local one while it exists, else a
    /// new one, enabled, never announced in SEDP and not counted among the participant's entities.
    pub(crate) fn builtin_topic<T: DdsType>(&self, name: &str) -> DdsResult<Topic<T>> {
        self.driver().check_alive()?;
        if let Some(t) = self.lookup_topicdescription::<T>(name) {
            return Ok(t);
        }
        let topic = Topic {
            inner: Arc::new(TopicInner {
                participant: self.clone(),
                name: name.to_string(),
                qos: TopicQos::default(),
            }),
            _t: std::marker::PhantomData,
        };
        let identity: Weak<dyn Any + Send + Sync> =
            Arc::downgrade(&topic.inner) as Weak<TopicInner>;
        self.registry()
            .add_topic(identity, name, T::TYPE_NAME, TopicQos::default(), true);
        Ok(topic)
    }
}

impl<T: DdsType> Topic<T> {
    /// Runs `f` on this topic's registry entry; `AlreadyDeleted` once deleted.
    fn with_entry<R>(&self, f: impl FnOnce(&mut TopicEntry) -> R) -> DdsResult<R> {
        self.participant().driver().check_alive()?;
        let ptr = Arc::as_ptr(&self.inner) as *const ();
        self.participant().registry().with(|e| {
            e.topics
                .iter_mut()
                .find(|t| !t.deleted && same(&t.identity, ptr))
                .map(f)
                .ok_or(DdsError::AlreadyDeleted)
        })
    }

    /// `AlreadyDeleted` once the topic (or its participant) was deleted.
    pub(crate) fn check_alive(&self) -> DdsResult<()> {
        self.with_entry(|_| ())
    }

    /// The topic's handle (`get_instance_handle`).
    pub fn instance_handle(&self) -> DdsResult<InstanceHandle> {
        self.with_entry(|t| t.node.handle)
    }

    /// The QoS in effect (`get_qos`).
    pub fn get_qos(&self) -> DdsResult<TopicQos> {
        self.with_entry(|t| t.qos.clone())
    }

    /// Changes the QoS (`set_qos`): TOPIC_DATA, DEADLINE, LATENCY_BUDGET, TRANSPORT_PRIORITY and LIFESPAN
    /// may change (a new TOPIC_DATA is announced again by the topic's readers and writers); the others
    /// cannot (`ImmutablePolicy`) once the topic is enabled. A disabled topic takes every policy.
    pub fn set_qos(&self, qos: &TopicQos) -> DdsResult<()> {
        let enabled = self.is_enabled();
        let announce = self.with_entry(|t| {
            if let (Some(p), true) = (t.qos.immutable_change(qos), enabled) {
                return Err(DdsError::ImmutablePolicy(p));
            }
            let changed = t.qos.topic_data != qos.topic_data;
            t.qos = qos.clone();
            Ok(changed)
        })??;
        if announce {
            let name = self.name().to_string();
            let endpoints: Vec<_> = self.participant().registry().with(|e| {
                e.writers
                    .iter()
                    .chain(e.readers.iter())
                    .filter(|w| w.topic == name && w.alive())
                    .map(|w| w.entity.clone())
                    .collect()
            });
            for w in endpoints.into_iter().filter_map(|w| w.upgrade()) {
                w.group_changed();
            }
        }
        Ok(())
    }

    /// Installs the topic listener for the statuses in `mask` (`set_listener`).
    pub fn set_listener(
        &self,
        listener: Box<dyn TopicListener>,
        mask: StatusMask,
    ) -> DdsResult<()> {
        let l: Arc<dyn ParentListener> = Arc::new(TopicLevel(Arc::from(listener)));
        self.with_entry(|t| t.node.set_listener(Some((l, mask))))
    }

    /// Removes the topic listener.
    pub fn clear_listener(&self) -> DdsResult<()> {
        self.with_entry(|t| t.node.set_listener(None))
    }

    /// The topic's status condition (INCONSISTENT_TOPIC).
    pub fn status_condition(&self) -> DdsResult<StatusCondition> {
        self.with_entry(|t| StatusCondition {
            core: t.node.status.clone(),
        })
    }

    /// INCONSISTENT_TOPIC (`get_inconsistent_topic_status`; resets the change count).
    pub fn inconsistent_topic_status(&self) -> DdsResult<InconsistentTopicStatus> {
        self.with_entry(|t| {
            let s = t.inconsistent.clone();
            t.inconsistent.total_count_change = 0;
            t.node
                .clear_up(t.node.handle, StatusMask::INCONSISTENT_TOPIC);
            s
        })
    }

    /// Enables the topic (`enable`): `PreconditionNotMet` while its participant is disabled; nothing when
    /// enabled already.
    pub fn enable(&self) -> DdsResult<()> {
        let h = self.instance_handle()?;
        let registry = self.participant().registry();
        if registry.enable(h, &[registry.node.handle])? {
            registry.announce_topics(self.participant().driver());
        }
        Ok(())
    }

    /// Whether the topic is enabled.
    pub fn is_enabled(&self) -> bool {
        self.instance_handle()
            .is_ok_and(|h| self.participant().registry().is_enabled(h))
    }
}

impl DomainParticipant {
    /// Deletes `topic` (`delete_topic`): `PreconditionNotMet` while readers or writers of this participant
    /// use its name.
    pub fn delete_topic<T: DdsType>(&self, topic: &Topic<T>) -> DdsResult<()> {
        self.driver().check_alive()?;
        let ptr = Arc::as_ptr(&topic.inner) as *const ();
        self.registry().with(|e| {
            let in_use = e
                .writers
                .iter()
                .chain(e.readers.iter())
                .any(|w| w.alive() && w.topic == topic.name());
            let Some(t) = e
                .topics
                .iter_mut()
                .find(|t| !t.deleted && same(&t.identity, ptr))
            else {
                return Err(DdsError::AlreadyDeleted);
            };
            if in_use {
                return Err(DdsError::PreconditionNotMet(
                    "the topic has readers or writers",
                ));
            }
            t.deleted = true;
            Ok(())
        })?;
        self.withdraw_topic(ptr);
        Ok(())
    }

    /// Withdraws the SEDP announcement of the topic at `ptr`, if it was announced.
    pub(super) fn withdraw_topic(&self, ptr: *const ()) {
        if let Some(g) = self.registry().take_topic_wire(ptr) {
            if self.driver().check_alive().is_ok() {
                self.driver().with_core(|c, now| c.withdraw_topic(now, g));
            }
        }
    }

    /// The local topic named `name` (`lookup_topicdescription`); `None` when there is none, or it has
    /// another type than `T`.
    pub fn lookup_topicdescription<T: DdsType>(&self, name: &str) -> Option<Topic<T>> {
        self.registry()
            .with(|e| local_topic(&e.topics, name, T::TYPE_NAME))
            .map(topic_from)
    }

    /// `find_topic`: the local topic named `name`, else waits up to `timeout` for a remote reader or writer
    /// on a topic of that name and creates it locally with the default topic QoS. `Timeout` when none
    /// appears; `PreconditionNotMet` when the topic has another type than `T`.
    pub fn find_topic<T: DdsType>(&self, name: &str, timeout: Duration) -> DdsResult<Topic<T>> {
        self.driver().check_alive()?;
        if let Some(t) = self.lookup_topicdescription::<T>(name) {
            return Ok(t);
        }
        let deadline = Instant::now().checked_add(timeout);
        let found = self.registry().wait_for(deadline, |e| {
            if self.driver().check_alive().is_err() {
                return Some(Err(DdsError::AlreadyDeleted));
            }
            e.topics
                .iter()
                .find(|t| !t.deleted && t.name == name)
                .map(|t| t.type_name.clone())
                .or_else(|| e.remote_topics.get(name).map(|t| t.to_string()))
                .map(Ok)
        });
        match found.transpose()? {
            None => Err(DdsError::Timeout),
            Some(ty) if ty != T::TYPE_NAME => {
                Err(DdsError::PreconditionNotMet("the topic has another type"))
            }
            Some(_) => match self.lookup_topicdescription::<T>(name) {
                Some(t) => Ok(t),
                None => self.create_topic::<T>(name, &self.default_topic_qos()),
            },
        }
    }

    /// `create_multitopic`: not supported.
    pub fn create_multitopic(
        &self,
        _name: &str,
        _type_name: &str,
        _expression: &str,
    ) -> DdsResult<()> {
        Err(DdsError::Unsupported(
            "MultiTopic (an optional DCPS profile) is not implemented",
        ))
    }
}

/// The live local topic `name` of type `type_name`.
fn local_topic(topics: &[TopicEntry], name: &str, type_name: &str) -> Option<Arc<TopicInner>> {
    topics
        .iter()
        .filter(|t| !t.deleted && t.name == name && t.type_name == type_name)
        .find_map(|t| t.identity.upgrade()?.downcast::<TopicInner>().ok())
}

fn topic_from<T>(inner: Arc<TopicInner>) -> Topic<T> {
    Topic {
        inner,
        _t: std::marker::PhantomData,
    }
}
