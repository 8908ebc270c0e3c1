//! The client side: asks for the types a peer announced and we lack, matches replies to its requests, and
//! stores each received object only after its hash checks out ([`TypeStore::insert_verified`]).
//!
//! Bounded: a limited number of requests in flight, each with a limited number of identifiers; only objects
//! that a request of ours asked for are looked at; requests that get no (full) answer expire, and the types
//! are asked for again the next time something wants them.

use std::collections::{BTreeMap, HashSet, VecDeque};
use std::time::{Duration, Instant};

use crate::xtypes::store::{component_of, is_lookup_id, StoreError, TypeStore};
use crate::xtypes::typeobject::{TypeIdentifier, TypeIdentifierTypeObjectPair, TypeObject};

use super::messages::*;

/// How much the client asks at once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ClientLimits {
    /// Requests in flight at once.
    pub max_in_flight: usize,
    /// Identifiers per request.
    pub max_ids_per_request: usize,
    /// Identifiers queued, waiting for a request.
    pub max_queued: usize,
    /// How long a request waits for its answer.
    pub timeout: Duration,
    /// Pages of one `getTypeDependencies` followed.
    pub max_dependency_pages: u32,
}

impl Default for ClientLimits {
    fn default() -> Self {
        ClientLimits {
            max_in_flight: 8,
            max_ids_per_request: 32,
            max_queued: 4096,
            timeout: Duration::from_secs(2),
            max_dependency_pages: 64,
        }
    }
}

#[derive(Debug)]
enum Asked {
    Types(Vec<TypeIdentifier>),
    Dependencies { id: TypeIdentifier, page: u32 },
}

#[derive(Debug)]
struct InFlight {
    asked: Asked,
    deadline: Instant,
}

#[derive(Debug)]
enum Queued {
    Dependencies {
        id: TypeIdentifier,
        continuation: Vec<u8>,
        page: u32,
    },
}

/// What a reply did.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct ReplyOutcome {
    /// Objects stored.
    pub stored: Vec<TypeIdentifier>,
    /// Objects refused, and why (a hash that does not match, a full store, ...).
    pub rejected: Vec<(TypeIdentifier, StoreError)>,
}

/// The TypeLookup client. See the module documentation.
#[derive(Debug)]
pub struct Client {
    writer_guid: [u8; 16],
    instance_name: String,
    limits: ClientLimits,
    next_sn: i64,
    in_flight: BTreeMap<i64, InFlight>,
    /// Identifiers to ask for with `getTypes`, in order, each once (`queued_set`), none in flight.
    queued: VecDeque<TypeIdentifier>,
    queued_set: HashSet<TypeIdentifier>,
    /// Identifiers in a request in flight.
    asked: HashSet<TypeIdentifier>,
    other: VecDeque<Queued>,
}

impl Client {
    /// A client whose requests come from the writer `writer_guid` (our request writer).
    pub fn new(writer_guid: [u8; 16], limits: ClientLimits) -> Self {
        let mut instance_name = String::from("dds.builtin.TOS.");
        for chunk in writer_guid[..12].chunks(4).chain([&writer_guid[12..]]) {
            for b in chunk {
                instance_name.push_str(&format!("{b:02x}"));
            }
        }
        Client {
            writer_guid,
            instance_name,
            limits,
            next_sn: 1,
            in_flight: BTreeMap::new(),
            queued: VecDeque::new(),
            queued_set: HashSet::new(),
            asked: HashSet::new(),
            other: VecDeque::new(),
        }
    }

    /// Queues the hashed and component identifiers among `ids` that `store` lacks and no request asks for
    /// yet.
    pub fn want(&mut self, store: &TypeStore, ids: impl IntoIterator<Item = TypeIdentifier>) {
        for id in ids {
            if !is_lookup_id(&id)
                || store.contains(&id)
                || self.asked.contains(&id)
                || self.queued_set.contains(&id)
                || self.queued.len() >= self.limits.max_queued
            {
                continue;
            }
            self.queued_set.insert(id.clone());
            self.queued.push_back(id);
        }
    }

    /// Queues a `getTypeDependencies` for `id` (used when a `TypeInformation` lists fewer dependencies than
    /// it counts).
    pub fn want_dependencies(&mut self, id: TypeIdentifier) {
        if self.other.len() < self.limits.max_in_flight {
            self.other.push_back(Queued::Dependencies {
                id,
                continuation: Vec::new(),
                page: 0,
            });
        }
    }

    /// Whether a request for `id` is queued or in flight.
    pub fn is_pending(&self, id: &TypeIdentifier) -> bool {
        self.asked.contains(id) || self.queued_set.contains(id)
    }

