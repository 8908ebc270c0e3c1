//! Participant configuration: defaults, environment variables and builder setters.
//!
//! [`Config::from_env`] starts from [`Config::default`] and applies these variables; the
//! `DomainParticipant` builder applies its own setters on top (the builder wins).
//!
//! | variable | meaning | values | default |
//! |---|---|---|---|
//! | `DDS_DOMAIN_ID` | domain id | `0`..=`232` | `0` |
//! | `DDS_TRANSPORT` | address family of every socket and locator | `udp` (or `udp4`: IPv4), `udp6` (IPv6), as Cyclone's `General/Transport` | `udp` |
//! | `DDS_INTERFACE` | network interface for all traffic | interface name (`lo`, `eth0`) or address (`127.0.0.1`, `::1`) | first up, multicast-capable, non-loopback interface of the family, else loopback |
//! | `DDS_MULTICAST` | use multicast (SPDP send and receive; the switch for multicast data too) | `on`/`off`, `true`/`false`, `1`/`0` | `on` |
//! | `DDS_MULTICAST_DATA` | multicast user data: our readers announce and join a multicast group, and our writers send a sample once to a group that two or more of their readers share | `off`, `on` (239.255.0.1, or ff02::ffff:239.255.0.1 with `udp6`, on the domain's user multicast port), or a group address | `off` |
//! | `DDS_PEERS` | unicast discovery peers | comma-separated `ip`, `ip:port`, `[ipv6]:port`; a bare ip expands to the SPDP ports of participant indices `0..=DDS_MAX_PARTICIPANT_INDEX` | none |
//! | `DDS_PARTICIPANT_INDEX` | participant index in the port formula | `auto` (probe `0..=max` by binding unicast ports), `none` (ephemeral ports), or a number | `auto` |
//! | `DDS_MAX_PARTICIPANT_INDEX` | highest index probed by `auto` and expanded by `DDS_PEERS` | number | `9` |
//! | `DDS_SPDP_INTERVAL_MS` | period of SPDP announcements | milliseconds | `1000` |
//! | `DDS_LEASE_DURATION_MS` | participant lease duration announced to peers | milliseconds | `10000` |
//! | `DDS_FRAGMENT_SIZE` | DATA_FRAG fragment size | bytes, `256`..=`65000` | `1344` |
//! | `DDS_MAX_MESSAGE_SIZE` | largest RTPS message (datagram) we send | bytes, `512`..=`65500` | `14720` |
//! | `DDS_SOCKET_BUFFER_SIZE` | requested SO_RCVBUF / SO_SNDBUF | bytes | `4194304` |
//! | `DDS_INTRA_PROCESS` | deliver to readers of the same participant directly (no serialization for them, no socket) | `on`/`off`, `true`/`false`, `1`/`0` | `on` |
//! | `DDS_GSO` | on Linux, a fragmented sample's datagrams to one destination leave in one `UDP_SEGMENT` send | `on`/`off`, `true`/`false`, `1`/`0` | `on` |
//! | `DDS_GATHER_MIN` | fragments of large samples of at least this many bytes per DATA_FRAG leave without a copy (scatter-gather sends of the sample's own buffer) | bytes, or `off` | `2048` |
//! | `DDS_RECEIVE_SPIN_US` | adaptive busy polling: while datagrams arrive less than 8 times this apart, a receive thread polls its socket up to this long after each batch instead of sleeping (saves a wake-up per datagram); it stops while the cores are contended (Linux CPU pressure, preempted polls) | microseconds, `0` = off | `50` |
//! | `DDS_SHM` | with the `shm` feature: shared memory with peers on this host (their readers get our writers' samples through it, not UDP) | `on`/`off`, `true`/`false`, `1`/`0` | `on` |
//! | `DDS_WRITE_BATCH` | write batching: samples share datagrams until full, flushed, or this delay has passed | `off`, `on` (1 ms), or a delay in microseconds | `off` |
//!
//! Invalid values are reported as [`ConfigError`] rather than silently ignored.

use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr};
use std::time::Duration;

use crate::rtps::discovery::ports::{self, PortError};

/// Highest valid domain id for UDPv4 with the default port parameters (PB + DG·232 + offsets < 65536).
pub const MAX_DOMAIN_ID: u32 = ports::MAX_DOMAIN_ID;

