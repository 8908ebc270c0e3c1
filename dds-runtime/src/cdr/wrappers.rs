//! Wrapper types for IDL types with no exact Rust counterpart: `wchar`, `wstring`, `long double`, and bounded
//! strings/sequences where a field attribute cannot reach (inside sequences, maps and arrays).

use std::ops::{Deref, DerefMut};

use super::collections::{
    decode_seq, decode_str, encode_seq, encode_str, seq_key_max_end, string_key_max_end,
};
use super::error::{DecodeError, DecodeErrorKind, EncodeError};
use super::header::{ByteOrder, XcdrVersion};
use super::primitives::prim_end;
use super::reader::CdrReader;
use super::traits::{CdrType, Layout};
use super::writer::CdrWriter;

/// IDL `wchar`: one UTF-16 code unit, 2 bytes on the wire in XCDR1 and XCDR2.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct WChar(pub u16);

impl From<u16> for WChar {
    fn from(v: u16) -> Self {
        WChar(v)
    }
}

impl TryFrom<char> for WChar {
    type Error = EncodeError;
    /// Characters outside the Basic Multilingual Plane need two code units and do not fit.
    fn try_from(c: char) -> Result<Self, EncodeError> {
        u16::try_from(u32::from(c))
            .map(WChar)
            .map_err(|_| EncodeError::InvalidValue {
                what: "wchar outside the BMP",
                value: u64::from(u32::from(c)),
            })
    }
}

impl CdrType for WChar {
    const LAYOUT: Layout = Layout::Primitive(2);
    const MIN_SIZE: usize = 2;

    #[inline]
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        w.write_u16(self.0);
        Ok(())
    }

    #[inline]
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        r.read_u16("wchar").map(WChar)
    }

    fn default_value() -> Self {
        WChar(0)
    }

    fn key_max_end(start: usize, version: XcdrVersion, _bound: Option<usize>) -> Option<usize> {
        Some(prim_end(start, 2, version))
    }
}

/// IDL `wstring`: a u32 byte count, then UTF-16 code units, no terminator (as Cyclone DDS writes it).
#[derive(Clone, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct WString(pub String);

impl From<&str> for WString {
    fn from(s: &str) -> Self {
        WString(s.to_owned())
    }
}

impl From<String> for WString {
    fn from(s: String) -> Self {
        WString(s)
    }
}

impl Deref for WString {
    type Target = String;
    fn deref(&self) -> &String {
        &self.0
    }
}

impl DerefMut for WString {
    fn deref_mut(&mut self) -> &mut String {
        &mut self.0
    }
}

impl CdrType for WString {
    const LAYOUT: Layout = Layout::String;
    const MIN_SIZE: usize = 4;

    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        self.encode_bounded(w, usize::MAX)
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        Self::decode_bounded(r, usize::MAX)
    }

    fn default_value() -> Self {
        WString::default()
    }

    fn encode_bounded(&self, w: &mut CdrWriter<'_>, bound: usize) -> Result<(), EncodeError> {
        let units = self.0.encode_utf16().count();
        if units > bound {
            return Err(EncodeError::BoundExceeded {
                what: "wstring",
                bound,
                len: units,
            });
        }
        w.write_len(units * 2, "wstring length")?;
        for u in self.0.encode_utf16() {
            match w.order() {
                ByteOrder::BigEndian => w.write_bytes(&u.to_be_bytes()),
                ByteOrder::LittleEndian => w.write_bytes(&u.to_le_bytes()),
            }
        }
        Ok(())
    }

    fn decode_bounded(r: &mut CdrReader<'_>, bound: usize) -> Result<Self, DecodeError> {
        let at = r.offset();
        let n = r.read_count(1, "wstring length")?;
        if n % 2 != 0 {
            return Err(DecodeError::new(
                at,
                "even wstring byte length",
                DecodeErrorKind::InvalidValue { found: n as u64 },
            ));
        }
        if n / 2 > bound {
            return Err(DecodeError::new(
                at,
                "wstring within its bound",
                DecodeErrorKind::BoundExceeded { bound, len: n / 2 },
            ));
        }
        let body = r.offset();
        let bytes = r.read_bytes(n, "wstring characters")?;
        let big = r.order() == ByteOrder::BigEndian;
        let units = bytes.chunks_exact(2).map(|c| {
            if big {
                u16::from_be_bytes([c[0], c[1]])
            } else {
                u16::from_le_bytes([c[0], c[1]])
            }
        });
        let mut s = String::with_capacity(n);
        for c in char::decode_utf16(units) {
            match c {
                Ok(c) => s.push(c),
                Err(_) => {
                    return Err(DecodeError::new(
                        body,
                        "UTF-16 wstring",
                        DecodeErrorKind::MalformedString,
                    ));
                }
            }
        }
        Ok(WString(s))
    }

    fn key_max_end(start: usize, _version: XcdrVersion, bound: Option<usize>) -> Option<usize> {
        bound.map(|b| ((start + 3) & !3) + 4 + 2 * b)
    }
}

