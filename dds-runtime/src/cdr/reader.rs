//! The decoder's input cursor: bounds, alignment, nested length limits and depth limits.

use super::error::{DecodeError, DecodeErrorKind};
use super::header::{ByteOrder, XcdrVersion};
use super::MAX_DEPTH;

/// Reads XCDR data. Offsets in errors are positions in the slice given to [`CdrReader::new`].
///
/// Invariant: `pos <= end <= data.len()` (`new` starts there, `begin_limit` only narrows `end` to at most the
/// bytes left, `end_limit` restores an enclosing `end`, and every read checks against `end`), so a range that
/// ends at or before `end` is inside `data` and needs no second bounds check.
pub struct CdrReader<'a> {
    data: &'a [u8],
    pos: usize,
    end: usize,
    origin: usize,
    version: XcdrVersion,
    order: ByteOrder,
    max_align: usize,
    key_only: bool,
    depth: u32,
}

/// A saved enclosing limit, restored by [`CdrReader::end_limit`].
#[derive(Debug)]
#[must_use]
pub struct Limit {
    end: usize,
    origin: usize,
}

/// Aligned read of a primitive: the in-bounds path is a few instructions and inlines; errors are built out of
/// line (a `DecodeError` is large, and building it inline kept these readers from inlining). Values of 4 bytes
/// or less align to their size in both versions (the maximum alignment is 4 or 8), so only 8-byte values
/// consult it; and one comparison against `end` is the only bounds check (see [`CdrReader::bytes_at`]).
macro_rules! get {
    ($self:ident, $t:ty, $n:expr, $what:expr) => {{
        let mask = if $n <= 4 {
            $n - 1
        } else {
            $n.min($self.max_align) - 1
        };
        let pad = ($self.pos - $self.origin).wrapping_neg() & mask;
        let start = $self.pos + pad;
        if start + $n > $self.end {
            return Err($self.short_read($n, $what));
        }
        let a: [u8; $n] = $self.bytes_at(start);
        $self.pos = start + $n;
        Ok(match $self.order {
            ByteOrder::BigEndian => <$t>::from_be_bytes(a),
            ByteOrder::LittleEndian => <$t>::from_le_bytes(a),
        })
    }};
}

impl<'a> CdrReader<'a> {
    /// A reader over `data` starting at `start`, which is also the alignment origin.
    pub fn new(
        data: &'a [u8],
        start: usize,
        version: XcdrVersion,
        order: ByteOrder,
        key_only: bool,
    ) -> Self {
        let start = start.min(data.len());
        CdrReader {
            data,
            pos: start,
            end: data.len(),
            origin: start,
            version,
            order,
            max_align: version.max_align(),
            key_only,
            depth: 0,
        }
    }

    /// The XCDR version being read.
    #[inline]
    pub fn version(&self) -> XcdrVersion {
        self.version
    }

    /// Whether this is XCDR2.
    #[inline]
    pub fn is_xcdr2(&self) -> bool {
        self.version == XcdrVersion::Xcdr2
    }

    /// The byte order being read.
    #[inline]
    pub fn order(&self) -> ByteOrder {
        self.order
    }

    /// Whether the payload holds key members only.
    #[inline]
    pub fn key_only(&self) -> bool {
        self.key_only
    }

    /// Current offset.
    #[inline]
    pub fn offset(&self) -> usize {
        self.pos
    }

    /// Bytes left before the current limit.
    #[inline]
    pub fn remaining(&self) -> usize {
        self.end - self.pos
    }

    /// An error at the current offset.
    #[cold]
    pub fn error(&self, expected: &'static str, kind: DecodeErrorKind) -> DecodeError {
        DecodeError::new(self.pos, expected, kind)
    }

    #[cold]
    #[inline(never)]
    fn eof(&self, expected: &'static str, needed: usize) -> DecodeError {
        self.error(
            expected,
            DecodeErrorKind::UnexpectedEof {
                needed,
                available: self.remaining(),
            },
        )
    }

    /// The error of an aligned read of `n` bytes that does not fit (the padding, or the value after it).
    #[cold]
    #[inline(never)]
    fn short_read(&mut self, n: usize, expected: &'static str) -> DecodeError {
        if let Err(e) = self.align(n, expected) {
            return e;
        }
        self.eof(expected, n)
    }

    /// The `N` bytes at `start`; the caller has checked `start + N <= self.end`.
    #[inline(always)]
    fn bytes_at<const N: usize>(&self, start: usize) -> [u8; N] {
        debug_assert!(start + N <= self.end && self.end <= self.data.len());
        // SAFETY: `start + N <= end <= data.len()` (the caller's check and the type's invariant).
        unsafe {
            self.data
                .as_ptr()
                .add(start)
                .cast::<[u8; N]>()
                .read_unaligned()
        }
    }

