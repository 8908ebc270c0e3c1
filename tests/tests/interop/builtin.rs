//! Our built-in subscriber against Cyclone DDS 11 (python `cyclonedds`): DCPSParticipant, DCPSPublication,
//! DCPSSubscription and DCPSTopic show a Cyclone participant, its writer and its reader as they appear, and
//! dispose them as they leave (`dds_delete` through ctypes on libddsc).

use std::process::Command;
use std::time::{Duration, Instant};

use dds_runtime::prelude::*;
use dds_runtime::rtps::VendorId;

use super::harness::{cyclone_peer, require_netns, Proc, Skip};
use crate::check;

const WAIT: Duration = Duration::from_secs(20);

/// The Cyclone side: a participant, then a writer and a reader of `BuiltinPeer` ("endpoints"), then the
/// writer deleted ("writer deleted"), then the participant deleted ("gone").
const PEER: &str = r#"
import sys, time
from dataclasses import dataclass
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import int32
from cyclonedds.internal import load_cyclonedds
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic

@dataclass
class Peer(IdlStruct, typename="BuiltinPeerType"):
    x: int32

lib = load_cyclonedds()
dp = DomainParticipant(int(sys.argv[1]))
print("participant", flush=True)
time.sleep(1)
tp = Topic(dp, "BuiltinPeer", Peer)
w = DataWriter(dp, tp)
r = DataReader(dp, tp)
print("endpoints", flush=True)
time.sleep(4)
lib.dds_delete(w._ref)
print("writer deleted", flush=True)
time.sleep(3)
lib.dds_delete(dp._ref)
print("gone", flush=True)
time.sleep(2)
"#;