/// Why a configuration value was rejected. `name` is the environment variable or the [`Config`] field.
#[derive(Debug, thiserror::Error, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum ConfigError {
    /// A numeric setting is not a number.
    #[error("invalid value {value:?} for {name}: not a number")]
    NotANumber {
        /// Variable or setting name.
        name: &'static str,
        /// The value given.
        value: String,
    },
    /// A switch is none of `on`/`off`, `true`/`false`, `yes`/`no`, `1`/`0`.
    #[error("invalid value {value:?} for {name}: expected on/off")]
    NotOnOff {
        /// Variable or setting name.
        name: &'static str,
        /// The value given.
        value: String,
    },
    /// `DDS_WRITE_BATCH` is neither `on`/`off` nor a number of microseconds.
    #[error("invalid value {value:?} for DDS_WRITE_BATCH: expected off, on or microseconds")]
    WriteBatch {
        /// The value given.
        value: String,
    },
    /// A peer is not an IP address or `address:port`.
    #[error("invalid value {value:?} for DDS_PEERS: expected an IP address or address:port")]
    Peer {
        /// The value given.
        value: String,
    },
    /// `DDS_TRANSPORT` is not `udp`, `udp4` or `udp6`.
    #[error("invalid value {value:?} for DDS_TRANSPORT: expected udp, udp4 or udp6")]
    Transport {
        /// The value given.
        value: String,
    },
    /// `DDS_MULTICAST_DATA` is neither on/off nor a multicast address.
    #[error("invalid value {value:?} for DDS_MULTICAST_DATA: expected off, on or a multicast group address")]
    MulticastData {
        /// The value given.
        value: String,
    },
    /// An address (interface, peer or multicast group) is not of the configured address family.
    #[error("{name} {addr} is not an address of the configured family ({family:?})")]
    AddressFamily {
        /// Setting name.
        name: &'static str,
        /// The address given.
        addr: IpAddr,
        /// The configured family.
        family: AddressFamily,
    },
    /// A size is outside its range.
    #[error("invalid value {value} for {name}: must be {min}..={max}")]
    OutOfRange {
        /// Setting name.
        name: &'static str,
        /// The value given.
        value: usize,
        /// Smallest accepted value.
        min: usize,
        /// Largest accepted value.
        max: usize,
    },
    /// The fragment size leaves no room for the RTPS headers below the largest message.
    #[error("fragment_size {fragment_size} must leave room for RTPS headers below max_message_size {max_message_size}")]
    FragmentTooLarge {
        /// The fragment size given.
        fragment_size: usize,
        /// The largest message size given.
        max_message_size: usize,
    },
    /// The SPDP interval is zero or longer than the lease duration.
    #[error("spdp_interval {spdp_interval:?} must be non-zero and not longer than the lease duration {lease_duration:?}")]
    SpdpInterval {
        /// The interval given.
        spdp_interval: Duration,
        /// The lease duration given.
        lease_duration: Duration,
    },
    /// The domain id or a participant index gives a port above 65535.
    #[error("invalid {name}: {source}")]
    Port {
        /// Setting name (`domain_id`, `participant_index` or `max_participant_index`).
        name: &'static str,
        /// Which port does not fit.
        #[source]
        source: PortError,
    },
}

impl From<PortError> for ConfigError {
    fn from(source: PortError) -> Self {
        let name = match source {
            PortError::Domain { .. } => "domain_id",
            _ => "participant_index",
        };
        ConfigError::Port { name, source }
    }
}

/// The address family of the participant's sockets and locators (Cyclone's `General/Transport`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AddressFamily {
    /// UDP over IPv4 (`udp`, `udp4`): LOCATOR_KIND_UDPv4.
    #[default]
    Ipv4,
    /// UDP over IPv6 (`udp6`): LOCATOR_KIND_UDPv6; SPDP multicast on ff02::ffff:239.255.0.1, as Cyclone.
    Ipv6,
}

