//! The rest of the `DomainParticipant` operations (DDS 1.4 §2.2.2.2.1): QoS, the participant listener,
//! `ignore_*`, `contains_entity`, `delete_contained_entities`, the default QoS of its children and
//! `get_current_time`. The entity-specific ones (`delete_publisher`, `find_topic`, ...) live with their
//! entity.

use std::sync::{Arc, Weak};
use std::time::SystemTime;

use crate::qos::{ChangeableQos, DomainParticipantQos, PublisherQos, SubscriberQos, TopicQos};
use crate::rtps::{EntityId, Guid, GuidPrefix};

use super::super::builtin::{
    topic_key, ParticipantBuiltinTopicData, PublicationBuiltinTopicData,
    SubscriptionBuiltinTopicData,
};
use super::super::chain::{ParentListener, StatusChange};
use super::super::driver::Driver;
use super::super::error::{DdsError, DdsResult};
use super::super::registry::Registry;
use super::super::sample::InstanceHandle;
use super::super::status::*;
use super::super::sync::lock;
use super::DomainParticipant;

/// Callbacks of a [`DomainParticipant`] for the statuses of every entity it contains that no more specific
/// listener is enabled for (DDS 1.4 §2.2.4.1). Entities are identified by their instance handle
/// (`DataWriter::instance_handle`, `Topic::instance_handle`, ...). Every method has an empty default.
#[allow(unused_variables)]
pub trait DomainParticipantListener: Send + Sync {
    /// A remote topic of the same name as a local topic has another type.
    fn on_inconsistent_topic(&self, topic: InstanceHandle, status: InconsistentTopicStatus) {}
    /// A writer matched or unmatched a reader.
    fn on_publication_matched(&self, writer: InstanceHandle, status: PublicationMatchedStatus) {}
    /// A writer found a reader with incompatible QoS.
    fn on_offered_incompatible_qos(&self, writer: InstanceHandle, status: IncompatibleQosStatus) {}
    /// A writer missed its offered deadline.
    fn on_offered_deadline_missed(&self, writer: InstanceHandle, status: DeadlineMissedStatus) {}
    /// A writer did not assert its manual liveliness within its lease.
    fn on_liveliness_lost(&self, writer: InstanceHandle, status: LivelinessLostStatus) {}
    /// A reader matched or unmatched a writer.
    fn on_subscription_matched(&self, reader: InstanceHandle, status: SubscriptionMatchedStatus) {}
    /// A reader found a writer with incompatible QoS.
    fn on_requested_incompatible_qos(&self, reader: InstanceHandle, status: IncompatibleQosStatus) {
    }
    /// A reader missed its requested deadline.
    fn on_requested_deadline_missed(&self, reader: InstanceHandle, status: DeadlineMissedStatus) {}
    /// A reader lost samples.
    fn on_sample_lost(&self, reader: InstanceHandle, status: SampleLostStatus) {}
    /// A reader rejected a sample.
    fn on_sample_rejected(&self, reader: InstanceHandle, status: SampleRejectedStatus) {}
    /// The liveliness of a writer matched by a reader changed.
    fn on_liveliness_changed(&self, reader: InstanceHandle, status: LivelinessChangedStatus) {}
    /// A reader has new data.
    fn on_data_available(&self, reader: InstanceHandle) {}
    /// A subscriber has new data in one of its readers (takes precedence over `on_data_available`).
    fn on_data_on_readers(&self, subscriber: InstanceHandle) {}
}

/// The participant listener as a level of the chain.
struct ParticipantLevel(Arc<dyn DomainParticipantListener>);

impl ParentListener for ParticipantLevel {
    fn on_status(&self, e: InstanceHandle, change: StatusChange) {
        let l = &self.0;
        match change {
            StatusChange::InconsistentTopic(s) => l.on_inconsistent_topic(e, s),
            StatusChange::PublicationMatched(s) => l.on_publication_matched(e, s),
            StatusChange::OfferedIncompatibleQos(s) => l.on_offered_incompatible_qos(e, s),
            StatusChange::OfferedDeadlineMissed(s) => l.on_offered_deadline_missed(e, s),
            StatusChange::LivelinessLost(s) => l.on_liveliness_lost(e, s),
            StatusChange::SubscriptionMatched(s) => l.on_subscription_matched(e, s),
            StatusChange::RequestedIncompatibleQos(s) => l.on_requested_incompatible_qos(e, s),
            StatusChange::RequestedDeadlineMissed(s) => l.on_requested_deadline_missed(e, s),
            StatusChange::SampleLost(s) => l.on_sample_lost(e, s),
            StatusChange::SampleRejected(s) => l.on_sample_rejected(e, s),
            StatusChange::LivelinessChanged(s) => l.on_liveliness_changed(e, s),
            StatusChange::DataAvailable => l.on_data_available(e),
        }
    }
    fn on_data_on_readers(&self, subscriber: InstanceHandle) {
        self.0.on_data_on_readers(subscriber);
    }
}

