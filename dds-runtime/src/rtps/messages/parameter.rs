//! Parameter lists (§9.4.2.11): (pid, length, value) entries aligned to 4, ended by PID_SENTINEL.

use super::cursor::Put;
use super::{Cursor, WireError};
use crate::rtps::types::*;

/// Parameter ids used by this implementation (§9.6.2.2, XTypes §7.6.3).
pub mod pid {
    /// Padding, skipped by readers.
    pub const PAD: u16 = 0x0000;
    /// Ends a parameter list.
    pub const SENTINEL: u16 = 0x0001;
    /// SPDP: how long the participant stays alive without announcements (Duration_t).
    pub const PARTICIPANT_LEASE_DURATION: u16 = 0x0002;
    /// Reader QoS: TIME_BASED_FILTER minimum separation.
    pub const TIME_BASED_FILTER: u16 = 0x0004;
    /// SEDP: the topic name (string).
    pub const TOPIC_NAME: u16 = 0x0005;
    /// Writer QoS: OWNERSHIP_STRENGTH value.
    pub const OWNERSHIP_STRENGTH: u16 = 0x0006;
    /// SEDP: the registered type name (string).
    pub const TYPE_NAME: u16 = 0x0007;
    /// SPDP: the domain id.
    pub const DOMAIN_ID: u16 = 0x000f;
    /// SPDP: the RTPS protocol version.
    pub const PROTOCOL_VERSION: u16 = 0x0015;
    /// SPDP: the vendor id.
    pub const VENDORID: u16 = 0x0016;
    /// QoS: RELIABILITY kind and max_blocking_time.
    pub const RELIABILITY: u16 = 0x001a;
    /// QoS: LIVELINESS kind and lease duration.
    pub const LIVELINESS: u16 = 0x001b;
    /// QoS: DURABILITY kind.
    pub const DURABILITY: u16 = 0x001d;
    /// Writer QoS: DURABILITY_SERVICE.
    pub const DURABILITY_SERVICE: u16 = 0x001e;
    /// QoS: OWNERSHIP kind.
    pub const OWNERSHIP: u16 = 0x001f;
    /// Group QoS: PRESENTATION.
    pub const PRESENTATION: u16 = 0x0021;
    /// QoS: DEADLINE period.
    pub const DEADLINE: u16 = 0x0023;
    /// QoS: DESTINATION_ORDER kind.
    pub const DESTINATION_ORDER: u16 = 0x0025;
    /// QoS: LATENCY_BUDGET duration.
    pub const LATENCY_BUDGET: u16 = 0x0027;
    /// Group QoS: PARTITION names.
    pub const PARTITION: u16 = 0x0029;
    /// Writer QoS: LIFESPAN duration.
    pub const LIFESPAN: u16 = 0x002b;
    /// QoS: USER_DATA octets.
    pub const USER_DATA: u16 = 0x002c;
    /// Group QoS: GROUP_DATA octets.
    pub const GROUP_DATA: u16 = 0x002d;
    /// Topic QoS: TOPIC_DATA octets.
    pub const TOPIC_DATA: u16 = 0x002e;
    /// SEDP: an endpoint's unicast locator.
    pub const UNICAST_LOCATOR: u16 = 0x002f;
    /// SEDP: an endpoint's multicast locator.
    pub const MULTICAST_LOCATOR: u16 = 0x0030;
    /// SPDP: a default (user traffic) unicast locator.
    pub const DEFAULT_UNICAST_LOCATOR: u16 = 0x0031;
    /// SPDP: a metatraffic unicast locator.
    pub const METATRAFFIC_UNICAST_LOCATOR: u16 = 0x0032;
    /// SPDP: a metatraffic multicast locator.
    pub const METATRAFFIC_MULTICAST_LOCATOR: u16 = 0x0033;
    /// The endpoint wants inline QoS with every DATA.
    pub const EXPECTS_INLINE_QOS: u16 = 0x0043;
    /// SPDP: the manual liveliness count.
    pub const PARTICIPANT_MANUAL_LIVELINESS_COUNT: u16 = 0x0034;
    /// QoS: HISTORY kind and depth.
    pub const HISTORY: u16 = 0x0040;
    /// QoS: RESOURCE_LIMITS.
    pub const RESOURCE_LIMITS: u16 = 0x0041;
    /// SPDP: a default (user traffic) multicast locator.
    pub const DEFAULT_MULTICAST_LOCATOR: u16 = 0x0048;
    /// Writer QoS: TRANSPORT_PRIORITY value.
    pub const TRANSPORT_PRIORITY: u16 = 0x0049;
    /// The participant's GUID.
    pub const PARTICIPANT_GUID: u16 = 0x0050;
    /// The publisher's or subscriber's GUID.
    pub const GROUP_GUID: u16 = 0x0052;
    /// The entity id of the endpoint's publisher or subscriber (RTPS 2.5 `remoteGroupEntityId`).
    pub const GROUP_ENTITYID: u16 = 0x0053;
    /// SPDP: the builtin endpoint set bits.
    pub const BUILTIN_ENDPOINT_SET: u16 = 0x0058;
    /// PID_COHERENT_SET (inline QoS): the sequence number of the first change of the coherent set.
    pub const COHERENT_SET: u16 = 0x0056;
    /// PID_GROUP_COHERENT_SET (inline QoS): the group sequence number of the first change of a group set.
    pub const GROUP_COHERENT_SET: u16 = 0x0063;
    /// PID_GROUP_SEQ_NUM (inline QoS): the change's sequence number within its publisher.
    pub const GROUP_SEQ_NUM: u16 = 0x0064;
    /// PID_WRITER_GROUP_INFO (inline QoS): the writers of a group coherent set.
    pub const WRITER_GROUP_INFO: u16 = 0x0065;
    /// SPDP: the property list (name, value pairs).
    pub const PROPERTY_LIST: u16 = 0x0059;
    /// SEDP: the endpoint's GUID.
    pub const ENDPOINT_GUID: u16 = 0x005a;
    /// SEDP: the largest serialized size of the type.
    pub const TYPE_MAX_SIZE_SERIALIZED: u16 = 0x0060;
    /// The entity's name.
    pub const ENTITY_NAME: u16 = 0x0062;
    /// ContentFilterProperty_t: a reader's content filter (SEDP).
    pub const CONTENT_FILTER_PROPERTY: u16 = 0x0035;
    /// ContentFilterInfo_t: the filter results a writer computed for a change (inline QoS).
    pub const CONTENT_FILTER_INFO: u16 = 0x0055;
    /// Inline QoS: the instance's key hash.
    pub const KEY_HASH: u16 = 0x0070;
    /// Inline QoS: dispose/unregister flags (see `messages::flags::StatusInfo`).
    pub const STATUS_INFO: u16 = 0x0071;
    /// QoS: DATA_REPRESENTATION ids.
    pub const DATA_REPRESENTATION: u16 = 0x0073;
    /// Reader QoS: TYPE_CONSISTENCY_ENFORCEMENT.
    pub const TYPE_CONSISTENCY: u16 = 0x0074;
    /// XTypes TYPE_INFORMATION.
    pub const TYPE_INFORMATION: u16 = 0x0075;
    /// SPDP: builtin endpoint QoS bits.
    pub const BUILTIN_ENDPOINT_QOS: u16 = 0x0077;
    /// SPDP: the domain tag (string).
    pub const DOMAIN_TAG: u16 = 0x4014;