impl AddressFamily {
    /// Parses `udp`, `udp4` or `udp6` (case-insensitive).
    pub fn parse(s: &str) -> Result<Self, ConfigError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "udp" | "udp4" | "ipv4" => Ok(AddressFamily::Ipv4),
            "udp6" | "ipv6" => Ok(AddressFamily::Ipv6),
            _ => Err(ConfigError::Transport {
                value: s.to_string(),
            }),
        }
    }

    /// Whether `a` belongs to this family.
    pub fn contains(self, a: IpAddr) -> bool {
        matches!(
            (self, a),
            (AddressFamily::Ipv4, IpAddr::V4(_)) | (AddressFamily::Ipv6, IpAddr::V6(_))
        )
    }

    /// The SPDP multicast group: 239.255.0.1, or ff02::ffff:239.255.0.1 (Cyclone's IPv6 default).
    pub fn spdp_group(self) -> IpAddr {
        match self {
            AddressFamily::Ipv4 => IpAddr::V4(ports::SPDP_MULTICAST_GROUP),
            AddressFamily::Ipv6 => IpAddr::V6(SPDP_MULTICAST_GROUP_V6),
        }
    }

    /// The loopback address of the family.
    pub fn loopback(self) -> IpAddr {
        match self {
            AddressFamily::Ipv4 => IpAddr::V4(Ipv4Addr::LOCALHOST),
            AddressFamily::Ipv6 => IpAddr::V6(Ipv6Addr::LOCALHOST),
        }
    }
}

/// The IPv6 SPDP multicast group Cyclone uses: ff02::ffff:239.255.0.1 (link-local scope).
pub const SPDP_MULTICAST_GROUP_V6: Ipv6Addr =
    Ipv6Addr::new(0xff02, 0, 0, 0, 0, 0xffff, 0xefff, 0x0001);

/// Multicast user data (`DDS_MULTICAST_DATA`), like Cyclone's `AllowMulticast` for data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MulticastData {
    /// Readers announce no multicast locator; writers send user data unicast only.
    #[default]
    Off,
    /// The SPDP group of the address family (as Cyclone's default) on the domain's user multicast port.
    On,
    /// This group on the domain's user multicast port.
    Group(IpAddr),
}

impl MulticastData {
    /// `off`/`on` (any form [`Config::from_lookup`] accepts for a switch) or a multicast group address.
    pub fn parse(s: &str) -> Result<Self, ConfigError> {
        let err = || ConfigError::MulticastData {
            value: s.to_string(),
        };
        if let Ok(a) = s.trim().parse::<IpAddr>() {
            return if a.is_multicast() {
                Ok(MulticastData::Group(a))
            } else {
                Err(err())
            };
        }
        match parse_bool("DDS_MULTICAST_DATA", s) {
            Ok(true) => Ok(MulticastData::On),
            Ok(false) => Ok(MulticastData::Off),
            Err(_) => Err(err()),
        }
    }

    /// The group to join and announce for `family`, `None` when off.
    pub fn group(self, family: AddressFamily) -> Option<IpAddr> {
        match self {
            MulticastData::Off => None,
            MulticastData::On => Some(family.spdp_group()),
            MulticastData::Group(g) => Some(g),
        }
    }
}

/// Which network interface the participant uses.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum InterfaceSelection {
    /// First up, multicast-capable, non-loopback interface of the address family; loopback when there is
    /// none.
    #[default]
    Auto,
    /// Interface by name, e.g. `lo`.
    Name(String),
    /// Interface by (one of) its addresses, IPv4 or IPv6.
    Address(IpAddr),
}

impl InterfaceSelection {
    /// Parses `lo`, `eth0`, `127.0.0.1` or `::1`; an empty string or `auto` means
    /// [`InterfaceSelection::Auto`].
    pub fn parse(s: &str) -> Self {
        let s = s.trim();
        if s.is_empty() || s.eq_ignore_ascii_case("auto") {
            InterfaceSelection::Auto
        } else if let Ok(a) = s.parse::<IpAddr>() {
            InterfaceSelection::Address(a)
        } else {
            InterfaceSelection::Name(s.to_string())
        }
    }
}

/// How the participant index of the RTPS port formula is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ParticipantIndex {
    /// Probe `0..=max_participant_index` and take the first index whose unicast ports are free.
    #[default]
    Auto,
    /// No index: unicast sockets use ephemeral ports (reachable only through SPDP announcements).
    None,
    /// This exact index; creating the participant fails when its ports are taken.
    Fixed(u32),
}

/// A unicast discovery peer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Peer {
    /// An address: SPDP goes to the metatraffic unicast ports of every participant index up to the maximum.
    Address(IpAddr),
    /// An exact address and port.
    SocketAddr(SocketAddr),
}

