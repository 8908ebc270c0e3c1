//! Multicast user data and IPv6 against Cyclone DDS 11 (python `cyclonedds`), checked on the wire:
//! - our writer with two Cyclone readers (two processes, so two unicast locators behind one group) sends
//!   each sample once, to the group;
//! - Cyclone's writer with two of our readers (two participants announcing the group) sends to the group,
//!   and both of our readers get every sample;
//! - IPv6 (Cyclone's `<Transport>udp6</Transport>`) both ways, discovery on ff02::ffff:239.255.0.1.
//!
//! Ignored by default (needs python3 + cyclonedds, tshark's `dumpcap`, and the netns of
//! `scripts/isolated`); the `interop` nextest profile runs them:
//! `scripts/isolated cargo nextest run -p dds-runtime --profile interop --run-ignored all --test dcps_interop_multicast`.
mod dcps_util;

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use dcps_util::*;
use dds_runtime::config::{AddressFamily, Config, InterfaceSelection, MulticastData};

/// The Cyclone peer: `pub DOMAIN TOPIC COUNT MATCHES` waits for MATCHES readers, writes shapes x = 0..COUNT
/// (color CYAN) and waits for acknowledgements; `sub DOMAIN TOPIC COUNT` prints `ready` once matched, then
/// `x=N` per sample, and exits after COUNT. Reliable, volatile, keep-all.
const PEER: &str = r#"
import sys, time
from dataclasses import dataclass
from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import appendable, key
from cyclonedds.idl.types import int32
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

mode, domain, topic, count = sys.argv[1], int(sys.argv[2]), sys.argv[3], int(sys.argv[4])
qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepAll)
dp = DomainParticipant(domain)
tp = Topic(dp, topic, ShapeType)
deadline = time.time() + 30
if mode == "pub":
    want = int(sys.argv[5])
    w = DataWriter(dp, tp, qos=qos)
    while w.get_publication_matched_status().current_count < want:
        if time.time() > deadline:
            print("no match", flush=True); sys.exit(2)
        time.sleep(0.05)
    time.sleep(1.0)
    print("ready", flush=True)
    for i in range(count):
        w.write(ShapeType(color="CYAN", x=i, y=2 * i, shapesize=20))
        time.sleep(0.005)
    w.wait_for_acks(duration(seconds=10))
    time.sleep(0.5)
    print("done", flush=True)
else:
    r = DataReader(dp, tp, qos=qos)
    while r.get_subscription_matched_status().current_count == 0:
        if time.time() > deadline:
            print("no match", flush=True); sys.exit(2)
        time.sleep(0.05)
    print("ready", flush=True)
    got = 0
    while got < count and time.time() < deadline:
        for s in r.take(N=100):
            if s.sample_info.valid_data:
                print(f"x={s.x}", flush=True)
                got += 1
        time.sleep(0.01)
    sys.exit(0 if got >= count else 3)
"#;

const COUNT: i32 = 40;

fn cyclone_uri(iface: &str, udp6: bool) -> String {
    let transport = if udp6 {
        "<Transport>udp6</Transport>"
    } else {
        ""
    };
    format!(
        r#"<CycloneDDS><Domain id="any"><General>{transport}<Interfaces><NetworkInterface name="{iface}" multicast="true"/></Interfaces><AllowMulticast>true</AllowMulticast></General></Domain></CycloneDDS>"#
    )
}

/// A Cyclone peer process whose stdout lines arrive on a channel.
struct Peer {
    child: Child,
    lines: mpsc::Receiver<String>,
    seen: Vec<String>,
}

