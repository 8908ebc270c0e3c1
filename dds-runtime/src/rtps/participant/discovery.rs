//! SPDP and SEDP processing, builtin endpoint wiring, and matching of user endpoints.

use std::sync::Arc;
use std::time::Instant;

use foldhash::HashMap;
use tracing::{debug, trace};

use super::interned::SharedQos;
use super::{Participant, ProxyParticipant};
use crate::qos::{Durability, QosPolicyId, ReaderQos, WriterQos};
use crate::rtps::api::{ChangeKind, Event, ReceivedSample, WriteChange};
use crate::rtps::discovery::matching::{match_endpoints_with, MatchResult};
use crate::rtps::discovery::{builtin, EndpointData, EndpointQos, ParticipantData};
use crate::rtps::messages::parameter::pid;
use crate::rtps::messages::Data;
use crate::rtps::reader::WriterProxy;
use crate::rtps::types::*;
use crate::rtps::writer::ReaderProxy;
use crate::xtypes::assign::{local_types, TypeResolver};
use crate::xtypes::typeobject::TypeIdentifier;

/// Upper bound on remote participants and endpoints, so discovery traffic cannot exhaust memory.
const MAX_PARTICIPANTS: usize = 4096;
const MAX_ENDPOINTS: usize = 65536;

impl Participant {
    pub(super) fn refresh_lease(&mut self, now: Instant, prefix: GuidPrefix) {
        if let Some(p) = self.participants.get_mut(&prefix) {
            p.lease_deadline = now + p.lease_duration;
        }
    }

    /// Writes a SEDP announcement (or its dispose) for a local endpoint.
    pub(super) fn announce(
        &mut self,
        now: Instant,
        sedp_writer: EntityId,
        guid: Guid,
        kind: ChangeKind,
        payload: Vec<u8>,
    ) {
        let payload = if kind == ChangeKind::Alive {
            payload
        } else {
            crate::rtps::discovery::encode_endpoint_key(&guid)
        };
        let change = WriteChange {
            kind,
            payload: payload.into(),
            key_hash: Some(guid.to_bytes()),
            source_timestamp: None,
        };
        if let Some(w) = self.writers.get_mut(&sedp_writer) {
            let _ = w.write(now, change, &mut self.out, &mut self.events);
        }
    }

    pub(super) fn on_spdp(&mut self, now: Instant, src: GuidPrefix, d: &Data<'_>) {
        let status = d.inline_qos.and_then(|q| q.status_info()).unwrap_or(0);
        if ChangeKind::from_status_info(status) != ChangeKind::Alive {
            let guid = d
                .inline_qos
                .and_then(|q| q.key_hash())
                .map(|k| Guid::from_bytes(k).prefix)
                .or_else(|| d.payload.and_then(spdp_key_prefix))
                .unwrap_or(src);
            if self.participants.contains_key(&guid) {
                debug!(participant = ?guid, "participant left");
                self.remove_participant(guid);
            }
            return;
        }
        let Some(payload) = d.payload else { return };
        if src == self.config.guid_prefix {
            return; // our own, looped back by multicast
        }
        // The periodic re-announcement of a known participant, byte for byte what it sent last: its lease
        // is renewed (by the message, `receive`) and nothing else changes. Checked before decoding, so
        // that the common case allocates nothing.
        let digest = self.announcement_digest(payload);
        if self
            .participants
            .get(&src)
            .is_some_and(|p| p.received == digest)
        {
            return;
        }
        let data = match ParticipantData::decode(payload) {
            Ok(x) => x,
            Err(e) => {
                debug!(error = %e, "dropping SPDP sample");
                return;
            }
        };
        if data.guid_prefix == self.config.guid_prefix
            || self.ignored.participant(&data.guid_prefix)
        {
            return;
        }
        if data.domain_id.is_some_and(|d| d != self.config.domain_id) || !data.domain_tag.is_empty()
        {
            trace!(participant = ?data.guid_prefix, "SPDP from another domain");
            return;
        }
        let lease_deadline = now + data.lease_duration;
        let group = self.shared_metatraffic_group(&data);
        if let Some(p) = self.participants.get_mut(&data.guid_prefix) {
            p.lease_deadline = lease_deadline;
            p.update(&data, group);
            p.received = digest;
            return;
        }
        if self.participants.len() >= MAX_PARTICIPANTS {
            return;
        }
        let prefix = data.guid_prefix;
        debug!(participant = ?prefix, vendor = ?data.vendor_id, "participant discovered");
        let mut proxy = Box::new(ProxyParticipant::new(&data, lease_deadline, group));
        proxy.received = digest;
        // One list for all the proxies of its builtin endpoints (the group last).
        let meta = proxy.metatraffic.clone();
        let bits = data.builtin_endpoints;
        self.events
            .push_back(Event::ParticipantDiscovered(Box::new(data)));
        self.participants.insert(prefix, proxy);
        // The TypeLookup endpoints are matched when a request or reply is first exchanged with it, the
        // participant-message ones when a message is (see `match_messages`).
        let pairs = |ours: EntityId| {
            !super::type_lookup::is_service_endpoint(ours)
                && !super::liveliness::is_message_endpoint(ours)
        };
        self.match_builtin_pairs(now, prefix, bits, &meta, group, pairs);
        if self.messages_written() {
            self.match_messages(now, prefix, super::liveliness::MESSAGES_OUT);
        }
        self.match_topic_builtins(now, prefix, bits, &meta, group);
        // Answer directly so the newcomer need not wait for our next periodic announcement.
        if !meta.is_empty() {
            self.send_spdp(Some(meta[..1].to_vec()));
        }
    }

