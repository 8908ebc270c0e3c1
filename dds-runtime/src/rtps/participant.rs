//! The participant: the sans-I/O state machine that owns every local endpoint and runs discovery.
//!
//! `receive` dispatches incoming submessages, `discovery` runs SPDP/SEDP/matching, `timers` the periodic work.

mod coherent;
mod control;
mod discovery;
mod enable;
mod filtering;
mod group;
mod group_order;
mod historical;
mod internal;
mod interned;
mod liveliness;
mod local;
mod managed;
mod receive;
mod shm;
mod timers;
#[cfg(feature = "net")]
pub(crate) use timers::KEPT_QUEUE_ROOM;
mod topics;
mod type_lookup;

use std::cell::Cell;
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::time::{Duration, Instant};

use foldhash::{HashMap, HashMapExt, HashSet, HashSetExt};

use super::api::*;
use super::discovery::{EndpointData, ParticipantData, ReaderData, WriterData};
use super::messages::Header;
use super::outbox::Outbox;
use super::reader::{Reader, ReaderParams};
use super::transmit::Transmit;
use super::types::*;
use super::writer::{Writer, WriterParams};
use crate::qos::{DataWriterQos, Durability, History, ReaderQos, ResourceLimits, WriterQos};

/// A discovered remote participant.
///
/// Compact (see `docs/performance.md`, "Footprint"): what the core consults often is kept decoded, the whole
/// announcement only in our own PL-CDR encoding, one allocation of its exact size, decoded when asked for
/// ([`ProxyParticipant::data`]). The decoded form costs five allocations and about twice the bytes.
#[derive(Debug)]
struct ProxyParticipant {
    lease_deadline: Instant,
    lease_duration: Duration,
    vendor_id: VendorId,
    builtin_endpoints: u32,
    /// Its TypeLookup endpoints are matched with ours (done when a request or reply is first exchanged).
    type_lookup_matched: bool,
    /// Which of its participant-message endpoints are matched with ours (done on first use, see
    /// `Participant::match_messages`): bits `MESSAGES_IN` (its writer) and `MESSAGES_OUT` (its reader).
    messages_matched: u8,
    /// Where its builtin endpoints listen: one list, shared with all their proxies. When its builtin readers
    /// share a metatraffic multicast group with us, the group is the last entry (for the proxies of its
    /// readers, `ReaderProxy::with_multicast_last`; the others use the first entry only).
    metatraffic: std::sync::Arc<[Locator]>,
    /// What it announced, in our own PL-CDR encoding without the fields kept decoded above and its GUID
    /// (the table's key): `ParticipantData::encode_without_kept`.
    announcement: Box<[u8]>,
    /// The digest of the SPDP payload last received from it (`Participant::announcement_digest`; 0 until
    /// set): a periodic re-announcement that matches is not decoded.
    received: u64,
}

impl ProxyParticipant {
    /// `group`: the metatraffic multicast group it shares with us, if any (kept last in `metatraffic`).
    fn new(data: &ParticipantData, lease_deadline: Instant, group: Option<Locator>) -> Self {
        ProxyParticipant {
            lease_deadline,
            lease_duration: data.lease_duration,
            vendor_id: data.vendor_id,
            builtin_endpoints: data.builtin_endpoints,
            type_lookup_matched: false,
            messages_matched: 0,
            metatraffic: metatraffic(data, group),
            announcement: data.encode_without_kept().into_boxed_slice(),
            received: 0,
        }
    }

    /// What the participant `prefix` (this one) announced. Our own encoding of a decoded announcement
    /// always decodes again; should it not, the fields kept decoded still are.
    fn data(&self, prefix: GuidPrefix) -> ParticipantData {
        ParticipantData {
            guid_prefix: prefix,
            vendor_id: self.vendor_id,
            lease_duration: self.lease_duration,
            builtin_endpoints: self.builtin_endpoints,
            ..ParticipantData::decode_without_kept(&self.announcement).unwrap_or_default()
        }
    }

