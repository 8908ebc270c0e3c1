//! The body of each submessage kind: read from a cursor (with the checks §9.4.5 asks of a receiver) and
//! written in either byte order. [`Submessage`](super::Submessage) dispatches on the submessage id.

use super::*;

impl AckNack {
    pub(super) fn read(flags: u8, c: &mut Cursor<'_>) -> Result<Self, WireError> {
        Ok(AckNack {
            reader_id: c.entity_id()?,
            writer_id: c.entity_id()?,
            reader_sn_state: c.sequence_number_set()?,
            count: c.i32()?,
            final_flag: AckNackFlags::from_bits_retain(flags).contains(AckNackFlags::FINAL),
        })
    }

    pub(super) fn write(&self, p: &mut Put<'_>) {
        p.bytes(&self.reader_id.0);
        p.bytes(&self.writer_id.0);
        p.sequence_number_set(&self.reader_sn_state);
        p.i32(self.count);
    }
}

impl Heartbeat {
    pub(super) fn read(flags: u8, c: &mut Cursor<'_>) -> Result<Self, WireError> {
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
        Ok(Heartbeat {
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

    pub(super) fn write(&self, p: &mut Put<'_>) {
        p.fixed::<28>(|f| {
            f.bytes(&self.reader_id.0);
            f.bytes(&self.writer_id.0);
            f.sequence_number(self.first_sn);
            f.sequence_number(self.last_sn);
            f.u32(self.count as u32);
        });
        if let Some(g) = &self.group_info {
            p.sequence_number(g.current_gsn);
            p.sequence_number(g.first_gsn);
            p.sequence_number(g.last_gsn);
            p.bytes(&g.writer_set);
            p.bytes(&g.secure_writer_set);
        }
    }
}

impl Gap {
    pub(super) fn read(c: &mut Cursor<'_>) -> Result<Self, WireError> {
        let reader_id = c.entity_id()?;
        let writer_id = c.entity_id()?;
        let gap_start = c.sequence_number()?;
        let gap_list = c.sequence_number_set()?;
        if gap_start.0 < 1 || gap_list.base < gap_start {
            return Err(WireError::Invalid("GAP range"));
        }
        Ok(Gap {
            reader_id,
            writer_id,
            gap_start,
            gap_list,
        })
    }

    pub(super) fn write(&self, p: &mut Put<'_>) {
        p.bytes(&self.reader_id.0);
        p.bytes(&self.writer_id.0);
        p.sequence_number(self.gap_start);
        p.sequence_number_set(&self.gap_list);
    }
}

impl InfoSource {
    pub(super) fn read(c: &mut Cursor<'_>) -> Result<Self, WireError> {
        c.skip(4)?;
        let major = c.u8()?;
        let minor = c.u8()?;
        Ok(InfoSource {
            version: ProtocolVersion { major, minor },
            vendor_id: VendorId(c.array()?),
            guid_prefix: c.guid_prefix()?,
        })
    }

    pub(super) fn write(&self, p: &mut Put<'_>) {
        p.u32(0);
        p.u8(self.version.major);
        p.u8(self.version.minor);
        p.bytes(&self.vendor_id.0);
        p.bytes(&self.guid_prefix.0);
    }
}

/// Whether an INFO_REPLY or INFO_REPLY_IP4 carries multicast locators (flag M).
fn has_multicast(flags: u8) -> bool {
    InfoReplyFlags::from_bits_retain(flags).contains(InfoReplyFlags::MULTICAST)
}

impl<'a> InfoReply<'a> {
    pub(super) fn read(flags: u8, c: &mut Cursor<'a>) -> Result<Self, WireError> {
        let unicast = locator_list(c)?;
        let multicast = if has_multicast(flags) {
            Some(locator_list(c)?)
        } else {
            None
        };
        Ok(InfoReply {
            unicast,
            multicast,
            little_endian: c.little_endian,
        })
    }

    pub(super) fn write(&self, p: &mut Put<'_>) {
        let uc: Vec<Locator> = self.unicast().collect();
        p.u32(uc.len() as u32);
        uc.iter().for_each(|l| p.locator(l));
        if self.multicast.is_some() {
            let mc: Vec<Locator> = self.multicast().collect();
            p.u32(mc.len() as u32);
            mc.iter().for_each(|l| p.locator(l));
        }
    }
}

impl InfoReplyIp4 {
    pub(super) fn read(flags: u8, c: &mut Cursor<'_>) -> Result<Self, WireError> {
        let unicast = ip4_locator(c)?;
        let multicast = if has_multicast(flags) {
            Some(ip4_locator(c)?)
        } else {
            None
        };
        Ok(InfoReplyIp4 { unicast, multicast })
    }

    pub(super) fn write(&self, p: &mut Put<'_>) {
        for l in std::iter::once(&self.unicast).chain(self.multicast.as_ref()) {
            let a = l.ipv4().unwrap_or_default();
            p.u32(u32::from_be_bytes(a));
            p.u32(l.port);
        }
    }
}

impl<'a> Data<'a> {
    pub(super) fn read(flags: u8, c: &mut Cursor<'a>) -> Result<Self, WireError> {
        let le = c.little_endian;
        let (reader_id, writer_id, writer_sn) = data_prefix(c)?;
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

    pub(super) fn write(&self, p: &mut Put<'_>) {
        p.fixed::<20>(|f| {
            f.u16(0);
            f.u16(16);
            f.bytes(&self.reader_id.0);
            f.bytes(&self.writer_id.0);
            f.sequence_number(self.writer_sn);
        });
        if let Some(q) = &self.inline_qos {
            put_inline_qos(p, q);
        }
        if let Some(b) = self.payload {
            p.bytes(b);
        }
    }
}

impl<'a> DataFrag<'a> {
    pub(super) fn read(flags: u8, c: &mut Cursor<'a>) -> Result<Self, WireError> {
        let le = c.little_endian;
        // The fixed fields after writerSN sit before the inline QoS; read them first, then honour
        // octetsToInlineQos.
        let mut f = *c;
        f.skip(20)?;
        let fragment_starting_num = f.u32()?;
        let fragments_in_submessage = f.u16()?;
        let fragment_size = f.u16()?;
        let sample_size = f.u32()?;
        let (reader_id, writer_id, writer_sn) = data_prefix(c)?;
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
        // The fragments' bytes: fragmentsInSubmessage * fragmentSize, cut at the sample's end; trailing
        // padding dropped.
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

    pub(super) fn write(&self, p: &mut Put<'_>) {
        p.u16(0);
        p.u16(28);
        p.bytes(&self.reader_id.0);
        p.bytes(&self.writer_id.0);
        p.sequence_number(self.writer_sn);
        p.u32(self.fragment_starting_num);
        p.u16(self.fragments_in_submessage);
        p.u16(self.fragment_size);
        p.u32(self.sample_size);
        if let Some(q) = &self.inline_qos {
            put_inline_qos(p, q);
        }
        p.bytes(self.payload);
    }
}

impl HeartbeatFrag {
    pub(super) fn read(c: &mut Cursor<'_>) -> Result<Self, WireError> {
        let reader_id = c.entity_id()?;
        let writer_id = c.entity_id()?;
        let writer_sn = c.sequence_number()?;
        let last_fragment_num = c.u32()?;
        let count = c.i32()?;
        if writer_sn.0 < 1 || last_fragment_num == 0 {
            return Err(WireError::Invalid("HEARTBEAT_FRAG"));
        }
        Ok(HeartbeatFrag {
            reader_id,
            writer_id,
            writer_sn,
            last_fragment_num,
            count,
        })
    }

    pub(super) fn write(&self, p: &mut Put<'_>) {
        p.bytes(&self.reader_id.0);
        p.bytes(&self.writer_id.0);
        p.sequence_number(self.writer_sn);
        p.u32(self.last_fragment_num);
        p.i32(self.count);
    }
}

impl NackFrag {
    pub(super) fn read(c: &mut Cursor<'_>) -> Result<Self, WireError> {
        let reader_id = c.entity_id()?;
        let writer_id = c.entity_id()?;
        let writer_sn = c.sequence_number()?;
        let fragment_number_state = c.fragment_number_set()?;
        let count = c.i32()?;
        if writer_sn.0 < 1 {
            return Err(WireError::Invalid("NACK_FRAG sequence number"));
        }
        Ok(NackFrag {
            reader_id,
            writer_id,
            writer_sn,
            fragment_number_state,
            count,
        })
    }

    pub(super) fn write(&self, p: &mut Put<'_>) {
        p.bytes(&self.reader_id.0);
        p.bytes(&self.writer_id.0);
        p.sequence_number(self.writer_sn);
        p.fragment_number_set(&self.fragment_number_state);
        p.i32(self.count);
    }
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
    p.u16(super::super::parameter::pid::SENTINEL);
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

/// Reads extraFlags and octetsToInlineQos, then the reader, writer and sequence number, and positions the
/// cursor at the inline QoS.
fn data_prefix(c: &mut Cursor<'_>) -> Result<(EntityId, EntityId, SequenceNumber), WireError> {
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
    c.skip(skip)?;
    Ok((reader_id, writer_id, sn))
}
