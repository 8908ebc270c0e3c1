//! PRESENTATION against Cyclone DDS 11 (python `cyclonedds`) and ours against ours, with shape_main's
//! command line.
//!
//! Cyclone 11.0.1 refuses `begin_coherent` (`dds_begin_coherent` returns UNSUPPORTED), so it cannot write
//! coherent sets; what it can do is announce and match the PRESENTATION QoS and read what our coherent
//! writers send. These tests check that, and the all-or-nothing delivery of sets ours against ours.

use std::process::Command;
use std::time::Duration;

use super::harness::{cyclone_peer, require_netns, root, Proc, Skip};
use super::shapes::Prog;
use super::tshark::start_capture;
use crate::check;

const WAIT: Duration = Duration::from_secs(20);

fn is_sample(l: &str) -> bool {
    l.starts_with("Square ") && l.ends_with(']') && !l.contains("NOT_ALIVE")
}

/// The `[size]` of a sample line.
fn size(l: &str) -> Option<u32> {
    l.rsplit_once('[')?.1.trim_end_matches(']').parse().ok()
}

/// Our coherent writer (topic scope, sets of 3) to a plain Cyclone reader: Cyclone reads every sample, in
/// order, and nothing else (the end-of-set markers are not samples to it).
#[test]
fn coherent_writer_ours_to_cyclone_reader() -> Result<(), Skip> {
    require_netns()?;
    let mut s = Prog::Cyclone.spawn("sub", "-S -t Square -d 183 -r -k 0")?;
    let mut p = Prog::Ours.spawn(
        "pub",
        "-P -t Square -d 183 -r -k 0 -c RED --coherent --access-scope t --coherent-sample-count 3 \
         --write-period 50 -z 0",
    )?;
    let got = s.wait_lines(WAIT, 30, is_sample);
    check!(got.is_some(), &[&p, &s], "Cyclone read 30 samples");
    let _ = p.interrupt(Duration::from_secs(10));
    let _ = s.interrupt(Duration::from_secs(10));
    let sizes: Vec<u32> = s.grep(is_sample).iter().filter_map(|l| size(l)).collect();
    check!(
        sizes.windows(2).all(|w| w[1] == w[0] + 1),
        &[&p, &s],
        "consecutive sizes (nothing lost, nothing extra): {sizes:?}"
    );
    check!(
        s.grep(|l| l.contains("NOT_ALIVE")).is_empty() || sizes.len() >= 30,
        &[&p, &s],
        "no spurious instance states"
    );
    Ok(())
}

/// A Cyclone publisher with the given PRESENTATION writing RED samples of increasing size.
fn cyclone_presentation_writer(domain: u32, scope: &str, coherent: bool) -> Result<Proc, Skip> {
    let peers = root().join("tests/peers");
    cyclone_peer()?;
    let script = format!(
        r#"
import sys, time
sys.path.insert(0, {peers:?})
from cyclone_shape import ShapeType
from cyclonedds.core import Qos, Policy, Listener
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import Publisher, DataWriter
from cyclonedds.topic import Topic
from cyclonedds.util import duration
scope = Policy.PresentationAccessScope.{scope}(coherent_access={coherent}, ordered_access=True)
dp = DomainParticipant({domain})
pub = Publisher(dp, qos=Qos(scope))
def incompat(_w, st):
    print("on_offered_incompatible_qos() policy %d" % st.last_policy_id, flush=True)
w = DataWriter(pub, Topic(dp, "Square", ShapeType),
               qos=Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepAll),
               listener=Listener(on_offered_incompatible_qos=incompat))
for i in range(400):
    w.write(ShapeType(color="RED", x=i, y=i, shapesize=i + 1))
    time.sleep(0.05)
"#,
        peers = peers.display().to_string(),
        coherent = if coherent { "True" } else { "False" },
    );
    let mut c = Command::new("python3");
    c.arg("-u").arg("-c").arg(script);
    Ok(Proc::spawn(&format!("cyclone {scope} writer"), c))
}

