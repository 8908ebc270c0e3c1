//! Sockets connected to one busy unicast destination each. A `send` on a connected UDP socket uses the route
//! the kernel cached at `connect`, where every `sendto` on the shared socket looks it up again: on loopback
//! that is about 0.4 µs of a 6 µs bare-UDP hop (`scripts/bench-latency.sh`, stacks `floor` and `floorc`), and
//! more for the datagrams of a fragmented sample.
//!
//! A destination gets one after [`HOT_SENDS`] sends (a writer's reader, a reader's writer), so that the
//! sparse discovery traffic keeps the shared socket; at most [`MAX_CONNECTED`] per participant, never given
//! back (a bounded number of descriptors). The sockets only send: their receive buffer is the kernel's
//! smallest, and nothing reads it.

use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, RwLock};

use super::iface::Interface;
use super::socket::connected_socket;

/// Sends to one destination before it gets a connected socket.
pub(super) const HOT_SENDS: u32 = 32;
/// Connected sockets per participant.
pub(super) const MAX_CONNECTED: usize = 8;
/// Destinations counted at once; beyond, new ones are not counted until a slot frees (they never do: the
/// table only fills while the connected sockets do).
const MAX_COUNTED: usize = 64;

/// The connected sockets of one participant, and the send counts of the destinations that have none yet.
#[derive(Debug)]
pub(super) struct Connected {
    on: bool,
    socks: RwLock<Vec<(SocketAddr, UdpSocket)>>,
    /// Set once `socks` holds [`MAX_CONNECTED`] (or a socket could not be made): no more counting.
    full: AtomicBool,
    counts: Mutex<Vec<(SocketAddr, u32)>>,
}

impl Connected {
    /// `on: false` never connects (every send on the shared socket).
    pub(super) fn new(on: bool) -> Self {
        Connected {
            on,
            socks: RwLock::new(Vec::new()),
            full: AtomicBool::new(!on),
            counts: Mutex::new(Vec::new()),
        }
    }

    /// Runs `send` with the socket connected to `dest`, if it has one: `None` when it has not (the caller
    /// sends on the shared socket). Counts the send otherwise, and connects a destination that became busy.
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
            if let Some((_, s)) = socks.iter().find(|(a, _)| *a == dest) {
                return Some(send(s));
            }
        }
        if self.full.load(Ordering::Relaxed) || dest.ip().is_multicast() || !self.count(dest) {
            return None;
        }
        match connected_socket(iface, dest, buf) {
            Ok(s) => {
                let mut socks = self.socks.write().unwrap_or_else(|e| e.into_inner());
                tracing::debug!(%dest, "connected socket for a busy destination");
                socks.push((dest, s));
                if socks.len() >= MAX_CONNECTED {
                    self.full.store(true, Ordering::Relaxed);
                }
                let (_, s) = socks.last()?;
                Some(send(s))
            }
            Err(e) => {
                tracing::debug!(%dest, error = %e, "no connected socket: sends stay on the shared socket");
                self.full.store(true, Ordering::Relaxed);
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
        self.socks.read().unwrap_or_else(|e| e.into_inner()).len()
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
}
