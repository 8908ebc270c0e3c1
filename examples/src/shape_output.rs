//! The lines shape_main prints; the interop suite and our tests match on them.

use dds_runtime::qos::QosPolicyId;

/// shape_main's name for a QoS policy id (the OMG configurators' table).
pub fn policy_name(id: Option<QosPolicyId>) -> &'static str {
    use QosPolicyId::*;
    match id {
        Some(UserData) => "USERDATA",
        Some(Durability) => "DURABILITY",
        Some(Presentation) => "PRESENTATION",
        Some(Deadline) => "DEADLINE",
        Some(LatencyBudget) => "LATENCYBUDGET",
        Some(Ownership) => "OWNERSHIP",
        Some(OwnershipStrength) => "OWNERSHIPSTRENGTH",
        Some(Liveliness) => "LIVELINESS",
        Some(TimeBasedFilter) => "TIMEBASEDFILTER",
        Some(Partition) => "PARTITION",
        Some(Reliability) => "RELIABILITY",
        Some(DestinationOrder) => "DESTINATIONORDER",
        Some(History) => "HISTORY",
        Some(ResourceLimits) => "RESOURCELIMITS",
        Some(EntityFactory) => "ENTITYFACTORY",
        Some(WriterDataLifecycle) => "WRITERDATALIFECYCLE",
        Some(ReaderDataLifecycle) => "READERDATALIFECYCLE",
        Some(TopicData) => "TOPICDATA",
        Some(GroupData) => "GROUPDATA",
        Some(TransportPriority) => "TRANSPORTPRIORITY",
        Some(Lifespan) => "LIFESPAN",
        Some(DurabilityService) => "DURABILITYSERVICE",
        Some(DataRepresentation) => "DATAREPRESENTATION",
        Some(TypeConsistencyEnforcement) => "TYPECONSISTENCYENFORCEMENT",
        Some(IgnoreLocal) => "IGNORELOCAL",
        None => "Unknown",
    }
}

/// `%-10s %-10s %03d %03d [%d]` plus ` {%u}` (last additional-payload byte) when there is a payload.
pub fn sample_line(topic: &str, color: &str, x: i32, y: i32, size: i32, payload: &[u8]) -> String {
    let mut s = format!("{topic:<10} {color:<10} {} {} [{size}]", pad3(x), pad3(y));
    if let Some(last) = payload.last() {
        s.push_str(&format!(" {{{last}}}"));
    }
    s
}

/// C's `%03d`: zero-padded to width 3, the sign counting towards the width.
fn pad3(v: i32) -> String {
    if v < 0 {
        format!("-{:02}", v.unsigned_abs())
    } else {
        format!("{v:03}")
    }
}

/// The instance-state lines shape_main prints for NOT_ALIVE samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NotAlive {
    /// NOT_ALIVE_DISPOSED_INSTANCE_STATE
    Disposed,
    /// NOT_ALIVE_NO_WRITERS_INSTANCE_STATE
    NoWriters,
}

/// `%-10s %-10s NOT_ALIVE_..._INSTANCE_STATE`.
pub fn instance_state_line(topic: &str, color: &str, state: NotAlive) -> String {
    let s = match state {
        NotAlive::Disposed => "NOT_ALIVE_DISPOSED_INSTANCE_STATE",
        NotAlive::NoWriters => "NOT_ALIVE_NO_WRITERS_INSTANCE_STATE",
    };
    format!("{topic:<10} {color:<10} {s}")
}

/// The writer listener's `on_publication_matched` line.
pub fn publication_matched_line(topic: &str, type_name: &str, current: u32, change: i32) -> String {
    format!("on_publication_matched() topic: '{topic}'  type: '{type_name}' : matched readers {current} (change = {change})")
}

/// The reader listener's `on_subscription_matched` line.
pub fn subscription_matched_line(
    topic: &str,
    type_name: &str,
    current: u32,
    change: i32,
) -> String {
    format!("on_subscription_matched() topic: '{topic}'  type: '{type_name}' : matched writers {current} (change = {change})")
}

fn policy_number(id: Option<QosPolicyId>) -> u32 {
    id.map(|p| p as u32).unwrap_or(0)
}

/// The writer listener's `on_offered_incompatible_qos` line: policy number and name.
pub fn offered_incompatible_line(topic: &str, type_name: &str, id: Option<QosPolicyId>) -> String {
    format!(
        "on_offered_incompatible_qos() topic: '{topic}'  type: '{type_name}' : {} ({})",
        policy_number(id),
        policy_name(id)
    )
}

/// The reader listener's `on_requested_incompatible_qos` line: policy number and name.
pub fn requested_incompatible_line(
    topic: &str,
    type_name: &str,
    id: Option<QosPolicyId>,
) -> String {
    format!(
        "on_requested_incompatible_qos() topic: '{topic}'  type: '{type_name}' : {} ({})",
        policy_number(id),
        policy_name(id)
    )
}

/// The writer listener's `on_offered_deadline_missed` line: the status' total count and its change.
pub fn offered_deadline_missed_line(
    topic: &str,
    type_name: &str,
    total: u32,
    change: u32,
) -> String {
    format!("on_offered_deadline_missed() topic: '{topic}'  type: '{type_name}' : (total = {total}, change = {change})")
}

/// The reader listener's `on_requested_deadline_missed` line: the status' total count and its change.
pub fn requested_deadline_missed_line(
    topic: &str,
    type_name: &str,
    total: u32,
    change: u32,
) -> String {
    format!("on_requested_deadline_missed() topic: '{topic}'  type: '{type_name}' : (total = {total}, change = {change})")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_lines_match_printf() {
        assert_eq!(
            sample_line("Square", "BLUE", 5, 123, 20, &[]),
            "Square     BLUE       005 123 [20]"
        );
        assert_eq!(
            sample_line("Circle", "RED", 240, 7, 30, &[255, 255]),
            "Circle     RED        240 007 [30] {255}"
        );
        assert_eq!(
            sample_line("LongTopicName", "C", -3, 0, 1, &[]),
            "LongTopicName C          -03 000 [1]"
        );
    }

    #[test]
    fn status_lines() {
        assert_eq!(
            instance_state_line("Square", "BLUE", NotAlive::Disposed),
            "Square     BLUE       NOT_ALIVE_DISPOSED_INSTANCE_STATE"
        );
        assert_eq!(
            publication_matched_line("Square", "ShapeType", 1, 1),
            "on_publication_matched() topic: 'Square'  type: 'ShapeType' : matched readers 1 (change = 1)"
        );
        assert_eq!(
            requested_incompatible_line("Square", "ShapeType", Some(QosPolicyId::Durability)),
            "on_requested_incompatible_qos() topic: 'Square'  type: 'ShapeType' : 2 (DURABILITY)"
        );
        assert_eq!(
            offered_incompatible_line("Square", "ShapeType", None),
            "on_offered_incompatible_qos() topic: 'Square'  type: 'ShapeType' : 0 (Unknown)"
        );
    }
}