    /// Takes a new announcement of the same participant (`group`: see [`ProxyParticipant::new`]); whether
    /// anything changed.
    fn update(&mut self, data: &ParticipantData, group: Option<Locator>) -> bool {
        let encoded = data.encode_without_kept();
        if *encoded == *self.announcement
            && (data.vendor_id, data.lease_duration, data.builtin_endpoints)
                == (self.vendor_id, self.lease_duration, self.builtin_endpoints)
        {
            return false;
        }
        *self = ProxyParticipant {
            type_lookup_matched: self.type_lookup_matched,
            messages_matched: self.messages_matched,
            ..ProxyParticipant::new(data, self.lease_deadline, group)
        };
        true
    }
}

/// Where a discovered participant's builtin endpoints listen: one list for all their proxies, the shared
/// multicast `group` last if there is one.
fn metatraffic(data: &ParticipantData, group: Option<Locator>) -> std::sync::Arc<[Locator]> {
    let first = if data.metatraffic_unicast.is_empty() {
        &data.metatraffic_multicast
    } else {
        &data.metatraffic_unicast
    };
    first.iter().copied().chain(group).collect()
}

/// A sans-I/O RTPS participant. See `docs/rtps-core.md`.
#[derive(Debug)]
pub struct Participant {
    config: ParticipantConfig,
    out: Outbox,
    events: VecDeque<Event>,
    /// Leases of matched writers with manual liveliness.
    leases: crate::rtps::liveliness::Leases,
    /// Leases of our own writers with manual liveliness (LIVELINESS_LOST).
    own_leases: super::writer::OwnLeases,
    /// Whether the participant sends and receives (see `enable`).
    enabled: bool,
    /// Local endpoints created disabled, not announced yet.
    deferred: enable::DeferredEndpoints,
    /// Remote topics announced in SEDP (DCPSTopic).
    known_topics: HashMap<Guid, super::discovery::TopicData>,
    /// Reused buffer for what readers deliver while a datagram is processed.
    scratch: Vec<Event>,
    /// Reused by each pass: the participants open messages go to (`timers::reader_timeouts`).
    open_scratch: Vec<(GuidPrefix, Locator)>,
    /// Reusable buffers of received samples (see `pool.rs`).
    rx_pools: crate::rtps::pool::ReceivePools,
    writers: BTreeMap<EntityId, Writer>,
    readers: BTreeMap<EntityId, Reader>,
    /// User endpoints (builtin ones are only in `writers`/`readers`).
    user_writers: BTreeSet<EntityId>,
    user_readers: BTreeSet<EntityId>,
    /// Service-internal endpoints (`internal.rs`).
    internal: BTreeSet<EntityId>,
    /// Local writers that stand in for another (`rtps/writer/stand_in.rs`): the only ones
    /// `original_gone` looks at, so forgetting a remote endpoint costs nothing per local writer.
    stand_ins: BTreeSet<EntityId>,
    /// Boxed: the table keeps spare slots (see `docs/performance.md`, "Footprint").
    participants: HashMap<GuidPrefix, Box<ProxyParticipant>>,
    /// Every known publication and subscription, remote and local (local ones match locally too).
    /// Every known endpoint, local and remote. Boxed: a table slot is then a pointer, not a whole
    /// announcement, which halves the memory per remote endpoint (the table keeps spare slots).
    known_writers: HashMap<Guid, Box<WriterData>>,
    known_readers: HashMap<Guid, Box<ReaderData>>,
    /// (local endpoint, remote endpoint) pairs already reported incompatible.
    incompatible: HashSet<(EntityId, Guid)>,
    next_entity_key: u32,
    spdp_sn: SequenceNumber,
    spdp_payload: Vec<u8>,
    /// Where the periodic announcement goes (`send_spdp`), kept between periods.
    spdp_dest: Vec<Locator>,
    spdp_due: Instant,
    pmd_due: Instant,
    /// Local readers matched with a remote writer, for DATA addressed to any reader (ENTITYID_UNKNOWN). Cleared
    /// whenever a reader gains a writer; ids of readers that lost it are skipped by a `has_proxy` check.
    readers_by_writer: HashMap<Guid, Vec<EntityId>>,
    /// A lower bound on every timer (`None`: unknown), so that traffic does not rescan every endpoint.
    timer_floor: Cell<Option<Instant>>,
    last_full_scan: Instant,
    /// What the application ignores (`ignore_participant`, `ignore_endpoint`, `ignore_topic`).
    ignored: control::Ignored,
    /// The TypeLookup service: the type store, its server and client.
    type_lookup: type_lookup::TypeLookupService,
    /// Pairs of our own endpoints matched for intra-process delivery.
    local: local::LocalMatches,
    /// Pairs of our endpoints and peers' matched over shared memory.
    shm: shm::ShmMatches,
    /// Group coherent sets waiting for the parts of all their writers.
    group_sets: group::GroupSets,
    /// GROUP ordered access: changes held until their group sequence number is next.
    group_order: group_order::GroupOrder,
    /// The QoS and type information shared by the known endpoints.
    interned: interned::Interned,
}

