//! Submessage structures (§9.4.5), decoded by borrowing from the datagram, and their encoders.

use super::cursor::Put;
use super::flags::*;
use super::{id, Cursor, ParameterList, WireError};
use crate::rtps::types::*;

/// Submessage flag bits shared by all: E (endianness).
pub const FLAG_E: u8 = 0x01;

/// ACKNACK (§9.4.5.2): a reader's positive and negative acknowledgements.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AckNack {
    /// The reader acknowledging (may be ENTITYID_UNKNOWN).
    pub reader_id: EntityId,
    /// The writer acknowledged.
    pub writer_id: EntityId,
    /// Everything below the base is acknowledged; set bits are missing.
    pub reader_sn_state: SequenceNumberSet,
    /// Counts ACKNACKs from this reader to this writer, to drop duplicates.
    pub count: i32,
    /// F: no answer is required.
    pub final_flag: bool,
}

/// HEARTBEAT (§9.4.5.6): the range of sequence numbers a writer has available.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Heartbeat {
    /// The reader addressed (ENTITYID_UNKNOWN: all matched readers).
    pub reader_id: EntityId,
    /// The writer announcing.
    pub writer_id: EntityId,
    /// The first sequence number still available.
    pub first_sn: SequenceNumber,
    /// The last sequence number written.
    pub last_sn: SequenceNumber,
    /// Counts HEARTBEATs from this writer, to drop duplicates.
    pub count: i32,
    /// F: the readers need not answer.
    pub final_flag: bool,
    /// L: the heartbeat asserts liveliness.
    pub liveliness_flag: bool,
    /// G: the writer belongs to a group (GROUP access scope) and says where the group stands.
    pub group_info: Option<HeartbeatGroupInfo>,
}

/// The group part of a HEARTBEAT (flag G, RTPS 2.5 §8.3.7.5, §9.4.5.6), sent by writers of a publisher with
/// GROUP access scope.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HeartbeatGroupInfo {
    /// The last group sequence number any writer of the group had written when the heartbeat was sent.
    pub current_gsn: SequenceNumber,
    /// The group sequence number of the change `first_sn`.
    pub first_gsn: SequenceNumber,
    /// The group sequence number of the change `last_sn`.
    pub last_gsn: SequenceNumber,
    /// The digest of the group's writers when `current_gsn` was written (`GroupDigest_t`).
    pub writer_set: [u8; 4],
    /// Reserved for DDS-Security (`GroupDigest_t`; zero here).
    pub secure_writer_set: [u8; 4],
}

/// GAP (§9.4.5.5): sequence numbers that will never be sent to the reader.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Gap {
    /// The reader addressed (ENTITYID_UNKNOWN: all matched readers).
    pub reader_id: EntityId,
    /// The writer.
    pub writer_id: EntityId,
    /// The first irrelevant sequence number of the contiguous range.
    pub gap_start: SequenceNumber,
    /// The range ends before the base; set bits are irrelevant too.
    pub gap_list: SequenceNumberSet,
}

impl Gap {
    /// Every sequence number the GAP declares irrelevant: [gap_start, gap_list.base) plus the set bits.
    pub fn contains(&self, sn: SequenceNumber) -> bool {
        (sn >= self.gap_start && sn < self.gap_list.base)
            || (sn >= self.gap_list.base && {
                let off = sn.0 - self.gap_list.base.0;
                off < 256 && self.gap_list.contains_offset(off as u32)
            })
    }
}

/// INFO_SRC (§9.4.5.8): the source of the following submessages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InfoSource {
    /// The source's protocol version.
    pub version: ProtocolVersion,
    /// The source's vendor.
    pub vendor_id: VendorId,
    /// The source's GUID prefix.
    pub guid_prefix: GuidPrefix,
}

/// INFO_REPLY: locator lists borrowed from the message (24 bytes each). Equality compares the locators.
#[derive(Debug, Clone, Copy)]
pub struct InfoReply<'a> {
    unicast: &'a [u8],
    multicast: Option<&'a [u8]>,
    little_endian: bool,
}

