//! SPDPdiscoveredParticipantData (§8.5.3.2, §9.6.2.2) and its parameter-list form.

use std::time::Duration;

use super::{pl_payload, PL_CDR_LE};
use crate::rtps::messages::parameter::{pid, put_string, ParameterWriter};
use crate::rtps::messages::WireError;
use crate::rtps::types::*;

/// What a participant announces about itself.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParticipantData {
    /// The participant's GUID prefix.
    pub guid_prefix: GuidPrefix,
    /// The RTPS version it speaks.
    pub protocol_version: ProtocolVersion,
    /// Its vendor.
    pub vendor_id: VendorId,
    /// Its domain id, when announced (absent: the receiver's own).
    pub domain_id: Option<u32>,
    /// Its domain tag; participants with a non-empty tag are ignored.
    pub domain_tag: String,
    /// Whether its builtin readers want inline QoS.
    pub expects_inline_qos: bool,
    /// Where to send it discovery traffic unicast.
    pub metatraffic_unicast: Vec<Locator>,
    /// Where to send it discovery traffic by multicast.
    pub metatraffic_multicast: Vec<Locator>,
    /// Where to send it user traffic unicast (unless an endpoint announces its own locators).
    pub default_unicast: Vec<Locator>,
    /// Where to send it user traffic by multicast.
    pub default_multicast: Vec<Locator>,
    /// How long it lives without announcing itself.
    pub lease_duration: Duration,
    /// Its builtin endpoints (`builtin::*` bits).
    pub builtin_endpoints: u32,
    /// Its manual liveliness count.
    pub manual_liveliness_count: i32,
    /// USER_DATA.
    pub user_data: Vec<u8>,
    /// Its property list (name, value).
    pub properties: Vec<(String, String)>,
    /// Its entity name, if announced.
    pub entity_name: Option<String>,
}

impl Default for ParticipantData {
    fn default() -> Self {
        ParticipantData {
            guid_prefix: GuidPrefix::UNKNOWN,
            protocol_version: ProtocolVersion::V2_5,
            vendor_id: VendorId::UNKNOWN,
            domain_id: None,
            domain_tag: String::new(),
            expects_inline_qos: false,
            metatraffic_unicast: Vec::new(),
            metatraffic_multicast: Vec::new(),
            default_unicast: Vec::new(),
            default_multicast: Vec::new(),
            // The spec default lease (§9.6.2.2: 100 s).
            lease_duration: Duration::from_secs(100),
            builtin_endpoints: 0,
            manual_liveliness_count: 0,
            user_data: Vec::new(),
            properties: Vec::new(),
            entity_name: None,
        }
    }
}

/// Caps what a hostile peer can make us keep per list.
const MAX_LOCATORS: usize = 64;

impl ParticipantData {
    /// The GUID of the participant entity.
    pub fn guid(&self) -> Guid {
        Guid::new(self.guid_prefix, EntityId::PARTICIPANT)
    }

    /// The serialized payload (PL_CDR_LE encapsulation).
    pub fn encode(&self) -> Vec<u8> {
        self.encode_parts(true)
    }

    /// The serialized payload without the GUID, the vendor, the builtin endpoint set and the lease: the
    /// form a discovered participant is kept in, those fields being kept decoded beside it (see
    /// `ProxyParticipant`). [`ParticipantData::decode_without_kept`] reads it back.
    pub(crate) fn encode_without_kept(&self) -> Vec<u8> {
        self.encode_parts(false)
    }

