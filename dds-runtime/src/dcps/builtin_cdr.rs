//! The built-in topic data types as topic types ([`DdsType`]), so that the built-in readers are ordinary
//! `DataReader<T>`s: a CDR form (`@final` structs keyed by the entity's GUID, `BuiltinTopicKey_t` of DDS
//! 1.4 §2.2.5 as 16 octets), the type descriptors and member access for filters and queries.
//!
//! Discovery feeds the built-in readers directly; the CDR form is what `lookup_instance`, `get_key_value`
//! and a writer of these types use. It carries the key, the names, USER_DATA / TOPIC_DATA, the vendor, the
//! entity name and the properties, but not an endpoint's QoS or type information (decoding gives the
//! defaults).

use crate::cdr::{
    CdrReader, CdrType, CdrWriter, DdsType, DecodeError, EncodeError, Extensibility, Layout,
    MemberDescriptor, TypeDescriptor, XcdrVersion,
};
use crate::filter::{FieldValue, FilterFields, PathSegment};
use crate::qos::{ReaderQos, WriterQos};
use crate::rtps::{EntityId, Guid, GuidPrefix, VendorId};

use super::builtin::{
    EndpointBuiltinTopicData, ParticipantBuiltinTopicData, TopicBuiltinTopicData,
};
use super::sample::InstanceHandle;

/// A member of a built-in type's descriptor.
const fn member(name: &'static str, id: u32, key: bool) -> MemberDescriptor {
    MemberDescriptor {
        name,
        id,
        key,
        optional: false,
        must_understand: key,
    }
}

/// The instance handle of a built-in topic instance from its serialized key (`cdr::instance_key`): the
/// entity's handle, as `get_matched_*_data`, `ignore_*` and `contains_entity` take it.
pub(crate) fn guid_key_handle(key: &[u8]) -> InstanceHandle {
    match <[u8; 16]>::try_from(key) {
        Ok(b) => InstanceHandle::from_guid(Guid::from_bytes(b)),
        Err(_) => InstanceHandle::NIL,
    }
}

/// [`guid_key_handle`] for DCPSTopic, whose key is the topic's handle (8 octets, big-endian).
pub(crate) fn topic_key_handle(key: &[u8]) -> InstanceHandle {
    match <[u8; 8]>::try_from(key) {
        Ok(b) => InstanceHandle(u64::from_be_bytes(b)),
        Err(_) => InstanceHandle::NIL,
    }
}

/// The member `path` names, for filters: `name` answers with `value`'s members below it.
fn field<'a>(
    path: &[PathSegment],
    members: &[(&str, &'a dyn FilterFields)],
) -> Option<FieldValue<'a>> {
    let (first, rest) = path.split_first()?;
    let name = first.member()?;
    let (_, v) = members.iter().find(|(n, _)| *n == name)?;
    v.field_value(rest)
}

/// Encodes properties as a flat `sequence<string>` of name, value, name, value, ...
fn encode_pairs(pairs: &[(String, String)], w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
    let flat: Vec<String> = pairs
        .iter()
        .flat_map(|(k, v)| [k.clone(), v.clone()])
        .collect();
    flat.encode(w)
}

fn decode_pairs(r: &mut CdrReader<'_>) -> Result<Vec<(String, String)>, DecodeError> {
    let flat = Vec::<String>::decode(r)?;
    Ok(flat
        .chunks_exact(2)
        .map(|p| (p[0].clone(), p[1].clone()))
        .collect())
}

/// The CdrType items every built-in type shares: a struct keyed by a fixed-size octet array.
macro_rules! keyed_struct {
    ($key_len:expr) => {
        const LAYOUT: Layout = Layout::Other;
        const MIN_SIZE: usize = $key_len;

        fn key_max_end(
            start: usize,
            _version: XcdrVersion,
            _bound: Option<usize>,
        ) -> Option<usize> {
            Some(start + $key_len)
        }
    };
}

static PARTICIPANT_MEMBERS: [MemberDescriptor; 5] = [
    member("key", 0, true),
    member("user_data", 1, false),
    member("vendor_id", 2, false),
    member("entity_name", 3, false),
    member("properties", 4, false),
];

