//! `dds ls`: participants, topics with their types, and every writer and reader with its main QoS.

use crate::render::{or_dash, table, Style};
use crate::snapshot::Snapshot;

/// The text form of `dds ls`.
pub(crate) fn text(s: &Snapshot, style: Style) -> String {
    let mut out = String::new();
    out.push_str(&style.heading(&format!("Participants ({})", s.participants.len())));
    out.push('\n');
    let mut rows = vec![header(&[
        "GUID PREFIX",
        "VENDOR",
        "NAME",
        "HOST",
        "PID",
        "PROGRAM",
    ])];
    rows.extend(s.participants.iter().map(|p| {
        vec![
            p.guid_prefix.clone(),
            p.vendor.clone(),
            or_dash(&p.name),
            or_dash(&p.host),
            or_dash(&p.pid),
            or_dash(&p.program),
        ]
    }));
    out.push_str(&table(style, &rows));

    let topics = s.topics();
    out.push('\n');
    out.push_str(&style.heading(&format!("Topics ({})", topics.len())));
    out.push('\n');
    for (topic, types) in &topics {
        let n = |d| {
            s.endpoints
                .iter()
                .filter(|e| e.topic == *topic && e.direction == d)
                .count()
        };
        let w = n(crate::snapshot::Direction::Writer);
        let r = n(crate::snapshot::Direction::Reader);
        let clash = if types.len() > 1 {
            "  (inconsistent types)"
        } else {
            ""
        };
        out.push_str(&format!(
            "  {}  {}  {}{clash}\n",
            style.key(topic),
            types.join(", "),
            style.dim(&format!("{w} writer(s), {r} reader(s)"))
        ));
    }

    out.push('\n');
    out.push_str(&style.heading(&format!("Endpoints ({})", s.endpoints.len())));
    out.push('\n');
    let mut rows = vec![header(&[
        "KIND",
        "TOPIC",
        "TYPE",
        "RELIABILITY",
        "DURABILITY",
        "OWNERSHIP",
        "PARTITIONS",
        "XTYPES",
        "GUID",
    ])];
    rows.extend(s.endpoints.iter().map(|e| {
        vec![
            e.direction.as_str().to_string(),
            e.topic.clone(),
            e.type_name.clone(),
            e.reliability.to_string(),
            e.durability.to_string(),
            e.ownership.to_string(),
            if e.partitions.is_empty() {
                "\"\"".to_string()
            } else {
                e.partitions.join(",")
            },
            if e.type_information { "yes" } else { "no" }.to_string(),
            e.guid.clone(),
        ]
    }));
    out.push_str(&table(style, &rows));
    out
}

pub(crate) fn header(cols: &[&str]) -> Vec<String> {
    cols.iter().map(|c| c.to_string()).collect()
}