    /// The next request to send, if any is queued and the in-flight budget allows.
    pub fn poll_request(&mut self, now: Instant) -> Option<Request> {
        if self.in_flight.len() >= self.limits.max_in_flight {
            return None;
        }
        let (asked, call) = if let Some(Queued::Dependencies {
            id,
            continuation,
            page,
        }) = self.other.pop_front()
        {
            let call = Call::GetTypeDependencies {
                type_ids: vec![id.clone()],
                continuation_point: continuation,
            };
            (Asked::Dependencies { id, page }, call)
        } else {
            if self.queued.is_empty() {
                return None;
            }
            let n = self
                .queued
                .len()
                .min(self.limits.max_ids_per_request.max(1));
            let ids: Vec<TypeIdentifier> = self.queued.drain(..n).collect();
            for id in &ids {
                self.queued_set.remove(id);
                self.asked.insert(id.clone());
            }
            (Asked::Types(ids.clone()), Call::GetTypes(ids))
        };
        let sn = self.next_sn;
        self.next_sn += 1;
        self.in_flight.insert(
            sn,
            InFlight {
                asked,
                deadline: now + self.limits.timeout,
            },
        );
        Some(Request {
            request_id: SampleIdentity {
                writer_guid: self.writer_guid,
                sequence_number: sn,
            },
            instance_name: self.instance_name.clone(),
            call,
        })
    }

    /// Handles a reply: ignored unless it answers a request of ours in flight; each object it carries that
    /// the request asked for is stored if its hash checks out.
    pub fn handle_reply(&mut self, store: &mut TypeStore, reply: &Reply) -> ReplyOutcome {
        let mut out = ReplyOutcome::default();
        let id = reply.related_request_id;
        // Cyclone DDS 0.10 puts its own reply writer's GUID (in host byte order) into `relatedRequestId`,
        // keeping only the sequence number: such a reply is matched by the number alone, and it can only
        // deliver objects (hash-checked) that the request asked for; it never ends a request.
        let exact = id.writer_guid == self.writer_guid;
        let Some(f) = self.in_flight.get_mut(&id.sequence_number) else {
            return out;
        };
        match (&mut f.asked, &reply.return_data) {
            (Asked::Types(asked), Return::GetTypes(Ok(types))) => {
                store_components(&mut self.asked, store, asked, &types.types, &mut out);
                for p in &types.types {
                    let Some(i) = asked.iter().position(|a| a == &p.type_identifier) else {
                        continue;
                    };
                    match store.insert_verified(p.type_identifier.clone(), p.type_object.clone()) {
                        Ok(_) => {
                            let id = asked.swap_remove(i);
                            self.asked.remove(&id);
                            out.stored.push(id);
                        }
                        Err(e) => out.rejected.push((p.type_identifier.clone(), e)),
                    }
                }
                if asked.is_empty() {
                    self.in_flight.remove(&id.sequence_number);
                }
            }
            (Asked::Dependencies { id: of, page }, Return::GetTypeDependencies(Ok(d))) if exact => {
                let (of, page) = (of.clone(), *page);
                self.in_flight.remove(&id.sequence_number);
                self.want(store, d.dependent_typeids.iter().map(|t| t.type_id.clone()));
                if !d.continuation_point.is_empty() && page + 1 < self.limits.max_dependency_pages {
                    self.other.push_back(Queued::Dependencies {
                        id: of,
                        continuation: d.continuation_point.clone(),
                        page: page + 1,
                    });
                }
            }
            _ if exact => {
                // An error return, or an answer to another operation: the request is over.
                if let Some(InFlight {
                    asked: Asked::Types(ids),
                    ..
                }) = self.in_flight.remove(&id.sequence_number)
                {
                    ids.iter().for_each(|i| {
                        self.asked.remove(i);
                    });
                }
            }
            _ => {}
        }
        out
    }

    /// Expires requests whose answer did not come in time; their types can be wanted again.
    pub fn handle_timeout(&mut self, now: Instant) {
        let expired: Vec<i64> = self
            .in_flight
            .iter()
            .filter(|(_, f)| f.deadline <= now)
            .map(|(sn, _)| *sn)
            .collect();
        for sn in expired {
            if let Some(InFlight {
                asked: Asked::Types(ids),
                ..
            }) = self.in_flight.remove(&sn)
            {
                for i in ids {
                    self.asked.remove(&i);
                }
            }
        }
    }

    /// When [`handle_timeout`](Self::handle_timeout) has something to do.
    pub fn next_timeout(&self) -> Option<Instant> {
        self.in_flight.values().map(|f| f.deadline).min()
    }
}

/// The objects of strongly connected components in a reply, each component stored whole if a type of it
/// was asked for: every asked identifier of a stored component is then answered.
fn store_components(
    pending: &mut HashSet<TypeIdentifier>,
    store: &mut TypeStore,
    asked: &mut Vec<TypeIdentifier>,
    pairs: &[TypeIdentifierTypeObjectPair],
    out: &mut ReplyOutcome,
) {
    let mut done = Vec::new();
    for p in pairs {
        let Some(c) = component_of(&p.type_identifier) else {
            continue;
        };
        if done.contains(&c) || !asked.iter().any(|a| component_of(a) == Some(c)) {
            continue;
        }
        done.push(c);
        let members: Vec<(TypeIdentifier, TypeObject)> = pairs
            .iter()
            .filter(|q| component_of(&q.type_identifier) == Some(c))
            .map(|q| (q.type_identifier.clone(), q.type_object.clone()))
            .collect();
        match store.insert_component(&members) {
            Ok(_) => asked.retain(|a| {
                let answered = component_of(a) == Some(c);
                if answered {
                    pending.remove(a);
                    out.stored.push(a.clone());
                }
                !answered
            }),
            Err(e) => out.rejected.push((p.type_identifier.clone(), e)),
        }
    }
}
