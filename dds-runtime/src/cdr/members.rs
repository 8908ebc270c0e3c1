//! Struct and union framing used by generated code: DHEADER, EMHEADER, XCDR1 parameter lists, optional
//! members and union discriminators. Generated code calls these; their names are not part of the user API.

use super::error::{DecodeError, DecodeErrorKind, EncodeError};
use super::header::{Extensibility, XcdrVersion};
use super::reader::{CdrReader, Limit};
use super::traits::CdrType;
use super::writer::{CdrWriter, LengthSlot};
use super::{PID_EXTENDED, PID_IGNORE, PID_LIST_END};

pub use super::primitives::prim_end;

/// The members of a struct, without the struct's own framing, so a derived struct (`#[dds(base)]`) can put
/// its base's members first inside its own DHEADER or parameter list. Generated; not for hand-written code.
#[doc(hidden)]
pub trait StructMembers: CdrType {
    /// Per-member decode state (each member `None` until read).
    type Partial: Default;
    /// Whether the struct or its base has key members.
    const HAS_KEYS: bool;
    /// Encodes the members (only keys in key modes when the struct has keys).
    fn encode_members(&self, w: &mut CdrWriter<'_>, ext: Extensibility) -> Result<(), EncodeError>;
    /// Decodes the members of a final/appendable encoding in declaration order.
    fn decode_members_in_order(
        r: &mut CdrReader<'_>,
        st: &StructDecoder,
        p: &mut Self::Partial,
    ) -> Result<(), DecodeError>;
    /// Decodes the member with this id from a mutable encoding; `false` if the id is not a member.
    fn decode_member_by_id(
        r: &mut CdrReader<'_>,
        id: u32,
        p: &mut Self::Partial,
    ) -> Result<bool, DecodeError>;
    /// Builds the value, defaulting members that were not read.
    fn finish(p: Self::Partial) -> Self;
    /// Key-size scan over the members.
    fn key_members_max_end(start: usize, version: XcdrVersion, ext: Extensibility)
        -> Option<usize>;
}

/// An aggregate being encoded.
#[derive(Debug)]
#[must_use]
pub struct StructEncoder {
    ext: Extensibility,
    slot: Option<LengthSlot>,
}

/// Starts a struct or union: depth check, and the DHEADER of XCDR2 appendable/mutable types.
#[inline]
pub fn begin_encode(
    w: &mut CdrWriter<'_>,
    ext: Extensibility,
) -> Result<StructEncoder, EncodeError> {
    w.enter()?;
    let slot = if w.is_xcdr2() && ext != Extensibility::Final {
        Some(w.begin_length())
    } else {
        None
    };
    Ok(StructEncoder { ext, slot })
}

/// Ends a struct or union: XCDR1 PID_LIST_END for mutable types, DHEADER patch for XCDR2.
#[inline]
pub fn end_encode(w: &mut CdrWriter<'_>, st: StructEncoder) -> Result<(), EncodeError> {
    if st.ext == Extensibility::Mutable && !w.is_xcdr2() {
        w.write_list_end();
    }
    w.leave();
    match st.slot {
        Some(s) => w.end_length(s),
        None => Ok(()),
    }
}

/// Encodes one non-optional member, with an EMHEADER or parameter header in mutable types.
#[inline]
pub fn encode_member<T: CdrType>(
    w: &mut CdrWriter<'_>,
    ext: Extensibility,
    id: u32,
    must_understand: bool,
    value: &T,
    bound: usize,
) -> Result<(), EncodeError> {
    if ext != Extensibility::Mutable {
        return value.encode_bounded(w, bound);
    }
    if w.is_xcdr2() {
        let slot = w.write_emheader(id, must_understand, T::LAYOUT.length_code())?;
        value.encode_bounded(w, bound)?;
        match slot {
            Some(s) => w.end_length(s),
            None => Ok(()),
        }
    } else {
        let p = w.begin_param(id, must_understand)?;
        value.encode_bounded(w, bound)?;
        w.end_param(p)
    }
}

/// Encodes an optional member: omitted when absent in mutable types, a presence byte in XCDR2 final/appendable
/// types, and a parameter header (length 0 when absent) in XCDR1 final/appendable types.
#[inline]
pub fn encode_optional<T: CdrType>(
    w: &mut CdrWriter<'_>,
    ext: Extensibility,
    id: u32,
    must_understand: bool,
    value: &Option<T>,
    bound: usize,
) -> Result<(), EncodeError> {
    if ext == Extensibility::Mutable {
        return match value {
            Some(v) => encode_member(w, ext, id, must_understand, v, bound),
            None => Ok(()),
        };
    }
    if w.is_xcdr2() {
        w.write_u8(u8::from(value.is_some()));
        match value {
            Some(v) => v.encode_bounded(w, bound),
            None => Ok(()),
        }
    } else {
        let p = w.begin_param(id, must_understand)?;
        if let Some(v) = value {
            v.encode_bounded(w, bound)?;
        }
        w.end_param(p)
    }
}

/// An aggregate being decoded.
#[derive(Debug)]
#[must_use]
pub struct StructDecoder {
    ext: Extensibility,
    limit: Option<Limit>,
}

/// A member header read from a mutable encoding (EMHEADER or parameter header); the reader is limited to the
/// member's body until [`end_member`].
#[derive(Debug)]
#[must_use]
pub struct MemberHeader {
    /// Member id.
    pub id: u32,
    /// Must-understand flag.
    pub must_understand: bool,
    at: usize,
    limit: Limit,
}

/// Starts decoding a struct or union (depth check, XCDR2 DHEADER). Always inlined: without a DHEADER (XCDR1, or
/// a final type) it is the depth check alone; the DHEADER is read out of line.
#[inline(always)]
pub fn begin_decode(
    r: &mut CdrReader<'_>,
    ext: Extensibility,
) -> Result<StructDecoder, DecodeError> {
    r.enter("struct")?;
    if r.is_xcdr2() && ext != Extensibility::Final {
        return begin_delimited(r, ext);
    }
    Ok(StructDecoder { ext, limit: None })
}

/// [`begin_decode`] of a DHEADER-delimited aggregate.
#[inline(never)]
fn begin_delimited(
    r: &mut CdrReader<'_>,
    ext: Extensibility,
) -> Result<StructDecoder, DecodeError> {
    let len = r.read_u32("DHEADER")? as usize;
    let limit = Some(r.begin_limit(len, "DHEADER")?);
    Ok(StructDecoder { ext, limit })
}

impl StructDecoder {
    /// Whether another member follows (an XCDR2 appendable sample from an older writer may stop early).
    #[inline]
    pub fn has_more(&self, r: &CdrReader<'_>) -> bool {
        self.limit.is_none() || r.remaining() > 0
    }

