//! Sockets connected to one busy unicast destination each. A `send` on a connected UDP socket uses the route
//! the kernel cached at `connect`, where every `sendto` on the shared socket looks it up again: on loopback
//! that is about 0.4 µs of a 6 µs bare-UDP hop (`scripts/bench-latency.sh`, stacks `floor` and `floorc`), and
//! more for the datagrams of a fragmented sample.
//!
//! A destination gets one after [`HOT_SENDS`] sends (a writer's reader, a reader's writer), so that the
//! sparse discovery traffic keeps the shared socket; at most [`MAX_CONNECTED`] per participant (a bounded number
//! of descriptors). When all are taken and another destination becomes busy, a socket whose destination was
//! not sent to for [`IDLE`] is given back (closed) and the busy one gets a socket in its place: a peer that went
//! away, or a reader that no longer reads, does not keep its socket for the participant's life. The sockets
//! only send: their receive buffer is the kernel's smallest, and nothing reads it.

use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, RwLock};
use std::time::{Duration, Instant};

use super::iface::Interface;
use super::socket::connected_socket;

/// Sends to one destination before it gets a connected socket.
pub(super) const HOT_SENDS: u32 = 32;
/// Connected sockets per participant.
pub(super) const MAX_CONNECTED: usize = 8;
/// A connected socket not used for this long may be given back to a busier destination.
pub(super) const IDLE: Duration = Duration::from_secs(10);
/// Destinations counted at once; beyond, new ones are not counted until a slot frees (a destination that
/// becomes busy leaves the table).
const MAX_COUNTED: usize = 64;

/// The connected sockets of one participant, and the send counts of the destinations that have none yet.
#[derive(Debug)]
pub(super) struct Connected {
    on: bool,
    idle: Duration,
    socks: RwLock<Table>,
    /// Set once a socket could not be made: no more counting.
    failed: AtomicBool,
    counts: Mutex<Vec<(SocketAddr, u32)>>,
}

/// The connected sockets, and when their use was last looked at.
#[derive(Debug, Default)]
struct Table {
    conns: Vec<Conn>,
    /// The start of the current idle window: a socket not used since (its flag still clear) is idle once
    /// the window is [`Connected::idle`] long. `None` until the table first fills.
    window: Option<Instant>,
}

/// One connected socket.
#[derive(Debug)]
struct Conn {
    dest: SocketAddr,
    sock: UdpSocket,
    /// Sent on since the idle window began.
    used: AtomicBool,
}

impl Connected {
    /// `on: false` never connects (every send on the shared socket).
    pub(super) fn new(on: bool) -> Self {
        Self::with_idle(on, IDLE)
    }

    /// Like [`new`](Self::new), giving back sockets idle for `idle` instead of [`IDLE`].
    pub(super) fn with_idle(on: bool, idle: Duration) -> Self {
        Connected {
            on,
            idle,
            socks: RwLock::new(Table::default()),
            failed: AtomicBool::new(!on),
            counts: Mutex::new(Vec::new()),
        }
    }

    /// Runs `send` with the socket connected to `dest`, if it has one: `None` when it has not (the caller
    /// sends on the shared socket). Counts the send otherwise, and connects a destination that became busy
    /// (in place of an idle one when all are taken).
    pub(super) fn with<R>(
        &self,
        dest: SocketAddr,
        iface: &Interface,
        buf: usize,
        send: impl FnOnce(&UdpSocket) -> R,
    ) -> Option<R> {
        if !self.on {
            return None;
        }
        {
            let socks = self.socks.read().unwrap_or_else(|e| e.into_inner());
            if let Some(c) = socks.conns.iter().find(|c| c.dest == dest) {
                if !c.used.load(Ordering::Relaxed) {
                    c.used.store(true, Ordering::Relaxed);
                }
                return Some(send(&c.sock));
            }
        }
        if self.failed.load(Ordering::Relaxed) || dest.ip().is_multicast() || !self.count(dest) {
            return None;
        }
        let mut socks = self.socks.write().unwrap_or_else(|e| e.into_inner());
        if socks.conns.len() >= MAX_CONNECTED && !socks.give_back_idle(Instant::now(), self.idle) {
            return None;
        }
        match connected_socket(iface, dest, buf) {
            Ok(sock) => {
                tracing::debug!(%dest, "connected socket for a busy destination");
                socks.conns.push(Conn {
                    dest,
                    sock,
                    used: AtomicBool::new(true),
                });
                let c = socks.conns.last()?;
                Some(send(&c.sock))
            }
            Err(e) => {
                tracing::debug!(%dest, error = %e, "no connected socket: sends stay on the shared socket");
                self.failed.store(true, Ordering::Relaxed);
                None
            }
        }
    }

    /// Counts one send to `dest`: true when it just became busy (and leaves the table).
    fn count(&self, dest: SocketAddr) -> bool {
        let mut counts = self.counts.lock().unwrap_or_else(|e| e.into_inner());
        match counts.iter().position(|(a, _)| *a == dest) {
            Some(i) => {
                counts[i].1 += 1;
                if counts[i].1 >= HOT_SENDS {
                    counts.swap_remove(i);
                    return true;
                }
            }
            None if counts.len() < MAX_COUNTED => counts.push((dest, 1)),
            None => {}
        }
        false
    }

    /// How many destinations have a connected socket.
    #[cfg(test)]
    pub(super) fn len(&self) -> usize {
        self.socks
            .read()
            .unwrap_or_else(|e| e.into_inner())
            .conns
            .len()
    }

