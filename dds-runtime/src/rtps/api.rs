//! The public types of the core's API: configuration, specs, changes, transmits, events and errors.

use std::fmt;
use std::ops::Deref;
use std::sync::Arc;
use std::time::Duration;

use super::discovery::{ports, ContentFilterProperty, ParticipantData, ReaderData, WriterData};
use super::messages::flags::StatusInfo;
use super::types::*;
use crate::qos::{IgnoreLocal, QosPolicyId, ReaderQos, WriterQos};
use crate::xtypes::TypeInformation;

/// Immutable shared bytes (a sample's serialized form). Cloning is a reference-count increment.
#[derive(Clone, Default)]
pub struct Payload {
    buf: Option<Buf>,
    start: usize,
    end: usize,
}

/// A payload's storage: a buffer of its own, a reusable one of a pool (`rtps/pool.rs`), or bytes some
/// other owner keeps (a sample read in place in shared memory, released with the last clone).
#[derive(Clone)]
enum Buf {
    Slice(Arc<[u8]>),
    Vec(Arc<Vec<u8>>),
    Owned(Arc<dyn AsRef<[u8]> + Send + Sync>),
    /// A typed sample handed to readers of its writer's participant as itself; serialized only when
    /// something reads its bytes.
    Local(Arc<dyn LocalSample>),
}

impl Buf {
    fn bytes(&self) -> &[u8] {
        match self {
            Buf::Slice(b) => b,
            Buf::Vec(v) => v,
            Buf::Owned(o) => (**o).as_ref(),
            Buf::Local(l) => l.bytes(),
        }
    }
}

/// Asks the CPU to bring `a`'s reference counts and value into the cache ahead of use (a hint: no effect
/// on other targets).
#[inline]
pub(crate) fn prefetch_arc<T>(a: &Arc<T>) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // The counts are the two words before the value; one line each side covers both.
        let p = Arc::as_ptr(a).cast::<i8>();
        // SAFETY: a prefetch is a hint that never faults, whatever the address; `wrapping_*` keep the
        // pointer arithmetic defined.
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(p.wrapping_sub(16));
            _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(std::mem::size_of::<T>()));
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = a;
}

/// A sample written as a typed value (`DataWriter::write_owned`, `write_shared`) that readers of the same
/// participant receive as itself, with no serialization: the core carries it in a [`Payload`]
/// ([`Payload::local`]) without looking inside.
pub trait LocalSample: Send + Sync + 'static {
    /// The serialized sample (with its encapsulation header), produced on the first call: for whatever
    /// needs the bytes after all (a reader of another type, a durability service).
    fn bytes(&self) -> &[u8];
    /// Whether `slot` is an `Option` of the sample's type.
    fn fits(&self, slot: &dyn std::any::Any) -> bool;
    /// Puts the sample into `slot` when it [`fits`](Self::fits): moved out when this is the last
    /// reference to it, else cloned.
    fn take_into(self: Arc<Self>, slot: &mut dyn std::any::Any);
}

