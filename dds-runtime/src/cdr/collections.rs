//! `CdrType` for strings, sequences (`Vec`), arrays, maps and `Box`.

use std::collections::BTreeMap;

use super::error::{DecodeError, DecodeErrorKind, EncodeError};
use super::header::XcdrVersion;
use super::reader::{CdrReader, Limit};
use super::short;
use super::traits::{CdrType, Layout};
use super::writer::CdrWriter;

/// Stops key-size scans of recursive types: past this the key is hashed anyway.
const KEY_SCAN_LIMIT: usize = 64;

#[inline]
const fn align4(p: usize) -> usize {
    (p + 3) & !3
}

#[inline(always)]
fn check_bound(what: &'static str, len: usize, bound: usize) -> Result<(), EncodeError> {
    if len > bound {
        Err(EncodeError::BoundExceeded { what, bound, len })
    } else {
        Ok(())
    }
}

#[cold]
#[inline(never)]
fn bound_error(
    r: &CdrReader<'_>,
    at: usize,
    expected: &'static str,
    len: usize,
    bound: usize,
) -> DecodeError {
    let _ = r;
    DecodeError::new(at, expected, DecodeErrorKind::BoundExceeded { bound, len })
}

/// Encodes a string body (length with NUL, bytes, NUL); shared by `String` and `BoundedString`.
#[inline]
pub(crate) fn encode_str(s: &str, w: &mut CdrWriter<'_>, bound: usize) -> Result<(), EncodeError> {
    check_bound("string", s.len(), bound)?;
    // The writer checks for a NUL inside (on the words it copies, for short strings).
    w.write_string(s.as_bytes())
}

/// Decodes a string body with one allocation, of exactly its length.
#[inline(always)]
pub(crate) fn decode_str(r: &mut CdrReader<'_>, bound: usize) -> Result<String, DecodeError> {
    let body = str_body(r, bound)?;
    let mut v = Vec::with_capacity(body.text.len());
    body.copy_to(&mut v)?;
    // SAFETY: `copy_to` checked that the bytes are UTF-8.
    Ok(unsafe { String::from_utf8_unchecked(v) })
}

/// Decodes a string body into `s`, reusing its buffer. On error `s` is empty.
#[inline]
pub(crate) fn decode_str_in_place(
    s: &mut String,
    r: &mut CdrReader<'_>,
    bound: usize,
) -> Result<(), DecodeError> {
    let body = str_body(r, bound)?;
    // SAFETY: `copy_to` leaves the vector empty or holding checked UTF-8.
    let v = unsafe { s.as_mut_vec() };
    v.clear();
    v.reserve(body.text.len());
    body.copy_to(v)
}

/// A string body's characters, its terminator and where they are, not yet checked for NULs or UTF-8.
struct StrBody<'a> {
    text: &'a [u8],
    nul: u8,
    at: usize,
}

impl StrBody<'_> {
    /// Appends the characters to `v` (empty, with room for them) and checks them: no NUL inside, a NUL after,
    /// UTF-8. A short ASCII string is copied and checked on the same few words; anything else takes
    /// [`str_checked`]. On error `v` stays empty.
    #[inline(always)]
    fn copy_to(&self, v: &mut Vec<u8>) -> Result<(), DecodeError> {
        let n = self.text.len();
        debug_assert!(v.is_empty() && v.capacity() >= n);
        let dst = v.as_mut_ptr();
        // SAFETY: `v` has room for `n` bytes and does not overlap the input.
        let ascii = n <= short::SHORT && unsafe { short::copy_short_ascii(self.text, dst) };
        if !(ascii && self.nul == 0) {
            str_checked(self.text, self.nul, self.at)?;
            if n > short::SHORT {
                // SAFETY: as above.
                unsafe { short::copy_bytes(self.text, dst) };
            }
        }
        // SAFETY: all `n` bytes were written above, and they are checked UTF-8.
        unsafe { v.set_len(n) };
        Ok(())
    }
}

/// Reads a string body's length (checked against `bound` and the input) and takes its bytes. Inlined: the
/// common short string is a few instructions here.
#[inline(always)]
fn str_body<'a>(r: &mut CdrReader<'a>, bound: usize) -> Result<StrBody<'a>, DecodeError> {
    let at = r.offset();
    let n = r.read_count(1, "string length")?;
    if n == 0 {
        // Some implementations send an empty string as length 0.
        return Ok(StrBody {
            text: &[],
            nul: 0,
            at,
        });
    }
    if n - 1 > bound {
        return Err(bound_error(r, at, "string within its bound", n - 1, bound));
    }
    let at = r.offset();
    let bytes = r.read_bytes(n, "string characters")?;
    let (text, nul) = bytes.split_at(n - 1);
    Ok(StrBody {
        text,
        nul: nul[0],
        at,
    })
}