    /// A keyed 64-bit digest of a received SPDP payload (the participant table's own random hasher), to
    /// recognise a repeated announcement without decoding or keeping it: equal digests are taken for equal
    /// bytes. A peer that forged a collision could only keep its own earlier announcement in force (the
    /// look-up is by the sender's prefix, and equal bytes decode to the same participant).
    fn announcement_digest(&self, payload: &[u8]) -> u64 {
        use std::hash::BuildHasher;
        self.participants.hasher().hash_one(payload)
    }

    /// Matches those builtin endpoints of ours that `which` selects with the ones the participant `prefix`
    /// announces in `bits`, at `meta` (its metatraffic locators, with `group` last when there is one).
    /// `group`: see [`Self::shared_metatraffic_group`]; `None` for endpoints addressed to one participant
    /// (their proxies then use the first locator only).
    pub(super) fn match_builtin_pairs(
        &mut self,
        now: Instant,
        prefix: GuidPrefix,
        bits: u32,
        meta: &Arc<[Locator]>,
        group: Option<Locator>,
        which: impl Fn(EntityId) -> bool,
    ) {
        for (ours, theirs, bit) in builtin::WRITER_PAIRS {
            if bits & bit != 0 && which(ours) {
                if let Some(w) = self.writers.get_mut(&ours) {
                    let proxy = ReaderProxy::new(Guid::new(prefix, theirs), meta.clone(), true)
                        .with_multicast_last(group.is_some());
                    w.add_proxy(now, proxy, true, &mut self.events);
                }
            }
        }
        for (ours, theirs, bit) in builtin::READER_PAIRS {
            if bits & bit != 0 && which(ours) {
                if let Some(r) = self.readers.get_mut(&ours) {
                    r.add_proxy(
                        now,
                        WriterProxy::new(Guid::new(prefix, theirs), meta.clone(), true),
                    );
                    self.readers_by_writer.clear();
                }
            }
        }
    }

    /// The shared group a discovered participant's metatraffic list `meta` ends with, if any (see
    /// `ProxyParticipant::metatraffic`): its last entry when that is one of our metatraffic multicast
    /// locators (it is the group then: without a group, such a locator would have been chosen as one).
    pub(super) fn metatraffic_group(&self, meta: &[Locator]) -> Option<Locator> {
        meta.last()
            .filter(|l| l.is_multicast() && self.config.metatraffic_multicast.contains(l))
            .copied()
    }

