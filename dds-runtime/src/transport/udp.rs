//! UDPv4 sockets of one participant and the threads that receive on them.

use std::io;
use std::net::{Ipv4Addr, SocketAddr, SocketAddrV4, UdpSocket};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use socket2::{Domain, Protocol, SockRef, Socket, Type};

use super::iface::{self, Interface};
use super::ports;
use crate::config::{Config, ParticipantIndex, Peer};

/// Which socket a datagram arrived on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    /// SPDP multicast (239.255.0.1 on the domain's discovery port).
    SpdpMulticast,
    /// Metatraffic unicast (SPDP to peers, SEDP).
    MetaUnicast,
    /// User-traffic unicast.
    UserUnicast,
}

/// One received datagram.
#[derive(Debug, Clone, Copy)]
pub struct Datagram<'a> {
    /// The payload.
    pub data: &'a [u8],
    /// The sender.
    pub from: SocketAddr,
}

/// Called by the receive threads with each batch of datagrams (one `recvmmsg`, at least one datagram).
pub type Receiver = Arc<dyn Fn(Channel, &[Datagram<'_>]) + Send + Sync>;

/// Datagrams received per `recvmmsg` call.
const RECV_BATCH: usize = 8;

/// Largest UDP payload we can receive.
const RECV_BUFFER: usize = 65536;

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

/// The sockets of one participant: metatraffic and user unicast (the index's ports, or ephemeral ones),
/// and optionally the shared SPDP multicast socket.
pub struct UdpTransport {
    iface: Interface,
    domain_id: u32,
    participant_index: Option<u32>,
    multicast: bool,
    meta_uc: Arc<UdpSocket>,
    user_uc: Arc<UdpSocket>,
    spdp_mc: Option<Arc<UdpSocket>>,
    spdp_peers: Vec<SocketAddrV4>,
    stop: Arc<AtomicBool>,
    threads: Mutex<Vec<JoinHandle<()>>>,
    stats: Arc<TransportStats>,
}

impl std::fmt::Debug for UdpTransport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("UdpTransport")
            .field("iface", &self.iface.name)
            .field("addr", &self.iface.addr)
            .field("participant_index", &self.participant_index)
            .field("meta_unicast", &self.metatraffic_unicast())
            .field("user_unicast", &self.user_unicast())
            .field("multicast", &self.multicast)
            .finish()
    }
}

fn new_udp() -> io::Result<Socket> {
    Socket::new(Domain::IPV4, Type::DGRAM, Some(Protocol::UDP))
}

fn set_buffers(s: &Socket, size: usize) {
    // The kernel caps SO_RCVBUF/SO_SNDBUF at rmem_max/wmem_max; with CAP_NET_ADMIN the *FORCE variants
    // go beyond. A smaller buffer is not an error, only lossier under bursts.
    if let Err(e) = s.set_recv_buffer_size(size) {
        tracing::debug!(error = %e, "SO_RCVBUF not applied");
    }
    if let Err(e) = s.set_send_buffer_size(size) {
        tracing::debug!(error = %e, "SO_SNDBUF not applied");
    }
    // Linux reports twice the requested value.
    if s.recv_buffer_size().unwrap_or(0) < size {
        force_buffer(s, libc::SO_RCVBUFFORCE, size);
    }
    if s.send_buffer_size().unwrap_or(0) < size {
        force_buffer(s, libc::SO_SNDBUFFORCE, size);
    }
    tracing::debug!(
        rcvbuf = s.recv_buffer_size().unwrap_or(0),
        sndbuf = s.send_buffer_size().unwrap_or(0),
        "socket buffers"
    );
}

fn force_buffer(s: &Socket, opt: libc::c_int, size: usize) {
    use std::os::fd::AsRawFd;
    let v = libc::c_int::try_from(size).unwrap_or(libc::c_int::MAX);
    // SAFETY: plain setsockopt on a valid descriptor with a c_int option value of the right length.
    let r = unsafe {
        libc::setsockopt(
            s.as_raw_fd(),
            libc::SOL_SOCKET,
            opt,
            (&v as *const libc::c_int).cast(),
            std::mem::size_of::<libc::c_int>() as libc::socklen_t,
        )
    };
    if r != 0 {
        tracing::trace!(error = %io::Error::last_os_error(), opt, "forced socket buffer size not applied");
    }
}

