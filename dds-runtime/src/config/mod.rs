//! Participant configuration: defaults, environment variables and builder setters.
//!
//! [`Config::from_env`] starts from [`Config::default`] and applies these variables; the
//! `DomainParticipant` builder applies its own setters on top (the builder wins).
//!
//! | variable | meaning | values | default |
//! |---|---|---|---|
//! | `DDS_DOMAIN_ID` | domain id | `0`..=`232` | `0` |
//! | `DDS_INTERFACE` | network interface for all traffic | interface name (`lo`, `eth0`) or IPv4 address (`127.0.0.1`) | first up, multicast-capable, non-loopback IPv4 interface, else loopback |
//! | `DDS_MULTICAST` | use multicast for SPDP (send and receive) | `on`/`off`, `true`/`false`, `1`/`0` | `on` |
//! | `DDS_PEERS` | unicast discovery peers | comma-separated `ip` or `ip:port`; a bare ip expands to the SPDP ports of participant indices `0..=DDS_MAX_PARTICIPANT_INDEX` | none |
//! | `DDS_PARTICIPANT_INDEX` | participant index in the port formula | `auto` (probe `0..=max` by binding unicast ports), `none` (ephemeral ports), or a number | `auto` |
//! | `DDS_MAX_PARTICIPANT_INDEX` | highest index probed by `auto` and expanded by `DDS_PEERS` | number | `9` |
//! | `DDS_SPDP_INTERVAL_MS` | period of SPDP announcements | milliseconds | `1000` |
//! | `DDS_LEASE_DURATION_MS` | participant lease duration announced to peers | milliseconds | `10000` |
//! | `DDS_FRAGMENT_SIZE` | DATA_FRAG fragment size | bytes, `256`..=`65000` | `1344` |
//! | `DDS_MAX_MESSAGE_SIZE` | largest RTPS message (datagram) we send | bytes, `512`..=`65500` | `14720` |
//! | `DDS_SOCKET_BUFFER_SIZE` | requested SO_RCVBUF / SO_SNDBUF | bytes | `4194304` |
//! | `DDS_INTRA_PROCESS` | deliver to readers of the same participant directly (no serialization for them, no socket) | `on`/`off`, `true`/`false`, `1`/`0` | `on` |
//! | `DDS_WRITE_BATCH` | write batching: samples share datagrams until full, flushed, or this delay has passed | `off`, `on` (1 ms), or a delay in microseconds | `off` |
//!
//! Invalid values are reported as [`ConfigError`] rather than silently ignored.

use std::net::{IpAddr, Ipv4Addr, SocketAddrV4};
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
    /// A peer is not an IPv4 address or `address:port`.
    #[error("invalid value {value:?} for DDS_PEERS: expected an IPv4 address or address:port")]
    Peer {
        /// The value given.
        value: String,
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

/// Which network interface the participant uses.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum InterfaceSelection {
    /// First up, multicast-capable, non-loopback IPv4 interface; loopback when there is none.
    #[default]
    Auto,
    /// Interface by name, e.g. `lo`.
    Name(String),
    /// Interface by (one of) its IPv4 addresses.
    Address(Ipv4Addr),
}

impl InterfaceSelection {
    /// Parses `lo`, `eth0` or `127.0.0.1`; an empty string or `auto` means [`InterfaceSelection::Auto`].
    pub fn parse(s: &str) -> Self {
        let s = s.trim();
        if s.is_empty() || s.eq_ignore_ascii_case("auto") {
            InterfaceSelection::Auto
        } else if let Ok(a) = s.parse::<Ipv4Addr>() {
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
    Address(Ipv4Addr),
    /// An exact address and port.
    SocketAddr(SocketAddrV4),
}

impl Peer {
    /// Parses `127.0.0.1` or `127.0.0.1:7410`.
    pub fn parse(s: &str) -> Result<Self, ConfigError> {
        let s = s.trim();
        if let Ok(a) = s.parse::<Ipv4Addr>() {
            return Ok(Peer::Address(a));
        }
        if let Ok(sa) = s.parse::<SocketAddrV4>() {
            return Ok(Peer::SocketAddr(sa));
        }
        // Accept `localhost` for convenience; nothing else is resolved (no DNS from a DDS stack).
        if s.eq_ignore_ascii_case("localhost") {
            return Ok(Peer::Address(Ipv4Addr::LOCALHOST));
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
    /// Network interface used for sending, receiving and multicast membership.
    pub interface: InterfaceSelection,
    /// Whether SPDP uses multicast (239.255.0.1 on the domain's discovery port).
    pub multicast: bool,
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
    /// Payload bytes per DATA_FRAG fragment.
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
}

impl Default for Config {
    fn default() -> Self {
        Config {
            domain_id: 0,
            interface: InterfaceSelection::Auto,
            multicast: true,
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
        Ok(())
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
        ])
        .unwrap();
        assert_eq!(c.domain_id, 7);
        assert_eq!(c.interface, InterfaceSelection::Name("lo".into()));
        assert!(!c.multicast);
        assert_eq!(
            c.peers,
            vec![
                Peer::Address(Ipv4Addr::LOCALHOST),
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
            InterfaceSelection::Address(Ipv4Addr::LOCALHOST)
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
    fn write_batch_forms() {
        let delay = |v: &str| env(&[("DDS_WRITE_BATCH", v)]).unwrap().write_batch_delay;
        assert_eq!(Config::default().write_batch_delay, None);
        assert_eq!(delay("off"), None);
        assert_eq!(delay("0"), None);
        assert_eq!(delay("on"), Some(DEFAULT_WRITE_BATCH_DELAY));
        assert_eq!(delay("250"), Some(Duration::from_micros(250)));
    }
}