impl Peer {
    /// Parses `127.0.0.1`, `127.0.0.1:7410`, `::1` or `[::1]:7410`.
    pub fn parse(s: &str) -> Result<Self, ConfigError> {
        let s = s.trim();
        if let Ok(a) = s.parse::<IpAddr>() {
            return Ok(Peer::Address(a));
        }
        if let Ok(sa) = s.parse::<SocketAddr>() {
            return Ok(Peer::SocketAddr(sa));
        }
        // Accept `localhost` for convenience; nothing else is resolved (no DNS from a DDS stack).
        if s.eq_ignore_ascii_case("localhost") {
            return Ok(Peer::Address(IpAddr::V4(Ipv4Addr::LOCALHOST)));
        }
        Err(ConfigError::Peer {
            value: s.to_string(),
        })
    }
}

/// The complete configuration of a participant's network side.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Config {
    /// DDS domain id.
    pub domain_id: u32,
    /// Address family of the sockets and locators (IPv4 or IPv6).
    pub transport: AddressFamily,
    /// Network interface used for sending, receiving and multicast membership.
    pub interface: InterfaceSelection,
    /// Whether SPDP uses multicast (239.255.0.1, or ff02::ffff:239.255.0.1, on the domain's discovery
    /// port). Off also turns multicast user data off.
    pub multicast: bool,
    /// Multicast user data: a group our readers join and announce, and whether our writers send to the
    /// groups their readers share.
    pub multicast_data: MulticastData,
    /// Unicast discovery peers.
    pub peers: Vec<Peer>,
    /// Participant index choice.
    pub participant_index: ParticipantIndex,
    /// Highest participant index probed by `Auto` and expanded for address-only peers.
    pub max_participant_index: u32,
    /// Period of SPDP announcements.
    pub spdp_interval: Duration,
    /// Participant lease duration.
    pub lease_duration: Duration,
    /// Payload bytes per DATA_FRAG fragment. User samples of which two fit one datagram of
    /// `max_message_size` go whole, as one DATA; larger ones in fragments of this size.
    pub fragment_size: usize,
    /// Largest datagram we send.
    pub max_message_size: usize,
    /// Requested socket buffer size (receive and send).
    pub socket_buffer_size: usize,
    /// Write batching: how long a written sample may wait for others to share its datagram. `None` sends
    /// each write at once (lowest latency); `Some` trades up to that much latency for throughput.
    pub write_batch_delay: Option<Duration>,
    /// Intra-process delivery: a writer gives its samples to readers of the same participant directly,
    /// with no serialization for the reader and no socket (`DDS_INTRA_PROCESS`, default on).
    pub intra_process: bool,
    /// The IGNORE_LOCAL policy of the user endpoints that leave theirs at
    /// [`IgnoreLocal::Inherit`](crate::qos::IgnoreLocal::Inherit), the QoS default (this default is
    /// `None`; `Inherit` here means `None`): a participant-wide default, as Cyclone has one per participant
    /// in its configuration. An endpoint that sets its own keeps it, `None` included (it then matches the
    /// endpoints this default would ignore).
    pub ignore_local: crate::qos::IgnoreLocal,
    /// Segmented sends (Linux `UDP_SEGMENT`, `DDS_GSO`, default on): a run of equal-sized datagrams to one
    /// destination, as a fragmented sample makes, leaves in one system call. Ignored elsewhere.
    pub gso: bool,
    /// Scatter-gather sends (`DDS_GATHER_MIN`, default 2048 bytes): a DATA_FRAG's slice of a sample of at
    /// least this many bytes goes to the socket from the sample's own buffer, not copied into the
    /// datagram. `None`: every datagram is copied together.
    pub gather_min: Option<usize>,
    /// Adaptive busy polling of the receive sockets (`DDS_RECEIVE_SPIN_US`, default 50 µs; 0: off). While datagrams
    /// arrive less than 8 times this apart, a receive thread polls its socket for up to this long after each batch
    /// instead of sleeping, which saves a thread wake-up per datagram on a request/reply or a fast stream
    /// (50 µs took an idle host's ping/pong hop from about 34 to 4 µs). Sparse traffic never polls, and the
    /// polling thread yields between polls. It pays only with a core to spare, so a thread stops polling
    /// while the cores are contended (the host's CPU pressure is high, or its polls were preempted; where
    /// Linux's CPU pressure cannot be read, it never polls), after polls that found nothing it polls
    /// shorter, and at most all cores but one of a process poll at once (`docs/performance.md`, session 25).
    pub receive_spin: Duration,
    /// Shared memory with peers on this host that can use it (`DDS_SHM`, default on; only with the `shm`
    /// feature, ignored without it): their readers get our writers' samples through shared memory, not
    /// UDP. Off, the participant does not announce it, and its peers use UDP with it.
    pub shm: bool,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            domain_id: 0,
            transport: AddressFamily::Ipv4,
            interface: InterfaceSelection::Auto,
            multicast: true,
            multicast_data: MulticastData::Off,
            peers: Vec::new(),
            participant_index: ParticipantIndex::Auto,
            max_participant_index: 9,
            spdp_interval: Duration::from_secs(1),
            lease_duration: Duration::from_secs(10),
            fragment_size: 1344,
            max_message_size: 14720,
            socket_buffer_size: 4 << 20,
            write_batch_delay: None,
            intra_process: true,
            ignore_local: crate::qos::IgnoreLocal::None,
            gso: true,
            gather_min: Some(2048),
            receive_spin: Duration::from_micros(50),
            shm: true,
        }
    }
}

