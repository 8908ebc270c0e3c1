//! `use dds_runtime::prelude::*;` brings in what a program using the DCPS API writes: the entities, their
//! QoS policies, samples and statuses, conditions, listeners, the derive and the configuration types.
//! Helpers (QoS matching, wire forms) stay in their modules.

pub use crate::cdr::{DdsType, XcdrVersion};
pub use crate::config::{AddressFamily, Config, MulticastData, ParticipantIndex};
pub use crate::dcps::*;
pub use crate::qos::{
    DataReaderQos, DataReaderQosBuilder, DataRepresentation, DataWriterQos, DataWriterQosBuilder,
    Deadline, DestinationOrder, DomainParticipantFactoryQos, DomainParticipantQos, Durability,
    DurabilityService, GroupData, History, IgnoreLocal, LatencyBudget, Lifespan, Liveliness,
    LivelinessKind, Ownership, OwnershipStrength, Partition, Presentation, PresentationAccessScope,
    PublisherQos, PublisherQosBuilder, QosPolicyId, ReaderDataLifecycle, Reliability,
    ResourceLimits, SubscriberQos, SubscriberQosBuilder, TimeBasedFilter, TopicData, TopicQos,
    TopicQosBuilder, TransportPriority, TypeConsistencyEnforcement, TypeConsistencyKind, UserData,
    WriterDataLifecycle, INFINITE, XCDR2_DATA_REPRESENTATION, XCDR_DATA_REPRESENTATION,
    XML_DATA_REPRESENTATION,
};
pub use crate::DdsType;