/// IDL `long double`: 16 bytes carried losslessly, most significant byte first in memory. Aligned like a
/// 64-bit value (8 in XCDR1, 4 in XCDR2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct LongDouble(pub [u8; 16]);

impl CdrType for LongDouble {
    const LAYOUT: Layout = Layout::Primitive(16);
    const MIN_SIZE: usize = 16;

    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        w.align(8);
        match w.order() {
            ByteOrder::BigEndian => w.write_bytes(&self.0),
            ByteOrder::LittleEndian => {
                let mut b = self.0;
                b.reverse();
                w.write_bytes(&b);
            }
        }
        Ok(())
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        r.align(8, "long double")?;
        let mut b = [0u8; 16];
        b.copy_from_slice(r.read_bytes(16, "long double")?);
        if r.order() == ByteOrder::LittleEndian {
            b.reverse();
        }
        Ok(LongDouble(b))
    }

    fn default_value() -> Self {
        LongDouble([0; 16])
    }

    fn key_max_end(start: usize, version: XcdrVersion, _bound: Option<usize>) -> Option<usize> {
        let a = version.max_align();
        Some(start.div_ceil(a) * a + 16)
    }
}

/// `string<N>` where no field attribute can give the bound.
#[derive(Clone, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct BoundedString<const N: usize>(pub String);

impl<const N: usize> Deref for BoundedString<N> {
    type Target = String;
    fn deref(&self) -> &String {
        &self.0
    }
}

impl<const N: usize> DerefMut for BoundedString<N> {
    fn deref_mut(&mut self) -> &mut String {
        &mut self.0
    }
}

impl<const N: usize> From<&str> for BoundedString<N> {
    fn from(s: &str) -> Self {
        BoundedString(s.to_owned())
    }
}

impl<const N: usize> CdrType for BoundedString<N> {
    const LAYOUT: Layout = Layout::String;
    const MIN_SIZE: usize = 4;

    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        encode_str(&self.0, w, N)
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        decode_str(r, N).map(BoundedString)
    }

    fn default_value() -> Self {
        BoundedString(String::new())
    }

    fn key_max_end(start: usize, _version: XcdrVersion, _bound: Option<usize>) -> Option<usize> {
        string_key_max_end(start, Some(N))
    }
}

/// `sequence<T, N>` where no field attribute can give the bound.
#[derive(Clone, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct BoundedSeq<T, const N: usize>(pub Vec<T>);

impl<T, const N: usize> Deref for BoundedSeq<T, N> {
    type Target = Vec<T>;
    fn deref(&self) -> &Vec<T> {
        &self.0
    }
}

impl<T, const N: usize> DerefMut for BoundedSeq<T, N> {
    fn deref_mut(&mut self) -> &mut Vec<T> {
        &mut self.0
    }
}

impl<T, const N: usize> From<Vec<T>> for BoundedSeq<T, N> {
    fn from(v: Vec<T>) -> Self {
        BoundedSeq(v)
    }
}

impl<T: CdrType, const N: usize> CdrType for BoundedSeq<T, N> {
    const LAYOUT: Layout = <Vec<T> as CdrType>::LAYOUT;
    const MIN_SIZE: usize = 4;
    const XCDR1_PLAIN: bool = T::XCDR1_PLAIN;
    const KEY_HAS_MUTABLE: bool = T::KEY_HAS_MUTABLE;

    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        encode_seq(&self.0, w, N)
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        decode_seq(r, N).map(BoundedSeq)
    }

    fn default_value() -> Self {
        BoundedSeq(Vec::new())
    }

    fn key_max_end(start: usize, version: XcdrVersion, _bound: Option<usize>) -> Option<usize> {
        seq_key_max_end::<T>(start, version, Some(N))
    }
}
