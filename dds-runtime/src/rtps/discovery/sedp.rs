//! DiscoveredWriterData / DiscoveredReaderData (§8.5.4, §9.6.2.2) and their parameter-list form.

use super::{pl_payload, PL_CDR_LE};
use crate::qos::wire::{read_reader_qos, read_writer_qos, write_reader_qos, write_writer_qos};
use crate::qos::{ReaderQos, WriterQos};
use crate::rtps::messages::parameter::{pid, ParameterWriter};
use crate::rtps::messages::{ParameterList, WireError};
use crate::rtps::types::*;
use crate::xtypes::TypeInformation;

const MAX_LOCATORS: usize = 64;

/// A publication as announced in SEDP.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct WriterData {
    pub guid: Guid,
    pub participant_guid: Option<Guid>,
    pub topic_name: String,
    pub type_name: String,
    pub qos: WriterQos,
    pub unicast_locators: Vec<Locator>,
    pub multicast_locators: Vec<Locator>,
    pub type_information: Option<TypeInformation>,
    pub entity_name: Option<String>,
}

/// A subscription as announced in SEDP.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ReaderData {
    pub guid: Guid,
    pub participant_guid: Option<Guid>,
    pub topic_name: String,
    pub type_name: String,
    pub qos: ReaderQos,
    pub unicast_locators: Vec<Locator>,
    pub multicast_locators: Vec<Locator>,
    pub expects_inline_qos: bool,
    pub type_information: Option<TypeInformation>,
    pub entity_name: Option<String>,
}

/// Fields common to both kinds while decoding.
#[derive(Default)]
struct Common {
    guid: Option<Guid>,
    participant_guid: Option<Guid>,
    topic_name: Option<String>,
    type_name: Option<String>,
    unicast: Vec<Locator>,
    multicast: Vec<Locator>,
    expects_inline_qos: bool,
    type_information: Option<TypeInformation>,
    entity_name: Option<String>,
}

/// The parameters an endpoint announcement cannot do without.
struct RequiredEndpointFields {
    guid: Guid,
    topic_name: String,
    type_name: String,
}

/// Walks an endpoint announcement: common parameters go into `Common`, the rest to `read_qos`. An unknown
/// must-understand parameter rejects the whole announcement; vendor-specific ones are skipped.
fn decode_endpoint(
    payload: &[u8],
    mut read_qos: impl FnMut(u16, &[u8], bool) -> Result<bool, WireError>,
) -> Result<(Common, RequiredEndpointFields), WireError> {
    let pl = pl_payload(payload)?;
    let mut c = Common::default();
    for p in pl.iter() {
        if p.id & pid::VENDOR_SPECIFIC != 0 {
            continue;
        }
        let known =
            read_common(&pl, p.id, p.value, &mut c)? || read_qos(p.id, p.value, pl.little_endian)?;
        if !known && p.id & pid::MUST_UNDERSTAND != 0 {
            return Err(WireError::MustUnderstand(p.id));
        }
    }
    let required = RequiredEndpointFields {
        guid: c
            .guid
            .take()
            .ok_or(WireError::Invalid("SEDP without endpoint GUID"))?,
        topic_name: c
            .topic_name
            .take()
            .ok_or(WireError::Invalid("SEDP without topic name"))?,
        type_name: c
            .type_name
            .take()
            .ok_or(WireError::Invalid("SEDP without type name"))?,
    };
    Ok((c, required))
}

fn read_common(
    pl: &ParameterList<'_>,
    id: u16,
    value: &[u8],
    c: &mut Common,
) -> Result<bool, WireError> {
    let mut cur = pl.cursor(value);
    match id {
        pid::ENDPOINT_GUID => c.guid = Some(cur.guid()?),
        pid::PARTICIPANT_GUID => c.participant_guid = Some(cur.guid()?),
        pid::TOPIC_NAME => c.topic_name = Some(cur.string()?.to_owned()),
        pid::TYPE_NAME => c.type_name = Some(cur.string()?.to_owned()),
        pid::UNICAST_LOCATOR => {
            let l = cur.locator()?;
            if c.unicast.len() < MAX_LOCATORS && !c.unicast.contains(&l) {
                c.unicast.push(l);
            }
        }
        pid::MULTICAST_LOCATOR => {
            let l = cur.locator()?;
            if c.multicast.len() < MAX_LOCATORS && !c.multicast.contains(&l) {
                c.multicast.push(l);
            }
        }
        pid::EXPECTS_INLINE_QOS => c.expects_inline_qos = cur.u8()? != 0,
        pid::TYPE_INFORMATION => c.type_information = Some(TypeInformation(value.to_vec())),
        pid::ENTITY_NAME => c.entity_name = Some(cur.string()?.to_owned()),
        // Known and deliberately unused.
        pid::KEY_HASH
        | pid::GROUP_GUID
        | pid::TYPE_MAX_SIZE_SERIALIZED
        | pid::PROTOCOL_VERSION
        | pid::VENDORID => {}
        _ => return Ok(false),
    }
    Ok(true)
}