/// The full checks of a string's characters `text` (at `at`) and its terminator `nul`: out of line, for
/// strings longer than 16 bytes, non-ASCII ones and invalid input.
#[inline(never)]
fn str_checked(text: &[u8], nul: u8, at: usize) -> Result<(), DecodeError> {
    if nul != 0 || text.contains(&0) {
        return Err(DecodeError::new(
            at,
            "NUL-terminated string",
            DecodeErrorKind::MalformedString,
        ));
    }
    match std::str::from_utf8(text) {
        Ok(_) => Ok(()),
        Err(e) => Err(DecodeError::new(
            at + e.valid_up_to(),
            "UTF-8 string",
            DecodeErrorKind::MalformedString,
        )),
    }
}

pub(crate) fn string_key_max_end(start: usize, bound: Option<usize>) -> Option<usize> {
    bound.map(|b| align4(start) + 4 + b + 1)
}

impl CdrType for String {
    const LAYOUT: Layout = Layout::String;
    const MIN_SIZE: usize = 4;

    #[inline]
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        encode_str(self, w, usize::MAX)
    }

    #[inline]
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        decode_str(r, usize::MAX)
    }

    fn default_value() -> Self {
        String::new()
    }

    #[inline]
    fn encode_bounded(&self, w: &mut CdrWriter<'_>, bound: usize) -> Result<(), EncodeError> {
        encode_str(self, w, bound)
    }

    #[inline]
    fn decode_bounded(r: &mut CdrReader<'_>, bound: usize) -> Result<Self, DecodeError> {
        decode_str(r, bound)
    }

    #[inline]
    fn decode_in_place(&mut self, r: &mut CdrReader<'_>, bound: usize) -> Result<(), DecodeError> {
        decode_str_in_place(self, r, bound)
    }

    fn key_max_end(start: usize, _version: XcdrVersion, bound: Option<usize>) -> Option<usize> {
        string_key_max_end(start, bound)
    }
}

/// Encodes a sequence body; shared by `Vec` and `BoundedSeq`.
#[inline]
pub(crate) fn encode_seq<T: CdrType>(
    items: &[T],
    w: &mut CdrWriter<'_>,
    bound: usize,
) -> Result<(), EncodeError> {
    check_bound("sequence", items.len(), bound)?;
    if !T::LAYOUT.is_primitive() && w.is_xcdr2() {
        w.enter()?;
        let slot = w.begin_length();
        w.write_len(items.len(), "sequence length")?;
        T::encode_slice(items, w)?;
        w.leave();
        w.end_length(slot)
    } else {
        w.write_len(items.len(), "sequence length")?;
        T::encode_slice(items, w)
    }
}

/// Capacity to reserve for `n` elements: never more memory than a small multiple of the input left. When an
/// element takes no more bytes in memory than its minimum on the wire (the numeric primitives), `n` itself is
/// within it: `seq_header` checked that `n * MIN_SIZE` bytes follow.
#[inline(always)]
fn capacity_for<T: CdrType>(n: usize, remaining: usize) -> usize {
    if std::mem::size_of::<T>() <= T::MIN_SIZE {
        return n;
    }
    let elem = std::mem::size_of::<T>().max(1);
    n.min((remaining.saturating_mul(8) / elem).max(16))
}

/// Decodes a sequence body; shared by `Vec` and `BoundedSeq`.
#[inline(always)]
pub(crate) fn decode_seq<T: CdrType>(
    r: &mut CdrReader<'_>,
    bound: usize,
) -> Result<Vec<T>, DecodeError> {
    let (limit, n) = seq_header::<T>(r, bound)?;
    // Sized once: a fresh `Vec` grown by `reserve` takes the allocator's slower growth path.
    let mut v = Vec::with_capacity(capacity_for::<T>(n, r.remaining()));
    T::decode_into(&mut v, n, r)?;
    seq_end(r, limit);
    Ok(v)
}

