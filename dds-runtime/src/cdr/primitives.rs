//! `CdrType` for the IDL primitives, with bulk copies for slices when the byte order matches the host.

use super::error::{DecodeError, DecodeErrorKind, EncodeError};
use super::header::XcdrVersion;
use super::reader::CdrReader;
use super::short;
use super::traits::{CdrType, Layout};
use super::writer::CdrWriter;

/// End offset of a primitive of `size` bytes written at `start` (key-size scans).
#[inline]
pub const fn prim_end(start: usize, size: usize, version: XcdrVersion) -> usize {
    let a = if size < version.max_align() {
        size
    } else {
        version.max_align()
    };
    let a = if a == 0 { 1 } else { a };
    start.div_ceil(a) * a + size
}

macro_rules! numeric {
    ($t:ty, $u:ty, $n:expr, $write:ident, $read:ident, $to:expr, $from:expr, $what:expr) => {
        impl CdrType for $t {
            const LAYOUT: Layout = Layout::Primitive($n);
            const MIN_SIZE: usize = $n;

            #[inline]
            fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
                #[allow(clippy::redundant_closure_call)]
                w.$write(($to)(*self));
                Ok(())
            }

            #[inline]
            fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
                #[allow(clippy::redundant_closure_call)]
                Ok(($from)(r.$read($what)?))
            }

            #[inline]
            fn default_value() -> Self {
                <$t>::default()
            }

            fn key_max_end(
                start: usize,
                version: XcdrVersion,
                _bound: Option<usize>,
            ) -> Option<usize> {
                Some(prim_end(start, $n, version))
            }

            #[inline]
            fn encode_slice(items: &[Self], w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
                if items.is_empty() {
                    return Ok(());
                }
                w.align($n);
                if w.order().is_native() {
                    // SAFETY: a numeric slice is initialized memory without padding; viewing it as bytes is sound.
                    let bytes = unsafe {
                        std::slice::from_raw_parts(
                            items.as_ptr().cast::<u8>(),
                            std::mem::size_of_val(items),
                        )
                    };
                    w.write_bytes(bytes);
                } else {
                    for v in items {
                        #[allow(clippy::redundant_closure_call)]
                        w.write_bytes(&(($to)(*v) as $u).swap_bytes().to_ne_bytes());
                    }
                }
                Ok(())
            }

            fn decode_array<const N: usize>(
                r: &mut CdrReader<'_>,
            ) -> Result<[Self; N], DecodeError> {
                let mut a = [<$t>::default(); N];
                if N == 0 {
                    return Ok(a);
                }
                r.align($n, $what)?;
                let bytes = r.read_bytes(N * $n, $what)?;
                if r.order().is_native() {
                    // SAFETY: `a` holds exactly N * $n bytes and every bit pattern is a valid value.
                    unsafe {
                        std::ptr::copy_nonoverlapping(
                            bytes.as_ptr(),
                            a.as_mut_ptr().cast::<u8>(),
                            N * $n,
                        );
                    }
                } else {
                    for (d, c) in a.iter_mut().zip(bytes.chunks_exact($n)) {
                        let mut b = [0u8; $n];
                        b.copy_from_slice(c);
                        #[allow(clippy::redundant_closure_call)]
                        {
                            *d = ($from)(<$u>::from_ne_bytes(b).swap_bytes());
                        }
                    }
                }
                Ok(a)
            }

            #[inline(always)]
            fn decode_into(
                out: &mut Vec<Self>,
                n: usize,
                r: &mut CdrReader<'_>,
            ) -> Result<(), DecodeError> {
                if n == 0 {
                    return Ok(());
                }
                r.align($n, $what)?;
                let len = n.checked_mul($n).unwrap_or(usize::MAX);
                let bytes = r.read_bytes(len, $what)?;
                out.reserve(n);
                if r.order().is_native() {
                    // SAFETY: `reserve(n)` made room for n more elements; every bit pattern is a valid value of
                    // this numeric type, and `bytes` holds exactly n of them (`len` bytes, not overlapping
                    // `out`, which the caller owns).
                    unsafe {
                        short::copy_bytes(bytes, out.as_mut_ptr().add(out.len()).cast::<u8>());
                        out.set_len(out.len() + n);
                    }
                } else {
                    for c in bytes.chunks_exact($n) {
                        let mut a = [0u8; $n];
                        a.copy_from_slice(c);
                        #[allow(clippy::redundant_closure_call)]
                        out.push(($from)(<$u>::from_ne_bytes(a).swap_bytes()));
                    }
                }
                Ok(())
            }
        }
    };
}

