//! The RTPS UDPv4 port formula (DDSI-RTPS 2.5 §9.6.1.1) with the default parameters.

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

/// The SPDP multicast group.
pub const SPDP_MULTICAST_GROUP: Ipv4Addr = Ipv4Addr::new(239, 255, 0, 1);

fn port(v: u32) -> Option<u16> {
    u16::try_from(v).ok()
}

/// SPDP multicast port of `domain`.
pub fn spdp_multicast(domain: u32) -> Option<u16> {
    port(PB.checked_add(DG.checked_mul(domain)?)?.checked_add(D0)?)
}

/// User-traffic multicast port of `domain`.
pub fn user_multicast(domain: u32) -> Option<u16> {
    port(PB.checked_add(DG.checked_mul(domain)?)?.checked_add(D2)?)
}

/// Metatraffic unicast port of participant `index` in `domain`.
pub fn metatraffic_unicast(domain: u32, index: u32) -> Option<u16> {
    port(
        PB.checked_add(DG.checked_mul(domain)?)?
            .checked_add(D1)?
            .checked_add(PG.checked_mul(index)?)?,
    )
}

/// User-traffic unicast port of participant `index` in `domain`.
pub fn user_unicast(domain: u32, index: u32) -> Option<u16> {
    port(
        PB.checked_add(DG.checked_mul(domain)?)?
            .checked_add(D3)?
            .checked_add(PG.checked_mul(index)?)?,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formula_matches_the_spec_table() {
        assert_eq!(spdp_multicast(0), Some(7400));
        assert_eq!(user_multicast(0), Some(7401));
        assert_eq!(metatraffic_unicast(0, 0), Some(7410));
        assert_eq!(user_unicast(0, 0), Some(7411));
        assert_eq!(metatraffic_unicast(1, 2), Some(7664));
        assert_eq!(user_unicast(1, 2), Some(7665));
        assert_eq!(spdp_multicast(232), Some(65400));
        assert_eq!(spdp_multicast(233), None);
        assert_eq!(user_unicast(0, u32::MAX), None);
    }
}
