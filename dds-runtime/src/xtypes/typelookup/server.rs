//! The server side: answers `getTypes` and `getTypeDependencies` from a [`TypeStore`], rate-limited per
//! requesting participant and bounded in what one reply may carry.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use crate::xtypes::store::TypeStore;
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
    /// Requests answered per participant per second (more are dropped).
    pub requests_per_second: u32,
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
            max_peers: 4096,
        }
    }
}

/// Requests per peer in one-second windows.
#[derive(Debug, Default)]
pub struct RateLimiter {
    windows: HashMap<[u8; 12], (Instant, u32)>,
}

impl RateLimiter {
    /// Whether `peer` may have one more request answered at `now` (and counts it).
    pub fn allow(&mut self, now: Instant, peer: [u8; 12], limits: &ServerLimits) -> bool {
        const WINDOW: Duration = Duration::from_secs(1);
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
}

impl Server {
    /// A server with these limits.
    pub fn new(limits: ServerLimits) -> Self {
        Server {
            limits,
            limiter: RateLimiter::default(),
        }
    }

    /// The reply to `req`, which came from participant `peer` (the RTPS source, not the header's claim);
    /// `None` when `peer` is over its rate.
    pub fn handle(
        &mut self,
        now: Instant,
        peer: [u8; 12],
        store: &TypeStore,
        req: &Request,
    ) -> Option<Reply> {
        if !self.limiter.allow(now, peer, &self.limits) {
            return None;
        }
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
        Some(Reply {
            related_request_id: req.request_id,
            remote_ex,
            return_data,
        })
    }

    fn get_types(&self, store: &TypeStore, ids: &[TypeIdentifier]) -> TypesOut {
        let mut out = TypesOut::default();
        let mut bytes = 0usize;
        for id in ids.iter().take(self.limits.max_ids_per_request) {
            if id.hash().is_none() || out.types.iter().any(|p| &p.type_identifier == id) {
                continue;
            }
            let Some(object) = store.get(id) else {
                continue;
            };
            bytes += store.serialized_size(id);
            if bytes > self.limits.max_reply_bytes && !out.types.is_empty() {
                break;
            }
            out.types.push(TypeIdentifierTypeObjectPair {
                type_identifier: id.clone(),
                type_object: (*object).clone(),
            });
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
