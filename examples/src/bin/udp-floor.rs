//! `udp-floor`: the floor under a DDS ping/pong: the same round trip over bare UDP sockets, with no DDS
//! stack in between. Its command line and its per-second lines are those of `dds-perf` and ddsperf, so that
//! the benchmark scripts run it as a third "stack" (`scripts/bench-latency.sh`):
//!
//! ```text
//! udp-floor [-i DOMAIN] [-D SECONDS] pong [connected] [mmsg]
//! udp-floor [-i DOMAIN] [-D SECONDS] ping [size S] [connected] [mmsg]
//! ```
//!
//! A ping of `size S` is S bytes split into datagrams of at most 14 720 bytes (the datagram size of both
//! DDS stacks' fragmented samples: 64 KiB is five of them), each sent with `sendto`; the pong waits for all
//! of them (blocking `recv`), then sends as many back. The pinger stamps the ping with the wall clock and,
//! once the whole pong is in, records half the round trip; every second it prints ddsperf's latency line
//! (`mean .. min .. 50% .. 90% .. 99% .. max .. cnt`), over the same percentile method (`perf_stats`).
//!
//! Levers, to measure what the kernel charges for them: `connected` makes each end `connect` its socket to
//! the other and use `send`; `mmsg` reads with `recvmmsg` (8 deep, `MSG_WAITFORONE`) as our receive
//! threads do, instead of `recv`.
//!
//! The pong listens on 127.0.0.1, port 7400 + 250 × DOMAIN + 200 (no DDS port of that domain); the ping
//! sends from an ephemeral port. Exit status: 0 fine, 1 no round trip, 3 bad arguments.

use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::process::ExitCode;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use dds_examples::perf_stats::{self, LatencyStat};
use dds_examples::shutdown;

/// The largest datagram either DDS stack sends for a fragmented sample.
const DATAGRAM: usize = 14_720;
/// seq (u32), index (u32), count (u32), stamp (i64).
const HEADER: usize = 20;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Mode {
    Ping,
    Pong,
}

#[derive(Debug, Clone, Copy)]
struct Opts {
    mode: Mode,
    domain: u16,
    duration: Option<Duration>,
    size: usize,
    connected: bool,
    mmsg: bool,
}

fn parse(args: &[String]) -> Result<Opts, String> {
    let mut o = Opts {
        mode: Mode::Pong,
        domain: 0,
        duration: None,
        size: 16,
        connected: false,
        mmsg: false,
    };
    let mut mode = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut val = || it.next().ok_or_else(|| format!("{a}: value missing"));
        match a.as_str() {
            "-i" => o.domain = val()?.parse().map_err(|_| "-i: bad domain")?,
            "-D" => {
                let s: f64 = val()?.parse().map_err(|_| "-D: bad duration")?;
                o.duration = Some(Duration::from_secs_f64(s.max(0.0)));
            }
            "ping" => mode = Some(Mode::Ping),
            "pong" => mode = Some(Mode::Pong),
            "size" => o.size = parse_size(val()?)?,
            "connected" => o.connected = true,
            "mmsg" => o.mmsg = true,
            _ => return Err(format!("unknown argument {a}")),
        }
    }
    o.mode = mode.ok_or("ping or pong expected")?;
    if o.domain > 232 {
        return Err("-i: domain above 232".into());
    }
    Ok(o)
}

/// `16`, `1k`, `64k`, `1M` (ddsperf's units, binary).
fn parse_size(s: &str) -> Result<usize, String> {
    let (num, mult) = match s.strip_suffix(['k', 'K']) {
        Some(n) => (n, 1024),
        None => match s.strip_suffix('M') {
            Some(n) => (n, 1 << 20),
            None => (s, 1),
        },
    };
    let v: usize = num.parse().map_err(|_| format!("size {s}: bad size"))?;
    match v.checked_mul(mult) {
        Some(n) if n <= 1 << 24 => Ok(n),
        _ => Err(format!("size {s}: too large")),
    }
}

fn now_ns() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos() as i64)
        .unwrap_or(0)
}

/// The datagram lengths of a message of `size` bytes: at most [`DATAGRAM`] each, at least [`HEADER`].
fn datagrams(size: usize) -> Vec<usize> {
    let n = size.div_ceil(DATAGRAM).max(1);
    (0..n)
        .map(|i| (size - i * DATAGRAM).clamp(HEADER, DATAGRAM))
        .collect()
}

/// A datagram's header fields.
#[derive(Debug, Clone, Copy)]
struct Header {
    seq: u32,
    count: u32,
    stamp: i64,
}