fn parse_num<N: std::str::FromStr>(name: &'static str, v: &str) -> Result<N, ConfigError> {
    v.trim().parse::<N>().map_err(|_| ConfigError::NotANumber {
        name,
        value: v.to_string(),
    })
}

/// Parses `on`/`off`, `true`/`false`, `yes`/`no`, `enabled`/`disabled`, `1`/`0`.
fn parse_bool(name: &'static str, v: &str) -> Result<bool, ConfigError> {
    match v.trim().to_ascii_lowercase().as_str() {
        "1" | "on" | "true" | "yes" | "enabled" => Ok(true),
        "0" | "off" | "false" | "no" | "disabled" => Ok(false),
        _ => Err(ConfigError::NotOnOff {
            name,
            value: v.to_string(),
        }),
    }
}

/// Default batch delay of `DDS_WRITE_BATCH=on`.
pub const DEFAULT_WRITE_BATCH_DELAY: Duration = Duration::from_millis(1);

/// `off`, `on` ([`DEFAULT_WRITE_BATCH_DELAY`]) or a delay in microseconds (`0` is off).
fn parse_batch_delay(v: &str) -> Result<Option<Duration>, ConfigError> {
    if let Ok(us) = v.trim().parse::<u64>() {
        return Ok((us > 0).then(|| Duration::from_micros(us)));
    }
    let on = parse_bool("DDS_WRITE_BATCH", v).map_err(|_| ConfigError::WriteBatch {
        value: v.to_string(),
    })?;
    Ok(on.then_some(DEFAULT_WRITE_BATCH_DELAY))
}

/// Checks that `value` lies in `min..=max`.
fn in_range(name: &'static str, value: usize, min: usize, max: usize) -> Result<(), ConfigError> {
    if (min..=max).contains(&value) {
        Ok(())
    } else {
        Err(ConfigError::OutOfRange {
            name,
            value,
            min,
            max,
        })
    }
}

impl Config {
    /// Defaults overridden by the `DDS_*` environment variables (see the module table).
    pub fn from_env() -> Result<Self, ConfigError> {
        Self::from_lookup(|k| std::env::var(k).ok())
    }

