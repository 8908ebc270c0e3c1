//! Linux UDP generic segmentation offload (`UDP_SEGMENT`): one `sendmsg` hands the kernel a run of
//! datagrams of one size (the last may be shorter) for one destination, and the kernel cuts them apart.
//! Datagrams given in pieces ([`Pieces`]) go as one `iovec` per piece: the kernel concatenates them and
//! cuts every segment size, so the pieces of each datagram must add up to exactly that size.
//! A fragmented sample is such a run: on loopback the receiver then finds all of its datagrams queued at
//! once (one wake-up, one `recvmmsg`) instead of waking for each `sendto`.
//!
//! Kernels or devices that refuse (`EIO`, `ENOPROTOOPT`, `EOPNOTSUPP`) turn it off for the socket's
//! lifetime; a path whose MTU is below the datagram size (`EMSGSIZE`, or `EINVAL` on older kernels) turns it
//! off for that destination. The caller then sends one datagram per call, which the kernel fragments.

use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::os::fd::AsRawFd;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

use socket2::SockAddr;

use super::gather::Pieces;

/// Destinations refused for their MTU remembered before segmentation is turned off altogether.
const MAX_REFUSED: usize = 64;

/// Whether segmented sends are tried, and to which destinations. A path whose MTU is below the datagram
/// size refuses (the kernel does not segment into IP fragments): `EMSGSIZE` (Linux 5.x and later, as on a
/// veth pair of MTU 1500 between network namespaces) or `EINVAL` (older kernels). That destination keeps
/// one send per datagram. Any other refusal turns segmentation off.
#[derive(Debug)]
pub(super) struct GsoState {
    on: AtomicBool,
    refused: Mutex<Vec<SocketAddr>>,
}

impl GsoState {
    pub(super) fn new(on: bool) -> Self {
        GsoState {
            on: AtomicBool::new(on),
            refused: Mutex::new(Vec::new()),
        }
    }

    pub(super) fn allows(&self, dest: SocketAddr) -> bool {
        self.on.load(Ordering::Relaxed)
            && !self
                .refused
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .contains(&dest)
    }

    pub(super) fn refused(&self, dest: SocketAddr, e: &io::Error) {
        let mut refused = self.refused.lock().unwrap_or_else(|e| e.into_inner());
        if too_big(e) && refused.len() < MAX_REFUSED {
            tracing::debug!(%dest, error = %e, "no segmented sends to this destination");
            refused.push(dest);
        } else {
            tracing::info!(%dest, error = %e, "segmented sends (UDP_SEGMENT) turned off");
            self.on.store(false, Ordering::Relaxed);
        }
    }
}

/// Most datagrams one `UDP_SEGMENT` send may carry (the kernel's `UDP_MAX_SEGMENTS` is 64 on older
/// kernels, 128 on newer ones).
pub(super) const MAX_SEGMENTS: usize = 64;

/// Most payload bytes one send may carry: an IPv4 datagram's 65 535 bytes less its IP and UDP headers
/// (IPv6 allows 8 more; the smaller bound serves both).
pub(super) const MAX_BYTES: usize = 65_535 - 20 - 8;

/// Most `iovec`s (pieces of datagrams) one segmented send carries.
const MAX_IOV: usize = 128;

/// How many of `payloads` (from the first) one segmented send can carry: a run whose datagrams all have
/// the first one's length, except that the run's last may be shorter, within [`MAX_SEGMENTS`],
/// [`MAX_BYTES`] and `MAX_IOV` pieces. At least 1.
pub(super) fn run_len<P: Pieces>(payloads: &[P]) -> usize {
    let Some(first) = payloads.first() else {
        return 0;
    };
    let size = first.total_len();
    let (mut total, mut pieces) = (0, 0);
    let mut n = 0;
    for p in payloads.iter().take(MAX_SEGMENTS) {
        let len = p.total_len();
        pieces += p.pieces().len();
        if len > size || total + len > MAX_BYTES || len == 0 || pieces > MAX_IOV {
            break;
        }
        total += len;
        n += 1;
        if len < size {
            break;
        }
    }
    n.max(1)
}