    fn encode_parts(&self, whole: bool) -> Vec<u8> {
        let mut out = Vec::with_capacity(256);
        out.extend_from_slice(&PL_CDR_LE);
        let mut w = ParameterWriter::new(&mut out, true);
        w.param(pid::PROTOCOL_VERSION, |p| {
            p.u8(self.protocol_version.major);
            p.u8(self.protocol_version.minor);
        });
        if whole {
            w.param(pid::VENDORID, |p| p.bytes(&self.vendor_id.0));
            w.guid(pid::PARTICIPANT_GUID, &self.guid());
            w.u32(pid::BUILTIN_ENDPOINT_SET, self.builtin_endpoints);
        }
        if let Some(d) = self.domain_id {
            w.u32(pid::DOMAIN_ID, d);
        }
        if !self.domain_tag.is_empty() {
            w.string(pid::DOMAIN_TAG, &self.domain_tag);
        }
        if self.expects_inline_qos {
            w.bool(pid::EXPECTS_INLINE_QOS, true);
        }
        for l in &self.metatraffic_unicast {
            w.locator(pid::METATRAFFIC_UNICAST_LOCATOR, l);
        }
        for l in &self.metatraffic_multicast {
            w.locator(pid::METATRAFFIC_MULTICAST_LOCATOR, l);
        }
        for l in &self.default_unicast {
            w.locator(pid::DEFAULT_UNICAST_LOCATOR, l);
        }
        for l in &self.default_multicast {
            w.locator(pid::DEFAULT_MULTICAST_LOCATOR, l);
        }
        if whole {
            w.duration(pid::PARTICIPANT_LEASE_DURATION, self.lease_duration);
        }
        if self.manual_liveliness_count != 0 {
            w.i32(
                pid::PARTICIPANT_MANUAL_LIVELINESS_COUNT,
                self.manual_liveliness_count,
            );
        }
        if !self.user_data.is_empty() {
            w.octets(pid::USER_DATA, &self.user_data);
        }
        if !self.properties.is_empty() {
            w.param(pid::PROPERTY_LIST, |p| {
                p.u32(self.properties.len() as u32);
                for (k, v) in &self.properties {
                    for s in [k, v] {
                        while p.out.len() % 4 != 0 {
                            p.u8(0);
                        }
                        put_string(p, s);
                    }
                }
                while p.out.len() % 4 != 0 {
                    p.u8(0);
                }
                // No binary properties.
                p.u32(0);
            });
        }
        if let Some(n) = &self.entity_name {
            w.string(pid::ENTITY_NAME, n);
        }
        w.finish();
        out
    }

    /// Decodes a serialized SPDP payload. Unknown parameters are skipped, vendor-specific ones ignored, and a
    /// not-understood must-understand parameter rejects the whole sample.
    pub fn decode(payload: &[u8]) -> Result<ParticipantData, WireError> {
        Self::decode_parts(payload, true)
    }

    /// Decodes [`ParticipantData::encode_without_kept`]'s form: the fields left out are at their defaults
    /// (the caller fills them in).
    pub(crate) fn decode_without_kept(payload: &[u8]) -> Result<ParticipantData, WireError> {
        Self::decode_parts(payload, false)
    }

