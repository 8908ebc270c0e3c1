//! The server side: answers `getTypes` and `getTypeDependencies` from a [`TypeStore`], rate-limited per
//! requesting participant and bounded in what one reply may carry.

use std::collections::{HashMap, VecDeque};
use std::time::{Duration, Instant};

use crate::xtypes::store::{is_lookup_id, TypeStore};
use crate::xtypes::typeobject::{TypeIdentifier, TypeIdentifierTypeObjectPair};

use super::messages::*;

/// What one request may cost us.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ServerLimits {
    /// Identifiers of one request that are looked at (the rest are ignored).
    pub max_ids_per_request: usize,
    /// Serialized type-object bytes in one `getTypes` reply (objects beyond are left out; ask again).
    pub max_reply_bytes: usize,
    /// Dependencies in one `getTypeDependencies` reply (a continuation point gives the rest).
    pub dependencies_page: usize,
    /// Requests answered per participant per second; more wait for a later second (see `max_deferred`).
    pub requests_per_second: u32,
    /// Requests over the rate kept to be answered later, from all participants together (more are
    /// dropped). Peers such as Cyclone DDS send a burst of requests when they discover many types and do not
    /// ask again, so dropping them would leave their types unresolved.
    pub max_deferred: usize,
    /// Participants whose rate is tracked at once.
    pub max_peers: usize,
}

impl Default for ServerLimits {
    fn default() -> Self {
        ServerLimits {
            max_ids_per_request: 64,
            max_reply_bytes: 256 << 10,
            dependencies_page: 64,
            requests_per_second: 64,
            max_deferred: 1024,
            max_peers: 4096,
        }
    }
}

/// The rate limiter's window.
const RATE_WINDOW: Duration = Duration::from_secs(1);

/// Requests per peer in one-second windows.
#[derive(Debug, Default)]
pub struct RateLimiter {
    windows: HashMap<[u8; 12], (Instant, u32)>,
}

impl RateLimiter {
    /// From when `peer` may have one more request answered (`None`: at once, it has no window).
    fn next_allowed(&self, peer: &[u8; 12], limits: &ServerLimits) -> Option<Instant> {
        self.windows.get(peer).map(|(start, count)| {
            if *count < limits.requests_per_second {
                *start
            } else {
                *start + RATE_WINDOW
            }
        })
    }

    /// Whether `peer` may have one more request answered at `now` (and counts it).
    pub fn allow(&mut self, now: Instant, peer: [u8; 12], limits: &ServerLimits) -> bool {
        const WINDOW: Duration = RATE_WINDOW;
        if !self.windows.contains_key(&peer) && self.windows.len() >= limits.max_peers {
            self.windows
                .retain(|_, (start, _)| now.saturating_duration_since(*start) < WINDOW);
            if self.windows.len() >= limits.max_peers {
                return false;
            }
        }
        let (start, count) = self.windows.entry(peer).or_insert((now, 0));
        if now.saturating_duration_since(*start) >= WINDOW {
            *start = now;
            *count = 0;
        }
        *count += 1;
        *count <= limits.requests_per_second
    }
}

/// The TypeLookup server. See the module documentation.
#[derive(Debug, Default)]
pub struct Server {
    limits: ServerLimits,
    limiter: RateLimiter,
    /// Requests over their peer's rate, oldest first, answered by [`Server::poll_deferred`].
    deferred: VecDeque<([u8; 12], Request)>,
}

impl Server {
    /// A server with these limits.
    pub fn new(limits: ServerLimits) -> Self {
        Server {
            limits,
            limiter: RateLimiter::default(),
            deferred: VecDeque::new(),
        }
    }

    /// The reply to `req`, which came from participant `peer` (the RTPS source, not the header's claim);
    /// `None` when `peer` is over its rate: the request then waits for [`Server::poll_deferred`] (or is
    /// dropped when `max_deferred` requests wait already).
    pub fn handle(
        &mut self,
        now: Instant,
        peer: [u8; 12],
        store: &TypeStore,
        req: &Request,
    ) -> Option<Reply> {
        let earlier_waits = self.deferred.iter().any(|(p, _)| *p == peer);
        if earlier_waits || !self.limiter.allow(now, peer, &self.limits) {
            if self.deferred.len() < self.limits.max_deferred {
                self.deferred.push_back((peer, req.clone()));
            }
            return None;
        }
        Some(self.answer(store, req))
    }

