//! What the observer knows at one moment, in plain data: participants, topics and endpoints, sorted.

use std::collections::BTreeMap;

use dds_runtime::prelude::*;
use dds_runtime::qos::{ReaderQos, WriterQos};
use dds_runtime::rtps::VendorId;
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
    /// Reads what the participant discovered (the content of the DCPSParticipant, DCPSPublication and
    /// DCPSSubscription built-in topics).
    pub(crate) fn of(p: &DomainParticipant) -> Self {
        let mut participants: Vec<_> = p
            .discovered_participant_data()
            .iter()
            .map(participant)
            .collect();
        participants.sort_by(|a, b| a.guid_prefix.cmp(&b.guid_prefix));
        let mut endpoints: Vec<_> = p
            .discovered_publications()
            .iter()
            .map(|w| endpoint(Direction::Writer, &Announced::from(w)))
            .chain(
                p.discovered_subscriptions()
                    .iter()
                    .map(|r| endpoint(Direction::Reader, &Announced::from(r))),
            )
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

fn participant(p: &ParticipantBuiltinTopicData) -> ParticipantInfo {
    // The property names Cyclone DDS and we announce, and `cyclonedds ps` reads.
    let prop = |name: &str| p.property(name).map(str::to_string);
    ParticipantInfo {
        guid_prefix: prefix_hex(&p.key),
        vendor: vendor_name(p.vendor_id),
        name: p.entity_name.clone(),
        host: prop("__Hostname"),
        pid: prop("__Pid"),
        program: prop("__ProcessName"),
        addresses: prop("__NetworkAddresses"),
    }
}

/// What `dds ls` shows of a publication or a subscription: the two differ only in their QoS type.
struct Announced<'a> {
    key: Guid,
    participant_key: Option<Guid>,
    topic_name: &'a str,
    type_name: &'a str,
    reliability: &'a Reliability,
    durability: &'a Durability,
    ownership: &'a Ownership,
    partition: &'a Partition,
    type_information: bool,
}

/// `From` for the built-in data of one direction: `$qos` is its QoS type, `$own` the field holding the
/// endpoint's own policies; everything else is shared.
macro_rules! announced_from {
    ($data:ty, $qos:ident, $own:ident) => {
        impl<'a> From<&'a $data> for Announced<'a> {
            fn from(d: &'a $data) -> Self {
                let $qos {
                    $own: q, partition, ..
                } = &d.qos;
                Announced {
                    key: d.key,
                    participant_key: d.participant_key,
                    topic_name: &d.topic_name,
                    type_name: &d.type_name,
                    reliability: &q.reliability,
                    durability: &q.durability,
                    ownership: &q.ownership,
                    partition,
                    type_information: d.type_information.is_some(),
                }
            }
        }
    };
}

announced_from!(PublicationBuiltinTopicData, WriterQos, writer);
announced_from!(SubscriptionBuiltinTopicData, ReaderQos, reader);

fn endpoint(direction: Direction, d: &Announced<'_>) -> EndpointInfo {
    EndpointInfo {
        direction,
        guid: guid_hex(&d.key),
        participant: prefix_hex(&d.participant_key.map_or(d.key.prefix, |g| g.prefix)),
        topic: d.topic_name.to_string(),
        type_name: d.type_name.to_string(),
        reliability: match d.reliability {
            Reliability::BestEffort => "best-effort",
            Reliability::Reliable { .. } => "reliable",
        },
        durability: match d.durability {
            Durability::Volatile => "volatile",
            Durability::TransientLocal => "transient-local",
            Durability::Transient => "transient",
            Durability::Persistent => "persistent",
        },
        ownership: match d.ownership {
            Ownership::Shared => "shared",
            Ownership::Exclusive => "exclusive",
        },
        partitions: d.partition.0.clone(),
        type_information: d.type_information,
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
