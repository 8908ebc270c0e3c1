//! Bounds-checked reading of fixed-size fields in either byte order.

use super::WireError;
use crate::rtps::types::*;

/// Reads from a borrowed slice; every read checks the length and fails with [`WireError::Truncated`].
#[derive(Clone, Copy, Debug)]
pub struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    pub little_endian: bool,
}

impl<'a> Cursor<'a> {
    pub fn new(data: &'a [u8], little_endian: bool) -> Self {
        Cursor {
            data,
            pos: 0,
            little_endian,
        }
    }
    pub fn pos(&self) -> usize {
        self.pos
    }
    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }
    pub fn rest(&self) -> &'a [u8] {
        &self.data[self.pos..]
    }
    pub fn bytes(&mut self, n: usize) -> Result<&'a [u8], WireError> {
        if self.remaining() < n {
            return Err(WireError::Truncated);
        }
        let s = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    pub fn skip(&mut self, n: usize) -> Result<(), WireError> {
        self.bytes(n).map(|_| ())
    }
    pub fn array<const N: usize>(&mut self) -> Result<[u8; N], WireError> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.bytes(N)?);
        Ok(a)
    }
    /// Skips to the next multiple of `n` (relative to the start of the slice).
    pub fn align(&mut self, n: usize) -> Result<(), WireError> {
        let pad = (n - self.pos % n) % n;
        self.skip(pad)
    }
    pub fn u8(&mut self) -> Result<u8, WireError> {
        Ok(self.bytes(1)?[0])
    }
    pub fn u16(&mut self) -> Result<u16, WireError> {
        let a = self.array::<2>()?;
        Ok(if self.little_endian {
            u16::from_le_bytes(a)
        } else {
            u16::from_be_bytes(a)
        })
    }
    pub fn i16(&mut self) -> Result<i16, WireError> {
        Ok(self.u16()? as i16)
    }
    pub fn u32(&mut self) -> Result<u32, WireError> {
        let a = self.array::<4>()?;
        Ok(if self.little_endian {
            u32::from_le_bytes(a)
        } else {
            u32::from_be_bytes(a)
        })
    }
    pub fn i32(&mut self) -> Result<i32, WireError> {
        Ok(self.u32()? as i32)
    }
    pub fn entity_id(&mut self) -> Result<EntityId, WireError> {
        Ok(EntityId(self.array()?))
    }
    pub fn guid_prefix(&mut self) -> Result<GuidPrefix, WireError> {
        Ok(GuidPrefix(self.array()?))
    }
    pub fn guid(&mut self) -> Result<Guid, WireError> {
        Ok(Guid::from_bytes(self.array()?))
    }
    pub fn sequence_number(&mut self) -> Result<SequenceNumber, WireError> {
        let high = self.i32()?;
        let low = self.u32()?;
        Ok(SequenceNumber::from_parts(high, low))
    }
    pub fn time(&mut self) -> Result<Time, WireError> {
        Ok(Time {
            seconds: self.i32()?,
            fraction: self.u32()?,
        })
    }
    pub fn duration(&mut self) -> Result<std::time::Duration, WireError> {
        let s = self.i32()?;
        let f = self.u32()?;
        Ok(duration_from_wire(s, f))
    }
    pub fn locator(&mut self) -> Result<Locator, WireError> {
        let kind = self.i32()?;
        let port = self.u32()?;
        Ok(Locator {
            kind,
            port,
            address: self.array()?,
        })
    }
    fn number_set_bits(&mut self) -> Result<(u32, [u32; 8]), WireError> {
        let num_bits = self.u32()?;
        if num_bits > 256 {
            return Err(WireError::Invalid("bitmap numBits > 256"));
        }
        let mut bitmap = [0u32; 8];
        for w in bitmap.iter_mut().take(num_bits.div_ceil(32) as usize) {
            *w = self.u32()?;
        }
        // Bits beyond numBits are meaningless; clear them so sets compare equal.
        if num_bits % 32 != 0 {
            let last = (num_bits / 32) as usize;
            bitmap[last] &= !(u32::MAX >> (num_bits % 32));
        }
        Ok((num_bits, bitmap))
    }
    pub fn sequence_number_set(&mut self) -> Result<SequenceNumberSet, WireError> {
        let base = self.sequence_number()?;
        let (num_bits, bitmap) = self.number_set_bits()?;
        Ok(SequenceNumberSet {
            base,
            num_bits,
            bitmap,
        })
    }
    pub fn fragment_number_set(&mut self) -> Result<FragmentNumberSet, WireError> {
        let base = self.u32()?;
        let (num_bits, bitmap) = self.number_set_bits()?;
        Ok(FragmentNumberSet {
            base,
            num_bits,
            bitmap,
        })
    }
    /// A CDR string: u32 length including the NUL, the bytes, the NUL. Returns the bytes without the NUL.
    pub fn string(&mut self) -> Result<&'a str, WireError> {
        let len = self.u32()? as usize;
        if len == 0 {
            return Ok("");
        }
        let b = self.bytes(len)?;
        let b = b.strip_suffix(&[0]).unwrap_or(b);
        std::str::from_utf8(b).map_err(|_| WireError::Invalid("string is not UTF-8"))
    }
    /// A CDR sequence<octet>.
    pub fn octets(&mut self) -> Result<&'a [u8], WireError> {
        let len = self.u32()? as usize;
        self.bytes(len)
    }
}

