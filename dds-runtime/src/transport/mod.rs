//! UDP transport over IPv4 or IPv6 ([`AddressFamily`](crate::config::AddressFamily)): interface selection, participant index probing (with the core's port formula,
//! [`crate::rtps::discovery::ports`]), the shared
//! SPDP multicast socket and receive threads.
//!
//! The transport knows nothing of RTPS messages. Receive threads hand every datagram to a
//! [`Receiver`] callback (the DCPS layer feeds it to the sans-I/O core); sending happens on whichever
//! thread drained the core's transmit queue, through [`UdpTransport::send_to`].
//!
//! Sockets:
//! - metatraffic unicast and user unicast, bound to `0.0.0.0` on the index's ports (or ephemeral ports when
//!   the participant index is `none`) and announced with the selected interface's address; the metatraffic
//!   socket also sends, with `IP_MULTICAST_IF` set to the interface and `IP_MULTICAST_LOOP` on so that
//!   participants on the same host see each other;
//! - when multicast is on, the SPDP multicast socket: `SO_REUSEADDR` + `SO_REUSEPORT` on the domain's
//!   discovery port, joined to 239.255.0.1 (IPv6: ff02::ffff:239.255.0.1) on the selected interface only
//!   (`IP_MULTICAST_ALL` off);
//! - when multicast data is on (`DDS_MULTICAST_DATA`), the same for the user-data group on the domain's
//!   user multicast port: our readers announce it, and peers' writers send there once for all of them.
//!
//! IPv6 sockets are IPv6-only; a participant speaks one family (`DDS_TRANSPORT`), and destinations of the
//! other family are skipped.
//!
//! On Linux, receive threads read with `recvmmsg` (up to 8 datagrams per call) and hand the whole batch to
//! the receiver, so the core's lock is taken once per batch; while the batches hold one datagram each (a
//! ping/pong), they read with `recvmsg`, which does not try for a second. With
//! [`Config::receive_spin`](crate::config::Config::receive_spin) (off by default), a receive thread polls
//! its socket for a while after a batch of dense traffic instead of sleeping, unless the cores are
//! contended (`poll.rs` decides). Elsewhere, or with
//! [`ReceivePath::OneByOne`], they read one datagram per `recv_from`. Sends are one `sendto` per datagram,
//! except that a busy unicast destination gets a socket connected to it (`send`, no route lookup per
//! datagram; at most 8 per participant), and on Linux a run of equal-sized datagrams to one destination (a
//! fragmented sample's) leaves in one `sendmsg` with `UDP_SEGMENT` ([`UdpTransport::send_run`];
//! `DDS_GSO=off` turns it off). A datagram may be given in pieces (its headers, then a slice of the
//! sample), which leave gathered by the kernel (`sendmsg` with one `iovec` each), also within a
//! segmented run. Options that only Linux has
//! (`SO_RCVBUFFORCE`, `IP_MULTICAST_ALL`) are set only there.

mod connected;
mod datagram;
mod gather;
#[cfg(target_os = "linux")]
mod gso;
pub mod iface;
#[cfg(target_os = "linux")]
mod mmsg;
mod poll;
mod recv;
#[cfg(feature = "shm")]
pub mod shm;
mod socket;
mod udp;

/// Stack of the threads that deliver samples to readers (receive, timer and shared-memory threads): a
/// `DataReader<T>` of a large plain type (a 4 MiB array) decodes it by value on them. Reserved, not
/// committed: only what is used takes memory.
pub(crate) const DELIVERY_STACK: usize = 64 << 20;

pub use datagram::{Channel, Datagram, Receiver, TransportStats};
pub use gather::Pieces;
pub(crate) use gather::{with_run_pieces, RUN};
pub use iface::Interface;
pub use recv::ReceivePath;
pub use udp::UdpTransport;
