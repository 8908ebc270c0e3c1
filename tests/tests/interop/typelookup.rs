//! The XTypes TypeLookup service against Cyclone DDS 11 (python `cyclonedds`), in both directions:
//! - `cyclonedds typeof` on a topic of ours resolves our type through our service and prints its IDL;
//! - `cyclonedds subscribe` on it prints our samples (decoded through the type it learnt from us);
//! - our client fetches the type of a topic written by a Cyclone Python program, a type this binary was never
//!   compiled with, and every object it stores hashes to the identifier Cyclone announced.

use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use dds_runtime::prelude::*;
use dds_runtime::xtypes::typeobject::{from_bytes, TypeBody, TypeInformation, TypeObject};

use super::harness::{cyclone_peer, loopback_participant, require_netns, Proc, Skip};

const URI: &str = r#"<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces><AllowMulticast>true</AllowMulticast></General></Domain></CycloneDDS>"#;

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "tl::Inner", appendable)]
pub struct Inner {
    pub a: i64,
    pub s: String,
}

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "tl::Outer")]
pub struct Outer {
    #[dds(key)]
    pub id: i32,
    pub inner: Inner,
    pub xs: Vec<Inner>,
}

/// The IDL Cyclone should rebuild from our type objects (lines trimmed, blank lines dropped); the derive's
/// default extensibility is appendable.
const OUR_IDL: &[&str] = &[
    "module tl {",
    "@appendable",
    "struct Inner {",
    "long long a;",
    "string s;",
    "};",
    "@appendable",
    "struct Outer {",
    "@key long id;",
    "tl::Inner inner;",
    "sequence<tl::Inner>  xs;",
    "};",
    "};",
];

/// `cyclonedds ARGS`, killed after `secs` (`subscribe` runs until interrupted).
fn cyclonedds_cli(secs: u32, args: &[&str]) -> Command {
    let mut c = Command::new("timeout");
    c.arg(secs.to_string())
        .arg("cyclonedds")
        .args(args)
        .env("CYCLONEDDS_URI", URI)
        .env("COLUMNS", "300")
        .env("NO_COLOR", "1");
    c
}

/// A participant of ours writing `Outer` samples on `topic` every 100 ms until the flag drops.
fn our_writer(
    domain: u32,
    topic: &str,
) -> (
    DomainParticipant,
    Arc<AtomicBool>,
    std::thread::JoinHandle<()>,
) {
    let p = loopback_participant(domain);
    let t = p
        .create_topic::<Outer>(topic, &TopicQos::default())
        .unwrap();
    let w = p
        .create_publisher(&PublisherQos::default())
        .unwrap()
        .create_datawriter(&t, &DataWriterQos::default())
        .unwrap();
    let run = Arc::new(AtomicBool::new(true));
    let flag = run.clone();
    let h = std::thread::spawn(move || {
        let mut i = 0;
        while flag.load(Ordering::Relaxed) {
            let s = Outer {
                id: i % 3,
                inner: Inner {
                    a: 1000 + i64::from(i),
                    s: format!("sample{i}"),
                },
                xs: vec![Inner {
                    a: 7,
                    s: "x".into(),
                }],
            };
            let _ = w.write(&s);
            i += 1;
            std::thread::sleep(Duration::from_millis(100));
        }
    });
    (p, run, h)
}

fn idl_lines(out: &str) -> Vec<String> {
    out.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with("As defined in"))
        .map(str::to_owned)
        .collect()
}

#[test]
fn cyclone_typeof_and_subscribe_resolve_our_type() -> Result<(), Skip> {
    require_netns()?;
    cyclone_peer()?;
    let domain = 151;
    let (_p, run, h) = our_writer(domain, "TlSquare");
    let d = domain.to_string();
    let typeof_out = cyclonedds_cli(
        30,
        &[
            "typeof",
            "-i",
            &d,
            "-r",
            "5s",
            "--suppress-progress-bar",
            "TlSquare",
        ],
    )
    .output()
    .expect("cyclonedds typeof");
    let text = String::from_utf8_lossy(&typeof_out.stdout);
    let lines = idl_lines(&text);
    let start = lines.iter().position(|l| l == "module tl {");
    let got: Vec<&str> = start
        .map(|s| {
            lines[s..]
                .iter()
                .map(String::as_str)
                .take(OUR_IDL.len())
                .collect()
        })
        .unwrap_or_default();
    assert_eq!(
        got,
        OUR_IDL,
        "cyclonedds typeof printed:\n{text}\n{}",
        String::from_utf8_lossy(&typeof_out.stderr)
    );

    let sub = cyclonedds_cli(
        12,
        &[
            "subscribe",
            "-i",
            &d,
            "-r",
            "6s",
            "--suppress-progress-bar",
            "--qos",
            "dds-default",
            "TlSquare",
        ],
    )
    .output()
    .expect("cyclonedds subscribe");
    let sub_text = String::from_utf8_lossy(&sub.stdout);
    let samples = sub_text.lines().filter(|l| l.contains("sample")).count();
    assert!(
        samples >= 3 && sub_text.contains("Outer(") && sub_text.contains("Inner("),
        "cyclonedds subscribe printed {samples} samples:\n{sub_text}\n{}",
        String::from_utf8_lossy(&sub.stderr)
    );
    run.store(false, Ordering::Relaxed);
    h.join().unwrap();
    Ok(())
}

