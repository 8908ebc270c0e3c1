//! The receive threads' loop, over one of two ways to read a socket: `recvmmsg` batches (Linux) or one
//! `recv_from` per datagram (everywhere).

use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use super::datagram::{
    Channel, Datagram, Receiver, RecvBatch, TransportStats, MAX_BATCH, RECV_BUFFER,
};
use super::poll::{self, Episode, PollPolicy, PollerSlot};

/// A placeholder for the unused entries of a batch.
const NO_DATAGRAM: Datagram<'static> = Datagram {
    data: &[],
    from: SocketAddr::V4(std::net::SocketAddrV4::new(
        std::net::Ipv4Addr::UNSPECIFIED,
        0,
    )),
};

/// How the receive threads read their sockets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum ReceivePath {
    /// Up to 8 datagrams per `recvmmsg` call, handed to the receiver as one batch, so that the core's lock is
    /// taken once per batch. Only Linux has `recvmmsg`: elsewhere this is [`ReceivePath::OneByOne`].
    #[default]
    Batched,
    /// One `recv_from` per datagram, each handed to the receiver alone: the portable path.
    OneByOne,
}

impl ReceivePath {
    /// The path actually used on this platform.
    pub fn effective(self) -> Self {
        if cfg!(target_os = "linux") {
            self
        } else {
            ReceivePath::OneByOne
        }
    }
}

/// One datagram per call through `recv_from`.
pub(super) struct SingleRecv {
    buf: Vec<u8>,
    len: usize,
    from: Option<SocketAddr>,
}

impl SingleRecv {
    pub(super) fn new() -> Self {
        SingleRecv {
            buf: vec![0u8; RECV_BUFFER],
            len: 0,
            from: None,
        }
    }
}

impl RecvBatch for SingleRecv {
    fn recv(&mut self, sock: &UdpSocket) -> io::Result<usize> {
        let (len, from) = sock.recv_from(&mut self.buf)?;
        self.len = len;
        self.from = Some(from);
        Ok(1)
    }

    fn datagram(&self, i: usize) -> Option<Datagram<'_>> {
        let from = self.from.filter(|_| i == 0)?;
        Some(Datagram {
            data: &self.buf[..self.len],
            from,
        })
    }
}

/// Reads `sock` the chosen way until `stop` is set. The batched path may poll for up to `spin` after a batch
/// that followed the one before it within a few `spin` windows (see [`Spin`] and [`PollPolicy`]).
pub(super) fn run(
    path: ReceivePath,
    spin: Duration,
    ch: Channel,
    sock: &UdpSocket,
    stop: &AtomicBool,
    rx: &Receiver,
    stats: &TransportStats,
) {
    let io = Io {
        ch,
        sock,
        stop,
        rx,
        stats,
    };
    match path.effective() {
        #[cfg(target_os = "linux")]
        ReceivePath::Batched => recv_loop(&mut super::mmsg::MmsgBatch::new(), Spin::new(spin), &io),
        // The portable path cannot poll: it always waits.
        _ => recv_loop(&mut SingleRecv::new(), Spin::new(Duration::ZERO), &io),
    }
}

/// What a receive thread reads from and hands its datagrams to.
struct Io<'a> {
    ch: Channel,
    sock: &'a UdpSocket,
    stop: &'a AtomicBool,
    rx: &'a Receiver,
    stats: &'a TransportStats,
}

/// Adaptive busy polling. While datagrams come close together (a ping/pong, a fast
/// stream), the thread polls the socket for up to the window after each batch instead of sleeping in the
/// kernel, so the next datagram is handled without a wake-up; it yields between polls. When to poll is
/// [`PollPolicy`]'s decision: never for sparse traffic, nor while the cores are contended.
struct Spin {
    policy: PollPolicy,
    until: Option<Instant>,
}

impl Spin {
    fn new(max: Duration) -> Self {
        Spin {
            policy: PollPolicy::new(max),
            until: None,
        }
    }

    /// A batch was just handled.
    fn arrived(&mut self) {
        if self.policy.enabled() {
            let now = Instant::now();
            self.until = self.policy.after_batch(now, poll::pressured(now));
        }
    }

    /// The next batch: polled for while the window is open, then waited for.
    fn next(&mut self, batch: &mut impl RecvBatch, io: &Io<'_>) -> io::Result<usize> {
        if let Some(until) = self.until.take() {
            if let Some(_slot) = PollerSlot::take() {
                self.policy.began(poll::thread_switches());
                let got = poll_until(batch, io, until);
                let how = match got {
                    Some(_) => Episode::Productive,
                    None => Episode::Empty,
                };
                self.policy
                    .ended(Instant::now(), how, poll::thread_switches());
                if let Some(r) = got {
                    return r;
                }
            }
        }
        batch.recv(io.sock)
    }
}

/// Polls `batch` until something arrives (or fails), `until`, or `stop`; yields between polls.
fn poll_until(
    batch: &mut impl RecvBatch,
    io: &Io<'_>,
    until: Instant,
) -> Option<io::Result<usize>> {
    loop {
        match batch.try_recv(io.sock) {
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => {}
            r => return Some(r),
        }
        if io.stop.load(Ordering::Relaxed) || Instant::now() >= until {
            return None;
        }
        std::thread::yield_now();
    }
}

fn recv_loop(batch: &mut impl RecvBatch, mut spin: Spin, io: &Io<'_>) {
    while !io.stop.load(Ordering::Relaxed) {
        match spin.next(batch, io) {
            Ok(n) => {
                if io.stop.load(Ordering::Relaxed) {
                    break;
                }
                deliver(batch, n, io);
                spin.arrived();
            }
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::WouldBlock
                        | io::ErrorKind::TimedOut
                        | io::ErrorKind::Interrupted
                ) => {}
            Err(e) => {
                if io.stop.load(Ordering::Relaxed) {
                    break;
                }
                // ICMP port-unreachable from an earlier send shows up here as ConnectionRefused.
                tracing::debug!(channel = ?io.ch, error = %e, "recv error");
            }
        }
    }
}

/// Hands the `n` datagrams of the last read to the receiver.
fn deliver(batch: &impl RecvBatch, n: usize, io: &Io<'_>) {
    // On the stack: no allocation per batch.
    let mut grams = [NO_DATAGRAM; MAX_BATCH];
    let mut k = 0;
    for d in (0..n.min(MAX_BATCH)).filter_map(|i| batch.datagram(i)) {
        if !d.data.is_empty() {
            grams[k] = d;
            k += 1;
        }
    }
    let grams = &grams[..k];
    if grams.is_empty() {
        return;
    }
    io.stats
        .received
        .fetch_add(grams.len() as u64, Ordering::Relaxed);
    for d in grams {
        tracing::trace!(channel = ?io.ch, from = %d.from, len = d.data.len(), "received");
    }
    (io.rx)(io.ch, grams);
}
