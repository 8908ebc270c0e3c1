//! UDP sockets (IPv4 or IPv6) of one participant and the threads that receive on them.

use std::io;
use std::net::{IpAddr, SocketAddr, SocketAddrV6, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use socket2::{SockRef, Socket};

use super::connected::{self, Connected};
use super::datagram::{Channel, Receiver, TransportStats};
use super::gather::{self, Pieces};
#[cfg(target_os = "linux")]
use super::gso::{self, GsoState};
use super::iface::{self, Interface};
use super::recv::{self, ReceivePath};
use super::socket::{multicast_socket, unicast_socket};
use crate::config::{AddressFamily, Config, ParticipantIndex, Peer};
use crate::rtps::discovery::ports::{self, PortError};

/// The sockets of one participant: metatraffic and user unicast (the index's ports, or ephemeral ones),
/// and optionally the shared SPDP multicast socket and the user-data multicast socket.
pub struct UdpTransport {
    iface: Interface,
    family: AddressFamily,
    domain_id: u32,
    participant_index: Option<u32>,
    multicast: bool,
    meta_uc: Arc<UdpSocket>,
    user_uc: Arc<UdpSocket>,
    spdp_mc: Option<Arc<UdpSocket>>,
    /// The user-data group and its socket, when multicast data is on.
    user_mc: Option<(SocketAddr, Arc<UdpSocket>)>,
    spdp_peers: Vec<SocketAddr>,
    stop: Arc<AtomicBool>,
    threads: Mutex<Vec<JoinHandle<()>>>,
    stats: Arc<TransportStats>,
    /// Which destinations take segmented sends (Linux `UDP_SEGMENT`).
    #[cfg(target_os = "linux")]
    gso: GsoState,
    /// How long receive threads poll after a batch (`Config::receive_spin`).
    spin: Duration,
    /// Sockets connected to the busiest unicast destinations.
    connected: Connected,
    /// `Config::socket_buffer_size`, for the connected sockets.
    buf: usize,
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
            .field("user_multicast", &self.user_multicast())
            .finish()
    }
}

/// The unicast sockets and the participant index they were bound for.
type UnicastSockets = (Option<u32>, Socket, Socket);