impl PartialEq for InfoReply<'_> {
    fn eq(&self, o: &Self) -> bool {
        self.unicast().eq(o.unicast())
            && self.multicast.is_some() == o.multicast.is_some()
            && self.multicast().eq(o.multicast())
    }
}
impl Eq for InfoReply<'_> {}

impl<'a> InfoReply<'a> {
    /// The unicast locators to reply to.
    pub fn unicast(&self) -> impl Iterator<Item = Locator> + 'a {
        locators(self.unicast, self.little_endian)
    }
    /// The multicast locators to reply to (none without the M flag).
    pub fn multicast(&self) -> impl Iterator<Item = Locator> + 'a {
        locators(self.multicast.unwrap_or(&[]), self.little_endian)
    }
}

fn locators(b: &[u8], le: bool) -> impl Iterator<Item = Locator> + '_ {
    b.chunks_exact(24)
        .filter_map(move |c| Cursor::new(c, le).locator().ok())
}

/// INFO_REPLY_IP4 (§9.4.5.11): where to reply, IPv4 form.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InfoReplyIp4 {
    /// The unicast locator to reply to.
    pub unicast: Locator,
    /// The multicast locator to reply to (M flag).
    pub multicast: Option<Locator>,
}

/// DATA (§9.4.5.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Data<'a> {
    /// The reader addressed (ENTITYID_UNKNOWN: all matched readers).
    pub reader_id: EntityId,
    /// The writer.
    pub writer_id: EntityId,
    /// The change's sequence number.
    pub writer_sn: SequenceNumber,
    /// Inline QoS (Q flag): key hash, status info and the like.
    pub inline_qos: Option<ParameterList<'a>>,
    /// The serialized payload (D flag) or serialized key (K flag).
    pub payload: Option<&'a [u8]>,
    /// K: the payload is a serialized key.
    pub key_flag: bool,
    /// N: the payload is not serialized by standard means.
    pub non_standard_flag: bool,
}

/// DATA_FRAG (§9.4.5.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DataFrag<'a> {
    /// The reader addressed (ENTITYID_UNKNOWN: all matched readers).
    pub reader_id: EntityId,
    /// The writer.
    pub writer_id: EntityId,
    /// The change's sequence number.
    pub writer_sn: SequenceNumber,
    /// 1-based number of the first fragment in this submessage.
    pub fragment_starting_num: u32,
    /// How many fragments this submessage carries.
    pub fragments_in_submessage: u16,
    /// The size of every fragment but the last.
    pub fragment_size: u16,
    /// The size of the whole serialized sample.
    pub sample_size: u32,
    /// Inline QoS (Q flag), in the submessage with the first fragment.
    pub inline_qos: Option<ParameterList<'a>>,
    /// The fragments' bytes, cut at the end of the sample.
    pub payload: &'a [u8],
    /// K: the fragments are of a serialized key.
    pub key_flag: bool,
    /// N: the payload is not serialized by standard means.
    pub non_standard_flag: bool,
}

impl DataFrag<'_> {
    /// Number of fragments of the whole sample.
    pub fn total_fragments(&self) -> u32 {
        self.sample_size.div_ceil(self.fragment_size as u32)
    }
}

/// HEARTBEAT_FRAG (§9.4.5.7): the fragments available of one sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HeartbeatFrag {
    /// The reader addressed (ENTITYID_UNKNOWN: all matched readers).
    pub reader_id: EntityId,
    /// The writer.
    pub writer_id: EntityId,
    /// The sample's sequence number.
    pub writer_sn: SequenceNumber,
    /// The last fragment available.
    pub last_fragment_num: u32,
    /// Counts HEARTBEAT_FRAGs from this writer, to drop duplicates.
    pub count: i32,
}

/// NACK_FRAG (§9.4.5.12): the fragments a reader is missing from one sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NackFrag {
    /// The reader asking.
    pub reader_id: EntityId,
    /// The writer asked.
    pub writer_id: EntityId,
    /// The sample's sequence number.
    pub writer_sn: SequenceNumber,
    /// The missing fragments.
    pub fragment_number_state: FragmentNumberSet,
    /// Counts NACK_FRAGs from this reader to this writer, to drop duplicates.
    pub count: i32,
}

