//! The encoder's output stream: alignment, byte order, DHEADER/EMHEADER/parameter headers.

use super::error::EncodeError;
use super::header::{ByteOrder, XcdrVersion};
use super::short::{copy_short, SHORT};
use super::MAX_DEPTH;

/// Byte runs at least this long are placed ([`CdrWriter::placing`]); shorter ones are not worth a gap.
#[cfg(any(test, feature = "shm"))]
pub(crate) const PLACE_MIN: usize = 4096;

/// Where an encoder puts long byte runs ([`CdrWriter::placing`]; `cdr::placement`).
#[cfg(any(test, feature = "shm"))]
pub(crate) trait PlaceRuns {
    /// Copies `bytes`, which come in the stream right before byte `at` of the encoder's buffer (after the
    /// runs placed before), to their place; false (nothing copied) when they do not fit.
    fn place(&mut self, at: usize, bytes: &[u8]) -> bool;
}

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
    /// Where long byte runs go instead of `buf` (`cdr::placement`: a shared-memory frame), if anywhere.
    /// Only with feature `shm` (the small-sample encoder keeps its size and instructions without it).
    #[cfg(any(test, feature = "shm"))]
    place: Option<&'a mut (dyn PlaceRuns + 'a)>,
    /// Bytes placed there so far: the stream's position is `buf`'s length plus these (`origin` is lowered
    /// by each run, so that [`position`](CdrWriter::position) needs no addition).
    #[cfg(any(test, feature = "shm"))]
    placed: usize,
}

/// A DHEADER or NEXTINT placeholder to patch once the body is written.
#[derive(Debug)]
#[must_use]
pub struct LengthSlot {
    at: usize,
    #[cfg(any(test, feature = "shm"))]
    placed: usize,
}

/// An XCDR1 parameter header (PID_EXTENDED form) whose length is patched at the end of the member.
#[derive(Debug)]
#[must_use]
pub struct ParamSlot {
    len_at: usize,
    body: usize,
    saved_origin: usize,
    #[cfg(any(test, feature = "shm"))]
    placed: usize,
}

/// An aligned primitive: its padding and its bytes in the writer's byte order, in one append
/// ([`CdrWriter::put_padded`]).
macro_rules! put {
    ($self:ident, $v:expr) => {{
        let v = $v;
        let bytes = match $self.order {
            ByteOrder::BigEndian => v.to_be_bytes(),
            ByteOrder::LittleEndian => v.to_le_bytes(),
        };
        let pad = $self.padding(bytes.len());
        $self.put_padded(pad, bytes);
    }};
}

/// The error for a string holding a NUL (out of line: never the hot path).
#[cold]
#[inline(never)]
fn nul_in_string(text: &[u8]) -> EncodeError {
    EncodeError::InvalidValue {
        what: "NUL inside a string",
        value: text.iter().position(|&b| b == 0).unwrap_or(0) as u64,
    }
}