/// Fixed-size fields in either byte order, gathered on the stack by [`Put::fixed`].
#[derive(Debug)]
pub struct Fixed<const N: usize> {
    buf: [u8; N],
    at: usize,
    little_endian: bool,
}

impl<const N: usize> Fixed<N> {
    pub fn bytes(&mut self, b: &[u8]) {
        self.buf[self.at..self.at + b.len()].copy_from_slice(b);
        self.at += b.len();
    }
    pub fn u16(&mut self, v: u16) {
        self.bytes(&word16(v, self.little_endian));
    }
    pub fn u32(&mut self, v: u32) {
        self.bytes(&word32(v, self.little_endian));
    }
    pub fn sequence_number(&mut self, sn: SequenceNumber) {
        self.u32(sn.high() as u32);
        self.u32(sn.low());
    }
    pub fn time(&mut self, t: Time) {
        self.u32(t.seconds as u32);
        self.u32(t.fraction);
    }
}

/// Appends fixed-size fields in either byte order.
#[derive(Debug)]
pub struct Put<'a> {
    pub out: &'a mut Vec<u8>,
    pub little_endian: bool,
}

fn word16(v: u16, little_endian: bool) -> [u8; 2] {
    if little_endian {
        v.to_le_bytes()
    } else {
        v.to_be_bytes()
    }
}

fn word32(v: u32, little_endian: bool) -> [u8; 4] {
    if little_endian {
        v.to_le_bytes()
    } else {
        v.to_be_bytes()
    }
}

impl Put<'_> {
    pub fn u8(&mut self, v: u8) {
        self.out.push(v);
    }
    pub fn u16(&mut self, v: u16) {
        self.out.extend_from_slice(&word16(v, self.little_endian));
    }
    pub fn u32(&mut self, v: u32) {
        self.out.extend_from_slice(&word32(v, self.little_endian));
    }
    pub fn i32(&mut self, v: i32) {
        self.u32(v as u32)
    }
    pub fn bytes(&mut self, b: &[u8]) {
        self.out.extend_from_slice(b);
    }
    /// Appends the fixed-size fields `f` writes (at most `N` bytes) at once: gathered on the stack, one
    /// growth check of the vector instead of one per field (the per-sample submessages' fixed parts).
    pub fn fixed<const N: usize>(&mut self, f: impl FnOnce(&mut Fixed<N>)) {
        let mut b = Fixed {
            buf: [0; N],
            at: 0,
            little_endian: self.little_endian,
        };
        f(&mut b);
        self.out.extend_from_slice(&b.buf[..b.at]);
    }
    pub fn sequence_number(&mut self, sn: SequenceNumber) {
        self.i32(sn.high());
        self.u32(sn.low());
    }
    pub fn time(&mut self, t: Time) {
        self.i32(t.seconds);
        self.u32(t.fraction);
    }
    pub fn duration(&mut self, d: std::time::Duration) {
        let (s, f) = duration_to_wire(d);
        self.i32(s);
        self.u32(f);
    }
    pub fn locator(&mut self, l: &Locator) {
        self.i32(l.kind);
        self.u32(l.port);
        self.bytes(&l.address);
    }
    pub fn sequence_number_set(&mut self, s: &SequenceNumberSet) {
        self.sequence_number(s.base);
        self.u32(s.num_bits);
        for w in s.words() {
            self.u32(*w);
        }
    }
    pub fn fragment_number_set(&mut self, s: &FragmentNumberSet) {
        self.u32(s.base);
        self.u32(s.num_bits);
        for w in s.words() {
            self.u32(*w);
        }
    }
    /// Pads with zeros to a multiple of `n` measured from `origin`.
    pub fn align_from(&mut self, origin: usize, n: usize) {
        while !(self.out.len() - origin).is_multiple_of(n) {
            self.out.push(0);
        }
    }
}
