//! The `dds` command line against Cyclone DDS 11 (Python binding): `dds ls --json` lists a Cyclone writer
//! and reader with their topic and type names, `dds ps` shows the Cyclone process, `dds subscribe --idl`
//! prints what the Cyclone writer writes, `dds publish --idl` reaches the Cyclone reader, and `dds typeof`
//! without `--idl` says why the discovered type cannot be used yet. `dds subscribe` shows the disposes of a
//! Cyclone writer that writes and at once disposes each instance (the dispose then usually only marks the
//! sample still held, as the reader cache does, instead of arriving as a sample of its own). Against Fast DDS
//! 2.9, which announces no type information, `dds typeof` says so and `dds subscribe --idl` works. A dispose of
//! an instance `dds subscribe` never saw shows the key members the dispose carried.

use std::ffi::OsStr;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

use serde_json::Value;

use super::harness::{cyclone_peer, our_bin, require_netns, Proc, Skip};
use crate::check;

const DOMAIN: u32 = 170;
const WAIT: Duration = Duration::from_secs(20);

/// What the Python peers start with: the binding's imports and the type of [`IDL`].
const PY_SHAPE: &str = r#"
import os, sys, time
from dataclasses import dataclass
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import int32
from cyclonedds.idl.annotations import key
from cyclonedds.core import Qos, Policy
from cyclonedds.util import duration

@dataclass
class ShapeType(IdlStruct, typename="ShapeType"):
    color: str
    key("color")
    x: int32
    y: int32
    shapesize: int32

"#;

/// A Cyclone peer that runs `body` after [`PY_SHAPE`], on [`DOMAIN`].
fn python_peer(body: &str) -> Command {
    python_peer_on(body, DOMAIN)
}

/// A Cyclone peer that runs `body` after [`PY_SHAPE`], on `domain` (its `sys.argv[1]`).
fn python_peer_on(body: &str, domain: u32) -> Command {
    let mut c = Command::new("python3");
    c.arg("-u")
        .arg("-c")
        .arg(format!("{PY_SHAPE}{body}"))
        .arg(domain.to_string());
    c
}

/// A Cyclone participant with a writer on "Square" and a reader on "Circle", both of type ShapeType.
const PEER: &str = r#"
dp = DomainParticipant(int(sys.argv[1]))
w = DataWriter(dp, Topic(dp, "Square", ShapeType))
r = DataReader(dp, Topic(dp, "Circle", ShapeType), qos=Qos(Policy.Reliability.Reliable(duration(seconds=1))))
print("ready", os.getpid(), flush=True)
i = 0
end = time.time() + 60
while time.time() < end:
    w.write(ShapeType(color="RED", x=i, y=2 * i, shapesize=30))
    i += 1
    for s in r.take(N=100):
        if isinstance(s, ShapeType):
            print("got", s.color, s.x, s.y, s.shapesize, flush=True)
    time.sleep(0.1)
"#;

/// The peer's type as IDL (the Python binding's structs are @final).
const IDL: &str =
    "@final struct ShapeType { @key string color; long x; long y; long shapesize; };\n";

/// Writes [`IDL`] to a file of its own.
fn idl_file() -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("dds-cli-interop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let f = dir.join("shape.idl");
    std::fs::write(&f, IDL).expect("IDL file");
    f
}

/// Starts the peer and returns it with its process id.
fn peer() -> Result<(Proc, String), Skip> {
    require_netns()?;
    cyclone_peer()?;
    let p = Proc::spawn("cyclone peer", python_peer(PEER));
    let ready = p.wait_line(WAIT, |l| l.starts_with("ready "));
    check!(ready.is_some(), &[&p], "peer did not start");
    let pid = ready.expect("checked")["ready ".len()..].trim().to_string();
    Ok((p, pid))
}