    /// Bit marking a vendor-specific parameter.
    pub const VENDOR_SPECIFIC: u16 = 0x8000;
    /// Bit marking a parameter the receiver must understand or drop the whole message/sample.
    pub const MUST_UNDERSTAND: u16 = 0x4000;
}

/// One parameter, borrowed from the message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Parameter<'a> {
    /// The parameter id (PID), flag bits included.
    pub id: u16,
    /// The value, padding included.
    pub value: &'a [u8],
}

/// A validated parameter list (the sentinel was found), borrowed from the message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParameterList<'a> {
    /// The entries, without the sentinel.
    pub data: &'a [u8],
    /// Whether the entries are little-endian.
    pub little_endian: bool,
}

impl<'a> ParameterList<'a> {
    /// Splits a parameter list off the front of `data`: returns the list and what follows the sentinel.
    pub fn parse(
        data: &'a [u8],
        little_endian: bool,
    ) -> Result<(ParameterList<'a>, &'a [u8]), WireError> {
        let mut c = Cursor::new(data, little_endian);
        loop {
            let start = c.pos();
            let id = c.u16()?;
            let len = c.u16()? as usize;
            if id == pid::SENTINEL {
                // The sentinel's length is ignored (§9.4.2.11), but its value, if any, must be present.
                let _ = c.skip(len);
                return Ok((
                    ParameterList {
                        data: &data[..start],
                        little_endian,
                    },
                    c.rest(),
                ));
            }
            c.skip(len)?;
        }
    }