fn put_header(buf: &mut [u8], seq: u32, index: u32, count: u32, stamp: i64) {
    buf[0..4].copy_from_slice(&seq.to_le_bytes());
    buf[4..8].copy_from_slice(&index.to_le_bytes());
    buf[8..12].copy_from_slice(&count.to_le_bytes());
    buf[12..20].copy_from_slice(&stamp.to_le_bytes());
}

fn get_header(buf: &[u8]) -> Option<Header> {
    let b = buf.get(..HEADER)?;
    let u = |i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    let mut stamp = [0u8; 8];
    stamp.copy_from_slice(&b[12..20]);
    Some(Header {
        seq: u(0),
        count: u(8),
        stamp: i64::from_le_bytes(stamp),
    })
}

/// A socket that reads one datagram per `recv`, or a batch per `recvmmsg` handed out one at a time.
struct Reader {
    sock: UdpSocket,
    mmsg: Option<Mmsg>,
}

impl Reader {
    /// The next datagram into `buf`: its length and sender.
    fn recv(&mut self, buf: &mut [u8]) -> io::Result<(usize, SocketAddr)> {
        match &mut self.mmsg {
            Some(m) => m.next(&self.sock, buf),
            None => self.sock.recv_from(buf),
        }
    }

    fn send(&self, buf: &[u8], to: SocketAddr, connected: bool) -> io::Result<usize> {
        if connected {
            self.sock.send(buf)
        } else {
            self.sock.send_to(buf, to)
        }
    }
}

/// `recvmmsg` with `MSG_WAITFORONE`, 8 deep, like the DDS receive threads.
struct Mmsg {
    bufs: Vec<Vec<u8>>,
    addrs: Vec<libc::sockaddr_storage>,
    lens: Vec<usize>,
    next: usize,
    got: usize,
}

impl Mmsg {
    fn new() -> Self {
        Mmsg {
            bufs: vec![vec![0u8; 65_536]; 8],
            // SAFETY: all-zero is a valid sockaddr_storage.
            addrs: vec![unsafe { std::mem::zeroed() }; 8],
            lens: vec![0; 8],
            next: 0,
            got: 0,
        }
    }

    fn next(&mut self, sock: &UdpSocket, out: &mut [u8]) -> io::Result<(usize, SocketAddr)> {
        if self.next == self.got {
            self.fill(sock)?;
        }
        let i = self.next;
        self.next += 1;
        let n = self.lens[i].min(out.len());
        out[..n].copy_from_slice(&self.bufs[i][..n]);
        // SAFETY: the kernel wrote a sockaddr_in of the socket's (IPv4) family.
        let sin = unsafe {
            &*(&self.addrs[i] as *const libc::sockaddr_storage).cast::<libc::sockaddr_in>()
        };
        let ip = std::net::Ipv4Addr::from(u32::from_be(sin.sin_addr.s_addr));
        Ok((n, SocketAddr::from((ip, u16::from_be(sin.sin_port)))))
    }

    fn fill(&mut self, sock: &UdpSocket) -> io::Result<()> {
        use std::os::fd::AsRawFd;
        let mut iovs: Vec<libc::iovec> = self
            .bufs
            .iter_mut()
            .map(|b| libc::iovec {
                iov_base: b.as_mut_ptr().cast(),
                iov_len: b.len(),
            })
            .collect();
        let mut hdrs: Vec<libc::mmsghdr> = (0..8)
            .map(|i| {
                // SAFETY: all-zero is a valid mmsghdr; the pointers set below outlive the call.
                let mut h: libc::mmsghdr = unsafe { std::mem::zeroed() };
                h.msg_hdr.msg_name = (&mut self.addrs[i] as *mut libc::sockaddr_storage).cast();
                h.msg_hdr.msg_namelen = std::mem::size_of::<libc::sockaddr_storage>() as _;
                h.msg_hdr.msg_iov = &mut iovs[i];
                h.msg_hdr.msg_iovlen = 1;
                h
            })
            .collect();
        // SAFETY: every header points at a live buffer of its stated length and a sockaddr_storage.
        let n = unsafe {
            libc::recvmmsg(
                sock.as_raw_fd(),
                hdrs.as_mut_ptr(),
                8,
                libc::MSG_WAITFORONE,
                std::ptr::null_mut(),
            )
        };
        if n <= 0 {
            return Err(io::Error::last_os_error());
        }
        self.got = n as usize;
        self.next = 0;
        for (l, h) in self.lens.iter_mut().zip(&hdrs) {
            *l = h.msg_len as usize;
        }
        Ok(())
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let o = match parse(&args) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("udp-floor: {e}");
            return ExitCode::from(3);
        }
    };
    shutdown::install();
    let port = 7400 + 250 * o.domain + 200;
    let r = match o.mode {
        Mode::Pong => pong(&o, port),
        Mode::Ping => ping(&o, port),
    };
    match r {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("udp-floor: {e}");
            ExitCode::from(2)
        }
    }
}