/// Runs `cmd` (a `dds` command) to completion and returns its stdout; fails the test, dumping `peer`,
/// when it did not exit successfully.
fn run_dds(cmd: &mut Command, peer: &Proc) -> String {
    let out = cmd.output().expect("running dds");
    check!(out.status.success(), &[peer], "{cmd:?} failed: {out:?}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Runs `dds ARGS --domain DOMAIN` to completion and parses its stdout as JSON.
fn dds_json(args: &[&str], peer: &Proc) -> Result<Value, Skip> {
    let mut cmd = Command::new(our_bin("dds")?);
    cmd.args(args)
        .args(["--domain", &DOMAIN.to_string(), "--wait", "3", "--json"]);
    let text = run_dds(&mut cmd, peer);
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

/// No `--idl`: the type of a topic written by a Cyclone Python program (whose type our binaries were never
/// compiled with) comes from type discovery, through the TypeLookup service.
#[test]
fn dds_typeof_and_subscribe_through_type_discovery() {
    let Ok((mut p, _)) = peer() else { return };
    let Ok(bin) = our_bin("dds") else { return };
    let domain = DOMAIN.to_string();
    let out = Command::new(&bin)
        .args(["typeof", "Square", "--domain", &domain, "--wait", "10"])
        .output()
        .expect("running dds");
    let idl = String::from_utf8_lossy(&out.stdout).to_string();
    check!(out.status.success(), &[&p], "dds typeof failed: {out:?}");
    check!(
        idl.contains("struct ShapeType")
            && ["color", "x", "y", "shapesize"]
                .iter()
                .all(|m| idl.contains(m))
            && idl.contains("@key"),
        &[&p],
        "typeof printed: {idl}"
    );
    let (rows, text) = three_squares(&bin, &domain, &[], &p);
    check!(
        rows.len() == 3 && rows.iter().all(|r| r["color"] == "RED"),
        &[&p],
        "three samples expected: {text}"
    );
    let _ = p.interrupt(WAIT);
}

#[test]
fn dds_subscribe_idl_prints_cyclone_samples() {
    let Ok((mut p, _)) = peer() else { return };
    let Ok(bin) = our_bin("dds") else { return };
    let idl = idl_file();
    let extra = [
        "--filter".as_ref(),
        "x >= 0".as_ref(),
        "--idl".as_ref(),
        idl.as_os_str(),
    ];
    let (rows, text) = three_squares(&bin, &DOMAIN.to_string(), &extra, &p);
    check!(rows.len() == 3, &[&p], "three samples expected: {text}");
    for r in &rows {
        let x = r["x"].as_i64().unwrap_or(-1);
        check!(
            r["color"] == "RED" && x >= 0 && r["y"].as_i64() == Some(2 * x) && r["shapesize"] == 30,
            &[&p],
            "sample: {r}"
        );
    }
    let _ = p.interrupt(WAIT);
}

#[test]
fn dds_publish_idl_reaches_cyclone_reader() {
    let Ok((mut p, _)) = peer() else { return };
    let Ok(bin) = our_bin("dds") else { return };
    let idl = idl_file();
    let out = Command::new(bin)
        .args([
            "publish",
            "Circle",
            r#"[{"color":"BLUE","x":7,"y":8,"shapesize":9},{"color":"GREEN","x":1}]"#,
        ])
        .arg("--idl")
        .arg(&idl)
        .args(["--domain", &DOMAIN.to_string(), "--wait", "10"])
        .output()
        .expect("running dds");
    check!(out.status.success(), &[&p], "dds publish failed: {out:?}");
    let got = p
        .wait_lines(WAIT, 2, |l| l.starts_with("got "))
        .unwrap_or_default();
    check!(got.len() >= 2, &[&p], "the Cyclone reader got {got:?}");
    check!(
        got.iter().any(|l| l == "got BLUE 7 8 9"),
        &[&p],
        "BLUE: {got:?}"
    );
    check!(
        got.iter().any(|l| l == "got GREEN 1 0 0"),
        &[&p],
        "GREEN: {got:?}"
    );
    let _ = p.interrupt(WAIT);
}

/// A Cyclone writer on "Flash" that, once matched, writes and at once disposes three instances. KEEP_ALL: its
/// side may match before ours does, and then a KEEP_LAST 1 history would hold only each instance's dispose
/// when our reader asks for what it missed (one CI run showed RED's dispose without its sample).
const DISPOSER: &str = r#"
dp = DomainParticipant(int(sys.argv[1]))
w = DataWriter(dp, Topic(dp, "Flash", ShapeType),
               qos=Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepAll))
end = time.time() + 20
while w.get_publication_matched_status().current_count == 0 and time.time() < end:
    time.sleep(0.05)
print("matched", flush=True)
for i, c in enumerate(["RED", "GREEN", "BLUE"]):
    s = ShapeType(color=c, x=i, y=i, shapesize=30)
    w.write(s)
    w.dispose(s)
    time.sleep(0.3)
w.wait_for_acks(duration(seconds=5))
print("done", flush=True)
time.sleep(3)
"#;

#[test]
fn dds_subscribe_shows_disposes_that_marked_held_samples() {
    if require_netns().is_err() || cyclone_peer().is_err() {
        return;
    }
    let Ok(bin) = our_bin("dds") else { return };
    let (rows, sub, peer) = subscribe_beside(&bin, "Flash", 6, DOMAIN, DISPOSER);
    let shown: Vec<(String, String)> = rows
        .iter()
        .map(|r| match r.get("kind") {
            Some(k) => (
                k.as_str().unwrap_or("?").to_string(),
                r["key"]["color"].as_str().unwrap_or("?").to_string(),
            ),
            None => (
                "Alive".to_string(),
                r["color"].as_str().unwrap_or("?").to_string(),
            ),
        })
        .collect();
    let want: Vec<(String, String)> = ["RED", "GREEN", "BLUE"]
        .iter()
        .flat_map(|c| {
            [
                ("Alive".to_string(), c.to_string()),
                ("Dispose".to_string(), c.to_string()),
            ]
        })
        .collect();
    check!(
        shown == want,
        &[&sub, &peer],
        "dds subscribe showed {shown:?}"
    );
}

/// A Cyclone writer on "Ghost" that, once matched, disposes PURPLE, an instance it never wrote, then writes
/// RED and unregisters it (without autodispose). On [`GHOST_DOMAIN`].
const GHOST: &str = r#"
dp = DomainParticipant(int(sys.argv[1]))
w = DataWriter(dp, Topic(dp, "Ghost", ShapeType),
               qos=Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepAll,
                       Policy.WriterDataLifecycle(autodispose=False)))
end = time.time() + 20
while w.get_publication_matched_status().current_count == 0 and time.time() < end:
    time.sleep(0.05)
print("matched", flush=True)
time.sleep(0.3)
w.dispose(ShapeType(color="PURPLE", x=0, y=0, shapesize=0))
time.sleep(0.3)
red = ShapeType(color="RED", x=1, y=1, shapesize=30)
w.write(red)
time.sleep(0.3)
w.unregister_instance(red)
w.wait_for_acks(duration(seconds=5))
print("done", flush=True)
time.sleep(3)
"#;

/// The domain of [`dds_subscribe_shows_the_key_of_a_dispose_of_an_instance_it_never_saw`].
const GHOST_DOMAIN: u32 = 129;

/// A dispose of an instance the reader never had a sample of carries only the key (Cyclone sends the
/// serialized key): `dds subscribe` shows its key members (the dynamic reader's invalid samples carry the
/// instance's key, also when the take forgets the instance at once), as it does for the unregister of an
/// instance it saw alive. Before session 27 both showed `"key": null`.
#[test]
fn dds_subscribe_shows_the_key_of_a_dispose_of_an_instance_it_never_saw() {
    if require_netns().is_err() || cyclone_peer().is_err() {
        return;
    }
    let Ok(bin) = our_bin("dds") else { return };
    let (rows, sub, peer) = subscribe_beside(&bin, "Ghost", 3, GHOST_DOMAIN, GHOST);
    let shown: Vec<(&str, &str, Option<i64>)> = rows
        .iter()
        .map(|r| {
            let (kind, v) = match r.get("kind") {
                Some(k) => (k.as_str().unwrap_or("?"), &r["key"]),
                None => ("Alive", r),
            };
            (kind, v["color"].as_str().unwrap_or("?"), v["x"].as_i64())
        })
        .collect();
    let want = [
        ("Dispose", "PURPLE", Some(0)),
        ("Alive", "RED", Some(1)),
        ("Unregister", "RED", Some(0)),
    ];
    check!(
        shown == want,
        &[&sub, &peer],
        "dds subscribe showed {shown:?}"
    );
}

/// `dds subscribe TOPIC --ndjson --reliable -n N` (the shapes IDL, `domain`) beside a Cyclone peer running
/// the Python `script` on the same domain: the rows it printed once it finished (checked), with both
/// processes for the caller's checks.
fn subscribe_beside(
    bin: &Path,
    topic: &str,
    n: u32,
    domain: u32,
    script: &str,
) -> (Vec<Value>, Proc, Proc) {
    let mut sub = Command::new(bin);
    sub.args([
        "subscribe",
        topic,
        "--ndjson",
        "--reliable",
        "-n",
        &n.to_string(),
    ])
    .args(["--timeout", "25"])
    .arg("--idl")
    .arg(idl_file())
    .args(["--domain", &domain.to_string()]);
    let mut sub = Proc::spawn("dds subscribe", sub);
    let mut peer = Proc::spawn("cyclone peer", python_peer_on(script, domain));
    let exit = sub.wait_exit(Duration::from_secs(30));
    let rows = ndjson_rows(&sub.lines().join("\n"));
    let _ = peer.interrupt(WAIT);
    check!(
        exit.is_some(),
        &[&sub, &peer],
        "dds subscribe did not finish"
    );
    (rows, sub, peer)
}

/// `dds subscribe Square --ndjson -n 3 --timeout 20` on `domain`, with `extra` arguments: the rows it printed
/// and its whole output, once it has exited successfully (`peer` is dumped if not).
fn three_squares(bin: &Path, domain: &str, extra: &[&OsStr], peer: &Proc) -> (Vec<Value>, String) {
    let mut cmd = Command::new(bin);
    cmd.args([
        "subscribe",
        "Square",
        "--ndjson",
        "-n",
        "3",
        "--timeout",
        "20",
    ])
    .args(extra)
    .args(["--domain", domain]);
    let text = run_dds(&mut cmd, peer);
    (ndjson_rows(&text), text)
}

/// The JSON documents of `dds subscribe --ndjson` output, one per line (other lines skipped).
fn ndjson_rows(text: &str) -> Vec<Value> {
    text.lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect()
}

#[path = "../recursive_types/mod.rs"]
#[allow(dead_code)] // Not every test uses every type.
mod recursive_types;

/// A recursive topic type: a writer of the derived `Rec::Holder` (two strongly connected components inside,
/// `Node` and `A`/`B`) in this process, on domain 36. No Cyclone program can be the writer: libddsc 11 refuses
/// such types at topic creation. `dds typeof` fetches the component objects through the TypeLookup service
/// and prints the type as IDL (forward declarations included); `dds subscribe` decodes the samples with the
/// dynamic type built from those objects, to the values the derive wrote.
#[test]
fn dds_typeof_and_subscribe_a_recursive_topic() {
    use dds_runtime::prelude::*;
    use recursive_types::{node_value, Holder, A, B};
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;

    const REC_DOMAIN: u32 = 36;
    if require_netns().is_err() {
        return;
    }
    let Ok(bin) = our_bin("dds") else { return };
    let p = super::harness::loopback_participant(REC_DOMAIN);
    let topic = p
        .create_topic::<Holder>("RecHolder", &TopicQos::default())
        .expect("topic");
    let w = p
        .create_publisher(&PublisherQos::default())
        .and_then(|publ| publ.create_datawriter(&topic, &DataWriterQos::default()))
        .expect("writer");
    let sample = Holder {
        id: 7,
        root: node_value(),
        a: A {
            x: 5,
            bs: vec![B {
                y: 6,
                as_: vec![A { x: 8, bs: vec![] }],
            }],
        },
    };
    // Written until the subscriber has what it needs (a best-effort, volatile reader may join late).
    let stop = Arc::new(AtomicBool::new(false));
    let writing = {
        let (stop, sample) = (stop.clone(), sample.clone());
        std::thread::spawn(move || {
            while !stop.load(Ordering::Relaxed) {
                w.write(&sample).expect("write");
                std::thread::sleep(Duration::from_millis(100));
            }
        })
    };
    let domain = REC_DOMAIN.to_string();
    let run = |args: &[&str]| {
        Command::new(&bin)
            .args(args)
            .args(["--domain", &domain])
            .output()
            .expect("running dds")
    };
    let out = run(&["typeof", "RecHolder", "--wait", "20"]);
    let idl = String::from_utf8_lossy(&out.stdout).to_string();
    let sub = run(&[
        "subscribe",
        "RecHolder",
        "--ndjson",
        "-n",
        "2",
        "--timeout",
        "30",
    ]);
    stop.store(true, Ordering::Relaxed);
    writing.join().expect("writer thread");
    assert!(out.status.success(), "dds typeof failed: {out:?}");
    eprintln!("dds typeof RecHolder:\n{idl}");
    for decl in [
        "struct Node {",
        "sequence<Rec::Node> children;",
        "struct A;",
        "struct B {",
        "sequence<Rec::A> as_;",
        "struct Holder {",
        "@key long id;",
    ] {
        assert!(idl.contains(decl), "no {decl:?} in typeof's IDL:\n{idl}");
    }
    let text = String::from_utf8_lossy(&sub.stdout).to_string();
    assert!(sub.status.success(), "dds subscribe failed: {sub:?}");
    let rows = ndjson_rows(&text);
    let expected = serde_json::json!({
        "id": 7,
        "root": {"value": 1, "children": [
            {"value": 2, "children": []},
            {"value": 3, "children": [{"value": 4, "children": []}]},
        ]},
        "a": {"x": 5, "bs": [{"y": 6, "as_": [{"x": 8, "bs": []}]}]},
    });
    assert_eq!(rows.len(), 2, "two samples expected: {text}");
    assert!(rows.iter().all(|r| r == &expected), "{text}");
}

/// Against Fast DDS 2.9, which announces no XTypes type information: `dds typeof` says so and exits 3 (and
/// names `--idl`), and `dds subscribe --idl` with the repository's shape IDL prints the Fast DDS writer's
/// samples.
#[test]
fn dds_against_fastdds_needs_idl_and_works_with_it() {
    use super::harness::{fastdds_peer, root};
    let Ok(()) = require_netns() else { return };
    let Ok(fast) = fastdds_peer() else { return };
    let Ok(bin) = our_bin("dds") else { return };
    let domain = DOMAIN.to_string();
    let mut c = Command::new(fast);
    c.args([
        "-P", "-t", "Square", "-d", &domain, "-c", "RED", "-r", "-x", "1",
    ]);
    let mut p = Proc::spawn("fastdds writer", c);
    let typeof_ = Command::new(&bin)
        .args(["typeof", "Square", "--domain", &domain])
        .output()
        .expect("running dds");
    let err = String::from_utf8_lossy(&typeof_.stderr).to_string();
    check!(
        typeof_.status.code() == Some(3)
            && err.contains("no XTypes type information")
            && err.contains("--idl"),
        &[&p],
        "dds typeof against Fast DDS: {typeof_:?}"
    );
    let idl = root().join("idl/shapes.idl");
    let (rows, text) = three_squares(&bin, &domain, &["--idl".as_ref(), idl.as_os_str()], &p);
    check!(
        rows.len() == 3
            && rows
                .iter()
                .all(|r| r["color"] == "RED" && r["x"].as_i64().is_some()),
        &[&p],
        "three RED samples expected: {text}"
    );
    let _ = p.interrupt(WAIT);
}
