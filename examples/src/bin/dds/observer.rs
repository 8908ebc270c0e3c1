//! A bare participant (SPDP and SEDP only, no endpoints) driven on its own UDP transport, so that the tool sees
//! every discovered writer and reader, not only those matched with an endpoint of its own.

use std::net::SocketAddr;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant, SystemTime};

use dds_runtime::prelude::*;
use dds_runtime::rtps::{GuidPrefix, Locator, Participant, ParticipantConfig, VendorId};
use dds_runtime::transport::{Datagram, Receiver, UdpTransport};

use crate::snapshot::Snapshot;

/// How often the loop sends what the core queued and fires its timers.
const TICK: Duration = Duration::from_millis(10);

/// Why the tool could not join the domain.
#[derive(Debug, thiserror::Error)]
pub(crate) enum JoinError {
    /// The configuration (environment, domain id) is invalid.
    #[error("configuration: {0}")]
    Config(#[from] DdsError),
    /// The sockets could not be bound or started.
    #[error("sockets: {0}")]
    Io(#[from] std::io::Error),
    /// The participant index gives no valid ports.
    #[error("ports: {0}")]
    Ports(#[from] dds_runtime::rtps::discovery::ports::PortError),
}

/// The observing participant.
pub(crate) struct Observer {
    core: Arc<Mutex<Participant>>,
    transport: UdpTransport,
}

impl Observer {
    /// Joins `domain` (else `DDS_DOMAIN_ID`, else 0; the other `DDS_*` variables apply too) and starts SPDP.
    pub(crate) fn join(domain: Option<u32>) -> Result<Self, JoinError> {
        let mut builder = DomainParticipant::builder();
        if let Some(d) = domain {
            builder = builder.domain_id(d);
        }
        let config = builder.resolve_config()?;
        let domain = config.domain_id;
        let transport = UdpTransport::bind(&config)?;
        let prefix = guid_prefix();
        let loc = |a: std::net::SocketAddrV4| Locator::udpv4(a.ip().octets(), a.port());
        let pc = ParticipantConfig::builder(
            domain,
            transport.participant_index().unwrap_or(0),
            prefix,
            transport.interface().addr.octets(),
        )?
        .metatraffic_unicast(vec![loc(transport.metatraffic_unicast())])
        .default_unicast(vec![loc(transport.user_unicast())])
        .metatraffic_multicast(
            transport
                .spdp_multicast()
                .map(loc)
                .into_iter()
                .collect::<Vec<_>>(),
        )
        .default_multicast(Vec::new())
        .initial_peers(
            transport
                .spdp_peers()
                .iter()
                .copied()
                .map(loc)
                .collect::<Vec<_>>(),
        )
        .spdp_interval(config.spdp_interval)
        .lease_duration(config.lease_duration)
        .max_message_size(config.max_message_size)
        .entity_name(Some("dds".to_string()))
        .build();
        let core = Arc::new(Mutex::new(Participant::new(pc, Instant::now())));
        let rx_core = core.clone();
        let rx: Receiver = Arc::new(move |_ch, datagrams: &[Datagram<'_>]| {
            let mut c = lock(&rx_core);
            let now = Instant::now();
            for d in datagrams {
                c.handle_datagram(now, d.data);
            }
        });
        transport.start(rx)?;
        Ok(Observer { core, transport })
    }

    /// Runs discovery for `d`.
    pub(crate) fn run_for(&self, d: Duration) {
        let end = Instant::now() + d;
        loop {
            self.step();
            let now = Instant::now();
            if now >= end {
                return;
            }
            std::thread::sleep(TICK.min(end - now));
        }
    }

    /// Fires due timers, drops the core's events (the snapshot reads its state instead) and sends.
    fn step(&self) {
        let mut c = lock(&self.core);
        let now = Instant::now();
        if c.poll_timeout().is_some_and(|t| t <= now) {
            c.handle_timeout(now);
        }
        while c.poll_event().is_some() {}
        while let Some(t) = c.poll_transmit(now) {
            for dest in &t.destinations {
                if let Some(SocketAddr::V4(a)) = dest.to_socket_addr() {
                    self.transport.send_to(&t.payload, a);
                }
            }
            c.recycle(t.payload);
        }
    }

    /// What is known now.
    pub(crate) fn snapshot(&self) -> Snapshot {
        Snapshot::of(&lock(&self.core))
    }
}

impl Drop for Observer {
    fn drop(&mut self) {
        lock(&self.core).shutdown(Instant::now());
        self.step();
        self.transport.shutdown();
    }
}

fn lock(m: &Mutex<Participant>) -> MutexGuard<'_, Participant> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Our vendor id, then the time, the process id and a fixed tail: unique enough for one short-lived tool.
fn guid_prefix() -> GuidPrefix {
    let t = SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .unwrap_or_default()
        .subsec_nanos()
        .to_be_bytes();
    let pid = std::process::id().to_be_bytes();
    let v = VendorId::THIS.0;
    GuidPrefix([
        v[0], v[1], t[0], t[1], t[2], t[3], pid[0], pid[1], pid[2], pid[3], 0xc1, 0x10,
    ])
}
