//! Linux `recvmmsg`: one system call reads up to [`RECV_BATCH`] queued datagrams; while they come one at a
//! time, `recvmsg` reads them ([`ReadMode`]).

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
    mode: ReadMode,
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
            mode: ReadMode::default(),
        }
    }
}

impl RecvBatch for MmsgBatch {
    fn recv(&mut self, sock: &UdpSocket) -> io::Result<usize> {
        if self.mode.single() {
            return self.read_one(sock);
        }
        let n = self.read(sock, libc::MSG_WAITFORONE)?;
        self.mode.batched(n);
        Ok(n)
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

impl MmsgBatch {
    /// One `recvmsg` into the first buffer.
    fn read_one(&mut self, sock: &UdpSocket) -> io::Result<usize> {
        let h = &mut self.hdrs[0];
        h.msg_hdr.msg_namelen = std::mem::size_of::<libc::sockaddr_storage>() as libc::socklen_t;
        // SAFETY: the header points at a live buffer of the stated length and a sockaddr_storage.
        let n = unsafe { libc::recvmsg(sock.as_raw_fd(), &mut h.msg_hdr, 0) };
        if n < 0 {
            return Err(io::Error::last_os_error());
        }
        h.msg_len = n as libc::c_uint;
        Ok(1)
    }
}

/// Reads one datagram per `recvmsg` while batches hold one. A `recvmmsg` that returns one datagram has
/// also tried for a second, which costs about 0.6 µs of a 6 µs bare-UDP hop on loopback
/// (`scripts/bench-latency.sh`, stacks `floor` and `floorm`): a ping/pong, or a stream the thread keeps up
/// with, reads one at a time after [`LONE_BATCHES`] such batches in a row. Every [`PROBE_EVERY`]th read is
/// then a batch again, and one of more than one datagram (a burst, a fragmented sample) goes back to
/// batches.
#[derive(Debug, Default)]
struct ReadMode {
    lone: u8,
    reads: u8,
}

/// Batches of one datagram in a row before reading one at a time.
const LONE_BATCHES: u8 = 4;
/// One read in this many is a batch while reading one at a time.
const PROBE_EVERY: u8 = 8;

impl ReadMode {
    /// Whether the next read takes one datagram.
    fn single(&mut self) -> bool {
        if self.lone < LONE_BATCHES {
            return false;
        }
        self.reads = (self.reads + 1) % PROBE_EVERY;
        self.reads != 0
    }

    /// A batch read returned `n` datagrams.
    fn batched(&mut self, n: usize) {
        self.lone = if n <= 1 {
            self.lone.saturating_add(1).min(LONE_BATCHES)
        } else {
            0
        };
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lone_batches_switch_to_single_reads_and_a_burst_switches_back() {
        let mut m = ReadMode::default();
        for _ in 0..LONE_BATCHES {
            assert!(!m.single());
            m.batched(1);
        }
        let singles = (0..PROBE_EVERY).filter(|_| m.single()).count();
        assert_eq!(
            singles,
            usize::from(PROBE_EVERY) - 1,
            "one probe per {PROBE_EVERY} reads"
        );
        m.batched(3);
        assert!(!m.single());
    }

    #[test]
    fn single_reads_and_batches_deliver_every_datagram() {
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        rx.set_read_timeout(Some(std::time::Duration::from_secs(5)))
            .unwrap();
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let dest = rx.local_addr().unwrap();
        let mut b = MmsgBatch::new();
        let mut next = 0u8;
        // One at a time (the batches turn into single reads), then bursts of five.
        for round in 0..40u8 {
            let burst = if round < 20 { 1 } else { 5 };
            for k in 0..burst {
                tx.send_to(&[round, k], dest).unwrap();
            }
            let mut got = 0;
            while got < burst {
                let n = b.recv(&rx).unwrap();
                for i in 0..n {
                    let d = b.datagram(i).unwrap();
                    assert_eq!(d.data, [round, got]);
                    assert_eq!(d.from, tx.local_addr().unwrap());
                    got += 1;
                }
            }
            next = next.wrapping_add(burst);
        }
        assert_eq!(next, 20 + 20 * 5);
    }
}
