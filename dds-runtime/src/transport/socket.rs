//! Socket creation and options. Linux-only options sit behind `cfg`; elsewhere the portable subset is used.

use std::io;
use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr};

use socket2::{Domain, InterfaceIndexOrAddress, Protocol, Socket, Type};

use super::iface::Interface;

/// A UDP socket of the interface's address family; IPv6 sockets are IPv6-only.
fn new_udp(iface: &Interface) -> io::Result<Socket> {
    match iface.addr {
        IpAddr::V4(_) => Socket::new(Domain::IPV4, Type::DGRAM, Some(Protocol::UDP)),
        IpAddr::V6(_) => {
            let s = Socket::new(Domain::IPV6, Type::DGRAM, Some(Protocol::UDP))?;
            s.set_only_v6(true)?;
            Ok(s)
        }
    }
}

/// The wildcard address of the interface's family at `port`.
fn any(iface: &Interface, port: u16) -> SocketAddr {
    match iface.addr {
        IpAddr::V4(_) => (Ipv4Addr::UNSPECIFIED, port).into(),
        IpAddr::V6(_) => (Ipv6Addr::UNSPECIFIED, port).into(),
    }
}

fn set_buffers(s: &Socket, size: usize) {
    // The kernel caps SO_RCVBUF/SO_SNDBUF (Linux: at rmem_max/wmem_max). A smaller buffer is not an error,
    // only lossier under bursts.
    if let Err(e) = s.set_recv_buffer_size(size) {
        tracing::debug!(error = %e, "SO_RCVBUF not applied");
    }
    if let Err(e) = s.set_send_buffer_size(size) {
        tracing::debug!(error = %e, "SO_SNDBUF not applied");
    }
    #[cfg(target_os = "linux")]
    linux::force_buffers(s, size);
    tracing::debug!(
        rcvbuf = s.recv_buffer_size().unwrap_or(0),
        sndbuf = s.send_buffer_size().unwrap_or(0),
        "socket buffers"
    );
}

/// With CAP_NET_ADMIN, the `*FORCE` variants go beyond the kernel's caps.
#[cfg(target_os = "linux")]
mod linux {
    use std::io;
    use std::os::fd::AsRawFd;

    use socket2::Socket;

    pub(super) fn force_buffers(s: &Socket, size: usize) {
        // Linux reports twice the requested value.
        if s.recv_buffer_size().unwrap_or(0) < size {
            force_buffer(s, libc::SO_RCVBUFFORCE, size);
        }
        if s.send_buffer_size().unwrap_or(0) < size {
            force_buffer(s, libc::SO_SNDBUFFORCE, size);
        }
    }

    fn force_buffer(s: &Socket, opt: libc::c_int, size: usize) {
        let v = libc::c_int::try_from(size).unwrap_or(libc::c_int::MAX);
        // SAFETY: plain setsockopt on a valid descriptor with a c_int option value of the right length.
        let r = unsafe {
            libc::setsockopt(
                s.as_raw_fd(),
                libc::SOL_SOCKET,
                opt,
                (&v as *const libc::c_int).cast(),
                std::mem::size_of::<libc::c_int>() as libc::socklen_t,
            )
        };
        if r != 0 {
            tracing::trace!(error = %io::Error::last_os_error(), opt, "forced socket buffer size not applied");
        }
    }
}

/// A unicast socket on `port` (0: ephemeral), also used to send (multicast interface and loop set).
pub(super) fn unicast_socket(iface: &Interface, port: u16, buf: usize) -> io::Result<Socket> {
    let s = new_udp(iface)?;
    set_buffers(&s, buf);
    match iface.addr {
        IpAddr::V4(a) => {
            s.set_multicast_if_v4(&a)?;
            s.set_multicast_loop_v4(true)?;
            s.set_multicast_ttl_v4(1)?;
        }
        IpAddr::V6(_) => {
            s.set_multicast_if_v6(iface.index)?;
            s.set_multicast_loop_v6(true)?;
            s.set_multicast_hops_v6(1)?;
        }
    }
    s.bind(&any(iface, port).into())?;
    Ok(s)
}

/// A multicast socket on `group`: every participant on the host binds the same port (the SPDP group's, or
/// the user-data group's).
pub(super) fn multicast_socket(
    iface: &Interface,
    group: IpAddr,
    port: u16,
    buf: usize,
) -> io::Result<Socket> {
    let s = new_udp(iface)?;
    s.set_reuse_address(true)?;
    // Windows shares the port with SO_REUSEADDR alone; the BSDs and Linux need SO_REUSEPORT too.
    #[cfg(all(
        unix,
        not(any(target_os = "solaris", target_os = "illumos", target_os = "cygwin"))
    ))]
    s.set_reuse_port(true)?;
    set_buffers(&s, buf);
    s.bind(&any(iface, port).into())?;
    match (group, iface.addr) {
        (IpAddr::V4(group), IpAddr::V4(addr)) => {
            // Without this, Linux delivers to a wildcard-bound socket the groups joined by any socket on
            // the host.
            #[cfg(target_os = "linux")]
            s.set_multicast_all_v4(false)?;
            let on = match iface.index {
                0 => InterfaceIndexOrAddress::Address(addr),
                index => InterfaceIndexOrAddress::Index(index),
            };
            s.join_multicast_v4_n(&group, &on)?;
        }
        (IpAddr::V6(group), IpAddr::V6(_)) => {
            #[cfg(target_os = "linux")]
            s.set_multicast_all_v6(false)?;
            s.join_multicast_v6(&group, iface.index)?;
        }
        _ => {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "multicast group {group} is not of the family of {}",
                    iface.addr
                ),
            ))
        }
    }
    Ok(s)
}

/// A socket that only sends, connected to `dest` (see `connected.rs`): an ephemeral port, the kernel's
/// smallest receive buffer, a send buffer of `buf` bytes where the kernel allows.
pub(super) fn connected_socket(
    iface: &Interface,
    dest: SocketAddr,
    buf: usize,
) -> io::Result<std::net::UdpSocket> {
    let s = new_udp(iface)?;
    // The kernel rounds this up to its minimum.
    let _ = s.set_recv_buffer_size(0);
    if let Err(e) = s.set_send_buffer_size(buf) {
        tracing::debug!(error = %e, "SO_SNDBUF not applied");
    }
    s.bind(&any(iface, 0).into())?;
    s.connect(&dest.into())?;
    Ok(s.into())
}
