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
    /// PAD.
    pub const PAD: u8 = 0x01;
    /// ACKNACK.
    pub const ACKNACK: u8 = 0x06;
    /// HEARTBEAT.
    pub const HEARTBEAT: u8 = 0x07;
    /// GAP.
    pub const GAP: u8 = 0x08;
    /// INFO_TS.
    pub const INFO_TS: u8 = 0x09;
    /// INFO_SRC.
    pub const INFO_SRC: u8 = 0x0c;
    /// INFO_REPLY_IP4.
    pub const INFO_REPLY_IP4: u8 = 0x0d;
    /// INFO_DST.
    pub const INFO_DST: u8 = 0x0e;
    /// INFO_REPLY.
    pub const INFO_REPLY: u8 = 0x0f;
    /// NACK_FRAG.
    pub const NACK_FRAG: u8 = 0x12;
    /// HEARTBEAT_FRAG.
    pub const HEARTBEAT_FRAG: u8 = 0x13;
    /// DATA.
    pub const DATA: u8 = 0x15;
    /// DATA_FRAG.
    pub const DATA_FRAG: u8 = 0x16;
}

/// Why a message or submessage was rejected.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WireError {
    /// The input ends before the structure does.
    #[error("truncated input")]
    Truncated,
    /// The message does not start with "RTPS".
    #[error("not an RTPS message")]
    NotRtps,
    /// A protocol major version other than 2.
    #[error("unsupported protocol version {0}.{1}")]
    Version(u8, u8),
    /// A field has a value the protocol does not allow (the field is named).
    #[error("invalid {0}")]
    Invalid(&'static str),
    /// A parameter with the must-understand bit that we do not know.
    #[error("parameter {0:#06x} must be understood")]
    MustUnderstand(u16),
}