/// Cyclone announces PRESENTATION (`scope`, coherent, ordered) and our coherent, ordered reader with the
/// same scope (`flag`) matches it and reads its samples (Cyclone sends them outside any set) in order.
fn presentation_cyclone_writer_to_ours(domain: u32, scope: &str, flag: char) -> Result<(), Skip> {
    require_netns()?;
    let mut s = Prog::Ours.spawn(
        "sub",
        &format!(
            "-S -t Square -d {domain} -r -k 0 -x 2 --coherent --ordered --access-scope {flag}"
        ),
    )?;
    let mut p = cyclone_presentation_writer(domain, scope, true)?;
    let got = s.wait_lines(WAIT, 10, is_sample);
    check!(
        got.is_some(),
        &[&p, &s],
        "our coherent reader read Cyclone's samples"
    );
    let sizes: Vec<u32> = s.grep(is_sample).iter().filter_map(|l| size(l)).collect();
    check!(
        sizes.windows(2).all(|w| w[1] == w[0] + 1),
        &[&p, &s],
        "in order: {sizes:?}"
    );
    check!(
        s.wait_line(Duration::from_secs(2), |l| l
            .starts_with("Reading coherent sets"))
            .is_some(),
        &[&p, &s],
        "coherent read loop"
    );
    let _ = s.interrupt(Duration::from_secs(10));
    let _ = p.interrupt(Duration::from_secs(5));
    Ok(())
}

#[test]
fn presentation_cyclone_writer_to_ours_topic_scope() -> Result<(), Skip> {
    presentation_cyclone_writer_to_ours(184, "Topic", 't')
}

#[test]
fn presentation_cyclone_writer_to_ours_group_scope() -> Result<(), Skip> {
    presentation_cyclone_writer_to_ours(189, "Group", 'g')
}

/// Offered INSTANCE scope against requested TOPIC scope: both sides report PRESENTATION (id 3) incompatible.
#[test]
fn presentation_scope_mismatch_cyclone_to_ours_is_incompatible() -> Result<(), Skip> {
    require_netns()?;
    let mut s = Prog::Ours.spawn(
        "sub",
        "-S -t Square -d 185 -r -k 0 -x 2 --coherent --access-scope t",
    )?;
    let mut p = cyclone_presentation_writer(185, "Instance", true)?;
    let ours = s.wait_line(WAIT, |l| {
        l.starts_with("on_requested_incompatible_qos()") && l.contains("PRESENTATION")
    });
    let theirs = p.wait_line(WAIT, |l| l == "on_offered_incompatible_qos() policy 3");
    check!(
        ours.is_some() && theirs.is_some(),
        &[&p, &s],
        "both report PRESENTATION incompatible"
    );
    check!(
        s.grep(is_sample).is_empty(),
        &[&p, &s],
        "no data across the mismatch"
    );
    let _ = s.interrupt(Duration::from_secs(10));
    let _ = p.interrupt(Duration::from_secs(5));
    Ok(())
}

/// The suite's coherent-set case (`Test_CoherentSets_*` with instances), ours against ours: 3 topics, 4
/// instances, sets of 3 iterations; every read loop that sees data sees whole sets (36 samples).
///
/// The publisher begins its first set before it has matched the reader, so the first two read loops with
/// data may hold a partial set: a VOLATILE reader matched to one topic's writer before another's sees only
/// the parts written after its match. Like the suite's own check, the first two loops with data are not
/// counted, and at least two whole sets must follow them.
fn coherent_sets_ours(domain: u32, scope: char) -> Result<(), Skip> {
    require_netns()?;
    let mut s = Prog::Ours.spawn(
        "sub",
        &format!(
            "-S -t Square -d {domain} -r -k 0 --coherent --access-scope {scope} --num-topics 3 \
             --take-read --read-period 100"
        ),
    )?;
    let mut p = Prog::Ours.spawn(
        "pub",
        &format!(
            "-P -t Square -d {domain} -r -k 0 --coherent --access-scope {scope} --num-topics 3 \
             --num-instances 4 --coherent-sample-count 3 --write-period 100 -z 0"
        ),
    )?;
    let enough = s.wait_lines(WAIT, 36 * 6, |l| {
        l.starts_with("Square") && l.ends_with(']')
    });
    let _ = p.interrupt(Duration::from_secs(10));
    let _ = s.interrupt(Duration::from_secs(10));
    check!(enough.is_some(), &[&p, &s], "six sets read");
    let mut per_loop = Vec::new();
    let mut n = 0;
    for l in s.lines() {
        if l.starts_with("Reading coherent sets") {
            if n > 0 {
                per_loop.push(n);
            }
            n = 0;
        } else if l.starts_with("Square") && l.ends_with(']') {
            n += 1;
        }
    }
    let settled = per_loop.get(2..).unwrap_or_default();
    check!(
        settled.len() >= 2 && settled.iter().all(|n| n % 36 == 0),
        &[&p, &s],
        "whole sets only after the first two loops: {per_loop:?}"
    );
    Ok(())
}

