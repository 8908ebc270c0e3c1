//! The standard UDPv4 port mapping (DDSI-RTPS 2.5 §9.6.1.1): PB 7400, DG 250, PG 2, d0 0, d1 10, d2 1, d3 11.
//!
//! Pure functions, the only copy of the formula: the core fills in default locators with them, the transport
//! binds and probes participant indexes with them and the configuration checks its ranges with them. A port
//! above 65535 is a [`PortError`], never a clamped or wrapped value.

use std::net::Ipv4Addr;

/// Port base.
pub const PB: u32 = 7400;
/// Domain gain.
pub const DG: u32 = 250;
/// Participant gain.
pub const PG: u32 = 2;
/// Offset of the SPDP (metatraffic) multicast port.
pub const D0: u32 = 0;
/// Offset of the metatraffic unicast port.
pub const D1: u32 = 10;
/// Offset of the user-traffic multicast port.
pub const D2: u32 = 1;
/// Offset of the user-traffic unicast port.
pub const D3: u32 = 11;

/// Highest domain id whose ports all fit in 16 bits (PB + DG·232 + d3 = 65411).
pub const MAX_DOMAIN_ID: u32 = 232;

/// The SPDP multicast group.
pub const SPDP_MULTICAST_GROUP: Ipv4Addr = Ipv4Addr::new(239, 255, 0, 1);

/// A domain id or participant index whose port would not fit in 16 bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PortError {
    /// The domain id is above [`MAX_DOMAIN_ID`].
    #[error(
        "domain id {domain} is out of range (0..={MAX_DOMAIN_ID}): its ports would exceed 65535"
    )]
    Domain {
        /// The domain id given.
        domain: u32,
    },
    /// The participant index gives a unicast port above 65535 in this domain.
    #[error("participant index {index} in domain {domain} gives a port above 65535")]
    ParticipantIndex {
        /// The domain id given.
        domain: u32,
        /// The participant index given.
        index: u32,
    },
}

/// PB + DG·domain, when the domain is in range.
fn domain_base(domain: u32) -> Result<u64, PortError> {
    if domain > MAX_DOMAIN_ID {
        return Err(PortError::Domain { domain });
    }
    Ok(u64::from(PB) + u64::from(DG) * u64::from(domain))
}

fn unicast(domain: u32, index: u32, offset: u32) -> Result<u16, PortError> {
    let port = domain_base(domain)? + u64::from(offset) + u64::from(PG) * u64::from(index);
    u16::try_from(port).map_err(|_| PortError::ParticipantIndex { domain, index })
}

fn multicast(domain: u32, offset: u32) -> Result<u16, PortError> {
    let port = domain_base(domain)? + u64::from(offset);
    u16::try_from(port).map_err(|_| PortError::Domain { domain })
}

/// SPDP multicast port: PB + DG·domain + d0.
pub fn spdp_multicast(domain: u32) -> Result<u16, PortError> {
    multicast(domain, D0)
}

/// User-traffic multicast port: PB + DG·domain + d2.
pub fn user_multicast(domain: u32) -> Result<u16, PortError> {
    multicast(domain, D2)
}

/// Metatraffic (SPDP/SEDP) unicast port: PB + DG·domain + d1 + PG·index.
pub fn metatraffic_unicast(domain: u32, index: u32) -> Result<u16, PortError> {
    unicast(domain, index, D1)
}

/// User-traffic unicast port: PB + DG·domain + d3 + PG·index.
pub fn user_unicast(domain: u32, index: u32) -> Result<u16, PortError> {
    unicast(domain, index, D3)
}

/// Checks that every port of participant `index` in `domain` fits (the user unicast port is the highest).
pub fn check(domain: u32, index: u32) -> Result<(), PortError> {
    user_unicast(domain, index).map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formula_matches_the_spec_table() {
        assert_eq!(spdp_multicast(0), Ok(7400));
        assert_eq!(user_multicast(0), Ok(7401));
        assert_eq!(metatraffic_unicast(0, 0), Ok(7410));
        assert_eq!(user_unicast(0, 0), Ok(7411));
        assert_eq!(metatraffic_unicast(0, 1), Ok(7412));
        assert_eq!(metatraffic_unicast(1, 2), Ok(7664));
        assert_eq!(user_unicast(1, 2), Ok(7665));
        assert_eq!(spdp_multicast(232), Ok(65400));
        assert_eq!(user_unicast(232, 0), Ok(65411));
    }

    #[test]
    fn out_of_range_is_an_error() {
        assert_eq!(spdp_multicast(233), Err(PortError::Domain { domain: 233 }));
        assert_eq!(
            metatraffic_unicast(u32::MAX, 0),
            Err(PortError::Domain { domain: u32::MAX })
        );
        assert_eq!(
            user_unicast(0, u32::MAX),
            Err(PortError::ParticipantIndex {
                domain: 0,
                index: u32::MAX
            })
        );
        // 65400 + 11 + 2·62 = 65535 fits; one more index does not.
        assert_eq!(check(232, 62), Ok(()));
        assert_eq!(
            check(232, 63),
            Err(PortError::ParticipantIndex {
                domain: 232,
                index: 63
            })
        );
        assert!(check(232, 0).is_ok());
        assert!(check(233, 0).is_err());
    }
}
