//! RTPS 2.5 message codec (§9.4): header, submessages and parameter lists.
//!
//! Decoding borrows from the datagram and allocates nothing. Any malformed input yields a [`WireError`];
//! nothing here panics on input.

mod codec;
mod cursor;
pub mod flags;
mod header;
pub mod parameter;
mod submessages;

pub use codec::{MessageBuilder, MessageIter};
pub(crate) use cursor::Cursor;
pub use header::Header;
pub(crate) use header::HEADER_LEN;
pub use parameter::{Parameter, ParameterList, ParameterWriter};
pub use submessages::*;

/// Submessage ids (§9.4.5.1.1).
pub mod id {
    pub const PAD: u8 = 0x01;
    pub const ACKNACK: u8 = 0x06;
    pub const HEARTBEAT: u8 = 0x07;
    pub const GAP: u8 = 0x08;
    pub const INFO_TS: u8 = 0x09;
    pub const INFO_SRC: u8 = 0x0c;
    pub const INFO_REPLY_IP4: u8 = 0x0d;
    pub const INFO_DST: u8 = 0x0e;
    pub const INFO_REPLY: u8 = 0x0f;
    pub const NACK_FRAG: u8 = 0x12;
    pub const HEARTBEAT_FRAG: u8 = 0x13;
    pub const DATA: u8 = 0x15;
    pub const DATA_FRAG: u8 = 0x16;
}

/// Why a message or submessage was rejected.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WireError {
    #[error("truncated input")]
    Truncated,
    #[error("not an RTPS message")]
    NotRtps,
    #[error("unsupported protocol version {0}.{1}")]
    Version(u8, u8),
    #[error("invalid {0}")]
    Invalid(&'static str),
    #[error("parameter {0:#06x} must be understood")]
    MustUnderstand(u16),
}
