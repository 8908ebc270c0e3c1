//! Type evolution against Cyclone DDS 11 (python `cyclonedds`) and ourselves: a writer of version 1 and a
//! reader of version 2 of an `@appendable` type (members added at the end), and of a `@mutable` type (members
//! reordered, one added, explicit ids), exchange data in both directions; each side reads in its own version.
//!
//! Neither side runs a TypeLookup service here: each process knows both versions (the Python peer creates a
//! topic of each, we build both type supports), so both resolve the other's type identifiers locally. The
//! test first checks that both sides compute the same TypeInformation for every version, since otherwise
//! they could not resolve each other's types.

use std::process::Command;
use std::time::{Duration, Instant};

use dds_runtime::prelude::*;
use dds_runtime::xtypes::XTypesType;

use super::harness::{cyclone_peer, loopback_participant, require_netns, Proc, Skip};

const URI: &str = r#"<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces><AllowMulticast>true</AllowMulticast></General></Domain></CycloneDDS>"#;

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "EvoApp", appendable)]
pub struct AppV1 {
    #[dds(key)]
    pub color: String,
    pub x: i32,
    pub y: i32,
}

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "EvoApp", appendable)]
pub struct AppV2 {
    #[dds(key)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub size: i32,
    pub label: String,
}

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "EvoMut", mutable)]
pub struct MutV1 {
    #[dds(key, id = 10)]
    pub color: String,
    #[dds(id = 20)]
    pub x: i32,
    #[dds(id = 30)]
    pub y: i32,
}

/// Version 2: declared in another order, with `size` (id 40) added.
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "EvoMut", mutable)]
pub struct MutV2 {
    #[dds(id = 30)]
    pub y: i32,
    #[dds(id = 40)]
    pub size: i32,
    #[dds(key, id = 10)]
    pub color: String,
    #[dds(id = 20)]
    pub x: i32,
}

/// The four types in the Python binding. `role name count`: read `count` samples as version `name`
/// (printing each as JSON), or write `count` samples of it once matched (then stay 20 s).
const PEER: &str = r#"
import sys, time, json, dataclasses
from dataclasses import dataclass
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.sub import DataReader
from cyclonedds.pub import DataWriter
from cyclonedds.core import Qos, Policy
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import key, appendable, mutable, member_id
from cyclonedds.idl.types import int32

@dataclass
@appendable
class AppV1(IdlStruct, typename="EvoApp"):
    color: str
    key("color")
    x: int32
    y: int32

@dataclass
@appendable
class AppV2(IdlStruct, typename="EvoApp"):
    color: str
    key("color")
    x: int32
    y: int32
    size: int32
    label: str

@dataclass
@mutable
class MutV1(IdlStruct, typename="EvoMut"):
    color: str
    key("color")
    member_id("color", 10)
    x: int32
    member_id("x", 20)
    y: int32
    member_id("y", 30)

@dataclass
@mutable
class MutV2(IdlStruct, typename="EvoMut"):
    y: int32
    member_id("y", 30)
    size: int32
    member_id("size", 40)
    color: str
    key("color")
    member_id("color", 10)
    x: int32
    member_id("x", 20)

TYPES = {"AppV1": AppV1, "AppV2": AppV2, "MutV1": MutV1, "MutV2": MutV2}
domain, role, name, count = int(sys.argv[1]), sys.argv[2], sys.argv[3], int(sys.argv[4])
dp = DomainParticipant(domain)
keep = []
for n, t in TYPES.items():
    t.__idl__.fill_type_data()
    print("TYPEINFO", n, t.__idl__._xt_bytedata[0].hex(), flush=True)
    keep.append(Topic(dp, "EvoRegister" + n, t))
qos = Qos(Policy.Reliability.Reliable(max_blocking_time=1000000000), Policy.History.KeepAll,
          Policy.Durability.TransientLocal)
T = TYPES[name]
topic = Topic(dp, "Evo" + name[:3], T)
if role == "read":
    r = DataReader(dp, topic, qos=qos)
    got, end = 0, time.time() + 30
    while got < count and time.time() < end:
        for s in r.take(N=100):
            if isinstance(s, T):
                got += 1
                print("SAMPLE", json.dumps(dataclasses.asdict(s), sort_keys=True), flush=True)
        time.sleep(0.05)
    print("DONE", got, flush=True)
