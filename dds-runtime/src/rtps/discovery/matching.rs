//! Writer/reader matching: topic and type names, partitions, then requested/offered QoS.

use crate::qos::{check_compatible, partitions_match, QosPolicyId, ReaderQos, WriterQos};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MatchResult {
    Match,
    /// Different topic, type or partition: not related at all, nothing to report.
    Unrelated,
    /// Same topic but a requested/offered conflict: reported as incompatible QoS on both sides.
    Incompatible(QosPolicyId),
}

/// A writer endpoint's matching-relevant description.
#[derive(Debug, Clone, Copy)]
pub struct WriterView<'a> {
    pub topic_name: &'a str,
    pub type_name: &'a str,
    pub qos: &'a WriterQos,
}

#[derive(Debug, Clone, Copy)]
pub struct ReaderView<'a> {
    pub topic_name: &'a str,
    pub type_name: &'a str,
    pub qos: &'a ReaderQos,
}

pub fn match_endpoints(w: WriterView<'_>, r: ReaderView<'_>) -> MatchResult {
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
    match check_compatible(w.qos, r.qos) {
        Ok(()) => MatchResult::Match,
        Err(p) => MatchResult::Incompatible(p),
    }
}