/// One decoded submessage.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Submessage<'a> {
    /// PAD: nothing.
    Pad,
    /// ACKNACK.
    AckNack(AckNack),
    /// HEARTBEAT.
    Heartbeat(Heartbeat),
    /// GAP.
    Gap(Gap),
    /// INFO_TS; `None` when the I flag invalidates the timestamp.
    InfoTs(Option<Time>),
    /// INFO_SRC.
    InfoSrc(InfoSource),
    /// INFO_DST: the GUID prefix of the participant the following submessages are for.
    InfoDst(GuidPrefix),
    /// INFO_REPLY.
    InfoReply(InfoReply<'a>),
    /// INFO_REPLY_IP4.
    InfoReplyIp4(InfoReplyIp4),
    /// DATA.
    Data(Data<'a>),
    /// DATA_FRAG.
    DataFrag(DataFrag<'a>),
    /// HEARTBEAT_FRAG.
    HeartbeatFrag(HeartbeatFrag),
    /// NACK_FRAG.
    NackFrag(NackFrag),
    /// Unknown or vendor-specific (id >= 0x80) submessages, skipped by the receiver.
    Unknown {
        /// The submessage id.
        id: u8,
        /// The flag bits as received.
        flags: u8,
        /// The body, undecoded.
        body: &'a [u8],
    },
}

impl<'a> Submessage<'a> {
    /// Decodes a submessage body (the bytes after its 4-byte header).
    pub fn decode(sid: u8, flags: u8, body: &'a [u8]) -> Result<Submessage<'a>, WireError> {
        let le = flags & FLAG_E != 0;
        let mut c = Cursor::new(body, le);
        Ok(match sid {
            id::PAD => Submessage::Pad,
            id::ACKNACK => {
                let reader_id = c.entity_id()?;
                let writer_id = c.entity_id()?;
                let reader_sn_state = c.sequence_number_set()?;
                let count = c.i32()?;
                Submessage::AckNack(AckNack {
                    reader_id,
                    writer_id,
                    reader_sn_state,
                    count,
                    final_flag: AckNackFlags::from_bits_retain(flags).contains(AckNackFlags::FINAL),
                })
            }
            id::HEARTBEAT => {
                let reader_id = c.entity_id()?;
                let writer_id = c.entity_id()?;
                let first_sn = c.sequence_number()?;
                let last_sn = c.sequence_number()?;
                let count = c.i32()?;
                // §8.3.7.5.3: first >= 1 and last >= first - 1.
                if first_sn.0 < 1 || last_sn.0 < first_sn.0 - 1 {
                    return Err(WireError::Invalid("HEARTBEAT sequence numbers"));
                }
                let f = HeartbeatFlags::from_bits_retain(flags);
                let group_info = if f.contains(HeartbeatFlags::GROUP_INFO) {
                    Some(HeartbeatGroupInfo {
                        current_gsn: c.sequence_number()?,
                        first_gsn: c.sequence_number()?,
                        last_gsn: c.sequence_number()?,
                        writer_set: c.array()?,
                        secure_writer_set: c.array()?,
                    })
                } else {
                    None
                };
                Submessage::Heartbeat(Heartbeat {
                    reader_id,
                    writer_id,
                    first_sn,
                    last_sn,
                    count,
                    final_flag: f.contains(HeartbeatFlags::FINAL),
                    liveliness_flag: f.contains(HeartbeatFlags::LIVELINESS),
                    group_info,
                })
            }
            id::GAP => {
                let reader_id = c.entity_id()?;
                let writer_id = c.entity_id()?;
                let gap_start = c.sequence_number()?;
                let gap_list = c.sequence_number_set()?;
                if gap_start.0 < 1 || gap_list.base < gap_start {
                    return Err(WireError::Invalid("GAP range"));
                }
                Submessage::Gap(Gap {
                    reader_id,
                    writer_id,
                    gap_start,
                    gap_list,
                })
            }
            id::INFO_TS => {
                if InfoTsFlags::from_bits_retain(flags).contains(InfoTsFlags::INVALIDATE) {
                    Submessage::InfoTs(None)
                } else {
                    Submessage::InfoTs(Some(c.time()?))
                }
            }
            id::INFO_SRC => {
                c.skip(4)?;
                let major = c.u8()?;
                let minor = c.u8()?;
                let vendor_id = VendorId(c.array()?);
                let guid_prefix = c.guid_prefix()?;
                Submessage::InfoSrc(InfoSource {
                    version: ProtocolVersion { major, minor },
                    vendor_id,
                    guid_prefix,
                })
            }
            id::INFO_DST => Submessage::InfoDst(c.guid_prefix()?),
            id::INFO_REPLY => {
                let unicast = locator_list(&mut c)?;
                let multicast = if InfoReplyFlags::from_bits_retain(flags)
                    .contains(InfoReplyFlags::MULTICAST)
                {
                    Some(locator_list(&mut c)?)
                } else {
                    None
                };
                Submessage::InfoReply(InfoReply {
                    unicast,
                    multicast,
                    little_endian: le,
                })
            }
            id::INFO_REPLY_IP4 => {
                let unicast = ip4_locator(&mut c)?;
                let multicast = if InfoReplyFlags::from_bits_retain(flags)
                    .contains(InfoReplyFlags::MULTICAST)
                {
                    Some(ip4_locator(&mut c)?)
                } else {
                    None
                };
                Submessage::InfoReplyIp4(InfoReplyIp4 { unicast, multicast })
            }
            id::DATA => Submessage::Data(decode_data(flags, c)?),
            id::DATA_FRAG => Submessage::DataFrag(decode_data_frag(flags, c)?),
            id::HEARTBEAT_FRAG => {
                let reader_id = c.entity_id()?;
                let writer_id = c.entity_id()?;
                let writer_sn = c.sequence_number()?;
                let last_fragment_num = c.u32()?;
                let count = c.i32()?;
                if writer_sn.0 < 1 || last_fragment_num == 0 {
                    return Err(WireError::Invalid("HEARTBEAT_FRAG"));
                }
                Submessage::HeartbeatFrag(HeartbeatFrag {
                    reader_id,
                    writer_id,
                    writer_sn,
                    last_fragment_num,
                    count,
                })
            }
            id::NACK_FRAG => {
                let reader_id = c.entity_id()?;
                let writer_id = c.entity_id()?;
                let writer_sn = c.sequence_number()?;
                let fragment_number_state = c.fragment_number_set()?;
                let count = c.i32()?;
                if writer_sn.0 < 1 {
                    return Err(WireError::Invalid("NACK_FRAG sequence number"));
                }
                Submessage::NackFrag(NackFrag {
                    reader_id,
                    writer_id,
                    writer_sn,
                    fragment_number_state,
                    count,
                })
            }
            _ => Submessage::Unknown {
                id: sid,
                flags,
                body,
            },
        })
    }

    /// The submessage id and the flag bits this submessage is encoded with.
    fn kind_and_flags(&self, little_endian: bool) -> (u8, u8) {
        let e = if little_endian { FLAG_E } else { 0 };
        let (sid, flags) = match self {
            Submessage::Pad => (id::PAD, 0),
            Submessage::AckNack(a) => (
                id::ACKNACK,
                AckNackFlags::FINAL.bits() * u8::from(a.final_flag),
            ),
            Submessage::Heartbeat(h) => {
                let mut f = HeartbeatFlags::empty();
                f.set(HeartbeatFlags::FINAL, h.final_flag);
                f.set(HeartbeatFlags::LIVELINESS, h.liveliness_flag);
                f.set(HeartbeatFlags::GROUP_INFO, h.group_info.is_some());
                (id::HEARTBEAT, f.bits())
            }
            Submessage::Gap(_) => (id::GAP, 0),
            Submessage::InfoTs(t) => (
                id::INFO_TS,
                InfoTsFlags::INVALIDATE.bits() * u8::from(t.is_none()),
            ),
            Submessage::InfoSrc(_) => (id::INFO_SRC, 0),
            Submessage::InfoDst(_) => (id::INFO_DST, 0),
            Submessage::InfoReply(r) => (
                id::INFO_REPLY,
                InfoReplyFlags::MULTICAST.bits() * u8::from(r.multicast.is_some()),
            ),
            Submessage::InfoReplyIp4(r) => (
                id::INFO_REPLY_IP4,
                InfoReplyFlags::MULTICAST.bits() * u8::from(r.multicast.is_some()),
            ),
            Submessage::Data(d) => {
                let mut f = DataFlags::empty();
                f.set(DataFlags::INLINE_QOS, d.inline_qos.is_some());
                if d.payload.is_some() {
                    f |= if d.key_flag {
                        DataFlags::KEY
                    } else {
                        DataFlags::DATA
                    };
                }
                f.set(DataFlags::NON_STANDARD, d.non_standard_flag);
                (id::DATA, f.bits())
            }
            Submessage::DataFrag(d) => {
                let mut f = DataFragFlags::empty();
                f.set(DataFragFlags::INLINE_QOS, d.inline_qos.is_some());
                f.set(DataFragFlags::KEY, d.key_flag);
                f.set(DataFragFlags::NON_STANDARD, d.non_standard_flag);
                (id::DATA_FRAG, f.bits())
            }
            Submessage::HeartbeatFrag(_) => (id::HEARTBEAT_FRAG, 0),
            Submessage::NackFrag(_) => (id::NACK_FRAG, 0),
            Submessage::Unknown { id, flags, .. } => (*id, *flags & !FLAG_E),
        };
        (sid, flags | e)
    }

    /// Appends this submessage (header included) in the given byte order, unpadded. Use [`append`] to add it
    /// to a message that may already hold submessages.
    pub fn encode(&self, out: &mut Vec<u8>, little_endian: bool) {
        let start = out.len();
        let (sid, flags) = self.kind_and_flags(little_endian);
        out.push(sid);
        out.push(flags);
        out.extend_from_slice(&[0, 0]);
        let body_start = out.len();
        let mut p = Put { out, little_endian };
        match self {
            Submessage::Pad => {}
            Submessage::AckNack(a) => {
                p.bytes(&a.reader_id.0);
                p.bytes(&a.writer_id.0);
                p.sequence_number_set(&a.reader_sn_state);
                p.i32(a.count);
            }
            Submessage::Heartbeat(h) => {
                p.bytes(&h.reader_id.0);
                p.bytes(&h.writer_id.0);
                p.sequence_number(h.first_sn);
                p.sequence_number(h.last_sn);
                p.i32(h.count);
                if let Some(g) = &h.group_info {
                    p.sequence_number(g.current_gsn);
                    p.sequence_number(g.first_gsn);
                    p.sequence_number(g.last_gsn);
                    p.bytes(&g.writer_set);
                    p.bytes(&g.secure_writer_set);
                }
            }
            Submessage::Gap(g) => {
                p.bytes(&g.reader_id.0);
                p.bytes(&g.writer_id.0);
                p.sequence_number(g.gap_start);
                p.sequence_number_set(&g.gap_list);
            }
            Submessage::InfoTs(t) => {
                if let Some(t) = t {
                    p.time(*t);
                }
            }
            Submessage::InfoSrc(s) => {
                p.u32(0);
                p.u8(s.version.major);
                p.u8(s.version.minor);
                p.bytes(&s.vendor_id.0);
                p.bytes(&s.guid_prefix.0);
            }
            Submessage::InfoDst(g) => p.bytes(&g.0),
            Submessage::InfoReply(r) => {
                let uc: Vec<Locator> = r.unicast().collect();
                p.u32(uc.len() as u32);
                uc.iter().for_each(|l| p.locator(l));
                if r.multicast.is_some() {
                    let mc: Vec<Locator> = r.multicast().collect();
                    p.u32(mc.len() as u32);
                    mc.iter().for_each(|l| p.locator(l));
                }
            }
            Submessage::InfoReplyIp4(r) => {
                for l in std::iter::once(&r.unicast).chain(r.multicast.as_ref()) {
                    let a = l.ipv4().unwrap_or_default();
                    p.u32(u32::from_be_bytes(a));
                    p.u32(l.port);
                }
            }
            Submessage::Data(d) => {
                p.u16(0);
                p.u16(16);
                p.bytes(&d.reader_id.0);
                p.bytes(&d.writer_id.0);
                p.sequence_number(d.writer_sn);
                if let Some(q) = &d.inline_qos {
                    put_inline_qos(&mut p, q);
                }
                if let Some(b) = d.payload {
                    p.bytes(b);
                }
            }
            Submessage::DataFrag(d) => {
                p.u16(0);
                p.u16(28);
                p.bytes(&d.reader_id.0);
                p.bytes(&d.writer_id.0);
                p.sequence_number(d.writer_sn);
                p.u32(d.fragment_starting_num);
                p.u16(d.fragments_in_submessage);
                p.u16(d.fragment_size);
                p.u32(d.sample_size);
                if let Some(q) = &d.inline_qos {
                    put_inline_qos(&mut p, q);
                }
                p.bytes(d.payload);
            }
            Submessage::HeartbeatFrag(h) => {
                p.bytes(&h.reader_id.0);
                p.bytes(&h.writer_id.0);
                p.sequence_number(h.writer_sn);
                p.u32(h.last_fragment_num);
                p.i32(h.count);
            }
            Submessage::NackFrag(n) => {
                p.bytes(&n.reader_id.0);
                p.bytes(&n.writer_id.0);
                p.sequence_number(n.writer_sn);
                p.fragment_number_set(&n.fragment_number_state);
                p.i32(n.count);
            }
            Submessage::Unknown { body, .. } => p.bytes(body),
        }
        // No trailing padding: the exact length lets a last submessage carry an unpadded payload. Whoever
        // appends another submessage pads first and extends this length ([`append`]).
        // Too long for the field: 0 means "to the end of the message" (valid for a last submessage).
        let len = u16::try_from(out.len() - body_start).unwrap_or(0);
        let b = if little_endian {
            len.to_le_bytes()
        } else {
            len.to_be_bytes()
        };
        out[start + 2..start + 4].copy_from_slice(&b);
    }
}

/// Appends `sub` to a message: first pads the previous submessage (at `last_header`) to a 4-byte boundary and
/// extends its octetsToNextHeader, so every submessage starts aligned (§9.4.1). Updates `last_header`.
pub fn append(
    out: &mut Vec<u8>,
    last_header: &mut Option<usize>,
    sub: &Submessage<'_>,
    little_endian: bool,
) {
    if !out.len().is_multiple_of(4) {
        while !out.len().is_multiple_of(4) {
            out.push(0);
        }
        if let Some(h) = *last_header {
            let le = out[h + 1] & FLAG_E != 0;
            let len = u16::try_from(out.len() - h - 4).unwrap_or(0);
            out[h + 2..h + 4].copy_from_slice(&if le {
                len.to_le_bytes()
            } else {
                len.to_be_bytes()
            });
        }
    }
    *last_header = Some(out.len());
    sub.encode(out, little_endian);
}

/// Re-encodes a parameter list in the target byte order (values copied verbatim when the order matches).
fn put_inline_qos(p: &mut Put<'_>, q: &ParameterList<'_>) {
    if q.little_endian == p.little_endian {
        p.bytes(q.data);
    } else {
        // Only lengths/pids swap; values are opaque here, which is right for KEY_HASH and STATUS_INFO.
        for prm in q.iter() {
            p.u16(prm.id);
            p.u16(prm.value.len() as u16);
            p.bytes(prm.value);
        }
    }
    p.u16(super::parameter::pid::SENTINEL);
    p.u16(0);
}

fn locator_list<'a>(c: &mut Cursor<'a>) -> Result<&'a [u8], WireError> {
    let n = c.u32()? as usize;
    // The length check comes before any use of n, so a huge count costs nothing.
    let bytes = n.checked_mul(24).ok_or(WireError::Truncated)?;
    c.bytes(bytes)
}

fn ip4_locator(c: &mut Cursor<'_>) -> Result<Locator, WireError> {
    let addr = c.u32()?;
    let port = c.u32()?;
    let mut l = Locator::udpv4(addr.to_be_bytes(), 0);
    l.port = port;
    Ok(l)
}

/// Reads extraFlags/octetsToInlineQos and positions at the inline QoS; returns (reader, writer, sn, cursor).
fn data_prefix<'a>(
    c: &mut Cursor<'a>,
    fixed: usize,
) -> Result<(EntityId, EntityId, SequenceNumber), WireError> {
    let _extra_flags = c.u16()?;
    let otiq = c.u16()? as usize;
    let reader_id = c.entity_id()?;
    let writer_id = c.entity_id()?;
    let sn = c.sequence_number()?;
    if sn.0 < 1 {
        return Err(WireError::Invalid("writerSN < 1"));
    }
    // Inline QoS starts octetsToInlineQos bytes after that field (position 4); it may skip unknown fields.
    let skip = (4 + otiq)
        .checked_sub(c.pos())
        .ok_or(WireError::Invalid("octetsToInlineQos"))?;
    let _ = fixed;
    c.skip(skip)?;
    Ok((reader_id, writer_id, sn))
}

