//! Linux `recvmmsg`: one system call reads up to [`RECV_BATCH`] queued datagrams; while they come one at a
//! time, `recvmsg` reads them ([`ReadMode`]).

use std::io;
use std::net::{Ipv4Addr, Ipv6Addr, SocketAddr, SocketAddrV4, SocketAddrV6, UdpSocket};
use std::os::fd::AsRawFd;
use std::time::{Duration, Instant};

use super::datagram::{Datagram, RecvBatch, MAX_BATCH, RECV_BUFFER};

/// Datagrams received per `recvmmsg` call.
const RECV_BATCH: usize = MAX_BATCH;

/// Buffers for one `recvmmsg` call. The pointers inside `hdrs` point into `slots` and the other vectors' heap
/// storage, which never reallocates after construction.
pub(super) struct MmsgBatch {
    slots: Slots,
    addrs: Vec<libc::sockaddr_storage>,
    /// Never read from Rust: `hdrs` point into it, so it must live as long as the batch.
    #[allow(dead_code)]
    iovs: Vec<libc::iovec>,
    hdrs: Vec<libc::mmsghdr>,
    mode: ReadMode,
}

// SAFETY: the raw pointers only reference the batch's own buffers; the batch is used by one thread.
unsafe impl Send for MmsgBatch {}

impl MmsgBatch {
    pub(super) fn new() -> Self {
        let slots = Slots::new();
        // SAFETY: sockaddr_storage and mmsghdr are plain C structs for which all-zero is valid.
        let mut addrs: Vec<libc::sockaddr_storage> = (0..RECV_BATCH)
            .map(|_| unsafe { std::mem::zeroed() })
            .collect();
        let mut iovs: Vec<libc::iovec> = (0..RECV_BATCH)
            .map(|i| libc::iovec {
                iov_base: slots.slot_ptr(i).cast(),
                iov_len: RECV_BUFFER,
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
            slots,
            addrs,
            iovs,
            hdrs,
            mode: ReadMode::default(),
        }
    }
}

/// The datagram buffers of a batch: [`RECV_BATCH`] slots of [`RECV_BUFFER`] bytes in one private anonymous
/// mapping, so that a page is resident only once a datagram was written into it.
///
/// A burst (200 peers announcing themselves, or one announcing thousands of endpoints) fills every slot, and
/// a large datagram all pages of its slot; without [`Slots::release`] that would stay resident for the
/// participant's life, up to the whole batch (512 KiB) per receive thread, where one datagram at a time
/// touches one page. Once the burst is over (a read timed out, or read a single small datagram at least
/// [`RELEASE_EVERY`] after the last release), the pages beyond the first slot's first page are given back
/// (see `docs/performance.md`, "Footprint"). A stream of large datagrams or full batches never meets that
/// condition, so it keeps its pages and pays nothing; a mixed one pays a few page faults per period.
struct Slots {
    base: std::ptr::NonNull<u8>,
    /// Per slot, the longest datagram written into it since the last release.
    touched: [usize; RECV_BATCH],
    last_release: Option<Instant>,
    /// At most one release per this (not counting read timeouts).
    every: Duration,
}

/// Bytes of the first slot kept resident by [`Slots::release`]: a small datagram's page.
const KEEP: usize = 4096;
const SLOTS_LEN: usize = RECV_BATCH * RECV_BUFFER;
/// See [`Slots`].
const RELEASE_EVERY: Duration = Duration::from_secs(1);

impl Slots {
    fn new() -> Self {
        // SAFETY: a fresh private anonymous mapping; no existing memory is involved.
        let p = unsafe {
            libc::mmap(
                std::ptr::null_mut(),
                SLOTS_LEN,
                libc::PROT_READ | libc::PROT_WRITE,
                libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
                -1,
                0,
            )
        };
        let base = (p != libc::MAP_FAILED)
            .then(|| std::ptr::NonNull::new(p.cast::<u8>()))
            .flatten()
            .unwrap_or_else(|| std::alloc::handle_alloc_error(Self::layout()));
        Slots {
            base,
            touched: [0; RECV_BATCH],
            last_release: None,
            every: RELEASE_EVERY,
        }
    }

