//! Types through discovery: the participant's type store (our endpoints' types, and those learnt through the
//! XTypes TypeLookup service), and the resolution of a discovered type, waiting for the service's answers.

use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::cdr::DdsType;
use crate::rtps::Participant;
use crate::xtypes::store::is_lookup_id;
use crate::xtypes::typeobject::{TypeIdentifier, TypeInformation, TypeObject};

use super::super::error::{DdsError, DdsResult};
use super::DomainParticipant;

/// How often a resolution looks at the store again (and asks again for what is still missing).
const POLL: Duration = Duration::from_millis(20);

/// The type of a discovered topic, resolved through the TypeLookup service: its `TypeInformation` and the
/// complete type object of the topic type and of every type it depends on.
#[derive(Debug, Clone)]
pub struct DiscoveredType {
    /// The topic.
    pub topic_name: String,
    /// The type name the endpoint announced.
    pub type_name: String,
    /// The `TypeInformation` it announced.
    pub information: TypeInformation,
    /// The complete object of the topic type first, then those of its dependencies, as announced.
    pub complete: Vec<(TypeIdentifier, Arc<TypeObject>)>,
}

impl DiscoveredType {
    /// The complete object of the topic type.
    pub fn top(&self) -> &Arc<TypeObject> {
        &self.complete[0].1
    }

    /// The complete object of `id`, if it is the topic type or one of its dependencies.
    pub fn object(&self, id: &TypeIdentifier) -> Option<&Arc<TypeObject>> {
        self.complete.iter().find(|(i, _)| i == id).map(|(_, o)| o)
    }
}

/// Puts the type objects of `T` into the core's store, so that the TypeLookup service answers for them.
pub(crate) fn register_local_types<T: DdsType>(core: &mut Participant) {
    register_type_bytes(core, T::TYPE_NAME, T::type_information(), T::type_mapping());
}

/// Puts the type objects of a type (its XCDR2 `TypeInformation` and `TypeMapping`) into the core's store.
pub(crate) fn register_type_bytes(
    core: &mut Participant,
    type_name: &str,
    information: Option<&[u8]>,
    mapping: Option<&[u8]>,
) {
    if let (Some(info), Some(mapping)) = (information, mapping) {
        if let Err(e) = core.register_types(info, mapping) {
            tracing::warn!(type_name, error = %e, "type objects not registered");
        }
    }
}

/// The complete identifiers a `TypeInformation` names: the topic type, then its listed dependencies (hashes,
/// and strongly connected components).
fn complete_ids(info: &TypeInformation) -> Vec<TypeIdentifier> {
    std::iter::once(&info.complete.typeid_with_size)
        .chain(&info.complete.dependent_typeids)
        .map(|t| t.type_id.clone())
        .filter(is_lookup_id)
        .collect()
}

impl DomainParticipant {
    /// The type object of `id` if the participant has it: a type of one of our endpoints, or one learnt
    /// through the TypeLookup service. Does not wait and sends nothing.
    pub fn type_object(&self, id: &TypeIdentifier) -> Option<Arc<TypeObject>> {
        self.driver().query_core(|c| c.type_store().get(id))
    }

    /// The type object of `id`, asked of every discovered participant's TypeLookup service if we lack it;
    /// each answer's hash is checked before it is kept. `Timeout` if no participant answered in `timeout`.
    pub fn discovered_type(
        &self,
        id: &TypeIdentifier,
        timeout: Duration,
    ) -> DdsResult<Arc<TypeObject>> {
        if id.hash().is_none() {
            return Err(DdsError::BadParameter(format!(
                "{id:?} is not a hashed type identifier"
            )));
        }
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(o) = self.type_object(id) {
                return Ok(o);
            }
            self.driver()
                .with_core(|c, now| c.request_types(now, [id.clone()]));
            wait_until(deadline)?;
        }
    }

    /// The type of `topic`, from the first discovered writer or reader of it that announced type information
    /// (waiting up to `timeout` for one), with the complete objects of the type and its dependencies resolved
    /// through the TypeLookup service. `Timeout` when no endpoint of the topic announced type information, or
    /// its types were not all received, in time.
    pub fn discovered_topic_type(
        &self,
        topic: &str,
        timeout: Duration,
    ) -> DdsResult<DiscoveredType> {
        let deadline = Instant::now() + timeout;
        let (type_name, information) = loop {
            if let Some(found) = self.driver().query_core(|c| announced_type(c, topic)) {
                break found;
            }
            wait_until(deadline)?;
        };
        let ids = complete_ids(&information);
        let truncated = usize::try_from(information.complete.dependent_typeid_count)
            .is_ok_and(|n| n > information.complete.dependent_typeids.len());
        let top = information.complete.typeid_with_size.type_id.clone();
        loop {
            let mut wanted = ids.clone();
            if truncated {
                // The list was cut short: ask for the rest, and for whatever those name.
                let more = self.driver().query_core(|c| {
                    c.type_store()
                        .dependencies(&top)
                        .iter()
                        .map(|t| t.type_id.clone())
                        .collect::<Vec<_>>()
                });
                wanted.extend(more);
            }
            // A component's id gives the objects of all its types.
            let objects: Vec<_> = self.driver().query_core(|c| {
                wanted
                    .iter()
                    .map(|id| c.type_store().objects_of(id))
                    .collect()
            });
            if objects.iter().all(Option::is_some) {
                let mut complete: Vec<(TypeIdentifier, Arc<TypeObject>)> = Vec::new();
                for (id, o) in objects.into_iter().flatten().flatten() {
                    if !complete.iter().any(|(i, _)| i == &id) {
                        complete.push((id, o));
                    }
                }
                return Ok(DiscoveredType {
                    topic_name: topic.to_string(),
                    type_name,
                    information,
                    complete,
                });
            }
            self.driver().with_core(|c, now| {
                if truncated {
                    c.request_type_dependencies(now, top.clone());
                }
                c.request_types(now, wanted);
            });
            wait_until(deadline)?;
        }
    }
}

/// Sleeps one poll interval, or fails with `Timeout` once `deadline` has passed.
fn wait_until(deadline: Instant) -> DdsResult<()> {
    let now = Instant::now();
    if now >= deadline {
        return Err(DdsError::Timeout);
    }
    std::thread::sleep(POLL.min(deadline - now));
    Ok(())
}

/// The type name and decoded `TypeInformation` of a known endpoint of `topic` that announced one.
fn announced_type(c: &Participant, topic: &str) -> Option<(String, TypeInformation)> {
    let writers = c
        .publications()
        .map(|d| (&d.topic_name, &d.type_name, &d.type_information));
    let readers = c
        .subscriptions()
        .map(|d| (&d.topic_name, &d.type_name, &d.type_information));
    writers
        .chain(readers)
        .filter(|(t, _, _)| t.as_str() == topic)
        .find_map(|(_, name, ti)| Some((name.clone(), ti.as_ref()?.decode().ok()?)))
}
