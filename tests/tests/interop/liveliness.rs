//! Manual liveliness against Cyclone DDS 11 (python `cyclonedds`, `dds_assert_liveliness` through ctypes on
//! its libddsc), both directions: a MANUAL_BY_TOPIC writer asserts (HEARTBEATs with the liveliness flag),
//! falls silent past its lease (lost), and comes back (regained: by asserting for our reader; by writing for
//! Cyclone's, which revives a lost writer only on DATA).

use std::process::Command;
use std::time::{Duration, Instant};

use dds_runtime::prelude::*;

use super::harness::{cyclone_peer, require_netns, Proc, Skip};
use crate::check;

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "ShapeType", appendable)]
struct ShapeType {
    #[dds(key)]
    color: String,
    x: i32,
    y: i32,
    shapesize: i32,
}

const LEASE: Duration = Duration::from_secs(1);
const WAIT: Duration = Duration::from_secs(20);

/// The Cyclone side. `writer`: writes once, asserts every 200 ms for 3 s ("asserting"), is silent for 3 s
/// ("silent"), asserts again for 3 s ("asserting again"). `reader`: prints each liveliness change as
/// `liveliness alive=A not_alive=N`, for 15 s. A third argument makes the liveliness AUTOMATIC.
const PEER: &str = r#"
import sys, time
from dataclasses import dataclass
from cyclonedds.core import Listener, Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import appendable, key
from cyclonedds.idl.types import int32
from cyclonedds.internal import load_cyclonedds
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

@dataclass
@appendable
class ShapeType(IdlStruct, typename="ShapeType"):
    color: str
    key("color")
    x: int32
    y: int32
    shapesize: int32

mode, domain = sys.argv[1], int(sys.argv[2])
kind = Policy.Liveliness.Automatic if len(sys.argv) > 3 else Policy.Liveliness.ManualByTopic
qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), kind(duration(seconds=1)))
dp = DomainParticipant(domain)
tp = Topic(dp, "Lively", ShapeType)
if mode == "writer":
    lib = load_cyclonedds()
    w = DataWriter(dp, tp, qos=qos)
    print("created", flush=True)
    time.sleep(2)
    w.write(ShapeType("RED", 1, 1, 30))
    def assert_for(secs):
        end = time.time() + secs
        while time.time() < end:
            rc = lib.dds_assert_liveliness(w._ref)
            if rc != 0:
                print("assert failed", rc, flush=True)
            time.sleep(0.2)
    print("asserting", flush=True)
    assert_for(3)
    print("silent", flush=True)
    time.sleep(3)
    print("asserting again", flush=True)
    assert_for(3)
    print("done", flush=True)
else:
    def changed(reader, st):
        print(f"liveliness alive={st.alive_count} not_alive={st.not_alive_count}", flush=True)
    r = DataReader(dp, tp, qos=qos, listener=Listener(on_liveliness_changed=changed))
    print("created", flush=True)
    time.sleep(15)
    print("done", flush=True)
"#;

fn peer(mode: &str, domain: u32) -> Result<Proc, Skip> {
    peer_with(mode, domain, &[])
}

fn peer_with(mode: &str, domain: u32, extra: &[&str]) -> Result<Proc, Skip> {
    cyclone_peer()?;
    let mut c = Command::new("python3");
    c.args(["-u", "-c", PEER, mode, &domain.to_string()]);
    c.args(extra);
    Ok(Proc::spawn(&format!("cyclone {mode}"), c))
}

fn qos() -> (DataWriterQos, DataReaderQos) {
    let l = Liveliness {
        kind: LivelinessKind::ManualByTopic,
        lease_duration: LEASE,
    };
    let w = DataWriterQos::builder()
        .reliability(Reliability::RELIABLE)
        .liveliness(l)
        .build();
    let r = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .liveliness(l)
        .build();
    (w, r)
}

fn participant(domain: u32) -> DomainParticipant {
    DomainParticipant::builder()
        .domain_id(domain)
        .build()
        .expect("participant")
}