#[test]
fn coherent_sets_topic_scope_ours_to_ours() -> Result<(), Skip> {
    coherent_sets_ours(186, 't')
}

#[test]
fn coherent_sets_group_scope_ours_to_ours() -> Result<(), Skip> {
    coherent_sets_ours(187, 'g')
}

#[test]
fn coherent_sets_instance_scope_ours_to_ours() -> Result<(), Skip> {
    coherent_sets_ours(188, 'i')
}

/// A Cyclone GROUP-scope coherent subscriber reading `Square` and `Square1`, printing `TOPIC SIZE` per
/// sample.
fn cyclone_group_reader(domain: u32) -> Result<Proc, Skip> {
    let peers = root().join("tests/peers");
    cyclone_peer()?;
    let script = format!(
        r#"
import sys, time
sys.path.insert(0, {peers:?})
from cyclone_shape import ShapeType
from cyclonedds.core import Qos, Policy
from cyclonedds.domain import DomainParticipant
from cyclonedds.sub import Subscriber, DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration
dp = DomainParticipant({domain})
sub = Subscriber(dp, qos=Qos(Policy.PresentationAccessScope.Group(coherent_access=True, ordered_access=False)))
rq = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepAll)
readers = [(n, DataReader(sub, Topic(dp, n, ShapeType), qos=rq)) for n in ("Square", "Square1")]
print("reading", flush=True)
while True:
    for n, r in readers:
        for s in r.take(N=100):
            if isinstance(s, ShapeType):
                print("%s %d" % (n, s.shapesize), flush=True)
    time.sleep(0.02)
"#,
        peers = peers.display().to_string(),
    );
    let mut c = Command::new("python3");
    c.arg("-u").arg("-c").arg(script);
    Ok(Proc::spawn("cyclone GROUP reader", c))
}