    /// The metatraffic multicast group a discovered participant shares with us, if any. Our SEDP (topics,
    /// publications, subscriptions) and participant-message writers send new announcements and periodic
    /// heartbeats there once two or more participants' readers share it (`Writer::choose_multicast`): one
    /// datagram instead of one per participant, as SPDP itself does. Repairs stay unicast; TypeLookup,
    /// addressed to one participant, too.
    fn shared_metatraffic_group(&self, data: &ParticipantData) -> Option<Locator> {
        data.metatraffic_multicast
            .iter()
            .find(|l| l.is_multicast() && self.config.metatraffic_multicast.contains(l))
            .copied()
    }

    pub(super) fn remove_participant(&mut self, prefix: GuidPrefix) {
        if self.participants.remove(&prefix).is_none() {
            return;
        }
        self.readers_by_writer.retain(|w, _| w.prefix != prefix);
        self.forget_topics_of(prefix);
        self.forget_group_sets(&prefix);
        self.forget_group_order(&prefix);
        for (ours, theirs, _) in builtin::WRITER_PAIRS {
            if let Some(w) = self.writers.get_mut(&ours) {
                w.remove_proxy(&Guid::new(prefix, theirs), &mut self.events);
            }
        }
        for (ours, theirs, _) in builtin::READER_PAIRS {
            if let Some(r) = self.readers.get_mut(&ours) {
                r.remove_proxy(&Guid::new(prefix, theirs));
            }
        }
        let writers: Vec<Guid> = self
            .known_writers
            .keys()
            .filter(|g| g.prefix == prefix)
            .copied()
            .collect();
        for g in writers {
            for (id, r) in self
                .readers
                .iter()
                .filter(|(id, _)| self.user_readers.contains(id))
            {
                if r.has_proxy(&g) {
                    self.events.push_back(Event::LivelinessChanged {
                        reader: *id,
                        writer: g,
                        alive: false,
                    });
                }
            }
            self.forget_endpoint::<WriterQos>(g);
            self.events.push_back(Event::PublicationRemoved { guid: g });
        }
        let readers: Vec<Guid> = self
            .known_readers
            .keys()
            .filter(|g| g.prefix == prefix)
            .copied()
            .collect();
        for g in readers {
            self.forget_endpoint::<ReaderQos>(g);
            self.events
                .push_back(Event::SubscriptionRemoved { guid: g });
        }
        self.incompatible.retain(|(_, g)| g.prefix != prefix);
        self.events.push_back(Event::ParticipantLost {
            guid_prefix: prefix,
        });
    }

    pub(super) fn on_builtin_sample(&mut self, now: Instant, s: ReceivedSample) {
        match s.reader {
            EntityId::SEDP_PUBLICATIONS_READER => self.on_sedp::<WriterQos>(now, &s),
            EntityId::SEDP_SUBSCRIPTIONS_READER => self.on_sedp::<ReaderQos>(now, &s),
            EntityId::TYPELOOKUP_REQUEST_READER => self.on_type_lookup_request(now, &s),
            EntityId::TYPELOOKUP_REPLY_READER => self.on_type_lookup_reply(now, &s),
            EntityId::SEDP_TOPICS_READER => self.on_sedp_topic(&s),
            EntityId::P2P_MESSAGE_READER => {
                if let Some((prefix, kind)) = builtin::decode_participant_message(&s.payload) {
                    if prefix == s.writer.prefix {
                        self.refresh_lease(now, prefix);
                        self.participant_message(now, s.writer, kind);
                    }
                }
            }
            _ => {}
        }
    }