/// Sends `payloads` (a run as [`run_len`] chose, at least two) to `dest` in one `sendmsg` with
/// `UDP_SEGMENT` set to the first one's length; `None`: to the destination `sock` is connected to.
pub(super) fn send_segments<P: Pieces>(
    sock: &UdpSocket,
    payloads: &[P],
    dest: Option<SocketAddr>,
) -> io::Result<()> {
    debug_assert!(payloads.len() >= 2 && payloads.len() <= MAX_SEGMENTS);
    let mut iovs = [libc::iovec {
        iov_base: std::ptr::null_mut(),
        iov_len: 0,
    }; MAX_IOV];
    let pieces = payloads.iter().flat_map(|d| d.pieces());
    let mut used = 0;
    for (iov, p) in iovs.iter_mut().zip(pieces) {
        iov.iov_base = p.as_ptr().cast_mut().cast();
        iov.iov_len = p.len();
        used += 1;
    }
    let addr = dest.map(SockAddr::from);
    let seg = payloads[0].total_len() as u16;
    // Room for one cmsghdr with a u16, aligned as the kernel wants (u64 alignment).
    let mut control = [0u64; 4];
    // SAFETY: all-zero is a valid msghdr; every pointer set below outlives the call.
    let mut msg: libc::msghdr = unsafe { std::mem::zeroed() };
    if let Some(addr) = &addr {
        msg.msg_name = addr.as_ptr().cast_mut().cast();
        msg.msg_namelen = addr.len();
    }
    msg.msg_iov = iovs.as_mut_ptr();
    msg.msg_iovlen = used as _;
    msg.msg_control = control.as_mut_ptr().cast();
    // SAFETY: CMSG_SPACE only computes a size.
    msg.msg_controllen = unsafe { libc::CMSG_SPACE(std::mem::size_of::<u16>() as u32) } as _;
    // SAFETY: the control buffer holds CMSG_SPACE(2) bytes (32 available), so the first header and
    // its data are inside it.
    unsafe {
        let c = libc::CMSG_FIRSTHDR(&msg);
        (*c).cmsg_level = libc::SOL_UDP;
        (*c).cmsg_type = libc::UDP_SEGMENT;
        (*c).cmsg_len = libc::CMSG_LEN(std::mem::size_of::<u16>() as u32) as _;
        std::ptr::write_unaligned(libc::CMSG_DATA(c).cast::<u16>(), seg);
    }
    // SAFETY: msg points at live iovecs, address and control data for the duration of the call.
    let n = unsafe { libc::sendmsg(sock.as_raw_fd(), &msg, 0) };
    if n < 0 {
        Err(io::Error::last_os_error())
    } else {
        Ok(())
    }
}

/// Whether an error of [`send_segments`] says the kernel, the device or the path cannot segment this run
/// (send its datagrams one by one), as opposed to an ordinary send failure.
pub(super) fn unsupported(e: &io::Error) -> bool {
    too_big(e)
        || matches!(
            e.raw_os_error(),
            Some(libc::EIO | libc::ENOPROTOOPT | libc::EOPNOTSUPP)
        )
}