/// Tells the registry of every remote endpoint discovered, and raises INCONSISTENT_TOPIC on the local
/// topics of the same name with another type.
pub(super) fn install_discovery_hook(driver: &Driver, registry: &Arc<Registry>) {
    let weak: Weak<Registry> = Arc::downgrade(registry);
    driver.set_discovery_hook(Box::new(move |ev| {
        let Some(reg) = weak.upgrade() else { return };
        for (node, status) in reg.on_discovery(ev) {
            tracing::warn!(topic = ?node.handle, "inconsistent topic");
            node.raise_up(node.handle, StatusMask::INCONSISTENT_TOPIC);
            if let Some(l) = node.find(StatusMask::INCONSISTENT_TOPIC) {
                l.on_status(node.handle, StatusChange::InconsistentTopic(status));
            }
        }
    }));
}

impl DomainParticipant {
    /// The participant QoS in effect (`get_qos`).
    pub fn get_qos(&self) -> DomainParticipantQos {
        self.registry.with(|e| e.participant_qos.clone())
    }

    /// Changes the participant QoS (`set_qos`): a new USER_DATA is announced in SPDP at once;
    /// `autoenable_created_entities` applies to the entities created from then on.
    pub fn set_qos(&self, qos: &DomainParticipantQos) -> DdsResult<()> {
        self.driver.check_alive()?;
        let old = self.get_qos();
        if let Some(p) = old.immutable_change(qos) {
            return Err(DdsError::ImmutablePolicy(p));
        }
        if old.user_data != qos.user_data {
            let data = qos.user_data.0.clone();
            self.driver.with_core(|c, _| c.set_user_data(data));
        }
        self.registry.with(|e| e.participant_qos = qos.clone());
        Ok(())
    }

    /// Installs the participant listener, called for the statuses in `mask` of every contained entity that
    /// has no more specific listener enabled for them (`set_listener`).
    pub fn set_listener(&self, listener: Box<dyn DomainParticipantListener>, mask: StatusMask) {
        let l: Arc<dyn ParentListener> = Arc::new(ParticipantLevel(Arc::from(listener)));
        self.registry.node.set_listener(Some((l, mask)));
    }

    /// Removes the participant listener.
    pub fn clear_listener(&self) {
        self.registry.node.set_listener(None);
    }

    /// Enables the participant (`enable`): it starts announcing itself (SPDP) and receiving. With
    /// `autoenable_created_entities`, the topics, publishers and subscribers it created disabled are
    /// enabled too (and their readers and writers as their own QoS says). Nothing when enabled already.
    pub fn enable(&self) -> DdsResult<()> {
        self.driver.check_alive()?;
        if self.registry.enable(self.registry.node.handle, &[])? {
            self.driver.with_core(|c, now| c.set_enabled(now, true));
            if self.get_qos().autoenable_created_entities {
                self.registry.enable_participant_contents();
                self.registry.announce_topics(&self.driver);
            }
        }
        Ok(())
    }

    /// Whether the participant is enabled.
    pub fn is_enabled(&self) -> bool {
        self.registry.is_enabled(self.registry.node.handle)
    }

    /// The current time (`get_current_time`), as source timestamps use it.
    pub fn get_current_time(&self) -> DdsResult<SystemTime> {
        self.driver.check_alive()?;
        Ok(SystemTime::now())
    }

    /// Ignores a remote participant (`ignore_participant`), by the handle of
    /// [`DiscoveredParticipant::handle`](super::DiscoveredParticipant): it and its endpoints are unmatched
    /// and its discovery traffic is dropped from then on. `BadParameter` for an unknown handle or our own.
    pub fn ignore_participant(&self, handle: InstanceHandle) -> DdsResult<()> {
        self.driver.check_alive()?;
        let prefix = self
            .driver
            .discovered_participants()
            .into_iter()
            .find(|p| participant_handle(*p) == handle)
            .ok_or_else(|| {
                DdsError::BadParameter(format!("no discovered participant {handle:?}"))
            })?;
        self.driver.with_core(|c, _| c.ignore_participant(prefix))?;
        Ok(())
    }

    /// Ignores every remote endpoint on the topic `name` (`ignore_topic` by name).
    pub fn ignore_topic(&self, name: &str) -> DdsResult<()> {
        self.driver.check_alive()?;
        self.driver.with_core(|c, _| c.ignore_topic(name))?;
        Ok(())
    }