fn builtin_writer_params(c: &ParticipantConfig) -> WriterParams {
    WriterParams {
        reliable: true,
        durability: Durability::TransientLocal,
        history: History::KeepLast(1),
        limits: ResourceLimits::default(),
        keyed: true,
        heartbeat_period: c.heartbeat_period,
        nack_response_delay: c.nack_response_delay,
        fragment_size: c.fragment_size,
        whole_max: c.fragment_size,
        frags_per_submessage: crate::rtps::writer::fragments_per_submessage(
            c.max_message_size,
            c.fragment_size,
        ),
        // Discovery data is never refused.
        high_watermark: usize::MAX,
        low_watermark: usize::MAX,
        max_repair_bytes: c.max_repair_bytes,
        piggyback_heartbeat_bytes: 0,
        lifespan: None,
    }
}

fn user_writer_params(c: &ParticipantConfig, q: &DataWriterQos, keyed: bool) -> WriterParams {
    WriterParams {
        reliable: q.reliability.is_reliable(),
        durability: q.durability,
        history: q.history,
        limits: q.resource_limits,
        keyed,
        heartbeat_period: c.heartbeat_period,
        nack_response_delay: c.nack_response_delay,
        fragment_size: c.fragment_size,
        whole_max: crate::rtps::writer::whole_sample_max(c.max_message_size, c.fragment_size),
        frags_per_submessage: crate::rtps::writer::fragments_per_submessage(
            c.max_message_size,
            c.fragment_size,
        ),
        high_watermark: c.whc_high_watermark.max(1),
        low_watermark: c.whc_low_watermark.min(c.whc_high_watermark),
        max_repair_bytes: c.max_repair_bytes,
        // Batched: about one heartbeat per full datagram rather than one per sample.
        piggyback_heartbeat_bytes: if c.write_batch_delay.is_some() {
            c.max_message_size
        } else {
            0
        },
        lifespan: (q.lifespan.0 < crate::qos::INFINITE).then_some(q.lifespan.0),
    }
}

fn reader_params(c: &ParticipantConfig, reliable: bool) -> ReaderParams {
    ReaderParams {
        reliable,
        heartbeat_response_delay: c.heartbeat_response_delay,
        ack_delay: c.heartbeat_response_delay,
        max_sample_size: c.max_sample_size,
        defrag_max_samples: c.defrag_max_samples.max(1),
        defrag_max_bytes: c.defrag_max_bytes,
        reorder_max_samples: c.reorder_max_samples.max(1),
        reorder_max_bytes: c.reorder_max_bytes,
    }
}

