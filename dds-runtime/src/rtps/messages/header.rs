//! The 20-byte RTPS message header (§9.4.4).

use super::{Cursor, WireError};
use crate::rtps::types::{GuidPrefix, ProtocolVersion, VendorId};

pub(crate) const HEADER_LEN: usize = 20;

/// The RTPS message header (§9.4.4): protocol version, vendor and the sender's GUID prefix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Header {
    /// The sender's protocol version.
    pub version: ProtocolVersion,
    /// The sender's vendor.
    pub vendor_id: VendorId,
    /// The sender's GUID prefix, the source of every submessage until an INFO_SRC.
    pub guid_prefix: GuidPrefix,
}

impl Header {
    /// Parses the header; returns it and the submessages that follow.
    pub fn parse(data: &[u8]) -> Result<(Header, &[u8]), WireError> {
        let mut c = Cursor::new(data, false);
        let magic = c.bytes(4).map_err(|_| WireError::NotRtps)?;
        if magic != b"RTPS" {
            return Err(WireError::NotRtps);
        }
        let major = c.u8()?;
        let minor = c.u8()?;
        // A different major version has a different message format: drop (§8.3.4.1).
        if major != 2 {
            return Err(WireError::Version(major, minor));
        }
        let vendor_id = VendorId(c.array()?);
        let guid_prefix = c.guid_prefix()?;
        Ok((
            Header {
                version: ProtocolVersion { major, minor },
                vendor_id,
                guid_prefix,
            },
            c.rest(),
        ))
    }

    /// Appends the 20-byte header.
    pub fn write(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(b"RTPS");
        out.push(self.version.major);
        out.push(self.version.minor);
        out.extend_from_slice(&self.vendor_id.0);
        out.extend_from_slice(&self.guid_prefix.0);
    }
}