    /// Whether `dest` has a connected socket.
    #[cfg(test)]
    pub(super) fn has(&self, dest: SocketAddr) -> bool {
        let socks = self.socks.read().unwrap_or_else(|e| e.into_inner());
        socks.conns.iter().any(|c| c.dest == dest)
    }
}

impl Table {
    /// Closes one socket not used since the idle window began, if the window is `idle` long, and starts a
    /// new window (every socket unused again); true when one was given back. The first call only starts
    /// the window.
    fn give_back_idle(&mut self, now: Instant, idle: Duration) -> bool {
        if self.window.is_some_and(|at| now.duration_since(at) < idle) {
            return false;
        }
        let started = self.window.replace(now).is_some();
        let i = self
            .conns
            .iter()
            .position(|c| !c.used.load(Ordering::Relaxed));
        for c in &self.conns {
            c.used.store(false, Ordering::Relaxed);
        }
        match i {
            Some(i) if started => {
                let c = self.conns.swap_remove(i);
                tracing::debug!(dest = %c.dest, "connected socket given back: its destination was idle");
                true
            }
            _ => false,
        }
    }
}

/// Whether `e`, from a connected socket, is an ICMP error of an earlier send reported on this one (the
/// destination was unreachable then): the caller may retry it once.
pub(super) fn stale_error(e: &io::Error) -> bool {
    e.kind() == io::ErrorKind::ConnectionRefused
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lo() -> Interface {
        super::super::iface::list()
            .unwrap()
            .into_iter()
            .find(|i| i.addr.is_loopback() && i.addr.is_ipv4())
            .expect("an IPv4 loopback interface")
    }

    #[test]
    fn a_busy_destination_gets_a_connected_socket_and_its_datagrams_arrive() {
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let dest = rx.local_addr().unwrap();
        let c = Connected::new(true);
        let iface = lo();
        for i in 0..HOT_SENDS - 1 {
            assert!(c.with(dest, &iface, 1 << 16, |_| ()).is_none(), "send {i}");
        }
        let sent = c
            .with(dest, &iface, 1 << 16, |s| s.send(b"hello"))
            .expect("connected");
        assert_eq!(sent.unwrap(), 5);
        assert_eq!(
            c.with(dest, &iface, 1 << 16, |s| s.send(b"again"))
                .unwrap()
                .unwrap(),
            5
        );
        let mut buf = [0u8; 16];
        assert_eq!(rx.recv(&mut buf).unwrap(), 5);
        assert_eq!(&buf[..5], b"hello");
        assert_eq!(rx.recv(&mut buf).unwrap(), 5);
        assert_eq!(c.len(), 1);
    }

    #[test]
    fn at_most_max_connected_and_never_multicast_or_when_off() {
        let c = Connected::new(true);
        let iface = lo();
        for port in 0..MAX_CONNECTED as u16 + 3 {
            let dest = SocketAddr::from(([127, 0, 0, 1], 20_000 + port));
            for _ in 0..HOT_SENDS {
                c.with(dest, &iface, 1 << 16, |_| ());
            }
        }
        assert_eq!(c.len(), MAX_CONNECTED);
        let mc = SocketAddr::from(([239, 255, 0, 1], 7400));
        let c = Connected::new(true);
        for _ in 0..2 * HOT_SENDS {
            assert!(c.with(mc, &iface, 1 << 16, |_| ()).is_none());
        }
        let off = Connected::new(false);
        let dest = SocketAddr::from(([127, 0, 0, 1], 20_000));
        for _ in 0..2 * HOT_SENDS {
            assert!(off.with(dest, &iface, 1 << 16, |_| ()).is_none());
        }
        assert_eq!(off.len(), 0);
    }

    /// All sockets taken: a destination that becomes busy gets the socket of one that was not sent to for
    /// the idle time (not before), and its datagrams arrive; the idle one goes back to the shared socket.
    #[test]
    fn an_idle_destination_gives_its_socket_to_a_busy_one() {
        let idle = Duration::from_millis(300);
        let c = Connected::with_idle(true, idle);
        let iface = lo();
        let dests: Vec<SocketAddr> = (0..MAX_CONNECTED as u16)
            .map(|p| SocketAddr::from(([127, 0, 0, 1], 21_000 + p)))
            .collect();
        for &d in &dests {
            for _ in 0..HOT_SENDS {
                c.with(d, &iface, 1 << 16, |_| ());
            }
        }
        assert_eq!(c.len(), MAX_CONNECTED);
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let busy = rx.local_addr().unwrap();
        let hot = |c: &Connected| {
            (0..HOT_SENDS)
                .filter_map(|_| c.with(busy, &iface, 1 << 16, |s| s.send(b"busy")))
                .count()
        };
        // The first time it is busy only starts the idle window; before the window is over, no socket.
        assert_eq!(hot(&c), 0);
        assert_eq!(hot(&c), 0);
        // Every destination but one is sent to during the window.
        let quiet = dests[3];
        let start = Instant::now();
        while start.elapsed() < idle + Duration::from_millis(50) {
            for &d in dests.iter().filter(|&&d| d != quiet) {
                assert!(c.with(d, &iface, 1 << 16, |_| ()).is_some());
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        assert_eq!(
            hot(&c),
            1,
            "the last of the 32 sends goes on the new socket"
        );
        assert!(c.has(busy) && !c.has(quiet));
        assert_eq!(c.len(), MAX_CONNECTED);
        let mut buf = [0u8; 8];
        assert_eq!(rx.recv(&mut buf).unwrap(), 4);
        assert_eq!(&buf[..4], b"busy");
        assert!(c.with(quiet, &iface, 1 << 16, |_| ()).is_none());
    }
}