/// The endpoint GUID of a SEDP sample, from the payload (also works for key-only payloads).
pub(crate) fn endpoint_guid(payload: &[u8]) -> Option<Guid> {
    let pl = pl_payload(payload).ok()?;
    let v = pl.get(pid::ENDPOINT_GUID)?;
    pl.cursor(v).guid().ok()
}

#[allow(clippy::too_many_arguments)]
fn write_common(
    w: &mut ParameterWriter<'_>,
    guid: &Guid,
    topic: &str,
    type_name: &str,
    uc: &[Locator],
    mc: &[Locator],
    ti: &Option<TypeInformation>,
    name: &Option<String>,
) {
    w.guid(pid::ENDPOINT_GUID, guid);
    w.guid(
        pid::PARTICIPANT_GUID,
        &Guid::new(guid.prefix, EntityId::PARTICIPANT),
    );
    w.string(pid::TOPIC_NAME, topic);
    w.string(pid::TYPE_NAME, type_name);
    for l in uc {
        w.locator(pid::UNICAST_LOCATOR, l);
    }
    for l in mc {
        w.locator(pid::MULTICAST_LOCATOR, l);
    }
    if let Some(ti) = ti {
        w.raw(pid::TYPE_INFORMATION, &ti.0);
    }
    if let Some(n) = name {
        w.string(pid::ENTITY_NAME, n);
    }
}

impl WriterData {
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(512);
        out.extend_from_slice(&PL_CDR_LE);
        let mut w = ParameterWriter::new(&mut out, true);
        write_common(
            &mut w,
            &self.guid,
            &self.topic_name,
            &self.type_name,
            &self.unicast_locators,
            &self.multicast_locators,
            &self.type_information,
            &self.entity_name,
        );
        write_writer_qos(&mut w, &self.qos);
        w.finish();
        out
    }

    pub fn decode(payload: &[u8]) -> Result<WriterData, WireError> {
        let mut qos = WriterQos::default();
        let (c, required) = decode_endpoint(payload, |id, value, le| {
            read_writer_qos(id, value, le, &mut qos)
        })?;
        Ok(WriterData {
            guid: required.guid,
            participant_guid: c.participant_guid,
            topic_name: required.topic_name,
            type_name: required.type_name,
            qos,
            unicast_locators: c.unicast,
            multicast_locators: c.multicast,
            type_information: c.type_information,
            entity_name: c.entity_name,
        })
    }
}

impl ReaderData {
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(512);
        out.extend_from_slice(&PL_CDR_LE);
        let mut w = ParameterWriter::new(&mut out, true);
        write_common(
            &mut w,
            &self.guid,
            &self.topic_name,
            &self.type_name,
            &self.unicast_locators,
            &self.multicast_locators,
            &self.type_information,
            &self.entity_name,
        );
        if self.expects_inline_qos {
            w.bool(pid::EXPECTS_INLINE_QOS, true);
        }
        write_reader_qos(&mut w, &self.qos);
        w.finish();
        out
    }

    pub fn decode(payload: &[u8]) -> Result<ReaderData, WireError> {
        let mut qos = ReaderQos::default();
        let (c, required) = decode_endpoint(payload, |id, value, le| {
            read_reader_qos(id, value, le, &mut qos)
        })?;
        Ok(ReaderData {
            guid: required.guid,
            participant_guid: c.participant_guid,
            topic_name: required.topic_name,
            type_name: required.type_name,
            qos,
            unicast_locators: c.unicast,
            multicast_locators: c.multicast,
            expects_inline_qos: c.expects_inline_qos,
            type_information: c.type_information,
            entity_name: c.entity_name,
        })
    }
}

