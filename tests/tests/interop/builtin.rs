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

fn run(domain: u32) -> Result<(), Skip> {
    require_netns()?;
    cyclone_peer()?;
    let p = DomainParticipant::builder()
        .domain_id(domain)
        .build()
        .expect("participant");
    let b = p.get_builtin_subscriber().expect("builtin subscriber");
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
