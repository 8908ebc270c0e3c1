//! Encapsulation header (RTPS 2.5 §10, XTypes 1.3 §7.6.3.1.2) and the enums that select an encoding.

use super::error::{DecodeError, DecodeErrorKind};

/// Extended CDR version.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum XcdrVersion {
    /// XCDR version 1 (classic CDR and PL_CDR); primitives align up to 8.
    Xcdr1,
    /// XCDR version 2 (PLAIN_CDR2, DELIMITED_CDR2, PL_CDR2); alignment capped at 4.
    Xcdr2,
}

impl XcdrVersion {
    /// Largest alignment a primitive gets in this version.
    pub const fn max_align(self) -> usize {
        match self {
            XcdrVersion::Xcdr1 => 8,
            XcdrVersion::Xcdr2 => 4,
        }
    }
}

/// Byte order of the encoded data.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ByteOrder {
    /// Most significant byte first.
    BigEndian,
    /// Least significant byte first.
    LittleEndian,
}

impl ByteOrder {
    /// The byte order of the machine we run on.
    #[cfg(target_endian = "little")]
    pub const NATIVE: ByteOrder = ByteOrder::LittleEndian;
    /// The byte order of the machine we run on.
    #[cfg(target_endian = "big")]
    pub const NATIVE: ByteOrder = ByteOrder::BigEndian;

    /// Whether this is the host byte order (enables bulk copies).
    #[inline]
    pub const fn is_native(self) -> bool {
        matches!(
            (self, ByteOrder::NATIVE),
            (ByteOrder::BigEndian, ByteOrder::BigEndian)
                | (ByteOrder::LittleEndian, ByteOrder::LittleEndian)
        )
    }
}

/// XTypes extensibility kind of a constructed type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Extensibility {
    /// `@final`: members cannot be added.
    Final,
    /// `@appendable`: members can be added at the end (DHEADER in XCDR2).
    Appendable,
    /// `@mutable`: members can be added anywhere (parameter lists).
    Mutable,
}

/// The encoding named by a representation id, without its byte order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Representation {
    /// 0x0000/0x0001: XCDR1 plain CDR.
    Cdr,
    /// 0x0002/0x0003: XCDR1 parameter list.
    PlCdr,
    /// 0x0006/0x0007: XCDR2 plain.
    Cdr2,
    /// 0x0008/0x0009: XCDR2 delimited.
    DCdr2,
    /// 0x000a/0x000b: XCDR2 parameter list.
    PlCdr2,
}

impl Representation {
    /// The encoding a top-level type of extensibility `ext` uses in `version`.
    pub const fn for_type(version: XcdrVersion, ext: Extensibility) -> Self {
        match (version, ext) {
            (XcdrVersion::Xcdr1, Extensibility::Mutable) => Representation::PlCdr,
            (XcdrVersion::Xcdr1, _) => Representation::Cdr,
            (XcdrVersion::Xcdr2, Extensibility::Final) => Representation::Cdr2,
            (XcdrVersion::Xcdr2, Extensibility::Appendable) => Representation::DCdr2,
            (XcdrVersion::Xcdr2, Extensibility::Mutable) => Representation::PlCdr2,
        }
    }

    /// The XCDR version of this encoding.
    pub const fn version(self) -> XcdrVersion {
        match self {
            Representation::Cdr | Representation::PlCdr => XcdrVersion::Xcdr1,
            _ => XcdrVersion::Xcdr2,
        }
    }

    const fn base_id(self) -> u16 {
        match self {
            Representation::Cdr => 0x0000,
            Representation::PlCdr => 0x0002,
            Representation::Cdr2 => 0x0006,
            Representation::DCdr2 => 0x0008,
            Representation::PlCdr2 => 0x000a,
        }
    }
}

/// The 4-byte encapsulation header that starts every serialized payload.
///
/// The representation id is big-endian; its low bit gives the byte order of the data. The options field carries
/// the number of padding bytes appended to the data in its low 2 bits (as Cyclone DDS writes it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct EncapsulationHeader {
    /// Representation identifier, e.g. 0x0001 for little-endian plain CDR.
    pub representation_id: u16,
    /// Representation options; bits 0..1 hold the trailing padding count.
    pub options: u16,
}

impl EncapsulationHeader {
    /// Size of the header on the wire.
    pub const SIZE: usize = 4;

    /// Builds the header for `repr` in byte order `order`, with no padding.
    pub const fn new(repr: Representation, order: ByteOrder) -> Self {
        let le = match order {
            ByteOrder::BigEndian => 0,
            ByteOrder::LittleEndian => 1,
        };
        EncapsulationHeader {
            representation_id: repr.base_id() | le,
            options: 0,
        }
    }

    /// The header for a top-level type of extensibility `ext`.
    pub const fn for_type(version: XcdrVersion, ext: Extensibility, order: ByteOrder) -> Self {
        Self::new(Representation::for_type(version, ext), order)
    }

    /// Parses the first 4 bytes of `payload`.
    pub fn parse(payload: &[u8]) -> Result<Self, DecodeError> {
        if payload.len() < Self::SIZE {
            return Err(DecodeError::new(
                0,
                "encapsulation header",
                DecodeErrorKind::UnexpectedEof {
                    needed: Self::SIZE,
                    available: payload.len(),
                },
            ));
        }
        let h = EncapsulationHeader {
            representation_id: u16::from_be_bytes([payload[0], payload[1]]),
            options: u16::from_be_bytes([payload[2], payload[3]]),
        };
        h.representation()?;
        Ok(h)
    }

    /// The header as it goes on the wire.
    pub const fn to_bytes(self) -> [u8; 4] {
        let r = self.representation_id.to_be_bytes();
        let o = self.options.to_be_bytes();
        [r[0], r[1], o[0], o[1]]
    }

    /// The encoding named by the representation id.
    pub fn representation(&self) -> Result<Representation, DecodeError> {
        Ok(match self.representation_id & !1 {
            0x0000 => Representation::Cdr,
            0x0002 => Representation::PlCdr,
            0x0006 => Representation::Cdr2,
            0x0008 => Representation::DCdr2,
            0x000a => Representation::PlCdr2,
            _ => {
                return Err(DecodeError::new(
                    0,
                    "a CDR/PL_CDR/CDR2/D_CDR2/PL_CDR2 representation id",
                    DecodeErrorKind::InvalidValue {
                        found: u64::from(self.representation_id),
                    },
                ))
            }
        })
    }

    /// The XCDR version of the payload.
    pub fn version(&self) -> Result<XcdrVersion, DecodeError> {
        Ok(self.representation()?.version())
    }

    /// The byte order of the payload.
    pub const fn byte_order(&self) -> ByteOrder {
        if self.representation_id & 1 == 1 {
            ByteOrder::LittleEndian
        } else {
            ByteOrder::BigEndian
        }
    }

    /// Number of padding bytes at the end of the payload (options bits 0..1).
    pub const fn padding(&self) -> usize {
        (self.options & 3) as usize
    }

    /// Returns the header with the padding count set.
    pub const fn with_padding(self, padding: usize) -> Self {
        EncapsulationHeader {
            representation_id: self.representation_id,
            options: (self.options & !3) | (padding as u16 & 3),
        }
    }
}