    /// An SEDP sample of direction `Q`: a new or changed announcement, or a dispose.
    fn on_sedp<Q: Direction>(&mut self, now: Instant, s: &ReceivedSample) {
        if s.kind != ChangeKind::Alive {
            if let Some(g) = endpoint_of(s) {
                if g.prefix == s.writer.prefix && Q::known(self).contains_key(&g) {
                    self.forget_endpoint::<Q>(g);
                    self.events.push_back(Q::removed(g));
                }
            }
            return;
        }
        match EndpointData::<Q>::decode(&s.payload) {
            Ok(d) if self.ignored.endpoint(&d.guid, &d.topic_name) => {
                trace!(endpoint = ?d.guid, "ignored SEDP announcement dropped");
            }
            Ok(mut d) if d.guid.prefix == s.writer.prefix => {
                self.interned.share(&mut d);
                let known = Q::known(self);
                let new = !known.contains_key(&d.guid);
                if !new || known.len() < MAX_ENDPOINTS {
                    // New, or announced again with another QoS (`set_qos`): reported either way.
                    if known.get(&d.guid).map(Box::as_ref) != Some(&d) {
                        self.events.push_back(Q::discovered(d.clone()));
                        self.want_announced_types(now, d.type_information.as_deref());
                    }
                    self.on_endpoint_known(now, d);
                }
            }
            Ok(_) => debug!(
                direction = Q::NAME,
                "SEDP announcement for another participant's endpoint ignored"
            ),
            Err(e) => debug!(direction = Q::NAME, error = %e, "dropping SEDP announcement"),
        }
    }

    /// Where to reach a known endpoint: its own unicast locators, else its participant's defaults.
    fn endpoint_locators<Q>(&self, d: &EndpointData<Q>) -> Vec<Locator> {
        let (prefix, uc, mc) = (d.guid.prefix, &d.unicast_locators, &d.multicast_locators);
        if !uc.is_empty() {
            return uc.to_vec();
        }
        if prefix == self.config.guid_prefix {
            return self.config.default_unicast.clone();
        }
        if let Some(p) = self.participants.get(&prefix) {
            let p = p.data(prefix);
            if !p.default_unicast.is_empty() {
                return p.default_unicast;
            }
            if !mc.is_empty() {
                return mc.to_vec();
            }
            return p.default_multicast;
        }
        mc.to_vec()
    }

    /// A multicast locator a known reader listens on, when multicast user data is on: its own multicast
    /// locators first, else its participant's defaults; only of the address family we send with.
    fn endpoint_multicast<Q>(&self, d: &EndpointData<Q>) -> Option<Locator> {
        if !self.config.multicast_data {
            return None;
        }
        let kind = self.config.default_unicast.first()?.kind;
        let usable = |l: &&Locator| l.kind == kind && l.is_multicast();
        if let Some(l) = d.multicast_locators.iter().find(usable) {
            return Some(*l);
        }
        if d.guid.prefix == self.config.guid_prefix {
            return self.config.default_multicast.iter().find(usable).copied();
        }
        let p = self.participants.get(&d.guid.prefix)?.data(d.guid.prefix);
        p.default_multicast.iter().find(usable).copied()
    }

    /// Announces a new local endpoint in SEDP and matches it.
    pub(super) fn publish_endpoint<Q: Direction>(&mut self, now: Instant, mut d: EndpointData<Q>) {
        self.interned.share(&mut d);
        self.announce(now, Q::ANNOUNCER, d.guid, ChangeKind::Alive, d.encode());
        // Local endpoints are reported as remote ones are (the DCPS services watch both).
        self.events.push_back(Q::discovered(d.clone()));
        self.on_endpoint_known(now, d);
        self.service(now);
    }

    /// An endpoint appeared or changed: (re)match it with every local endpoint of the other direction, and
    /// a local one also with every known endpoint of the other direction.
    fn on_endpoint_known<Q: Direction>(&mut self, now: Instant, d: EndpointData<Q>) {
        let guid = d.guid;
        Q::known_mut(self).insert(guid, Box::new(d));
        for local in Q::local_peers(self) {
            self.rematch(now, local, guid);
        }
        if guid.prefix == self.config.guid_prefix {
            for remote in Q::known_peers(self) {
                self.rematch(now, Q::local(guid.entity_id), remote);
            }
        }
    }