/// Decodes a sequence body into `v`, reusing its buffer and, for non-primitive elements, the elements it
/// already holds (decoded in place).
pub(crate) fn decode_seq_in_place<T: CdrType>(
    v: &mut Vec<T>,
    r: &mut CdrReader<'_>,
    bound: usize,
) -> Result<(), DecodeError> {
    let (limit, n) = seq_header::<T>(r, bound)?;
    // Primitives are copied in bulk; other elements are decoded over the ones already there.
    let keep = if T::LAYOUT.is_primitive() {
        0
    } else {
        v.len().min(n)
    };
    v.truncate(keep);
    for e in v.iter_mut() {
        e.decode_in_place(r, usize::MAX)?;
    }
    v.reserve(capacity_for::<T>(n - keep, r.remaining()));
    T::decode_into(v, n - keep, r)?;
    seq_end(r, limit);
    Ok(())
}

/// A sequence's DHEADER (XCDR2, non-primitive elements) and its checked length.
#[inline(always)]
fn seq_header<T: CdrType>(
    r: &mut CdrReader<'_>,
    bound: usize,
) -> Result<(Option<Limit>, usize), DecodeError> {
    let limit = if !T::LAYOUT.is_primitive() && r.is_xcdr2() {
        r.enter("sequence")?;
        let len = r.read_u32("sequence DHEADER")? as usize;
        Some(r.begin_limit(len, "sequence DHEADER")?)
    } else {
        None
    };
    let at = r.offset();
    let n = r.read_count(T::MIN_SIZE, "sequence length")?;
    if n > bound {
        return Err(bound_error(r, at, "sequence within its bound", n, bound));
    }
    Ok((limit, n))
}

/// Closes what [`seq_header`] opened.
#[inline(always)]
fn seq_end(r: &mut CdrReader<'_>, limit: Option<Limit>) {
    if let Some(l) = limit {
        r.end_limit(l);
        r.leave();
    }
}

pub(crate) fn seq_key_max_end<T: CdrType>(
    start: usize,
    version: XcdrVersion,
    bound: Option<usize>,
) -> Option<usize> {
    let bound = bound?;
    if start > KEY_SCAN_LIMIT || bound > KEY_SCAN_LIMIT {
        return None;
    }
    // The hashed key stream carries no DHEADER.
    let mut p = align4(start) + 4;
    for _ in 0..bound {
        p = T::key_max_end(p, version, None)?;
        if p > KEY_SCAN_LIMIT {
            return None;
        }
    }
    Some(p)
}

impl<T: CdrType> CdrType for Vec<T> {
    const LAYOUT: Layout = match T::LAYOUT {
        Layout::Primitive(n) => Layout::PrimitiveSequence(n),
        _ => Layout::Delimited,
    };
    const MIN_SIZE: usize = 4;
    const XCDR1_PLAIN: bool = T::XCDR1_PLAIN;
    const KEY_HAS_MUTABLE: bool = T::KEY_HAS_MUTABLE;

    #[inline]
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        encode_seq(self, w, usize::MAX)
    }

    #[inline]
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        decode_seq(r, usize::MAX)
    }

    fn default_value() -> Self {
        Vec::new()
    }

    #[inline]
    fn encode_bounded(&self, w: &mut CdrWriter<'_>, bound: usize) -> Result<(), EncodeError> {
        encode_seq(self, w, bound)
    }

    #[inline]
    fn decode_bounded(r: &mut CdrReader<'_>, bound: usize) -> Result<Self, DecodeError> {
        decode_seq(r, bound)
    }

    #[inline]
    fn decode_in_place(&mut self, r: &mut CdrReader<'_>, bound: usize) -> Result<(), DecodeError> {
        decode_seq_in_place(self, r, bound)
    }

    fn key_max_end(start: usize, version: XcdrVersion, bound: Option<usize>) -> Option<usize> {
        seq_key_max_end::<T>(start, version, bound)
    }
}