/// A unicast socket on `port` (0: ephemeral), also used to send (multicast interface and loop set).
fn unicast_socket(iface: &Interface, port: u16, buf: usize) -> io::Result<Socket> {
    let s = new_udp()?;
    set_buffers(&s, buf);
    s.set_multicast_if_v4(&iface.addr)?;
    s.set_multicast_loop_v4(true)?;
    s.set_multicast_ttl_v4(1)?;
    s.bind(&SocketAddrV4::new(Ipv4Addr::UNSPECIFIED, port).into())?;
    Ok(s)
}

/// The shared multicast socket: every participant on the host binds the same port.
fn multicast_socket(
    iface: &Interface,
    group: Ipv4Addr,
    port: u16,
    buf: usize,
) -> io::Result<Socket> {
    let s = new_udp()?;
    s.set_reuse_address(true)?;
    s.set_reuse_port(true)?;
    set_buffers(&s, buf);
    s.bind(&SocketAddrV4::new(Ipv4Addr::UNSPECIFIED, port).into())?;
    // Without this, Linux delivers to a wildcard-bound socket the groups joined by any socket on the host.
    s.set_multicast_all_v4(false)?;
    s.join_multicast_v4_n(
        &group,
        &socket2::InterfaceIndexOrAddress::Index(iface.index),
    )?;
    Ok(s)
}

fn local_port(s: &UdpSocket) -> u16 {
    s.local_addr().map(|a| a.port()).unwrap_or(0)
}

impl UdpTransport {
    /// Chooses the interface, the participant index and binds the sockets. Starts no thread.
    pub fn bind(config: &Config) -> io::Result<Self> {
        let all = iface::list()?;
        let iface = iface::select(&config.interface, &all)?;
        let buf = config.socket_buffer_size;
        let domain = config.domain_id;
        let bad = |what: &str| io::Error::new(io::ErrorKind::InvalidInput, what.to_string());

        let (participant_index, meta_uc, user_uc) = match config.participant_index {
            ParticipantIndex::None => (
                None,
                unicast_socket(&iface, 0, buf)?,
                unicast_socket(&iface, 0, buf)?,
            ),
            ParticipantIndex::Fixed(i) => {
                let mp =
                    ports::metatraffic_unicast(domain, i).ok_or_else(|| bad("port overflow"))?;
                let up = ports::user_unicast(domain, i).ok_or_else(|| bad("port overflow"))?;
                (
                    Some(i),
                    unicast_socket(&iface, mp, buf)?,
                    unicast_socket(&iface, up, buf)?,
                )
            }
            ParticipantIndex::Auto => {
                let mut found = None;
                for i in 0..=config.max_participant_index {
                    let (Some(mp), Some(up)) = (
                        ports::metatraffic_unicast(domain, i),
                        ports::user_unicast(domain, i),
                    ) else {
                        break;
                    };
                    let Ok(m) = unicast_socket(&iface, mp, buf) else {
                        continue;
                    };
                    let Ok(u) = unicast_socket(&iface, up, buf) else {
                        continue;
                    };
                    found = Some((Some(i), m, u));
                    break;
                }
                found.ok_or_else(|| {
                    io::Error::new(
                        io::ErrorKind::AddrInUse,
                        format!(
                            "no free participant index in 0..={} for domain {domain}",
                            config.max_participant_index
                        ),
                    )
                })?
            }
        };

        let spdp_port = ports::spdp_multicast(domain).ok_or_else(|| bad("port overflow"))?;
        let spdp_mc = if config.multicast {
            Some(Arc::new(UdpSocket::from(multicast_socket(
                &iface,
                ports::SPDP_MULTICAST_GROUP,
                spdp_port,
                buf,
            )?)))
        } else {
            None
        };

        let mut spdp_peers = Vec::new();
        for p in &config.peers {
            match *p {
                Peer::SocketAddr(sa) => spdp_peers.push(sa),
                Peer::Address(a) => {
                    for i in 0..=config.max_participant_index {
                        if let Some(port) = ports::metatraffic_unicast(domain, i) {
                            spdp_peers.push(SocketAddrV4::new(a, port));
                        }
                    }
                }
            }
        }

        let t = UdpTransport {
            iface,
            domain_id: domain,
            participant_index,
            multicast: config.multicast,
            meta_uc: Arc::new(meta_uc.into()),
            user_uc: Arc::new(user_uc.into()),
            spdp_mc,
            spdp_peers,
            stop: Arc::new(AtomicBool::new(false)),
            threads: Mutex::new(Vec::new()),
            stats: Arc::new(TransportStats::default()),
        };
        tracing::info!(transport = ?t, "transport bound");
        Ok(t)
    }