/// Appends `pad` (< 8) zero bytes to `buf` with one capacity check and two plain stores: a slice copy of a
/// run-time length, or `resize`, would call `memcpy`/`memset`, which costs more than the bytes themselves.
#[inline(always)]
pub(crate) fn push_zeros(buf: &mut Vec<u8>, pad: usize) {
    debug_assert!(pad < 8);
    buf.reserve(8);
    let len = buf.len();
    // SAFETY: `reserve` made room for 8 bytes after `len`, and `pad < 8`: the store stays within the
    // capacity, and every byte below the new length has been written.
    unsafe {
        buf.as_mut_ptr()
            .add(len)
            .cast::<[u8; 8]>()
            .write_unaligned([0; 8]);
        buf.set_len(len + (pad & 7));
    }
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
            #[cfg(any(test, feature = "shm"))]
            place: None,
            #[cfg(any(test, feature = "shm"))]
            placed: 0,
        }
    }

    /// [`new`](Self::new), with byte runs of at least [`PLACE_MIN`] bytes copied to `place` rather than
    /// appended to `buf` (when it takes them).
    #[cfg(any(test, feature = "shm"))]
    pub(crate) fn placing(
        buf: &'a mut Vec<u8>,
        version: XcdrVersion,
        order: ByteOrder,
        place: &'a mut (dyn PlaceRuns + 'a),
    ) -> Self {
        let mut w = Self::new(buf, version, order, EncodeMode::Sample);
        w.place = Some(place);
        w
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
        // `origin` went down by every placed run (and may have wrapped).
        self.buf.len().wrapping_sub(self.origin)
    }

    /// Total bytes in the underlying buffer.
    #[inline]
    pub fn buffer_len(&self) -> usize {
        self.buf.len()
    }

    /// Pads with zeros to a multiple of `n` (a power of two; capped at 4 in XCDR2).
    #[inline]
    pub fn align(&mut self, n: usize) {
        let pad = self.padding(n);
        if pad != 0 {
            push_zeros(self.buf, pad);
        }
    }

    /// The padding before a value aligned to `n` (a power of two, capped at the version's maximum).
    #[inline(always)]
    fn padding(&self, n: usize) -> usize {
        // Every version aligns up to 4 bytes: only 8-byte values depend on it (a constant `n` folds).
        let n = if n <= 4 { n } else { n.min(self.max_align) };
        self.position().wrapping_neg() & (n - 1)
    }

    /// Appends `pad` (< 8) zero bytes and then `bytes`, with one capacity check and no libc call.
    #[inline(always)]
    fn put_padded<const N: usize>(&mut self, pad: usize, bytes: [u8; N]) {
        debug_assert!(pad < 8);
        let pad = pad & 7;
        self.buf.reserve(8 + N);
        let len = self.buf.len();
        // SAFETY: `reserve` made room for 8 + N bytes after `len`; with `pad < 8` both stores stay within
        // the capacity, and every byte below the new length (len + pad + N) has been written.
        unsafe {
            let p = self.buf.as_mut_ptr().add(len);
            p.cast::<[u8; 8]>().write_unaligned([0; 8]);
            p.add(pad).cast::<[u8; N]>().write_unaligned(bytes);
            self.buf.set_len(len + pad + N);
        }
    }

    /// Writes a string body: the aligned length (with the NUL), the characters and the NUL. Fails when
    /// `text` holds a NUL (nothing is appended then). Strings of up to 16 bytes take one capacity check and
    /// a few word stores, with the NUL check on the same words; longer ones use `memchr` and `memcpy`.
    #[inline(always)]
    pub fn write_string(&mut self, text: &[u8]) -> Result<(), EncodeError> {
        let n = text.len();
        if n > SHORT {
            return self.write_long_string(text);
        }
        let len = match self.order {
            ByteOrder::BigEndian => (n as u32 + 1).to_be_bytes(),
            ByteOrder::LittleEndian => (n as u32 + 1).to_le_bytes(),
        };
        let pad = self.padding(4) & 3;
        self.buf.reserve(8 + 4 + SHORT + 1);
        let at = self.buf.len();
        // SAFETY: `reserve` made room for 8 + 4 + SHORT + 1 bytes after `at`: the zero word (8 bytes), the
        // length at `pad` < 4, `n` <= SHORT characters after it and the NUL all stay within the capacity. The
        // length is only raised (to cover exactly what was written) when no NUL was found.
        unsafe {
            let p = self.buf.as_mut_ptr().add(at);
            p.cast::<[u8; 8]>().write_unaligned([0; 8]);
            p.add(pad).cast::<[u8; 4]>().write_unaligned(len);
            if copy_short(text, p.add(pad + 4)) {
                return Err(nul_in_string(text));
            }
            p.add(pad + 4 + n).write(0);
            self.buf.set_len(at + pad + 4 + n + 1);
        }
        Ok(())
    }

    /// [`write_string`](Self::write_string) for strings longer than [`SHORT`]: `memchr` and `memcpy`.
    #[inline(never)]
    fn write_long_string(&mut self, text: &[u8]) -> Result<(), EncodeError> {
        if text.contains(&0) {
            return Err(nul_in_string(text));
        }
        let n = text.len();
        let len = u32::try_from(n + 1).map_err(|_| EncodeError::TooLarge {
            what: "string length",
            len: n as u64 + 1,
        })?;
        self.write_u32(len);
        self.buf.reserve(n + 1);
        self.buf.extend_from_slice(text);
        self.buf.push(0);
        Ok(())
    }

    /// Appends raw bytes (no alignment). Up to 16 bytes are copied with word stores (no `memcpy` call).
    #[inline]
    pub fn write_bytes(&mut self, bytes: &[u8]) {
        let n = bytes.len();
        if n > SHORT {
            #[cfg(any(test, feature = "shm"))]
            if n >= PLACE_MIN && self.try_place(bytes) {
                return;
            }
            self.buf.extend_from_slice(bytes);
            return;
        }
        self.buf.reserve(SHORT);
        let at = self.buf.len();
        // SAFETY: `reserve` made room for SHORT >= n bytes after `at`; all n are written before the length
        // covers them.
        unsafe {
            copy_short(bytes, self.buf.as_mut_ptr().add(at));
            self.buf.set_len(at + n);
        }
    }

    /// Copies a long run to the placement, if there is one and it takes it.
    #[cfg(any(test, feature = "shm"))]
    #[cold]
    #[inline(never)]
    fn try_place(&mut self, bytes: &[u8]) -> bool {
        let at = self.buf.len();
        if !self
            .place
            .as_deref_mut()
            .is_some_and(|p| p.place(at, bytes))
        {
            return false;
        }
        self.placed += bytes.len();
        self.origin = self.origin.wrapping_sub(bytes.len());
        true
    }

    /// Writes an octet.
    #[inline]
    pub fn write_u8(&mut self, v: u8) {
        self.buf.push(v);
    }

    /// Writes an aligned 16-bit value (its padding included).
    #[inline]
    pub fn write_u16(&mut self, v: u16) {
        put!(self, v);
    }

    /// Writes an aligned 32-bit value.
    #[inline]
    pub fn write_u32(&mut self, v: u32) {
        put!(self, v);
    }

    /// Writes an aligned 64-bit value.
    #[inline]
    pub fn write_u64(&mut self, v: u64) {
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
        LengthSlot {
            at,
            #[cfg(any(test, feature = "shm"))]
            placed: self.placed,
        }
    }

    /// Patches `slot` with the number of bytes written since it.
    #[inline]
    pub fn end_length(&mut self, slot: LengthSlot) -> Result<(), EncodeError> {
        let len = self.buf.len() - slot.at - 4;
        #[cfg(any(test, feature = "shm"))]
        let len = len + (self.placed - slot.placed);
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
            #[cfg(any(test, feature = "shm"))]
            placed: self.placed,
        })
    }

    /// Ends a parameter: pads the body to 4 and patches its length.
    pub fn end_param(&mut self, slot: ParamSlot) -> Result<(), EncodeError> {
        self.align(4);
        self.origin = slot.saved_origin;
        let len = self.buf.len() - slot.body;
        // Runs placed inside the parameter moved the origin, and count in its length.
        #[cfg(any(test, feature = "shm"))]
        let len = {
            let placed = self.placed - slot.placed;
            self.origin = self.origin.wrapping_sub(placed);
            len + placed
        };
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every length around the short/long boundary, a NUL at every position of each: an error and nothing
    /// appended; without a NUL the exact bytes (length, characters, NUL) after the padding.
    #[test]
    fn strings_of_every_short_length_and_nul_position() {
        for order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
            for prefix in 0..4usize {
                for n in 0..=40usize {
                    let text: Vec<u8> = (0..n).map(|i| b'a' + (i % 26) as u8).collect();
                    let mut buf = vec![7u8; prefix];
                    let mut w =
                        CdrWriter::new(&mut buf, XcdrVersion::Xcdr1, order, EncodeMode::Sample);
                    w.write_u8(1);
                    w.write_string(&text).unwrap();
                    let len = (n as u32 + 1).to_le_bytes();
                    let len = match order {
                        ByteOrder::LittleEndian => len,
                        ByteOrder::BigEndian => (n as u32 + 1).to_be_bytes(),
                    };
                    let mut want = vec![7u8; prefix];
                    want.extend_from_slice(&[1, 0, 0, 0]);
                    want.extend_from_slice(&len);
                    want.extend_from_slice(&text);
                    want.push(0);
                    assert_eq!(buf, want, "n {n}, prefix {prefix}");
                    for at in 0..n {
                        let mut bad = text.clone();
                        bad[at] = 0;
                        let mut buf = vec![7u8; prefix];
                        let mut w =
                            CdrWriter::new(&mut buf, XcdrVersion::Xcdr1, order, EncodeMode::Sample);
                        assert_eq!(
                            w.write_string(&bad),
                            Err(EncodeError::InvalidValue {
                                what: "NUL inside a string",
                                value: at as u64
                            })
                        );
                        assert_eq!(buf, vec![7u8; prefix], "nothing appended on error");
                    }
                }
            }
        }
    }

    #[test]
    fn short_byte_runs_are_copied_exactly() {
        for n in 0..=40usize {
            let bytes: Vec<u8> = (0..n as u8).collect();
            let mut buf = vec![9u8];
            let mut w = CdrWriter::new(
                &mut buf,
                XcdrVersion::Xcdr2,
                ByteOrder::LittleEndian,
                EncodeMode::Sample,
            );
            w.write_bytes(&bytes);
            assert_eq!(buf[0], 9);
            assert_eq!(&buf[1..], &bytes[..]);
        }
    }
}
