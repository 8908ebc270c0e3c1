//! DiscoveredWriterData / DiscoveredReaderData (§8.5.4, §9.6.2.2) and their parameter-list form.

use std::sync::Arc;

use super::{pl_payload, ContentFilterProperty, PL_CDR_LE};
use crate::qos::{ReaderQos, WriterQos};
use crate::rtps::messages::parameter::{pid, ParameterWriter};
use crate::rtps::messages::{ParameterList, WireError};
use crate::rtps::types::*;
use crate::xtypes::TypeInformation;

const MAX_LOCATORS: usize = 64;

/// An endpoint as announced in SEDP (§8.5.4): a publication (`Q` = [`WriterQos`], see [`WriterData`]) or a
/// subscription (`Q` = [`ReaderQos`], see [`ReaderData`]). The two directions differ only in their QoS.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct EndpointData<Q> {
    /// The endpoint's GUID (PID_ENDPOINT_GUID), also the key of the SEDP sample.
    pub guid: Guid,
    /// The owning participant (PID_PARTICIPANT_GUID), if announced.
    pub participant_guid: Option<Guid>,
    /// The topic name.
    pub topic_name: String,
    /// The registered type name.
    pub type_name: String,
    /// The QoS as announced: endpoint, group and topic parts. Shared: a participant keeps one copy of each
    /// distinct QoS its peers announce (see `docs/performance.md`, "Footprint").
    pub qos: Arc<Q>,
    /// Unicast locators of the endpoint; empty means its participant's default unicast locators.
    pub unicast_locators: Vec<Locator>,
    /// Multicast locators of the endpoint.
    pub multicast_locators: Vec<Locator>,
    /// The endpoint wants inline QoS with every DATA (announced by readers only; always `false` for writers).
    pub expects_inline_qos: bool,
    /// XTypes TYPE_INFORMATION, kept opaque. Shared like `qos`.
    pub type_information: Option<Arc<TypeInformation>>,
    /// PID_ENTITY_NAME, if announced.
    pub entity_name: Option<String>,
    /// PID_CONTENT_FILTER_PROPERTY: the reader's content filter (readers only; boxed, as it is rarely set).
    pub content_filter: Option<Box<ContentFilterProperty>>,
    /// The endpoint's publisher or subscriber, if announced (PID_GROUP_ENTITYID with the endpoint's
    /// prefix, or PID_GROUP_GUID). Ours announce it for members of a group with GROUP access scope: the
    /// writers that share group sequence numbers.
    pub group: Option<Guid>,
}

/// A publication as announced in SEDP (DiscoveredWriterData).
pub type WriterData = EndpointData<WriterQos>;

/// A subscription as announced in SEDP (DiscoveredReaderData).
pub type ReaderData = EndpointData<ReaderQos>;

/// The QoS part of an SEDP announcement, the only part in which the two directions differ on the wire.
pub trait EndpointQos: Default {
    /// Appends the QoS parameters of this direction.
    fn write_params(&self, w: &mut ParameterWriter<'_>);
    /// Decodes one parameter into `self`; `Ok(false)` when it is not a QoS parameter of this direction.
    fn read_param(&mut self, id: u16, value: &[u8], little_endian: bool)
        -> Result<bool, WireError>;
}

impl<Q: EndpointQos> EndpointData<Q> {
    /// The PL_CDR_LE payload of the SEDP sample announcing this endpoint.
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(512);
        out.extend_from_slice(&PL_CDR_LE);
        let mut w = ParameterWriter::new(&mut out, true);
        w.guid(pid::ENDPOINT_GUID, &self.guid);
        w.guid(
            pid::PARTICIPANT_GUID,
            &Guid::new(self.guid.prefix, EntityId::PARTICIPANT),
        );
        w.string(pid::TOPIC_NAME, &self.topic_name);
        w.string(pid::TYPE_NAME, &self.type_name);
        for l in &self.unicast_locators {
            w.locator(pid::UNICAST_LOCATOR, l);
        }
        for l in &self.multicast_locators {
            w.locator(pid::MULTICAST_LOCATOR, l);
        }
        if let Some(ti) = &self.type_information {
            w.raw(pid::TYPE_INFORMATION, &ti.0);
        }
        if let Some(n) = &self.entity_name {
            w.string(pid::ENTITY_NAME, n);
        }
        if self.expects_inline_qos {
            w.bool(pid::EXPECTS_INLINE_QOS, true);
        }
        if let Some(f) = &self.content_filter {
            f.write(&mut w);
        }
        if let Some(g) = &self.group {
            w.raw(pid::GROUP_ENTITYID, &g.entity_id.0);
        }
        self.qos.write_params(&mut w);
        w.finish();
        out
    }

