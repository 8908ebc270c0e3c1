//! Writer/reader matching: topic and type names, partitions, then requested/offered QoS.

use super::{ReaderData, WriterData};
use crate::qos::{check_compatible, partitions_match, QosPolicyId};

/// The outcome of matching a publication with a subscription.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MatchResult {
    /// Same topic, type and partition, and compatible QoS: the endpoints communicate.
    Match,
    /// Different topic, type or partition: not related at all, nothing to report.
    Unrelated,
    /// Same topic but a requested/offered conflict: reported as incompatible QoS on both sides.
    Incompatible(QosPolicyId),
}

/// Matches a publication with a subscription (DDS 1.4 §2.2.3, RTPS 2.5 §8.5.5.1).
pub fn match_endpoints(w: &WriterData, r: &ReaderData) -> MatchResult {
    if w.topic_name != r.topic_name {
        return MatchResult::Unrelated;
    }
    // Type names must agree; with type information an assignability check could relax this (not done yet).
    if w.type_name != r.type_name {
        return MatchResult::Unrelated;
    }
    if !partitions_match(&w.qos.partition, &r.qos.partition) {
        return MatchResult::Unrelated;
    }
    match check_compatible(&w.qos, &r.qos) {
        Ok(()) => MatchResult::Match,
        Err(p) => MatchResult::Incompatible(p),
    }
}