    fn layout() -> std::alloc::Layout {
        std::alloc::Layout::from_size_align(SLOTS_LEN, KEEP).expect("a valid layout")
    }

    fn slot_ptr(&self, i: usize) -> *mut u8 {
        assert!(i < RECV_BATCH);
        // SAFETY: within the mapping of RECV_BATCH slots.
        unsafe { self.base.as_ptr().add(i * RECV_BUFFER) }
    }

    /// The first `len` bytes of slot `i` (at most the slot).
    fn slot(&self, i: usize, len: usize) -> &[u8] {
        // SAFETY: the mapping is readable and lives as long as `self`; `recvmmsg` writes only while `self`
        // is borrowed mutably.
        unsafe { std::slice::from_raw_parts(self.slot_ptr(i), len.min(RECV_BUFFER)) }
    }

    /// Notes the lengths of the datagrams a read wrote into the first slots; after a single small one
    /// (no burst under way), releases what an earlier burst touched, at most once per `every`.
    fn wrote(&mut self, lens: impl ExactSizeIterator<Item = usize>) {
        let mut single_small = lens.len() == 1;
        for (t, len) in self.touched.iter_mut().zip(lens) {
            single_small &= len <= KEEP;
            *t = (*t).max(len.min(RECV_BUFFER));
        }
        if single_small && self.holds_spare() {
            let now = Instant::now();
            if self.last_release.is_none_or(|t| now >= t + self.every) {
                self.last_release = Some(now);
                self.release();
            }
        }
    }

    /// Whether pages beyond the first slot's first page were written since the last release.
    fn holds_spare(&self) -> bool {
        self.touched[0] > KEEP || self.touched[1..].iter().any(|&t| t > 0)
    }

    /// Gives back every page written since the last release but the first slot's first page (which holds
    /// a small datagram just read, if any). Their contents are zeros when next read, which nothing relies
    /// on: a datagram overwrites what it needs.
    fn release(&mut self) {
        for i in 0..RECV_BATCH {
            let keep = if i == 0 { KEEP } else { 0 };
            if std::mem::take(&mut self.touched[i]) <= keep {
                continue;
            }
            // SAFETY: a page-aligned range inside our own mapping (slots and KEEP are page multiples);
            // MADV_DONTNEED on private anonymous memory only drops its pages.
            unsafe {
                libc::madvise(
                    self.slot_ptr(i).add(keep).cast(),
                    RECV_BUFFER - keep,
                    libc::MADV_DONTNEED,
                );
            }
        }
    }
}

impl Drop for Slots {
    fn drop(&mut self) {
        // SAFETY: the mapping made in `new`, unmapped once; nothing points into it any more.
        unsafe {
            libc::munmap(self.base.as_ptr().cast(), SLOTS_LEN);
        }
    }
}

impl RecvBatch for MmsgBatch {
    fn recv(&mut self, sock: &UdpSocket) -> io::Result<usize> {
        self.read_as_mode(sock, libc::MSG_WAITFORONE)
    }

    fn try_recv(&mut self, sock: &UdpSocket) -> io::Result<usize> {
        self.read_as_mode(sock, libc::MSG_DONTWAIT)
    }

