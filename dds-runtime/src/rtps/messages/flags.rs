//! The flag bits of each submessage kind (RTPS 2.5 §9.4.5), the second byte of a submessage header. Bit 0
//! (E, `ENDIANNESS`) is common to all kinds: set when the submessage is little-endian.

use bitflags::bitflags;

bitflags! {
    /// Flags of ACKNACK (§9.4.5.2).
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct AckNackFlags: u8 {
        /// E: little-endian body.
        const ENDIANNESS = 0x01;
        /// F: the reader does not require an answer.
        const FINAL = 0x02;
    }

    /// Flags of HEARTBEAT (§9.4.5.6).
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct HeartbeatFlags: u8 {
        /// E: little-endian body.
        const ENDIANNESS = 0x01;
        /// F: the writer does not require an answer.
        const FINAL = 0x02;
        /// L: the heartbeat also asserts the writer's liveliness.
        const LIVELINESS = 0x04;
        /// G: GroupInfo (current, first and last group sequence numbers, writer set) follows the count.
        const GROUP_INFO = 0x08;
    }

    /// Flags of INFO_TS (§9.4.5.9).
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct InfoTsFlags: u8 {
        /// E: little-endian body.
        const ENDIANNESS = 0x01;
        /// I: no timestamp follows; later submessages have none.
        const INVALIDATE = 0x02;
    }

    /// Flags of INFO_REPLY and INFO_REPLY_IP4 (§9.4.5.10, §9.4.5.11).
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct InfoReplyFlags: u8 {
        /// E: little-endian body.
        const ENDIANNESS = 0x01;
        /// M: a multicast locator list follows the unicast one.
        const MULTICAST = 0x02;
    }

    /// Flags of DATA (§9.4.5.3).
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct DataFlags: u8 {
        /// E: little-endian body.
        const ENDIANNESS = 0x01;
        /// Q: inline QoS follow the fixed fields.
        const INLINE_QOS = 0x02;
        /// D: the payload is serialized data.
        const DATA = 0x04;
        /// K: the payload is a serialized key.
        const KEY = 0x08;
        /// N: the payload is not serialized by standard means.
        const NON_STANDARD = 0x10;
    }

    /// Flags of DATA_FRAG (§9.4.5.4).
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct DataFragFlags: u8 {
        /// E: little-endian body.
        const ENDIANNESS = 0x01;
        /// Q: inline QoS follow the fixed fields.
        const INLINE_QOS = 0x02;
        /// K: the fragments are of a serialized key.
        const KEY = 0x04;
        /// N: the payload is not serialized by standard means.
        const NON_STANDARD = 0x08;
    }
}

bitflags! {
    /// The flags in the last byte of the PID_STATUS_INFO inline QoS (§9.6.4.9).
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct StatusInfo: u8 {
        /// D: the instance was disposed.
        const DISPOSED = 0x01;
        /// U: the instance was unregistered.
        const UNREGISTERED = 0x02;
        /// F: the sample was filtered out for this reader.
        const FILTERED = 0x04;
    }
}
