//! Network interface discovery and selection, IPv4 and IPv6.
//!
//! On Unix the list comes from `getifaddrs`; elsewhere from [`list_portable`], which knows only the loopback
//! addresses and the IPv4 address the host would send multicast from.

use std::io;
use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddrV4, UdpSocket};

use crate::config::{AddressFamily, InterfaceSelection};

/// One address (IPv4 or IPv6) of one network interface.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Interface {
    /// Interface name, e.g. `lo`.
    pub name: String,
    /// Kernel interface index.
    pub index: u32,
    /// The address.
    pub addr: IpAddr,
    /// IFF_UP.
    pub up: bool,
    /// IFF_LOOPBACK.
    pub loopback: bool,
    /// IFF_MULTICAST.
    pub multicast: bool,
}

/// All IPv4 and IPv6 interface addresses of this host (of this network namespace).
pub fn list() -> io::Result<Vec<Interface>> {
    os_list()
}

#[cfg(not(unix))]
fn os_list() -> io::Result<Vec<Interface>> {
    list_portable()
}

/// The portable fallback of [`list`]: loopback (`lo`, index 0, 127.0.0.1 and ::1), and the address the host
/// picks as the source of a datagram to the SPDP multicast group (`default`, index 0: multicast is joined by
/// address), when there is a route. Connecting a UDP socket sends nothing.
pub fn list_portable() -> io::Result<Vec<Interface>> {
    let lo = |addr: IpAddr| Interface {
        name: "lo".into(),
        index: 0,
        addr,
        up: true,
        loopback: true,
        multicast: true,
    };
    let mut out = vec![
        lo(Ipv4Addr::LOCALHOST.into()),
        lo(Ipv6Addr::LOCALHOST.into()),
    ];
    let probe = UdpSocket::bind(SocketAddrV4::new(Ipv4Addr::UNSPECIFIED, 0))?;
    let group = crate::rtps::discovery::ports::SPDP_MULTICAST_GROUP;
    if probe.connect(SocketAddrV4::new(group, 7400)).is_ok() {
        if let Ok(std::net::SocketAddr::V4(a)) = probe.local_addr() {
            if !a.ip().is_loopback() && !a.ip().is_unspecified() {
                out.push(Interface {
                    name: "default".into(),
                    index: 0,
                    addr: IpAddr::V4(*a.ip()),
                    up: true,
                    loopback: false,
                    multicast: true,
                });
            }
        }
    }
    Ok(out)
}

/// Every AF_INET and AF_INET6 address of `getifaddrs`.
#[cfg(unix)]
fn os_list() -> io::Result<Vec<Interface>> {
    use std::ffi::CStr;
    let mut out = Vec::new();
    let mut head: *mut libc::ifaddrs = std::ptr::null_mut();
    // SAFETY: getifaddrs fills `head` with a list we free below with freeifaddrs.
    if unsafe { libc::getifaddrs(&mut head) } != 0 {
        return Err(io::Error::last_os_error());
    }
    let mut cur = head;
    while !cur.is_null() {
        // SAFETY: `cur` is a node of the list returned by getifaddrs, valid until freeifaddrs.
        let ifa = unsafe { &*cur };
        cur = ifa.ifa_next;
        if ifa.ifa_addr.is_null() || ifa.ifa_name.is_null() {
            continue;
        }
        // SAFETY: ifa_addr is non-null and points to a sockaddr of the family it declares.
        let family = unsafe { (*ifa.ifa_addr).sa_family } as i32;
        let addr = if family == libc::AF_INET {
            // SAFETY: family is AF_INET, so the address is a sockaddr_in.
            let sin = unsafe { &*(ifa.ifa_addr as *const libc::sockaddr_in) };
            IpAddr::V4(Ipv4Addr::from(u32::from_be(sin.sin_addr.s_addr)))
        } else if family == libc::AF_INET6 {
            // SAFETY: family is AF_INET6, so the address is a sockaddr_in6.
            let sin6 = unsafe { &*(ifa.ifa_addr as *const libc::sockaddr_in6) };
            IpAddr::V6(Ipv6Addr::from(sin6.sin6_addr.s6_addr))
        } else {
            continue;
        };
        // SAFETY: ifa_name is a NUL-terminated C string owned by the list.
        let name = unsafe { CStr::from_ptr(ifa.ifa_name) }
            .to_string_lossy()
            .into_owned();
        let flags = ifa.ifa_flags;
        // SAFETY: ifa_name is a valid C string.
        let index = unsafe { libc::if_nametoindex(ifa.ifa_name) };
        out.push(Interface {
            name,
            index,
            addr,
            up: flags & libc::IFF_UP as u32 != 0,
            loopback: flags & libc::IFF_LOOPBACK as u32 != 0,
            multicast: flags & libc::IFF_MULTICAST as u32 != 0,
        });
    }
    // SAFETY: `head` came from getifaddrs and is freed once.
    unsafe { libc::freeifaddrs(head) };
    Ok(out)
}

/// Picks the IPv4 interface described by `sel` from `all` (see [`select_in`]).
pub fn select(sel: &InterfaceSelection, all: &[Interface]) -> io::Result<Interface> {
    select_in(AddressFamily::Ipv4, sel, all)
}

