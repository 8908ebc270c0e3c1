//! Communication statuses (DDS 1.4 §2.2.4.1). Getters return the status and reset its `*_change` counts.

use std::collections::HashMap;

use crate::qos::QosPolicyId;
use crate::rtps::Guid;

use super::sample::InstanceHandle;

/// A communication status whose `*_change` counts reset when the application reads it (or a listener
/// consumes it).
pub(crate) trait Status: Clone {
    /// Zeroes the `*_change` counts.
    fn reset_changes(&mut self);
}

/// PUBLICATION_MATCHED and SUBSCRIPTION_MATCHED: the same counts, about the other side.
pub(crate) trait MatchedStatus: Status {
    /// Records that `remote` matched or unmatched; `list` holds the currently matched GUIDs.
    fn record_match(&mut self, list: &mut Vec<Guid>, remote: Guid, matched: bool);
}

/// `Status` and `MatchedStatus` for PUBLICATION_MATCHED and SUBSCRIPTION_MATCHED, which differ only in the
/// name of the last remote handle.
macro_rules! matched_status {
    ($status:ty, $last_handle:ident) => {
        impl Status for $status {
            fn reset_changes(&mut self) {
                self.total_count_change = 0;
                self.current_count_change = 0;
            }
        }

        impl MatchedStatus for $status {
            fn record_match(&mut self, list: &mut Vec<Guid>, remote: Guid, matched: bool) {
                if matched {
                    if !list.contains(&remote) {
                        list.push(remote);
                        self.total_count += 1;
                        self.total_count_change += 1;
                        self.current_count_change += 1;
                    }
                } else if let Some(p) = list.iter().position(|g| *g == remote) {
                    list.remove(p);
                    self.current_count_change -= 1;
                }
                self.current_count = u32::try_from(list.len()).unwrap_or(u32::MAX);
                self.$last_handle = InstanceHandle::from_guid(remote);
            }
        }
    };
}

bitflags::bitflags! {
    /// A set of status kinds (`StatusMask`), with the DDS bit values.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    pub struct StatusMask: u32 {
        /// INCONSISTENT_TOPIC.
        const INCONSISTENT_TOPIC = 1 << 0;
        /// OFFERED_DEADLINE_MISSED.
        const OFFERED_DEADLINE_MISSED = 1 << 1;
        /// REQUESTED_DEADLINE_MISSED.
        const REQUESTED_DEADLINE_MISSED = 1 << 2;
        /// OFFERED_INCOMPATIBLE_QOS.
        const OFFERED_INCOMPATIBLE_QOS = 1 << 5;
        /// REQUESTED_INCOMPATIBLE_QOS.
        const REQUESTED_INCOMPATIBLE_QOS = 1 << 6;
        /// SAMPLE_LOST.
        const SAMPLE_LOST = 1 << 7;
        /// SAMPLE_REJECTED.
        const SAMPLE_REJECTED = 1 << 8;
        /// DATA_ON_READERS.
        const DATA_ON_READERS = 1 << 9;
        /// DATA_AVAILABLE.
        const DATA_AVAILABLE = 1 << 10;
        /// LIVELINESS_LOST.
        const LIVELINESS_LOST = 1 << 11;
        /// LIVELINESS_CHANGED.
        const LIVELINESS_CHANGED = 1 << 12;
        /// PUBLICATION_MATCHED.
        const PUBLICATION_MATCHED = 1 << 13;
        /// SUBSCRIPTION_MATCHED.
        const SUBSCRIPTION_MATCHED = 1 << 14;
    }
}

/// PUBLICATION_MATCHED.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct PublicationMatchedStatus {
    /// Readers ever matched.
    pub total_count: u32,
    /// Change since the last get.
    pub total_count_change: u32,
    /// Readers matched now.
    pub current_count: u32,
    /// Change since the last get.
    pub current_count_change: i32,
    /// The reader of the last change.
    pub last_subscription_handle: InstanceHandle,
}

/// SUBSCRIPTION_MATCHED.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct SubscriptionMatchedStatus {
    /// Writers ever matched.
    pub total_count: u32,
    /// Change since the last get.
    pub total_count_change: u32,
    /// Writers matched now.
    pub current_count: u32,
    /// Change since the last get.
    pub current_count_change: i32,
    /// The writer of the last change.
    pub last_publication_handle: InstanceHandle,
}

