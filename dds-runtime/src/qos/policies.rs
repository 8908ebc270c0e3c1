//! The DDS QoS policies (DDS 1.4 §2.2.3) as plain values.

use std::time::Duration;

use crate::cdr::XcdrVersion;

/// `DURATION_INFINITE`: maps to the wire value {0x7fffffff, 0xffffffff}.
pub const INFINITE: Duration = Duration::MAX;

/// DDS `QosPolicyId_t` values, reported by the incompatible-QoS events.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u32)]
pub enum QosPolicyId {
    UserData = 1,
    Durability = 2,
    Presentation = 3,
    Deadline = 4,
    LatencyBudget = 5,
    Ownership = 6,
    OwnershipStrength = 7,
    Liveliness = 8,
    TimeBasedFilter = 9,
    Partition = 10,
    Reliability = 11,
    DestinationOrder = 12,
    History = 13,
    ResourceLimits = 14,
    EntityFactory = 15,
    WriterDataLifecycle = 16,
    ReaderDataLifecycle = 17,
    TopicData = 18,
    GroupData = 19,
    TransportPriority = 20,
    Lifespan = 21,
    DurabilityService = 22,
    DataRepresentation = 23,
    TypeConsistencyEnforcement = 24,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reliability {
    BestEffort,
    Reliable { max_blocking_time: Duration },
}

impl Reliability {
    /// Reliable with the spec's default max_blocking_time of 100 ms.
    pub const RELIABLE: Reliability = Reliability::Reliable {
        max_blocking_time: Duration::from_millis(100),
    };

    pub fn is_reliable(&self) -> bool {
        matches!(self, Reliability::Reliable { .. })
    }
}

/// Ordered: a writer offering a kind satisfies readers requesting the same or a lower kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum Durability {
    #[default]
    Volatile,
    TransientLocal,
    Transient,
    Persistent,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum History {
    KeepLast(u32),
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
    pub max_samples: Option<u32>,
    pub max_instances: Option<u32>,
    pub max_samples_per_instance: Option<u32>,
}

#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Partition(pub Vec<String>);

impl Partition {
    pub fn new<I: IntoIterator<Item = S>, S: Into<String>>(names: I) -> Self {
        Partition(names.into_iter().map(Into::into).collect())
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Deadline(pub Duration);
impl Default for Deadline {
    fn default() -> Self {
        Deadline(INFINITE)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LatencyBudget(pub Duration);

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum LivelinessKind {
    #[default]
    Automatic,
    ManualByParticipant,
    ManualByTopic,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Liveliness {
    pub kind: LivelinessKind,
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

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Ownership {
    #[default]
    Shared,
    Exclusive,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OwnershipStrength(pub i32);

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum DestinationOrder {
    #[default]
    ByReceptionTimestamp,
    BySourceTimestamp,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum PresentationAccessScope {
    #[default]
    Instance,
    Topic,
    Group,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Presentation {
    pub access_scope: PresentationAccessScope,
    pub coherent_access: bool,
    pub ordered_access: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Lifespan(pub Duration);
impl Default for Lifespan {
    fn default() -> Self {
        Lifespan(INFINITE)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TimeBasedFilter {
    pub minimum_separation: Duration,
}

#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct UserData(pub Vec<u8>);
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct TopicData(pub Vec<u8>);
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct GroupData(pub Vec<u8>);

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WriterDataLifecycle {
    pub autodispose_unregistered_instances: bool,
}
impl Default for WriterDataLifecycle {
    fn default() -> Self {
        WriterDataLifecycle {
            autodispose_unregistered_instances: true,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReaderDataLifecycle {
    pub autopurge_nowriter_samples_delay: Duration,
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

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TransportPriority(pub i32);

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DurabilityService {
    pub service_cleanup_delay: Duration,
    pub history: History,
    pub max_samples: Option<u32>,
    pub max_instances: Option<u32>,
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

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TypeConsistencyKind {
    DisallowTypeCoercion,
    #[default]
    AllowTypeCoercion,
}

/// XTypes 1.3 §7.6.3.4.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TypeConsistencyEnforcement {
    pub kind: TypeConsistencyKind,
    pub ignore_sequence_bounds: bool,
    pub ignore_string_bounds: bool,
    pub ignore_member_names: bool,
    pub prevent_type_widening: bool,
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
