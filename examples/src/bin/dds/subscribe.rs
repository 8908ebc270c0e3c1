//! `dds subscribe TOPIC`: a dynamic reader of the topic's type, printing each sample as a table row, a JSON
//! document or an NDJSON line, optionally filtered, until `--count` samples or interrupted.

use std::collections::HashMap;
use std::hash::Hash;
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

/// The change an instance state stands for (`Alive` for ALIVE).
fn kind_of(state: InstanceState) -> ChangeKind {
    match state {
        InstanceState::Alive => ChangeKind::Alive,
        InstanceState::NotAliveDisposed => ChangeKind::Dispose,
        InstanceState::NotAliveNoWriters => ChangeKind::Unregister,
    }
}

/// One taken sample as [`Instances::lines`] sees it.
#[derive(Clone, Copy, Debug)]
struct Taken<K> {
    instance: K,
    state: InstanceState,
    valid: bool,
}

/// The state each instance was last shown in. A dispose or unregister that arrives while samples of the
/// instance are still held marks them (their instance state) instead of becoming a sample of its own
/// (dcps/cache.rs): it is shown once, after the last of them, and not again when it does come as a sample.
struct Instances<K>(HashMap<K, InstanceState>);

impl<K: Eq + Hash + Copy> Instances<K> {
    fn new() -> Self {
        Instances(HashMap::new())
    }

    /// What to print for a batch of taken samples, as (index in the batch, change): the data of each valid
    /// sample (`Alive`), and after the last sample of an instance in the batch, the instance's state change
    /// when it is not alive and was not shown yet.
    fn lines(&mut self, batch: &[Taken<K>]) -> Vec<(usize, ChangeKind)> {
        let mut last: HashMap<K, usize> = HashMap::new();
        for (i, t) in batch.iter().enumerate() {
            last.insert(t.instance, i);
        }
        let mut out = Vec::new();
        for (i, t) in batch.iter().enumerate() {
            if t.valid {
                out.push((i, ChangeKind::Alive));
            }
            if last[&t.instance] != i {
                continue;
            }
            let before = self.0.insert(t.instance, t.state);
            if t.state != InstanceState::Alive && before != Some(t.state) {
                out.push((i, kind_of(t.state)));
            }
        }
        out
    }
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
    let mut instances = Instances::new();
    let mut shown = 0usize;
    while !stop.load(Ordering::SeqCst)
        && o.count.is_none_or(|n| shown < n)
        && end.is_none_or(|e| Instant::now() < e)
    {
        reader.wait_for_data(Duration::from_millis(100));
        let batch = reader.take();
        let taken: Vec<Taken<InstanceHandle>> = batch
            .iter()
            .map(|s| Taken {
                instance: s.info.instance_handle,
                state: s.info.instance_state,
                valid: s.info.valid_data,
            })
            .collect();
        for (i, kind) in instances.lines(&taken) {
            let s = &batch[i];
            let pass = match (&filter, &s.data) {
                (Some(f), Some(d)) => kind != ChangeKind::Alive || f.matches(d),
                _ => true,
            };
            if !pass || o.count.is_some_and(|n| shown >= n) {
                continue;
            }
            let data = s.data.as_ref().map_or(Json::Null, DynamicData::to_json);
            let line = match o.format {
                Format::Table => row(&cols, kind, &data),
                Format::Json => {
                    serde_json::to_string_pretty(&document(kind, &data)).unwrap_or_default()
                }
                Format::Ndjson => document(kind, &data).to_string(),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn t(instance: u32, state: InstanceState, valid: bool) -> Taken<u32> {
        Taken {
            instance,
            state,
            valid,
        }
    }

    use InstanceState::{Alive, NotAliveDisposed as Disposed, NotAliveNoWriters as NoWriters};

    #[test]
    fn a_dispose_that_marked_held_samples_is_shown_after_the_last_of_them() {
        let mut inst = Instances::new();
        // Instance 1: two samples, disposed while held; instance 2: alive.
        let batch = [
            t(1, Disposed, true),
            t(2, Alive, true),
            t(1, Disposed, true),
        ];
        assert_eq!(
            inst.lines(&batch),
            [
                (0, ChangeKind::Alive),
                (1, ChangeKind::Alive),
                (2, ChangeKind::Alive),
                (2, ChangeKind::Dispose)
            ]
        );
        // The same dispose arriving later as a sample of its own is not shown twice.
        assert_eq!(inst.lines(&[t(1, Disposed, false)]), []);
    }

    #[test]
    fn a_dispose_or_unregister_as_a_sample_of_its_own_is_shown_once() {
        let mut inst = Instances::new();
        assert_eq!(inst.lines(&[t(3, Alive, true)]), [(0, ChangeKind::Alive)]);
        assert_eq!(
            inst.lines(&[t(3, NoWriters, false)]),
            [(0, ChangeKind::Unregister)]
        );
        // Alive again (a new writer), then disposed: shown again.
        assert_eq!(
            inst.lines(&[t(3, Alive, true), t(3, Disposed, false)]),
            [(0, ChangeKind::Alive), (1, ChangeKind::Dispose)]
        );
    }

    #[test]
    fn an_instance_marked_in_one_batch_and_held_over_is_not_shown_twice() {
        let mut inst = Instances::new();
        assert_eq!(
            inst.lines(&[t(4, NoWriters, true)]),
            [(0, ChangeKind::Alive), (0, ChangeKind::Unregister)]
        );
        assert_eq!(
            inst.lines(&[t(4, NoWriters, true)]),
            [(0, ChangeKind::Alive)]
        );
    }
}