impl Participant {
    /// A participant with its builtin endpoints, announcing itself from `now` on (drain `poll_transmit`).
    pub fn new(mut config: ParticipantConfig, now: Instant) -> Self {
        // Fragments must fit the 16-bit fragmentSize field and leave room for headers in a datagram.
        config.fragment_size = config.fragment_size.clamp(64, 65000);
        let header = Header {
            version: ProtocolVersion::V2_5,
            vendor_id: config.vendor_id,
            guid_prefix: config.guid_prefix,
        };
        let mut p = Participant {
            out: Outbox::new(header, config.max_message_size),
            events: VecDeque::new(),
            leases: Default::default(),
            own_leases: Default::default(),
            enabled: true,
            deferred: Default::default(),
            known_topics: HashMap::new(),
            scratch: Vec::new(),
            open_scratch: Vec::new(),
            rx_pools: Default::default(),
            writers: BTreeMap::new(),
            readers: BTreeMap::new(),
            user_writers: BTreeSet::new(),
            user_readers: BTreeSet::new(),
            internal: BTreeSet::new(),
            stand_ins: BTreeSet::new(),
            participants: HashMap::new(),
            known_writers: HashMap::new(),
            known_readers: HashMap::new(),
            incompatible: HashSet::new(),
            next_entity_key: 1,
            spdp_sn: SequenceNumber(1),
            spdp_payload: Vec::new(),
            spdp_dest: Vec::new(),
            spdp_due: now,
            pmd_due: now,
            readers_by_writer: HashMap::new(),
            timer_floor: Cell::new(None),
            last_full_scan: now,
            ignored: control::Ignored::new(),
            type_lookup: type_lookup::TypeLookupService::new(config.guid_prefix),
            local: Default::default(),
            shm: Default::default(),
            group_sets: group::GroupSets::default(),
            group_order: group_order::GroupOrder::default(),
            interned: Default::default(),
            config,
        };
        let prefix = p.config.guid_prefix;
        p.local.join_process(prefix);
        for (w, _, _) in super::discovery::builtin::WRITER_PAIRS {
            let mut params = builtin_writer_params(&p.config);
            if type_lookup::is_service_endpoint(w) {
                params = type_lookup::writer_params(params);
            }
            p.writers
                .insert(w, Writer::new(Guid::new(prefix, w), params));
        }
        for (r, _, _) in super::discovery::builtin::READER_PAIRS {
            p.readers.insert(
                r,
                Reader::new(Guid::new(prefix, r), reader_params(&p.config, true)),
            );
        }
        p.add_topic_builtins();
        p.spdp_payload = p.participant_data().encode();
        p.service(now);
        p
    }

    /// The configuration it runs with (the fragment size clamped to 64..=65000).
    pub fn config(&self) -> &ParticipantConfig {
        &self.config
    }
    /// Our GUID prefix.
    pub fn guid_prefix(&self) -> GuidPrefix {
        self.config.guid_prefix
    }

    /// What we announce in SPDP.
    pub fn participant_data(&self) -> ParticipantData {
        let c = &self.config;
        ParticipantData {
            guid_prefix: c.guid_prefix,
            protocol_version: ProtocolVersion::V2_5,
            vendor_id: c.vendor_id,
            domain_id: Some(c.domain_id),
            domain_tag: String::new(),
            expects_inline_qos: false,
            metatraffic_unicast: c.metatraffic_unicast.clone(),
            metatraffic_multicast: c.metatraffic_multicast.clone(),
            default_unicast: c.default_unicast.clone(),
            default_multicast: c.default_multicast.clone(),
            lease_duration: c.lease_duration,
            builtin_endpoints: super::discovery::builtin::OURS
                | super::discovery::topics::TOPIC_BITS,
            manual_liveliness_count: 0,
            user_data: c.user_data.clone(),
            properties: c.properties.clone(),
            entity_name: c.entity_name.clone(),
        }
    }

    /// The next datagram to send. Held batched writes are included once their delay has run out.
    pub fn poll_transmit(&mut self, now: Instant) -> Option<Transmit> {
        self.out
            .pop(now, self.config.write_batch_delay.unwrap_or_default())
    }

    /// Releases batched writes at the next [`poll_transmit`](Self::poll_transmit).
    pub fn flush(&mut self) {
        self.out.request_flush();
    }

    /// Gives a sent datagram's buffer back for reuse (optional; saves an allocation per datagram).
    pub fn recycle(&mut self, buf: Vec<u8>) {
        self.out.recycle(buf);
    }

    /// Hands a sent [`Transmit`] back whole: its payload buffer and its destination list are reused for
    /// later datagrams (no allocation per datagram in the steady state).
    pub fn recycle_transmit(&mut self, t: Transmit) {
        self.out.recycle(t.payload);
        self.out.recycle_shared(t.shared);
        self.out.recycle_destinations(t.destinations);
    }