    /// Reads the next member header of a mutable encoding, or `None` at the end of the list.
    pub fn next_member(
        &mut self,
        r: &mut CdrReader<'_>,
    ) -> Result<Option<MemberHeader>, DecodeError> {
        debug_assert_eq!(self.ext, Extensibility::Mutable);
        if r.is_xcdr2() {
            if r.remaining() == 0 {
                return Ok(None);
            }
            let at = r.offset();
            let h = r.read_u32("EMHEADER")?;
            let id = h & 0x0fff_ffff;
            let lc = (h >> 28) & 7;
            let len = match lc {
                0..=3 => 1usize << lc,
                4 => r.read_u32("NEXTINT")? as usize,
                _ => {
                    // NEXTINT is the body's own leading u32 (string length, DHEADER or element count).
                    let n = r.read_u32("NEXTINT")? as usize;
                    r.rewind(4);
                    let unit = match lc {
                        5 => 1usize,
                        6 => 4,
                        _ => 8,
                    };
                    n.checked_mul(unit)
                        .and_then(|b| b.checked_add(4))
                        .ok_or_else(|| {
                            DecodeError::new(
                                at,
                                "EMHEADER member length",
                                DecodeErrorKind::LengthTooLarge {
                                    length: n as u64,
                                    remaining: r.remaining(),
                                },
                            )
                        })?
                }
            };
            let limit = r.begin_limit(len, "member body")?;
            Ok(Some(MemberHeader {
                id,
                must_understand: h & 0x8000_0000 != 0,
                at,
                limit,
            }))
        } else {
            loop {
                r.align(4, "parameter header")?;
                let at = r.offset();
                let pid = r.read_u16("parameter id")?;
                let short_len = r.read_u16("parameter length")? as usize;
                let (id, mu, len) = match pid & 0x3fff {
                    PID_LIST_END => return Ok(None),
                    PID_IGNORE => {
                        r.skip(short_len, "ignored parameter")?;
                        continue;
                    }
                    PID_EXTENDED => {
                        if short_len < 8 {
                            return Err(DecodeError::new(
                                at,
                                "PID_EXTENDED length of at least 8",
                                DecodeErrorKind::InvalidValue {
                                    found: short_len as u64,
                                },
                            ));
                        }
                        let x = r.read_u32("extended member id")?;
                        let len = r.read_u32("extended member length")? as usize;
                        r.skip(short_len - 8, "PID_EXTENDED padding")?;
                        (x & 0x0fff_ffff, x & 0x4000_0000 != 0, len)
                    }
                    p => (u32::from(p), pid & 0x4000 != 0, short_len),
                };
                let limit = r.begin_param_limit(len, "parameter body")?;
                return Ok(Some(MemberHeader {
                    id,
                    must_understand: mu,
                    at,
                    limit,
                }));
            }
        }
    }

