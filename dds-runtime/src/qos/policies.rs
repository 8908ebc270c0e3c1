//! The DDS QoS policies (DDS 1.4 §2.2.3) as plain values.

use std::time::Duration;

use crate::cdr::XcdrVersion;

/// `DURATION_INFINITE`: maps to the wire value {0x7fffffff, 0xffffffff}.
pub const INFINITE: Duration = Duration::MAX;

/// DDS `QosPolicyId_t` values, reported by the incompatible-QoS events.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u32)]
pub enum QosPolicyId {
    /// USER_DATA.
    UserData = 1,
    /// DURABILITY.
    Durability = 2,
    /// PRESENTATION.
    Presentation = 3,
    /// DEADLINE.
    Deadline = 4,
    /// LATENCY_BUDGET.
    LatencyBudget = 5,
    /// OWNERSHIP.
    Ownership = 6,
    /// OWNERSHIP_STRENGTH.
    OwnershipStrength = 7,
    /// LIVELINESS.
    Liveliness = 8,
    /// TIME_BASED_FILTER.
    TimeBasedFilter = 9,
    /// PARTITION.
    Partition = 10,
    /// RELIABILITY.
    Reliability = 11,
    /// DESTINATION_ORDER.
    DestinationOrder = 12,
    /// HISTORY.
    History = 13,
    /// RESOURCE_LIMITS.
    ResourceLimits = 14,
    /// ENTITY_FACTORY.
    EntityFactory = 15,
    /// WRITER_DATA_LIFECYCLE.
    WriterDataLifecycle = 16,
    /// READER_DATA_LIFECYCLE.
    ReaderDataLifecycle = 17,
    /// TOPIC_DATA.
    TopicData = 18,
    /// GROUP_DATA.
    GroupData = 19,
    /// TRANSPORT_PRIORITY.
    TransportPriority = 20,
    /// LIFESPAN.
    Lifespan = 21,
    /// DURABILITY_SERVICE.
    DurabilityService = 22,
    /// DATA_REPRESENTATION.
    DataRepresentation = 23,
    /// TYPE_CONSISTENCY_ENFORCEMENT.
    TypeConsistencyEnforcement = 24,
    /// IGNORE_LOCAL (a vendor extension, see [`IgnoreLocal`]; not a standard id, never on the wire).
    IgnoreLocal = 0x8001,
}

/// RELIABILITY: whether lost samples are repaired.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reliability {
    /// Samples may be lost; no acknowledgements, no repairs.
    BestEffort,
    /// Every sample is delivered, in order, repaired when lost.
    Reliable {
        /// How long `write` may block on flow control or full resources.
        max_blocking_time: Duration,
    },
}

impl Reliability {
    /// Reliable with the spec's default max_blocking_time of 100 ms.
    pub const RELIABLE: Reliability = Reliability::Reliable {
        max_blocking_time: Duration::from_millis(100),
    };

    /// Whether this is [`Reliability::Reliable`].
    pub fn is_reliable(&self) -> bool {
        matches!(self, Reliability::Reliable { .. })
    }
}

/// Ordered: a writer offering a kind satisfies readers requesting the same or a lower kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum Durability {
    /// Samples exist only while the writer sends them.
    #[default]
    Volatile,
    /// The writer keeps its history for late-joining readers.
    TransientLocal,
    /// The data outlives its writer: a durability service keeps it for late joiners (see
    /// `dcps::durability`; as TransientLocal when no service runs).
    Transient,
    /// As Transient, and the data also survives a restart of the service when it has a persistent store.
    Persistent,
}

/// HISTORY: how many samples per instance are kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum History {
    /// The last `n` samples per instance.
    KeepLast(u32),
    /// Every sample, up to the resource limits.
    KeepAll,
}

impl Default for History {
    fn default() -> Self {
        History::KeepLast(1)
    }
}

/// `None` means LENGTH_UNLIMITED.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ResourceLimits {
    /// Most samples held in total.
    pub max_samples: Option<u32>,
    /// Most instances held.
    pub max_instances: Option<u32>,
    /// Most samples held per instance.
    pub max_samples_per_instance: Option<u32>,
}

/// PARTITION: names (or fnmatch patterns) of the partitions of a publisher or subscriber; empty is "".
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Partition(pub Vec<String>);

impl Partition {
    /// Partitions with these names.
    pub fn new<I: IntoIterator<Item = S>, S: Into<String>>(names: I) -> Self {
        Partition(names.into_iter().map(Into::into).collect())
    }
}

/// DEADLINE: the longest period between samples of an instance (default infinite).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Deadline(pub Duration);
impl Default for Deadline {
    fn default() -> Self {
        Deadline(INFINITE)
    }
}

/// LATENCY_BUDGET: the acceptable delay (a hint; default zero).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LatencyBudget(pub Duration);

/// LIVELINESS kind: who asserts that a writer is alive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum LivelinessKind {
    /// The infrastructure, by the participant's lease.
    #[default]
    Automatic,
    /// The application, for the whole participant.
    ManualByParticipant,
    /// The application, per writer.
    ManualByTopic,
}