    /// Sends slices of samples of at least `min` bytes (the fragments of large samples) without copying
    /// them: their [`Transmit`]s carry shares of the samples' buffers ([`Transmit::shared`]), for an I/O
    /// layer that sends with scatter-gather. `None` (the default): every datagram is in
    /// [`Transmit::payload`] alone.
    pub fn gather_sends(&mut self, min: Option<usize>) {
        self.out.gather_from(min);
    }

    /// The next event for the DCPS layer, in order.
    pub fn poll_event(&mut self) -> Option<Event> {
        loop {
            let e = self.events.pop_front()?;
            // Builtin writers' flow-control notes are internal.
            if let Event::WriterAcknowledged { writer } | Event::WriterUnblocked { writer } = &e {
                if writer.is_builtin() {
                    continue;
                }
            }
            if self.hides(&e) {
                continue;
            }
            self.note_polled(&e);
            return Some(e);
        }
    }

    /// Runs the work due at `now` (heartbeats, repairs, SPDP, leases, lingering writers, batch deadlines).
    pub fn handle_timeout(&mut self, now: Instant) {
        self.service(now);
    }

    fn alloc_entity(&mut self, kind: u8) -> Result<EntityId, CoreError> {
        if self.next_entity_key >= 1 << 24 {
            return Err(CoreError::OutOfEntityIds);
        }
        let k = self.next_entity_key.to_be_bytes();
        self.next_entity_key += 1;
        Ok(EntityId::new([k[1], k[2], k[3]], kind))
    }

    /// An entity id for a reader that exists only inside this process (an application's reader of a built-in
    /// topic): a built-in reader kind, never announced, from the same counter as the participant's endpoints.
    /// Its key starts with a byte in 0x80..=0xbf, which no built-in entity of RTPS or DDS Security uses.
    pub fn alloc_local_reader_id(&mut self) -> Result<EntityId, CoreError> {
        if self.next_entity_key >= 1 << 22 {
            return Err(CoreError::OutOfEntityIds);
        }
        let k = (self.next_entity_key | 0x80_0000).to_be_bytes();
        self.next_entity_key += 1;
        Ok(EntityId::new([k[1], k[2], k[3]], 0xc7))
    }

    /// Checks a spec and gives the new endpoint an entity id (`kinds`: without key, with key).
    fn new_endpoint<Q>(
        &mut self,
        spec: EndpointSpec<Q>,
        kinds: [u8; 2],
    ) -> Result<EndpointData<Q>, CoreError> {
        self.timers_changed();
        if spec.topic_name.is_empty() || spec.type_name.is_empty() {
            return Err(CoreError::BadParameter("empty topic or type name"));
        }
        let id = self.alloc_entity(kinds[usize::from(spec.keyed)])?;
        let guid = Guid::new(self.config.guid_prefix, id);
        Ok(EndpointData {
            guid,
            participant_guid: Some(Guid::new(guid.prefix, EntityId::PARTICIPANT)),
            topic_name: spec.topic_name,
            type_name: spec.type_name,
            qos: spec.qos.into(),
            unicast_locators: Vec::new(),
            multicast_locators: Vec::new(),
            expects_inline_qos: false,
            type_information: spec.type_information.map(Into::into),
            entity_name: spec.entity_name,
            content_filter: spec.content_filter.map(Box::new),
            group: None,
        })
    }

    /// Creates a local writer and announces it in SEDP; it matches local and remote readers from then on.
    pub fn create_writer(&mut self, now: Instant, spec: WriterSpec) -> Result<EntityId, CoreError> {
        let data = self.add_writer(spec)?;
        let id = data.guid.entity_id;
        self.track_own_lease(now, id, &data.qos.writer.liveliness);
        self.publish_endpoint(now, data);
        Ok(id)
    }