impl Payload {
    /// Shares `bytes` whole.
    pub fn new(bytes: impl Into<Arc<[u8]>>) -> Self {
        let buf: Arc<[u8]> = bytes.into();
        let end = buf.len();
        Payload {
            buf: Some(Buf::Slice(buf)),
            start: 0,
            end,
        }
    }
    /// Brings the shared buffer's reference counts into the cache ahead of a clone or drop (a hint).
    pub(crate) fn prefetch(&self) {
        if let Some(Buf::Vec(v)) = &self.buf {
            prefetch_arc(v);
        }
    }
    /// Shares the bytes of a pooled buffer whole.
    pub(crate) fn from_shared_vec(v: Arc<Vec<u8>>) -> Self {
        let end = v.len();
        Payload {
            buf: Some(Buf::Vec(v)),
            start: 0,
            end,
        }
    }
    /// Shares the bytes `owner` keeps, with no copy; they are released when the last clone is dropped.
    /// The bytes must not change while the payload lives.
    pub fn from_owner(owner: Arc<dyn AsRef<[u8]> + Send + Sync>) -> Self {
        let end = (*owner).as_ref().len();
        Payload {
            buf: Some(Buf::Owned(owner)),
            start: 0,
            end,
        }
    }
    /// Carries a typed sample for intra-process delivery. `len` is what the writer accounts for: the
    /// serialized length when the sample was serialized already, else 0 (it then must not be sent: only
    /// readers of the same participant get it). Reading the payload's bytes serializes it.
    pub fn local(sample: Arc<dyn LocalSample>, len: usize) -> Self {
        Payload {
            buf: Some(Buf::Local(sample)),
            start: 0,
            end: len,
        }
    }
    /// Whether the bytes are kept by another owner ([`Payload::from_owner`]: a sample read in place in
    /// shared memory).
    pub fn is_from_owner(&self) -> bool {
        matches!(self.buf, Some(Buf::Owned(_)))
    }
    /// Whether this payload carries a typed sample ([`Payload::local`]).
    pub fn is_local(&self) -> bool {
        matches!(self.buf, Some(Buf::Local(_)))
    }
    /// Puts the typed sample of a [`Payload::local`] into `slot`, an `Option` of its type (see
    /// [`LocalSample::take_into`]); gives the payload back for serialized bytes or another type.
    pub fn take_local_into(self, slot: &mut dyn std::any::Any) -> Result<(), Payload> {
        if !matches!(&self.buf, Some(Buf::Local(l)) if l.fits(&*slot)) {
            return Err(self);
        }
        if let Some(Buf::Local(l)) = self.buf {
            l.take_into(slot);
        }
        Ok(())
    }
    /// The length the writer's history and flow control account for: the byte length, except for a
    /// typed sample not serialized when written ([`Payload::local`] with 0), which reading does not change.
    pub fn accounted_len(&self) -> usize {
        self.end - self.start
    }
    /// A copy of `b` in a buffer of its own.
    pub fn copy_from_slice(b: &[u8]) -> Self {
        Payload::new(Arc::<[u8]>::from(b))
    }
    /// `part` as a sub-range of `whole` when it lies inside it (no copy), else a copy of `part`.
    pub fn share_or_copy(whole: Option<&Payload>, part: &[u8]) -> Payload {
        if let Some(w) = whole {
            let base = w.as_ptr() as usize;
            let start = part.as_ptr() as usize;
            if start >= base && start + part.len() <= base + w.len() {
                return w.slice(start - base..start - base + part.len());
            }
        }
        Payload::copy_from_slice(part)
    }
    /// The same bytes, copied into a buffer of their own if they are a slice of a larger one, so that
    /// keeping them does not keep the rest alive.
    pub fn compact(self) -> Payload {
        if self.is_part() {
            Payload::copy_from_slice(&self)
        } else {
            self
        }
    }
    /// Whether the bytes are a slice of a larger buffer (which keeping them keeps alive whole).
    pub(crate) fn is_part(&self) -> bool {
        match &self.buf {
            Some(Buf::Local(_)) | None => false,
            Some(b) => b.bytes().len() > self.len(),
        }
    }
    /// A sub-range sharing the same buffer; clamps out-of-range bounds.
    pub fn slice(&self, range: std::ops::Range<usize>) -> Payload {
        let end = (self.start + range.end).min(self.end);
        let start = (self.start + range.start).min(end);
        Payload {
            buf: self.buf.clone(),
            start,
            end,
        }
    }
}

impl Deref for Payload {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        match &self.buf {
            // Serialized on demand: the whole sample, whatever length was accounted for.
            Some(Buf::Local(l)) => l.bytes(),
            Some(b) => &b.bytes()[self.start..self.end],
            None => &[],
        }
    }
}
impl AsRef<[u8]> for Payload {
    fn as_ref(&self) -> &[u8] {
        self
    }
}
impl From<Vec<u8>> for Payload {
    fn from(v: Vec<u8>) -> Self {
        Payload::new(v)
    }
}
impl From<&[u8]> for Payload {
    fn from(v: &[u8]) -> Self {
        Payload::copy_from_slice(v)
    }
}
impl From<Arc<[u8]>> for Payload {
    fn from(v: Arc<[u8]>) -> Self {
        Payload::new(v)
    }
}
impl PartialEq for Payload {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}
impl Eq for Payload {}
impl fmt::Debug for Payload {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_local() {
            return write!(
                f,
                "Payload(local sample, {} bytes accounted)",
                self.accounted_len()
            );
        }
        write!(f, "Payload({} bytes)", self.len())
    }
}