/// OFFERED_INCOMPATIBLE_QOS and REQUESTED_INCOMPATIBLE_QOS.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct IncompatibleQosStatus {
    /// Incompatible remote entities seen.
    pub total_count: u32,
    /// Change since the last get.
    pub total_count_change: u32,
    /// Policy of the last incompatibility.
    pub last_policy_id: Option<QosPolicyId>,
    /// Count per policy.
    pub policies: Vec<(QosPolicyId, u32)>,
}

impl IncompatibleQosStatus {
    pub(crate) fn record(&mut self, policy: QosPolicyId) {
        self.total_count += 1;
        self.total_count_change += 1;
        self.last_policy_id = Some(policy);
        match self.policies.iter_mut().find(|(p, _)| *p == policy) {
            Some((_, n)) => *n += 1,
            None => self.policies.push((policy, 1)),
        }
    }
}

/// OFFERED_INCOMPATIBLE_QOS.
pub type OfferedIncompatibleQosStatus = IncompatibleQosStatus;
/// REQUESTED_INCOMPATIBLE_QOS.
pub type RequestedIncompatibleQosStatus = IncompatibleQosStatus;

/// OFFERED_DEADLINE_MISSED and REQUESTED_DEADLINE_MISSED.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct DeadlineMissedStatus {
    /// Missed deadlines.
    pub total_count: u32,
    /// Change since the last get.
    pub total_count_change: u32,
    /// Instance of the last miss.
    pub last_instance_handle: InstanceHandle,
}

/// REQUESTED_DEADLINE_MISSED.
pub type RequestedDeadlineMissedStatus = DeadlineMissedStatus;
/// OFFERED_DEADLINE_MISSED.
pub type OfferedDeadlineMissedStatus = DeadlineMissedStatus;

/// SAMPLE_LOST.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct SampleLostStatus {
    /// Samples lost.
    pub total_count: u32,
    /// Change since the last get.
    pub total_count_change: u32,
}

/// Why a sample was rejected.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum SampleRejectedReason {
    /// Not rejected.
    #[default]
    NotRejected,
    /// `max_instances` reached.
    ByInstancesLimit,
    /// `max_samples` reached.
    BySamplesLimit,
    /// `max_samples_per_instance` reached.
    BySamplesPerInstanceLimit,
}

/// SAMPLE_REJECTED.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct SampleRejectedStatus {
    /// Samples rejected.
    pub total_count: u32,
    /// Change since the last get.
    pub total_count_change: u32,
    /// Reason of the last rejection.
    pub last_reason: SampleRejectedReason,
    /// Instance of the last rejection.
    pub last_instance_handle: InstanceHandle,
}

/// LIVELINESS_CHANGED.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct LivelinessChangedStatus {
    /// Matched writers currently alive.
    pub alive_count: u32,
    /// Matched writers currently not alive.
    pub not_alive_count: u32,
    /// Change since the last get.
    pub alive_count_change: i32,
    /// Change since the last get.
    pub not_alive_count_change: i32,
    /// Writer of the last change.
    pub last_publication_handle: InstanceHandle,
}

/// LIVELINESS_LOST: the writer did not assert its liveliness within its lease (MANUAL_BY_PARTICIPANT or
/// MANUAL_BY_TOPIC), so its readers consider it not alive.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct LivelinessLostStatus {
    /// Times the writer lost its liveliness.
    pub total_count: u32,
    /// Change since the last get.
    pub total_count_change: u32,
}

impl Status for LivelinessLostStatus {
    fn reset_changes(&mut self) {
        self.total_count_change = 0;
    }
}

impl LivelinessLostStatus {
    /// Records one lapse.
    pub(crate) fn record(&mut self) {
        self.total_count = self.total_count.saturating_add(1);
        self.total_count_change = self.total_count_change.saturating_add(1);
    }
}

matched_status!(PublicationMatchedStatus, last_subscription_handle);
matched_status!(SubscriptionMatchedStatus, last_publication_handle);

impl Status for IncompatibleQosStatus {
    fn reset_changes(&mut self) {
        self.total_count_change = 0;
    }
}

impl Status for DeadlineMissedStatus {
    fn reset_changes(&mut self) {
        self.total_count_change = 0;
    }
}

