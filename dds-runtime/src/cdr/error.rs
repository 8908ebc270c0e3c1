//! Encode and decode errors.

use thiserror::Error;

/// Why a sample could not be encoded.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum EncodeError {
    /// A string, sequence or map is longer than its IDL bound (never truncated).
    #[error("{what}: length {len} exceeds the bound {bound}")]
    BoundExceeded {
        /// What was being encoded.
        what: &'static str,
        /// The IDL bound.
        bound: usize,
        /// The actual length.
        len: usize,
    },
    /// A value has no representation in the IDL type (e.g. a `char` above U+00FF, a NUL inside a string).
    #[error("{what}: value {value:#x} cannot be represented")]
    InvalidValue {
        /// What was being encoded.
        what: &'static str,
        /// The offending value.
        value: u64,
    },
    /// A length does not fit its wire field (u32 lengths, 28-bit member ids, ...).
    #[error("{what}: {len} does not fit the wire format")]
    TooLarge {
        /// What was being encoded.
        what: &'static str,
        /// The length or id.
        len: u64,
    },
    /// The value nests deeper than [`MAX_DEPTH`](super::MAX_DEPTH).
    #[error("nesting deeper than {limit} levels")]
    DepthExceeded {
        /// The limit.
        limit: u32,
    },
}

/// Why a payload could not be decoded. Always says where and what was expected.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("at offset {offset}: expected {expected}: {kind}")]
pub struct DecodeError {
    /// Byte offset in the payload (the encapsulation header counts, so the first data byte is at 4).
    pub offset: usize,
    /// What the decoder was reading.
    pub expected: &'static str,
    /// What went wrong.
    pub kind: DecodeErrorKind,
}

impl DecodeError {
    /// Builds an error.
    pub fn new(offset: usize, expected: &'static str, kind: DecodeErrorKind) -> Self {
        DecodeError {
            offset,
            expected,
            kind,
        }
    }
}

/// The failure behind a [`DecodeError`].
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum DecodeErrorKind {
    /// The input ends too early.
    #[error("{needed} bytes needed, {available} available")]
    UnexpectedEof {
        /// Bytes needed.
        needed: usize,
        /// Bytes left.
        available: usize,
    },
    /// A length prefix claims more than the remaining input can hold.
    #[error("length {length} cannot fit in the {remaining} bytes left")]
    LengthTooLarge {
        /// The length read.
        length: u64,
        /// Bytes left.
        remaining: usize,
    },
    /// A value outside its domain (bool not 0/1, unknown enumerator, bad id, ...).
    #[error("invalid value {found:#x}")]
    InvalidValue {
        /// The value read.
        found: u64,
    },
    /// A string, sequence or map longer than its IDL bound.
    #[error("length {len} exceeds the bound {bound}")]
    BoundExceeded {
        /// The IDL bound.
        bound: usize,
        /// The length read.
        len: usize,
    },
    /// Bytes that are not valid UTF-8 / UTF-16, or a string without its terminating NUL.
    #[error("malformed string")]
    MalformedString,
    /// A member flagged must-understand that this type does not have.
    #[error("unknown must-understand member id {id:#x}")]
    UnknownMustUnderstand {
        /// The member id.
        id: u32,
    },
    /// A member or element overruns the length given by its enclosing header.
    #[error("overruns its enclosing length by {excess} bytes")]
    Overrun {
        /// Bytes past the end.
        excess: usize,
    },
    /// The payload nests deeper than [`MAX_DEPTH`](super::MAX_DEPTH).
    #[error("nesting deeper than {limit} levels")]
    DepthExceeded {
        /// The limit.
        limit: u32,
    },
}