    /// Re-evaluates every match between a local endpoint and a peer's endpoint that announces type
    /// information: called when types arrive through TypeLookup, so that a pair matched (or refused) by type
    /// name while the peer's type was unresolved is decided by assignability, as if the type had been known
    /// from the start (a match that no longer holds is unmatched and reported incompatible).
    pub(super) fn rematch_typed(&mut self, now: Instant) {
        self.rematch_typed_of::<WriterQos>(now);
        self.rematch_typed_of::<ReaderQos>(now);
    }

    fn rematch_typed_of<Q: Direction>(&mut self, now: Instant) {
        let own = self.config.guid_prefix;
        let typed: Vec<Guid> = Q::known(self)
            .iter()
            .filter(|(g, d)| g.prefix != own && d.type_information.is_some())
            .map(|(g, _)| *g)
            .collect();
        if typed.is_empty() {
            return;
        }
        let locals = Q::local_peers(self);
        for remote in typed {
            for &local in &locals {
                self.rematch(now, local, remote);
            }
        }
    }

    /// Matches (or unmatches) one local endpoint with one known endpoint of the other direction, and reports
    /// what changed.
    fn rematch(&mut self, now: Instant, local: Local, remote: Guid) {
        let ours = |id| Guid::new(self.config.guid_prefix, id);
        let (wguid, rguid) = match local {
            Local::Writer(id) => (ours(id), remote),
            Local::Reader(id) => (remote, ours(id)),
        };
        let (Some(wd), Some(rd)) = (
            self.known_writers.get(&wguid),
            self.known_readers.get(&rguid),
        ) else {
            return;
        };
        // Assignability resolves types from this participant's store (ours, and peers' types learnt through
        // TypeLookup), then from the process's own types.
        let store = self.type_store();
        let types = |id: &TypeIdentifier| store.get(id).or_else(|| local_types().resolve(id));
        let res = if super::local::ignores_local(wd, rd) {
            MatchResult::Unrelated
        } else {
            match_endpoints_with(wd, rd, &types)
        };
        let Some(has) = self.has_proxy(local, remote) else {
            return;
        };
        match res {
            MatchResult::Match => {
                if !has {
                    self.add_proxy(now, local, remote);
                    self.events.push_back(local.matched(remote, true));
                } else if let Local::Writer(id) = local {
                    self.refresh_reader_filter(id, remote);
                }
                self.incompatible.remove(&(local.id(), remote));
            }
            other => {
                if has && self.remove_proxy(local, remote) {
                    self.events.push_back(local.matched(remote, false));
                }
                if let MatchResult::Incompatible(policy) = other {
                    if self.incompatible.insert((local.id(), remote)) {
                        self.events.push_back(local.incompatible(remote, policy));
                    }
                }
            }
        }
    }

    /// Whether `local` already has a proxy for `remote`; `None` when it cannot match (gone or lingering).
    fn has_proxy(&self, local: Local, remote: Guid) -> Option<bool> {
        let wire = match local {
            Local::Writer(id) => self
                .writers
                .get(&id)
                .filter(|w| w.linger_until.is_none())
                .map(|w| w.has_proxy(&remote)),
            Local::Reader(id) => self.readers.get(&id).map(|r| r.has_proxy(&remote)),
        };
        wire.map(|has| has || self.has_local_match(local, remote))
    }

