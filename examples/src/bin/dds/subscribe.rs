//! `dds subscribe TOPIC`: a dynamic reader of the topic's type, printing each sample as a table row, a JSON
//! document or an NDJSON line, optionally filtered, until `--count` samples or interrupted.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::ValueEnum;
use dds_runtime::filter::ContentFilter;
use dds_runtime::prelude::*;
use dds_runtime::rtps::ChangeKind;
use dds_runtime::xtypes::dynamic::{DynamicData, DynamicType};
use serde_json::Value as Json;

use crate::resolve::Resolved;

/// How samples are printed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum Format {
    /// One row per sample under a header of the top-level members.
    Table,
    /// One indented JSON document per sample.
    Json,
    /// One JSON document per line.
    Ndjson,
}

/// What `subscribe` was asked for.
pub(crate) struct Options {
    pub(crate) format: Format,
    pub(crate) filter: Option<String>,
    pub(crate) count: Option<usize>,
    pub(crate) timeout: Option<Duration>,
    pub(crate) reliable: bool,
}

/// Column width of the table.
const CELL: usize = 12;

fn columns(ty: &DynamicType) -> Vec<String> {
    match (ty.as_struct(), ty.as_union()) {
        (Some(s), _) => s.members.iter().map(|m| m.name.clone()).collect(),
        (None, Some(_)) => vec!["discriminator".into(), "value".into()],
        _ => vec!["value".into()],
    }
}

fn cell(j: &Json) -> String {
    match j {
        Json::String(s) => s.clone(),
        Json::Null => "-".into(),
        other => other.to_string(),
    }
}

fn row(cols: &[String], kind: ChangeKind, j: &Json) -> String {
    let mut out = String::new();
    for c in cols {
        let v = match j {
            Json::Object(o) if o.contains_key(c) => cell(&o[c]),
            Json::Object(o) if c == "value" => o
                .iter()
                .find(|(k, _)| *k != "discriminator")
                .map_or("-".into(), |(_, v)| cell(v)),
            _ => "-".into(),
        };
        out.push_str(&format!("{v:<CELL$} "));
    }
    if kind != ChangeKind::Alive {
        out.push_str(&format!("({kind:?})"));
    }
    out.trim_end().to_string()
}

fn document(kind: ChangeKind, j: &Json) -> Json {
    match kind {
        ChangeKind::Alive => j.clone(),
        k => serde_json::json!({ "kind": format!("{k:?}"), "key": j }),
    }
}

/// Reads and prints until done; the exit code.
pub(crate) fn run(
    p: &DomainParticipant,
    topic: &str,
    resolved: Resolved,
    o: &Options,
) -> Result<(), String> {
    let filter = match &o.filter {
        Some(f) => {
            Some(ContentFilter::new(f, &[] as &[&str]).map_err(|e| format!("--filter: {e}"))?)
        }
        None => None,
    };
    let mut t = p
        .create_dynamic_topic(topic, resolved.ty.clone(), &TopicQos::default())
        .map_err(|e| e.to_string())?;
    if let Some(ti) = resolved.type_information {
        t = t.with_type_information(ti);
    }
    let reliability = if o.reliable {
        Reliability::Reliable {
            max_blocking_time: Duration::from_millis(100),
        }
    } else {
        Reliability::BestEffort
    };
    let qos = DataReaderQos::builder()
        .reliability(reliability)
        .history(History::KeepLast(1000))
        .build();
    let reader = p
        .create_subscriber(&SubscriberQos::default())
        .and_then(|s| s.create_dynamic_reader(&t, &qos))
        .map_err(|e| e.to_string())?;
    let stop = Arc::new(AtomicBool::new(false));
    let s = stop.clone();
    let _ = ctrlc::set_handler(move || s.store(true, Ordering::SeqCst));
    let cols = columns(&resolved.ty);
    let mut out = std::io::stdout().lock();
    if o.format == Format::Table {
        let head: String = cols.iter().map(|c| format!("{c:<CELL$} ")).collect();
        writeln!(out, "{}", head.trim_end()).map_err(|e| e.to_string())?;
    }
    let end = o.timeout.map(|t| Instant::now() + t);
    let mut shown = 0usize;
    while !stop.load(Ordering::SeqCst)
        && o.count.is_none_or(|n| shown < n)
        && end.is_none_or(|e| Instant::now() < e)
    {
        reader.wait_for_data(Duration::from_millis(100));
        for s in reader.take() {
            let pass = match (&filter, &s.data) {
                (Some(f), Some(d)) => s.kind != ChangeKind::Alive || f.matches(d),
                _ => true,
            };
            if !pass || o.count.is_some_and(|n| shown >= n) {
                continue;
            }
            let data = s.data.as_ref().map_or(Json::Null, DynamicData::to_json);
            let line = match o.format {
                Format::Table => row(&cols, s.kind, &data),
                Format::Json => {
                    serde_json::to_string_pretty(&document(s.kind, &data)).unwrap_or_default()
                }
                Format::Ndjson => document(s.kind, &data).to_string(),
            };
            shown += 1;
            // A closed pipe (`dds subscribe T | head`) ends the command quietly.
            if writeln!(out, "{line}").and_then(|()| out.flush()).is_err() {
                return Ok(());
            }
        }
    }
    Ok(())
}