    /// Starts one receive thread per socket; each calls `rx` for every datagram.
    pub fn start(&self, rx: Receiver) -> io::Result<()> {
        let mut socks = vec![
            (Channel::MetaUnicast, self.meta_uc.clone()),
            (Channel::UserUnicast, self.user_uc.clone()),
        ];
        if let Some(mc) = &self.spdp_mc {
            socks.push((Channel::SpdpMulticast, mc.clone()));
        }
        let mut threads = self.threads.lock().unwrap_or_else(|e| e.into_inner());
        for (ch, sock) in socks {
            // A timeout so that the thread notices `stop` even if shutdown() cannot wake it.
            sock.set_read_timeout(Some(Duration::from_millis(500)))?;
            let stop = self.stop.clone();
            let rx = rx.clone();
            let stats = self.stats.clone();
            let h = std::thread::Builder::new()
                .name(format!("dds-rx-{ch:?}"))
                .spawn(move || recv_loop(ch, &sock, &stop, &rx, &stats))?;
            threads.push(h);
        }
        Ok(())
    }

    /// Sends one datagram. Multicast destinations are skipped when multicast is off.
    pub fn send_to(&self, payload: &[u8], dest: SocketAddrV4) {
        if dest.ip().is_multicast() && !self.multicast {
            return;
        }
        match self.meta_uc.send_to(payload, dest) {
            Ok(_) => {
                self.stats.sent.fetch_add(1, Ordering::Relaxed);
                tracing::trace!(%dest, len = payload.len(), "sent");
            }
            Err(e) => {
                self.stats.send_errors.fetch_add(1, Ordering::Relaxed);
                tracing::debug!(%dest, len = payload.len(), error = %e, "send failed");
            }
        }
    }

    /// Sends `payload` to each destination.
    pub fn send_all(&self, payload: &[u8], dests: &[SocketAddrV4]) {
        for d in dests {
            self.send_to(payload, *d);
        }
    }

    /// The chosen interface.
    pub fn interface(&self) -> &Interface {
        &self.iface
    }
    /// Domain id the ports were computed for.
    pub fn domain_id(&self) -> u32 {
        self.domain_id
    }
    /// The participant index, `None` when ephemeral ports are used.
    pub fn participant_index(&self) -> Option<u32> {
        self.participant_index
    }
    /// Whether multicast is in use.
    pub fn multicast_enabled(&self) -> bool {
        self.multicast
    }
    /// Metatraffic unicast locator to announce.
    pub fn metatraffic_unicast(&self) -> SocketAddrV4 {
        SocketAddrV4::new(self.iface.addr, local_port(&self.meta_uc))
    }
    /// User-traffic unicast locator to announce.
    pub fn user_unicast(&self) -> SocketAddrV4 {
        SocketAddrV4::new(self.iface.addr, local_port(&self.user_uc))
    }
    /// SPDP multicast locator to announce, if multicast is on.
    pub fn spdp_multicast(&self) -> Option<SocketAddrV4> {
        self.spdp_mc.as_ref().and_then(|_| {
            ports::spdp_multicast(self.domain_id)
                .map(|p| SocketAddrV4::new(ports::SPDP_MULTICAST_GROUP, p))
        })
    }
    /// Unicast SPDP destinations from the configured peers.
    pub fn spdp_peers(&self) -> &[SocketAddrV4] {
        &self.spdp_peers
    }
    /// Datagram counters.
    pub fn stats(&self) -> &TransportStats {
        &self.stats
    }

