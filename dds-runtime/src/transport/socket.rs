//! Socket creation and options. Linux-only options sit behind `cfg`; elsewhere the portable subset is used.

use std::io;
use std::net::{Ipv4Addr, SocketAddrV4};

use socket2::{Domain, InterfaceIndexOrAddress, Protocol, Socket, Type};

use super::iface::Interface;

fn new_udp() -> io::Result<Socket> {
    Socket::new(Domain::IPV4, Type::DGRAM, Some(Protocol::UDP))
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
    let s = new_udp()?;
    set_buffers(&s, buf);
    s.set_multicast_if_v4(&iface.addr)?;
    s.set_multicast_loop_v4(true)?;
    s.set_multicast_ttl_v4(1)?;
    s.bind(&SocketAddrV4::new(Ipv4Addr::UNSPECIFIED, port).into())?;
    Ok(s)
}

/// The shared multicast socket: every participant on the host binds the same port.
pub(super) fn multicast_socket(
    iface: &Interface,
    group: Ipv4Addr,
    port: u16,
    buf: usize,
) -> io::Result<Socket> {
    let s = new_udp()?;
    s.set_reuse_address(true)?;
    // Windows shares the port with SO_REUSEADDR alone; the BSDs and Linux need SO_REUSEPORT too.
    #[cfg(all(
        unix,
        not(any(target_os = "solaris", target_os = "illumos", target_os = "cygwin"))
    ))]
    s.set_reuse_port(true)?;
    set_buffers(&s, buf);
    s.bind(&SocketAddrV4::new(Ipv4Addr::UNSPECIFIED, port).into())?;
    // Without this, Linux delivers to a wildcard-bound socket the groups joined by any socket on the host.
    #[cfg(target_os = "linux")]
    s.set_multicast_all_v4(false)?;
    let on = match iface.index {
        0 => InterfaceIndexOrAddress::Address(iface.addr),
        index => InterfaceIndexOrAddress::Index(index),
    };
    s.join_multicast_v4_n(&group, &on)?;
    Ok(s)
}
