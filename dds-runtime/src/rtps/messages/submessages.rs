//! Submessage structures (§9.4.5), decoded by borrowing from the datagram, and their encoders.

use super::cursor::Put;
use super::flags::*;
use super::{id, Cursor, ParameterList, WireError};
use crate::rtps::types::*;

mod body;

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
        let c = &mut Cursor::new(body, flags & FLAG_E != 0);
        Ok(match sid {
            id::PAD => Submessage::Pad,
            id::ACKNACK => Submessage::AckNack(AckNack::read(flags, c)?),
            id::HEARTBEAT => Submessage::Heartbeat(Heartbeat::read(flags, c)?),
            id::GAP => Submessage::Gap(Gap::read(c)?),
            id::INFO_TS => {
                if InfoTsFlags::from_bits_retain(flags).contains(InfoTsFlags::INVALIDATE) {
                    Submessage::InfoTs(None)
                } else {
                    Submessage::InfoTs(Some(c.time()?))
                }
            }
            id::INFO_SRC => Submessage::InfoSrc(InfoSource::read(c)?),
            id::INFO_DST => Submessage::InfoDst(c.guid_prefix()?),
            id::INFO_REPLY => Submessage::InfoReply(InfoReply::read(flags, c)?),
            id::INFO_REPLY_IP4 => Submessage::InfoReplyIp4(InfoReplyIp4::read(flags, c)?),
            id::DATA => Submessage::Data(Data::read(flags, c)?),
            id::DATA_FRAG => Submessage::DataFrag(DataFrag::read(flags, c)?),
            id::HEARTBEAT_FRAG => Submessage::HeartbeatFrag(HeartbeatFrag::read(c)?),
            id::NACK_FRAG => Submessage::NackFrag(NackFrag::read(c)?),
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
        out.extend_from_slice(&[sid, flags, 0, 0]);
        let body_start = out.len();
        let p = &mut Put { out, little_endian };
        match self {
            Submessage::Pad => {}
            Submessage::AckNack(a) => a.write(p),
            Submessage::Heartbeat(h) => h.write(p),
            Submessage::Gap(g) => g.write(p),
            Submessage::InfoTs(t) => {
                if let Some(t) = t {
                    p.fixed::<8>(|f| f.time(*t));
                }
            }
            Submessage::InfoSrc(s) => s.write(p),
            Submessage::InfoDst(g) => p.bytes(&g.0),
            Submessage::InfoReply(r) => r.write(p),
            Submessage::InfoReplyIp4(r) => r.write(p),
            Submessage::Data(d) => d.write(p),
            Submessage::DataFrag(d) => d.write(p),
            Submessage::HeartbeatFrag(h) => h.write(p),
            Submessage::NackFrag(n) => n.write(p),
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
            let len = out.len() - h - 4;
            set_octets_to_next_header(out, h, len);
        }
    }
    *last_header = Some(out.len());
    sub.encode(out, little_endian);
}

/// The octetsToNextHeader of the submessage whose header starts at `h` in `msg`, in the byte order its E
/// flag says.
pub(crate) fn octets_to_next_header(msg: &[u8], h: usize) -> usize {
    let field = [msg[h + 2], msg[h + 3]];
    usize::from(if msg[h + 1] & FLAG_E != 0 {
        u16::from_le_bytes(field)
    } else {
        u16::from_be_bytes(field)
    })
}

/// Sets the octetsToNextHeader of the submessage whose header starts at `h` in `msg` to `len`, in the byte
/// order its E flag says; too long for the field, 0 ("to the end of the message").
pub(crate) fn set_octets_to_next_header(msg: &mut [u8], h: usize, len: usize) {
    let len = u16::try_from(len).unwrap_or(0);
    let b = if msg[h + 1] & FLAG_E != 0 {
        len.to_le_bytes()
    } else {
        len.to_be_bytes()
    };
    msg[h + 2..h + 4].copy_from_slice(&b);
}
