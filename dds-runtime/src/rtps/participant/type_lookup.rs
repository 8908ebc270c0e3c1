//! The TypeLookup service in the participant: the four built-in endpoints carry the messages of
//! [`crate::xtypes::typelookup`]; the participant owns the [`TypeStore`], answers requests from it, and asks
//! for the types that remote endpoints announce and the store lacks.

use std::time::Instant;

use tracing::{debug, trace};

use super::{Participant, WriterParams};
use crate::qos::{Durability, History, ResourceLimits};
use crate::rtps::api::{ReceivedSample, WriteChange};
use crate::rtps::types::{EntityId, Guid, GuidPrefix};
use crate::xtypes::store::{StoreLimits, TypeStore};
use crate::xtypes::typelookup::{self, Client, ClientLimits, Server, ServerLimits};
use crate::xtypes::typeobject::{self, TypeIdentifier};

/// Replies (or requests) a service writer keeps for repair: a volatile KEEP_LAST history, so a peer that
/// stops acknowledging cannot make it grow.
const HISTORY_DEPTH: u32 = 64;

/// The participant's side of the service: its type store, server and client.
#[derive(Debug)]
pub(super) struct TypeLookupService {
    store: TypeStore,
    server: Server,
    client: Client,
}

impl TypeLookupService {
    pub(super) fn new(prefix: GuidPrefix) -> Self {
        TypeLookupService {
            store: TypeStore::new(StoreLimits::default()),
            server: Server::new(ServerLimits::default()),
            client: Client::new(
                Guid::new(prefix, EntityId::TYPELOOKUP_REQUEST_WRITER).to_bytes(),
                ClientLimits::default(),
            ),
        }
    }
}

/// Whether `id` is one of the service's four endpoints.
pub(super) fn is_service_endpoint(id: EntityId) -> bool {
    matches!(
        id,
        EntityId::TYPELOOKUP_REQUEST_WRITER
            | EntityId::TYPELOOKUP_REQUEST_READER
            | EntityId::TYPELOOKUP_REPLY_WRITER
            | EntityId::TYPELOOKUP_REPLY_READER
    )
}

/// Whether `id` is one of the service's two writers.
fn is_service_writer(id: EntityId) -> bool {
    matches!(
        id,
        EntityId::TYPELOOKUP_REQUEST_WRITER | EntityId::TYPELOOKUP_REPLY_WRITER
    )
}

/// The service writers: reliable, volatile, keyless, KEEP_LAST [`HISTORY_DEPTH`] (as Cyclone's are reliable
/// and volatile).
pub(super) fn writer_params(base: WriterParams) -> WriterParams {
    WriterParams {
        durability: Durability::Volatile,
        history: History::KeepLast(HISTORY_DEPTH),
        limits: ResourceLimits::default(),
        keyed: false,
        ..base
    }
}

impl Participant {
    /// The participant's type store: the type objects of our own endpoints ([`register_types`]) and those
    /// learnt through the TypeLookup service, each checked against its hash.
    ///
    /// [`register_types`]: Self::register_types
    pub fn type_store(&self) -> &TypeStore {
        &self.type_lookup.store
    }

    /// Adds the types of a local endpoint (its XCDR2 `TypeInformation` and `TypeMapping`, as
    /// `xtypes::TypeSupport` builds them) to the store, so that the service can answer for them.
    pub fn register_types(
        &mut self,
        information: &[u8],
        mapping: &[u8],
    ) -> Result<(), crate::cdr::DecodeError> {
        let info: typeobject::TypeInformation = typeobject::from_bytes(information)?;
        let mapping: typeobject::TypeMapping = typeobject::from_bytes(mapping)?;
        self.type_lookup.store.add_owned(&info, &mapping);
        Ok(())
    }

    /// Asks every participant's TypeLookup service for the objects of those `ids` the store lacks (and no
    /// request in flight asks for already). Drain `poll_transmit`; poll [`type_store`](Self::type_store) for the
    /// answer (requests expire after two seconds and may be made again).
    pub fn request_types(&mut self, now: Instant, ids: impl IntoIterator<Item = TypeIdentifier>) {
        let s = &mut self.type_lookup;
        s.client.want(&s.store, ids);
        self.send_type_requests(now);
    }

    /// Asks for the identifiers `id` depends on (`getTypeDependencies`, following continuation points), then
    /// for the objects of those the store lacks.
    pub fn request_type_dependencies(&mut self, now: Instant, id: TypeIdentifier) {
        self.type_lookup.client.want_dependencies(id);
        self.send_type_requests(now);
    }

    /// A remote endpoint announced this `TypeInformation`: ask for the types it names that we lack.
    pub(super) fn want_announced_types(
        &mut self,
        now: Instant,
        information: Option<&crate::xtypes::TypeInformation>,
    ) {
        let Some(info) = information.and_then(|t| t.decode().ok()) else {
            return;
        };
        let s = &mut self.type_lookup;
        s.store.add_dependencies(&info);
        let missing = s.store.missing(&info);
        if missing.is_empty() {
            return;
        }
        for d in [&info.minimal, &info.complete] {
            let listed = d.dependent_typeids.len();
            if usize::try_from(d.dependent_typeid_count).is_ok_and(|n| n > listed) {
                s.client
                    .want_dependencies(d.typeid_with_size.type_id.clone());
            }
        }
        s.client.want(&s.store, missing);
        self.send_type_requests(now);
    }