fn wait_until(timeout: Duration, mut f: impl FnMut() -> bool) -> bool {
    let end = Instant::now() + timeout;
    while Instant::now() < end {
        if f() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    f()
}

fn state_of<T>(samples: &[Sample<T>], h: InstanceHandle) -> Option<InstanceState> {
    samples
        .iter()
        .rev()
        .find(|s| s.info.instance_handle == h)
        .map(|s| s.info.instance_state)
}

#[test]
fn builtin_readers_see_cyclone_entities_come_and_go() {
    let _ = run(216);
}

/// A participant in `domain` (with a Cyclone peer available) and its built-in subscriber.
fn builtin_subscriber(domain: u32) -> Result<(DomainParticipant, BuiltinSubscriber), Skip> {
    require_netns()?;
    cyclone_peer()?;
    let p = DomainParticipant::builder()
        .domain_id(domain)
        .build()
        .expect("participant");
    let b = p.get_builtin_subscriber().expect("builtin subscriber");
    Ok((p, b))
}

fn run(domain: u32) -> Result<(), Skip> {
    let (_p, b) = builtin_subscriber(domain)?;
    let (parts, pubs, subs, topics) = (
        b.participant_reader(),
        b.publication_reader(),
        b.subscription_reader(),
        b.topic_reader(),
    );
    let mut c = Command::new("python3");
    c.args(["-u", "-c", PEER, &domain.to_string()]);
    let peer = Proc::spawn("cyclone builtin peer", c);
    check!(
        peer.wait_line(WAIT, |l| l == "endpoints").is_some(),
        &[&peer],
        "peer did not start"
    );
    // Its writer and reader, announced in SEDP.
    let mut writer = None;
    check!(
        wait_until(WAIT, || {
            writer = pubs
                .read()
                .unwrap()
                .into_iter()
                .find_map(|s| s.data.filter(|d| d.topic_name == "BuiltinPeer"));
            writer.is_some()
        }),
        &[&peer],
        "no DCPSPublication for the Cyclone writer"
    );
    let writer = writer.unwrap();
    assert_eq!(writer.type_name, "BuiltinPeerType");
    let cyclone = writer.participant_key.expect("participant key").prefix;
    let mut reader = None;
    check!(
        wait_until(WAIT, || {
            reader = subs.read().unwrap().into_iter().find_map(|s| {
                s.data
                    .filter(|d| d.topic_name == "BuiltinPeer" && d.key.prefix == cyclone)
            });
            reader.is_some()
        }),
        &[&peer],
        "no DCPSSubscription for the Cyclone reader"
    );
    let reader = reader.unwrap();
    // The participant, as Cyclone announced it.
    let ph =
        InstanceHandle::from_guid(Guid::new(cyclone, dds_runtime::rtps::EntityId::PARTICIPANT));
    let data = parts.read_instance(ph).expect("DCPSParticipant instance");
    let pd = data
        .last()
        .and_then(|s| s.data.clone())
        .expect("participant data");
    assert_eq!(pd.vendor_id, VendorId::CYCLONE);
    assert!(
        pd.property("__Pid").is_some(),
        "properties: {:?}",
        pd.properties
    );
    assert!(topics
        .read()
        .unwrap()
        .iter()
        .filter_map(|s| s.data.as_ref())
        .any(|t| t.name == "BuiltinPeer" && t.type_name == "BuiltinPeerType"));
    // The writer is deleted: disposed in DCPSPublication, the reader still alive.
    check!(
        peer.wait_line(WAIT, |l| l == "writer deleted").is_some(),
        &[&peer],
        "peer stopped"
    );
    let wh = InstanceHandle::from_guid(writer.key);
    let rh = InstanceHandle::from_guid(reader.key);
    check!(
        wait_until(Duration::from_secs(5), || {
            state_of(&pubs.read().unwrap(), wh) == Some(InstanceState::NotAliveDisposed)
        }),
        &[&peer],
        "writer not disposed"
    );
    assert_eq!(
        state_of(&subs.read().unwrap(), rh),
        Some(InstanceState::Alive)
    );
    // The participant is deleted: it and its reader are disposed.
    check!(
        peer.wait_line(WAIT, |l| l == "gone").is_some(),
        &[&peer],
        "peer stopped"
    );
    check!(
        wait_until(Duration::from_secs(5), || {
            state_of(&parts.read().unwrap(), ph) == Some(InstanceState::NotAliveDisposed)
                && state_of(&subs.read().unwrap(), rh) == Some(InstanceState::NotAliveDisposed)
        }),
        &[&peer],
        "participant or reader not disposed: {:?} {:?}",
        state_of(&parts.read().unwrap(), ph),
        state_of(&subs.read().unwrap(), rh)
    );
    Ok(())
}

/// The Cyclone side of the second test: a participant with a writer and a reader of `BuiltinPeer2`; the
/// process exits once the file `argv[2]` exists (the binding deletes the participant on exit).
const PEER_EXITS: &str = r#"
import sys, time
from dataclasses import dataclass
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import int32
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic

@dataclass
class Peer(IdlStruct, typename="BuiltinPeerType"):
    x: int32

dp = DomainParticipant(int(sys.argv[1]))
tp = Topic(dp, "BuiltinPeer2", Peer)
w = DataWriter(dp, tp)
r = DataReader(dp, tp)
print("endpoints", flush=True)
import os
for _ in range(600):
    if os.path.exists(sys.argv[2]):
        break
    time.sleep(0.05)
print("exiting", flush=True)
"#;

struct DataOnReaders(std::sync::Arc<std::sync::atomic::AtomicU32>);

impl SubscriberListener for DataOnReaders {
    fn on_data_on_readers(&self, _s: &Subscriber) {
        self.0.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    }
}

/// The built-in readers are `DataReader`s: a WaitSet on their read conditions wakes on a Cyclone
/// participant and its endpoints, the built-in subscriber's listener gets `on_data_on_readers`, and after
/// the Cyclone process exits its participant is read by instance state (NOT_ALIVE).
#[test]
fn builtin_datareaders_wait_for_cyclone_and_see_it_exit() {
    let _ = run_exit(225);
}

fn run_exit(domain: u32) -> Result<(), Skip> {
    let (_p, b) = builtin_subscriber(domain)?;
    let parts = b
        .lookup_datareader::<ParticipantBuiltinTopicData>("DCPSParticipant")
        .unwrap()
        .expect("DCPSParticipant reader");
    let pubs = b
        .lookup_datareader::<PublicationBuiltinTopicData>("DCPSPublication")
        .unwrap()
        .expect("DCPSPublication reader");
    let subs = b
        .lookup_datareader::<SubscriptionBuiltinTopicData>("DCPSSubscription")
        .unwrap()
        .expect("DCPSSubscription reader");
    let _ = parts.take().unwrap(); // our own participant
    let calls = std::sync::Arc::new(std::sync::atomic::AtomicU32::new(0));
    b.set_listener(
        Box::new(DataOnReaders(calls.clone())),
        StatusMask::DATA_ON_READERS,
    )
    .unwrap();
    let new = (
        SampleStateMask::NOT_READ,
        ViewStateMask::ANY,
        InstanceStateMask::ALIVE,
    );
    let ws = WaitSet::new();
    let (pc, wc, rc) = (
        parts.create_readcondition(new.0, new.1, new.2),
        pubs.create_readcondition(new.0, new.1, new.2),
        subs.create_readcondition(new.0, new.1, new.2),
    );
    for c in [&pc, &wc, &rc] {
        ws.attach_condition(c.clone());
    }
    let stop = std::env::temp_dir().join(format!("builtin-exit-{}", std::process::id()));
    let _ = std::fs::remove_file(&stop);
    let mut c = Command::new("python3");
    c.args(["-u", "-c", PEER_EXITS, &domain.to_string()]);
    c.arg(&stop);
    let mut peer = Proc::spawn("cyclone builtin peer", c);
    check!(
        peer.wait_line(WAIT, |l| l == "endpoints").is_some(),
        &[&peer],
        "peer did not start"
    );
    // Wake on each read condition in turn, reading what woke us.
    let (mut cyclone, mut writer, mut reader) = (None, None, None);
    let end = Instant::now() + WAIT;
    while (cyclone.is_none() || writer.is_none() || reader.is_none()) && Instant::now() < end {
        if ws.wait(Duration::from_secs(1)).is_err() {
            continue;
        }
        for s in parts.take_w_condition(&pc).unwrap() {
            cyclone = cyclone.or(s.data.map(|d| d.key));
        }
        for s in pubs.take_w_condition(&wc).unwrap() {
            writer = writer.or(s.data.filter(|d| d.topic_name == "BuiltinPeer2"));
        }
        for s in subs.take_w_condition(&rc).unwrap() {
            reader = reader.or(s.data.filter(|d| d.topic_name == "BuiltinPeer2"));
        }
    }
    check!(
        cyclone.is_some() && writer.is_some() && reader.is_some(),
        &[&peer],
        "not everything discovered: {cyclone:?} {writer:?} {reader:?}"
    );
    let cyclone = cyclone.unwrap();
    assert_eq!(writer.unwrap().key.prefix, cyclone);
    assert!(
        calls.load(std::sync::atomic::Ordering::SeqCst) >= 1,
        "on_data_on_readers"
    );
    // The process exits: its participant becomes NOT_ALIVE.
    std::fs::write(&stop, b"").expect("stop file");
    check!(
        peer.wait_exit(WAIT).is_some(),
        &[&peer],
        "the peer did not exit"
    );
    let _ = std::fs::remove_file(&stop);
    let ph =
        InstanceHandle::from_guid(Guid::new(cyclone, dds_runtime::rtps::EntityId::PARTICIPANT));
    check!(
        wait_until(WAIT, || {
            parts
                .select()
                .instance_state(InstanceStateMask::NOT_ALIVE)
                .read()
                .unwrap()
                .iter()
                .any(|s| s.info.instance_handle == ph)
        }),
        &[&peer],
        "the Cyclone participant did not become NOT_ALIVE"
    );
    assert_eq!(
        parts
            .read_instance(ph)
            .unwrap()
            .last()
            .unwrap()
            .info
            .instance_state,
        InstanceState::NotAliveDisposed
    );
    Ok(())
}