fn decode_data<'a>(flags: u8, mut c: Cursor<'a>) -> Result<Data<'a>, WireError> {
    let le = c.little_endian;
    let (reader_id, writer_id, writer_sn) = data_prefix(&mut c, 20)?;
    let f = DataFlags::from_bits_retain(flags);
    let (q, d, k, n) = (
        f.contains(DataFlags::INLINE_QOS),
        f.contains(DataFlags::DATA),
        f.contains(DataFlags::KEY),
        f.contains(DataFlags::NON_STANDARD),
    );
    if d && k {
        return Err(WireError::Invalid("DATA with both D and K"));
    }
    let mut rest = c.rest();
    let inline_qos = if q {
        let (pl, r) = ParameterList::parse(rest, le)?;
        rest = r;
        Some(pl)
    } else {
        None
    };
    let payload = if d || k { Some(rest) } else { None };
    Ok(Data {
        reader_id,
        writer_id,
        writer_sn,
        inline_qos,
        payload,
        key_flag: k,
        non_standard_flag: n,
    })
}

fn decode_data_frag<'a>(flags: u8, mut c: Cursor<'a>) -> Result<DataFrag<'a>, WireError> {
    let le = c.little_endian;
    let start = c;
    let _ = start;
    // The fixed fields after writerSN sit before the inline QoS; read them first, then honour octetsToInlineQos.
    let mut f = c;
    f.skip(20)?;
    let fragment_starting_num = f.u32()?;
    let fragments_in_submessage = f.u16()?;
    let fragment_size = f.u16()?;
    let sample_size = f.u32()?;
    let (reader_id, writer_id, writer_sn) = data_prefix(&mut c, 32)?;
    if c.pos() < 32 {
        return Err(WireError::Invalid("DATA_FRAG octetsToInlineQos"));
    }
    if fragment_starting_num == 0 || fragment_size == 0 || fragments_in_submessage == 0 {
        return Err(WireError::Invalid("DATA_FRAG fragment fields"));
    }
    let first_byte = (fragment_starting_num as u64 - 1) * fragment_size as u64;
    if first_byte >= sample_size as u64 {
        return Err(WireError::Invalid("DATA_FRAG beyond sample"));
    }
    let flags = DataFragFlags::from_bits_retain(flags);
    let mut rest = c.rest();
    let inline_qos = if flags.contains(DataFragFlags::INLINE_QOS) {
        let (pl, r) = ParameterList::parse(rest, le)?;
        rest = r;
        Some(pl)
    } else {
        None
    };
    // The fragments' bytes: fragmentsInSubmessage * fragmentSize, cut at the sample's end; trailing padding dropped.
    let want = (fragments_in_submessage as u64 * fragment_size as u64)
        .min(sample_size as u64 - first_byte) as usize;
    if rest.len() < want {
        return Err(WireError::Truncated);
    }
    Ok(DataFrag {
        reader_id,
        writer_id,
        writer_sn,
        fragment_starting_num,
        fragments_in_submessage,
        fragment_size,
        sample_size,
        inline_qos,
        payload: &rest[..want],
        key_flag: flags.contains(DataFragFlags::KEY),
        non_standard_flag: flags.contains(DataFragFlags::NON_STANDARD),
    })
}
