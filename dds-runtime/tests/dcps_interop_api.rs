//! The DCPS API against a real Cyclone DDS 11 peer (python `cyclonedds`, inline scripts): a changed
//! OWNERSHIP_STRENGTH re-announced in SEDP (`set_qos`), and `ignore_participant`. (Cyclone 11 does not rematch
//! a remote writer whose PARTITION changed, so a partition change is tested between our own participants,
//! in `dcps_api::publisher_set_qos_partition_rematches`.)
//! Ignored by default (needs python3 + cyclonedds); the nextest profile `interop` runs it:
//! `scripts/isolated cargo nextest run -p dds-runtime --profile interop --run-ignored all --test dcps_interop_api`.
mod dcps_util;

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use dcps_util::*;
use dds_runtime::prelude::*;

const CYCLONE_URI: &str = r#"<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces><AllowMulticast>true</AllowMulticast></General></Domain></CycloneDDS>"#;

/// The shape type and a participant, shared by the scripts.
const PRELUDE: &str = r#"
import os, sys, time
sys.path.insert(0, os.environ["DCPS_UTIL"])
from cyclone_shapes import ShapeType  # the shapes type, as the other Cyclone interop test declares it
from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader, Subscriber
from cyclonedds.topic import Topic
from cyclonedds.util import duration

dp = DomainParticipant(int(os.environ["DDS_DOMAIN_ID"]))
tp = Topic(dp, sys.argv[1], ShapeType)
RELIABLE = Policy.Reliability.Reliable(duration(seconds=1))
def out(*a):
    print(*a, flush=True)
"#;

/// Reads partition B; prints `x=N` per sample and `strength=N` whenever a matched writer's announced
/// ownership strength changes (first when it matches); exits after `x=99` with strength 42 seen, or after 20 s.
const READER: &str = r#"
sub = Subscriber(dp, qos=Qos(Policy.Partition(["B"])))
r = DataReader(sub, tp, qos=Qos(RELIABLE))
seen_x, seen_s, last = False, False, None
end = time.time() + 20
while time.time() < end and not (seen_x and seen_s):
    for s in r.take(N=10):
        out(f"x={s.x}")
        seen_x = seen_x or s.x == 99
    for h in r.get_matched_publications():
        d = r.get_matched_publication_data(h)
        st = d.qos[Policy.OwnershipStrength].strength if d and Policy.OwnershipStrength in d.qos else 0
        if st != last:
            out(f"strength={st}")
            last = st
        seen_s = seen_s or st == 42
    time.sleep(0.02)
time.sleep(2)  # stay to acknowledge what was received
"#;

/// Writes x = 0, 1, ... every 20 ms for 15 s.
const WRITER: &str = r#"
w = DataWriter(dp, tp, qos=Qos(RELIABLE))
out("writing")
end, i = time.time() + 15, 0
while time.time() < end:
    w.write(ShapeType("RED", i, 0, 30))
    i += 1
    time.sleep(0.02)
"#;

/// The Cyclone process, killed when dropped (also when an assertion fails).
struct Peer(Child);

impl Drop for Peer {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Runs `PRELUDE + body` with `topic` as argument; its stdout lines arrive on the receiver.
fn cyclone(domain: u32, topic: &str, body: &str) -> (Peer, mpsc::Receiver<String>) {
    let mut child = Command::new("python3")
        .arg("-c")
        .arg(format!("{PRELUDE}{body}"))
        .arg(topic)
        .env("CYCLONEDDS_URI", CYCLONE_URI)
        .env("DDS_DOMAIN_ID", domain.to_string())
        .env(
            "DCPS_UTIL",
            concat!(env!("CARGO_MANIFEST_DIR"), "/tests/dcps_util"),
        )
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("python3 with cyclonedds");
    let out = BufReader::new(child.stdout.take().unwrap());
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for l in out.lines().map_while(Result::ok) {
            if tx.send(l).is_err() {
                break;
            }
        }
    });
    (Peer(child), rx)
}

/// Collects lines until one equals `want` or `timeout` passes.
fn wait_line(
    rx: &mpsc::Receiver<String>,
    want: &str,
    timeout: Duration,
    seen: &mut Vec<String>,
) -> bool {
    let end = Instant::now() + timeout;
    while let Some(left) = end.checked_duration_since(Instant::now()) {
        match rx.recv_timeout(left) {
            Ok(l) => {
                let hit = l == want;
                seen.push(l);
                if hit {
                    return true;
                }
            }
            Err(_) => return false,
        }
    }
    false
}

#[test]
#[ignore = "needs python3 with cyclonedds; run by the interop profile"]
fn set_qos_strength_reaches_cyclone() {
    let p = participant(64);
    let t = p
        .create_topic::<ShapeType>("ApiPart", &TopicQos::default())
        .unwrap();
    let publ = p
        .create_publisher(&PublisherQos::builder().partition(["B"]).build())
        .unwrap();
    let w = publ
        .create_datawriter(
            &t,
            &DataWriterQos::builder().reliability(reliable()).build(),
        )
        .unwrap();
    let (child, rx) = cyclone(64, "ApiPart", READER);
    assert!(
        wait_until(Duration::from_secs(20), || w.matched_subscriptions().len()
            == 1),
        "no match with Cyclone"
    );
    let mut seen = Vec::new();
    assert!(
        wait_line(&rx, "strength=0", Duration::from_secs(20), &mut seen),
        "Cyclone did not match our writer: {seen:?}"
    );
    let mut q = w.get_qos().unwrap();
    q.ownership_strength = OwnershipStrength(42);
    w.set_qos(&q).unwrap();
    w.write(&shape("RED", 99)).unwrap();
    let acked = w.wait_for_acknowledgments(Duration::from_secs(10));
    let got_x = wait_line(&rx, "x=99", Duration::from_secs(20), &mut seen);
    let got_s = seen.iter().any(|l| l == "strength=42")
        || wait_line(&rx, "strength=42", Duration::from_secs(20), &mut seen);
    drop(child);
    assert!(
        acked.is_ok(),
        "not acknowledged: {acked:?}, Cyclone printed {seen:?}"
    );
    assert!(got_x, "Cyclone did not receive the sample: {seen:?}");
    assert!(
        got_s,
        "Cyclone did not see the new ownership strength: {seen:?}"
    );
}

#[test]
#[ignore = "needs python3 with cyclonedds; run by the interop profile"]
fn ignore_participant_drops_a_cyclone_writer() {
    let p = participant(65);
    let (child, rx) = cyclone(65, "ApiIgnore", WRITER);
    let r = reader::<ShapeType>(
        &p,
        "ApiIgnore",
        &DataReaderQos::builder().reliability(reliable()).build(),
    );
    let mut seen = Vec::new();
    assert!(wait_line(
        &rx,
        "writing",
        Duration::from_secs(20),
        &mut seen
    ));
    assert!(
        wait_until(Duration::from_secs(20), || !r.take().unwrap().is_empty()),
        "no data from Cyclone"
    );
    let h = p.discovered_participant_handles();
    assert_eq!(h.len(), 1, "one Cyclone participant");
    p.ignore_participant(h[0]).unwrap();
    assert!(r.matched_publications().is_empty());
    std::thread::sleep(Duration::from_millis(200));
    r.take().unwrap();
    std::thread::sleep(Duration::from_secs(2));
    let late = r.take().unwrap();
    let still = p.discovered_participant_handles();
    drop(child);
    assert!(
        late.is_empty(),
        "{} samples after ignore_participant",
        late.len()
    );
    assert!(
        still.is_empty(),
        "the ignored participant came back through SPDP"
    );
}