impl Peer {
    fn spawn(uri: &str, args: &[String]) -> Peer {
        let mut child = Command::new("python3")
            .arg("-c")
            .arg(PEER)
            .args(args)
            .env("CYCLONEDDS_URI", uri)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("python3 with cyclonedds");
        let out = BufReader::new(child.stdout.take().unwrap());
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for l in out.lines().map_while(Result::ok) {
                let _ = tx.send(l);
            }
        });
        Peer {
            child,
            lines,
            seen: Vec::new(),
        }
    }

    fn wait_line(&mut self, timeout: Duration, want: impl Fn(&str) -> bool) -> bool {
        let end = std::time::Instant::now() + timeout;
        while let Some(left) = end.checked_duration_since(std::time::Instant::now()) {
            match self.lines.recv_timeout(left) {
                Ok(l) => {
                    let hit = want(&l);
                    self.seen.push(l);
                    if hit {
                        return true;
                    }
                }
                Err(_) => return false,
            }
        }
        false
    }

    /// Waits for the exit; the lines it printed, and whether it succeeded.
    fn finish(mut self) -> (bool, Vec<String>) {
        let ok = self.child.wait().map(|s| s.success()).unwrap_or(false);
        while let Ok(l) = self.lines.recv_timeout(Duration::from_millis(200)) {
            self.seen.push(l);
        }
        (ok, std::mem::take(&mut self.seen))
    }
}

impl Drop for Peer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `dumpcap` writing UDP on `iface` to a file.
struct Capture {
    child: Child,
    path: PathBuf,
}

impl Capture {
    fn start(iface: &str, name: &str) -> Capture {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
        let path = dir.join(format!("{name}-{}.pcapng", std::process::id()));
        let _ = std::fs::remove_file(&path);
        let mut child = Command::new("dumpcap")
            .args(["-q", "-i", iface, "-f", "udp", "-w"])
            .arg(&path)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("dumpcap (tshark)");
        // dumpcap says "Capturing on" once the capture runs.
        let err = BufReader::new(child.stderr.take().unwrap());
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for l in err.lines().map_while(Result::ok) {
                if l.contains("Capturing on") {
                    let _ = tx.send(());
                }
            }
        });
        let started = rx.recv_timeout(Duration::from_secs(10)).is_ok();
        if !started {
            std::thread::sleep(Duration::from_secs(1));
        }
        Capture { child, path }
    }

    /// Stops the capture; one line per frame carrying a DATA of a user writer (kind 0x02, keyed):
    /// `vendor|destination address|destination port|sequence numbers`.
    fn stop(mut self) -> Vec<String> {
        std::thread::sleep(Duration::from_millis(300));
        let _ = Command::new("kill")
            .args(["-INT", &self.child.id().to_string()])
            .status();
        let _ = self.child.wait();
        let out = Command::new("tshark")
            .arg("-r")
            .arg(&self.path)
            .args([
                "-Y",
                "rtps.sm.id == 0x15 && rtps.sm.wrEntityId.entityKind == 0x02",
                "-T",
                "fields",
                "-E",
                "separator=|",
                "-e",
                "rtps.vendorId",
                "-e",
                "ip.dst",
                "-e",
                "ipv6.dst",
                "-e",
                "udp.dstport",
                "-e",
                "rtps.sm.seqNumber",
            ])
            .output()
            .expect("tshark -r");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(|l| l.replace("||", "|"))
            .collect()
    }
}

