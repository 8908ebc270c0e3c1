//! Dynamic topics, writers and readers: endpoints whose type is a [`DynamicType`] known only at run time.
//!
//! They take part in discovery and matching exactly as typed endpoints do: the same topic and type names, the
//! same keyedness, the same data representation rules, and a `TypeInformation` built from the dynamic type
//! ([`DynamicType::type_support`], the derive's builder), so that they match peers by assignability and the
//! TypeLookup service serves their type objects ([`DynamicTopic::with_type_information`] announces other
//! bytes instead). Samples are [`DynamicData`], byte-identical on the wire to the
//! derived code for the same type. A dynamic reader runs on the typed reader's machinery: instances, read/take
//! by state, read and query conditions, statuses, a listener ([`DynamicReaderListener`]) and a status
//! condition. A dynamic writer writes and disposes, with the typed writer's statuses, a listener
//! ([`DynamicWriterListener`]) and a status condition.

mod reader;
mod writer;

use std::sync::Arc;

use crate::qos::TopicQos;
use crate::xtypes::dynamic::{DynamicData, DynamicType};

use super::error::{DdsError, DdsResult};
use super::participant::DomainParticipant;

pub use reader::{DynamicReader, DynamicReaderListener, DynamicSample};
pub use writer::{DynamicWriter, DynamicWriterListener};

struct TopicInner {
    participant: DomainParticipant,
    name: String,
    ty: DynamicType,
    qos: TopicQos,
    /// The XCDR2 `TypeInformation` its endpoints announce, and the `TypeMapping` (when known) whose
    /// objects the participant serves.
    type_information: Option<Vec<u8>>,
    type_mapping: Option<Vec<u8>>,
}

/// A topic of a dynamic type. Cheap to clone.
#[derive(Clone)]
pub struct DynamicTopic {
    inner: Arc<TopicInner>,
}

impl std::fmt::Debug for DynamicTopic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DynamicTopic")
            .field("name", &self.inner.name)
            .field("type", &self.inner.ty)
            .finish()
    }
}

impl DomainParticipant {
    /// Creates a topic whose type is `ty` (a struct or union: its scoped name is the topic's type name).
    pub fn create_dynamic_topic(
        &self,
        name: &str,
        ty: DynamicType,
        qos: &TopicQos,
    ) -> DdsResult<DynamicTopic> {
        self.driver().check_alive()?;
        if ty.as_struct().is_none() && ty.as_union().is_none() {
            return Err(DdsError::BadParameter(format!(
                "{} is not a struct or union",
                ty.name()
            )));
        }
        let (type_information, type_mapping) = match ty.type_support() {
            Ok(s) => (Some(s.information_bytes), Some(s.mapping_bytes)),
            Err(e) => {
                tracing::warn!(topic = name, type_name = %ty.name(), error = %e,
                    "no type objects: endpoints announce no type information and match by type name");
                (None, None)
            }
        };
        Ok(DynamicTopic {
            inner: Arc::new(TopicInner {
                participant: self.clone(),
                name: name.to_string(),
                ty,
                qos: qos.clone(),
                type_information,
                type_mapping,
            }),
        })
    }
}

impl DynamicTopic {
    /// The same topic announcing these XCDR2 `TypeInformation` bytes for its endpoints (when type information
    /// is announced at all: `xtypes::announce_type_information`) instead of those built from its type, e.g.
    /// the bytes a discovered endpoint announced for the type objects this type was built from (the
    /// participant then serves no objects for it).
    pub fn with_type_information(self, bytes: Vec<u8>) -> Self {
        let i = &self.inner;
        DynamicTopic {
            inner: Arc::new(TopicInner {
                participant: i.participant.clone(),
                name: i.name.clone(),
                ty: i.ty.clone(),
                qos: i.qos.clone(),
                type_information: Some(bytes),
                type_mapping: None,
            }),
        }
    }

    /// The topic name.
    pub fn name(&self) -> &str {
        &self.inner.name
    }

    /// The type.
    pub fn dynamic_type(&self) -> &DynamicType {
        &self.inner.ty
    }

    /// The type name announced in discovery.
    pub fn type_name(&self) -> String {
        self.inner.ty.resolved().name()
    }

    /// The topic QoS.
    pub fn qos(&self) -> &TopicQos {
        &self.inner.qos
    }

    /// The participant.
    pub fn participant(&self) -> &DomainParticipant {
        &self.inner.participant
    }

    /// A sample of the topic's type with every member at its default.
    pub fn new_sample(&self) -> DynamicData {
        DynamicData::new(self.inner.ty.clone())
    }

    /// The XCDR2 `TypeInformation` bytes its endpoints announce (when type information is announced at all).
    pub fn type_information_bytes(&self) -> Option<&[u8]> {
        self.inner.type_information.as_deref()
    }

    fn type_information(&self) -> Option<crate::xtypes::TypeInformation> {
        match &self.inner.type_mapping {
            Some(m) => crate::xtypes::announced_type_information_for(
                self.inner.type_information.as_deref(),
                Some(m),
            ),
            None => {
                crate::xtypes::announced_type_information(self.inner.type_information.as_deref())
            }
        }
    }

    /// Puts the type's objects into the participant's store (for its TypeLookup service).
    fn register_types(&self, core: &mut crate::rtps::Participant) {
        super::participant::register_type_bytes(
            core,
            &self.type_name(),
            self.inner.type_information.as_deref(),
            self.inner.type_mapping.as_deref(),
        );
    }
}