/// LIVELINESS: how a writer's liveliness is asserted and how long it lasts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Liveliness {
    /// Who asserts liveliness.
    pub kind: LivelinessKind,
    /// How long a writer stays alive without an assertion.
    pub lease_duration: Duration,
}
impl Default for Liveliness {
    fn default() -> Self {
        Liveliness {
            kind: LivelinessKind::Automatic,
            lease_duration: INFINITE,
        }
    }
}

/// OWNERSHIP: whether several writers may update the same instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Ownership {
    /// Every writer's samples are delivered.
    #[default]
    Shared,
    /// Only the strongest writer's samples are delivered.
    Exclusive,
}

/// OWNERSHIP_STRENGTH: the writer's strength under exclusive ownership.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OwnershipStrength(pub i32);

/// DESTINATION_ORDER: which timestamp orders samples of an instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum DestinationOrder {
    /// The order in which samples arrive.
    #[default]
    ByReceptionTimestamp,
    /// The writers' source timestamps.
    BySourceTimestamp,
}

/// PRESENTATION access scope: the extent of coherent and ordered access.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum PresentationAccessScope {
    /// Per instance.
    #[default]
    Instance,
    /// Per topic.
    Topic,
    /// Across the topics of a publisher or subscriber.
    Group,
}

/// PRESENTATION: coherent and ordered access of a publisher or subscriber.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Presentation {
    /// The scope of the guarantees below.
    pub access_scope: PresentationAccessScope,
    /// Changes made in a coherent set are delivered together.
    pub coherent_access: bool,
    /// Changes are delivered in the order they were made.
    pub ordered_access: bool,
}

/// LIFESPAN: how long a sample stays valid after it was written (default infinite).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Lifespan(pub Duration);
impl Default for Lifespan {
    fn default() -> Self {
        Lifespan(INFINITE)
    }
}

/// TIME_BASED_FILTER: the reader wants at most one sample per instance per period.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TimeBasedFilter {
    /// The shortest time between two delivered samples of an instance.
    pub minimum_separation: Duration,
}

/// USER_DATA: application octets announced with a participant, writer or reader.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct UserData(pub Vec<u8>);
/// TOPIC_DATA: application octets announced with a topic.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct TopicData(pub Vec<u8>);
/// GROUP_DATA: application octets announced with a publisher or subscriber.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct GroupData(pub Vec<u8>);

/// WRITER_DATA_LIFECYCLE.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WriterDataLifecycle {
    /// Whether unregistering an instance also disposes it (default true).
    pub autodispose_unregistered_instances: bool,
}
impl Default for WriterDataLifecycle {
    fn default() -> Self {
        WriterDataLifecycle {
            autodispose_unregistered_instances: true,
        }
    }
}

/// READER_DATA_LIFECYCLE.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReaderDataLifecycle {
    /// How long samples of instances without writers are kept (default infinite).
    pub autopurge_nowriter_samples_delay: Duration,
    /// How long samples of disposed instances are kept (default infinite).
    pub autopurge_disposed_samples_delay: Duration,
}
impl Default for ReaderDataLifecycle {
    fn default() -> Self {
        ReaderDataLifecycle {
            autopurge_nowriter_samples_delay: INFINITE,
            autopurge_disposed_samples_delay: INFINITE,
        }
    }
}

/// Data representation id of XCDR1 (XTypes 1.3 §7.6.3.1.1), the default when a list is empty.
pub const XCDR_DATA_REPRESENTATION: i16 = 0;
/// Data representation id of XML (XTypes 1.3 §7.6.3.1.1); not supported for data, but may be announced.
pub const XML_DATA_REPRESENTATION: i16 = 1;
/// Data representation id of XCDR2 (XTypes 1.3 §7.6.3.1.1).
pub const XCDR2_DATA_REPRESENTATION: i16 = 2;

/// DATA_REPRESENTATION: the representation ids a writer offers (it uses only the first) or a reader accepts.
/// An empty list means the default, XCDR1.
///
/// ```
/// use dds_runtime::qos::DataRepresentation;
/// use dds_runtime::cdr::XcdrVersion;
/// assert_eq!(DataRepresentation::from(XcdrVersion::Xcdr2), DataRepresentation::xcdr2());
/// assert!(DataRepresentation::accept_both().accepts(0) && DataRepresentation::accept_both().accepts(2));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct DataRepresentation(Vec<i16>);