impl Drop for Capture {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn v4_multicast_data() -> Config {
    Config {
        interface: InterfaceSelection::Name("lo".into()),
        multicast_data: MulticastData::On,
        ..Config::default()
    }
}

/// The user multicast port of `domain` (PB 7400 + DG 250 · domain + d2 1).
fn user_multicast_port(domain: u32) -> String {
    (7400 + 250 * domain + 1).to_string()
}

fn args(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

#[test]
#[ignore = "needs python3 with cyclonedds and dumpcap; run in the interop profile"]
fn our_writer_sends_each_sample_once_to_two_cyclone_readers() {
    let domain = 71;
    let uri = cyclone_uri("lo", false);
    let cap = Capture::start("lo", "mcast-ours-to-cyclone");
    let p = participant_with(domain, v4_multicast_data());
    let (wq, _) = reliable_keep_all();
    let w = writer::<ShapeType>(&p, "McastOut", &wq);
    let d = domain.to_string();
    let mut subs: Vec<Peer> = (0..2)
        .map(|_| Peer::spawn(&uri, &args(&["sub", &d, "McastOut", &COUNT.to_string()])))
        .collect();
    assert!(
        wait_until(Duration::from_secs(30), || w
            .publication_matched_status()
            .current_count
            == 2),
        "our writer did not match both Cyclone readers"
    );
    for s in &mut subs {
        assert!(
            s.wait_line(Duration::from_secs(30), |l| l == "ready"),
            "{:?}",
            s.seen
        );
    }
    std::thread::sleep(Duration::from_millis(500));
    for i in 0..COUNT {
        w.write(&shape("ORANGE", i)).unwrap();
    }
    // Acknowledgements from the Cyclone readers have taken 8–10 s on a loaded machine (see docs/network.md).
    let t0 = std::time::Instant::now();
    w.wait_for_acknowledgments(Duration::from_secs(30)).unwrap();
    eprintln!("acknowledged after {:?}", t0.elapsed());
    for s in subs {
        let (ok, lines) = s.finish();
        let xs: Vec<String> = lines
            .iter()
            .filter(|l| l.starts_with("x="))
            .cloned()
            .collect();
        assert!(ok, "Cyclone reader did not get every sample: {lines:?}");
        assert_eq!(xs, (0..COUNT).map(|i| format!("x={i}")).collect::<Vec<_>>());
    }
    let frames = cap.stop();
    let ours: Vec<&String> = frames.iter().filter(|f| f.starts_with("0x01dd|")).collect();
    let group = format!("0x01dd|239.255.0.1|{}|", user_multicast_port(domain));
    let to_group: Vec<&&String> = ours.iter().filter(|f| f.starts_with(&group)).collect();
    let unicast: Vec<&&String> = ours.iter().filter(|f| !f.starts_with(&group)).collect();
    eprintln!(
        "our DATA frames: {} to the group, {} unicast (repairs)",
        to_group.len(),
        unicast.len()
    );
    assert_eq!(to_group.len(), COUNT as usize, "{ours:?}");
    assert!(
        unicast.len() < COUNT as usize / 4,
        "samples went unicast to the readers: {unicast:?}"
    );
}

#[test]
#[ignore = "needs python3 with cyclonedds and dumpcap; run in the interop profile"]
fn cyclone_writer_sends_to_the_group_our_readers_announce() {
    let domain = 72;
    let uri = cyclone_uri("lo", false);
    let cap = Capture::start("lo", "mcast-cyclone-to-ours");
    let ps: Vec<_> = (0..2)
        .map(|_| participant_with(domain, v4_multicast_data()))
        .collect();
    let (_, rq) = reliable_keep_all();
    let readers: Vec<_> = ps
        .iter()
        .map(|p| reader::<ShapeType>(p, "McastIn", &rq))
        .collect();
    let d = domain.to_string();
    let mut publ = Peer::spawn(
        &uri,
        &args(&["pub", &d, "McastIn", &COUNT.to_string(), "2"]),
    );
    assert!(
        publ.wait_line(Duration::from_secs(30), |l| l == "ready"),
        "{:?}",
        publ.seen
    );
    for r in &readers {
        assert_eq!(
            take_xs(r, COUNT as usize, Duration::from_secs(20)),
            (0..COUNT).collect::<Vec<_>>()
        );
    }
    let (ok, lines) = publ.finish();
    assert!(ok, "{lines:?}");
    let frames = cap.stop();
    let cyclone: Vec<&String> = frames.iter().filter(|f| f.starts_with("0x0110|")).collect();
    let group = format!("0x0110|239.255.0.1|{}|", user_multicast_port(domain));
    let to_group = cyclone.iter().filter(|f| f.starts_with(&group)).count();
    eprintln!(
        "Cyclone DATA frames: {} to the group of {}",
        to_group,
        cyclone.len()
    );
    assert!(
        to_group >= COUNT as usize,
        "Cyclone did not send every sample to the group our readers announce: {cyclone:?}"
    );
}

/// A veth pair in the test's namespace with fd00::1 on `v0`: IPv6 multicast does not loop back over `lo`.
fn ipv6_link() -> &'static str {
    let sh = |c: &str| {
        Command::new("sh")
            .arg("-c")
            .arg(c)
            .status()
            .map(|s| s.success())
            .unwrap_or(false)
    };
    if !sh("ip link show v0 >/dev/null 2>&1") {
        assert!(
            sh(
                "ip link add v0 type veth peer name v1 && ip link set v1 up && ip link set v0 up \
                && ip -6 addr add fd00::1/64 dev v0 nodad"
            ),
            "cannot make a veth pair (needs the netns of scripts/isolated)"
        );
        std::thread::sleep(Duration::from_secs(2));
    }
    "v0"
}

fn v6_config(iface: &str) -> Config {
    Config {
        transport: AddressFamily::Ipv6,
        interface: InterfaceSelection::Name(iface.into()),
        ..Config::default()
    }
}

#[test]
#[ignore = "needs python3 with cyclonedds and dumpcap; run in the interop profile"]
fn ipv6_both_ways_with_cyclone() {
    let domain = 73;
    let iface = ipv6_link();
    let uri = cyclone_uri(iface, true);
    // Traffic between local addresses of v0 goes over `lo`; multicast over v0: capture both.
    let cap = Capture::start("any", "ipv6-cyclone");
    let p = participant_with(domain, v6_config(iface));
    let (wq, rq) = reliable_keep_all();
    let w = writer::<ShapeType>(&p, "V6Out", &wq);
    let r = reader::<ShapeType>(&p, "V6In", &rq);
    let d = domain.to_string();
    let mut sub = Peer::spawn(&uri, &args(&["sub", &d, "V6Out", &COUNT.to_string()]));
    let mut publ = Peer::spawn(&uri, &args(&["pub", &d, "V6In", &COUNT.to_string(), "1"]));
    assert!(
        wait_until(Duration::from_secs(30), || w
            .publication_matched_status()
            .current_count
            == 1),
        "our IPv6 writer did not match Cyclone's reader"
    );
    assert!(
        sub.wait_line(Duration::from_secs(30), |l| l == "ready"),
        "{:?}",
        sub.seen
    );
    for i in 0..COUNT {
        w.write(&shape("ORANGE", i)).unwrap();
    }
    // Acknowledgements from the Cyclone readers have taken 8–10 s on a loaded machine (see docs/network.md).
    w.wait_for_acknowledgments(Duration::from_secs(30)).unwrap();
    assert!(
        publ.wait_line(Duration::from_secs(30), |l| l == "ready"),
        "{:?}",
        publ.seen
    );
    assert_eq!(
        take_xs(&r, COUNT as usize, Duration::from_secs(20)),
        (0..COUNT).collect::<Vec<_>>()
    );
    let (ok, lines) = sub.finish();
    assert!(ok, "Cyclone's IPv6 reader: {lines:?}");
    let (ok, lines) = publ.finish();
    assert!(ok, "Cyclone's IPv6 writer: {lines:?}");
    let frames = cap.stop();
    // Every user DATA went over IPv6 (no IPv4 destination), from both vendors.
    assert!(
        frames.iter().any(|f| f.starts_with("0x01dd|")),
        "{frames:?}"
    );
    assert!(
        frames.iter().any(|f| f.starts_with("0x0110|")),
        "{frames:?}"
    );
    assert!(
        frames
            .iter()
            .all(|f| f.split('|').nth(1).is_some_and(|a| a.contains(':'))),
        "{frames:?}"
    );
}