    /// The entries in order (sentinel excluded, PID_PAD skipped).
    pub fn iter(&self) -> impl Iterator<Item = Parameter<'a>> + 'a {
        let mut c = Cursor::new(self.data, self.little_endian);
        std::iter::from_fn(move || loop {
            let id = c.u16().ok()?;
            let len = c.u16().ok()? as usize;
            let value = c.bytes(len).ok()?;
            if id != pid::PAD {
                return Some(Parameter { id, value });
            }
        })
    }

    /// The value of the first parameter with id `id`.
    pub fn get(&self, id: u16) -> Option<&'a [u8]> {
        self.iter().find(|p| p.id == id).map(|p| p.value)
    }

    /// A cursor over one parameter's value in this list's byte order.
    pub fn cursor(&self, value: &'a [u8]) -> Cursor<'a> {
        Cursor::new(value, self.little_endian)
    }

    /// Finds the first parameter that is not vendor-specific, not in `understood`, and has the must-understand bit.
    pub fn check_must_understand(&self, understood: impl Fn(u16) -> bool) -> Result<(), WireError> {
        for p in self.iter() {
            if p.id & pid::VENDOR_SPECIFIC != 0 {
                continue;
            }
            if p.id & pid::MUST_UNDERSTAND != 0 && !understood(p.id) {
                return Err(WireError::MustUnderstand(p.id));
            }
        }
        Ok(())
    }

    /// The inline QoS a reader acts on for a DATA, in one pass over the list (where [`key_hash`],
    /// [`status_info`], [`coherent_set`], [`group_seq_num`] and [`check_must_understand`] walk it once
    /// each); each field from the first parameter of its id, as those give it.
    ///
    /// [`key_hash`]: Self::key_hash
    /// [`status_info`]: Self::status_info
    /// [`coherent_set`]: Self::coherent_set
    /// [`group_seq_num`]: Self::group_seq_num
    /// [`check_must_understand`]: Self::check_must_understand
    pub fn data_params(&self, understood: impl Fn(u16) -> bool) -> DataParams {
        let mut d = DataParams::default();
        let mut seen = 0u8;
        let mut first = |bit: u8| {
            let new = seen & bit == 0;
            seen |= bit;
            new
        };
        for p in self.iter() {
            match p.id {
                pid::KEY_HASH if first(1) => d.key_hash = p.value.get(..16).map(key16),
                pid::STATUS_INFO if first(2) => d.status_info = p.value.get(3).copied(),
                pid::COHERENT_SET if first(4) => d.coherent_set = self.sequence_value(p.value),
                pid::GROUP_SEQ_NUM if first(8) => d.group_seq_num = self.sequence_value(p.value),
                id if id & pid::VENDOR_SPECIFIC == 0
                    && id & pid::MUST_UNDERSTAND != 0
                    && !understood(id)
                    && d.not_understood.is_none() =>
                {
                    d.not_understood = Some(id)
                }
                _ => {}
            }
        }
        d
    }

    /// Inline QoS: the key hash.
    pub fn key_hash(&self) -> Option<[u8; 16]> {
        self.get(pid::KEY_HASH).and_then(|v| v.get(..16)).map(key16)
    }

    /// Inline QoS: PID_COHERENT_SET, the first sequence number of the change's coherent set.
    pub fn coherent_set(&self) -> Option<SequenceNumber> {
        self.sequence_number(pid::COHERENT_SET)
    }

    /// Inline QoS: PID_GROUP_SEQ_NUM, the change's number within its publisher's group.
    pub fn group_seq_num(&self) -> Option<SequenceNumber> {
        self.sequence_number(pid::GROUP_SEQ_NUM)
    }

    /// Inline QoS: PID_GROUP_COHERENT_SET, the group sequence number of the first change of the group
    /// coherent set.
    pub fn group_coherent_set(&self) -> Option<SequenceNumber> {
        self.sequence_number(pid::GROUP_COHERENT_SET)
    }

    /// A parameter holding a `SequenceNumber_t`.
    fn sequence_number(&self, id: u16) -> Option<SequenceNumber> {
        self.sequence_value(self.get(id)?)
    }

    /// A parameter's value read as a `SequenceNumber_t`.
    fn sequence_value(&self, v: &[u8]) -> Option<SequenceNumber> {
        let mut c = self.cursor(v);
        let high = c.i32().ok()?;
        let low = c.u32().ok()?;
        Some(SequenceNumber::from_parts(high, low))
    }

    /// Inline QoS: PID_WRITER_GROUP_INFO, the digest of the writers of a group coherent set.
    pub fn writer_group_info(&self) -> Option<[u8; 4]> {
        let v = self.get(pid::WRITER_GROUP_INFO)?.get(..4)?;
        Some([v[0], v[1], v[2], v[3]])
    }

    /// Inline QoS: the status-info flags (last byte; 0x01 disposed, 0x02 unregistered).
    pub fn status_info(&self) -> Option<u8> {
        self.get(pid::STATUS_INFO).and_then(|v| v.get(3).copied())
    }
}