    /// Ends the aggregate: skips unread bytes of a DHEADER-delimited body.
    #[inline]
    pub fn end(self, r: &mut CdrReader<'_>) {
        if let Some(l) = self.limit {
            r.end_limit(l);
        }
        r.leave();
    }
}

/// Finishes a member read with [`StructDecoder::next_member`], skipping what its type did not consume.
#[inline]
pub fn end_member(r: &mut CdrReader<'_>, m: MemberHeader) {
    r.end_limit(m.limit);
}

/// Skips a member this type does not know; fails if it is flagged must-understand.
pub fn skip_member(r: &mut CdrReader<'_>, m: MemberHeader) -> Result<(), DecodeError> {
    if m.must_understand {
        return Err(DecodeError::new(
            m.at,
            "a member id of this type",
            DecodeErrorKind::UnknownMustUnderstand { id: m.id },
        ));
    }
    end_member(r, m);
    Ok(())
}

/// Decodes a struct member into its slot of the struct's decode state. A function of its own so that a debug
/// build keeps the temporaries of a large member (a `Result`, the moved value, the `Option`) in this frame
/// instead of one set per member in the struct's frame; optimised builds inline it.
#[inline]
pub fn decode_into_slot<T: CdrType>(
    slot: &mut Option<T>,
    r: &mut CdrReader<'_>,
    bound: usize,
) -> Result<(), DecodeError> {
    *slot = Some(T::decode_bounded(r, bound)?);
    Ok(())
}

/// Decodes an optional member of a final/appendable type (presence byte in XCDR2, parameter in XCDR1).
pub fn decode_optional<T: CdrType>(
    r: &mut CdrReader<'_>,
    bound: usize,
) -> Result<Option<T>, DecodeError> {
    if r.is_xcdr2() {
        let at = r.offset();
        match r.read_u8("optional presence flag")? {
            0 => Ok(None),
            1 => T::decode_bounded(r, bound).map(Some),
            b => Err(DecodeError::new(
                at,
                "optional presence flag (0 or 1)",
                DecodeErrorKind::InvalidValue {
                    found: u64::from(b),
                },
            )),
        }
    } else {
        let mut st = StructDecoder {
            ext: Extensibility::Mutable,
            limit: None,
        };
        let at = r.offset();
        let Some(m) = st.next_member(r)? else {
            return Err(DecodeError::new(
                at,
                "parameter header of an optional member",
                DecodeErrorKind::InvalidValue { found: 0 },
            ));
        };
        let v = if r.remaining() == 0 {
            None
        } else {
            Some(T::decode_bounded(r, bound)?)
        };
        end_member(r, m);
        Ok(v)
    }
}

/// A union discriminator type: integers, `bool`, `char` and enums deriving `DdsType`.
pub trait Discriminator: CdrType + Copy {
    /// How the default discriminator value is searched (libddsc's rule).
    const SEARCH: DefaultSearch;
    /// The label value as an integer.
    fn to_raw(&self) -> i64;
    /// Writes a label value that may not be a valid `Self` (an enum's default label).
    fn write_raw(w: &mut CdrWriter<'_>, raw: i64) -> Result<(), EncodeError>;
    /// Reads a label value without requiring it to be a valid `Self`.
    fn read_raw(r: &mut CdrReader<'_>) -> Result<i64, DecodeError>;
    /// Enumerator values as written on the wire, in declaration order (enums only).
    fn enumerators() -> &'static [i64] {
        &[]
    }
}

/// Where the default discriminator search starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DefaultSearch {
    /// Signed integers: -1, -2, ... down to `min`.
    Down(i64),
    /// Unsigned integers and chars: 0, 1, ... up to `max`.
    Up(i64),
    /// `true` first, then `false`.
    Bool,
    /// The first enumerator (in declaration order) that no label uses, as libddsc requires.
    Enum,
}

/// The discriminator written for a union's default member: the first value (in Cyclone's search order) that
/// no label uses.
pub fn default_discriminator<D: Discriminator>(labels: &[i64]) -> Result<i64, EncodeError> {
    let none = EncodeError::InvalidValue {
        what: "no discriminator value left for the default member",
        value: 0,
    };
    match D::SEARCH {
        DefaultSearch::Down(min) => {
            let mut v = -1i64;
            while labels.contains(&v) {
                if v <= min {
                    return Err(none);
                }
                v -= 1;
            }
            Ok(v)
        }
        DefaultSearch::Up(max) => {
            let mut v = 0i64;
            while labels.contains(&v) {
                if v >= max {
                    return Err(none);
                }
                v += 1;
            }
            Ok(v)
        }
        DefaultSearch::Bool => {
            if !labels.contains(&1) {
                Ok(1)
            } else if !labels.contains(&0) {
                Ok(0)
            } else {
                Err(none)
            }
        }
        DefaultSearch::Enum => D::enumerators()
            .iter()
            .copied()
            .find(|v| !labels.contains(v))
            .ok_or(none),
    }
}

/// Writes a union discriminator (with its member header, id 0, in mutable unions).
pub fn encode_discriminator<D: Discriminator>(
    w: &mut CdrWriter<'_>,
    ext: Extensibility,
    raw: i64,
) -> Result<(), EncodeError> {
    if ext != Extensibility::Mutable {
        return D::write_raw(w, raw);
    }
    if w.is_xcdr2() {
        let slot = w.write_emheader(0, true, D::LAYOUT.length_code())?;
        D::write_raw(w, raw)?;
        match slot {
            Some(s) => w.end_length(s),
            None => Ok(()),
        }
    } else {
        let p = w.begin_param(0, true)?;
        D::write_raw(w, raw)?;
        w.end_param(p)
    }
}

/// Reads a union discriminator (see [`encode_discriminator`]).
pub fn decode_discriminator<D: Discriminator>(
    r: &mut CdrReader<'_>,
    st: &mut StructDecoder,
) -> Result<i64, DecodeError> {
    if st.ext != Extensibility::Mutable {
        return D::read_raw(r);
    }
    let at = r.offset();
    match st.next_member(r)? {
        Some(m) => {
            let v = D::read_raw(r)?;
            end_member(r, m);
            Ok(v)
        }
        None => Err(DecodeError::new(
            at,
            "union discriminator",
            DecodeErrorKind::UnexpectedEof {
                needed: 4,
                available: 0,
            },
        )),
    }
}

/// Reads the member of a mutable union (after its discriminator), or `None` if it carries none.
pub fn decode_union_member<T: CdrType>(
    r: &mut CdrReader<'_>,
    st: &mut StructDecoder,
    bound: usize,
) -> Result<T, DecodeError> {
    if st.ext != Extensibility::Mutable {
        return T::decode_bounded(r, bound);
    }
    let at = r.offset();
    match st.next_member(r)? {
        Some(m) => {
            let v = T::decode_bounded(r, bound)?;
            end_member(r, m);
            Ok(v)
        }
        None => Err(DecodeError::new(
            at,
            "union member",
            DecodeErrorKind::UnexpectedEof {
                needed: 4,
                available: 0,
            },
        )),
    }
}

macro_rules! int_discriminator {
    ($t:ty, $search:expr) => {
        impl Discriminator for $t {
            const SEARCH: DefaultSearch = $search;
            #[inline]
            fn to_raw(&self) -> i64 {
                *self as i64
            }
            #[inline]
            fn write_raw(w: &mut CdrWriter<'_>, raw: i64) -> Result<(), EncodeError> {
                (raw as $t).encode(w)
            }
            #[inline]
            fn read_raw(r: &mut CdrReader<'_>) -> Result<i64, DecodeError> {
                <$t>::decode(r).map(|v| v as i64)
            }
        }
    };
}

int_discriminator!(i8, DefaultSearch::Down(i8::MIN as i64));
int_discriminator!(i16, DefaultSearch::Down(i16::MIN as i64));
int_discriminator!(i32, DefaultSearch::Down(i32::MIN as i64));
int_discriminator!(i64, DefaultSearch::Down(i64::MIN));
int_discriminator!(u8, DefaultSearch::Up(u8::MAX as i64));
int_discriminator!(u16, DefaultSearch::Up(u16::MAX as i64));
int_discriminator!(u32, DefaultSearch::Up(u32::MAX as i64));
int_discriminator!(u64, DefaultSearch::Up(i64::MAX));

impl Discriminator for bool {
    const SEARCH: DefaultSearch = DefaultSearch::Bool;
    fn to_raw(&self) -> i64 {
        i64::from(*self)
    }
    fn write_raw(w: &mut CdrWriter<'_>, raw: i64) -> Result<(), EncodeError> {
        w.write_u8(u8::from(raw != 0));
        Ok(())
    }
    fn read_raw(r: &mut CdrReader<'_>) -> Result<i64, DecodeError> {
        bool::decode(r).map(i64::from)
    }
}

impl Discriminator for super::WChar {
    const SEARCH: DefaultSearch = DefaultSearch::Up(0xffff);
    fn to_raw(&self) -> i64 {
        i64::from(self.0)
    }
    fn write_raw(w: &mut CdrWriter<'_>, raw: i64) -> Result<(), EncodeError> {
        w.write_u16(raw as u16);
        Ok(())
    }
    fn read_raw(r: &mut CdrReader<'_>) -> Result<i64, DecodeError> {
        r.read_u16("wchar discriminator").map(i64::from)
    }
}

impl Discriminator for char {
    const SEARCH: DefaultSearch = DefaultSearch::Up(127);
    fn to_raw(&self) -> i64 {
        i64::from(u32::from(*self))
    }
    fn write_raw(w: &mut CdrWriter<'_>, raw: i64) -> Result<(), EncodeError> {
        w.write_u8(raw as u8);
        Ok(())
    }
    fn read_raw(r: &mut CdrReader<'_>) -> Result<i64, DecodeError> {
        r.read_u8("char8 discriminator").map(i64::from)
    }
}
