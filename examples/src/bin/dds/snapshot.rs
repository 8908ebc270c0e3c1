//! What the observer knows at one moment, in plain data: participants, topics and endpoints, sorted.

use std::collections::BTreeMap;

use dds_runtime::prelude::*;
use dds_runtime::rtps::discovery::{EndpointData, ParticipantData};
use dds_runtime::rtps::{Guid, GuidPrefix, Participant, VendorId};
use serde_json::{json, Value};

/// A discovered participant.
#[derive(Debug, Clone)]
pub(crate) struct ParticipantInfo {
    pub(crate) guid_prefix: String,
    pub(crate) vendor: String,
    pub(crate) name: Option<String>,
    pub(crate) host: Option<String>,
    pub(crate) pid: Option<String>,
    pub(crate) program: Option<String>,
    pub(crate) addresses: Option<String>,
}

/// Whether an endpoint writes or reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Direction {
    Writer,
    Reader,
}

impl Direction {
    pub(crate) fn as_str(self) -> &'static str {
        match self {
            Direction::Writer => "writer",
            Direction::Reader => "reader",
        }
    }
}

/// A discovered writer or reader with the QoS a person asks about first.
#[derive(Debug, Clone)]
pub(crate) struct EndpointInfo {
    pub(crate) direction: Direction,
    pub(crate) guid: String,
    pub(crate) participant: String,
    pub(crate) topic: String,
    pub(crate) type_name: String,
    pub(crate) reliability: &'static str,
    pub(crate) durability: &'static str,
    pub(crate) ownership: &'static str,
    pub(crate) partitions: Vec<String>,
    pub(crate) type_information: bool,
}

/// Everything discovered, sorted for stable output.
#[derive(Debug, Clone, Default)]
pub(crate) struct Snapshot {
    pub(crate) participants: Vec<ParticipantInfo>,
    pub(crate) endpoints: Vec<EndpointInfo>,
}

impl Snapshot {
    /// Reads the core's discovery state.
    pub(crate) fn of(core: &Participant) -> Self {
        let mut participants: Vec<_> = core.discovered_participants().map(participant).collect();
        participants.sort_by(|a, b| a.guid_prefix.cmp(&b.guid_prefix));
        let mut endpoints: Vec<_> = core
            .publications()
            .map(|w| {
                let q = &w.qos.writer;
                endpoint(
                    Direction::Writer,
                    w,
                    (&q.reliability, &q.durability, &q.ownership),
                    &w.qos.partition,
                )
            })
            .chain(core.subscriptions().map(|r| {
                let q = &r.qos.reader;
                endpoint(
                    Direction::Reader,
                    r,
                    (&q.reliability, &q.durability, &q.ownership),
                    &r.qos.partition,
                )
            }))
            .filter(|e| !e.participant.is_empty())
            .collect();
        endpoints.sort_by(|a, b| {
            (&a.topic, &a.participant, &a.guid).cmp(&(&b.topic, &b.participant, &b.guid))
        });
        Snapshot {
            participants,
            endpoints,
        }
    }

    /// Topic name → type names seen on it (more than one is an inconsistency worth showing).
    pub(crate) fn topics(&self) -> BTreeMap<&str, Vec<&str>> {
        let mut m: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
        for e in &self.endpoints {
            let types = m.entry(e.topic.as_str()).or_default();
            if !types.contains(&e.type_name.as_str()) {
                types.push(e.type_name.as_str());
            }
        }
        m
    }

    /// The machine form of `dds ls`.
    pub(crate) fn to_json(&self) -> Value {
        json!({
            "participants": self.participants.iter().map(ParticipantInfo::to_json).collect::<Vec<_>>(),
            "topics": self.topics().into_iter().map(|(t, types)| json!({"name": t, "types": types})).collect::<Vec<_>>(),
            "endpoints": self.endpoints.iter().map(EndpointInfo::to_json).collect::<Vec<_>>(),
        })
    }
}

impl ParticipantInfo {
    pub(crate) fn to_json(&self) -> Value {
        json!({
            "guid_prefix": self.guid_prefix,
            "vendor": self.vendor,
            "name": self.name,
            "host": self.host,
            "pid": self.pid,
            "program": self.program,
            "addresses": self.addresses,
        })
    }
}

impl EndpointInfo {
    pub(crate) fn to_json(&self) -> Value {
        json!({
            "kind": self.direction.as_str(),
            "guid": self.guid,
            "participant": self.participant,
            "topic": self.topic,
            "type": self.type_name,
            "reliability": self.reliability,
            "durability": self.durability,
            "ownership": self.ownership,
            "partitions": self.partitions,
            "type_information": self.type_information,
        })
    }
}

fn participant(p: &ParticipantData) -> ParticipantInfo {
    // The property names Cyclone DDS announces and its `cyclonedds ps` reads.
    let prop = |name: &str| {
        p.properties
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.clone())
    };
    ParticipantInfo {
        guid_prefix: prefix_hex(&p.guid_prefix),
        vendor: vendor_name(p.vendor_id),
        name: p.entity_name.clone(),
        host: prop("__Hostname"),
        pid: prop("__Pid"),
        program: prop("__ProcessName"),
        addresses: prop("__NetworkAddresses"),
    }
}

type MainQos<'a> = (&'a Reliability, &'a Durability, &'a Ownership);

fn endpoint<Q>(
    direction: Direction,
    d: &EndpointData<Q>,
    (reliability, durability, ownership): MainQos<'_>,
    partition: &Partition,
) -> EndpointInfo {
    EndpointInfo {
        direction,
        guid: guid_hex(&d.guid),
        participant: d
            .participant_guid
            .map(|g| prefix_hex(&g.prefix))
            .unwrap_or_else(|| prefix_hex(&d.guid.prefix)),
        topic: d.topic_name.clone(),
        type_name: d.type_name.clone(),
        reliability: match reliability {
            Reliability::BestEffort => "best-effort",
            Reliability::Reliable { .. } => "reliable",
        },
        durability: match durability {
            Durability::Volatile => "volatile",
            Durability::TransientLocal => "transient-local",
            Durability::Transient => "transient",
            Durability::Persistent => "persistent",
        },
        ownership: match ownership {
            Ownership::Shared => "shared",
            Ownership::Exclusive => "exclusive",
        },
        partitions: partition.0.clone(),
        type_information: d.type_information.is_some(),
    }
}

/// `0110abcd:12345678:9abcdef0`, the GUID prefix as three 32-bit words.
pub(crate) fn prefix_hex(p: &GuidPrefix) -> String {
    let w = |i: usize| u32::from_be_bytes([p.0[i], p.0[i + 1], p.0[i + 2], p.0[i + 3]]);
    format!("{:08x}:{:08x}:{:08x}", w(0), w(4), w(8))
}

/// The prefix, then the entity id.
fn guid_hex(g: &Guid) -> String {
    format!(
        "{}:{:08x}",
        prefix_hex(&g.prefix),
        u32::from_be_bytes(g.entity_id.0)
    )
}

fn vendor_name(v: VendorId) -> String {
    match v {
        VendorId::CYCLONE => "Eclipse Cyclone DDS".into(),
        VendorId::FASTDDS => "eProsima Fast DDS".into(),
        VendorId::RTI => "RTI Connext".into(),
        VendorId::OPENDDS => "OpenDDS".into(),
        VendorId::THIS => "dds-runtime".into(),
        VendorId([a, b]) => format!("{a:02x}{b:02x}"),
    }
}