/// Defines [`ParticipantConfig`] (read-only getters) and [`ParticipantConfigBuilder`] (one setter per field)
/// from one list. `copy` fields are returned by value, `ref` fields by reference.
macro_rules! participant_config {
    ($($(#[$doc:meta])* $field:ident: $ty:ty = $kind:ident,)*) => {
        /// Everything the core needs to know about the local participant. Build it with
        /// [`ParticipantConfig::builder`] (standard ports for one unicast address) or
        /// [`ParticipantConfigBuilder::default`]; read it back with the getters.
        ///
        /// ```
        /// use std::time::Duration;
        /// use dds_runtime::rtps::{GuidPrefix, ParticipantConfig};
        /// let c = ParticipantConfig::builder(0, 1, GuidPrefix([7; 12]), [127, 0, 0, 1])
        ///     .lease_duration(Duration::from_secs(3))
        ///     .build();
        /// assert_eq!(c.lease_duration(), Duration::from_secs(3));
        /// assert_eq!(c.default_unicast()[0].port, 7413);
        /// ```
        #[derive(Debug, Clone)]
        pub struct ParticipantConfig {
            $(pub(crate) $field: $ty,)*
        }

        impl ParticipantConfig {
            $(participant_config!(@get $kind $(#[$doc])* $field: $ty);)*
        }

        /// Builds a [`ParticipantConfig`]; every setter replaces one value.
        #[derive(Debug, Clone)]
        pub struct ParticipantConfigBuilder(ParticipantConfig);

        impl ParticipantConfigBuilder {
            $(
                $(#[$doc])*
                pub fn $field(mut self, value: impl Into<$ty>) -> Self {
                    self.0.$field = value.into();
                    self
                }
            )*
        }
    };
    (@get copy $(#[$doc:meta])* $field:ident: $ty:ty) => {
        $(#[$doc])*
        pub fn $field(&self) -> $ty {
            self.$field
        }
    };
    (@get ref $(#[$doc:meta])* $field:ident: $ty:ty) => {
        $(#[$doc])*
        pub fn $field(&self) -> &$ty {
            &self.$field
        }
    };
}

participant_config! {
    /// The DDS domain id.
    domain_id: u32 = copy,
    /// The participant index used in the port formula (chosen by the transport).
    participant_id: u32 = copy,
    /// The GUID prefix of the participant and all its endpoints.
    guid_prefix: GuidPrefix = copy,
    /// The vendor id in every message header; defaults to [`VendorId::THIS`] (0x01dd).
    vendor_id: VendorId = copy,
    /// Where peers send discovery traffic to us unicast.
    metatraffic_unicast: Vec<Locator> = ref,
    /// The SPDP multicast destinations (default 239.255.0.1 at the domain's SPDP port).
    metatraffic_multicast: Vec<Locator> = ref,
    /// Where peers send user data to us unicast.
    default_unicast: Vec<Locator> = ref,
    /// Where peers may send user data to us by multicast.
    default_multicast: Vec<Locator> = ref,
    /// Period of SPDP announcements (default 3 s).
    spdp_interval: Duration = copy,
    /// Lease announced to peers (default 10 s, like Cyclone).
    lease_duration: Duration = copy,
    /// Unicast SPDP destinations in addition to the multicast ones.
    initial_peers: Vec<Locator> = ref,
    /// Datagram payload limit for packing (default 14720, Cyclone's MaxMessageSize).
    max_message_size: usize = copy,
    /// DATA_FRAG fragment size (default 1344; ≤ 65535). A user writer sends a sample whole, as one DATA,
    /// when two fit one datagram of [`max_message_size`](Self::max_message_size) (with 256 bytes of headers),
    /// and in fragments of this size when not; builtin writers fragment every sample larger than this.
    fragment_size: usize = copy,
    /// USER_DATA announced in SPDP.
    user_data: Vec<u8> = ref,
    /// PID_ENTITY_NAME announced in SPDP.
    entity_name: Option<String> = ref,
    /// PID_PROPERTY_LIST announced in SPDP (name, value).
    properties: Vec<(String, String)> = ref,
    /// Period of heartbeats while data is unacknowledged (default 100 ms).
    heartbeat_period: Duration = copy,
    /// Delay before answering a NACK, so that requests merge (default 5 ms).
    nack_response_delay: Duration = copy,
    /// Delay before answering a HEARTBEAT with an ACKNACK (default 0). Acknowledgements that ask for
    /// nothing wait longer, so that those of one pass share a datagram: 5 ms in built-in readers, 20 ms for
    /// a user reader's pre-emptive ACKNACK; a NACK is never delayed beyond this value.
    heartbeat_response_delay: Duration = copy,
    /// Flow control: `write` refuses (WouldBlock) once this many bytes are unacknowledged (default 512 KiB),
    /// until they drop below [`whc_low_watermark`](Self::whc_low_watermark). For large samples the window
    /// grows to hold four samples of the size last written (at most 4 MiB), released at half of it.
    whc_high_watermark: usize = copy,
    /// Flow control: where a blocked writer is released (default 128 KiB).
    whc_low_watermark: usize = copy,
    /// Largest sample accepted from the network (default 64 MiB); bigger ones are dropped and acknowledged.
    max_sample_size: usize = copy,
    /// Per remote writer: samples defragmented at once (default 8).
    defrag_max_samples: usize = copy,
    /// Per remote writer: bytes held in fragments, overhead counted (default 16 MiB).
    defrag_max_bytes: usize = copy,
    /// Per remote writer: out-of-order samples held for reordering (default 32 768); beyond it, later
    /// samples are dropped and requested again once the gap is filled. The default holds a whole window of
    /// small samples (512 KiB of 16-byte samples is 26 000), so that one lost or late datagram costs one
    /// repair, not a repair of everything the writer sent after it.
    reorder_max_samples: usize = copy,
    /// Per remote writer: bytes of out-of-order samples held for reordering (default 64 MiB).
    reorder_max_bytes: usize = copy,
    /// How long a deleted reliable writer lingers waiting for acknowledgements (default 1 s).
    writer_linger_duration: Duration = copy,
    /// Upper bound on bytes retransmitted per repair round to one reader (default 256 KiB).
    max_repair_bytes: usize = copy,
    /// Write batching: user DATA waits up to this long for more samples to share its datagram, leaving
    /// earlier when the datagram is full, on [`Participant::flush`](super::Participant::flush), or with any
    /// other outgoing traffic. `None` (the default) sends every write at once.
    write_batch_delay: Option<Duration> = copy,
    /// Intra-process delivery (default on): a local writer and a local reader of this participant match
    /// without wire state; the writer's changes reach the reader as events, never as datagrams (see
    /// `docs/rtps-core.md`, "Intra-process delivery").
    intra_process: bool = copy,
    /// Multicast user data (Cyclone's `AllowMulticast` for data): when on, a writer sends each new sample
    /// once to a multicast locator shared by two or more of its matched readers (the readers' own
    /// multicast locators, else their participants' default multicast locators) instead of once per reader;
    /// repairs still go to each reader's unicast locator. Off (the default): data goes unicast only. What
    /// *our* readers announce is [`default_multicast`](Self::default_multicast).
    multicast_data: bool = copy,
    /// The IGNORE_LOCAL policy of the user endpoints whose own is [`IgnoreLocal::Inherit`] (the QoS
    /// default; this default is `None`): a participant-wide default, as Cyclone's configuration has one per
    /// participant. An endpoint that sets its own (`None` included) keeps it.
    ignore_local: IgnoreLocal = copy,
}

impl ParticipantConfig {
    /// A builder for one IPv4 unicast address with the standard ports (PB 7400, DG 250, PG 2, d0..d3 =
    /// 0, 10, 1, 11), SPDP multicast to 239.255.0.1 and the defaults documented on each field. Fails when a
    /// port would exceed 65535.
    pub fn builder(
        domain_id: u32,
        participant_id: u32,
        guid_prefix: GuidPrefix,
        unicast_ip: [u8; 4],
    ) -> Result<ParticipantConfigBuilder, ports::PortError> {
        let mc = ports::SPDP_MULTICAST_GROUP.octets();
        Ok(ParticipantConfigBuilder(ParticipantConfig {
            domain_id,
            participant_id,
            guid_prefix,
            vendor_id: VendorId::THIS,
            metatraffic_unicast: vec![Locator::udpv4(
                unicast_ip,
                ports::metatraffic_unicast(domain_id, participant_id)?,
            )],
            metatraffic_multicast: vec![Locator::udpv4(mc, ports::spdp_multicast(domain_id)?)],
            default_unicast: vec![Locator::udpv4(
                unicast_ip,
                ports::user_unicast(domain_id, participant_id)?,
            )],
            default_multicast: vec![Locator::udpv4(mc, ports::user_multicast(domain_id)?)],
            spdp_interval: Duration::from_secs(3),
            lease_duration: Duration::from_secs(10),
            initial_peers: Vec::new(),
            max_message_size: 14720,
            fragment_size: 1344,
            user_data: Vec::new(),
            entity_name: None,
            properties: Vec::new(),
            heartbeat_period: Duration::from_millis(100),
            nack_response_delay: Duration::from_millis(5),
            heartbeat_response_delay: Duration::ZERO,
            whc_high_watermark: 512 * 1024,
            whc_low_watermark: 128 * 1024,
            max_sample_size: 64 * 1024 * 1024,
            defrag_max_samples: 8,
            defrag_max_bytes: 16 * 1024 * 1024,
            reorder_max_samples: 32 * 1024,
            reorder_max_bytes: 64 * 1024 * 1024,
            writer_linger_duration: Duration::from_secs(1),
            max_repair_bytes: 256 * 1024,
            write_batch_delay: None,
            intra_process: true,
            multicast_data: false,
            ignore_local: IgnoreLocal::None,
        }))
    }

    /// [`builder`](Self::builder) with nothing changed.
    pub fn new(
        domain_id: u32,
        participant_id: u32,
        guid_prefix: GuidPrefix,
        unicast_ip: [u8; 4],
    ) -> Result<Self, ports::PortError> {
        Ok(Self::builder(domain_id, participant_id, guid_prefix, unicast_ip)?.build())
    }

    /// A builder starting from this configuration.
    pub fn to_builder(&self) -> ParticipantConfigBuilder {
        ParticipantConfigBuilder(self.clone())
    }
}

/// Domain 0, participant index 0, a zero GUID prefix and 127.0.0.1 (see [`ParticipantConfig::builder`]).
impl Default for ParticipantConfig {
    fn default() -> Self {
        ParticipantConfigBuilder::default().build()
    }
}

/// Domain 0, participant index 0, a zero GUID prefix and 127.0.0.1 (see [`ParticipantConfig::builder`]).
impl Default for ParticipantConfigBuilder {
    fn default() -> Self {
        // Domain 0 and participant index 0 give the lowest ports, which are always in range.
        ParticipantConfig::builder(0, 0, GuidPrefix::default(), [127, 0, 0, 1])
            .expect("the ports of domain 0, participant 0 are in range")
    }
}

impl ParticipantConfigBuilder {
    /// The finished configuration.
    pub fn build(self) -> ParticipantConfig {
        self.0
    }
}

impl From<ParticipantConfigBuilder> for ParticipantConfig {
    fn from(b: ParticipantConfigBuilder) -> Self {
        b.build()
    }
}

/// What a change does to its instance (PID_STATUS_INFO on the wire).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ChangeKind {
    /// A new value of the instance.
    Alive,
    /// The instance was disposed.
    Dispose,
    /// The writer unregistered the instance.
    Unregister,
    /// Both at once (e.g. Cyclone's autodispose on unregister).
    DisposeUnregister,
}

impl ChangeKind {
    /// The PID_STATUS_INFO flag bits of this kind.
    pub fn status_info(self) -> u8 {
        let flags = match self {
            ChangeKind::Alive => StatusInfo::empty(),
            ChangeKind::Dispose => StatusInfo::DISPOSED,
            ChangeKind::Unregister => StatusInfo::UNREGISTERED,
            ChangeKind::DisposeUnregister => StatusInfo::DISPOSED | StatusInfo::UNREGISTERED,
        };
        flags.bits()
    }
    /// The kind for PID_STATUS_INFO flag bits (other bits than disposed and unregistered are ignored).
    pub fn from_status_info(flags: u8) -> Self {
        let flags = StatusInfo::from_bits_truncate(flags);
        match (
            flags.contains(StatusInfo::DISPOSED),
            flags.contains(StatusInfo::UNREGISTERED),
        ) {
            (false, false) => ChangeKind::Alive,
            (true, false) => ChangeKind::Dispose,
            (false, true) => ChangeKind::Unregister,
            (true, true) => ChangeKind::DisposeUnregister,
        }
    }
}

/// One change to write.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WriteChange {
    /// What the change does to its instance.
    pub kind: ChangeKind,
    /// Serialized sample (with encapsulation header); for non-Alive kinds the serialized key (may be empty).
    pub payload: Payload,
    /// Sent as PID_KEY_HASH inline QoS and used as the instance identity for KEEP_LAST history.
    /// Required for keyed topics; `None` for keyless ones.
    pub key_hash: Option<[u8; 16]>,
    /// Sent in INFO_TS; `None` sends no timestamp.
    pub source_timestamp: Option<Time>,
}

impl WriteChange {
    /// A new value (kind [`ChangeKind::Alive`]) with no key hash and no timestamp.
    pub fn alive(payload: impl Into<Payload>) -> Self {
        WriteChange {
            kind: ChangeKind::Alive,
            payload: payload.into(),
            key_hash: None,
            source_timestamp: None,
        }
    }
    /// Sets the key hash (required for keyed writers).
    pub fn with_key_hash(mut self, key_hash: [u8; 16]) -> Self {
        self.key_hash = Some(key_hash);
        self
    }
    /// Sets the source timestamp sent in INFO_TS.
    pub fn with_timestamp(mut self, t: Time) -> Self {
        self.source_timestamp = Some(t);
        self
    }
    /// Sets the kind (dispose, unregister).
    pub fn with_kind(mut self, kind: ChangeKind) -> Self {
        self.kind = kind;
        self
    }
}

/// A local endpoint to create: a writer (`Q` = [`WriterQos`], see [`WriterSpec`]) or a reader (`Q` =
/// [`ReaderQos`], see [`ReaderSpec`]).
#[derive(Debug, Clone)]
pub struct EndpointSpec<Q> {
    /// The topic name (must not be empty).
    pub topic_name: String,
    /// The registered type name (must not be empty).
    pub type_name: String,
    /// Whether the type has key members (decides the entity kind and, for writers, KEEP_LAST per instance).
    pub keyed: bool,
    /// Endpoint, group and topic QoS as announced. The data representation is
    /// `qos.writer.data_representation` (offered) or `qos.reader.data_representation` (accepted).
    pub qos: Q,
    /// XTypes TYPE_INFORMATION to announce, kept opaque.
    pub type_information: Option<TypeInformation>,
    /// PID_ENTITY_NAME to announce.
    pub entity_name: Option<String>,
    /// PID_CONTENT_FILTER_PROPERTY to announce (readers on a content-filtered topic).
    pub content_filter: Option<ContentFilterProperty>,
    /// A service's endpoint inside this participant (the durability service's, for one): it matches the
    /// participant's other endpoints as usual, but their matched, incompatible-QoS and liveliness events
    /// never mention it, so users' statuses count only what users created. Peers see it as any endpoint.
    pub internal: bool,
}

/// A local writer to create.
pub type WriterSpec = EndpointSpec<WriterQos>;

/// A local reader to create.
pub type ReaderSpec = EndpointSpec<ReaderQos>;

impl<Q> EndpointSpec<Q> {
    /// An endpoint without type information or entity name.
    pub fn new(
        topic_name: impl Into<String>,
        type_name: impl Into<String>,
        keyed: bool,
        qos: impl Into<Q>,
    ) -> Self {
        EndpointSpec {
            topic_name: topic_name.into(),
            type_name: type_name.into(),
            keyed,
            qos: qos.into(),
            type_information: None,
            entity_name: None,
            content_filter: None,
            internal: false,
        }
    }
}

/// A received change delivered to a local reader.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReceivedSample {
    /// The local reader it is for.
    pub reader: EntityId,
    /// The remote (or local) writer that wrote it.
    pub writer: Guid,
    /// The writer's sequence number.
    pub sequence: SequenceNumber,
    /// What the change does to its instance.
    pub kind: ChangeKind,
    /// Serialized sample, or serialized key (possibly empty) when `kind` is not Alive.
    pub payload: Payload,
    /// PID_KEY_HASH, when the writer sent one (Cyclone does not).
    pub key_hash: Option<[u8; 16]>,
    /// The writer's INFO_TS, if any.
    pub source_timestamp: Option<Time>,
    /// PID_GROUP_SEQ_NUM: the change's number among all changes of its writer's publisher, from
    /// publishers with GROUP access scope.
    pub group_sequence: Option<SequenceNumber>,
}

/// Names a group coherent set (RTPS 2.5 §8.7.6): the group sequence number of its first change and the
/// digest of its writers (`PID_GROUP_COHERENT_SET`, `PID_WRITER_GROUP_INFO`), both from the end-of-set
/// markers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct GroupSetId {
    /// The group sequence number of the set's first change.
    pub set: SequenceNumber,
    /// The digest of the writers of the set (`GroupDigest_t`).
    pub writers: [u8; 4],
}

/// What the core reports to the DCPS layer.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Event {
    /// A change for a local reader.
    Sample(ReceivedSample),
    /// A whole coherent set from one writer (RTPS 2.5 §8.7.6), in the writer's order: every change the
    /// writer made between `begin_coherent_set` and `end_coherent_set`. Delivered only once every change
    /// of the set arrived; a set with a missing change is reported as [`Event::SampleLost`] instead.
    CoherentSet {
        /// The local reader.
        reader: EntityId,
        /// The writer of the set.
        writer: Guid,
        /// The changes of the set (never empty).
        samples: Vec<ReceivedSample>,
        /// For a writer's part of a group coherent set (GROUP access scope): the set. The parts of one
        /// group set are delivered together, once every writer's part arrived, in group sequence order: a
        /// part comes in several events (consecutive changes each) when other writers wrote in between.
        group: Option<GroupSetId>,
    },
    /// A local writer matched or unmatched a reader.
    PublicationMatched {
        /// The local writer.
        writer: EntityId,
        /// The reader.
        reader: Guid,
        /// `true` when matched, `false` when no longer.
        matched: bool,
    },
    /// A local reader matched or unmatched a writer.
    SubscriptionMatched {
        /// The local reader.
        reader: EntityId,
        /// The writer.
        writer: Guid,
        /// `true` when matched, `false` when no longer.
        matched: bool,
    },
    /// A local writer and a reader on its topic have incompatible QoS (reported once per pair).
    OfferedIncompatibleQos {
        /// The local writer.
        writer: EntityId,
        /// The reader.
        reader: Guid,
        /// The first incompatible policy.
        policy: QosPolicyId,
    },
    /// A local reader and a writer on its topic have incompatible QoS (reported once per pair).
    RequestedIncompatibleQos {
        /// The local reader.
        reader: EntityId,
        /// The writer.
        writer: Guid,
        /// The first incompatible policy.
        policy: QosPolicyId,
    },
    /// A remote participant appeared.
    ParticipantDiscovered(Box<ParticipantData>),
    /// A remote participant left or its lease expired.
    ParticipantLost {
        /// Its GUID prefix.
        guid_prefix: GuidPrefix,
    },
    /// A publication (remote) appeared, or was announced again with other data (its QoS changed).
    PublicationDiscovered(Box<WriterData>),
    /// A known publication is gone.
    PublicationRemoved {
        /// Its GUID.
        guid: Guid,
    },
    /// A subscription (remote) appeared, or was announced again with other data (its QoS changed).
    SubscriptionDiscovered(Box<ReaderData>),
    /// A known subscription is gone.
    SubscriptionRemoved {
        /// Its GUID.
        guid: Guid,
    },
    /// A matched remote writer's liveliness changed (automatic: participant lease; manual: its messages).
    LivelinessChanged {
        /// The local reader.
        reader: EntityId,
        /// The matched writer.
        writer: Guid,
        /// Whether the writer is alive now.
        alive: bool,
    },
    /// A local writer with manual liveliness did not assert it within its lease (LIVELINESS_LOST; once per
    /// lapse: the next write or assertion renews it).
    LivelinessLost {
        /// The local writer.
        writer: EntityId,
    },
    /// Samples from `writer` that `reader` will never get (writer no longer had them, or buffers overflowed).
    SampleLost {
        /// The local reader.
        reader: EntityId,
        /// The writer.
        writer: Guid,
        /// How many changes were lost.
        count: u64,
    },
    /// A deleted writer finished lingering and is gone.
    WriterDeleted {
        /// The local writer.
        writer: EntityId,
    },
    /// A remote topic was announced in SEDP (DCPSTopic), or announced again with other data.
    TopicDiscovered(Box<crate::rtps::discovery::TopicData>),
    /// A remote topic announced in SEDP was withdrawn (or its participant left).
    TopicRemoved {
        /// The topic's GUID.
        guid: Guid,
    },
    /// A local reader was deleted (after its unmatch events).
    ReaderDeleted {
        /// The local reader.
        reader: EntityId,
    },
    /// Flow control released a writer that returned WouldBlock: unacknowledged bytes fell below the low watermark.
    WriterUnblocked {
        /// The local writer.
        writer: EntityId,
    },
    /// Every matched reliable reader acknowledged everything the writer wrote (wait_for_acknowledgments).
    WriterAcknowledged {
        /// The local writer.
        writer: EntityId,
    },
}

/// Why the core refused to create an endpoint.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CoreError {
    /// No local endpoint has this id.
    #[error("no such entity {0:?}")]
    UnknownEntity(EntityId),
    /// All 2^24 entity keys are used up.
    #[error("out of entity ids")]
    OutOfEntityIds,
    /// A spec was refused; the text says why.
    #[error("bad parameter: {0}")]
    BadParameter(&'static str),
}

/// Why [`Participant::write`](super::Participant::write) refused a change.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WriteError {
    /// Flow control or KEEP_ALL resource limits refuse the change for now; retry after acknowledgements
    /// arrive (within the writer's max_blocking_time).
    #[error("writer would block")]
    WouldBlock,
    /// No local user writer has this id.
    #[error("no such writer {0:?}")]
    UnknownWriter(EntityId),
    /// The writer is lingering after deletion.
    #[error("writer is being deleted")]
    Deleted,
    /// The serialized size exceeds what a sample can have.
    #[error("sample of {0} bytes exceeds the maximum sample size")]
    TooLarge(usize),
    /// A keyed writer got a change without a key hash.
    #[error("keyed writer needs a key hash")]
    MissingKeyHash,
}

#[cfg(test)]
mod tests {
    use super::Payload;

    #[test]
    fn share_or_copy_shares_only_what_lies_inside() {
        let whole = Payload::from(vec![1u8, 2, 3, 4, 5, 6]);
        let inside = Payload::share_or_copy(Some(&whole), &whole[2..5]);
        assert_eq!(&inside[..], &[3, 4, 5]);
        assert_eq!(inside.as_ptr(), whole[2..].as_ptr(), "no copy");
        let elsewhere = [3u8, 4, 5];
        let copied = Payload::share_or_copy(Some(&whole), &elsewhere);
        assert_eq!(&copied[..], &[3, 4, 5]);
        assert_ne!(copied.as_ptr(), elsewhere.as_ptr());
        assert_eq!(&Payload::share_or_copy(None, &whole[..2])[..], &[1, 2]);
    }

    #[test]
    fn compact_drops_the_rest_of_the_buffer() {
        let whole = Payload::from(vec![9u8; 1000]);
        let part = whole.slice(10..20);
        let compacted = part.clone().compact();
        assert_eq!(compacted, part);
        assert_ne!(compacted.as_ptr(), part.as_ptr());
        let alone = Payload::from(vec![7u8; 10]);
        assert_eq!(
            alone.clone().compact().as_ptr(),
            alone.as_ptr(),
            "already compact"
        );
    }
}
