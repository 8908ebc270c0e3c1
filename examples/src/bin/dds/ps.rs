//! `dds ps`: one line per application (participant): host, pid, program and its number of writers and readers.

use serde_json::{json, Value};

use crate::ls::header;
use crate::render::{or_dash, table, Style};
use crate::snapshot::{Direction, ParticipantInfo, Snapshot};

/// A participant with its endpoint counts.
struct App<'a> {
    p: &'a ParticipantInfo,
    writers: usize,
    readers: usize,
}

fn apps(s: &Snapshot) -> Vec<App<'_>> {
    s.participants
        .iter()
        .map(|p| {
            let n = |d| {
                s.endpoints
                    .iter()
                    .filter(|e| e.participant == p.guid_prefix && e.direction == d)
                    .count()
            };
            App {
                p,
                writers: n(Direction::Writer),
                readers: n(Direction::Reader),
            }
        })
        .collect()
}

/// The text form of `dds ps`.
pub(crate) fn text(s: &Snapshot, style: Style) -> String {
    let mut rows = vec![header(&[
        "HOST",
        "PID",
        "PROGRAM",
        "NAME",
        "VENDOR",
        "WRITERS",
        "READERS",
        "GUID PREFIX",
    ])];
    rows.extend(apps(s).into_iter().map(|a| {
        vec![
            or_dash(&a.p.host),
            or_dash(&a.p.pid),
            or_dash(&a.p.program),
            or_dash(&a.p.name),
            a.p.vendor.clone(),
            a.writers.to_string(),
            a.readers.to_string(),
            a.p.guid_prefix.clone(),
        ]
    }));
    table(style, &rows)
}

/// The machine form of `dds ps`.
pub(crate) fn json(s: &Snapshot) -> Value {
    json!({
        "applications": apps(s).into_iter().map(|a| {
            let mut v = a.p.to_json();
            v["writers"] = json!(a.writers);
            v["readers"] = json!(a.readers);
            v
        }).collect::<Vec<_>>()
    })
}
