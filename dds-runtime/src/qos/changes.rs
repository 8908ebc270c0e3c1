//! Which policies `set_qos` may change once an entity is enabled (the "Changeable" column of DDS 1.4
//! §2.2.3): [`immutable_change`] names the first policy a new QoS set changes although it may not.

use super::entities::*;
use super::policies::QosPolicyId;

/// A QoS set whose policies are either changeable or fixed once its entity is enabled.
pub trait ChangeableQos {
    /// The first policy that differs between `self` (in effect) and `new` although it cannot change,
    /// `None` when `new` only changes changeable policies.
    fn immutable_change(&self, new: &Self) -> Option<QosPolicyId>;
}

/// `Some(policy)` for the first listed field that differs.
macro_rules! first_difference {
    ($old:expr, $new:expr, [$($field:ident => $id:ident),* $(,)?]) => {{
        let (old, new) = ($old, $new);
        None$(.or_else(|| (old.$field != new.$field).then_some(QosPolicyId::$id)))*
    }};
}

impl ChangeableQos for DataWriterQos {
    fn immutable_change(&self, new: &Self) -> Option<QosPolicyId> {
        first_difference!(self, new, [
            durability => Durability,
            durability_service => DurabilityService,
            liveliness => Liveliness,
            reliability => Reliability,
            destination_order => DestinationOrder,
            history => History,
            resource_limits => ResourceLimits,
            ownership => Ownership,
            data_representation => DataRepresentation,
            ignore_local => IgnoreLocal,
        ])
    }
}

impl ChangeableQos for DataReaderQos {
    fn immutable_change(&self, new: &Self) -> Option<QosPolicyId> {
        first_difference!(self, new, [
            durability => Durability,
            liveliness => Liveliness,
            reliability => Reliability,
            destination_order => DestinationOrder,
            history => History,
            resource_limits => ResourceLimits,
            ownership => Ownership,
            data_representation => DataRepresentation,
            type_consistency => TypeConsistencyEnforcement,
            ignore_local => IgnoreLocal,
        ])
    }
}

impl ChangeableQos for TopicQos {
    fn immutable_change(&self, new: &Self) -> Option<QosPolicyId> {
        first_difference!(self, new, [
            durability => Durability,
            durability_service => DurabilityService,
            liveliness => Liveliness,
            reliability => Reliability,
            destination_order => DestinationOrder,
            history => History,
            resource_limits => ResourceLimits,
            ownership => Ownership,
            data_representation => DataRepresentation,
            type_consistency => TypeConsistencyEnforcement,
        ])
    }
}

impl ChangeableQos for PublisherQos {
    fn immutable_change(&self, new: &Self) -> Option<QosPolicyId> {
        first_difference!(self, new, [presentation => Presentation])
    }
}

impl ChangeableQos for SubscriberQos {
    fn immutable_change(&self, new: &Self) -> Option<QosPolicyId> {
        first_difference!(self, new, [presentation => Presentation])
    }
}

impl ChangeableQos for DomainParticipantQos {
    fn immutable_change(&self, _new: &Self) -> Option<QosPolicyId> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::qos::{History, Reliability};
    use std::time::Duration;

    #[test]
    fn changeable_and_immutable_writer_policies() {
        let q = DataWriterQos::default();
        let deadline = DataWriterQos::builder()
            .deadline(Duration::from_secs(1))
            .ownership_strength(3)
            .build();
        assert_eq!(q.immutable_change(&deadline), None);
        let history = DataWriterQos::builder().history(History::KeepAll).build();
        assert_eq!(q.immutable_change(&history), Some(QosPolicyId::History));
        let rel = DataReaderQos::builder()
            .reliability(Reliability::RELIABLE)
            .build();
        assert_eq!(
            DataReaderQos::default().immutable_change(&rel),
            Some(QosPolicyId::Reliability)
        );
    }
}