impl<T: CdrType, const N: usize> CdrType for [T; N] {
    const LAYOUT: Layout = match T::LAYOUT {
        Layout::Primitive(_) | Layout::PrimitiveArray => Layout::PrimitiveArray,
        _ => Layout::DelimitedArray,
    };
    const MIN_SIZE: usize = {
        let m = T::MIN_SIZE.saturating_mul(N);
        if m == 0 {
            1
        } else {
            m
        }
    };
    const XCDR1_PLAIN: bool = T::XCDR1_PLAIN;
    const KEY_HAS_MUTABLE: bool = T::KEY_HAS_MUTABLE;

    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        if matches!(Self::LAYOUT, Layout::DelimitedArray) && w.is_xcdr2() {
            w.enter()?;
            let slot = w.begin_length();
            self.encode_flat(w)?;
            w.leave();
            w.end_length(slot)
        } else {
            self.encode_flat(w)
        }
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        // Both branches are tail calls into functions of their own: a debug build then holds no copy of the
        // array in this frame (a 64 KiB array passed through several frames by value overflowed small stacks).
        if matches!(Self::LAYOUT, Layout::DelimitedArray) && r.is_xcdr2() {
            decode_delimited_array::<T, N>(r)
        } else {
            Self::decode_flat(r)
        }
    }

    fn encode_flat(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        if T::LAYOUT.is_array() {
            for x in self {
                x.encode_flat(w)?;
            }
            Ok(())
        } else {
            T::encode_slice(self, w)
        }
    }

    fn decode_flat(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        if T::LAYOUT.is_array() {
            decode_inner_dimension::<T, N>(r)
        } else {
            T::decode_array::<N>(r)
        }
    }

    fn default_value() -> Self {
        std::array::from_fn(|_| T::default_value())
    }

    fn key_max_end(start: usize, version: XcdrVersion, _bound: Option<usize>) -> Option<usize> {
        if start > KEY_SCAN_LIMIT || N > KEY_SCAN_LIMIT {
            return None;
        }
        let mut p = start;
        for _ in 0..N {
            p = T::key_max_end(p, version, None)?;
            if p > KEY_SCAN_LIMIT {
                return None;
            }
        }
        Some(p)
    }
}

/// An XCDR2 array of non-primitive elements: a DHEADER, then the elements.
fn decode_delimited_array<T: CdrType, const N: usize>(
    r: &mut CdrReader<'_>,
) -> Result<[T; N], DecodeError> {
    r.enter("array")?;
    let len = r.read_u32("array DHEADER")? as usize;
    let l = r.begin_limit(len, "array DHEADER")?;
    let v = <[T; N]>::decode_flat(r)?;
    r.end_limit(l);
    r.leave();
    Ok(v)
}

/// The outer dimension of a multi-dimensional array: each element is an array written without a header.
fn decode_inner_dimension<T: CdrType, const N: usize>(
    r: &mut CdrReader<'_>,
) -> Result<[T; N], DecodeError> {
    let mut err = None;
    let arr = std::array::from_fn(|_| {
        if err.is_none() {
            match T::decode_flat(r) {
                Ok(v) => return v,
                Err(e) => err = Some(e),
            }
        }
        T::default_value()
    });
    match err {
        None => Ok(arr),
        Some(e) => Err(e),
    }
}

impl<K: CdrType + Ord, V: CdrType> CdrType for BTreeMap<K, V> {
    const LAYOUT: Layout = if K::LAYOUT.is_primitive() && V::LAYOUT.is_primitive() {
        Layout::Other
    } else {
        Layout::Delimited
    };
    const MIN_SIZE: usize = 4;
    const XCDR1_PLAIN: bool = K::XCDR1_PLAIN && V::XCDR1_PLAIN;
    const KEY_HAS_MUTABLE: bool = K::KEY_HAS_MUTABLE || V::KEY_HAS_MUTABLE;

    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        self.encode_bounded(w, usize::MAX)
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        Self::decode_bounded(r, usize::MAX)
    }

    fn default_value() -> Self {
        BTreeMap::new()
    }

    fn encode_bounded(&self, w: &mut CdrWriter<'_>, bound: usize) -> Result<(), EncodeError> {
        check_bound("map", self.len(), bound)?;
        let delimited = matches!(Self::LAYOUT, Layout::Delimited) && w.is_xcdr2();
        w.enter()?;
        let slot = if delimited {
            Some(w.begin_length())
        } else {
            None
        };
        w.write_len(self.len(), "map length")?;
        for (k, v) in self {
            k.encode(w)?;
            v.encode(w)?;
        }
        w.leave();
        match slot {
            Some(s) => w.end_length(s),
            None => Ok(()),
        }
    }

    fn decode_bounded(r: &mut CdrReader<'_>, bound: usize) -> Result<Self, DecodeError> {
        r.enter("map")?;
        let limit = if matches!(Self::LAYOUT, Layout::Delimited) && r.is_xcdr2() {
            let len = r.read_u32("map DHEADER")? as usize;
            Some(r.begin_limit(len, "map DHEADER")?)
        } else {
            None
        };
        let at = r.offset();
        let n = r.read_count(K::MIN_SIZE + V::MIN_SIZE, "map length")?;
        if n > bound {
            return Err(bound_error(r, at, "map within its bound", n, bound));
        }
        let mut m = BTreeMap::new();
        for _ in 0..n {
            let k = K::decode(r)?;
            let v = V::decode(r)?;
            m.insert(k, v);
        }
        if let Some(l) = limit {
            r.end_limit(l);
        }
        r.leave();
        Ok(m)
    }

    fn key_max_end(_start: usize, _version: XcdrVersion, _bound: Option<usize>) -> Option<usize> {
        None
    }
}