impl DeadlineMissedStatus {
    /// Records the instances whose deadline passed.
    pub(crate) fn record(&mut self, missed: &[InstanceHandle]) {
        let n = u32::try_from(missed.len()).unwrap_or(u32::MAX);
        self.total_count = self.total_count.saturating_add(n);
        self.total_count_change = self.total_count_change.saturating_add(n);
        self.last_instance_handle = *missed.last().unwrap_or(&InstanceHandle::NIL);
    }
}

impl Status for SampleLostStatus {
    fn reset_changes(&mut self) {
        self.total_count_change = 0;
    }
}

impl SampleLostStatus {
    /// Records `count` lost samples.
    pub(crate) fn record(&mut self, count: u64) {
        let n = u32::try_from(count).unwrap_or(u32::MAX);
        self.total_count = self.total_count.saturating_add(n);
        self.total_count_change = self.total_count_change.saturating_add(n);
    }
}

impl Status for SampleRejectedStatus {
    fn reset_changes(&mut self) {
        self.total_count_change = 0;
    }
}

impl SampleRejectedStatus {
    /// Records one rejected sample.
    pub(crate) fn record(&mut self, reason: SampleRejectedReason, handle: InstanceHandle) {
        self.total_count += 1;
        self.total_count_change += 1;
        self.last_reason = reason;
        self.last_instance_handle = handle;
    }
}

impl Status for LivelinessChangedStatus {
    fn reset_changes(&mut self) {
        self.alive_count_change = 0;
        self.not_alive_count_change = 0;
    }
}

impl LivelinessChangedStatus {
    /// Moves `writer` from the state in `writers` (absent: not matched) to `to` (`None`: unmatched),
    /// keeping the counts equal to the matched writers alive and not alive. Whether anything changed.
    pub(crate) fn record(
        &mut self,
        writers: &mut HashMap<Guid, bool>,
        writer: Guid,
        to: Option<bool>,
    ) -> bool {
        let from = match to {
            Some(alive) => writers.insert(writer, alive),
            None => writers.remove(&writer),
        };
        if from == to {
            return false;
        }
        for (state, delta) in [(from, -1), (to, 1)] {
            let (count, change) = match state {
                Some(true) => (&mut self.alive_count, &mut self.alive_count_change),
                Some(false) => (&mut self.not_alive_count, &mut self.not_alive_count_change),
                None => continue,
            };
            *count = count.saturating_add_signed(delta);
            *change = change.saturating_add(delta);
        }
        self.last_publication_handle = InstanceHandle::from_guid(writer);
        true
    }
}

/// The statuses of a data writer.
#[derive(Debug, Clone, Default)]
pub(crate) struct WriterStatuses {
    pub(crate) publication_matched: PublicationMatchedStatus,
    pub(crate) offered_incompatible_qos: IncompatibleQosStatus,
    pub(crate) offered_deadline_missed: DeadlineMissedStatus,
    pub(crate) liveliness_lost: LivelinessLostStatus,
}

/// The statuses of a data reader.
#[derive(Debug, Clone, Default)]
pub(crate) struct ReaderStatuses {
    pub(crate) subscription_matched: SubscriptionMatchedStatus,
    pub(crate) requested_incompatible_qos: IncompatibleQosStatus,
    pub(crate) requested_deadline_missed: DeadlineMissedStatus,
    pub(crate) sample_lost: SampleLostStatus,
    pub(crate) sample_rejected: SampleRejectedStatus,
    pub(crate) liveliness_changed: LivelinessChangedStatus,
    /// The matched writers and whether each is alive (what `liveliness_changed` counts).
    pub(crate) writers_alive: HashMap<Guid, bool>,
}

/// INCONSISTENT_TOPIC: a remote topic of the same name with another type was discovered.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct InconsistentTopicStatus {
    /// Inconsistent remote endpoints seen.
    pub total_count: u32,
    /// Change since the last get.
    pub total_count_change: u32,
}

impl Status for InconsistentTopicStatus {
    fn reset_changes(&mut self) {
        self.total_count_change = 0;
    }
}

impl InconsistentTopicStatus {
    /// Records one inconsistent remote endpoint.
    pub(crate) fn record(&mut self) {
        self.total_count = self.total_count.saturating_add(1);
        self.total_count_change = self.total_count_change.saturating_add(1);
    }
}
