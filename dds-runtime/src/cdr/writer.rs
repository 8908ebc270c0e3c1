//! The encoder's output stream: alignment, byte order, DHEADER/EMHEADER/parameter headers.

use super::error::EncodeError;
use super::header::{ByteOrder, XcdrVersion};
use super::MAX_DEPTH;

/// What is being encoded: a full sample, a key-only sample, or the key-hash stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EncodeMode {
    /// Every member.
    Sample,
    /// Key members only, in declaration order (the serialized key).
    Key,
    /// Key members only, as hashed: member-id order, no DHEADER/EMHEADER/parameter headers.
    KeyHash,
}

/// Writes XCDR data after an encapsulation header into a caller-owned `Vec` (no allocation when it has capacity).
pub struct CdrWriter<'a> {
    buf: &'a mut Vec<u8>,
    origin: usize,
    version: XcdrVersion,
    order: ByteOrder,
    max_align: usize,
    mode: EncodeMode,
    depth: u32,
}

/// A DHEADER or NEXTINT placeholder to patch once the body is written.
#[derive(Debug)]
#[must_use]
pub struct LengthSlot {
    at: usize,
}

/// An XCDR1 parameter header (PID_EXTENDED form) whose length is patched at the end of the member.
#[derive(Debug)]
#[must_use]
pub struct ParamSlot {
    len_at: usize,
    body: usize,
    saved_origin: usize,
}

macro_rules! put {
    ($self:ident, $v:expr) => {{
        let v = $v;
        match $self.order {
            ByteOrder::BigEndian => $self.buf.extend_from_slice(&v.to_be_bytes()),
            ByteOrder::LittleEndian => $self.buf.extend_from_slice(&v.to_le_bytes()),
        }
    }};
}

impl<'a> CdrWriter<'a> {
    /// A writer whose alignment origin is the current end of `buf`.
    pub fn new(
        buf: &'a mut Vec<u8>,
        version: XcdrVersion,
        order: ByteOrder,
        mode: EncodeMode,
    ) -> Self {
        let origin = buf.len();
        CdrWriter {
            buf,
            origin,
            version,
            order,
            max_align: version.max_align(),
            mode,
            depth: 0,
        }
    }

    /// The XCDR version being written.
    #[inline]
    pub fn version(&self) -> XcdrVersion {
        self.version
    }

    /// Whether this is XCDR2.
    #[inline]
    pub fn is_xcdr2(&self) -> bool {
        self.version == XcdrVersion::Xcdr2
    }

    /// The byte order being written.
    #[inline]
    pub fn order(&self) -> ByteOrder {
        self.order
    }

    /// Full sample, key, or key-hash stream.
    #[inline]
    pub fn mode(&self) -> EncodeMode {
        self.mode
    }

    /// Whether only key members are written.
    #[inline]
    pub fn key_only(&self) -> bool {
        self.mode != EncodeMode::Sample
    }

    /// Bytes written since the alignment origin.
    #[inline]
    pub fn position(&self) -> usize {
        self.buf.len() - self.origin
    }

    /// Total bytes in the underlying buffer.
    #[inline]
    pub fn buffer_len(&self) -> usize {
        self.buf.len()
    }

    /// Pads with zeros to a multiple of `n` (a power of two; capped at 4 in XCDR2).
    #[inline]
    pub fn align(&mut self, n: usize) {
        let n = n.min(self.max_align);
        let pad = self.position().wrapping_neg() & (n - 1);
        if pad != 0 {
            // A slice copy of at most 7 bytes compiles to plain stores; `resize` calls memset.
            self.buf.extend_from_slice(&[0u8; 8][..pad]);
        }
    }