fn reader(sock: UdpSocket, o: &Opts) -> io::Result<Reader> {
    // Wakes the loops now and then to look at the clock and the stop flag.
    sock.set_read_timeout(Some(Duration::from_millis(200)))?;
    Ok(Reader {
        sock,
        mmsg: o.mmsg.then(Mmsg::new),
    })
}

fn timed_out(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut | io::ErrorKind::Interrupted
    )
}

/// Answers whole pings with pongs of the same datagrams until the duration ends.
fn pong(o: &Opts, port: u16) -> io::Result<bool> {
    let mut r = reader(UdpSocket::bind(("127.0.0.1", port))?, o)?;
    let end = o.duration.map(|d| Instant::now() + d);
    let mut buf = vec![0u8; 65_536];
    let mut lens = Vec::new();
    let (mut seq, mut got) = (None, 0u32);
    let mut peer = None;
    while !shutdown::requested() && end.is_none_or(|e| Instant::now() < e) {
        let (n, from) = match r.recv(&mut buf) {
            Ok(x) => x,
            Err(e) if timed_out(&e) => continue,
            Err(e) => return Err(e),
        };
        let Some(h) = get_header(&buf[..n]) else {
            continue;
        };
        if o.connected && peer != Some(from) {
            r.sock.connect(from)?;
            peer = Some(from);
        }
        if seq != Some(h.seq) {
            (seq, got) = (Some(h.seq), 0);
            lens.clear();
        }
        lens.push(n);
        got += 1;
        if got == h.count {
            for (i, &len) in lens.iter().enumerate() {
                put_header(&mut buf, h.seq, i as u32, h.count, h.stamp);
                r.send(&buf[..len], from, o.connected)?;
            }
        }
    }
    Ok(true)
}

/// Pings as fast as the pongs come back; prints the latency line every second.
fn ping(o: &Opts, port: u16) -> io::Result<bool> {
    let to = SocketAddr::from(([127, 0, 0, 1], port));
    let sock = UdpSocket::bind("127.0.0.1:0")?;
    if o.connected {
        sock.connect(to)?;
    }
    let mut r = reader(sock, o)?;
    let start = Instant::now();
    let end = o.duration.map(|d| start + d);
    let mut next_line = start + Duration::from_secs(1);
    let lens = datagrams(o.size);
    let count = lens.len() as u32;
    let mut out = vec![0u8; DATAGRAM];
    let mut buf = vec![0u8; 65_536];
    let mut stat = LatencyStat::new();
    let pid = std::process::id();
    let mut seq = 0u32;
    while !shutdown::requested() && end.is_none_or(|e| Instant::now() < e) {
        seq = seq.wrapping_add(1);
        let stamp = now_ns();
        for (i, &len) in lens.iter().enumerate() {
            put_header(&mut out, seq, i as u32, count, stamp);
            r.send(&out[..len], to, o.connected)?;
        }
        if let Some(sent) = await_pong(&mut r, &mut buf, seq, count)? {
            stat.record((now_ns() - sent) / 2);
        }
        let now = Instant::now();
        if now >= next_line {
            let prefix = perf_stats::prefix(pid, (now - start).as_secs_f64());
            if let Some(s) = stat.take_summary() {
                let line = perf_stats::latency_line(&prefix, "", "udp", o.size as u32, &s);
                println!("{line}");
            }
            next_line += Duration::from_secs(1);
        }
    }
    Ok(stat.total > 0)
}

/// Reads until all `count` datagrams of pong `seq` are in: the ping's stamp, or `None` after a timeout (a
/// lost datagram: the caller pings again).
fn await_pong(r: &mut Reader, buf: &mut [u8], seq: u32, count: u32) -> io::Result<Option<i64>> {
    let mut got = 0;
    loop {
        let (n, _) = match r.recv(buf) {
            Ok(x) => x,
            Err(e) if timed_out(&e) => return Ok(None),
            Err(e) => return Err(e),
        };
        match get_header(&buf[..n]) {
            Some(h) if h.seq == seq => {
                got += 1;
                if got == count {
                    return Ok(Some(h.stamp));
                }
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_split_like_the_dds_stacks() {
        assert_eq!(datagrams(16), vec![20]);
        assert_eq!(datagrams(1024), vec![1024]);
        assert_eq!(
            datagrams(65_536),
            vec![14_720, 14_720, 14_720, 14_720, 6_656]
        );
        assert_eq!(parse_size("64k"), Ok(65_536));
        assert!(parse_size("x").is_err());
    }
}