/// The segments are larger than the path's MTU allows.
fn too_big(e: &io::Error) -> bool {
    matches!(e.raw_os_error(), Some(libc::EMSGSIZE | libc::EINVAL))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_are_equal_sized_datagrams_with_a_shorter_last() {
        let a: &[u8] = &[0u8; 1000];
        let b: &[u8] = &[0u8; 400];
        assert_eq!(run_len(&[a, a, a, b, a]), 4);
        assert_eq!(run_len(&[a, a]), 2);
        assert_eq!(run_len(&[b, a]), 1);
        assert_eq!(run_len(&[a]), 1);
        let big: &[u8] = &[0u8; 14_720];
        // 4 × 14 720 = 58 880 fits, a fifth would pass 65 507.
        assert_eq!(run_len(&[big, big, big, big, big]), 4);
        let tiny = [0u8; 10];
        let many: Vec<&[u8]> = (0..100).map(|_| &tiny[..]).collect();
        assert_eq!(run_len(&many), MAX_SEGMENTS);
    }

    /// A route of MTU 1400 (made inside the private namespace the suite runs in, `scripts/isolated`): a
    /// segmented send of larger datagrams is refused as too big for that destination only, and the
    /// datagrams then go one by one.
    #[test]
    fn segments_above_the_path_mtu_are_refused_for_that_destination_only() {
        // A local route of its own for one loopback address: other tests' traffic keeps lo's MTU.
        let route = "route replace local 127.0.0.77/32 dev lo mtu lock 1400 table local";
        let made = std::process::Command::new("ip")
            .args(route.split(' '))
            .status();
        if !made.is_ok_and(|s| s.success()) {
            eprintln!("skipped: cannot add a route of MTU 1400 here (run under scripts/isolated, as root)");
            return;
        }
        let rx = UdpSocket::bind("127.0.0.77:0").unwrap();
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let dest = rx.local_addr().unwrap();
        let payloads: [&[u8]; 3] = [&[1; 2000], &[2; 2000], &[3; 500]];
        let e = send_segments(&tx, &payloads, Some(dest)).unwrap_err();
        assert!(unsupported(&e), "{e}");
        let state = GsoState::new(true);
        state.refused(dest, &e);
        assert!(!state.allows(dest));
        assert!(state.allows("127.0.0.1:7400".parse().unwrap()));
        for p in payloads {
            tx.send_to(p, dest).unwrap();
        }
        let mut buf = [0u8; 4000];
        for p in payloads {
            let n = rx.recv(&mut buf).unwrap();
            assert_eq!(&buf[..n], p);
        }
    }

    #[test]
    fn runs_of_pieced_datagrams_count_their_whole_lengths() {
        let (head, body, short): (&[u8], &[u8], &[u8]) = (&[1; 40], &[2; 960], &[3; 360]);
        let full: &[&[u8]] = &[head, body];
        let last: &[&[u8]] = &[head, short];
        assert_eq!(run_len(&[full, full, last, full]), 3);
        assert_eq!(run_len(&[full, &[head, body, head][..]]), 1);
        // At most MAX_IOV pieces in one send.
        let split: Vec<&[u8]> = vec![&[4; 10]; 10];
        let many = vec![&split[..]; MAX_SEGMENTS];
        assert_eq!(run_len(&many), MAX_IOV / 10);
    }

    #[test]
    fn a_segmented_send_of_pieces_arrives_as_the_datagrams_they_make() {
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let (head, body, tail): (&[u8], &[u8], &[u8]) = (&[1; 44], &[2; 1156], &[3; 500]);
        let grams: [&[&[u8]]; 3] = [&[head, body], &[head, &body[..600], &body[600..]], &[tail]];
        match send_segments(&tx, &grams, Some(rx.local_addr().unwrap())) {
            Err(e) if unsupported(&e) => return, // no GSO here: the fallback's case
            r => r.unwrap(),
        }
        let mut buf = [0u8; 2000];
        for g in grams {
            let n = rx.recv(&mut buf).unwrap();
            assert_eq!(&buf[..n], &g.concat()[..]);
        }
    }

    #[test]
    fn a_segmented_send_arrives_as_separate_datagrams() {
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let payloads: [&[u8]; 3] = [&[1; 1200], &[2; 1200], &[3; 500]];
        match send_segments(&tx, &payloads, Some(rx.local_addr().unwrap())) {
            Err(e) if unsupported(&e) => return, // no GSO here: the fallback's case
            r => r.unwrap(),
        }
        let mut buf = [0u8; 2000];
        for p in payloads {
            let n = rx.recv(&mut buf).unwrap();
            assert_eq!(&buf[..n], p);
        }
    }
}