/// A Cyclone writer of a type we were never compiled with; prints its TypeInformation, writes until killed.
const WRITER: &str = r#"
import sys, time
from dataclasses import dataclass
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.pub import DataWriter
from cyclonedds.idl import IdlStruct, IdlUnion
from cyclonedds.idl.types import sequence, int16, case, default, array
import cyclonedds.idl.annotations as annotate

@dataclass
@annotate.mutable
class Point(IdlStruct, typename="py::Point"):
    x: float
    y: float
    label: str

class Choice(IdlUnion, discriminator=int16, typename="py::Choice"):
    p: case[1, Point]
    n: case[2, int]
    s: default[str]

@dataclass
@annotate.appendable
class Track(IdlStruct, typename="py::Track"):
    id: int
    points: sequence[Point]
    what: Choice
    tags: array[int16, 3]

Track.__idl__.fill_type_data()
print("TYPEINFO", Track.__idl__._xt_bytedata[0].hex(), flush=True)
dp = DomainParticipant(int(sys.argv[1]))
w = DataWriter(dp, Topic(dp, "PyTrack", Track))
i = 0
while True:
    w.write(Track(id=i, points=[Point(x=1.0, y=2.0, label="a")], what=Choice(n=i), tags=[1, 2, 3]))
    i += 1
    time.sleep(0.1)
"#;

fn struct_members(o: &TypeObject) -> Vec<String> {
    let TypeObject::Complete(c) = o else {
        panic!("not complete: {o:?}")
    };
    match &c.0 {
        TypeBody::Struct { members, .. } => members.iter().map(|m| format!("{:?}", m)).collect(),
        other => vec![format!("{other:?}")],
    }
}

#[test]
fn our_client_fetches_a_cyclone_python_type() -> Result<(), Skip> {
    require_netns()?;
    cyclone_peer()?;
    let domain = 152;
    let mut py = Command::new("python3");
    py.args(["-c", WRITER, &domain.to_string()])
        .env("CYCLONEDDS_URI", URI);
    let writer = Proc::spawn("cyclone writer", py);
    let line = writer
        .wait_line(Duration::from_secs(20), |l| l.starts_with("TYPEINFO "))
        .unwrap_or_else(|| panic!("no TYPEINFO line\n{}", writer.dump()));
    let hex = line["TYPEINFO ".len()..].trim();
    let bytes: Vec<u8> = (0..hex.len() / 2)
        .map(|i| u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).unwrap())
        .collect();
    let theirs: TypeInformation = from_bytes(&bytes).unwrap();

    let p = loopback_participant(domain);
    let t = p
        .discovered_topic_type("PyTrack", Duration::from_secs(20))
        .unwrap_or_else(|e| panic!("type not resolved: {e}\n{}", writer.dump()));
    assert_eq!(t.type_name, "py::Track");
    // The same identifiers (libddsc announces the topic types' serialized sizes as 0, the binding computes
    // them, so the whole structures differ in those two numbers).
    for (ours, py) in [
        (&t.information.minimal, &theirs.minimal),
        (&t.information.complete, &theirs.complete),
    ] {
        assert_eq!(ours.typeid_with_size.type_id, py.typeid_with_size.type_id);
        assert_eq!(ours.dependent_typeids, py.dependent_typeids);
    }
    // Track, Point and Choice: every complete object, each stored after its hash was checked.
    assert_eq!(
        t.complete.len(),
        1 + theirs.complete.dependent_typeids.len()
    );
    assert!(t.complete.len() >= 3, "{:?}", t.complete);
    assert_eq!(t.complete[0].0, theirs.complete.typeid_with_size.type_id);
    let members = struct_members(t.top()).join("\n");
    for name in ["\"id\"", "\"points\"", "\"what\"", "\"tags\""] {
        assert!(members.contains(name), "{name} not in\n{members}");
    }
    // The minimal objects can be resolved too, one by one.
    let minimal = &theirs.minimal.typeid_with_size.type_id;
    let m = p
        .discovered_type(minimal, Duration::from_secs(10))
        .expect("minimal type");
    assert!(matches!(*m, TypeObject::Minimal(_)));
    drop(writer);
    Ok(())
}