/// The first 16 bytes of `v` (checked by the caller) as a key hash.
fn key16(v: &[u8]) -> [u8; 16] {
    let mut k = [0u8; 16];
    k.copy_from_slice(&v[..16]);
    k
}

/// What [`ParameterList::data_params`] reads from a DATA's inline QoS.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct DataParams {
    /// PID_KEY_HASH.
    pub key_hash: Option<[u8; 16]>,
    /// PID_STATUS_INFO's flags (its last byte).
    pub status_info: Option<u8>,
    /// PID_COHERENT_SET.
    pub coherent_set: Option<SequenceNumber>,
    /// PID_GROUP_SEQ_NUM.
    pub group_seq_num: Option<SequenceNumber>,
    /// The first parameter that is not vendor-specific, has the must-understand bit and is not understood.
    pub not_understood: Option<u16>,
}

/// Appends a parameter list in the given byte order. Call [`ParameterWriter::finish`] to add the sentinel.
pub struct ParameterWriter<'a> {
    put: Put<'a>,
}

impl<'a> ParameterWriter<'a> {
    /// A writer appending to `out` in the given byte order.
    pub fn new(out: &'a mut Vec<u8>, little_endian: bool) -> Self {
        ParameterWriter {
            put: Put { out, little_endian },
        }
    }