impl DataRepresentation {
    /// XCDR1 only.
    pub fn xcdr1() -> Self {
        DataRepresentation(vec![XCDR_DATA_REPRESENTATION])
    }
    /// XCDR2 only.
    pub fn xcdr2() -> Self {
        DataRepresentation(vec![XCDR2_DATA_REPRESENTATION])
    }
    /// XCDR1 and XCDR2 (for a reader: accepts either; for a writer: offers XCDR1).
    pub fn accept_both() -> Self {
        Self::any_of([XCDR_DATA_REPRESENTATION, XCDR2_DATA_REPRESENTATION])
    }
    /// The given representation ids, in order of preference.
    pub fn any_of(ids: impl IntoIterator<Item = i16>) -> Self {
        DataRepresentation(ids.into_iter().collect())
    }
    /// The representation ids as listed (empty: the default, XCDR1).
    pub fn ids(&self) -> &[i16] {
        &self.0
    }
    /// What a writer with this policy offers.
    pub fn offered(&self) -> i16 {
        self.0.first().copied().unwrap_or(XCDR_DATA_REPRESENTATION)
    }
    /// Whether a reader with this policy accepts `id`.
    pub fn accepts(&self, id: i16) -> bool {
        if self.0.is_empty() {
            id == XCDR_DATA_REPRESENTATION
        } else {
            self.0.contains(&id)
        }
    }
}

impl From<XcdrVersion> for DataRepresentation {
    fn from(v: XcdrVersion) -> Self {
        match v {
            XcdrVersion::Xcdr1 => Self::xcdr1(),
            XcdrVersion::Xcdr2 => Self::xcdr2(),
        }
    }
}

/// TRANSPORT_PRIORITY: a hint to the transport (announced, not used).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TransportPriority(pub i32);

/// DURABILITY_SERVICE: settings of a durability service (announced, not used).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DurabilityService {
    /// How long the service keeps data of instances without writers.
    pub service_cleanup_delay: Duration,
    /// The service's history.
    pub history: History,
    /// The service's limit on samples.
    pub max_samples: Option<u32>,
    /// The service's limit on instances.
    pub max_instances: Option<u32>,
    /// The service's limit on samples per instance.
    pub max_samples_per_instance: Option<u32>,
}
impl Default for DurabilityService {
    fn default() -> Self {
        DurabilityService {
            service_cleanup_delay: Duration::ZERO,
            history: History::KeepLast(1),
            max_samples: None,
            max_instances: None,
            max_samples_per_instance: None,
        }
    }
}

/// TYPE_CONSISTENCY_ENFORCEMENT kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TypeConsistencyKind {
    /// The reader's and writer's types must be equal.
    DisallowTypeCoercion,
    /// The writer's type must be assignable to the reader's.
    #[default]
    AllowTypeCoercion,
}

/// XTypes 1.3 §7.6.3.4.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TypeConsistencyEnforcement {
    /// Whether types must be equal or assignable.
    pub kind: TypeConsistencyKind,
    /// Sequence bounds do not count.
    pub ignore_sequence_bounds: bool,
    /// String bounds do not count.
    pub ignore_string_bounds: bool,
    /// Member names do not count.
    pub ignore_member_names: bool,
    /// Types may not be widened.
    pub prevent_type_widening: bool,
    /// Type information must be validated.
    pub force_type_validation: bool,
}
impl Default for TypeConsistencyEnforcement {
    fn default() -> Self {
        TypeConsistencyEnforcement {
            kind: TypeConsistencyKind::AllowTypeCoercion,
            ignore_sequence_bounds: true,
            ignore_string_bounds: true,
            ignore_member_names: false,
            prevent_type_widening: false,
            force_type_validation: false,
        }
    }
}

/// IGNORE_LOCAL, a vendor extension (Cyclone DDS's `ignorelocal`; ROS 2's `ignore_local_publications`):
/// which writers and readers of this process an endpoint ignores. A reader and a writer do not match when
/// either side's policy excludes the other. Local only: never announced (no PID), so remote peers see no
/// difference; an endpoint of another participant in this process only knows its own policy (it sees a
/// match the other side refuses, but no data flows). Fixed once the entity is enabled.
///
/// An endpoint's QoS starts at [`Inherit`](IgnoreLocal::Inherit): it takes its participant's default
/// (`Config::ignore_local`). Any other value is the endpoint's own and wins over that default, `None`
/// included (as an explicitly set policy does in Cyclone), so an endpoint can match its own participant's
/// endpoints although the participant ignores local peers by default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
#[non_exhaustive]
pub enum IgnoreLocal {
    /// Match every endpoint (the DDS behaviour).
    #[default]
    None,
    /// Do not match the endpoints of the same participant.
    Participant,
    /// Do not match the endpoints of any participant of the same process.
    Process,
    /// Not set on the endpoint: its participant's default applies (`Config::ignore_local`, itself `None`
    /// unless set). The default of `DataWriterQos::ignore_local` and `DataReaderQos::ignore_local`; as a
    /// participant default it means `None`.
    Inherit,
}

impl IgnoreLocal {
    /// The policy in effect: `self`, or `default` when `self` is [`Inherit`](IgnoreLocal::Inherit); never
    /// `Inherit` (an inherited `Inherit` is `None`).
    pub fn or_inherited(self, default: IgnoreLocal) -> IgnoreLocal {
        match (self, default) {
            (IgnoreLocal::Inherit, IgnoreLocal::Inherit) => IgnoreLocal::None,
            (IgnoreLocal::Inherit, d) => d,
            (own, _) => own,
        }
    }
}