    fn decode_parts(payload: &[u8], need_guid: bool) -> Result<ParticipantData, WireError> {
        let pl = pl_payload(payload)?;
        let mut d = ParticipantData::default();
        let mut have_guid = false;
        for p in pl.iter() {
            if p.id & pid::VENDOR_SPECIFIC != 0 {
                continue;
            }
            let mut c = pl.cursor(p.value);
            match p.id {
                pid::PROTOCOL_VERSION => {
                    d.protocol_version = ProtocolVersion {
                        major: c.u8()?,
                        minor: c.u8()?,
                    };
                }
                pid::VENDORID => d.vendor_id = VendorId(c.array()?),
                pid::PARTICIPANT_GUID => {
                    d.guid_prefix = c.guid()?.prefix;
                    have_guid = true;
                }
                pid::BUILTIN_ENDPOINT_SET => d.builtin_endpoints = c.u32()?,
                pid::DOMAIN_ID => d.domain_id = Some(c.u32()?),
                pid::DOMAIN_TAG => d.domain_tag = c.string()?.to_owned(),
                pid::EXPECTS_INLINE_QOS => d.expects_inline_qos = c.u8()? != 0,
                pid::METATRAFFIC_UNICAST_LOCATOR => {
                    push_locator(&mut d.metatraffic_unicast, c.locator()?)
                }
                pid::METATRAFFIC_MULTICAST_LOCATOR => {
                    push_locator(&mut d.metatraffic_multicast, c.locator()?)
                }
                pid::DEFAULT_UNICAST_LOCATOR => push_locator(&mut d.default_unicast, c.locator()?),
                pid::DEFAULT_MULTICAST_LOCATOR => {
                    push_locator(&mut d.default_multicast, c.locator()?)
                }
                pid::PARTICIPANT_LEASE_DURATION => d.lease_duration = c.duration()?,
                pid::PARTICIPANT_MANUAL_LIVELINESS_COUNT => d.manual_liveliness_count = c.i32()?,
                pid::USER_DATA => d.user_data = c.octets()?.to_vec(),
                pid::ENTITY_NAME => d.entity_name = Some(c.string()?.to_owned()),
                pid::PROPERTY_LIST => {
                    let n = c.u32()? as usize;
                    if n > c.remaining() / 8 {
                        return Err(WireError::Truncated);
                    }
                    let mut props = Vec::with_capacity(n);
                    for _ in 0..n {
                        c.align(4)?;
                        let k = c.string()?.to_owned();
                        c.align(4)?;
                        let v = c.string()?.to_owned();
                        props.push((k, v));
                    }
                    d.properties = props;
                }
                id if id & pid::MUST_UNDERSTAND != 0 => return Err(WireError::MustUnderstand(id)),
                _ => {}
            }
        }
        if need_guid && !have_guid {
            return Err(WireError::Invalid("SPDP without participant GUID"));
        }
        // Kept as long as the participant is known: no spare capacity.
        for v in [
            &mut d.metatraffic_unicast,
            &mut d.metatraffic_multicast,
            &mut d.default_unicast,
            &mut d.default_multicast,
        ] {
            v.shrink_to_fit();
        }
        Ok(d)
    }
}

fn push_locator(v: &mut Vec<Locator>, l: Locator) {
    if v.len() < MAX_LOCATORS && !v.contains(&l) {
        v.push(l);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let d = ParticipantData {
            guid_prefix: GuidPrefix([1; 12]),
            vendor_id: VendorId::THIS,
            domain_id: Some(3),
            metatraffic_unicast: vec![Locator::udpv4([127, 0, 0, 1], 7410)],
            metatraffic_multicast: vec![Locator::udpv4([239, 255, 0, 1], 7400)],
            default_unicast: vec![Locator::udpv4([127, 0, 0, 1], 7411)],
            lease_duration: Duration::from_secs(10),
            builtin_endpoints: super::super::builtin::OURS,
            user_data: vec![1, 2, 3],
            properties: vec![("a".into(), "bcd".into()), ("ef".into(), "".into())],
            entity_name: Some("p".into()),
            ..Default::default()
        };
        let enc = d.encode();
        assert_eq!(ParticipantData::decode(&enc).unwrap(), d);
        for n in 0..enc.len() {
            let _ = ParticipantData::decode(&enc[..n]);
        }
    }

    #[test]
    fn the_kept_form_leaves_out_what_is_kept_decoded() {
        let d = ParticipantData {
            guid_prefix: GuidPrefix([1; 12]),
            vendor_id: VendorId::THIS,
            domain_id: Some(3),
            metatraffic_unicast: vec![Locator::udpv4([127, 0, 0, 1], 7410)],
            lease_duration: Duration::from_secs(10),
            builtin_endpoints: super::super::builtin::OURS,
            properties: vec![("a".into(), "bcd".into())],
            ..Default::default()
        };
        let kept = d.encode_without_kept();
        // GUID (4 + 16), vendor (4 + 4), builtin endpoint set (4 + 4), lease (4 + 8).
        assert_eq!(d.encode().len() - kept.len(), 48);
        let back = ParticipantData::decode_without_kept(&kept).unwrap();
        assert_eq!(
            ParticipantData {
                guid_prefix: d.guid_prefix,
                vendor_id: d.vendor_id,
                lease_duration: d.lease_duration,
                builtin_endpoints: d.builtin_endpoints,
                ..back
            },
            d
        );
        assert!(ParticipantData::decode(&kept).is_err(), "no GUID");
    }
}