    /// Adds a local writer, not yet announced.
    fn add_writer(&mut self, spec: WriterSpec) -> Result<WriterData, CoreError> {
        let keyed = spec.keyed;
        let internal = spec.internal;
        let kinds = [
            entity_kind::USER_WRITER_NO_KEY,
            entity_kind::USER_WRITER_WITH_KEY,
        ];
        let mut spec = spec;
        local::inherit(&mut spec.qos.writer.ignore_local, self.config.ignore_local);
        let data = self.new_endpoint(spec, kinds)?;
        let id = data.guid.entity_id;
        local::note_ignore_local(data.guid, data.qos.writer.ignore_local);
        let params = user_writer_params(&self.config, &data.qos.writer, keyed);
        let mut writer = Writer::new(data.guid, params);
        if let Some(original) = internal
            .then(|| crate::rtps::writer::stand_in_for(&data.qos.writer.user_data.0))
            .flatten()
        {
            writer.stand_in_for(original);
            self.stand_ins.insert(id);
        }
        self.writers.insert(id, writer);
        self.user_writers.insert(id);
        if internal {
            self.mark_internal(id);
        }
        Ok(data)
    }

    /// Creates a local reader and announces it in SEDP; it matches local and remote writers from then on.
    pub fn create_reader(&mut self, now: Instant, spec: ReaderSpec) -> Result<EntityId, CoreError> {
        let data = self.add_reader(spec)?;
        let id = data.guid.entity_id;
        self.publish_endpoint(now, data);
        Ok(id)
    }

    /// Adds a local reader, not yet announced.
    fn add_reader(&mut self, spec: ReaderSpec) -> Result<ReaderData, CoreError> {
        let kinds = [
            entity_kind::USER_READER_NO_KEY,
            entity_kind::USER_READER_WITH_KEY,
        ];
        let internal = spec.internal;
        let mut spec = spec;
        local::inherit(&mut spec.qos.reader.ignore_local, self.config.ignore_local);
        let data = self.new_endpoint(spec, kinds)?;
        let id = data.guid.entity_id;
        local::note_ignore_local(data.guid, data.qos.reader.ignore_local);
        let reliable = data.qos.reader.reliability.is_reliable();
        let params = reader_params(&self.config, reliable);
        self.readers.insert(id, Reader::new(data.guid, params));
        self.user_readers.insert(id);
        if internal {
            self.mark_internal(id);
        }
        Ok(data)
    }

    /// Deletes a writer. A reliable writer with unacknowledged data lingers (still repairing, refusing writes)
    /// until acknowledged or `writer_linger_duration` passes; then `Event::WriterDeleted`.
    pub fn delete_writer(&mut self, now: Instant, id: EntityId) {
        self.timers_changed();
        if self.drop_deferred(id) {
            return;
        }
        if !self.user_writers.contains(&id) {
            return;
        }
        let Some(w) = self.writers.get_mut(&id) else {
            return;
        };
        if w.linger_until.is_some() {
            return;
        }
        self.own_leases.untrack(id);
        if w.is_acknowledged() {
            self.finish_writer(now, id);
        } else {
            w.linger_until = Some(now + self.config.writer_linger_duration);
        }
        self.service(now);
    }

    /// Deletes a reader at once: unmatch events and an SEDP dispose.
    pub fn delete_reader(&mut self, now: Instant, id: EntityId) {
        self.timers_changed();
        if self.drop_deferred(id) {
            return;
        }
        if !self.user_readers.remove(&id) {
            return;
        }
        let guid = Guid::new(self.config.guid_prefix, id);
        if let Some(r) = self.readers.remove(&id) {
            for w in r.matched() {
                self.events.push_back(Event::SubscriptionMatched {
                    reader: id,
                    writer: *w,
                    matched: false,
                });
            }
        }
        self.announce(
            now,
            EntityId::SEDP_SUBSCRIPTIONS_WRITER,
            guid,
            ChangeKind::DisposeUnregister,
            Vec::new(),
        );
        self.forget_endpoint::<ReaderQos>(guid);
        self.forget_shm_endpoint(id);
        self.events.push_back(Event::ReaderDeleted { reader: id });
        self.service(now);
    }