numeric!(
    u16,
    u16,
    2,
    write_u16,
    read_u16,
    |v: u16| v,
    |v: u16| v,
    "uint16"
);
numeric!(
    i16,
    u16,
    2,
    write_u16,
    read_u16,
    |v: i16| v as u16,
    |v: u16| v as i16,
    "int16"
);
numeric!(
    u32,
    u32,
    4,
    write_u32,
    read_u32,
    |v: u32| v,
    |v: u32| v,
    "uint32"
);
numeric!(
    i32,
    u32,
    4,
    write_u32,
    read_u32,
    |v: i32| v as u32,
    |v: u32| v as i32,
    "int32"
);
numeric!(
    u64,
    u64,
    8,
    write_u64,
    read_u64,
    |v: u64| v,
    |v: u64| v,
    "uint64"
);
numeric!(
    i64,
    u64,
    8,
    write_u64,
    read_u64,
    |v: i64| v as u64,
    |v: u64| v as i64,
    "int64"
);
numeric!(
    f32,
    u32,
    4,
    write_u32,
    read_u32,
    f32::to_bits,
    f32::from_bits,
    "float32"
);
numeric!(
    f64,
    u64,
    8,
    write_u64,
    read_u64,
    f64::to_bits,
    f64::from_bits,
    "float64"
);

macro_rules! byte_like {
    ($t:ty, $what:expr) => {
        impl CdrType for $t {
            const LAYOUT: Layout = Layout::Primitive(1);

            #[inline]
            fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
                w.write_u8(*self as u8);
                Ok(())
            }

            #[inline]
            fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
                Ok(r.read_u8($what)? as $t)
            }

            #[inline]
            fn default_value() -> Self {
                0
            }

            fn key_max_end(
                start: usize,
                _version: XcdrVersion,
                _bound: Option<usize>,
            ) -> Option<usize> {
                Some(start + 1)
            }

            #[inline]
            fn encode_slice(items: &[Self], w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
                // SAFETY: u8/i8 slices are plain bytes.
                let bytes =
                    unsafe { std::slice::from_raw_parts(items.as_ptr().cast::<u8>(), items.len()) };
                w.write_bytes(bytes);
                Ok(())
            }

            fn decode_array<const N: usize>(
                r: &mut CdrReader<'_>,
            ) -> Result<[Self; N], DecodeError> {
                let bytes = r.read_bytes(N, $what)?;
                let mut a = [0 as $t; N];
                for (d, &b) in a.iter_mut().zip(bytes) {
                    *d = b as $t;
                }
                Ok(a)
            }

            #[inline]
            fn decode_into(
                out: &mut Vec<Self>,
                n: usize,
                r: &mut CdrReader<'_>,
            ) -> Result<(), DecodeError> {
                let bytes = r.read_bytes(n, $what)?;
                out.reserve(n);
                // SAFETY: `reserve(n)` made room for n more elements; a byte is a valid u8/i8, and `bytes`
                // holds exactly n of them (not overlapping `out`, which the caller owns).
                unsafe {
                    short::copy_bytes(bytes, out.as_mut_ptr().add(out.len()).cast::<u8>());
                    out.set_len(out.len() + n);
                }
                Ok(())
            }
        }
    };
}

byte_like!(u8, "octet");
byte_like!(i8, "int8");

impl CdrType for bool {
    const LAYOUT: Layout = Layout::Primitive(1);

    #[inline]
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        w.write_u8(u8::from(*self));
        Ok(())
    }

    #[inline]
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        match r.read_u8("boolean")? {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(DecodeError::new(
                r.offset() - 1,
                "boolean (0 or 1)",
                DecodeErrorKind::InvalidValue {
                    found: u64::from(b),
                },
            )),
        }
    }

    fn default_value() -> Self {
        false
    }

    fn key_max_end(start: usize, _version: XcdrVersion, _bound: Option<usize>) -> Option<usize> {
        Some(start + 1)
    }

    fn decode_into(
        out: &mut Vec<Self>,
        n: usize,
        r: &mut CdrReader<'_>,
    ) -> Result<(), DecodeError> {
        let at = r.offset();
        let bytes = r.read_bytes(n, "boolean")?;
        if let Some(i) = bytes.iter().position(|&b| b > 1) {
            return Err(DecodeError::new(
                at + i,
                "boolean (0 or 1)",
                DecodeErrorKind::InvalidValue {
                    found: u64::from(bytes[i]),
                },
            ));
        }
        out.extend(bytes.iter().map(|&b| b == 1));
        Ok(())
    }
}

/// IDL `char` (char8): one byte, Latin-1. Characters above U+00FF cannot be encoded.
impl CdrType for char {
    const LAYOUT: Layout = Layout::Primitive(1);

    #[inline]
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        let v = u32::from(*self);
        if v > 0xff {
            return Err(EncodeError::InvalidValue {
                what: "char8 above U+00FF",
                value: u64::from(v),
            });
        }
        w.write_u8(v as u8);
        Ok(())
    }

    #[inline]
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        Ok(char::from(r.read_u8("char8")?))
    }

    fn default_value() -> Self {
        '\0'
    }

    fn key_max_end(start: usize, _version: XcdrVersion, _bound: Option<usize>) -> Option<usize> {
        Some(start + 1)
    }
}
