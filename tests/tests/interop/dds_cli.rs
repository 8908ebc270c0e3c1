//! The `dds` command line against Cyclone DDS 11 (Python binding): `dds ls --json` lists a Cyclone writer
//! and reader with their topic and type names, and `dds ps` shows the Cyclone process.

use std::process::Command;
use std::time::Duration;

use serde_json::Value;

use super::harness::{cyclone_peer, our_bin, require_netns, Proc, Skip};
use crate::check;

const DOMAIN: u32 = 170;
const WAIT: Duration = Duration::from_secs(20);

/// A Cyclone participant with a writer on "Square" and a reader on "Circle", both of type ShapeType.
const PEER: &str = r#"
import os, sys, time
from dataclasses import dataclass
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import int32
from cyclonedds.idl.annotations import key

@dataclass
class ShapeType(IdlStruct, typename="ShapeType"):
    color: str
    key("color")
    x: int32
    y: int32
    shapesize: int32

dp = DomainParticipant(int(sys.argv[1]))
w = DataWriter(dp, Topic(dp, "Square", ShapeType))
r = DataReader(dp, Topic(dp, "Circle", ShapeType))
print("ready", os.getpid(), flush=True)
time.sleep(60)
"#;

/// Starts the peer and returns it with its process id.
fn peer() -> Result<(Proc, String), Skip> {
    require_netns()?;
    cyclone_peer()?;
    let mut c = Command::new("python3");
    c.arg("-u").arg("-c").arg(PEER).arg(DOMAIN.to_string());
    let p = Proc::spawn("cyclone peer", c);
    let ready = p.wait_line(WAIT, |l| l.starts_with("ready "));
    check!(ready.is_some(), &[&p], "peer did not start");
    let pid = ready.expect("checked")["ready ".len()..].trim().to_string();
    Ok((p, pid))
}

/// Runs `dds ARGS --domain DOMAIN` to completion and parses its stdout as JSON.
fn dds_json(args: &[&str], peer: &Proc) -> Result<Value, Skip> {
    let out = Command::new(our_bin("dds")?)
        .args(args)
        .args(["--domain", &DOMAIN.to_string(), "--wait", "3", "--json"])
        .output()
        .expect("running dds");
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    check!(
        out.status.success(),
        &[peer],
        "dds {args:?} failed: {out:?}"
    );
    Ok(serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("dds {args:?}: not JSON ({e}): {text}")))
}

#[test]
fn dds_ls_lists_cyclone_endpoints() {
    let Ok((mut p, _)) = peer() else { return };
    let Ok(v) = dds_json(&["ls"], &p) else { return };
    let endpoints = v["endpoints"].as_array().cloned().unwrap_or_default();
    let has = |kind: &str, topic: &str| {
        endpoints
            .iter()
            .any(|e| e["kind"] == kind && e["topic"] == topic && e["type"] == "ShapeType")
    };
    check!(has("writer", "Square"), &[&p], "no Square writer in {v}");
    check!(has("reader", "Circle"), &[&p], "no Circle reader in {v}");
    let topics = v["topics"].as_array().cloned().unwrap_or_default();
    check!(
        topics
            .iter()
            .any(|t| t["name"] == "Square" && t["types"][0] == "ShapeType"),
        &[&p],
        "no Square topic in {v}"
    );
    let _ = p.interrupt(WAIT);
}

#[test]
fn dds_ps_shows_cyclone_process() {
    let Ok((mut p, pid)) = peer() else { return };
    let Ok(v) = dds_json(&["ps"], &p) else { return };
    let apps = v["applications"].as_array().cloned().unwrap_or_default();
    let app = apps.iter().find(|a| a["pid"] == pid.as_str());
    check!(app.is_some(), &[&p], "pid {pid} not in {v}");
    let app = app.expect("checked");
    check!(
        app["vendor"] == "Eclipse Cyclone DDS",
        &[&p],
        "vendor: {app}"
    );
    check!(
        app["program"]
            .as_str()
            .is_some_and(|s| s.contains("python")),
        &[&p],
        "program: {app}"
    );
    check!(
        app["writers"] == 1 && app["readers"] == 1,
        &[&p],
        "counts: {app}"
    );
    let _ = p.interrupt(WAIT);
}

#[test]
fn dds_typeof_says_not_yet() {
    let Ok(bin) = our_bin("dds") else { return };
    let out = Command::new(bin)
        .args(["typeof", "Square"])
        .output()
        .expect("running dds");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("needs XTypes dynamic types"));
}