    fn finish_writer(&mut self, now: Instant, id: EntityId) {
        self.user_writers.remove(&id);
        self.own_leases.untrack(id);
        let guid = Guid::new(self.config.guid_prefix, id);
        self.original_gone(guid);
        if let Some(w) = self.writers.remove(&id) {
            for r in w.matched() {
                self.events.push_back(Event::PublicationMatched {
                    writer: id,
                    reader: *r,
                    matched: false,
                });
            }
        }
        self.announce(
            now,
            EntityId::SEDP_PUBLICATIONS_WRITER,
            guid,
            ChangeKind::DisposeUnregister,
            Vec::new(),
        );
        self.forget_endpoint::<WriterQos>(guid);
        self.forget_shm_endpoint(id);
        self.events.push_back(Event::WriterDeleted { writer: id });
    }

    /// Queues one change of a user writer. `Err(WouldBlock)` when flow control or KEEP_ALL resource limits
    /// refuse it: call again after acknowledgements arrive ([`Event::WriterUnblocked`]).
    pub fn write(
        &mut self,
        now: Instant,
        writer: EntityId,
        change: WriteChange,
    ) -> Result<SequenceNumber, WriteError> {
        self.write_filtered(now, writer, change, Vec::new())
    }

    /// Whether every matched reliable reader acknowledged everything the writer wrote (true for unknown ids).
    pub fn is_acknowledged(&self, writer: EntityId) -> bool {
        self.writers
            .get(&writer)
            .is_none_or(|w| w.is_acknowledged())
    }

    /// Bytes written but not yet acknowledged by every reliable reader (what flow control looks at).
    pub fn unacknowledged_bytes(&self, writer: EntityId) -> usize {
        self.writers.get(&writer).map_or(0, |w| w.unacked_bytes())
    }

    /// The readers a local user writer is matched with.
    pub fn writer_matches(&self, writer: EntityId) -> Vec<Guid> {
        if !self.user_writers.contains(&writer) {
            return Vec::new();
        }
        let prefix = self.config.guid_prefix;
        let local = self.local_readers(writer).iter();
        self.writers
            .get(&writer)
            .map(|w| w.matched().copied())
            .into_iter()
            .flatten()
            .chain(local.map(|r| Guid::new(prefix, *r)))
            .chain(self.shm_readers(writer).iter().copied())
            .collect()
    }

    /// Back-pressure for a reliable reader: it delivers at most `credit` more changes (`None`: no limit)
    /// until the next call. A change beyond the credit is not acknowledged; the writer repairs it once
    /// credit is given back. Held changes that now fit are delivered (drain `poll_event`).
    pub fn set_reader_credit(&mut self, reader: EntityId, credit: Option<usize>) {
        self.timers_changed();
        if let Some(r) = self.readers.get_mut(&reader) {
            let mut out = Vec::new();
            r.set_credit(credit, &mut out);
            out.into_iter().for_each(|e| self.push_delivery(e));
        }
    }

    /// The writers a local user reader is matched with.
    pub fn reader_matches(&self, reader: EntityId) -> Vec<Guid> {
        if !self.user_readers.contains(&reader) {
            return Vec::new();
        }
        let prefix = self.config.guid_prefix;
        let local = self.local_writers_of(reader).map(|w| Guid::new(prefix, w));
        self.readers
            .get(&reader)
            .map(|r| r.matched().copied())
            .into_iter()
            .flatten()
            .chain(local)
            .chain(self.shm_writers_of(reader))
            .collect()
    }

    /// Discovered remote participants.
    /// Decoded on each call: the core keeps them compact (see `docs/performance.md`, "Footprint").
    pub fn discovered_participants(&self) -> impl Iterator<Item = ParticipantData> + '_ {
        self.participants.iter().map(|(k, p)| p.data(*k))
    }

    /// A known publication (remote or local), e.g. for ownership strength or builtin topics.
    pub fn publication(&self, guid: &Guid) -> Option<&WriterData> {
        self.known_writers.get(guid).map(Box::as_ref)
    }
    /// A known subscription (remote or local).
    pub fn subscription(&self, guid: &Guid) -> Option<&ReaderData> {
        self.known_readers.get(guid).map(Box::as_ref)
    }

    /// Announces our departure: SPDP dispose to everyone, so peers drop us without waiting for the lease.
    /// Drain `poll_transmit` afterwards.
    pub fn shutdown(&mut self, _now: Instant) {
        self.timers_changed();
        self.send_spdp_dispose();
    }
}