    /// Like [`Config::from_env`] but reading variables through `lookup` (for tests and embedding).
    pub fn from_lookup(lookup: impl Fn(&str) -> Option<String>) -> Result<Self, ConfigError> {
        let mut c = Config::default();
        if let Some(v) = lookup("DDS_DOMAIN_ID") {
            c.domain_id = parse_num("DDS_DOMAIN_ID", &v)?;
        }
        if let Some(v) = lookup("DDS_TRANSPORT") {
            c.transport = AddressFamily::parse(&v)?;
        }
        if let Some(v) = lookup("DDS_MULTICAST_DATA") {
            c.multicast_data = MulticastData::parse(&v)?;
        }
        if let Some(v) = lookup("DDS_INTERFACE") {
            c.interface = InterfaceSelection::parse(&v);
        }
        if let Some(v) = lookup("DDS_MULTICAST") {
            c.multicast = parse_bool("DDS_MULTICAST", &v)?;
        }
        if let Some(v) = lookup("DDS_PEERS") {
            c.peers = v
                .split(',')
                .filter(|s| !s.trim().is_empty())
                .map(Peer::parse)
                .collect::<Result<_, _>>()?;
        }
        if let Some(v) = lookup("DDS_PARTICIPANT_INDEX") {
            c.participant_index = match v.trim().to_ascii_lowercase().as_str() {
                "auto" | "" => ParticipantIndex::Auto,
                "none" => ParticipantIndex::None,
                _ => ParticipantIndex::Fixed(parse_num("DDS_PARTICIPANT_INDEX", &v)?),
            };
        }
        if let Some(v) = lookup("DDS_MAX_PARTICIPANT_INDEX") {
            c.max_participant_index = parse_num("DDS_MAX_PARTICIPANT_INDEX", &v)?;
        }
        if let Some(v) = lookup("DDS_SPDP_INTERVAL_MS") {
            c.spdp_interval = Duration::from_millis(parse_num("DDS_SPDP_INTERVAL_MS", &v)?);
        }
        if let Some(v) = lookup("DDS_LEASE_DURATION_MS") {
            c.lease_duration = Duration::from_millis(parse_num("DDS_LEASE_DURATION_MS", &v)?);
        }
        if let Some(v) = lookup("DDS_FRAGMENT_SIZE") {
            c.fragment_size = parse_num("DDS_FRAGMENT_SIZE", &v)?;
        }
        if let Some(v) = lookup("DDS_MAX_MESSAGE_SIZE") {
            c.max_message_size = parse_num("DDS_MAX_MESSAGE_SIZE", &v)?;
        }
        if let Some(v) = lookup("DDS_SOCKET_BUFFER_SIZE") {
            c.socket_buffer_size = parse_num("DDS_SOCKET_BUFFER_SIZE", &v)?;
        }
        if let Some(v) = lookup("DDS_INTRA_PROCESS") {
            c.intra_process = parse_bool("DDS_INTRA_PROCESS", &v)?;
        }
        if let Some(v) = lookup("DDS_GSO") {
            c.gso = parse_bool("DDS_GSO", &v)?;
        }
        if let Some(v) = lookup("DDS_GATHER_MIN") {
            c.gather_min = match v.trim() {
                "off" => None,
                n => Some(parse_num("DDS_GATHER_MIN", n)?),
            };
        }
        if let Some(v) = lookup("DDS_RECEIVE_SPIN_US") {
            c.receive_spin = Duration::from_micros(parse_num("DDS_RECEIVE_SPIN_US", &v)?);
        }
        if let Some(v) = lookup("DDS_SHM") {
            c.shm = parse_bool("DDS_SHM", &v)?;
        }
        if let Some(v) = lookup("DDS_WRITE_BATCH") {
            c.write_batch_delay = parse_batch_delay(&v)?;
        }
        c.validate()?;
        Ok(c)
    }

    /// Checks ranges and relations between values.
    pub fn validate(&self) -> Result<(), ConfigError> {
        ports::spdp_multicast(self.domain_id)?;
        in_range("fragment_size", self.fragment_size, 256, 65000)?;
        in_range("max_message_size", self.max_message_size, 512, 65500)?;
        if self.fragment_size + 64 > self.max_message_size {
            return Err(ConfigError::FragmentTooLarge {
                fragment_size: self.fragment_size,
                max_message_size: self.max_message_size,
            });
        }
        if self.spdp_interval.is_zero() || self.lease_duration < self.spdp_interval {
            return Err(ConfigError::SpdpInterval {
                spdp_interval: self.spdp_interval,
                lease_duration: self.lease_duration,
            });
        }
        ports::check(self.domain_id, self.max_participant_index).map_err(|source| {
            ConfigError::Port {
                name: "max_participant_index",
                source,
            }
        })?;
        if let ParticipantIndex::Fixed(i) = self.participant_index {
            ports::check(self.domain_id, i)?;
        }
        self.check_family()
    }

