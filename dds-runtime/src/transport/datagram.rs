//! What the receive paths and the sockets share: the datagram as handed to the receiver, the socket it
//! came from, the receiver callback, counters, and the batch-reading interface of the receive paths.

use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::AtomicU64;
use std::sync::Arc;

/// Which socket a datagram arrived on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Channel {
    /// SPDP multicast (239.255.0.1, or ff02::ffff:239.255.0.1, on the domain's discovery port).
    SpdpMulticast,
    /// Metatraffic unicast (SPDP to peers, SEDP).
    MetaUnicast,
    /// User-traffic unicast.
    UserUnicast,
    /// User-traffic multicast (the group of `DDS_MULTICAST_DATA`).
    UserMulticast,
}

/// One received datagram.
#[derive(Debug, Clone, Copy)]
pub struct Datagram<'a> {
    /// The payload.
    pub data: &'a [u8],
    /// The sender.
    pub from: SocketAddr,
}

/// Called by the receive threads with each batch of datagrams (at least one; see [`ReceivePath`](super::ReceivePath)).
pub type Receiver = Arc<dyn Fn(Channel, &[Datagram<'_>]) + Send + Sync>;

/// Counters for diagnostics and tests.
#[derive(Debug, Default)]
pub struct TransportStats {
    /// Datagrams received.
    pub received: AtomicU64,
    /// Datagrams sent.
    pub sent: AtomicU64,
    /// Send failures (logged, not returned: UDP is lossy anyway).
    pub send_errors: AtomicU64,
}

/// Most datagrams one read of a socket returns.
pub(super) const MAX_BATCH: usize = 8;

/// Largest UDP payload we can receive.
pub(super) const RECV_BUFFER: usize = 65536;

/// Buffers for reading one batch of datagrams from a socket.
pub(super) trait RecvBatch {
    /// Blocks for the first datagram, then takes what else the implementation can; returns how many arrived.
    fn recv(&mut self, sock: &UdpSocket) -> io::Result<usize>;
    /// Takes what is queued without blocking (`WouldBlock` when nothing is). Only paths that can poll are
    /// ever asked; the others keep this default.
    fn try_recv(&mut self, _sock: &UdpSocket) -> io::Result<usize> {
        Err(io::ErrorKind::Unsupported.into())
    }
    /// The `i`th datagram of the last batch; `None` when its sender is neither IPv4 nor IPv6.
    fn datagram(&self, i: usize) -> Option<Datagram<'_>>;
}
