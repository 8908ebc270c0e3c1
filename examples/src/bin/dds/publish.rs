//! `dds publish TOPIC JSON`: a dynamic writer of the topic's type writing the samples given as JSON (one
//! object, an array of objects, or `-` for NDJSON on stdin).

use std::io::BufRead;
use std::time::Duration;

use dds_runtime::prelude::*;
use dds_runtime::xtypes::dynamic::{DynamicData, DynamicType};
use serde_json::Value as Json;

use crate::resolve::Resolved;

/// Pause between the first match and the first write.
const SETTLE: Duration = Duration::from_millis(500);

/// What `publish` was asked for.
pub(crate) struct Options {
    pub(crate) repeat: usize,
    pub(crate) interval: Duration,
    pub(crate) wait: Duration,
}

/// The samples of the JSON argument.
fn samples(ty: &DynamicType, json: &str) -> Result<Vec<DynamicData>, String> {
    let docs: Vec<Json> = if json == "-" {
        let mut v = Vec::new();
        for line in std::io::stdin().lock().lines() {
            let line = line.map_err(|e| e.to_string())?;
            if !line.trim().is_empty() {
                v.push(serde_json::from_str(&line).map_err(|e| format!("stdin: {e}"))?);
            }
        }
        v
    } else {
        match serde_json::from_str(json).map_err(|e| format!("JSON: {e}"))? {
            Json::Array(a) => a,
            one => vec![one],
        }
    };
    docs.iter()
        .map(|d| DynamicData::from_json(ty, d).map_err(|e| e.to_string()))
        .collect()
}

/// Writes the samples; waits for readers first and for their acknowledgments after.
pub(crate) fn run(
    p: &DomainParticipant,
    topic: &str,
    resolved: Resolved,
    json: &str,
    o: &Options,
) -> Result<(), String> {
    let data = samples(&resolved.ty, json)?;
    let mut t = p
        .create_dynamic_topic(topic, resolved.ty.clone(), &TopicQos::default())
        .map_err(|e| e.to_string())?;
    if let Some(ti) = resolved.type_information {
        t = t.with_type_information(ti);
    }
    let qos = DataWriterQos::builder()
        .reliability(Reliability::Reliable {
            max_blocking_time: Duration::from_secs(1),
        })
        .history(History::KeepAll)
        .build();
    let w = p
        .create_publisher(&PublisherQos::default())
        .and_then(|publ| publ.create_dynamic_writer(&t, &qos))
        .map_err(|e| e.to_string())?;
    if w.wait_for_readers(1, o.wait) {
        // Our side matched; give the reader's side the moment it takes to match us too, or a volatile reader
        // misses what is written before (discovery is not symmetric in time).
        std::thread::sleep(SETTLE);
    } else {
        eprintln!(
            "dds publish: no reader of {topic:?} matched within {:?}; writing anyway",
            o.wait
        );
    }
    for round in 0..o.repeat {
        if round > 0 {
            std::thread::sleep(o.interval);
        }
        for d in &data {
            w.write(d).map_err(|e| e.to_string())?;
        }
    }
    if w.wait_for_acknowledgments(Duration::from_secs(5)).is_err() {
        eprintln!("dds publish: not every reader acknowledged within 5 s");
    }
    eprintln!(
        "dds publish: wrote {} sample(s) to {topic:?} ({} reader(s))",
        data.len() * o.repeat,
        w.matched_readers().len()
    );
    Ok(())
}