impl CdrType for ParticipantBuiltinTopicData {
    keyed_struct!(16);

    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        Guid::new(self.key, EntityId::PARTICIPANT)
            .to_bytes()
            .encode(w)?;
        if w.key_only() {
            return Ok(());
        }
        self.user_data.encode(w)?;
        self.vendor_id.0.encode(w)?;
        self.entity_name.clone().unwrap_or_default().encode(w)?;
        encode_pairs(&self.properties, w)
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        let key = Guid::from_bytes(<[u8; 16]>::decode(r)?).prefix;
        let mut d = Self::default_value();
        d.key = key;
        if r.key_only() {
            return Ok(d);
        }
        d.user_data = Vec::decode(r)?;
        d.vendor_id = VendorId(<[u8; 2]>::decode(r)?);
        d.entity_name = Some(String::decode(r)?).filter(|n| !n.is_empty());
        d.properties = decode_pairs(r)?;
        Ok(d)
    }

    fn default_value() -> Self {
        ParticipantBuiltinTopicData {
            key: GuidPrefix::UNKNOWN,
            user_data: Vec::new(),
            vendor_id: VendorId([0, 0]),
            entity_name: None,
            properties: Vec::new(),
        }
    }
}

impl FilterFields for ParticipantBuiltinTopicData {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        static NO_NAME: String = String::new();
        let name: &dyn FilterFields = self.entity_name.as_ref().unwrap_or(&NO_NAME);
        field(
            path,
            &[("user_data", &self.user_data), ("entity_name", name)],
        )
    }
}

impl DdsType for ParticipantBuiltinTopicData {
    const TYPE_NAME: &'static str = "DDS::ParticipantBuiltinTopicData";
    const EXTENSIBILITY: Extensibility = Extensibility::Final;
    const IS_KEYED: bool = true;

    fn type_descriptor() -> TypeDescriptor {
        TypeDescriptor {
            type_name: Self::TYPE_NAME,
            extensibility: Self::EXTENSIBILITY,
            members: &PARTICIPANT_MEMBERS,
        }
    }
}

static ENDPOINT_MEMBERS: [MemberDescriptor; 4] = [
    member("key", 0, true),
    member("participant_key", 1, false),
    member("topic_name", 2, false),
    member("type_name", 3, false),
];

/// CdrType, FilterFields and DdsType of DCPSPublication and DCPSSubscription (they differ in the QoS).
macro_rules! endpoint_type {
    ($qos:ty, $name:literal) => {
        impl CdrType for EndpointBuiltinTopicData<$qos> {
            keyed_struct!(16);

            fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
                self.key.to_bytes().encode(w)?;
                if w.key_only() {
                    return Ok(());
                }
                self.participant_key
                    .unwrap_or(Guid::UNKNOWN)
                    .to_bytes()
                    .encode(w)?;
                self.topic_name.encode(w)?;
                self.type_name.encode(w)
            }

            fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
                let mut d = Self::default_value();
                d.key = Guid::from_bytes(<[u8; 16]>::decode(r)?);
                if r.key_only() {
                    return Ok(d);
                }
                let p = Guid::from_bytes(<[u8; 16]>::decode(r)?);
                d.participant_key = (p != Guid::UNKNOWN).then_some(p);
                d.topic_name = String::decode(r)?;
                d.type_name = String::decode(r)?;
                Ok(d)
            }

            fn default_value() -> Self {
                EndpointBuiltinTopicData {
                    key: Guid::UNKNOWN,
                    participant_key: None,
                    topic_name: String::new(),
                    type_name: String::new(),
                    qos: <$qos>::default(),
                    type_information: None,
                }
            }
        }

        impl FilterFields for EndpointBuiltinTopicData<$qos> {
            fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
                field(
                    path,
                    &[
                        ("topic_name", &self.topic_name),
                        ("type_name", &self.type_name),
                    ],
                )
            }
        }

        impl DdsType for EndpointBuiltinTopicData<$qos> {
            const TYPE_NAME: &'static str = $name;
            const EXTENSIBILITY: Extensibility = Extensibility::Final;
            const IS_KEYED: bool = true;

            fn type_descriptor() -> TypeDescriptor {
                TypeDescriptor {
                    type_name: Self::TYPE_NAME,
                    extensibility: Self::EXTENSIBILITY,
                    members: &ENDPOINT_MEMBERS,
                }
            }
        }
    };
}

endpoint_type!(WriterQos, "DDS::PublicationBuiltinTopicData");
endpoint_type!(ReaderQos, "DDS::SubscriptionBuiltinTopicData");

static TOPIC_MEMBERS: [MemberDescriptor; 4] = [
    member("key", 0, true),
    member("name", 1, false),
    member("type_name", 2, false),
    member("topic_data", 3, false),
];

