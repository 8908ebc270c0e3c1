//! The receive threads' loop, over one of two ways to read a socket: `recvmmsg` batches (Linux) or one
//! `recv_from` per datagram (everywhere).

use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};

use super::datagram::{
    Channel, Datagram, Receiver, RecvBatch, TransportStats, MAX_BATCH, RECV_BUFFER,
};

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

/// Reads `sock` the chosen way until `stop` is set.
pub(super) fn run(
    path: ReceivePath,
    ch: Channel,
    sock: &UdpSocket,
    stop: &AtomicBool,
    rx: &Receiver,
    stats: &TransportStats,
) {
    match path.effective() {
        #[cfg(target_os = "linux")]
        ReceivePath::Batched => recv_loop(
            &mut super::mmsg::MmsgBatch::new(),
            ch,
            sock,
            stop,
            rx,
            stats,
        ),
        _ => recv_loop(&mut SingleRecv::new(), ch, sock, stop, rx, stats),
    }
}

fn recv_loop(
    batch: &mut impl RecvBatch,
    ch: Channel,
    sock: &UdpSocket,
    stop: &AtomicBool,
    rx: &Receiver,
    stats: &TransportStats,
) {
    while !stop.load(Ordering::Relaxed) {
        match batch.recv(sock) {
            Ok(n) => {
                if stop.load(Ordering::Relaxed) {
                    break;
                }
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
                    continue;
                }
                stats
                    .received
                    .fetch_add(grams.len() as u64, Ordering::Relaxed);
                for d in grams {
                    tracing::trace!(channel = ?ch, from = %d.from, len = d.data.len(), "received");
                }
                rx(ch, grams);
            }
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::WouldBlock
                        | io::ErrorKind::TimedOut
                        | io::ErrorKind::Interrupted
                ) => {}
            Err(e) => {
                if stop.load(Ordering::Relaxed) {
                    break;
                }
                // ICMP port-unreachable from an earlier send shows up here as ConnectionRefused.
                tracing::debug!(channel = ?ch, error = %e, "recv error");
            }
        }
    }
}
