//! SEDP topic announcements (DCPSTopic, RTPS 2.5 §8.5.4.3 and §9.6.2.2, the builtin endpoints
//! `SEDP_TOPICS_WRITER`/`SEDP_TOPICS_READER` with builtin-endpoint-set bits 28 and 29): a topic's GUID, name,
//! type name and TOPIC_DATA in a parameter list. Cyclone DDS 11 announces no topic endpoints by default; we
//! announce and read them (ours with ours, and any peer that sends them).

use super::builtin::{TOPICS_ANNOUNCER, TOPICS_DETECTOR};
use super::{encode_endpoint_key, pl_payload, PL_CDR_LE};
use crate::rtps::messages::parameter::{pid, ParameterWriter};
use crate::rtps::messages::WireError;
use crate::rtps::types::{EntityId, Guid};

/// The builtin-endpoint-set bits of the topic endpoints we run.
pub const TOPIC_BITS: u32 = TOPICS_ANNOUNCER | TOPICS_DETECTOR;

/// (our topics writer, the remote reader it serves, the bit the remote must announce for it).
pub const TOPIC_WRITER_PAIR: (EntityId, EntityId, u32) = (
    EntityId::SEDP_TOPICS_WRITER,
    EntityId::SEDP_TOPICS_READER,
    TOPICS_DETECTOR,
);

/// (our topics reader, the remote writer it listens to, the bit the remote must announce for it).
pub const TOPIC_READER_PAIR: (EntityId, EntityId, u32) = (
    EntityId::SEDP_TOPICS_READER,
    EntityId::SEDP_TOPICS_WRITER,
    TOPICS_ANNOUNCER,
);

/// RTPS entity kind of a topic's GUID (as the DCPS registry uses for topic handles).
pub const TOPIC_ENTITY_KIND: u8 = 0x0a;

/// A topic as SEDP announces it.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct TopicData {
    /// The topic's GUID (its participant's prefix).
    pub guid: Guid,
    /// The topic name.
    pub topic_name: String,
    /// The type name.
    pub type_name: String,
    /// TOPIC_DATA.
    pub topic_data: Vec<u8>,
}

impl TopicData {
    /// The announcement's payload (PL_CDR_LE).
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(128);
        out.extend_from_slice(&PL_CDR_LE);
        let mut w = ParameterWriter::new(&mut out, true);
        w.guid(pid::ENDPOINT_GUID, &self.guid);
        w.string(pid::TOPIC_NAME, &self.topic_name);
        w.string(pid::TYPE_NAME, &self.type_name);
        if !self.topic_data.is_empty() {
            w.octets(pid::TOPIC_DATA, &self.topic_data);
        }
        w.finish();
        out
    }

    /// Decodes an announcement; unknown parameters are skipped unless they must be understood.
    pub fn decode(payload: &[u8]) -> Result<Self, WireError> {
        let pl = pl_payload(payload)?;
        let (mut guid, mut name, mut type_name) = (None, None, None);
        let mut topic_data = Vec::new();
        for p in pl.iter() {
            let mut cur = pl.cursor(p.value);
            match p.id {
                pid::ENDPOINT_GUID => guid = Some(cur.guid()?),
                pid::TOPIC_NAME => name = Some(cur.string()?.to_owned()),
                pid::TYPE_NAME => type_name = Some(cur.string()?.to_owned()),
                pid::TOPIC_DATA => topic_data = cur.octets()?.to_vec(),
                id if id & pid::MUST_UNDERSTAND != 0 && id & pid::VENDOR_SPECIFIC == 0 => {
                    return Err(WireError::MustUnderstand(id));
                }
                _ => {}
            }
        }
        Ok(TopicData {
            guid: guid.ok_or(WireError::Invalid("SEDP topic without GUID"))?,
            topic_name: name.ok_or(WireError::Invalid("SEDP topic without name"))?,
            type_name: type_name.ok_or(WireError::Invalid("SEDP topic without type name"))?,
            topic_data,
        })
    }

    /// The payload of a dispose of topic `guid` (its key).
    pub fn encode_key(guid: &Guid) -> Vec<u8> {
        encode_endpoint_key(guid)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtps::types::GuidPrefix;

    #[test]
    fn round_trip_and_hostile_input() {
        let d = TopicData {
            guid: Guid::new(GuidPrefix([7; 12]), EntityId([0, 0, 1, TOPIC_ENTITY_KIND])),
            topic_name: "Square".into(),
            type_name: "ShapeType".into(),
            topic_data: b"td".to_vec(),
        };
        let bytes = d.encode();
        assert_eq!(TopicData::decode(&bytes).unwrap(), d);
        for n in 0..bytes.len() {
            let _ = TopicData::decode(&bytes[..n]);
        }
        let key = TopicData::encode_key(&d.guid);
        assert!(TopicData::decode(&key).is_err(), "a key alone has no name");
    }
}