fn wait_until(timeout: Duration, mut f: impl FnMut() -> bool) -> bool {
    let end = Instant::now() + timeout;
    while Instant::now() < end {
        if f() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    f()
}

#[test]
fn manual_liveliness_lost_and_regained_cyclone_to_us() {
    let _ = cyclone_to_us(195);
}

fn cyclone_to_us(domain: u32) -> Result<(), Skip> {
    require_netns()?;
    let p = participant(domain);
    let t = p
        .create_topic::<ShapeType>("Lively", &TopicQos::default())
        .expect("topic");
    let r = p
        .create_subscriber(&SubscriberQos::default())
        .and_then(|s| s.create_datareader(&t, &qos().1))
        .expect("reader");
    let w = peer("writer", domain)?;
    check!(
        w.wait_line(WAIT, |l| l == "silent").is_some(),
        &[&w],
        "peer did not assert"
    );
    let before = r.liveliness_changed_status();
    check!(
        before.not_alive_count == 0 && before.alive_count == 1,
        &[&w],
        "lost while asserting (the matched writer counts alive): {before:?}"
    );
    check!(
        wait_until(Duration::from_secs(3), || r
            .liveliness_changed_status()
            .not_alive_count
            == 1),
        &[&w],
        "not lost while silent: {:?}",
        r.liveliness_changed_status()
    );
    check!(
        w.wait_line(WAIT, |l| l == "asserting again").is_some(),
        &[&w],
        "peer stopped"
    );
    check!(
        wait_until(Duration::from_secs(2), || {
            let s = r.liveliness_changed_status();
            s.alive_count == 1 && s.not_alive_count == 0
        }),
        &[&w],
        "not regained: {:?}",
        r.liveliness_changed_status()
    );
    Ok(())
}

/// Our writer with `wq` on the test topic, matched with the Cyclone reader `rd`, after its first write.
fn matched_writer(
    domain: u32,
    wq: &DataWriterQos,
    rd: &Proc,
) -> Result<(DomainParticipant, DataWriter<ShapeType>), Skip> {
    let p = participant(domain);
    let t = p
        .create_topic::<ShapeType>("Lively", &TopicQos::default())
        .expect("topic");
    let w = p
        .create_publisher(&PublisherQos::default())
        .and_then(|s| s.create_datawriter(&t, wq))
        .expect("writer");
    check!(
        wait_until(WAIT, || w.publication_matched_status().current_count == 1),
        &[rd],
        "no match"
    );
    w.write(&ShapeType {
        color: "RED".into(),
        ..Default::default()
    })
    .expect("write");
    Ok((p, w))
}

#[test]
fn manual_liveliness_lost_and_regained_us_to_cyclone() {
    let _ = us_to_cyclone(196);
}

fn us_to_cyclone(domain: u32) -> Result<(), Skip> {
    require_netns()?;
    let rd = peer("reader", domain)?;
    check!(
        rd.wait_line(WAIT, |l| l == "created").is_some(),
        &[&rd],
        "peer reader"
    );
    let (_p, w) = matched_writer(domain, &qos().0, &rd)?;
    // Matching may take longer than the lease: count lapses from the first write on.
    let base = w.liveliness_lost_status().total_count;
    let assert_for = |d: Duration| {
        let end = Instant::now() + d;
        while Instant::now() < end {
            w.assert_liveliness().expect("assert");
            std::thread::sleep(Duration::from_millis(200));
        }
    };
    assert_for(Duration::from_secs(2));
    check!(
        rd.grep(|l| l.starts_with("liveliness") && !l.ends_with("not_alive=0"))
            .is_empty(),
        &[&rd],
        "lost while asserting"
    );
    check!(
        w.liveliness_lost_status().total_count == base,
        &[&rd],
        "our writer reported LIVELINESS_LOST while asserting"
    );
    std::thread::sleep(Duration::from_secs(2));
    check!(
        rd.wait_line(Duration::from_secs(2), |l| l
            == "liveliness alive=0 not_alive=1")
            .is_some(),
        &[&rd],
        "not lost while silent"
    );
    // Our writer knows it too: LIVELINESS_LOST once for the lapse.
    check!(
        w.liveliness_lost_status().total_count == base + 1,
        &[&rd],
        "our writer did not report LIVELINESS_LOST"
    );
    // Cyclone renews a live writer's lease on a HEARTBEAT with the liveliness flag (checked above: no loss
    // while asserting) but revives a writer it declared lost only when DATA arrives from it.
    w.write(&ShapeType {
        color: "RED".into(),
        x: 2,
        ..Default::default()
    })
    .expect("write");
    assert_for(Duration::from_secs(1));
    check!(
        // The first such line is the writer becoming alive when it matched; the second is the regain.
        rd.wait_lines(Duration::from_secs(2), 2, |l| l
            == "liveliness alive=1 not_alive=0")
            .is_some(),
        &[&rd],
        "not regained"
    );
    eprintln!(
        "cyclone reader saw: {:?}",
        rd.grep(|l| l.starts_with("liveliness"))
    );
    let lost = rd.grep(|l| l == "liveliness alive=0 not_alive=1");
    check!(lost.len() == 1, &[&rd], "lost {} times", lost.len());
    check!(
        w.liveliness_lost_status().total_count == base + 1,
        &[&rd],
        "our writer lost liveliness again after writing and asserting"
    );
    Ok(())
}

/// AUTOMATIC liveliness with a lease (1 s) shorter than our SPDP interval (3 s): the participant asserts
/// often enough for it, so a Cyclone reader requesting the same lease keeps our idle writer alive.
#[test]
fn automatic_liveliness_with_a_short_lease_keeps_an_idle_writer_alive_at_cyclone() {
    let _ = automatic_us_to_cyclone(214);
}

fn automatic_us_to_cyclone(domain: u32) -> Result<(), Skip> {
    require_netns()?;
    let rd = peer_with("reader", domain, &["automatic"])?;
    check!(
        rd.wait_line(WAIT, |l| l == "created").is_some(),
        &[&rd],
        "peer reader"
    );
    let wq = DataWriterQos::builder()
        .reliability(Reliability::RELIABLE)
        .liveliness(Liveliness {
            kind: LivelinessKind::Automatic,
            lease_duration: LEASE,
        })
        .build();
    let (_p, w) = matched_writer(domain, &wq, &rd)?;
    check!(
        rd.wait_line(WAIT, |l| l == "liveliness alive=1 not_alive=0")
            .is_some(),
        &[&rd],
        "never alive"
    );
    // Idle for six leases.
    std::thread::sleep(6 * LEASE);
    let lost = rd.grep(|l| l.starts_with("liveliness") && !l.ends_with("not_alive=0"));
    check!(
        lost.is_empty(),
        &[&rd],
        "idle AUTOMATIC writer lost: {lost:?}"
    );
    check!(
        w.liveliness_lost_status().total_count == 0,
        &[&rd],
        "our writer reported LIVELINESS_LOST"
    );
    Ok(())
}