    fn datagram(&self, i: usize) -> Option<Datagram<'_>> {
        let from = sockaddr(&self.addrs[i])?;
        Some(Datagram {
            data: self.slots.slot(i, self.hdrs[i].msg_len as usize),
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
            let e = io::Error::last_os_error();
            // A blocking read that timed out: the socket was quiet, a burst (if any) is over.
            if flags == libc::MSG_WAITFORONE && e.kind() == io::ErrorKind::WouldBlock {
                self.slots.release();
            }
            return Err(e);
        }
        let n = n as usize;
        self.slots
            .wrote(self.hdrs.iter().take(n).map(|h| h.msg_len as usize));
        Ok(n)
    }
}

impl MmsgBatch {
    /// A batch, or one datagram while [`ReadMode`] says so; `flags`: `MSG_WAITFORONE` to block for the
    /// first datagram, `MSG_DONTWAIT` not to (a poll).
    fn read_as_mode(&mut self, sock: &UdpSocket, flags: libc::c_int) -> io::Result<usize> {
        if self.mode.single() {
            let one = if flags == libc::MSG_DONTWAIT {
                flags
            } else {
                0
            };
            return self.read_one(sock, one);
        }
        let n = self.read(sock, flags)?;
        self.mode.batched(n);
        Ok(n)
    }

