//! `DomainParticipant`, the entry point of the DCPS API, and its builder. The machinery behind it (core,
//! transport, timer thread, routing) is the [`Driver`](super::driver::Driver). The factories of the other
//! entities (`create_topic`, `create_publisher`, ...) live with the entity they create, so that this module
//! depends on none of them.

mod factory;
mod ops;
mod types;

pub use factory::DomainParticipantFactory;
pub use ops::DomainParticipantListener;
pub use types::DiscoveredType;
pub(crate) use types::{register_local_types, register_type_bytes};

use std::sync::{Arc, Weak};
use std::time::Duration;

use crate::config::{
    AddressFamily, Config, InterfaceSelection, MulticastData, ParticipantIndex, Peer,
};
use crate::qos::DomainParticipantQos;
use crate::rtps::{EntityId, Guid, GuidPrefix};
use crate::transport::UdpTransport;

use super::condition::StatusCondition;
use super::driver::Driver;
use super::durability::DurabilityServiceConfig;
use super::error::DdsResult;
use super::registry::Registry;
use super::sample::InstanceHandle;

/// A participant discovered through SPDP.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct DiscoveredParticipant {
    /// Its GUID prefix.
    pub guid_prefix: GuidPrefix,
    /// Its handle.
    pub handle: InstanceHandle,
}

impl DiscoveredParticipant {
    fn new(guid_prefix: GuidPrefix) -> Self {
        DiscoveredParticipant {
            guid_prefix,
            handle: InstanceHandle::from_guid(Guid::new(guid_prefix, EntityId::PARTICIPANT)),
        }
    }
}

/// Write batching (overrides `DDS_WRITE_BATCH`), see [`DomainParticipantBuilder::write_batching`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WriteBatching {
    /// Every write leaves at once (lowest latency).
    Off,
    /// A written sample waits up to this long for others to share its datagram.
    Delay(Duration),
}

impl WriteBatching {
    /// The delay, `None` when off.
    pub fn delay(self) -> Option<Duration> {
        match self {
            WriteBatching::Off => None,
            WriteBatching::Delay(d) => Some(d),
        }
    }
}

/// Stops the participant's threads when the last `DomainParticipant` handle goes away.
struct Guard(Arc<Driver>);

impl Drop for Guard {
    fn drop(&mut self) {
        self.0.shutdown();
    }
}

/// The entry point: one participant in one DDS domain. Cheap to clone. Topics, publishers, subscribers,
/// readers and writers keep their participant alive; when the last of these handles is dropped the
/// participant stops its threads and closes its sockets.
#[derive(Clone)]
pub struct DomainParticipant {
    driver: Arc<Driver>,
    _guard: Arc<Guard>,
    registry: Arc<Registry>,
}

/// A reference to a participant that does not keep it alive (held by listeners of its entities).
#[derive(Clone)]
pub(crate) struct WeakParticipant {
    driver: Weak<Driver>,
    guard: Weak<Guard>,
    registry: Weak<Registry>,
}

impl WeakParticipant {
    /// The participant, while some handle of it exists.
    pub(crate) fn upgrade(&self) -> Option<DomainParticipant> {
        Some(DomainParticipant {
            driver: self.driver.upgrade()?,
            _guard: self.guard.upgrade()?,
            registry: self.registry.upgrade()?,
        })
    }
}

impl std::fmt::Debug for DomainParticipant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DomainParticipant")
            .field("domain_id", &self.driver.config.domain_id)
            .field("guid_prefix", &self.driver.guid_prefix)
            .field("transport", &self.driver.transport)
            .finish()
    }
}

/// Builds a [`DomainParticipant`]: configuration from the environment (see [`crate::config`]) with the
/// builder's settings on top.
#[derive(Debug, Clone, Default)]
pub struct DomainParticipantBuilder {
    domain_id: Option<u32>,
    interface: Option<InterfaceSelection>,
    multicast: Option<bool>,
    transport: Option<AddressFamily>,
    multicast_data: Option<MulticastData>,
    peers: Option<Vec<Peer>>,
    participant_index: Option<ParticipantIndex>,
    spdp_interval: Option<Duration>,
    lease_duration: Option<Duration>,
    fragment_size: Option<usize>,
    max_message_size: Option<usize>,
    write_batching: Option<WriteBatching>,
    config: Option<Config>,
    ignore_env: bool,
    user_data: Vec<u8>,
    name: Option<String>,
    durability_service: Option<DurabilityServiceConfig>,
    qos: Option<DomainParticipantQos>,
}

