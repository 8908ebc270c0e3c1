//! "What is the type of topic T": from an IDL file, or from discovery. The discovery side finds the topic's
//! type name and the `TypeInformation` its endpoints announce, then fetches the complete type objects of the
//! type and its dependencies from the peer through the XTypes TypeLookup service
//! ([`DomainParticipant::discovered_topic_type`]) and builds a `DynamicType` from them.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::{Duration, Instant};

use dds_runtime::prelude::*;
use dds_runtime::xtypes::dynamic::{types_from_idl_file, DynamicType, IdlOptions};
use dds_runtime::xtypes::typeobject::TypeIdentifier;
use dds_runtime::xtypes::TypeInformation;

/// The type a topic is read or written with.
pub(crate) struct Resolved {
    /// The type.
    pub(crate) ty: DynamicType,
    /// The `TypeInformation` bytes to announce with it, when they came from discovery.
    pub(crate) type_information: Option<Vec<u8>>,
}

/// Something that can tell the type of a topic.
pub(crate) trait TopicTypes {
    /// The type of `topic`, or why it cannot be known.
    fn resolve(&self, topic: &str) -> Result<Resolved, String>;
}

/// What discovery says about a topic: its type name and the type information its endpoints announced.
pub(crate) struct DiscoveredTypes<'a> {
    participant: &'a DomainParticipant,
    wait: Duration,
}

/// The type name (and type information, if any) discovered for a topic.
pub(crate) struct DiscoveredTopic {
    pub(crate) type_name: String,
    pub(crate) type_information: Option<TypeInformation>,
}

impl<'a> DiscoveredTypes<'a> {
    /// Discovery through `participant`, waiting up to `wait` for an endpoint of the topic.
    pub(crate) fn new(participant: &'a DomainParticipant, wait: Duration) -> Self {
        DiscoveredTypes { participant, wait }
    }

    /// The topic's type name and type information, once a writer or reader of it is discovered.
    pub(crate) fn topic(&self, topic: &str) -> Option<DiscoveredTopic> {
        let end = Instant::now() + self.wait;
        loop {
            let p = self.participant;
            let found = p
                .discovered_publications()
                .into_iter()
                .filter(|x| x.topic_name == topic)
                .map(|x| (x.type_name, x.type_information))
                .chain(
                    p.discovered_subscriptions()
                        .into_iter()
                        .filter(|x| x.topic_name == topic)
                        .map(|x| (x.type_name, x.type_information)),
                )
                .max_by_key(|(_, ti)| ti.is_some());
            if let Some((type_name, type_information)) = found {
                return Some(DiscoveredTopic {
                    type_name,
                    type_information,
                });
            }
            if Instant::now() >= end {
                return None;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// The topic's type as a `DynamicType`, from the complete type objects fetched through the TypeLookup
    /// service (the topic type and its dependencies, each checked against its hash).
    fn type_objects(&self, topic: &str) -> Result<DynamicType, String> {
        let d = self
            .participant
            .discovered_topic_type(topic, self.wait)
            .map_err(|e| {
                format!("the TypeLookup service did not give the type objects of {topic:?}: {e}")
            })?;
        let id = d.information.complete.typeid_with_size.type_id.clone();
        let lookup = |i: &TypeIdentifier| {
            d.object(i)
                .cloned()
                .or_else(|| self.participant.type_object(i))
        };
        DynamicType::from_type_identifier(&id, &lookup)
            .map_err(|e| format!("the discovered type of {topic:?} cannot be used: {e}"))
    }
}

impl TopicTypes for DiscoveredTypes<'_> {
    fn resolve(&self, topic: &str) -> Result<Resolved, String> {
        let d = self.topic(topic).ok_or_else(|| {
            format!(
                "no writer or reader of topic {topic:?} discovered within {:?}",
                self.wait
            )
        })?;
        let Some(info) = d.type_information else {
            return Err(format!(
                "topic {topic:?} (type {}) announces no XTypes type information (Fast DDS 2.9 and older peers do \
                 not): give the type with --idl FILE",
                d.type_name
            ));
        };
        let ty = self
            .type_objects(topic)
            .map_err(|e| format!("{e} (type {}); give the type with --idl FILE", d.type_name))?;
        Ok(Resolved {
            ty,
            type_information: Some(info.0),
        })
    }
}

/// Types from an IDL file; the topic's type is `--type`, else the discovered type name, else the file's only
/// struct.
pub(crate) struct IdlTypes<'a> {
    types: BTreeMap<String, DynamicType>,
    type_name: Option<String>,
    discovery: DiscoveredTypes<'a>,
}

impl<'a> IdlTypes<'a> {
    /// Compiles `path` (its directory is on the include path).
    pub(crate) fn load(
        path: &Path,
        type_name: Option<String>,
        discovery: DiscoveredTypes<'a>,
    ) -> Result<Self, String> {
        let mut opts = IdlOptions::default();
        if let Some(dir) = path.parent() {
            opts.include_dirs.push(dir.to_path_buf());
        }
        let types =
            types_from_idl_file(path, &opts).map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(IdlTypes {
            types,
            type_name,
            discovery,
        })
    }

    fn pick(&self, name: &str) -> Result<DynamicType, String> {
        let bare = name.trim_start_matches("::");
        self.types.get(bare).cloned().ok_or_else(|| {
            format!(
                "the IDL declares no type {bare:?} (it has: {})",
                self.candidates().join(", ")
            )
        })
    }

    fn candidates(&self) -> Vec<String> {
        self.types
            .iter()
            .filter(|(_, t)| t.as_struct().is_some() || t.as_union().is_some())
            .map(|(n, _)| n.clone())
            .collect()
    }
}

impl TopicTypes for IdlTypes<'_> {
    fn resolve(&self, topic: &str) -> Result<Resolved, String> {
        if let Some(n) = &self.type_name {
            return self.pick(n).map(|ty| Resolved {
                ty,
                type_information: None,
            });
        }
        let structs = self.candidates();
        if let [only] = structs.as_slice() {
            return self.pick(only).map(|ty| Resolved {
                ty,
                type_information: None,
            });
        }
        match self.discovery.topic(topic) {
            Some(d) => self.pick(&d.type_name).map(|ty| Resolved { ty, type_information: None }),
            None => Err(format!(
                "topic {topic:?} not discovered, and the IDL has several types ({}): choose one with --type",
                structs.join(", ")
            )),
        }
    }
}