    /// Appends raw bytes (no alignment).
    #[inline]
    pub fn write_bytes(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    /// Writes an octet.
    #[inline]
    pub fn write_u8(&mut self, v: u8) {
        self.buf.push(v);
    }

    /// Writes an aligned 16-bit value.
    #[inline]
    pub fn write_u16(&mut self, v: u16) {
        self.align(2);
        put!(self, v);
    }

    /// Writes an aligned 32-bit value.
    #[inline]
    pub fn write_u32(&mut self, v: u32) {
        self.align(4);
        put!(self, v);
    }

    /// Writes an aligned 64-bit value.
    #[inline]
    pub fn write_u64(&mut self, v: u64) {
        self.align(8);
        put!(self, v);
    }

    /// Writes a u32 length, failing if it does not fit.
    #[inline]
    pub fn write_len(&mut self, len: usize, what: &'static str) -> Result<(), EncodeError> {
        let v = u32::try_from(len).map_err(|_| EncodeError::TooLarge {
            what,
            len: len as u64,
        })?;
        self.write_u32(v);
        Ok(())
    }

    /// Reserves a 4-aligned u32 to hold the byte length of what follows (DHEADER, NEXTINT).
    #[inline]
    pub fn begin_length(&mut self) -> LengthSlot {
        self.align(4);
        let at = self.buf.len();
        self.buf.extend_from_slice(&[0; 4]);
        LengthSlot { at }
    }

    /// Patches `slot` with the number of bytes written since it.
    #[inline]
    pub fn end_length(&mut self, slot: LengthSlot) -> Result<(), EncodeError> {
        let len = self.buf.len() - slot.at - 4;
        let v = u32::try_from(len).map_err(|_| EncodeError::TooLarge {
            what: "DHEADER",
            len: len as u64,
        })?;
        let bytes = match self.order {
            ByteOrder::BigEndian => v.to_be_bytes(),
            ByteOrder::LittleEndian => v.to_le_bytes(),
        };
        self.buf[slot.at..slot.at + 4].copy_from_slice(&bytes);
        Ok(())
    }

    /// Writes an XCDR2 EMHEADER with length code `lc`; for LC 4 it also reserves NEXTINT, returned as a slot.
    pub fn write_emheader(
        &mut self,
        id: u32,
        must_understand: bool,
        lc: u8,
    ) -> Result<Option<LengthSlot>, EncodeError> {
        if id > 0x0fff_ffff {
            return Err(EncodeError::TooLarge {
                what: "member id",
                len: u64::from(id),
            });
        }
        let mut h = id | (u32::from(lc) << 28);
        if must_understand {
            h |= 0x8000_0000;
        }
        self.write_u32(h);
        Ok(if lc == 4 {
            Some(self.begin_length())
        } else {
            None
        })
    }

    /// Starts an XCDR1 parameter (PID_EXTENDED form, as Cyclone writes it). The member body's alignment origin
    /// is its first byte.
    pub fn begin_param(
        &mut self,
        id: u32,
        must_understand: bool,
    ) -> Result<ParamSlot, EncodeError> {
        if id > 0x0fff_ffff {
            return Err(EncodeError::TooLarge {
                what: "member id",
                len: u64::from(id),
            });
        }
        self.align(4);
        // PID_EXTENDED always carries the must-understand bit; the member's own flag rides in the id word.
        // The 12 header bytes (the length patched later) are known up front: build them once and append them in one copy.
        let pid = super::PID_EXTENDED | 0x4000;
        let word = id | if must_understand { 0x4000_0000 } else { 0 };
        let mut h = [0u8; 12];
        match self.order {
            ByteOrder::BigEndian => {
                h[0..2].copy_from_slice(&pid.to_be_bytes());
                h[2..4].copy_from_slice(&8u16.to_be_bytes());
                h[4..8].copy_from_slice(&word.to_be_bytes());
            }
            ByteOrder::LittleEndian => {
                h[0..2].copy_from_slice(&pid.to_le_bytes());
                h[2..4].copy_from_slice(&8u16.to_le_bytes());
                h[4..8].copy_from_slice(&word.to_le_bytes());
            }
        }
        self.buf.extend_from_slice(&h);
        let len_at = self.buf.len() - 4;
        let body = self.buf.len();
        let saved_origin = std::mem::replace(&mut self.origin, body);
        Ok(ParamSlot {
            len_at,
            body,
            saved_origin,
        })
    }

    /// Ends a parameter: pads the body to 4 and patches its length.
    pub fn end_param(&mut self, slot: ParamSlot) -> Result<(), EncodeError> {
        self.align(4);
        self.origin = slot.saved_origin;
        let len = self.buf.len() - slot.body;
        let v = u32::try_from(len).map_err(|_| EncodeError::TooLarge {
            what: "parameter",
            len: len as u64,
        })?;
        let bytes = match self.order {
            ByteOrder::BigEndian => v.to_be_bytes(),
            ByteOrder::LittleEndian => v.to_le_bytes(),
        };
        self.buf[slot.len_at..slot.len_at + 4].copy_from_slice(&bytes);
        Ok(())
    }

    /// Writes PID_LIST_END, closing an XCDR1 parameter list (with the must-understand bit, as Cyclone does).
    pub fn write_list_end(&mut self) {
        self.align(4);
        self.write_u16(super::PID_LIST_END | 0x4000);
        self.write_u16(0);
    }

    /// Enters one nesting level (structs, unions, collections of them).
    #[inline]
    pub fn enter(&mut self) -> Result<(), EncodeError> {
        if self.depth >= MAX_DEPTH {
            return Err(EncodeError::DepthExceeded { limit: MAX_DEPTH });
        }
        self.depth += 1;
        Ok(())
    }

    /// Leaves a nesting level.
    #[inline]
    pub fn leave(&mut self) {
        self.depth = self.depth.saturating_sub(1);
    }

    /// Runs `f` with a different mode (a nested type's own key members, say), restoring it afterwards.
    pub fn with_mode<R>(&mut self, mode: EncodeMode, f: impl FnOnce(&mut Self) -> R) -> R {
        let saved = std::mem::replace(&mut self.mode, mode);
        let r = f(self);
        self.mode = saved;
        r
    }
}
