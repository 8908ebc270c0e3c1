//! Enabled and disabled entities (DDS 1.4 §2.2.2.1.1.7, ENTITY_FACTORY.autoenable_created_entities).
//!
//! An entity created by a factory (participant factory, participant, publisher, subscriber) whose QoS has
//! `autoenable_created_entities = false`, or by a factory that is itself disabled, starts disabled. A
//! disabled participant neither sends nor receives; a disabled reader or writer is not announced in SEDP
//! and matches nothing. `enable()` fails with `PreconditionNotMet` while the entity's factory (and, for a
//! reader or writer, its topic) is disabled; enabling a factory whose QoS autoenables also enables what it
//! created disabled. Operations other than QoS, listeners, status conditions, `enable` and the factory
//! operations return `NotEnabled` on a disabled entity.
//!
//! The registry keeps the handles of the disabled participant, topics, publishers and subscribers;
//! readers and writers keep their own flag (checked on their hot paths) in their endpoint state.

use super::driver::Driver;
use super::error::{DdsError, DdsResult};
use super::registry::{Entities, GroupQos, Registry};
use super::sample::InstanceHandle;

impl Registry {
    /// Whether the participant, topic, publisher or subscriber `h` is enabled.
    pub(crate) fn is_enabled(&self, h: InstanceHandle) -> bool {
        self.with(|e| !e.disabled.contains(&h))
    }

    /// Whether a child created now by the factory `parent` (whose QoS has `autoenable`) starts enabled;
    /// when it does not and `child` is a participant, topic, publisher or subscriber, it is recorded
    /// disabled.
    pub(crate) fn create_child(
        &self,
        parent: InstanceHandle,
        autoenable: bool,
        child: Option<InstanceHandle>,
    ) -> bool {
        self.with(|e| {
            let enabled = autoenable && !e.disabled.contains(&parent);
            if let (false, Some(c)) = (enabled, child) {
                e.disabled.insert(c);
            }
            enabled
        })
    }

    /// Enables `h` (`PreconditionNotMet` while one of `parents` is disabled). Whether it was disabled.
    pub(crate) fn enable(&self, h: InstanceHandle, parents: &[InstanceHandle]) -> DdsResult<bool> {
        self.check_parents_enabled(parents)?;
        Ok(self.with(|e| e.disabled.remove(&h)))
    }

    /// The participant was enabled and autoenables: enables the topics, publishers and subscribers it
    /// created disabled, and their readers and writers as their QoS says.
    pub(crate) fn enable_participant_contents(&self) {
        let participant = self.node.handle;
        let (topics, pubs, subs) = self.with(|e| {
            let topics: Vec<InstanceHandle> = e.topics.iter().map(|t| t.node.handle).collect();
            (
                topics,
                disabled_groups(e, &e.publishers),
                disabled_groups(e, &e.subscribers),
            )
        });
        for t in topics {
            let _ = self.enable(t, &[participant]);
        }
        for (g, auto) in pubs {
            if self.enable(g, &[participant]).is_ok() && auto {
                self.enable_group_children::<crate::qos::PublisherQos>(g);
            }
        }
        for (g, auto) in subs {
            if self.enable(g, &[participant]).is_ok() && auto {
                self.enable_group_children::<crate::qos::SubscriberQos>(g);
            }
        }
    }

    /// Enables the publisher or subscriber at `ptr` (`enable`): `PreconditionNotMet` while the participant
    /// is disabled; with `autoenable_created_entities`, its readers or writers created disabled too.
    pub(crate) fn enable_group<Q: GroupQos>(&self, ptr: *const ()) -> DdsResult<()> {
        let (g, auto) = self.with_group::<Q, _>(ptr, |g| (g.node.handle, g.qos.autoenable()))?;
        if self.enable(g, &[self.node.handle])? && auto {
            self.enable_group_children::<Q>(g);
        }
        Ok(())
    }

    /// Enables the readers or writers of the group `g` that were created disabled (their topics
    /// permitting).
    pub(crate) fn enable_group_children<Q: GroupQos>(&self, g: InstanceHandle) {
        for c in self.children::<Q>(g) {
            if let Some(entity) = c.entity.upgrade() {
                if let Err(e) = entity.enable() {
                    tracing::debug!(error = %e, "contained entity not enabled");
                }
            }
        }
    }
}

/// The publishers or subscribers in `groups` that are disabled, with their autoenable setting.
fn disabled_groups<Q: GroupQos, C>(
    e: &Entities,
    groups: &[super::registry::Group<Q, C>],
) -> Vec<(InstanceHandle, bool)> {
    groups
        .iter()
        .filter(|g| !g.deleted)
        .map(|g| (g.node.handle, g.qos.autoenable()))
        .filter(|(h, _)| e.disabled.contains(h))
        .collect()
}

impl Registry {
    /// Announces in SEDP (DCPSTopic) every enabled topic not announced yet.
    pub(crate) fn announce_topics(&self, driver: &Driver) {
        let todo: Vec<(InstanceHandle, String, String, Vec<u8>)> = self.with(|e| {
            e.topics
                .iter()
                .filter(|t| {
                    !t.deleted
                        && !t.builtin
                        && t.wire.is_none()
                        && !e.disabled.contains(&t.node.handle)
                })
                .map(|t| {
                    let data = t.qos.topic_data.0.clone();
                    (t.node.handle, t.name.clone(), t.type_name.clone(), data)
                })
                .collect()
        });
        for (h, name, type_name, data) in todo {
            match driver.with_core(|c, now| c.announce_topic(now, &name, &type_name, data)) {
                Ok(g) => self.with(|e| {
                    if let Some(t) = e.topics.iter_mut().find(|t| t.node.handle == h) {
                        t.wire = Some(g);
                    }
                }),
                Err(err) => tracing::debug!(error = %err, topic = %name, "topic not announced"),
            }
        }
    }

    /// Records a topic, publisher or subscriber just created by the participant: disabled when the
    /// participant is, or its QoS does not autoenable.
    pub(crate) fn created_by_participant(&self, child: InstanceHandle) {
        let participant = self.node.handle;
        let auto = self.with(|e| e.participant_qos.autoenable_created_entities);
        self.create_child(participant, auto, Some(child));
    }

    /// Whether a reader or writer created now by the group at `ptr` starts enabled.
    pub(crate) fn group_creates_enabled<Q: GroupQos>(&self, ptr: *const ()) -> DdsResult<bool> {
        let (g, auto) = self.with_group::<Q, _>(ptr, |g| (g.node.handle, g.qos.autoenable()))?;
        Ok(self.create_child(g, auto, None))
    }

    /// `PreconditionNotMet` while one of `parents` is disabled.
    pub(crate) fn check_parents_enabled(&self, parents: &[InstanceHandle]) -> DdsResult<()> {
        self.with(|e| {
            if parents.iter().any(|p| e.disabled.contains(p)) {
                Err(DdsError::PreconditionNotMet(
                    "the entity's factory or topic is not enabled",
                ))
            } else {
                Ok(())
            }
        })
    }

    /// `NotEnabled` while the participant is disabled.
    pub(crate) fn check_participant_enabled(&self) -> DdsResult<()> {
        if self.is_enabled(self.node.handle) {
            Ok(())
        } else {
            Err(DdsError::NotEnabled)
        }
    }
}