else:
    w = DataWriter(dp, topic, qos=qos)
    end = time.time() + 20
    while w.get_publication_matched_status().current_count < 1 and time.time() < end:
        time.sleep(0.05)
    print("MATCHED", w.get_publication_matched_status().current_count, flush=True)
    # Cyclone matches our reader when it sees our SEDP; we match its writer when we see its SEDP, which may
    # come later: give our side time (see docs/xtypes.md, "Limits").
    time.sleep(1.0)
    for i in range(count):
        if name.startswith("App"):
            s = T(color="CYC", x=i, y=2 * i) if name == "AppV1" else T(color="CYC", x=i, y=2 * i, size=30, label="v2")
        else:
            s = T(color="CYC", x=i, y=2 * i) if name == "MutV1" else T(color="CYC", x=i, y=2 * i, size=30)
        w.write(s)
    print("WROTE", count, flush=True)
    time.sleep(20)
"#;

const COUNT: i32 = 5;

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

fn qos() -> (DataWriterQos, DataReaderQos) {
    let rel = Reliability::Reliable {
        max_blocking_time: Duration::from_secs(1),
    };
    (
        DataWriterQos::builder()
            .reliability(rel)
            .history(History::KeepAll)
            .durability(Durability::TransientLocal)
            .build(),
        DataReaderQos::builder()
            .reliability(rel)
            .history(History::KeepAll)
            .durability(Durability::TransientLocal)
            .build(),
    )
}

fn peer(domain: u32, role: &str, name: &str) -> Proc {
    let mut py = Command::new("python3");
    py.args([
        "-c",
        PEER,
        &domain.to_string(),
        role,
        name,
        &COUNT.to_string(),
    ])
    .env("CYCLONEDDS_URI", URI);
    Proc::spawn(&format!("cyclone {role} {name}"), py)
}