    /// One `recvmsg` into the first buffer, with these flags (0: blocking).
    fn read_one(&mut self, sock: &UdpSocket, flags: libc::c_int) -> io::Result<usize> {
        let h = &mut self.hdrs[0];
        h.msg_hdr.msg_namelen = std::mem::size_of::<libc::sockaddr_storage>() as libc::socklen_t;
        // SAFETY: the header points at a live buffer of the stated length and a sockaddr_storage.
        let n = unsafe { libc::recvmsg(sock.as_raw_fd(), &mut h.msg_hdr, flags) };
        if n < 0 {
            let e = io::Error::last_os_error();
            // As for a batch: a blocking read that timed out means the socket was quiet.
            if flags == 0 && e.kind() == io::ErrorKind::WouldBlock {
                self.slots.release();
            }
            return Err(e);
        }
        h.msg_len = n as libc::c_uint;
        self.slots.wrote(std::iter::once(n as usize));
        Ok(1)
    }
}

/// Reads one datagram per `recvmsg` while batches hold one. A `recvmmsg` that returns one datagram has
/// also tried for a second, which costs about 0.6 µs of a 6 µs bare-UDP hop on loopback
/// (`scripts/bench-latency.sh`, stacks `floor` and `floorm`): a ping/pong, or a stream the thread keeps up
/// with, reads one at a time after [`LONE_BATCHES`] such batches in a row. Every [`PROBE_EVERY`]th read is
/// then a batch again, and one of more than one datagram (a burst, a fragmented sample) goes back to
/// batches. Blocking reads and polls (`MSG_DONTWAIT`) follow the same mode.
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
        // One at a time (the batches turn into single reads), then bursts of five; odd rounds poll.
        for round in 0..40u8 {
            let burst = if round < 20 { 1 } else { 5 };
            for k in 0..burst {
                tx.send_to(&[round, k], dest).unwrap();
            }
            let mut got = 0;
            while got < burst {
                let n = if round % 2 == 1 {
                    match b.try_recv(&rx) {
                        Err(e) if e.kind() == io::ErrorKind::WouldBlock => continue,
                        r => r.unwrap(),
                    }
                } else {
                    b.recv(&rx).unwrap()
                };
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

    /// Resident pages of slot `i`, by `mincore`.
    fn resident_pages(s: &Slots, i: usize) -> usize {
        let mut v = vec![0u8; RECV_BUFFER / KEEP];
        // SAFETY: a page-aligned range of our mapping and one status byte per page.
        let r = unsafe { libc::mincore(s.slot_ptr(i).cast(), RECV_BUFFER, v.as_mut_ptr()) };
        assert_eq!(r, 0, "mincore: {}", io::Error::last_os_error());
        v.iter().filter(|&&b| b & 1 != 0).count()
    }

    fn all_pages(s: &Slots) -> usize {
        (0..RECV_BATCH).map(|i| resident_pages(s, i)).sum()
    }

    fn pair() -> (UdpSocket, UdpSocket) {
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        tx.connect(rx.local_addr().unwrap()).unwrap();
        (rx, tx)
    }

    /// A large datagram leaves its slot's pages resident until the socket is quiet for a read timeout;
    /// then only the first page stays, and the next datagrams arrive whole.
    #[test]
    fn a_quiet_socket_gives_back_the_pages_of_a_burst() {
        let (rx, tx) = pair();
        rx.set_read_timeout(Some(Duration::from_millis(50)))
            .unwrap();
        let mut b = MmsgBatch::new();
        assert_eq!(all_pages(&b.slots), 0, "nothing touched yet");
        let big: Vec<u8> = (0..60_000u32).map(|i| (i % 251) as u8).collect();
        tx.send(&big).unwrap();
        assert_eq!(b.recv(&rx).unwrap(), 1);
        assert_eq!(b.datagram(0).unwrap().data, &big[..]);
        assert!(resident_pages(&b.slots, 0) >= 14);
        let quiet = b.recv(&rx).unwrap_err();
        assert_eq!(quiet.kind(), io::ErrorKind::WouldBlock);
        assert!(all_pages(&b.slots) <= 1, "released after the timeout");
        for len in [100, 60_000, 100] {
            tx.send(&big[..len]).unwrap();
            assert_eq!(b.recv(&rx).unwrap(), 1);
            assert_eq!(b.datagram(0).unwrap().data, &big[..len]);
        }
    }

    /// Writes `len` bytes into slot `i`, as `recvmmsg` would.
    fn fill(s: &Slots, i: usize, len: usize) {
        // SAFETY: within slot `i` of the mapping.
        unsafe { std::ptr::write_bytes(s.slot_ptr(i), 1, len) };
    }

    /// A burst of small datagrams fills every slot's first page; the next single small datagram (once the
    /// release period passed) gives them back; a large one, or a full batch, releases nothing.
    #[test]
    fn a_single_small_datagram_after_a_burst_gives_its_pages_back() {
        let mut s = Slots::new();
        s.every = Duration::ZERO;
        (0..RECV_BATCH).for_each(|i| fill(&s, i, 1_000));
        s.wrote([1_000; RECV_BATCH].into_iter());
        assert_eq!(all_pages(&s), RECV_BATCH, "one page per slot");
        fill(&s, 0, 30_000);
        s.wrote([30_000].into_iter());
        assert_eq!(
            all_pages(&s),
            RECV_BATCH + 7,
            "a large datagram releases nothing"
        );
        fill(&s, 0, 200);
        s.wrote([200].into_iter());
        assert_eq!(all_pages(&s), 1, "only the first slot's first page");
        s.every = Duration::from_secs(3600);
        (0..2).for_each(|i| fill(&s, i, 1_000));
        s.wrote([1_000; 2].into_iter());
        s.wrote([200].into_iter());
        assert_eq!(all_pages(&s), 2, "at most one release per period");
    }

    /// Through a socket: every datagram of a burst arrives whole, and once it is over one page stays.
    #[test]
    fn datagrams_arrive_whole_across_releases() {
        let (rx, tx) = pair();
        let mut b = MmsgBatch::new();
        b.slots.every = Duration::ZERO;
        let sizes = [1_000, 50_000, 3_000, 65_000, 10, 20_000, 4_096, 4_097, 700];
        for (k, &len) in sizes.iter().enumerate() {
            tx.send(&vec![k as u8; len]).unwrap();
        }
        let mut seen = Vec::new();
        while seen.len() < sizes.len() {
            let n = b.recv(&rx).unwrap();
            seen.extend((0..n).map(|i| b.datagram(i).unwrap().data.to_vec()));
        }
        for (k, (d, &len)) in seen.iter().zip(&sizes).enumerate() {
            assert_eq!(d, &vec![k as u8; len]);
        }
        tx.send(&[9u8; 200]).unwrap();
        assert_eq!(b.recv(&rx).unwrap(), 1);
        assert_eq!(b.datagram(0).unwrap().data, &[9u8; 200]);
        assert_eq!(all_pages(&b.slots), 1);
    }
}
