//! Per-entity QoS sets and their builders, with the DDS default values.

use super::policies::*;

/// Defines a QoS struct, its `Default` (the spec defaults), and a builder with one setter per policy.
macro_rules! qos_set {
    ($(#[$meta:meta])* $name:ident, $builder:ident { $($field:ident : $ty:ty = $default:expr),* $(,)? }) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, Eq)]
        pub struct $name {
            $(
                #[doc = concat!("The `", stringify!($field), "` policy; default `", stringify!($default), "`.")]
                pub $field: $ty,
            )*
        }

        impl Default for $name {
            fn default() -> Self {
                $name { $($field: $default,)* }
            }
        }

        impl $name {
            /// A builder starting from the defaults.
            pub fn builder() -> $builder {
                $builder(Self::default())
            }
        }

        #[doc = concat!("Builder for [`", stringify!($name), "`]; starts from the defaults.")]
        #[derive(Debug, Clone)]
        pub struct $builder($name);

        impl $builder {
            $(
                #[doc = concat!("Sets the `", stringify!($field), "` policy.")]
                pub fn $field(mut self, value: impl Into<$ty>) -> Self {
                    self.0.$field = value.into();
                    self
                }
            )*
            /// The finished QoS set.
            pub fn build(self) -> $name {
                self.0
            }
        }

        impl From<$builder> for $name {
            fn from(b: $builder) -> $name {
                b.0
            }
        }
    };
}

qos_set!(
    /// TopicQos: defaults per DDS 1.4 (best-effort, volatile, keep-last 1).
    TopicQos, TopicQosBuilder {
    topic_data: TopicData = TopicData::default(),
    durability: Durability = Durability::Volatile,
    durability_service: DurabilityService = DurabilityService::default(),
    deadline: Deadline = Deadline::default(),
    latency_budget: LatencyBudget = LatencyBudget::default(),
    liveliness: Liveliness = Liveliness::default(),
    reliability: Reliability = Reliability::BestEffort,
    destination_order: DestinationOrder = DestinationOrder::default(),
    history: History = History::KeepLast(1),
    resource_limits: ResourceLimits = ResourceLimits::default(),
    transport_priority: TransportPriority = TransportPriority::default(),
    lifespan: Lifespan = Lifespan::default(),
    ownership: Ownership = Ownership::default(),
    data_representation: DataRepresentation = DataRepresentation::default(),
    type_consistency: TypeConsistencyEnforcement = TypeConsistencyEnforcement::default(),
});

qos_set!(
    /// PublisherQos.
    PublisherQos, PublisherQosBuilder {
    presentation: Presentation = Presentation::default(),
    partition: Partition = Partition::default(),
    group_data: GroupData = GroupData::default(),
    autoenable_created_entities: bool = true,
});

qos_set!(
    /// SubscriberQos.
    SubscriberQos, SubscriberQosBuilder {
    presentation: Presentation = Presentation::default(),
    partition: Partition = Partition::default(),
    group_data: GroupData = GroupData::default(),
    autoenable_created_entities: bool = true,
});

qos_set!(
    /// DataWriterQos: reliable (max_blocking_time 100 ms), volatile, keep-last 1.
    DataWriterQos, DataWriterQosBuilder {
    durability: Durability = Durability::Volatile,
    durability_service: DurabilityService = DurabilityService::default(),
    deadline: Deadline = Deadline::default(),
    latency_budget: LatencyBudget = LatencyBudget::default(),
    liveliness: Liveliness = Liveliness::default(),
    reliability: Reliability = Reliability::RELIABLE,
    destination_order: DestinationOrder = DestinationOrder::default(),
    history: History = History::KeepLast(1),
    resource_limits: ResourceLimits = ResourceLimits::default(),
    transport_priority: TransportPriority = TransportPriority::default(),
    lifespan: Lifespan = Lifespan::default(),
    user_data: UserData = UserData::default(),
    ownership: Ownership = Ownership::default(),
    ownership_strength: OwnershipStrength = OwnershipStrength::default(),
    writer_data_lifecycle: WriterDataLifecycle = WriterDataLifecycle::default(),
    data_representation: DataRepresentation = DataRepresentation::default(),
    ignore_local: IgnoreLocal = IgnoreLocal::Inherit,
});

qos_set!(
    /// DataReaderQos: best-effort, volatile, keep-last 1.
    DataReaderQos, DataReaderQosBuilder {
    durability: Durability = Durability::Volatile,
    deadline: Deadline = Deadline::default(),
    latency_budget: LatencyBudget = LatencyBudget::default(),
    liveliness: Liveliness = Liveliness::default(),
    reliability: Reliability = Reliability::BestEffort,
    destination_order: DestinationOrder = DestinationOrder::default(),
    history: History = History::KeepLast(1),
    resource_limits: ResourceLimits = ResourceLimits::default(),
    user_data: UserData = UserData::default(),
    ownership: Ownership = Ownership::default(),
    time_based_filter: TimeBasedFilter = TimeBasedFilter::default(),
    reader_data_lifecycle: ReaderDataLifecycle = ReaderDataLifecycle::default(),
    data_representation: DataRepresentation = DataRepresentation::default(),
    type_consistency: TypeConsistencyEnforcement = TypeConsistencyEnforcement::default(),
    ignore_local: IgnoreLocal = IgnoreLocal::Inherit,
});

impl DataWriterQos {
    /// DDS `copy_from_topic_qos`: the topic's values for the policies both sets share.
    pub fn from_topic(t: &TopicQos) -> Self {
        DataWriterQos {
            durability: t.durability,
            durability_service: t.durability_service,
            deadline: t.deadline,
            latency_budget: t.latency_budget,
            liveliness: t.liveliness,
            reliability: t.reliability,
            destination_order: t.destination_order,
            history: t.history,
            resource_limits: t.resource_limits,
            transport_priority: t.transport_priority,
            lifespan: t.lifespan,
            ownership: t.ownership,
            data_representation: t.data_representation.clone(),
            ..Default::default()
        }
    }
}

impl DataReaderQos {
    /// DDS `copy_from_topic_qos`.
    pub fn from_topic(t: &TopicQos) -> Self {
        DataReaderQos {
            durability: t.durability,
            deadline: t.deadline,
            latency_budget: t.latency_budget,
            liveliness: t.liveliness,
            reliability: t.reliability,
            destination_order: t.destination_order,
            history: t.history,
            resource_limits: t.resource_limits,
            ownership: t.ownership,
            data_representation: t.data_representation.clone(),
            type_consistency: t.type_consistency,
            ..Default::default()
        }
    }
}

impl<const N: usize> From<[&str; N]> for Partition {
    fn from(v: [&str; N]) -> Self {
        Partition::new(v)
    }
}
impl From<Vec<String>> for Partition {
    fn from(v: Vec<String>) -> Self {
        Partition(v)
    }
}
impl From<&[&str]> for Partition {
    fn from(v: &[&str]) -> Self {
        Partition::new(v.iter().copied())
    }
}
impl From<Vec<u8>> for UserData {
    fn from(v: Vec<u8>) -> Self {
        UserData(v)
    }
}
impl From<Vec<u8>> for TopicData {
    fn from(v: Vec<u8>) -> Self {
        TopicData(v)
    }
}
impl From<Vec<u8>> for GroupData {
    fn from(v: Vec<u8>) -> Self {
        GroupData(v)
    }
}
impl From<std::time::Duration> for Deadline {
    fn from(v: std::time::Duration) -> Self {
        Deadline(v)
    }
}
impl From<std::time::Duration> for LatencyBudget {
    fn from(v: std::time::Duration) -> Self {
        LatencyBudget(v)
    }
}
impl From<std::time::Duration> for Lifespan {
    fn from(v: std::time::Duration) -> Self {
        Lifespan(v)
    }
}
impl From<i32> for OwnershipStrength {
    fn from(v: i32) -> Self {
        OwnershipStrength(v)
    }
}
impl From<i32> for TransportPriority {
    fn from(v: i32) -> Self {
        TransportPriority(v)
    }
}
impl From<Vec<i16>> for DataRepresentation {
    fn from(v: Vec<i16>) -> Self {
        DataRepresentation::any_of(v)
    }
}

qos_set!(
    /// DomainParticipantQos: USER_DATA announced in SPDP and ENTITY_FACTORY.
    DomainParticipantQos, DomainParticipantQosBuilder {
    user_data: UserData = UserData::default(),
    autoenable_created_entities: bool = true,
});

qos_set!(
    /// The QoS of the participant factory itself (DDS `DomainParticipantFactoryQos`): ENTITY_FACTORY.
    DomainParticipantFactoryQos, DomainParticipantFactoryQosBuilder {
    autoenable_created_entities: bool = true,
});