    /// Writes one parameter whose value `f` appends; pads to 4 and fills in the length.
    pub fn param(&mut self, id: u16, f: impl FnOnce(&mut Put<'_>)) {
        self.put.u16(id);
        let len_at = self.put.out.len();
        self.put.u16(0);
        let start = self.put.out.len();
        f(&mut self.put);
        self.put.align_from(start, 4);
        let len = (self.put.out.len() - start).min(u16::MAX as usize) as u16;
        let b = if self.put.little_endian {
            len.to_le_bytes()
        } else {
            len.to_be_bytes()
        };
        self.put.out[len_at..len_at + 2].copy_from_slice(&b);
    }

    /// A parameter holding `value` as is.
    pub fn raw(&mut self, id: u16, value: &[u8]) {
        self.param(id, |p| p.bytes(value));
    }
    /// A `u32` parameter.
    pub fn u32(&mut self, id: u16, v: u32) {
        self.param(id, |p| p.u32(v));
    }
    /// An `i32` parameter.
    pub fn i32(&mut self, id: u16, v: i32) {
        self.param(id, |p| p.i32(v));
    }
    /// A boolean parameter (one octet, padded).
    pub fn bool(&mut self, id: u16, v: bool) {
        self.param(id, |p| p.u8(v as u8));
    }
    /// A Duration_t parameter.
    pub fn duration(&mut self, id: u16, d: std::time::Duration) {
        self.param(id, |p| p.duration(d));
    }
    /// A GUID parameter.
    pub fn guid(&mut self, id: u16, g: &Guid) {
        self.param(id, |p| p.bytes(&g.to_bytes()));
    }
    /// A locator parameter.
    pub fn locator(&mut self, id: u16, l: &Locator) {
        self.param(id, |p| p.locator(l));
    }
    /// A CDR string parameter.
    pub fn string(&mut self, id: u16, s: &str) {
        self.param(id, |p| put_string(p, s));
    }
    /// A sequence-of-octets parameter (length, then bytes).
    pub fn octets(&mut self, id: u16, b: &[u8]) {
        self.param(id, |p| {
            p.u32(b.len() as u32);
            p.bytes(b);
        });
    }
    /// Ends the list without a sentinel: the form [`ParameterList::data`] holds (encoders add the sentinel).
    pub fn without_sentinel(self) {}

    /// Ends the list with the sentinel.
    pub fn finish(mut self) {
        self.put.u16(pid::SENTINEL);
        self.put.u16(0);
    }
}

/// A CDR string (length with NUL, bytes, NUL), unaligned after.
pub fn put_string(p: &mut Put<'_>, s: &str) {
    p.u32(s.len() as u32 + 1);
    p.bytes(s.as_bytes());
    p.u8(0);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_both_orders() {
        for le in [true, false] {
            let mut buf = Vec::new();
            let mut w = ParameterWriter::new(&mut buf, le);
            w.string(pid::TOPIC_NAME, "abc");
            w.u32(pid::DOMAIN_ID, 7);
            w.raw(0x8001, &[1, 2, 3, 4]);
            w.finish();
            buf.extend_from_slice(b"tail");
            let (pl, rest) = ParameterList::parse(&buf, le).unwrap();
            assert_eq!(rest, b"tail");
            let ps: Vec<_> = pl.iter().collect();
            assert_eq!(ps.len(), 3);
            assert_eq!(ps[0].id, pid::TOPIC_NAME);
            assert_eq!(pl.cursor(ps[0].value).string().unwrap(), "abc");
            assert_eq!(pl.cursor(pl.get(pid::DOMAIN_ID).unwrap()).u32().unwrap(), 7);
            assert!(pl.check_must_understand(|_| false).is_ok());
        }
    }

    #[test]
    fn data_params_read_what_the_single_getters_read() {
        for le in [true, false] {
            let mut buf = Vec::new();
            let mut w = ParameterWriter::new(&mut buf, le);
            w.raw(pid::PAD, &[0; 4]);
            w.raw(pid::STATUS_INFO, &[0, 0, 0, 3]);
            w.raw(pid::KEY_HASH, &[7; 16]);
            w.raw(pid::KEY_HASH, &[8; 16]);
            w.raw(pid::COHERENT_SET, &[0, 0, 0, 0, 5, 0, 0, 0]);
            w.raw(pid::GROUP_SEQ_NUM, &[0; 4]);
            w.raw(0x8fff | pid::MUST_UNDERSTAND, &[0; 4]);
            w.raw(0x4ffe, &[0; 4]);
            w.raw(0x4ffd, &[0; 4]);
            w.finish();
            let (pl, _) = ParameterList::parse(&buf, le).unwrap();
            let d = pl.data_params(|_| false);
            assert_eq!(d.key_hash, pl.key_hash());
            assert_eq!(d.key_hash, Some([7; 16]), "the first of its id");
            assert_eq!(d.status_info, pl.status_info());
            assert_eq!(d.status_info, Some(3));
            assert_eq!(d.coherent_set, pl.coherent_set());
            assert!(d.coherent_set.is_some());
            assert_eq!(d.group_seq_num, pl.group_seq_num());
            assert_eq!(d.group_seq_num, None, "too short a value");
            assert_eq!(
                d.not_understood,
                Some(0x4ffe),
                "vendor-specific ones are skipped"
            );
            assert_eq!(
                pl.check_must_understand(|_| false),
                Err(WireError::MustUnderstand(0x4ffe))
            );
            assert_eq!(pl.data_params(|id| id >= 0x4ffd).not_understood, None);
        }
        let empty = ParameterList {
            data: &[],
            little_endian: true,
        };
        assert_eq!(empty.data_params(|_| false), DataParams::default());
    }

    #[test]
    fn must_understand_and_truncation() {
        let mut buf = Vec::new();
        let mut w = ParameterWriter::new(&mut buf, true);
        w.u32(0x4fff, 1);
        w.finish();
        let (pl, _) = ParameterList::parse(&buf, true).unwrap();
        assert_eq!(
            pl.check_must_understand(|_| false),
            Err(WireError::MustUnderstand(0x4fff))
        );
        for n in 0..buf.len() - 4 {
            assert!(ParameterList::parse(&buf[..n], true).is_err(), "prefix {n}");
        }
    }
}