/// Our reader of `R` takes `COUNT` samples (from whoever writes) and returns them in order of `key`.
fn read_all<R: DdsType + Clone>(r: &DataReader<R>, key: impl Fn(&R) -> i32) -> Vec<R> {
    let mut got: Vec<R> = Vec::new();
    let end = Instant::now() + Duration::from_secs(30);
    while (got.len() as i32) < COUNT && Instant::now() < end {
        got.extend(
            r.take()
                .unwrap()
                .into_iter()
                .filter_map(|s| s.data().cloned()),
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    got.sort_by_key(|s| key(s));
    got
}

fn topic<T: DdsType>(p: &DomainParticipant, name: &str) -> Topic<T> {
    p.create_topic::<T>(name, &TopicQos::default()).unwrap()
}

fn writer<T: DdsType>(p: &DomainParticipant, name: &str) -> DataWriter<T> {
    p.create_publisher(&PublisherQos::default())
        .unwrap()
        .create_datawriter(&topic::<T>(p, name), &qos().0)
        .unwrap()
}

fn reader<T: DdsType>(p: &DomainParticipant, name: &str) -> DataReader<T> {
    p.create_subscriber(&SubscriberQos::default())
        .unwrap()
        .create_datareader(&topic::<T>(p, name), &qos().1)
        .unwrap()
}

/// What a Cyclone reader printed, as JSON values in `x` order.
fn cyclone_samples(p: &Proc) -> Vec<serde_json::Value> {
    let done = p
        .wait_line(Duration::from_secs(40), |l| l.starts_with("DONE "))
        .unwrap_or_else(|| panic!("reader did not finish\n{}", p.dump()));
    assert_eq!(done.trim(), format!("DONE {COUNT}"), "{}", p.dump());
    let mut v: Vec<serde_json::Value> = p
        .grep(|l| l.starts_with("SAMPLE "))
        .iter()
        .map(|l| serde_json::from_str(&l["SAMPLE ".len()..]).unwrap())
        .collect();
    v.sort_by_key(|s| s["x"].as_i64());
    v
}

fn check_type_information(p: &Proc) {
    let ours = [
        ("AppV1", AppV1::type_support()),
        ("AppV2", AppV2::type_support()),
        ("MutV1", MutV1::type_support()),
        ("MutV2", MutV2::type_support()),
    ];
    let lines = p
        .wait_lines(Duration::from_secs(20), 4, |l| l.starts_with("TYPEINFO "))
        .unwrap_or_else(|| panic!("no TYPEINFO lines\n{}", p.dump()));
    for (name, support) in ours {
        let line = lines
            .iter()
            .find(|l| l.starts_with(&format!("TYPEINFO {name} ")))
            .unwrap_or_else(|| panic!("no TYPEINFO for {name}\n{}", p.dump()));
        assert_eq!(
            line.split_whitespace().nth(2).unwrap(),
            hex(&support.expect("type support").information_bytes),
            "{name}: Cyclone's TypeInformation differs from ours"
        );
    }
}

#[test]
fn evolution_against_cyclone() -> Result<(), Skip> {
    require_netns()?;
    cyclone_peer()?;
    std::env::set_var(dds_runtime::xtypes::ANNOUNCE_ENV, "on");
    let domain = 143;
    let p = loopback_participant(domain);
    let app = |x: i32, v2: bool| {
        (
            x,
            2 * x,
            if v2 { 30 } else { 0 },
            if v2 { "v2" } else { "" }.to_string(),
        )
    };

    // Our version-1 writers, Cyclone's version-2 readers.
    let w1 = writer::<AppV1>(&p, "EvoApp");
    let m1 = writer::<MutV1>(&p, "EvoMut");
    for x in 0..COUNT {
        w1.write(&AppV1 {
            color: "OURS".into(),
            x,
            y: 2 * x,
        })
        .unwrap();
        m1.write(&MutV1 {
            color: "OURS".into(),
            x,
            y: 2 * x,
        })
        .unwrap();
    }
    let r = peer(domain, "read", "AppV2");
    check_type_information(&r);
    let got = cyclone_samples(&r);
    for (x, s) in got.iter().enumerate() {
        let (x, y, size, label) = app(x as i32, false);
        assert_eq!(
            s,
            &serde_json::json!({"color": "OURS", "x": x, "y": y, "size": size, "label": label})
        );
    }
    let r = peer(domain, "read", "MutV2");
    for (x, s) in cyclone_samples(&r).iter().enumerate() {
        let x = x as i32;
        assert_eq!(
            s,
            &serde_json::json!({"color": "OURS", "x": x, "y": 2 * x, "size": 0})
        );
    }
    drop((w1, m1));

    // Cyclone's version-2 writers, our version-1 readers.
    // Readers first: Cyclone keeps only the durability_service history (KEEP_LAST 1) for late joiners.
    let (ra, rm) = (reader::<AppV1>(&p, "EvoApp"), reader::<MutV1>(&p, "EvoMut"));
    let _wa = peer(domain, "write", "AppV2");
    let _wm = peer(domain, "write", "MutV2");
    let a: Vec<AppV1> = read_all(&ra, |s| s.x);
    assert_eq!(
        a,
        (0..COUNT)
            .map(|x| AppV1 {
                color: "CYC".into(),
                x,
                y: 2 * x
            })
            .collect::<Vec<_>>()
    );
    let m: Vec<MutV1> = read_all(&rm, |s| s.x);
    assert_eq!(
        m,
        (0..COUNT)
            .map(|x| MutV1 {
                color: "CYC".into(),
                x,
                y: 2 * x
            })
            .collect::<Vec<_>>()
    );
    drop((_wa, _wm, ra, rm));

    // Cyclone's version-1 writers, our version-2 readers (defaults for what version 1 lacks).
    let p2 = loopback_participant(domain);
    let (ra, rm) = (
        reader::<AppV2>(&p2, "EvoApp"),
        reader::<MutV2>(&p2, "EvoMut"),
    );
    let _wa = peer(domain, "write", "AppV1");
    let _wm = peer(domain, "write", "MutV1");
    let a: Vec<AppV2> = read_all(&ra, |s| s.x);
    let want: Vec<AppV2> = (0..COUNT)
        .map(|x| AppV2 {
            color: "CYC".into(),
            x,
            y: 2 * x,
            ..Default::default()
        })
        .collect();
    assert_eq!(a, want);
    let m: Vec<MutV2> = read_all(&rm, |s| s.x);
    let want: Vec<MutV2> = (0..COUNT)
        .map(|x| MutV2 {
            color: "CYC".into(),
            x,
            y: 2 * x,
            size: 0,
        })
        .collect();
    assert_eq!(m, want);
    drop((_wa, _wm, ra, rm));

    // Our version-2 writers, Cyclone's version-1 readers.
    let w2 = writer::<AppV2>(&p2, "EvoApp");
    let m2 = writer::<MutV2>(&p2, "EvoMut");
    for x in 0..COUNT {
        w2.write(&AppV2 {
            color: "OURS2".into(),
            x,
            y: 2 * x,
            size: 30,
            label: "v2".into(),
        })
        .unwrap();
        m2.write(&MutV2 {
            color: "OURS2".into(),
            x,
            y: 2 * x,
            size: 30,
        })
        .unwrap();
    }
    let r = peer(domain, "read", "AppV1");
    for (x, s) in cyclone_samples(&r).iter().enumerate() {
        let x = x as i32;
        assert_eq!(
            s,
            &serde_json::json!({"color": "OURS2", "x": x, "y": 2 * x})
        );
    }
    let r = peer(domain, "read", "MutV1");
    for (x, s) in cyclone_samples(&r).iter().enumerate() {
        let x = x as i32;
        assert_eq!(
            s,
            &serde_json::json!({"color": "OURS2", "x": x, "y": 2 * x})
        );
    }
    Ok(())
}

/// The same exchanges ours against ours: version-1 writer and version-2 reader, and the reverse, both kinds.
#[test]
fn evolution_ours_against_ours() -> Result<(), Skip> {
    require_netns()?;
    std::env::set_var(dds_runtime::xtypes::ANNOUNCE_ENV, "on");
    let domain = 144;
    let (pw, pr) = (loopback_participant(domain), loopback_participant(domain));
    let (w1, m1) = (
        writer::<AppV1>(&pw, "EvoApp"),
        writer::<MutV1>(&pw, "EvoMut"),
    );
    let (w2, m2) = (
        writer::<AppV2>(&pw, "EvoApp2"),
        writer::<MutV2>(&pw, "EvoMut2"),
    );
    for x in 0..COUNT {
        w1.write(&AppV1 {
            color: "A".into(),
            x,
            y: 2 * x,
        })
        .unwrap();
        m1.write(&MutV1 {
            color: "A".into(),
            x,
            y: 2 * x,
        })
        .unwrap();
        w2.write(&AppV2 {
            color: "B".into(),
            x,
            y: 2 * x,
            size: 30,
            label: "v2".into(),
        })
        .unwrap();
        m2.write(&MutV2 {
            color: "B".into(),
            x,
            y: 2 * x,
            size: 30,
        })
        .unwrap();
    }
    let a: Vec<AppV2> = read_all(&reader::<AppV2>(&pr, "EvoApp"), |s| s.x);
    let want: Vec<AppV2> = (0..COUNT)
        .map(|x| AppV2 {
            color: "A".into(),
            x,
            y: 2 * x,
            ..Default::default()
        })
        .collect();
    assert_eq!(a, want);
    let m: Vec<MutV2> = read_all(&reader::<MutV2>(&pr, "EvoMut"), |s| s.x);
    let want: Vec<MutV2> = (0..COUNT)
        .map(|x| MutV2 {
            color: "A".into(),
            x,
            y: 2 * x,
            size: 0,
        })
        .collect();
    assert_eq!(m, want);
    let a: Vec<AppV1> = read_all(&reader::<AppV1>(&pr, "EvoApp2"), |s| s.x);
    assert_eq!(
        a,
        (0..COUNT)
            .map(|x| AppV1 {
                color: "B".into(),
                x,
                y: 2 * x
            })
            .collect::<Vec<_>>()
    );
    let m: Vec<MutV1> = read_all(&reader::<MutV1>(&pr, "EvoMut2"), |s| s.x);
    assert_eq!(
        m,
        (0..COUNT)
            .map(|x| MutV1 {
                color: "B".into(),
                x,
                y: 2 * x
            })
            .collect::<Vec<_>>()
    );
    Ok(())
}