    /// Decodes an SEDP payload. An unknown must-understand parameter rejects the whole announcement;
    /// vendor-specific ones are skipped; the endpoint GUID, topic name and type name are required.
    pub fn decode(payload: &[u8]) -> Result<Self, WireError> {
        let pl = pl_payload(payload)?;
        let mut d = Decoded::<Q>::default();
        for p in pl.iter() {
            if p.id & pid::VENDOR_SPECIFIC != 0 {
                continue;
            }
            let known = d.read_common(&pl, p.id, p.value)?
                || d.qos.read_param(p.id, p.value, pl.little_endian)?;
            if !known && p.id & pid::MUST_UNDERSTAND != 0 {
                return Err(WireError::MustUnderstand(p.id));
            }
        }
        d.finish()
    }
}

/// An announcement while it is decoded: the required parameters are tracked apart.
#[derive(Default)]
struct Decoded<Q> {
    data: EndpointData<Q>,
    qos: Q,
    guid: Option<Guid>,
    topic_name: Option<String>,
    type_name: Option<String>,
    group_entity: Option<EntityId>,
}

impl<Q> Decoded<Q> {
    /// Decodes one parameter common to both directions; `Ok(false)` when `id` is not one of them.
    fn read_common(
        &mut self,
        pl: &ParameterList<'_>,
        id: u16,
        value: &[u8],
    ) -> Result<bool, WireError> {
        let mut cur = pl.cursor(value);
        let d = &mut self.data;
        match id {
            pid::ENDPOINT_GUID => self.guid = Some(cur.guid()?),
            pid::PARTICIPANT_GUID => d.participant_guid = Some(cur.guid()?),
            pid::TOPIC_NAME => self.topic_name = Some(cur.string()?.to_owned()),
            pid::TYPE_NAME => self.type_name = Some(cur.string()?.to_owned()),
            pid::UNICAST_LOCATOR => add_locator(&mut d.unicast_locators, cur.locator()?),
            pid::MULTICAST_LOCATOR => add_locator(&mut d.multicast_locators, cur.locator()?),
            pid::EXPECTS_INLINE_QOS => d.expects_inline_qos = cur.u8()? != 0,
            pid::TYPE_INFORMATION => {
                d.type_information = Some(Arc::new(TypeInformation(value.to_vec())))
            }
            pid::ENTITY_NAME => d.entity_name = Some(cur.string()?.to_owned()),
            pid::CONTENT_FILTER_PROPERTY => {
                d.content_filter = Some(Box::new(ContentFilterProperty::read(&mut cur)?))
            }
            pid::GROUP_GUID => d.group = Some(cur.guid()?),
            pid::GROUP_ENTITYID => self.group_entity = Some(cur.entity_id()?),
            // Known and deliberately unused.
            pid::KEY_HASH
            | pid::TYPE_MAX_SIZE_SERIALIZED
            | pid::PROTOCOL_VERSION
            | pid::VENDORID => {}
            _ => return Ok(false),
        }
        Ok(true)
    }

    fn finish(self) -> Result<EndpointData<Q>, WireError> {
        let guid = self
            .guid
            .ok_or(WireError::Invalid("SEDP without endpoint GUID"))?;
        let group = self
            .group_entity
            .map(|e| Guid::new(guid.prefix, e))
            .or(self.data.group);
        Ok(EndpointData {
            guid,
            group,
            topic_name: self
                .topic_name
                .ok_or(WireError::Invalid("SEDP without topic name"))?,
            type_name: self
                .type_name
                .ok_or(WireError::Invalid("SEDP without type name"))?,
            qos: Arc::new(self.qos),
            ..self.data
        })
    }
}

/// Adds a decoded locator, ignoring duplicates and anything beyond [`MAX_LOCATORS`].
fn add_locator(list: &mut Vec<Locator>, l: Locator) {
    if list.len() < MAX_LOCATORS && !list.contains(&l) {
        list.push(l);
    }
}

/// The endpoint GUID of a SEDP sample, from the payload (also works for key-only payloads).
pub(crate) fn endpoint_guid(payload: &[u8]) -> Option<Guid> {
    let pl = pl_payload(payload).ok()?;
    let v = pl.get(pid::ENDPOINT_GUID)?;
    pl.cursor(v).guid().ok()
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
            qos: WriterQos::new(wq, &pubq, &tq).into(),
            unicast_locators: vec![Locator::udpv4([10, 0, 0, 1], 7411)],
            multicast_locators: vec![],
            type_information: Some(TypeInformation(vec![1, 2, 3, 4]).into()),
            expects_inline_qos: false,
            entity_name: None,
            content_filter: None,
            group: Some(Guid::new(GuidPrefix([2; 12]), EntityId([0, 0, 3, 8]))),
        };
        let enc = w.encode();
        let back = WriterData::decode(&enc).unwrap();
        assert_eq!(back.group, w.group);
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
            qos: ReaderQos::from(rq).into(),
            expects_inline_qos: true,
            content_filter: Some(Box::new(ContentFilterProperty::ddssql(
                "Square_f",
                "Square",
                "x < %0",
                vec!["5".into()],
            ))),
            ..Default::default()
        };
        let back = ReaderData::decode(&r.encode()).unwrap();
        assert_eq!(back.content_filter, r.content_filter);
        assert_eq!(back.qos.reader.data_representation.ids(), [0, 2]);
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