    /// Ignores a remote topic by its handle (`ignore_topic` as DDS defines it): the instance handle of its
    /// `DCPSTopic` sample (`TopicBuiltinTopicData::key`). `BadParameter` for a topic not discovered.
    pub fn ignore_topic_by_handle(&self, handle: InstanceHandle) -> DdsResult<()> {
        let name = self
            .registry
            .with(|e| {
                e.remote_topics
                    .iter()
                    .find(|(n, t)| topic_key(n, t) == handle)
                    .map(|(n, _)| n.to_string())
            })
            .ok_or_else(|| DdsError::BadParameter(format!("no discovered topic {handle:?}")))?;
        self.ignore_topic(&name)
    }

    /// Ignores a remote writer (`ignore_publication`), by its handle (`SampleInfo::publication_handle`,
    /// `DataReader::matched_publications`): unmatched now, its announcements dropped from then on.
    pub fn ignore_publication(&self, handle: InstanceHandle) -> DdsResult<()> {
        let guid = self.remote_endpoint(handle, true)?;
        self.driver.with_core(|c, _| c.ignore_endpoint(guid))?;
        Ok(())
    }

    /// Ignores a remote reader (`ignore_subscription`), like [`ignore_publication`](Self::ignore_publication).
    pub fn ignore_subscription(&self, handle: InstanceHandle) -> DdsResult<()> {
        let guid = self.remote_endpoint(handle, false)?;
        self.driver.with_core(|c, _| c.ignore_endpoint(guid))?;
        Ok(())
    }

    /// The GUID of the known remote writer (or reader) with this handle.
    fn remote_endpoint(&self, handle: InstanceHandle, writer: bool) -> DdsResult<Guid> {
        self.driver.check_alive()?;
        let own = self.driver.guid_prefix;
        let find = |g: Guid| g.prefix != own && InstanceHandle::from_guid(g) == handle;
        let guid = self.driver.with_core(|c, _| {
            if writer {
                c.publications().map(|d| d.guid).find(|g| find(*g))
            } else {
                c.subscriptions().map(|d| d.guid).find(|g| find(*g))
            }
        });
        guid.ok_or_else(|| DdsError::BadParameter(format!("no remote endpoint {handle:?}")))
    }

    /// Whether `handle` designates an entity this participant contains: one of its topics, publishers,
    /// subscribers, or their readers and writers (`contains_entity`).
    pub fn contains_entity(&self, handle: InstanceHandle) -> bool {
        self.registry.with(|e| {
            e.topics
                .iter()
                .any(|t| !t.deleted && t.node.handle == handle)
                || e.publishers
                    .iter()
                    .any(|g| !g.deleted && g.node.handle == handle)
                || e.subscribers
                    .iter()
                    .any(|g| !g.deleted && g.node.handle == handle)
                || e.writers
                    .iter()
                    .chain(e.readers.iter())
                    .any(|w| w.alive() && InstanceHandle::from_guid(w.guid) == handle)
        })
    }

    /// Whether a topic, publisher, subscriber, reader or writer of this participant still exists.
    /// The built-in subscriber and its readers and topics are not among them.
    pub(super) fn has_contained_entities(&self) -> bool {
        let builtin = self.builtin_subscriber_handle();
        self.registry.with(|e| {
            e.topics.iter().any(|t| !t.deleted && !t.builtin)
                || e.publishers.iter().any(|g| !g.deleted)
                || e.subscribers
                    .iter()
                    .any(|g| !g.deleted && Some(g.node.handle) != builtin)
                || e.writers
                    .iter()
                    .chain(e.readers.iter())
                    .any(|w| w.alive() && Some(w.group) != builtin)
        })
    }

    /// The handle of the built-in subscriber, once created.
    fn builtin_subscriber_handle(&self) -> Option<InstanceHandle> {
        lock(&self.registry.builtin)
            .as_ref()
            .map(|f| f.group_handle())
    }

    /// Deletes every reader, writer, publisher, subscriber and topic of the participant
    /// (`delete_contained_entities`): writers unregister their instances and leave SEDP, readers leave
    /// SEDP; handles still held return `AlreadyDeleted` from then on.
    pub fn delete_contained_entities(&self) -> DdsResult<()> {
        self.driver.check_alive()?;
        let builtin = self.builtin_subscriber_handle();
        let ids: Vec<EntityId> = self.registry.with(|e| {
            e.publishers.iter_mut().for_each(|g| g.deleted = true);
            e.subscribers
                .iter_mut()
                .filter(|g| Some(g.node.handle) != builtin)
                .for_each(|g| g.deleted = true);
            e.topics
                .iter_mut()
                .filter(|t| !t.builtin)
                .for_each(|t| t.deleted = true);
            e.writers
                .iter()
                .chain(e.readers.iter())
                .filter(|w| Some(w.group) != builtin)
                .map(|w| w.guid.entity_id)
                .collect()
        });
        let endpoints = self.registry.mark_deleted(&ids);
        for id in endpoints {
            self.driver.delete_endpoint(id);
        }
        Ok(())
    }

