//! XTypes on the wire against Cyclone DDS 11 (python `cyclonedds`), with a writer of ours in this process:
//! - the TypeInformation we announce in SEDP is byte-identical to the one Cyclone computes for the same type;
//! - a Cyclone reader of that type matches and receives every sample;
//! - `cyclonedds ls` shows our writer's XTypes type id (no longer "unset");
//! - `cyclonedds ps` shows our host name, process id and program name (SPDP properties).

use std::process::Command;
use std::time::{Duration, Instant};

use dds_runtime::prelude::*;
use dds_runtime::xtypes::typeobject::TypeIdentifier;
use dds_runtime::xtypes::XTypesType;

use super::harness::{cyclone_peer, require_netns, Proc, Skip};

const URI: &str = r#"<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces><AllowMulticast>true</AllowMulticast></General></Domain></CycloneDDS>"#;

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(name = "XtShape", appendable)]
pub struct XtShape {
    #[dds(key)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
}

/// The same type in the Python binding: prints its TypeInformation, then every sample it reads.
const READER: &str = r#"
import sys, time
from dataclasses import dataclass
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.sub import DataReader
from cyclonedds.core import Qos, Policy
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import key, appendable
from cyclonedds.idl.types import int32

@dataclass
@appendable
class XtShape(IdlStruct, typename="XtShape"):
    color: str
    key("color")
    x: int32
    y: int32
    shapesize: int32

XtShape.__idl__.fill_type_data()
print("TYPEINFO", XtShape.__idl__._xt_bytedata[0].hex(), flush=True)
dp = DomainParticipant(int(sys.argv[1]))
qos = Qos(Policy.Reliability.Reliable(max_blocking_time=1000000000), Policy.History.KeepAll)
r = DataReader(dp, Topic(dp, "XtSquare", XtShape), qos=qos)
want, got, end = int(sys.argv[2]), 0, time.time() + 30
while got < want and time.time() < end:
    for s in r.take(N=100):
        if isinstance(s, XtShape):
            got += 1
            print("SAMPLE", s.color, s.x, flush=True)
    time.sleep(0.05)
print("DONE", got, flush=True)
"#;

fn cyclonedds_cli(args: &[&str]) -> Command {
    let mut c = Command::new("cyclonedds");
    c.args(args)
        .env("CYCLONEDDS_URI", URI)
        .env("COLUMNS", "300")
        .env("NO_COLOR", "1");
    c
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

#[test]
fn cyclone_sees_our_type_information_and_process() -> Result<(), Skip> {
    require_netns()?;
    cyclone_peer()?;
    // Announcing type information is opt-in (docs/xtypes.md); nextest runs each test in its own process.
    std::env::set_var(dds_runtime::xtypes::ANNOUNCE_ENV, "on");
    let domain = 141;
    let p = DomainParticipant::builder()
        .domain_id(domain)
        .interface("lo")
        .spdp_interval(Duration::from_millis(200))
        .build()
        .expect("participant");
    let t = p
        .create_topic::<XtShape>("XtSquare", &TopicQos::default())
        .unwrap();
    let wq = DataWriterQos::builder()
        .reliability(Reliability::Reliable {
            max_blocking_time: Duration::from_secs(1),
        })
        .history(History::KeepAll)
        .build();
    let w = p
        .create_publisher(&PublisherQos::default())
        .unwrap()
        .create_datawriter(&t, &wq)
        .unwrap();
    let support = XtShape::type_support().expect("type support");

    let mut py = Command::new("python3");
    py.args(["-c", READER, &domain.to_string(), "10"])
        .env("CYCLONEDDS_URI", URI);
    let reader = Proc::spawn("cyclone reader", py);
    let theirs = reader
        .wait_line(Duration::from_secs(20), |l| l.starts_with("TYPEINFO "))
        .unwrap_or_else(|| panic!("no TYPEINFO line\n{}", reader.dump()));
    assert_eq!(
        theirs["TYPEINFO ".len()..].trim(),
        hex(&support.information_bytes),
        "TypeInformation bytes"
    );

    let deadline = Instant::now() + Duration::from_secs(20);
    while w.publication_matched_status().current_count < 1 {
        assert!(
            Instant::now() < deadline,
            "no match with Cyclone\n{}",
            reader.dump()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    for i in 0..10 {
        w.write(&XtShape {
            color: "RED".into(),
            x: i,
            y: 2 * i,
            shapesize: 30,
        })
        .unwrap();
    }
    let done = reader
        .wait_line(Duration::from_secs(30), |l| l.starts_with("DONE "))
        .unwrap_or_else(|| panic!("reader did not finish\n{}", reader.dump()));
    assert_eq!(done.trim(), "DONE 10", "{}", reader.dump());

    let ls = cyclonedds_cli(&[
        "ls",
        "-i",
        &domain.to_string(),
        "-r",
        "3s",
        "--suppress-progress-bar",
        "-t",
        "XtSquare",
    ])
    .output()
    .expect("cyclonedds ls");
    let ls_out = String::from_utf8_lossy(&ls.stdout);
    let ids: Vec<String> = [support.complete_id(), support.minimal_id()]
        .iter()
        .filter_map(|id| match id {
            TypeIdentifier::Minimal(h) | TypeIdentifier::Complete(h) => Some(hex(h).to_uppercase()),
            _ => None,
        })
        .collect();
    assert!(
        ids.iter().any(|h| ls_out.contains(h.as_str())),
        "our type id {ids:?} not in `cyclonedds ls`:\n{ls_out}"
    );

    let ps = cyclonedds_cli(&[
        "ps",
        "-i",
        &domain.to_string(),
        "-r",
        "3s",
        "--suppress-progress-bar",
    ])
    .output()
    .expect("cyclonedds ps");
    let ps_out = String::from_utf8_lossy(&ps.stdout);
    let pid = std::process::id().to_string();
    let exe = std::env::current_exe().unwrap();
    let exe = exe.file_name().unwrap().to_string_lossy();
    let host = String::from_utf8(Command::new("hostname").output().unwrap().stdout).unwrap();
    let row = ps_out
        .lines()
        .find(|l| l.contains(&pid))
        .unwrap_or_else(|| panic!("pid {pid} not in `cyclonedds ps`:\n{ps_out}"));
    assert!(row.contains(host.trim()), "host {host:?} not in {row:?}");
    assert!(row.contains(exe.as_ref()), "program {exe:?} not in {row:?}");
    println!("cyclonedds ps: {row}");
    drop(reader);
    Ok(())
}