    /// Gives `local` a proxy for the known endpoint `remote`.
    fn add_proxy(&mut self, now: Instant, local: Local, remote: Guid) {
        if self.add_local_match(now, local, remote) {
            return;
        }
        match local {
            Local::Writer(id) => {
                let Some(rd) = self.known_readers.get(&remote) else {
                    return;
                };
                let reliable = rd.qos.reader.reliability.is_reliable();
                let durable = rd.qos.reader.durability >= Durability::TransientLocal;
                let locators = self.endpoint_locators(rd);
                let multicast = self.endpoint_multicast(rd);
                // The reader's implementation decides some wire forms (see `ReaderProxy::for_vendor`); our
                // own readers are not in `participants`.
                let vendor = self
                    .participants
                    .get(&remote.prefix)
                    .map_or(VendorId::THIS, |p| p.vendor_id);
                let hold = self.original_serves(id, rd, vendor);
                if let Some(w) = self.writers.get_mut(&id) {
                    if hold {
                        w.hold_next(remote);
                    }
                    let proxy = ReaderProxy::new(remote, locators, reliable)
                        .with_multicast(multicast)
                        .for_vendor(vendor);
                    w.add_proxy(now, proxy, durable, &mut self.events);
                }
                self.refresh_reader_filter(id, remote);
            }
            Local::Reader(id) => {
                let Some(wd) = self.known_writers.get(&remote) else {
                    return;
                };
                let reliable = wd.qos.writer.reliability.is_reliable();
                let liveliness = wd.qos.writer.liveliness;
                let locators = self.endpoint_locators(wd);
                // One of our volatile writers owes a new reader nothing, and says so with its first DATA
                // or HEARTBEAT: no pre-emptive ACKNACK, which at scale is one submessage per match
                // (docs/performance.md, "Scale"). Other implementations' writers may wait for one.
                let ours = self
                    .participants
                    .get(&remote.prefix)
                    .is_none_or(|p| p.vendor_id == VendorId::THIS);
                let preemptive = !ours || wd.qos.writer.durability >= Durability::TransientLocal;
                if let Some(r) = self.readers.get_mut(&id) {
                    let proxy = WriterProxy::new(remote, locators, reliable);
                    r.add_proxy_with(now, proxy, preemptive);
                    self.readers_by_writer.clear();
                    self.track_liveliness(now, remote, id, &liveliness);
                }
            }
        }
    }

    /// Removes `local`'s proxy for `remote`; whether it had one.
    fn remove_proxy(&mut self, local: Local, remote: Guid) -> bool {
        if self.remove_local_match(local, remote) {
            return true;
        }
        match local {
            Local::Writer(id) => self
                .writers
                .get_mut(&id)
                .is_some_and(|w| w.remove_proxy(&remote, &mut self.events)),
            Local::Reader(id) => {
                self.untrack_liveliness(&remote, id);
                self.readers
                    .get_mut(&id)
                    .is_some_and(|r| r.remove_proxy(&remote))
            }
        }
    }

    /// A known endpoint of direction `Q` is gone: unmatch it from every local endpoint of the other direction.
    pub(super) fn forget_endpoint<Q: Direction>(&mut self, g: Guid) {
        self.original_gone(g);
        Q::known_mut(self).remove(&g);
        self.readers_by_writer.remove(&g);
        for local in Q::local_peers(self) {
            if self.remove_proxy(local, g) {
                self.events.push_back(local.matched(g, false));
            }
        }
        self.incompatible.retain(|(_, x)| *x != g);
    }
}

/// The endpoint GUID of a SEDP dispose/unregister: the key hash (the GUID itself) or the key payload.
fn endpoint_of(s: &ReceivedSample) -> Option<Guid> {
    s.key_hash
        .map(Guid::from_bytes)
        .or_else(|| crate::rtps::discovery::endpoint_guid_of(&s.payload))
}

/// The participant prefix in an SPDP key-only payload.
fn spdp_key_prefix(payload: &[u8]) -> Option<GuidPrefix> {
    let pl = crate::rtps::discovery::pl_payload(payload).ok()?;
    let v = pl.get(pid::PARTICIPANT_GUID)?;
    pl.cursor(v).guid().ok().map(|g| g.prefix)
}

/// A local user endpoint, seen from matching.
#[derive(Debug, Clone, Copy)]
pub(super) enum Local {
    Writer(EntityId),
    Reader(EntityId),
}

impl Local {
    fn id(self) -> EntityId {
        match self {
            Local::Writer(id) | Local::Reader(id) => id,
        }
    }