/// Binds the metatraffic and user unicast sockets as the configured participant index says.
fn bind_unicast(config: &Config, iface: &Interface) -> io::Result<UnicastSockets> {
    let buf = config.socket_buffer_size;
    let domain = config.domain_id;
    Ok(match config.participant_index {
        ParticipantIndex::None => (
            None,
            unicast_socket(iface, 0, buf)?,
            unicast_socket(iface, 0, buf)?,
        ),
        ParticipantIndex::Fixed(i) => {
            let mp = ports::metatraffic_unicast(domain, i).map_err(port_error)?;
            let up = ports::user_unicast(domain, i).map_err(port_error)?;
            (
                Some(i),
                unicast_socket(iface, mp, buf)?,
                unicast_socket(iface, up, buf)?,
            )
        }
        ParticipantIndex::Auto => {
            let mut found = None;
            for i in 0..=config.max_participant_index {
                let (Ok(mp), Ok(up)) = (
                    ports::metatraffic_unicast(domain, i),
                    ports::user_unicast(domain, i),
                ) else {
                    break;
                };
                let Ok(m) = unicast_socket(iface, mp, buf) else {
                    continue;
                };
                let Ok(u) = unicast_socket(iface, up, buf) else {
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
    })
}

/// Unicast SPDP destinations: each peer's address, or its metatraffic ports of every index up to the maximum.
fn spdp_peers(config: &Config) -> Vec<SocketAddr> {
    let mut spdp_peers = Vec::new();
    for p in &config.peers {
        match *p {
            Peer::SocketAddr(sa) => spdp_peers.push(sa),
            Peer::Address(a) => {
                for i in 0..=config.max_participant_index {
                    if let Ok(port) = ports::metatraffic_unicast(config.domain_id, i) {
                        spdp_peers.push(SocketAddr::new(a, port));
                    }
                }
            }
        }
    }
    spdp_peers
}

/// The group socket for `group` on `port`, or `None` when there is no group.
fn group_socket(
    iface: &Interface,
    group: Option<IpAddr>,
    port: u16,
    buf: usize,
) -> io::Result<Option<(SocketAddr, Arc<UdpSocket>)>> {
    let Some(group) = group else {
        return Ok(None);
    };
    let s = multicast_socket(iface, group, port, buf)?;
    Ok(Some((SocketAddr::new(group, port), Arc::new(s.into()))))
}

/// A port that does not fit is invalid input to [`UdpTransport::bind`]; the typed error is the source.
fn port_error(e: PortError) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, e)
}

fn local_port(s: &UdpSocket) -> u16 {
    s.local_addr().map(|a| a.port()).unwrap_or(0)
}

impl UdpTransport {
    /// Chooses the interface, the participant index and binds the sockets. Starts no thread.
    pub fn bind(config: &Config) -> io::Result<Self> {
        config
            .validate()
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e))?;
        let family = config.transport;
        let all = iface::list()?;
        let iface = iface::select_in(family, &config.interface, &all)?;
        let buf = config.socket_buffer_size;
        let domain = config.domain_id;

        let (participant_index, meta_uc, user_uc) = bind_unicast(config, &iface)?;
        let spdp_port = ports::spdp_multicast(domain).map_err(port_error)?;
        let spdp_group = config.multicast.then(|| family.spdp_group());
        let spdp_mc = group_socket(&iface, spdp_group, spdp_port, buf)?.map(|(_, s)| s);
        let user_port = ports::user_multicast(domain).map_err(port_error)?;
        let user_mc = group_socket(&iface, config.multicast_data_group(), user_port, buf)?;

        let spdp_peers = spdp_peers(config);
        let t = UdpTransport {
            iface,
            family,
            domain_id: domain,
            participant_index,
            multicast: config.multicast,
            meta_uc: Arc::new(meta_uc.into()),
            user_uc: Arc::new(user_uc.into()),
            spdp_mc,
            user_mc,
            spdp_peers,
            stop: Arc::new(AtomicBool::new(false)),
            threads: Mutex::new(Vec::new()),
            stats: Arc::new(TransportStats::default()),
            #[cfg(target_os = "linux")]
            gso: GsoState::new(config.gso),
            spin: config.receive_spin,
            connected: Connected::new(true),
            buf,
        };
        tracing::info!(transport = ?t, "transport bound");
        Ok(t)
    }

    /// Starts one receive thread per socket; each calls `rx` for every datagram. Reads in batches where the
    /// platform can ([`ReceivePath::Batched`]).
    pub fn start(&self, rx: Receiver) -> io::Result<()> {
        self.start_with(rx, ReceivePath::default())
    }

    /// Like [`UdpTransport::start`], reading the sockets the given way.
    pub fn start_with(&self, rx: Receiver, path: ReceivePath) -> io::Result<()> {
        let mut socks = vec![
            (Channel::MetaUnicast, self.meta_uc.clone()),
            (Channel::UserUnicast, self.user_uc.clone()),
        ];
        if let Some(mc) = &self.spdp_mc {
            socks.push((Channel::SpdpMulticast, mc.clone()));
        }
        if let Some((_, mc)) = &self.user_mc {
            socks.push((Channel::UserMulticast, mc.clone()));
        }
        let mut threads = self.threads.lock().unwrap_or_else(|e| e.into_inner());
        for (ch, sock) in socks {
            // A timeout so that the thread notices `stop` even if shutdown() cannot wake it.
            sock.set_read_timeout(Some(Duration::from_millis(500)))?;
            let stop = self.stop.clone();
            let rx = rx.clone();
            let stats = self.stats.clone();
            let spin = self.spin;
            let h = std::thread::Builder::new()
                .name(format!("dds-rx-{ch:?}"))
                .stack_size(super::DELIVERY_STACK)
                .spawn(move || recv::run(path, spin, ch, &sock, &stop, &rx, &stats))?;
            threads.push(h);
        }
        Ok(())
    }

    /// Sends one datagram. Multicast destinations are skipped when multicast is off, and destinations of
    /// the other address family always (a peer may announce both). A busy unicast destination gets a
    /// socket of its own, connected to it (`connected.rs`).
    pub fn send_to(&self, payload: &[u8], dest: impl Into<SocketAddr>) {
        let dest = self.scoped(dest.into());
        if (dest.ip().is_multicast() && !self.multicast) || !self.family.contains(dest.ip()) {
            return;
        }
        let r = self
            .connected
            .with(dest, &self.iface, self.buf, |s| match s.send(payload) {
                // An ICMP error of an earlier send to this destination: this one was not sent.
                Err(e) if connected::stale_error(&e) => s.send(payload),
                r => r,
            })
            .unwrap_or_else(|| self.meta_uc.send_to(payload, dest));
        match r {
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

    /// Sends `payloads` to `dest`, in order. On Linux a run of datagrams of one length (the last may be
    /// shorter) leaves in one `UDP_SEGMENT` send, as a fragmented sample's do, where the kernel and the
    /// path allow it; elsewhere, and after a refusal, one `sendto` per datagram.
    ///
    /// A datagram may be given in pieces (`&[&[u8]]`, [`Pieces`]): they leave as one datagram, gathered by
    /// the kernel, without a copy here.
    pub fn send_run<P: Pieces>(&self, payloads: &[P], dest: impl Into<SocketAddr>) {
        let dest = self.scoped(dest.into());
        let mut rest = payloads;
        while !rest.is_empty() {
            let n = self.send_segmented(rest, dest);
            if n == 0 {
                self.send_pieces(rest[0].pieces(), dest);
                rest = &rest[1..];
            } else {
                rest = &rest[n..];
            }
        }
    }

    /// One segmented send of the run at the head of `payloads`: how many datagrams it took (0: not sent,
    /// send the first one alone).
    #[cfg(target_os = "linux")]
    fn send_segmented<P: Pieces>(&self, payloads: &[P], dest: SocketAddr) -> usize {
        let n = gso::run_len(payloads);
        if n < 2
            || (dest.ip().is_multicast() && !self.multicast)
            || !self.family.contains(dest.ip())
            || !self.gso.allows(dest)
        {
            return 0;
        }
        let run = &payloads[..n];
        let sent = self
            .connected
            .with(dest, &self.iface, self.buf, |s| {
                gso::send_segments(s, run, None)
            })
            .unwrap_or_else(|| gso::send_segments(&self.meta_uc, run, Some(dest)));
        match sent {
            Ok(()) => {
                self.stats.sent.fetch_add(n as u64, Ordering::Relaxed);
                tracing::trace!(%dest, datagrams = n, len = payloads[0].total_len(), "sent segmented");
                n
            }
            Err(e) if gso::unsupported(&e) => {
                self.gso.refused(dest, &e);
                0
            }
            Err(e) => {
                self.stats
                    .send_errors
                    .fetch_add(n as u64, Ordering::Relaxed);
                tracing::debug!(%dest, datagrams = n, error = %e, "segmented send failed");
                n
            }
        }
    }

    #[cfg(not(target_os = "linux"))]
    fn send_segmented<P: Pieces>(&self, _: &[P], _: SocketAddr) -> usize {
        0
    }

    /// Sends one datagram given in pieces, as [`send_to`](UdpTransport::send_to) does one buffer.
    fn send_pieces(&self, pieces: &[&[u8]], dest: SocketAddr) {
        if let [one] = pieces {
            return self.send_to(one, dest);
        }
        if (dest.ip().is_multicast() && !self.multicast) || !self.family.contains(dest.ip()) {
            return;
        }
        let r = self
            .connected
            .with(dest, &self.iface, self.buf, |s| {
                match gather::send_pieces(s, pieces, None) {
                    Err(e) if connected::stale_error(&e) => gather::send_pieces(s, pieces, None),
                    r => r,
                }
            })
            .unwrap_or_else(|| gather::send_pieces(&self.meta_uc, pieces, Some(dest)));
        let len = pieces.total_len();
        match r {
            Ok(_) => {
                self.stats.sent.fetch_add(1, Ordering::Relaxed);
                tracing::trace!(%dest, len, pieces = pieces.len(), "sent gathered");
            }
            Err(e) => {
                self.stats.send_errors.fetch_add(1, Ordering::Relaxed);
                tracing::debug!(%dest, len, error = %e, "send failed");
            }
        }
    }

    /// Sends `payload` to each destination.
    pub fn send_all(&self, payload: &[u8], dests: &[SocketAddr]) {
        for d in dests {
            self.send_to(payload, *d);
        }
    }

    /// A link-local IPv6 destination gets our interface as its scope (a locator carries no scope).
    fn scoped(&self, dest: SocketAddr) -> SocketAddr {
        match dest {
            SocketAddr::V6(v6) if v6.scope_id() == 0 && needs_scope(v6.ip()) => SocketAddr::V6(
                SocketAddrV6::new(*v6.ip(), v6.port(), v6.flowinfo(), self.iface.index),
            ),
            d => d,
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
    /// The address family of every socket.
    pub fn address_family(&self) -> AddressFamily {
        self.family
    }
    /// Metatraffic unicast locator to announce.
    pub fn metatraffic_unicast(&self) -> SocketAddr {
        SocketAddr::new(self.iface.addr, local_port(&self.meta_uc))
    }
    /// User-traffic unicast locator to announce.
    pub fn user_unicast(&self) -> SocketAddr {
        SocketAddr::new(self.iface.addr, local_port(&self.user_uc))
    }
    /// SPDP multicast locator to announce, if multicast is on.
    pub fn spdp_multicast(&self) -> Option<SocketAddr> {
        self.spdp_mc.as_ref().and_then(|_| {
            ports::spdp_multicast(self.domain_id)
                .ok()
                .map(|p| SocketAddr::new(self.family.spdp_group(), p))
        })
    }
    /// User-data multicast locator our readers announce (and whose group we joined), if multicast data
    /// is on.
    pub fn user_multicast(&self) -> Option<SocketAddr> {
        self.user_mc.as_ref().map(|(a, _)| *a)
    }
    /// Unicast SPDP destinations from the configured peers.
    pub fn spdp_peers(&self) -> &[SocketAddr] {
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
        if let Some((_, mc)) = &self.user_mc {
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

/// Link-local unicast (fe80::/10) and link- or interface-local multicast (ff01::/16, ff02::/16) need a scope.
fn needs_scope(a: &std::net::Ipv6Addr) -> bool {
    let s0 = a.segments()[0];
    s0 & 0xffc0 == 0xfe80 || (s0 & 0xff00 == 0xff00 && matches!(s0 & 0x000f, 1 | 2))
}