/// Key-only payload for an SEDP dispose/unregister: just the endpoint GUID.
pub(crate) fn encode_endpoint_key(guid: &Guid) -> Vec<u8> {
    let mut out = Vec::with_capacity(28);
    out.extend_from_slice(&PL_CDR_LE);
    let mut w = ParameterWriter::new(&mut out, true);
    w.guid(pid::ENDPOINT_GUID, guid);
    w.finish();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::qos::*;
    use std::time::Duration;

    #[test]
    fn round_trip_all_policies() {
        let wq = DataWriterQos::builder()
            .reliability(Reliability::Reliable {
                max_blocking_time: Duration::from_millis(250),
            })
            .durability(Durability::TransientLocal)
            .deadline(Duration::from_secs(2))
            .latency_budget(Duration::from_millis(3))
            .liveliness(Liveliness {
                kind: LivelinessKind::ManualByTopic,
                lease_duration: Duration::from_secs(4),
            })
            .ownership(Ownership::Exclusive)
            .ownership_strength(7)
            .destination_order(DestinationOrder::BySourceTimestamp)
            .history(History::KeepAll)
            .resource_limits(ResourceLimits {
                max_samples: Some(10),
                max_instances: None,
                max_samples_per_instance: Some(3),
            })
            .lifespan(Duration::from_secs(9))
            .user_data(vec![1, 2])
            .transport_priority(5)
            .data_representation(DataRepresentation::xcdr2())
            .build();
        let pubq = PublisherQos::builder()
            .partition(["A", "B*"])
            .group_data(vec![9])
            .presentation(Presentation {
                access_scope: PresentationAccessScope::Topic,
                coherent_access: true,
                ordered_access: false,
            })
            .build();
        let tq = TopicQos::builder().topic_data(vec![4, 5, 6]).build();
        let w = WriterData {
            guid: Guid::new(GuidPrefix([2; 12]), EntityId([0, 0, 1, 2])),
            participant_guid: Some(Guid::new(GuidPrefix([2; 12]), EntityId::PARTICIPANT)),
            topic_name: "Square".into(),
            type_name: "ShapeType".into(),
            qos: WriterQos::new(wq, &pubq, &tq),
            unicast_locators: vec![Locator::udpv4([10, 0, 0, 1], 7411)],
            multicast_locators: vec![],
            type_information: Some(TypeInformation(vec![1, 2, 3, 4])),
            entity_name: None,
        };
        let enc = w.encode();
        let back = WriterData::decode(&enc).unwrap();
        // Durations pass through 2^-32 fractions; compare after one more round trip.
        assert_eq!(WriterData::decode(&back.encode()).unwrap(), back);
        assert_eq!(back.topic_name, "Square");
        assert_eq!(back.qos.partition, Partition::new(["A", "B*"]));
        assert_eq!(back.qos.writer.ownership_strength.0, 7);
        assert_eq!(back.qos.writer.history, History::KeepAll);
        assert_eq!(
            back.qos.writer.data_representation,
            DataRepresentation::xcdr2()
        );
        assert_eq!(back.qos.topic_data.0, vec![4, 5, 6]);
        assert_eq!(
            back.qos.presentation.access_scope,
            PresentationAccessScope::Topic
        );
        assert_eq!(back.type_information, w.type_information);
        assert!(
            back.qos.writer.deadline.0.abs_diff(Duration::from_secs(2)) < Duration::from_nanos(2)
        );

        let rq = DataReaderQos::builder()
            .reliability(Reliability::RELIABLE)
            .time_based_filter(TimeBasedFilter {
                minimum_separation: Duration::from_millis(10),
            })
            .data_representation(vec![0, 2])
            .build();
        let r = ReaderData {
            guid: Guid::new(GuidPrefix([3; 12]), EntityId([0, 0, 1, 7])),
            topic_name: "Square".into(),
            type_name: "ShapeType".into(),
            qos: ReaderQos::from(rq),
            expects_inline_qos: true,
            ..Default::default()
        };
        let back = ReaderData::decode(&r.encode()).unwrap();
        assert_eq!(back.qos.reader.data_representation.0, vec![0, 2]);
        assert!(back.expects_inline_qos);
        assert!(back.qos.reader.reliability.is_reliable());
        assert_eq!(
            back.qos.reader.type_consistency,
            TypeConsistencyEnforcement::default()
        );
        let enc = r.encode();
        for n in 0..enc.len() {
            let _ = ReaderData::decode(&enc[..n]);
        }
    }

    #[test]
    fn unknown_and_must_understand() {
        let mut out = PL_CDR_LE.to_vec();
        let mut w = ParameterWriter::new(&mut out, true);
        w.guid(
            pid::ENDPOINT_GUID,
            &Guid::new(GuidPrefix([3; 12]), EntityId([0, 0, 1, 7])),
        );
        w.string(pid::TOPIC_NAME, "t");
        w.string(pid::TYPE_NAME, "T");
        w.u32(0x0fff, 1); // unknown: ignored
        w.u32(0xc001, 1); // vendor-specific with must-understand: still ignored
        w.finish();
        assert!(ReaderData::decode(&out).is_ok());
        let mut out2 = out[..out.len() - 4].to_vec();
        let mut w = ParameterWriter::new(&mut out2, true);
        w.u32(0x4fff, 1);
        w.finish();
        assert_eq!(
            ReaderData::decode(&out2),
            Err(WireError::MustUnderstand(0x4fff))
        );
    }
}
