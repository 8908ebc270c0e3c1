//! The built-in topic data (DDS 1.4 §2.2.5) that `get_matched_publication_data`,
//! `get_matched_subscription_data` and `get_discovered_participant_data` return: what discovery announced
//! about a remote entity.

use crate::qos::{ReaderQos, WriterQos};
use crate::rtps::discovery::{EndpointData, ParticipantData};
use crate::rtps::{Guid, GuidPrefix};

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
}

/// DCPSParticipant: a participant as SPDP announced it.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct ParticipantBuiltinTopicData {
    /// Its GUID prefix.
    pub key: GuidPrefix,
    /// Its USER_DATA.
    pub user_data: Vec<u8>,
}

impl From<&EndpointData<WriterQos>> for PublicationBuiltinTopicData {
    fn from(d: &EndpointData<WriterQos>) -> Self {
        PublicationBuiltinTopicData {
            key: d.guid,
            participant_key: d.participant_guid,
            topic_name: d.topic_name.clone(),
            type_name: d.type_name.clone(),
            qos: d.qos.clone(),
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
        }
    }
}

impl From<&ParticipantData> for ParticipantBuiltinTopicData {
    fn from(d: &ParticipantData) -> Self {
        ParticipantBuiltinTopicData {
            key: d.guid_prefix,
            user_data: d.user_data.clone(),
        }
    }
}