    /// The next waiting request whose peer's rate allows it now, answered (call until `None`).
    pub fn poll_deferred(&mut self, now: Instant, store: &TypeStore) -> Option<Reply> {
        let limits = &self.limits;
        let i = self.deferred.iter().position(|(p, _)| {
            self.limiter
                .next_allowed(p, limits)
                .is_none_or(|t| now >= t)
        })?;
        let (peer, req) = self.deferred.remove(i)?;
        if !self.limiter.allow(now, peer, &self.limits) {
            // Too many peers tracked at once: try again later.
            self.deferred.push_front((peer, req));
            return None;
        }
        Some(self.answer(store, &req))
    }

    /// When [`Server::poll_deferred`] has something to answer (`None` while nothing waits; a waiting
    /// request of a peer no longer tracked is answered at the next poll).
    pub fn next_deferred(&self) -> Option<Instant> {
        let limits = &self.limits;
        self.deferred
            .iter()
            .filter_map(|(p, _)| self.limiter.next_allowed(p, limits))
            .min()
    }

    fn answer(&self, store: &TypeStore, req: &Request) -> Reply {
        let (remote_ex, return_data) = match &req.call {
            Call::GetTypes(ids) => (
                RemoteExceptionCode::Ok,
                Return::GetTypes(Ok(self.get_types(store, ids))),
            ),
            Call::GetTypeDependencies {
                type_ids,
                continuation_point,
            } => match self.dependencies(store, type_ids, continuation_point) {
                Some(d) => (RemoteExceptionCode::Ok, Return::GetTypeDependencies(Ok(d))),
                None => (
                    RemoteExceptionCode::InvalidArgument,
                    Return::GetTypeDependencies(Ok(TypeDependencies::default())),
                ),
            },
            Call::Other(d) => (RemoteExceptionCode::UnknownOperation, Return::Other(*d)),
        };
        Reply {
            related_request_id: req.request_id,
            remote_ex,
            return_data,
        }
    }

    fn get_types(&self, store: &TypeStore, ids: &[TypeIdentifier]) -> TypesOut {
        let mut out = TypesOut::default();
        let mut bytes = 0usize;
        // A type of a strongly connected component (or the component, index 0) is answered with every type of
        // the component: its objects are checked against the component's hash together.
        for id in ids.iter().take(self.limits.max_ids_per_request) {
            if !is_lookup_id(id) || out.types.iter().any(|p| &p.type_identifier == id) {
                continue;
            }
            let Some(objects) = store.objects_of(id) else {
                continue;
            };
            bytes += objects
                .iter()
                .map(|(i, _)| store.serialized_size(i))
                .sum::<usize>();
            if bytes > self.limits.max_reply_bytes && !out.types.is_empty() {
                break;
            }
            for (type_identifier, object) in objects {
                if !out
                    .types
                    .iter()
                    .any(|p| p.type_identifier == type_identifier)
                {
                    out.types.push(TypeIdentifierTypeObjectPair {
                        type_identifier,
                        type_object: (*object).clone(),
                    });
                }
            }
        }
        out
    }

    /// One page of the dependencies of `ids`; `None` for a continuation point we did not hand out.
    fn dependencies(
        &self,
        store: &TypeStore,
        ids: &[TypeIdentifier],
        continuation: &[u8],
    ) -> Option<TypeDependencies> {
        let start = match continuation {
            [] => 0,
            [a, b, c, d] => u32::from_le_bytes([*a, *b, *c, *d]) as usize,
            _ => return None,
        };
        let mut all = Vec::new();
        for id in ids.iter().take(self.limits.max_ids_per_request) {
            for d in store.dependencies(id).iter() {
                if !all.contains(d) {
                    all.push(d.clone());
                }
            }
        }
        if start > all.len() {
            return None;
        }
        let end = all.len().min(start + self.limits.dependencies_page.max(1));
        let continuation_point = if end < all.len() {
            (end as u32).to_le_bytes().to_vec()
        } else {
            Vec::new()
        };
        Some(TypeDependencies {
            dependent_typeids: all.drain(start..end).collect(),
            continuation_point,
        })
    }
}
