//! The earliest timer among an endpoint's proxies, kept so that asking for it is O(1).
//!
//! A participant asks every endpoint for its next deadline after each datagram it receives. Scanning every
//! matched proxy for that made discovery quadratic: 100 participants with 20 endpoints each spent most of their
//! CPU there (`scripts/bench-scale.sh`). Instead each endpoint keeps a lower bound, lowered wherever a proxy
//! timer is armed and recomputed exactly only when it fires. A bound that turns out early (the timer it came from
//! was cleared) costs one pass that finds nothing due and recomputes it.

use std::time::Instant;

/// A lower bound on the earliest armed proxy timer of one endpoint; `None`: no proxy timer is armed.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct DueFloor(Option<Instant>);

impl DueFloor {
    /// A proxy timer was armed at `t` (or not, for `None`).
    pub(crate) fn lower(&mut self, t: Option<Instant>) {
        if let Some(t) = t {
            self.0 = Some(self.0.map_or(t, |f| f.min(t)));
        }
    }

    /// The bound.
    pub(crate) fn get(self) -> Option<Instant> {
        self.0
    }

    /// Whether a proxy timer may be due at `now`.
    pub(crate) fn reached(self, now: Instant) -> bool {
        self.0.is_some_and(|t| t <= now)
    }

    /// Replaces the bound by the exact earliest timer, after a pass over the proxies.
    pub(crate) fn set_exact(&mut self, t: Option<Instant>) {
        self.0 = t;
    }
}