    /// The matched-status event for this endpoint and `remote`.
    fn matched(self, remote: Guid, matched: bool) -> Event {
        match self {
            Local::Writer(writer) => Event::PublicationMatched {
                writer,
                reader: remote,
                matched,
            },
            Local::Reader(reader) => Event::SubscriptionMatched {
                reader,
                writer: remote,
                matched,
            },
        }
    }

    /// The incompatible-QoS event (offered for writers, requested for readers).
    fn incompatible(self, remote: Guid, policy: QosPolicyId) -> Event {
        match self {
            Local::Writer(writer) => Event::OfferedIncompatibleQos {
                writer,
                reader: remote,
                policy,
            },
            Local::Reader(reader) => Event::RequestedIncompatibleQos {
                reader,
                writer: remote,
                policy,
            },
        }
    }
}

/// What the participant keeps apart for each SEDP direction (publications, subscriptions).
pub(super) trait Direction: EndpointQos + SharedQos + Clone {
    /// For logs.
    const NAME: &'static str;
    /// Our SEDP writer that announces local endpoints of this direction.
    const ANNOUNCER: EntityId;
    /// Known endpoints of this direction, remote and local.
    fn known(p: &Participant) -> &HashMap<Guid, Box<EndpointData<Self>>>;
    /// Known endpoints of this direction, for changes.
    fn known_mut(p: &mut Participant) -> &mut HashMap<Guid, Box<EndpointData<Self>>>;
    /// A local endpoint of this direction.
    fn local(id: EntityId) -> Local;
    /// Local endpoints of the other direction.
    fn local_peers(p: &Participant) -> Vec<Local>;
    /// Known endpoints of the other direction.
    fn known_peers(p: &Participant) -> Vec<Guid>;
    /// The discovery event for a new endpoint.
    fn discovered(d: EndpointData<Self>) -> Event;
    /// The event for an endpoint that is gone.
    fn removed(guid: Guid) -> Event;
}

impl Direction for WriterQos {
    const NAME: &'static str = "publication";
    const ANNOUNCER: EntityId = EntityId::SEDP_PUBLICATIONS_WRITER;
    fn known(p: &Participant) -> &HashMap<Guid, Box<EndpointData<Self>>> {
        &p.known_writers
    }
    fn known_mut(p: &mut Participant) -> &mut HashMap<Guid, Box<EndpointData<Self>>> {
        &mut p.known_writers
    }
    fn local(id: EntityId) -> Local {
        Local::Writer(id)
    }
    fn local_peers(p: &Participant) -> Vec<Local> {
        p.user_readers.iter().map(|&id| Local::Reader(id)).collect()
    }
    fn known_peers(p: &Participant) -> Vec<Guid> {
        p.known_readers.keys().copied().collect()
    }
    fn discovered(d: EndpointData<Self>) -> Event {
        Event::PublicationDiscovered(Box::new(d))
    }
    fn removed(guid: Guid) -> Event {
        Event::PublicationRemoved { guid }
    }
}

impl Direction for ReaderQos {
    const NAME: &'static str = "subscription";
    const ANNOUNCER: EntityId = EntityId::SEDP_SUBSCRIPTIONS_WRITER;
    fn known(p: &Participant) -> &HashMap<Guid, Box<EndpointData<Self>>> {
        &p.known_readers
    }
    fn known_mut(p: &mut Participant) -> &mut HashMap<Guid, Box<EndpointData<Self>>> {
        &mut p.known_readers
    }
    fn local(id: EntityId) -> Local {
        Local::Reader(id)
    }
    fn local_peers(p: &Participant) -> Vec<Local> {
        p.user_writers.iter().map(|&id| Local::Writer(id)).collect()
    }
    fn known_peers(p: &Participant) -> Vec<Guid> {
        p.known_writers.keys().copied().collect()
    }
    fn discovered(d: EndpointData<Self>) -> Event {
        Event::SubscriptionDiscovered(Box::new(d))
    }
    fn removed(guid: Guid) -> Event {
        Event::SubscriptionRemoved { guid }
    }
}
