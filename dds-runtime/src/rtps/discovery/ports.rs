//! The standard port mapping (DDSI-RTPS 2.5 §9.6.1.1): PB 7400, DG 250, PG 2, d0 0, d1 10, d2 1, d3 11.
//! Pure functions; the transport probes participant indexes with them. Results saturate at u16::MAX+1
//! boundaries by returning `None` from the checked variants when a port would not fit.

pub const PB: u32 = 7400;
pub const DG: u32 = 250;
pub const PG: u32 = 2;
pub const D0: u32 = 0;
pub const D1: u32 = 10;
pub const D2: u32 = 1;
pub const D3: u32 = 11;

/// SPDP multicast port: PB + DG·domain + d0.
pub fn spdp_multicast(domain: u32) -> u16 {
    checked(PB + DG * domain + D0)
}
/// Metatraffic (SPDP/SEDP) unicast port: PB + DG·domain + d1 + PG·participant.
pub fn metatraffic_unicast(domain: u32, participant: u32) -> u16 {
    checked(PB + DG * domain + D1 + PG * participant)
}
/// User-traffic multicast port: PB + DG·domain + d2.
pub fn user_multicast(domain: u32) -> u16 {
    checked(PB + DG * domain + D2)
}
/// User-traffic unicast port: PB + DG·domain + d3 + PG·participant.
pub fn user_unicast(domain: u32, participant: u32) -> u16 {
    checked(PB + DG * domain + D3 + PG * participant)
}

/// Whether the domain and participant index give valid (≤ 65535) ports.
pub fn valid(domain: u32, participant: u32) -> bool {
    domain <= 232
        && (PB as u64 + DG as u64 * domain as u64 + D3 as u64 + PG as u64 * participant as u64)
            <= 65535
}

fn checked(p: u32) -> u16 {
    u16::try_from(p).unwrap_or(u16::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_ports() {
        assert_eq!(spdp_multicast(0), 7400);
        assert_eq!(user_multicast(0), 7401);
        assert_eq!(metatraffic_unicast(0, 0), 7410);
        assert_eq!(user_unicast(0, 0), 7411);
        assert_eq!(metatraffic_unicast(0, 1), 7412);
        assert_eq!(user_unicast(1, 2), 7400 + 250 + 11 + 4);
        assert!(valid(232, 0));
        assert!(!valid(233, 0));
    }
}