impl CdrType for TopicBuiltinTopicData {
    keyed_struct!(8);

    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        self.key.0.to_be_bytes().encode(w)?;
        if w.key_only() {
            return Ok(());
        }
        self.name.encode(w)?;
        self.type_name.encode(w)?;
        self.topic_data.encode(w)
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        let mut d = Self::default_value();
        d.key = InstanceHandle(u64::from_be_bytes(<[u8; 8]>::decode(r)?));
        if r.key_only() {
            return Ok(d);
        }
        d.name = String::decode(r)?;
        d.type_name = String::decode(r)?;
        d.topic_data = Vec::decode(r)?;
        Ok(d)
    }

    fn default_value() -> Self {
        TopicBuiltinTopicData {
            key: InstanceHandle::NIL,
            name: String::new(),
            type_name: String::new(),
            topic_data: Vec::new(),
        }
    }
}

impl FilterFields for TopicBuiltinTopicData {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        field(
            path,
            &[
                ("name", &self.name),
                ("type_name", &self.type_name),
                ("topic_data", &self.topic_data),
            ],
        )
    }
}

impl DdsType for TopicBuiltinTopicData {
    const TYPE_NAME: &'static str = "DDS::TopicBuiltinTopicData";
    const EXTENSIBILITY: Extensibility = Extensibility::Final;
    const IS_KEYED: bool = true;

    fn type_descriptor() -> TypeDescriptor {
        TypeDescriptor {
            type_name: Self::TYPE_NAME,
            extensibility: Self::EXTENSIBILITY,
            members: &TOPIC_MEMBERS,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cdr::{self, ByteOrder};

    fn round_trip<T: DdsType + PartialEq + std::fmt::Debug>(v: &T) -> T {
        let mut buf = Vec::new();
        cdr::serialize(v, XcdrVersion::Xcdr2, ByteOrder::LittleEndian, &mut buf).unwrap();
        cdr::deserialize(&buf).unwrap()
    }

    #[test]
    fn participant_round_trips_and_its_key_is_the_participant_guid() {
        let mut d = ParticipantBuiltinTopicData::default_value();
        d.key = GuidPrefix([7; 12]);
        d.user_data = b"app".to_vec();
        d.vendor_id = VendorId([1, 16]);
        d.entity_name = Some("p".into());
        d.properties = vec![("__Pid".into(), "42".into())];
        assert_eq!(round_trip(&d), d);
        let mut key = Vec::new();
        cdr::instance_key(&d, &mut key).unwrap();
        let g = Guid::new(d.key, EntityId::PARTICIPANT);
        assert_eq!(key, g.to_bytes());
        assert_eq!(guid_key_handle(&key), InstanceHandle::from_guid(g));
    }

    #[test]
    fn endpoint_and_topic_keys_give_the_entity_handles() {
        let mut w = EndpointBuiltinTopicData::<WriterQos>::default_value();
        w.key = Guid::new(GuidPrefix([3; 12]), EntityId([0, 0, 1, 2]));
        w.participant_key = Some(Guid::new(GuidPrefix([3; 12]), EntityId::PARTICIPANT));
        w.topic_name = "Square".into();
        w.type_name = "ShapeType".into();
        assert_eq!(round_trip(&w), w);
        let mut key = Vec::new();
        cdr::instance_key(&w, &mut key).unwrap();
        assert_eq!(guid_key_handle(&key), InstanceHandle::from_guid(w.key));

        let t = TopicBuiltinTopicData::new("Square", "ShapeType", b"td".to_vec());
        assert_eq!(round_trip(&t), t);
        let mut key = Vec::new();
        cdr::instance_key(&t, &mut key).unwrap();
        assert_eq!(topic_key_handle(&key), t.key);
    }

    #[test]
    fn truncated_input_never_panics() {
        let mut d = ParticipantBuiltinTopicData::default_value();
        d.properties = vec![("a".into(), "b".into())];
        let mut buf = Vec::new();
        cdr::serialize(&d, XcdrVersion::Xcdr2, ByteOrder::LittleEndian, &mut buf).unwrap();
        for n in 0..buf.len() {
            let r = cdr::deserialize::<ParticipantBuiltinTopicData>(&buf[..n]);
            // Header and key cut: an error; later cuts may land on padding, but never panic.
            assert!(n >= 20 || r.is_err(), "{n} bytes");
        }
        assert_eq!(
            cdr::deserialize::<ParticipantBuiltinTopicData>(&buf).unwrap(),
            d
        );
    }
}