impl DomainParticipantBuilder {
    /// Domain id (overrides `DDS_DOMAIN_ID`).
    pub fn domain_id(mut self, d: u32) -> Self {
        self.domain_id = Some(d);
        self
    }
    /// Interface by name (`"lo"`) or address (`"127.0.0.1"`) (overrides `DDS_INTERFACE`).
    pub fn interface(mut self, s: &str) -> Self {
        self.interface = Some(InterfaceSelection::parse(s));
        self
    }
    /// Multicast discovery on or off (overrides `DDS_MULTICAST`).
    pub fn multicast(mut self, on: bool) -> Self {
        self.multicast = Some(on);
        self
    }
    /// UDP over IPv4 or IPv6 (overrides `DDS_TRANSPORT`).
    pub fn transport(mut self, family: AddressFamily) -> Self {
        self.transport = Some(family);
        self
    }
    /// Multicast user data: readers announce a multicast locator and writers send each sample once to it
    /// (overrides `DDS_MULTICAST_DATA`; see `docs/network.md`).
    pub fn multicast_data(mut self, m: MulticastData) -> Self {
        self.multicast_data = Some(m);
        self
    }
    /// Unicast discovery peers, `"127.0.0.1"` or `"127.0.0.1:7410"` (overrides `DDS_PEERS`).
    pub fn peers<S: AsRef<str>>(mut self, peers: impl IntoIterator<Item = S>) -> DdsResult<Self> {
        self.peers = Some(
            peers
                .into_iter()
                .map(|p| Peer::parse(p.as_ref()))
                .collect::<Result<_, _>>()?,
        );
        Ok(self)
    }
    /// Participant index choice (overrides `DDS_PARTICIPANT_INDEX`).
    pub fn participant_index(mut self, i: ParticipantIndex) -> Self {
        self.participant_index = Some(i);
        self
    }
    /// SPDP announcement period.
    pub fn spdp_interval(mut self, d: Duration) -> Self {
        self.spdp_interval = Some(d);
        self
    }
    /// Participant lease duration.
    pub fn lease_duration(mut self, d: Duration) -> Self {
        self.lease_duration = Some(d);
        self
    }
    /// DATA_FRAG fragment size.
    pub fn fragment_size(mut self, n: usize) -> Self {
        self.fragment_size = Some(n);
        self
    }
    /// Largest datagram sent.
    pub fn max_message_size(mut self, n: usize) -> Self {
        self.max_message_size = Some(n);
        self
    }
    /// Write batching (overrides `DDS_WRITE_BATCH`): with [`WriteBatching::Delay`], written samples wait up
    /// to the delay for others to share their datagram; [`DomainParticipant::flush`] and
    /// [`DataWriter::flush`] send them at once. [`WriteBatching::Off`] sends every write immediately.
    ///
    /// [`DataWriter::flush`]: crate::dcps::DataWriter::flush
    pub fn write_batching(mut self, batching: WriteBatching) -> Self {
        self.write_batching = Some(batching);
        self
    }
    /// Starts from this configuration instead of the environment.
    pub fn config(mut self, c: Config) -> Self {
        self.config = Some(c);
        self
    }
    /// Ignores the `DDS_*` environment variables.
    pub fn ignore_env(mut self) -> Self {
        self.ignore_env = true;
        self
    }
    /// USER_DATA announced in SPDP.
    pub fn user_data(mut self, d: Vec<u8>) -> Self {
        self.user_data = d;
        self
    }
    /// The participant QoS (USER_DATA, ENTITY_FACTORY); its USER_DATA replaces [`user_data`](Self::user_data)
    /// when not empty. Without it, the participant factory's default participant QoS applies.
    pub fn qos(mut self, q: DomainParticipantQos) -> Self {
        self.qos = Some(q);
        self
    }
    /// Entity name announced in SPDP.
    pub fn name(mut self, n: impl Into<String>) -> Self {
        self.name = Some(n.into());
        self
    }

    /// The effective configuration.
    pub fn resolve_config(&self) -> DdsResult<Config> {
        let mut c = match &self.config {
            Some(c) => c.clone(),
            None if self.ignore_env => Config::default(),
            None => Config::from_env()?,
        };
        if let Some(d) = self.domain_id {
            c.domain_id = d;
        }
        if let Some(i) = &self.interface {
            c.interface = i.clone();
        }
        if let Some(m) = self.multicast {
            c.multicast = m;
        }
        if let Some(t) = self.transport {
            c.transport = t;
        }
        if let Some(m) = self.multicast_data {
            c.multicast_data = m;
        }
        if let Some(p) = &self.peers {
            c.peers = p.clone();
        }
        if let Some(i) = self.participant_index {
            c.participant_index = i;
        }
        if let Some(d) = self.spdp_interval {
            c.spdp_interval = d;
        }
        if let Some(d) = self.lease_duration {
            c.lease_duration = d;
        }
        if let Some(n) = self.fragment_size {
            c.fragment_size = n;
        }
        if let Some(n) = self.max_message_size {
            c.max_message_size = n;
        }
        if let Some(b) = self.write_batching {
            c.write_batch_delay = b.delay();
        }
        c.validate()?;
        Ok(c)
    }