/// `@external` members and recursion.
impl<T: CdrType> CdrType for Box<T> {
    const LAYOUT: Layout = T::LAYOUT;
    // Not delegated: `@external` is where IDL recursion lives (A -> Box<B> -> A), and constants that looked
    // through the box would depend on themselves. So an external member counts as final and plain here.
    const MIN_SIZE: usize = 1;

    #[inline]
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        (**self).encode(w)
    }

    #[inline]
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        T::decode(r).map(Box::new)
    }

    fn default_value() -> Self {
        Box::new(T::default_value())
    }

    fn encode_bounded(&self, w: &mut CdrWriter<'_>, bound: usize) -> Result<(), EncodeError> {
        (**self).encode_bounded(w, bound)
    }

    fn decode_bounded(r: &mut CdrReader<'_>, bound: usize) -> Result<Self, DecodeError> {
        T::decode_bounded(r, bound).map(Box::new)
    }

    fn key_max_end(start: usize, version: XcdrVersion, bound: Option<usize>) -> Option<usize> {
        if start > KEY_SCAN_LIMIT {
            return None;
        }
        T::key_max_end(start, version, bound)
    }
}

#[cfg(test)]
mod string_tests {
    use super::*;
    use crate::cdr::ByteOrder;

    /// The short-string fast path agrees with the full checks for every length up to 40 and every position
    /// of a NUL, a byte above 0x7f (invalid alone), and a two-byte UTF-8 character; decoding into a reused
    /// string gives the same.
    #[test]
    fn short_string_checks_agree_with_the_full_ones() {
        let decode = |text: &[u8]| {
            let mut p = ((text.len() + 1) as u32).to_le_bytes().to_vec();
            p.extend_from_slice(text);
            p.push(0);
            let mut r = CdrReader::new(&p, 0, XcdrVersion::Xcdr1, ByteOrder::LittleEndian, false);
            let fresh = decode_str(&mut r, usize::MAX).ok();
            // Into a reused string (with a longer old value): the same result, and empty on error.
            let mut reused = "an old value longer than forty characters...".to_owned();
            let mut r = CdrReader::new(&p, 0, XcdrVersion::Xcdr1, ByteOrder::LittleEndian, false);
            match decode_str_in_place(&mut reused, &mut r, usize::MAX) {
                Ok(()) => assert_eq!(Some(&reused), fresh.as_ref()),
                Err(_) => assert!(fresh.is_none() && reused.is_empty()),
            }
            fresh
        };
        let reference = |text: &[u8]| {
            (!text.contains(&0))
                .then(|| std::str::from_utf8(text).ok().map(str::to_owned))
                .flatten()
        };
        for n in 0..=40usize {
            let base: Vec<u8> = (0..n).map(|i| b'A' + (i % 26) as u8).collect();
            assert_eq!(decode(&base), reference(&base), "plain {n}");
            // A terminator other than NUL.
            let mut p = ((n + 1) as u32).to_le_bytes().to_vec();
            p.extend_from_slice(&base);
            p.push(b'X');
            let mut r = CdrReader::new(&p, 0, XcdrVersion::Xcdr1, ByteOrder::LittleEndian, false);
            assert!(decode_str(&mut r, usize::MAX).is_err(), "terminator, {n}");
            for at in 0..n {
                for b in [0u8, 0x80, 0xff] {
                    let mut t = base.clone();
                    t[at] = b;
                    assert_eq!(decode(&t), reference(&t), "n {n}, byte {b:#x} at {at}");
                }
                if at + 1 < n {
                    let mut t = base.clone();
                    t[at] = 0xc3;
                    t[at + 1] = 0xa9; // é
                    assert_eq!(decode(&t), reference(&t), "n {n}, é at {at}");
                }
            }
        }
    }
}
