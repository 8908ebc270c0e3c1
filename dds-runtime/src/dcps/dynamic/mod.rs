//! Dynamic topics, writers and readers: endpoints whose type is a [`DynamicType`] known only at run time.
//!
//! They take part in discovery and matching exactly as typed endpoints do: the same topic and type names, the
//! same keyedness, the same data representation rules, and the same `TypeInformation` when the topic has it
//! (a type built from discovered type objects keeps the bytes it came with; see
//! [`DynamicTopic::with_type_information`]). Samples are [`DynamicData`], byte-identical on the wire to the
//! derived code for the same type. Listeners, conditions, instances and read/take by state are left to the
//! typed API: a dynamic writer writes and disposes, a dynamic reader takes what arrived.

mod reader;
mod writer;

use std::sync::{Arc, Mutex};

use crate::qos::TopicQos;
use crate::xtypes::dynamic::{DynamicData, DynamicType};

use super::error::{DdsError, DdsResult};
use super::participant::DomainParticipant;
use super::sync::lock;
use crate::rtps::Guid;

pub use reader::{DynamicReader, DynamicSample};
pub use writer::DynamicWriter;

struct TopicInner {
    participant: DomainParticipant,
    name: String,
    ty: DynamicType,
    qos: TopicQos,
    type_information: Option<Vec<u8>>,
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
        Ok(DynamicTopic {
            inner: Arc::new(TopicInner {
                participant: self.clone(),
                name: name.to_string(),
                ty,
                qos: qos.clone(),
                type_information: None,
            }),
        })
    }
}

impl DynamicTopic {
    /// The same topic announcing these XCDR2 `TypeInformation` bytes for its endpoints (when type information
    /// is announced at all: `xtypes::announce_type_information`), e.g. the bytes a discovered endpoint
    /// announced for the type objects this type was built from.
    pub fn with_type_information(self, bytes: Vec<u8>) -> Self {
        let i = &self.inner;
        DynamicTopic {
            inner: Arc::new(TopicInner {
                participant: i.participant.clone(),
                name: i.name.clone(),
                ty: i.ty.clone(),
                qos: i.qos.clone(),
                type_information: Some(bytes),
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

    fn type_information(&self) -> Option<crate::xtypes::TypeInformation> {
        crate::xtypes::announced_type_information(self.inner.type_information.as_deref())
    }
}

/// Records that `peer` matched (or unmatched) an endpoint whose matched peers are `list`.
fn record_match(list: &Mutex<Vec<Guid>>, peer: Guid, matched: bool) {
    let mut m = lock(list);
    m.retain(|g| *g != peer);
    if matched {
        m.push(peer);
    }
}