    /// Every address given (interface, peers, multicast data group) is of the configured family.
    fn check_family(&self) -> Result<(), ConfigError> {
        let family = self.transport;
        let check = |name, addr: IpAddr| {
            if family.contains(addr) {
                Ok(())
            } else {
                Err(ConfigError::AddressFamily { name, addr, family })
            }
        };
        if let InterfaceSelection::Address(a) = self.interface {
            check("interface", a)?;
        }
        for p in &self.peers {
            match *p {
                Peer::Address(a) => check("peer", a)?,
                Peer::SocketAddr(sa) => check("peer", sa.ip())?,
            }
        }
        if let MulticastData::Group(g) = self.multicast_data {
            check("multicast data group", g)?;
        }
        Ok(())
    }

    /// The multicast group our readers join and announce for user data, `None` when multicast data (or
    /// multicast) is off.
    pub fn multicast_data_group(&self) -> Option<IpAddr> {
        if self.multicast {
            self.multicast_data.group(self.transport)
        } else {
            None
        }
    }

    /// Whether `ip` is loopback (used to decide multicast-loop defaults and logging).
    pub fn is_loopback(ip: IpAddr) -> bool {
        ip.is_loopback()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn env(pairs: &[(&str, &str)]) -> Result<Config, ConfigError> {
        let m: HashMap<String, String> = pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        Config::from_lookup(|k| m.get(k).cloned())
    }

    #[test]
    fn env_overrides_defaults() {
        let c = env(&[
            ("DDS_DOMAIN_ID", "7"),
            ("DDS_INTERFACE", "lo"),
            ("DDS_MULTICAST", "off"),
            ("DDS_PEERS", "127.0.0.1, 127.0.0.2:7410"),
            ("DDS_PARTICIPANT_INDEX", "none"),
            ("DDS_SPDP_INTERVAL_MS", "250"),
            ("DDS_FRAGMENT_SIZE", "8000"),
            ("DDS_RECEIVE_SPIN_US", "40"),
        ])
        .unwrap();
        assert_eq!(c.receive_spin, Duration::from_micros(40));
        assert_eq!(c.domain_id, 7);
        assert_eq!(c.interface, InterfaceSelection::Name("lo".into()));
        assert!(!c.multicast);
        assert_eq!(
            c.peers,
            vec![
                Peer::Address(Ipv4Addr::LOCALHOST.into()),
                Peer::SocketAddr("127.0.0.2:7410".parse().unwrap())
            ]
        );
        assert_eq!(c.participant_index, ParticipantIndex::None);
        assert_eq!(c.spdp_interval, Duration::from_millis(250));
        assert_eq!(c.fragment_size, 8000);
        let c = env(&[
            ("DDS_INTERFACE", "127.0.0.1"),
            ("DDS_PARTICIPANT_INDEX", "3"),
        ])
        .unwrap();
        assert_eq!(
            c.interface,
            InterfaceSelection::Address(Ipv4Addr::LOCALHOST.into())
        );
        assert_eq!(c.participant_index, ParticipantIndex::Fixed(3));
    }

    #[test]
    fn bad_values_are_errors() {
        assert!(matches!(
            env(&[("DDS_DOMAIN_ID", "x")]),
            Err(ConfigError::NotANumber { name: "DDS_DOMAIN_ID", value }) if value == "x"
        ));
        assert_eq!(
            env(&[("DDS_DOMAIN_ID", "233")]),
            Err(ConfigError::Port {
                name: "domain_id",
                source: PortError::Domain { domain: 233 }
            })
        );
        assert!(matches!(
            env(&[("DDS_MULTICAST", "maybe")]),
            Err(ConfigError::NotOnOff { name: "DDS_MULTICAST", value }) if value == "maybe"
        ));
        assert!(matches!(
            env(&[("DDS_PEERS", "host.example")]),
            Err(ConfigError::Peer { value }) if value == "host.example"
        ));
        assert_eq!(
            env(&[("DDS_FRAGMENT_SIZE", "20000")]),
            Err(ConfigError::FragmentTooLarge {
                fragment_size: 20000,
                max_message_size: 14720
            })
        );
        assert_eq!(
            env(&[("DDS_PARTICIPANT_INDEX", "40000")]),
            Err(ConfigError::Port {
                name: "participant_index",
                source: PortError::ParticipantIndex {
                    domain: 0,
                    index: 40000
                }
            })
        );
        assert!(matches!(
            env(&[("DDS_WRITE_BATCH", "soon")]),
            Err(ConfigError::WriteBatch { value }) if value == "soon"
        ));
    }

    #[test]
    fn ranges_and_relations_are_checked() {
        assert_eq!(
            env(&[("DDS_FRAGMENT_SIZE", "100")]),
            Err(ConfigError::OutOfRange {
                name: "fragment_size",
                value: 100,
                min: 256,
                max: 65000
            })
        );
        assert_eq!(
            env(&[("DDS_MAX_MESSAGE_SIZE", "70000")]),
            Err(ConfigError::OutOfRange {
                name: "max_message_size",
                value: 70000,
                min: 512,
                max: 65500
            })
        );
        assert!(matches!(
            env(&[("DDS_SPDP_INTERVAL_MS", "0")]),
            Err(ConfigError::SpdpInterval { .. })
        ));
        assert_eq!(
            env(&[
                ("DDS_DOMAIN_ID", "232"),
                ("DDS_MAX_PARTICIPANT_INDEX", "100")
            ]),
            Err(ConfigError::Port {
                name: "max_participant_index",
                source: PortError::ParticipantIndex {
                    domain: 232,
                    index: 100
                }
            })
        );
    }

    #[test]
    fn address_family_and_multicast_data() {
        let c = env(&[]).unwrap();
        assert_eq!(c.transport, AddressFamily::Ipv4);
        assert_eq!(c.multicast_data_group(), None);
        let c = env(&[
            ("DDS_TRANSPORT", "udp6"),
            ("DDS_INTERFACE", "::1"),
            ("DDS_PEERS", "::1,[::1]:7410"),
            ("DDS_MULTICAST_DATA", "on"),
        ])
        .unwrap();
        assert_eq!(c.transport, AddressFamily::Ipv6);
        assert_eq!(
            c.interface,
            InterfaceSelection::Address(Ipv6Addr::LOCALHOST.into())
        );
        assert_eq!(
            c.peers,
            vec![
                Peer::Address(Ipv6Addr::LOCALHOST.into()),
                Peer::SocketAddr("[::1]:7410".parse().unwrap())
            ]
        );
        assert_eq!(
            c.multicast_data_group(),
            Some("ff02::ffff:239.255.0.1".parse().unwrap())
        );
        let c = env(&[("DDS_MULTICAST_DATA", "239.255.0.9")]).unwrap();
        assert_eq!(
            c.multicast_data_group(),
            Some("239.255.0.9".parse().unwrap())
        );
        let c = env(&[("DDS_MULTICAST_DATA", "on"), ("DDS_MULTICAST", "off")]).unwrap();
        assert_eq!(c.multicast_data_group(), None, "multicast off wins");
        assert!(matches!(
            env(&[("DDS_TRANSPORT", "tcp")]),
            Err(ConfigError::Transport { .. })
        ));
        assert!(matches!(
            env(&[("DDS_MULTICAST_DATA", "10.0.0.1")]),
            Err(ConfigError::MulticastData { .. })
        ));
        assert!(matches!(
            env(&[("DDS_TRANSPORT", "udp6"), ("DDS_INTERFACE", "127.0.0.1")]),
            Err(ConfigError::AddressFamily {
                name: "interface",
                ..
            })
        ));
        assert!(matches!(
            env(&[("DDS_PEERS", "::1")]),
            Err(ConfigError::AddressFamily { name: "peer", .. })
        ));
    }

    #[test]
    fn write_batch_forms() {
        let delay = |v: &str| env(&[("DDS_WRITE_BATCH", v)]).unwrap().write_batch_delay;
        assert_eq!(Config::default().write_batch_delay, None);
        assert_eq!(delay("off"), None);
        assert_eq!(delay("0"), None);
        assert_eq!(delay("on"), Some(DEFAULT_WRITE_BATCH_DELAY));
        assert_eq!(delay("250"), Some(Duration::from_micros(250)));
    }

    #[test]
    fn gather_min_forms() {
        let min = |v: &str| env(&[("DDS_GATHER_MIN", v)]).map(|c| c.gather_min);
        assert_eq!(Config::default().gather_min, Some(2048));
        assert_eq!(min("off").unwrap(), None);
        assert_eq!(min("8192").unwrap(), Some(8192));
        assert!(min("lots").is_err());
    }
}