    /// Stops and joins the receive threads. Idempotent; also done on drop.
    pub fn shutdown(&self) {
        if self.stop.swap(true, Ordering::SeqCst) {
            return;
        }
        let mut socks: Vec<&UdpSocket> = vec![&self.meta_uc, &self.user_uc];
        if let Some(mc) = &self.spdp_mc {
            socks.push(mc);
        }
        for s in socks {
            // On Linux this wakes a blocked recvfrom even on an unconnected UDP socket (it reports ENOTCONN).
            let _ = SockRef::from(s).shutdown(std::net::Shutdown::Read);
        }
        let threads = std::mem::take(&mut *self.threads.lock().unwrap_or_else(|e| e.into_inner()));
        let me = std::thread::current().id();
        for h in threads {
            // A receive callback may drop the last participant handle; never join ourselves.
            if h.thread().id() != me {
                let _ = h.join();
            }
        }
        tracing::debug!("transport stopped");
    }
}

impl Drop for UdpTransport {
    fn drop(&mut self) {
        self.shutdown();
    }
}

/// Buffers for one `recvmmsg` call. The pointers inside `hdrs` point into the other vectors' heap storage,
/// which never reallocates after construction.
struct RecvBatch {
    bufs: Vec<Vec<u8>>,
    addrs: Vec<libc::sockaddr_storage>,
    /// Never read from Rust: `hdrs` point into it, so it must live as long as the batch.
    #[allow(dead_code)]
    iovs: Vec<libc::iovec>,
    hdrs: Vec<libc::mmsghdr>,
}

// SAFETY: the raw pointers only reference the batch's own heap buffers; the batch is used by one thread.
unsafe impl Send for RecvBatch {}

impl RecvBatch {
    fn new() -> Self {
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
        RecvBatch {
            bufs,
            addrs,
            iovs,
            hdrs,
        }
    }

    /// Blocks for the first datagram, then takes what else is queued; returns how many arrived.
    fn recv(&mut self, sock: &UdpSocket) -> io::Result<usize> {
        use std::os::fd::AsRawFd;
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
                libc::MSG_WAITFORONE,
                std::ptr::null_mut(),
            )
        };
        if n < 0 {
            Err(io::Error::last_os_error())
        } else {
            Ok(n as usize)
        }
    }

    fn datagram(&self, i: usize) -> Option<Datagram<'_>> {
        let len = (self.hdrs[i].msg_len as usize).min(self.bufs[i].len());
        let from = sockaddr_v4(&self.addrs[i])?;
        Some(Datagram {
            data: &self.bufs[i][..len],
            from,
        })
    }
}

fn sockaddr_v4(a: &libc::sockaddr_storage) -> Option<SocketAddr> {
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

fn recv_loop(
    ch: Channel,
    sock: &UdpSocket,
    stop: &AtomicBool,
    rx: &Receiver,
    stats: &TransportStats,
) {
    let mut batch = RecvBatch::new();
    while !stop.load(Ordering::Relaxed) {
        match batch.recv(sock) {
            Ok(n) => {
                if stop.load(Ordering::Relaxed) {
                    break;
                }
                let grams: Vec<Datagram<'_>> = (0..n)
                    .filter_map(|i| batch.datagram(i))
                    .filter(|d| !d.data.is_empty())
                    .collect();
                if grams.is_empty() {
                    continue;
                }
                stats
                    .received
                    .fetch_add(grams.len() as u64, Ordering::Relaxed);
                for d in &grams {
                    tracing::trace!(channel = ?ch, from = %d.from, len = d.data.len(), "received");
                }
                rx(ch, &grams);
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
