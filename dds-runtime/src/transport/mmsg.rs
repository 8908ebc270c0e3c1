//! Linux `recvmmsg`: one system call reads up to [`RECV_BATCH`] queued datagrams.

use std::io;
use std::net::{Ipv4Addr, Ipv6Addr, SocketAddr, SocketAddrV4, SocketAddrV6, UdpSocket};
use std::os::fd::AsRawFd;

use super::datagram::{Datagram, RecvBatch, MAX_BATCH, RECV_BUFFER};

/// Datagrams received per `recvmmsg` call.
const RECV_BATCH: usize = MAX_BATCH;

/// Buffers for one `recvmmsg` call. The pointers inside `hdrs` point into the other vectors' heap storage,
/// which never reallocates after construction.
pub(super) struct MmsgBatch {
    bufs: Vec<Vec<u8>>,
    addrs: Vec<libc::sockaddr_storage>,
    /// Never read from Rust: `hdrs` point into it, so it must live as long as the batch.
    #[allow(dead_code)]
    iovs: Vec<libc::iovec>,
    hdrs: Vec<libc::mmsghdr>,
}

// SAFETY: the raw pointers only reference the batch's own heap buffers; the batch is used by one thread.
unsafe impl Send for MmsgBatch {}

impl MmsgBatch {
    pub(super) fn new() -> Self {
        let mut bufs: Vec<Vec<u8>> = (0..RECV_BATCH).map(|_| vec![0u8; RECV_BUFFER]).collect();
        // SAFETY: sockaddr_storage and mmsghdr are plain C structs for which all-zero is valid.
        let mut addrs: Vec<libc::sockaddr_storage> = (0..RECV_BATCH)
            .map(|_| unsafe { std::mem::zeroed() })
            .collect();
        let mut iovs: Vec<libc::iovec> = bufs
            .iter_mut()
            .map(|b| libc::iovec {
                iov_base: b.as_mut_ptr().cast(),
                iov_len: b.len(),
            })
            .collect();
        let hdrs: Vec<libc::mmsghdr> = (0..RECV_BATCH)
            .map(|i| {
                // SAFETY: see above.
                let mut h: libc::mmsghdr = unsafe { std::mem::zeroed() };
                h.msg_hdr.msg_name = (&mut addrs[i] as *mut libc::sockaddr_storage).cast();
                h.msg_hdr.msg_iov = &mut iovs[i];
                h.msg_hdr.msg_iovlen = 1;
                h
            })
            .collect();
        MmsgBatch {
            bufs,
            addrs,
            iovs,
            hdrs,
        }
    }
}

impl RecvBatch for MmsgBatch {
    fn recv(&mut self, sock: &UdpSocket) -> io::Result<usize> {
        self.read(sock, libc::MSG_WAITFORONE)
    }

    fn try_recv(&mut self, sock: &UdpSocket) -> io::Result<usize> {
        self.read(sock, libc::MSG_DONTWAIT)
    }

    fn datagram(&self, i: usize) -> Option<Datagram<'_>> {
        let len = (self.hdrs[i].msg_len as usize).min(self.bufs[i].len());
        let from = sockaddr(&self.addrs[i])?;
        Some(Datagram {
            data: &self.bufs[i][..len],
            from,
        })
    }
}

impl MmsgBatch {
    /// One `recvmmsg` with these flags.
    fn read(&mut self, sock: &UdpSocket, flags: libc::c_int) -> io::Result<usize> {
        for h in &mut self.hdrs {
            h.msg_hdr.msg_namelen =
                std::mem::size_of::<libc::sockaddr_storage>() as libc::socklen_t;
            h.msg_len = 0;
        }
        // SAFETY: every header points at a live buffer of the stated length and a sockaddr_storage.
        let n = unsafe {
            libc::recvmmsg(
                sock.as_raw_fd(),
                self.hdrs.as_mut_ptr(),
                RECV_BATCH as libc::c_uint,
                flags,
                std::ptr::null_mut(),
            )
        };
        if n < 0 {
            Err(io::Error::last_os_error())
        } else {
            Ok(n as usize)
        }
    }
}

fn sockaddr(a: &libc::sockaddr_storage) -> Option<SocketAddr> {
    if i32::from(a.ss_family) == libc::AF_INET6 {
        // SAFETY: the family says this storage holds a sockaddr_in6.
        let sin6 = unsafe { &*(a as *const libc::sockaddr_storage).cast::<libc::sockaddr_in6>() };
        return Some(SocketAddr::V6(SocketAddrV6::new(
            Ipv6Addr::from(sin6.sin6_addr.s6_addr),
            u16::from_be(sin6.sin6_port),
            u32::from_be(sin6.sin6_flowinfo),
            sin6.sin6_scope_id,
        )));
    }
    if i32::from(a.ss_family) != libc::AF_INET {
        return None;
    }
    // SAFETY: the family says this storage holds a sockaddr_in.
    let sin = unsafe { &*(a as *const libc::sockaddr_storage).cast::<libc::sockaddr_in>() };
    Some(SocketAddr::V4(SocketAddrV4::new(
        Ipv4Addr::from(u32::from_be(sin.sin_addr.s_addr)),
        u16::from_be(sin.sin_port),
    )))
}