    /// Matches our service endpoints with those of the participant `prefix`, unless done already. A
    /// participant's four service proxies are made when a request or reply is first exchanged with it (most
    /// peers never exchange one): see `docs/performance.md`, "Footprint".
    pub(super) fn match_type_lookup(&mut self, now: Instant, prefix: GuidPrefix) {
        let Some(p) = self.participants.get_mut(&prefix) else {
            return;
        };
        if p.type_lookup_matched {
            return;
        }
        p.type_lookup_matched = true;
        let bits = p.builtin_endpoints;
        let meta = p.metatraffic.clone();
        trace!(participant = ?prefix, "TypeLookup endpoints matched");
        // Addressed to one participant: never via a shared multicast group.
        self.match_builtin_pairs(now, prefix, bits, &meta, None, is_service_endpoint);
    }

    /// A submessage from `writer` arrived that may carry (or announce) a change: if it is a remote service
    /// writer's (a request or reply) or participant-message writer's, the endpoints of its participant of
    /// that kind are matched before it is handled (see also `Participant::match_messages`).
    pub(super) fn service_traffic(&mut self, now: Instant, writer: Guid) {
        if is_service_writer(writer.entity_id) {
            self.match_type_lookup(now, writer.prefix);
        } else if writer.entity_id == EntityId::P2P_MESSAGE_WRITER {
            self.match_messages(now, writer.prefix, super::liveliness::MESSAGES_IN);
        }
    }

    /// Matches the service endpoints of every discovered participant: our requests go to all of them.
    fn match_type_lookup_all(&mut self, now: Instant) {
        let pending: Vec<GuidPrefix> = self
            .participants
            .iter()
            .filter(|(_, p)| !p.type_lookup_matched)
            .map(|(prefix, _)| *prefix)
            .collect();
        for prefix in pending {
            self.match_type_lookup(now, prefix);
        }
    }

    /// Writes the client's queued requests on the request writer.
    fn send_type_requests(&mut self, now: Instant) {
        let mut matched = false;
        while let Some(req) = self.type_lookup.client.poll_request(now) {
            if !matched {
                self.match_type_lookup_all(now);
                matched = true;
            }
            match typelookup::encode_request(&req) {
                Ok(bytes) => self.write_service(now, EntityId::TYPELOOKUP_REQUEST_WRITER, bytes),
                Err(e) => debug!(error = %e, "TypeLookup request not encodable"),
            }
        }
    }

    fn write_service(&mut self, now: Instant, writer: EntityId, payload: Vec<u8>) {
        self.timers_changed();
        if let Some(w) = self.writers.get_mut(&writer) {
            let _ = w.write(
                now,
                WriteChange::alive(payload),
                &mut self.out,
                &mut self.events,
            );
        }
    }

    /// A request arrived on our request reader: answer it from the store (rate-limited per participant).
    pub(super) fn on_type_lookup_request(&mut self, now: Instant, s: &ReceivedSample) {
        let req = match typelookup::decode_request(&s.payload) {
            Ok(r) => r,
            Err(e) => {
                debug!(writer = ?s.writer, error = %e, "dropping TypeLookup request");
                return;
            }
        };
        let t = &mut self.type_lookup;
        let Some(reply) = t.server.handle(now, s.writer.prefix.0, &t.store, &req) else {
            debug!(writer = ?s.writer, "TypeLookup request over the rate limit: answered later");
            self.timers_changed();
            return;
        };
        trace!(writer = ?s.writer, call = ?req.call, "TypeLookup request answered");
        self.send_type_reply(now, &reply);
    }

    fn send_type_reply(&mut self, now: Instant, reply: &typelookup::Reply) {
        match typelookup::encode_reply(reply) {
            Ok(bytes) => self.write_service(now, EntityId::TYPELOOKUP_REPLY_WRITER, bytes),
            Err(e) => debug!(error = %e, "TypeLookup reply not encodable"),
        }
    }

    /// When requests that were over their peer's rate can be answered.
    pub(super) fn type_lookup_due(&self) -> Option<Instant> {
        self.type_lookup.server.next_deferred()
    }

    /// A reply arrived on our reply reader: if it answers one of our requests, store what checks out.
    pub(super) fn on_type_lookup_reply(&mut self, now: Instant, s: &ReceivedSample) {
        let reply = match typelookup::decode_reply(&s.payload) {
            Ok(r) => r,
            Err(e) => {
                debug!(writer = ?s.writer, error = %e, "dropping TypeLookup reply");
                return;
            }
        };
        let t = &mut self.type_lookup;
        let out = t.client.handle_reply(&mut t.store, &reply);
        for (id, e) in &out.rejected {
            debug!(writer = ?s.writer, ?id, error = %e, "TypeLookup reply object refused");
        }
        if !out.stored.is_empty() {
            debug!(writer = ?s.writer, stored = out.stored.len(), "types learnt through TypeLookup");
            // Pairs decided by type name while a peer's type was unresolved are decided by assignability now.
            self.rematch_typed(now);
        }
        // A dependencies answer may have queued more requests.
        self.send_type_requests(now);
    }

    /// Expires unanswered requests of ours, and answers the peers' requests that waited for their rate.
    pub(super) fn type_lookup_timeout(&mut self, now: Instant) {
        self.type_lookup.client.handle_timeout(now);
        loop {
            let t = &mut self.type_lookup;
            let Some(reply) = t.server.poll_deferred(now, &t.store) else {
                break;
            };
            self.send_type_reply(now, &reply);
        }
    }
}