    /// The durability service this participant runs (default: `DDS_DURABILITY_SERVICE` and
    /// `DDS_DURABILITY_STORE`, else one for its own TRANSIENT and PERSISTENT writers; see
    /// [`super::durability`]).
    pub fn durability_service(mut self, c: DurabilityServiceConfig) -> Self {
        self.durability_service = Some(c);
        self
    }

    /// Binds the sockets, starts the receive and timer threads and begins SPDP.
    pub fn build(self) -> DdsResult<DomainParticipant> {
        let config = self.resolve_config()?;
        let durability = match self.durability_service {
            Some(c) => c,
            None if self.ignore_env => DurabilityServiceConfig::default(),
            None => DurabilityServiceConfig::from_env()?,
        };
        let qos = self.qos.clone().unwrap_or_else(|| {
            factory::DomainParticipantFactory::get_instance().default_participant_qos()
        });
        // A participant is created disabled when the factory does not autoenable (DDS 1.4 §2.2.2.1.1.7).
        let enabled = factory::DomainParticipantFactory::get_instance()
            .qos()
            .autoenable_created_entities;
        let user_data = if qos.user_data.0.is_empty() {
            self.user_data
        } else {
            qos.user_data.0.clone()
        };
        let mut qos = qos;
        qos.user_data = user_data.clone().into();
        let driver = Driver::start(config, user_data, self.name, enabled)?;
        let guard = Arc::new(Guard(driver.clone()));
        let registry = Arc::new(Registry::new(
            driver.guid_prefix,
            driver.status.clone(),
            qos,
        ));
        if !enabled {
            registry.with(|e| e.disabled.insert(registry.node.handle));
        }
        ops::install_discovery_hook(&driver, &registry);
        super::durability::install(&driver, &durability)?;
        let p = DomainParticipant {
            driver,
            _guard: guard,
            registry,
        };
        factory::DomainParticipantFactory::get_instance().register(&p);
        Ok(p)
    }
}

impl DomainParticipant {
    /// A participant in `domain_id` with the configuration from the environment.
    pub fn new(domain_id: u32) -> DdsResult<Self> {
        Self::builder().domain_id(domain_id).build()
    }

    /// A builder.
    pub fn builder() -> DomainParticipantBuilder {
        DomainParticipantBuilder::default()
    }

    /// The domain id.
    pub fn domain_id(&self) -> u32 {
        self.driver.config.domain_id
    }

    /// Sends the samples that write batching holds back (see
    /// [`DomainParticipantBuilder::write_batching`]); without batching there is nothing to send.
    pub fn flush(&self) {
        self.driver.flush();
    }

    /// The effective configuration.
    pub fn config(&self) -> &Config {
        &self.driver.config
    }

    /// Counters of the participant's UDP transport (datagrams sent and received).
    pub fn transport_stats(&self) -> &crate::transport::TransportStats {
        self.driver.transport.stats()
    }

    /// The RTPS GUID prefix.
    pub fn guid_prefix(&self) -> GuidPrefix {
        self.driver.guid_prefix
    }

    /// The participant's own handle.
    pub fn instance_handle(&self) -> InstanceHandle {
        InstanceHandle::from_guid(Guid::new(self.driver.guid_prefix, EntityId::PARTICIPANT))
    }

    /// The transport (chosen interface, participant index, bound ports, counters).
    pub fn transport(&self) -> &UdpTransport {
        &self.driver.transport
    }

    /// Remote participants currently known through SPDP.
    pub fn discovered_participants(&self) -> Vec<DiscoveredParticipant> {
        self.driver
            .discovered_participants()
            .into_iter()
            .map(DiscoveredParticipant::new)
            .collect()
    }

    /// Asserts the liveliness of this participant's MANUAL_BY_PARTICIPANT writers: a ParticipantMessageData of
    /// kind MANUAL goes to every participant (see the liveliness section of docs/dcps-api.md).
    pub fn assert_liveliness(&self) -> DdsResult<()> {
        self.driver.check_alive()?;
        self.registry.check_participant_enabled()?;
        self.driver.with_core(|c, now| c.assert_liveliness(now));
        Ok(())
    }

    /// The participant's status condition.
    pub fn status_condition(&self) -> StatusCondition {
        StatusCondition {
            core: self.driver.status.clone(),
        }
    }

    /// The driver the participant's entities run on.
    pub(crate) fn driver(&self) -> &Arc<Driver> {
        &self.driver
    }

    /// The registry of the entities the participant contains.
    pub(crate) fn registry(&self) -> &Arc<Registry> {
        &self.registry
    }

    /// A reference that does not keep the participant alive.
    pub(crate) fn downgrade(&self) -> WeakParticipant {
        WeakParticipant {
            driver: Arc::downgrade(&self.driver),
            guard: Arc::downgrade(&self._guard),
            registry: Arc::downgrade(&self.registry),
        }
    }
}
