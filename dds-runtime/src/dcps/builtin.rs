//! The built-in topic data (DDS 1.4 §2.2.5) that `get_matched_publication_data`,
//! `get_matched_subscription_data` and `get_discovered_participant_data` return: what discovery announced
//! about a remote entity.

use crate::qos::{ReaderQos, WriterQos};
use crate::rtps::discovery::{EndpointData, ParticipantData};
use crate::rtps::{EntityId, Guid, GuidPrefix, VendorId};
use crate::xtypes::TypeInformation;

use super::sample::InstanceHandle;

/// DCPSPublication or DCPSSubscription: a writer (`Q` = [`WriterQos`]) or reader (`Q` = [`ReaderQos`]) as
/// SEDP announced it. The two directions differ only in their QoS; use the aliases
/// [`PublicationBuiltinTopicData`] and [`SubscriptionBuiltinTopicData`]. (The core's `EndpointData<Q>` is the
/// wire form: it also carries locators, inline-QoS expectations and the content filter.)
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct EndpointBuiltinTopicData<Q> {
    /// The endpoint's GUID.
    pub key: Guid,
    /// Its participant's GUID: as announced, else the one its GUID prefix names.
    pub participant_key: Option<Guid>,
    /// The topic name.
    pub topic_name: String,
    /// The type name.
    pub type_name: String,
    /// Its QoS: the writer's (reader's), its publisher's (subscriber's: presentation, partition, group data)
    /// and TOPIC_DATA.
    pub qos: Q,
    /// Its XTypes TypeInformation (PID_TYPE_INFORMATION), when announced.
    pub type_information: Option<TypeInformation>,
}

/// DCPSPublication: a writer as SEDP announced it.
pub type PublicationBuiltinTopicData = EndpointBuiltinTopicData<WriterQos>;

/// DCPSSubscription: a reader as SEDP announced it.
pub type SubscriptionBuiltinTopicData = EndpointBuiltinTopicData<ReaderQos>;

/// DCPSParticipant: a participant as SPDP announced it.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct ParticipantBuiltinTopicData {
    /// Its GUID prefix.
    pub key: GuidPrefix,
    /// Its USER_DATA.
    pub user_data: Vec<u8>,
    /// The vendor of its DDS implementation.
    pub vendor_id: VendorId,
    /// Its entity name (PID_ENTITY_NAME), when announced.
    pub entity_name: Option<String>,
    /// Its PROPERTY_LIST: among others the host name, process id and program name that Cyclone DDS and we
    /// announce (`__Hostname`, `__Pid`, `__ProcessName`).
    pub properties: Vec<(String, String)>,
}

impl ParticipantBuiltinTopicData {
    /// The value of property `name`, if announced.
    pub fn property(&self, name: &str) -> Option<&str> {
        self.properties
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
}

impl<Q: Clone> From<&EndpointData<Q>> for EndpointBuiltinTopicData<Q> {
    fn from(d: &EndpointData<Q>) -> Self {
        EndpointBuiltinTopicData {
            key: d.guid,
            // Cyclone does not send PID_PARTICIPANT_GUID in SEDP: the GUID prefix names the participant.
            participant_key: d
                .participant_guid
                .or(Some(Guid::new(d.guid.prefix, EntityId::PARTICIPANT))),
            topic_name: d.topic_name.clone(),
            type_name: d.type_name.clone(),
            qos: Q::clone(&d.qos),
            type_information: d.type_information.as_deref().cloned(),
        }
    }
}

impl From<&ParticipantData> for ParticipantBuiltinTopicData {
    fn from(d: &ParticipantData) -> Self {
        ParticipantBuiltinTopicData {
            key: d.guid_prefix,
            user_data: d.user_data.clone(),
            vendor_id: d.vendor_id,
            entity_name: d.entity_name.clone(),
            properties: d.properties.clone(),
        }
    }
}

/// DCPSTopic: a topic as discovery learnt it (from the readers and writers announced on it; see the
/// built-in topics section of docs/dcps-api.md).
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct TopicBuiltinTopicData {
    /// The topic's key: derived from its name and type name.
    pub key: InstanceHandle,
    /// The topic name.
    pub name: String,
    /// The type name.
    pub type_name: String,
    /// Its TOPIC_DATA, as the first endpoint seen on it announced it.
    pub topic_data: Vec<u8>,
}

impl TopicBuiltinTopicData {
    /// The data of topic `name` with type `type_name`.
    pub(crate) fn new(name: &str, type_name: &str, topic_data: Vec<u8>) -> Self {
        TopicBuiltinTopicData {
            key: topic_key(name, type_name),
            name: name.to_string(),
            type_name: type_name.to_string(),
            topic_data,
        }
    }
}

/// A stable handle for a topic: FNV-1a of its name and type name (never NIL).
pub(crate) fn topic_key(name: &str, type_name: &str) -> InstanceHandle {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in name.bytes().chain([0]).chain(type_name.bytes()) {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    InstanceHandle(h.max(1))
}