    /// Sets the QoS new publishers get from [`PublisherQos::default`]-less creation
    /// (`set_default_publisher_qos`); see [`default_publisher_qos`](Self::default_publisher_qos).
    pub fn set_default_publisher_qos(&self, qos: &PublisherQos) -> DdsResult<()> {
        self.registry
            .with(|e| e.default_publisher_qos = qos.clone());
        Ok(())
    }

    /// The default publisher QoS (`get_default_publisher_qos`), to pass to `create_publisher`.
    pub fn default_publisher_qos(&self) -> PublisherQos {
        self.registry.with(|e| e.default_publisher_qos.clone())
    }

    /// Sets the default subscriber QoS (`set_default_subscriber_qos`).
    pub fn set_default_subscriber_qos(&self, qos: &SubscriberQos) -> DdsResult<()> {
        self.registry
            .with(|e| e.default_subscriber_qos = qos.clone());
        Ok(())
    }

    /// The default subscriber QoS (`get_default_subscriber_qos`), to pass to `create_subscriber`.
    pub fn default_subscriber_qos(&self) -> SubscriberQos {
        self.registry.with(|e| e.default_subscriber_qos.clone())
    }

    /// Sets the default topic QoS (`set_default_topic_qos`).
    pub fn set_default_topic_qos(&self, qos: &TopicQos) -> DdsResult<()> {
        self.registry.with(|e| e.default_topic_qos = qos.clone());
        Ok(())
    }

    /// The default topic QoS (`get_default_topic_qos`), to pass to `create_topic`.
    pub fn default_topic_qos(&self) -> TopicQos {
        self.registry.with(|e| e.default_topic_qos.clone())
    }

    /// What SPDP announced about the discovered participant `handle` (`get_discovered_participant_data`);
    /// `BadParameter` for an unknown handle.
    pub fn get_discovered_participant_data(
        &self,
        handle: InstanceHandle,
    ) -> DdsResult<ParticipantBuiltinTopicData> {
        self.driver.check_alive()?;
        self.driver
            .with_core(|c, _| {
                c.discovered_participants()
                    .find(|p| participant_handle(p.guid_prefix) == handle)
                    .map(|p| ParticipantBuiltinTopicData::from(&p))
            })
            .ok_or_else(|| DdsError::BadParameter(format!("no discovered participant {handle:?}")))
    }

    /// The remote topics discovered through their readers and writers, as (name, type name)
    /// (`get_discovered_topics` and `get_discovered_topic_data`; SEDP topic announcements are not used).
    pub fn discovered_topics(&self) -> Vec<(String, String)> {
        let mut v: Vec<(String, String)> = self.registry.with(|e| {
            e.remote_topics
                .iter()
                .map(|(n, t)| (n.to_string(), t.to_string()))
                .collect()
        });
        v.sort();
        v
    }

    /// What SPDP announced about every participant discovered so far.
    pub fn discovered_participant_data(&self) -> Vec<ParticipantBuiltinTopicData> {
        self.driver.with_core(|c, _| {
            c.discovered_participants()
                .map(|p| ParticipantBuiltinTopicData::from(&p))
                .collect()
        })
    }

    /// Every publication known, remote and local, matched or not (the DCPSPublication built-in topic's
    /// content).
    pub fn discovered_publications(&self) -> Vec<PublicationBuiltinTopicData> {
        self.driver.with_core(|c, _| {
            c.publications()
                .map(PublicationBuiltinTopicData::from)
                .collect()
        })
    }

    /// Every subscription known, remote and local, matched or not (the DCPSSubscription built-in topic's
    /// content).
    pub fn discovered_subscriptions(&self) -> Vec<SubscriptionBuiltinTopicData> {
        self.driver.with_core(|c, _| {
            c.subscriptions()
                .map(SubscriptionBuiltinTopicData::from)
                .collect()
        })
    }

    /// The handles of the remote participants discovered (`get_discovered_participants`).
    pub fn discovered_participant_handles(&self) -> Vec<InstanceHandle> {
        self.driver
            .discovered_participants()
            .into_iter()
            .map(participant_handle)
            .collect()
    }
}

fn participant_handle(p: GuidPrefix) -> InstanceHandle {
    InstanceHandle::from_guid(Guid::new(p, EntityId::PARTICIPANT))
}
