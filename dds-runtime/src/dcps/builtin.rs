//! The built-in topic data (DDS 1.4 §2.2.5) that `get_matched_publication_data`,
//! `get_matched_subscription_data` and `get_discovered_participant_data` return: what discovery announced
//! about a remote entity.

use crate::qos::{ReaderQos, WriterQos};
use crate::rtps::discovery::{EndpointData, ParticipantData};
use crate::rtps::{Guid, GuidPrefix, VendorId};
use crate::xtypes::TypeInformation;

/// DCPSPublication: a writer as SEDP announced it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PublicationBuiltinTopicData {
    /// The writer's GUID.
    pub key: Guid,
    /// Its participant's GUID, when announced.
    pub participant_key: Option<Guid>,
    /// The topic name.
    pub topic_name: String,
    /// The type name.
    pub type_name: String,
    /// Its QoS: the writer's, its publisher's (presentation, partition, group data) and TOPIC_DATA.
    pub qos: WriterQos,
    /// Its XTypes TypeInformation (PID_TYPE_INFORMATION), when announced.
    pub type_information: Option<TypeInformation>,
}

/// DCPSSubscription: a reader as SEDP announced it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct SubscriptionBuiltinTopicData {
    /// The reader's GUID.
    pub key: Guid,
    /// Its participant's GUID, when announced.
    pub participant_key: Option<Guid>,
    /// The topic name.
    pub topic_name: String,
    /// The type name.
    pub type_name: String,
    /// Its QoS: the reader's, its subscriber's and TOPIC_DATA.
    pub qos: ReaderQos,
    /// Its XTypes TypeInformation (PID_TYPE_INFORMATION), when announced.
    pub type_information: Option<TypeInformation>,
}

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

impl From<&EndpointData<WriterQos>> for PublicationBuiltinTopicData {
    fn from(d: &EndpointData<WriterQos>) -> Self {
        PublicationBuiltinTopicData {
            key: d.guid,
            participant_key: d.participant_guid,
            topic_name: d.topic_name.clone(),
            type_name: d.type_name.clone(),
            qos: d.qos.clone(),
            type_information: d.type_information.clone(),
        }
    }
}

impl From<&EndpointData<ReaderQos>> for SubscriptionBuiltinTopicData {
    fn from(d: &EndpointData<ReaderQos>) -> Self {
        SubscriptionBuiltinTopicData {
            key: d.guid,
            participant_key: d.participant_guid,
            topic_name: d.topic_name.clone(),
            type_name: d.type_name.clone(),
            qos: d.qos.clone(),
            type_information: d.type_information.clone(),
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