    /// The `n` bytes at the current offset; the caller has checked `n <= self.remaining()`.
    #[inline(always)]
    fn slice_here(&self, n: usize) -> &'a [u8] {
        debug_assert!(self.pos + n <= self.end && self.end <= self.data.len());
        // SAFETY: `pos + n <= end <= data.len()` (the caller's check and the type's invariant).
        unsafe { self.data.get_unchecked(self.pos..self.pos + n) }
    }

    /// Skips padding to a multiple of `n` (capped at 4 in XCDR2).
    #[inline]
    pub fn align(&mut self, n: usize, expected: &'static str) -> Result<(), DecodeError> {
        let n = n.min(self.max_align);
        let pad = (self.pos - self.origin).wrapping_neg() & (n - 1);
        if pad > self.remaining() {
            return Err(self.eof(expected, pad));
        }
        self.pos += pad;
        Ok(())
    }

    /// Takes `n` raw bytes.
    #[inline]
    pub fn read_bytes(
        &mut self,
        n: usize,
        expected: &'static str,
    ) -> Result<&'a [u8], DecodeError> {
        if n > self.remaining() {
            return Err(self.eof(expected, n));
        }
        let b = self.slice_here(n);
        self.pos += n;
        Ok(b)
    }

    /// Steps back `n` bytes (to re-read a NEXTINT that is also the body's first word).
    #[inline]
    pub(crate) fn rewind(&mut self, n: usize) {
        self.pos -= n;
    }

    /// Skips `n` bytes.
    #[inline]
    pub fn skip(&mut self, n: usize, expected: &'static str) -> Result<(), DecodeError> {
        self.read_bytes(n, expected).map(|_| ())
    }

    /// Reads an octet.
    #[inline]
    pub fn read_u8(&mut self, expected: &'static str) -> Result<u8, DecodeError> {
        if self.pos >= self.end {
            return Err(self.eof(expected, 1));
        }
        let [b] = self.bytes_at::<1>(self.pos);
        self.pos += 1;
        Ok(b)
    }

    /// Reads an aligned 16-bit value.
    #[inline]
    pub fn read_u16(&mut self, expected: &'static str) -> Result<u16, DecodeError> {
        get!(self, u16, 2, expected)
    }

    /// Reads an aligned 32-bit value.
    #[inline]
    pub fn read_u32(&mut self, expected: &'static str) -> Result<u32, DecodeError> {
        get!(self, u32, 4, expected)
    }

    /// Reads an aligned 64-bit value.
    #[inline]
    pub fn read_u64(&mut self, expected: &'static str) -> Result<u64, DecodeError> {
        get!(self, u64, 8, expected)
    }

    /// Reads a u32 element count and checks that `count * min_elem_size` bytes can still follow, so a hostile
    /// length fails before anything is allocated.
    #[inline]
    pub fn read_count(
        &mut self,
        min_elem_size: usize,
        expected: &'static str,
    ) -> Result<usize, DecodeError> {
        let at = self.pos;
        let n = self.read_u32(expected)? as usize;
        let need = n.saturating_mul(min_elem_size.max(1));
        if need > self.remaining() {
            return Err(self.count_too_large(at, n, expected));
        }
        Ok(n)
    }

    /// The error of [`read_count`](Self::read_count): `n` elements (read at `at`) cannot follow.
    #[cold]
    #[inline(never)]
    fn count_too_large(&self, at: usize, n: usize, expected: &'static str) -> DecodeError {
        DecodeError::new(
            at,
            expected,
            DecodeErrorKind::LengthTooLarge {
                length: n as u64,
                remaining: self.remaining(),
            },
        )
    }

    /// Restricts reading to the next `len` bytes (a DHEADER, EMHEADER or parameter body).
    pub fn begin_limit(
        &mut self,
        len: usize,
        expected: &'static str,
    ) -> Result<Limit, DecodeError> {
        if len > self.remaining() {
            return Err(self.error(
                expected,
                DecodeErrorKind::LengthTooLarge {
                    length: len as u64,
                    remaining: self.remaining(),
                },
            ));
        }
        let saved = Limit {
            end: self.end,
            origin: self.origin,
        };
        self.end = self.pos + len;
        Ok(saved)
    }

    /// Like [`begin_limit`](Self::begin_limit), and the body is its own alignment origin (XCDR1 parameters).
    pub fn begin_param_limit(
        &mut self,
        len: usize,
        expected: &'static str,
    ) -> Result<Limit, DecodeError> {
        let saved = self.begin_limit(len, expected)?;
        self.origin = self.pos;
        Ok(saved)
    }

    /// Skips whatever is left of the limited region and restores the enclosing limit.
    pub fn end_limit(&mut self, saved: Limit) {
        self.pos = self.end;
        // Clamped: a `Limit` of another, longer reader must not lift `end` past this reader's data.
        self.end = saved.end.min(self.data.len()).max(self.pos);
        self.origin = saved.origin;
    }

    /// Enters one nesting level; fails past [`MAX_DEPTH`].
    #[inline]
    pub fn enter(&mut self, expected: &'static str) -> Result<(), DecodeError> {
        if self.depth >= MAX_DEPTH {
            return Err(self.error(
                expected,
                DecodeErrorKind::DepthExceeded { limit: MAX_DEPTH },
            ));
        }
        self.depth += 1;
        Ok(())
    }

    /// Leaves a nesting level.
    #[inline]
    pub fn leave(&mut self) {
        self.depth = self.depth.saturating_sub(1);
    }

    /// Runs `f` with key-only reading switched on or off, restoring it afterwards.
    pub fn with_key_only<R>(&mut self, key_only: bool, f: impl FnOnce(&mut Self) -> R) -> R {
        let saved = std::mem::replace(&mut self.key_only, key_only);
        let r = f(self);
        self.key_only = saved;
        r
    }
}
