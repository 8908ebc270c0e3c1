//! Who wrote a sample: the writer's GUID, and the DDS implementation its vendor id names.

use std::fmt;

/// A remote writer's GUID (prefix, then entity id).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct WriterId(pub [u8; 16]);

impl WriterId {
    /// The GUID prefix: the participant.
    pub fn prefix(&self) -> [u8; 12] {
        let mut p = [0; 12];
        p.copy_from_slice(&self.0[..12]);
        p
    }

    /// The implementation that made the participant, from the vendor id that implementations put in the
    /// first two bytes of their GUID prefixes (OMG's vendor id list).
    pub fn vendor(&self) -> &'static str {
        match [self.0[0], self.0[1]] {
            [0x01, 0xdd] => "dds-rs",
            [0x01, 0x10] => "Cyclone DDS",
            [0x01, 0x0f] => "Fast DDS",
            [0x01, 0x01] => "Connext",
            [0x01, 0x02] | [0x01, 0x11] => "OpenSplice",
            [0x01, 0x03] => "OpenDDS",
            [0x01, 0x06] => "CoreDX",
            [0x01, 0x0c] => "InterCOM",
            _ => "unknown",
        }
    }
}

impl fmt::Display for WriterId {
    /// The participant part in hex, in groups of four bytes, as DDS tools print GUIDs.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, chunk) in self.0[..12].chunks(4).enumerate() {
            if i > 0 {
                f.write_str(":")?;
            }
            for b in chunk {
                write!(f, "{b:02x}")?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vendor_and_text() {
        let mut g = [0u8; 16];
        g[..4].copy_from_slice(&[0x01, 0x10, 0xab, 0xcd]);
        let w = WriterId(g);
        assert_eq!(w.vendor(), "Cyclone DDS");
        assert_eq!(w.to_string(), "0110abcd:00000000:00000000");
        assert_eq!(w.prefix()[..2], [0x01, 0x10]);
    }
}