/// Our GROUP-scope coherent publisher (two topics, sets of 3 iterations) to a Cyclone GROUP-scope
/// reader: Cyclone reads every sample of both topics in order and nothing else (end-of-set markers and
/// the group parameters are not samples to it), and the wire carries `PID_COHERENT_SET`,
/// `PID_GROUP_SEQ_NUM`, `PID_GROUP_COHERENT_SET` and `PID_WRITER_GROUP_INFO` (checked with tshark).
#[test]
fn group_coherent_sets_ours_to_cyclone_reader_on_the_wire() -> Result<(), Skip> {
    require_netns()?;
    let (mut t, cap_s) = start_capture("group")?;
    let mut s = cyclone_group_reader(190)?;
    let mut p = Prog::Ours.spawn(
        "pub",
        "-P -t Square -d 190 -r -k 0 -c RED --coherent --access-scope g --num-topics 2 \
         --coherent-sample-count 3 --write-period 50 -z 0",
    )?;
    let both = |l: &str| l.starts_with("Square1 ");
    let got = s.wait_lines(WAIT, 30, both);
    let _ = p.interrupt(Duration::from_secs(10));
    std::thread::sleep(Duration::from_millis(300));
    let _ = s.interrupt(Duration::from_secs(5));
    let _ = t.interrupt(Duration::from_secs(10));
    check!(
        got.is_some(),
        &[&p, &s],
        "Cyclone read 30 samples of Square1"
    );
    for topic in ["Square", "Square1"] {
        let sizes: Vec<u32> = s
            .grep(|l| l.split(' ').next() == Some(topic))
            .iter()
            .filter_map(|l| l.split(' ').nth(1)?.parse().ok())
            .collect();
        check!(
            sizes.len() >= 30 && sizes.windows(2).all(|w| w[1] == w[0] + 1),
            &[&p, &s],
            "{topic}: every sample, in order, nothing else: {sizes:?}"
        );
    }
    let out = Command::new("tshark")
        .args([
            "-r",
            &cap_s,
            "-Y",
            "rtps.vendorId == 0x01dd && rtps.sm.id == 0x15",
        ])
        .args(["-T", "fields", "-e", "rtps.param.id"])
        .output()
        .expect("tshark -r");
    let ids = String::from_utf8_lossy(&out.stdout).to_string();
    for (id, name) in [
        ("0x0056", "PID_COHERENT_SET"),
        ("0x0064", "PID_GROUP_SEQ_NUM"),
        ("0x0063", "PID_GROUP_COHERENT_SET"),
        ("0x0065", "PID_WRITER_GROUP_INFO"),
    ] {
        check!(
            ids.contains(id),
            &[&t],
            "{name} ({id}) on our DATA: {}",
            &ids[..ids.len().min(2000)]
        );
    }
    // Our heartbeats carry GroupInfo (flag G, 0x08), and Cyclone, which does not know it, still
    // acknowledges: its ACKNACKs to our writers move past the first change.
    let fields = |filter: &str, field: &str| {
        let out = Command::new("tshark")
            .args(["-r", &cap_s, "-Y", filter, "-T", "fields", "-e", field])
            .output()
            .expect("tshark -r");
        String::from_utf8_lossy(&out.stdout).to_string()
    };
    let hb_flags = fields(
        "rtps.vendorId == 0x01dd && rtps.sm.id == 0x07 && (rtps.sm.wrEntityId.entityKind == 2 || rtps.sm.wrEntityId.entityKind == 3)",
        "rtps.sm.flags",
    );
    let g_flag = hb_flags
        .split([',', '\n'])
        .filter_map(|f| u8::from_str_radix(f.trim().trim_start_matches("0x"), 16).ok())
        .any(|f| f & 0x08 != 0);
    check!(
        g_flag,
        &[&t],
        "a HEARTBEAT with flag G from our writers: {}",
        &hb_flags[..hb_flags.len().min(500)]
    );
    let acks = fields(
        "rtps.vendorId == 0x0110 && rtps.sm.id == 0x06 && (rtps.sm.wrEntityId.entityKind == 2 || rtps.sm.wrEntityId.entityKind == 3)",
        "rtps.sm.seqNumber",
    );
    let acked = acks
        .split([',', '\n'])
        .filter_map(|n| n.trim().parse::<i64>().ok())
        .max()
        .unwrap_or(0);
    check!(
        acked > 10,
        &[&t],
        "Cyclone acknowledges our group writers (highest ACKNACK base {acked}): {}",
        &acks[..acks.len().min(500)]
    );
    let _ = std::fs::remove_file(&cap_s);
    Ok(())
}

/// Why no test here has Cyclone write coherent sets: Cyclone DDS 11.0.1 refuses `begin_coherent` on a
/// GROUP-scope coherent publisher with DDS_RETCODE_UNSUPPORTED. When a later Cyclone accepts it, this
/// fails, and Cyclone-written sets (TOPIC and GROUP scope) can be tested against our readers.
#[test]
fn cyclone_11_refuses_begin_coherent() -> Result<(), Skip> {
    require_netns()?;
    cyclone_peer()?;
    let script = r#"
from cyclonedds.core import Qos, Policy, DDSException
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import Publisher
dp = DomainParticipant(191)
for scope in (Policy.PresentationAccessScope.Topic, Policy.PresentationAccessScope.Group):
    pub = Publisher(dp, qos=Qos(scope(coherent_access=True, ordered_access=True)))
    try:
        pub.begin_coherent()
        print("accepted", flush=True)
    except DDSException as e:
        print("refused %s" % e.code, flush=True)
"#;
    let mut c = Command::new("python3");
    c.arg("-u").arg("-c").arg(script);
    let mut p = Proc::spawn("cyclone begin_coherent", c);
    let _ = p.wait_exit(Duration::from_secs(20));
    // DDS_RETCODE_UNSUPPORTED is -2 in Cyclone's C API.
    let refused = p.grep(|l| l == "refused -2");
    check!(
        refused.len() == 2,
        &[&p],
        "Cyclone 11 refuses begin_coherent (TOPIC and GROUP scope): {:?}",
        p.lines()
    );
    Ok(())
}