/// Picks the interface described by `sel` from the addresses of `family` in `all`. By name, an IPv6
/// interface's global (or unique-local) address is preferred to its link-local one, which needs a scope.
pub fn select_in(
    family: AddressFamily,
    sel: &InterfaceSelection,
    all: &[Interface],
) -> io::Result<Interface> {
    let mut of: Vec<&Interface> = all.iter().filter(|i| family.contains(i.addr)).collect();
    // Stable: link-local IPv6 addresses after the others of the same interface.
    of.sort_by_key(|i| is_link_local(i.addr));
    let found = match sel {
        InterfaceSelection::Name(n) => of.iter().find(|i| &i.name == n),
        InterfaceSelection::Address(a) => of.iter().find(|i| &i.addr == a),
        InterfaceSelection::Auto => of
            .iter()
            .find(|i| i.up && i.multicast && !i.loopback)
            .or_else(|| of.iter().find(|i| i.up && i.loopback))
            .or_else(|| of.first()),
    };
    found.map(|i| (*i).clone()).ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::NotFound,
            format!(
                "no {family:?} interface matches {sel:?} (have: {:?})",
                names(all)
            ),
        )
    })
}

fn is_link_local(a: IpAddr) -> bool {
    matches!(a, IpAddr::V6(v6) if v6.segments()[0] & 0xffc0 == 0xfe80)
}

fn names(all: &[Interface]) -> Vec<String> {
    all.iter()
        .map(|i| format!("{}={}", i.name, i.addr))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ifs() -> Vec<Interface> {
        vec![
            Interface {
                name: "lo".into(),
                index: 1,
                addr: Ipv4Addr::LOCALHOST.into(),
                up: true,
                loopback: true,
                multicast: false,
            },
            Interface {
                name: "eth0".into(),
                index: 2,
                addr: Ipv4Addr::new(10, 0, 0, 5).into(),
                up: true,
                loopback: false,
                multicast: true,
            },
        ]
    }

    #[test]
    fn selects_by_name_address_and_auto() {
        let all = ifs();
        assert_eq!(
            select(&InterfaceSelection::Name("lo".into()), &all)
                .unwrap()
                .index,
            1
        );
        assert_eq!(
            select(
                &InterfaceSelection::Address(Ipv4Addr::new(10, 0, 0, 5).into()),
                &all
            )
            .unwrap()
            .name,
            "eth0"
        );
        assert_eq!(
            select(&InterfaceSelection::Auto, &all).unwrap().name,
            "eth0"
        );
        assert_eq!(
            select(&InterfaceSelection::Auto, &all[..1]).unwrap().name,
            "lo"
        );
        assert!(select(&InterfaceSelection::Name("wlan9".into()), &all).is_err());
    }

    #[test]
    fn host_has_some_ipv4_interface() {
        let all = list().unwrap();
        assert!(all.iter().any(|i| i.loopback), "{all:?}");
    }

    #[test]
    fn portable_list_has_loopback_first() {
        let all = list_portable().unwrap();
        assert_eq!(all[0].addr, Ipv4Addr::LOCALHOST);
        assert!(all.iter().any(|i| i.addr == Ipv6Addr::LOCALHOST), "{all:?}");
        assert!(
            all.iter().all(|i| i.up && !i.addr.is_unspecified()),
            "{all:?}"
        );
        assert_eq!(
            select(&InterfaceSelection::Name("lo".into()), &all)
                .unwrap()
                .addr,
            Ipv4Addr::LOCALHOST
        );
    }

    #[test]
    fn selects_within_the_address_family() {
        let mut all = ifs();
        let v6 = |name: &str, index, addr: &str, loopback| Interface {
            name: name.into(),
            index,
            addr: addr.parse().unwrap(),
            up: true,
            loopback,
            multicast: !loopback,
        };
        all.push(v6("eth0", 2, "fe80::1", false));
        all.push(v6("eth0", 2, "fd00::5", false));
        all.push(v6("lo", 1, "::1", true));
        let pick =
            |sel: &InterfaceSelection| select_in(AddressFamily::Ipv6, sel, &all).unwrap().addr;
        assert_eq!(
            pick(&InterfaceSelection::Auto),
            "fd00::5".parse::<IpAddr>().unwrap()
        );
        assert_eq!(
            pick(&InterfaceSelection::Name("eth0".into())),
            "fd00::5".parse::<IpAddr>().unwrap()
        );
        assert_eq!(
            pick(&InterfaceSelection::Name("lo".into())),
            IpAddr::from(Ipv6Addr::LOCALHOST)
        );
        assert_eq!(
            pick(&InterfaceSelection::Address("fe80::1".parse().unwrap())),
            "fe80::1".parse::<IpAddr>().unwrap()
        );
        assert!(select_in(
            AddressFamily::Ipv6,
            &InterfaceSelection::Address(Ipv4Addr::LOCALHOST.into()),
            &all
        )
        .is_err());
        assert_eq!(
            select(&InterfaceSelection::Name("eth0".into()), &all)
                .unwrap()
                .addr,
            IpAddr::from(Ipv4Addr::new(10, 0, 0, 5))
        );
    }
}
