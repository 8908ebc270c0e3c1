//! The armed timers of an endpoint's proxies in deadline order, so that finding the next one is O(1) and
//! firing one is O(log n).
//!
//! A participant asks every endpoint for its next deadline after each datagram it receives, and a builtin
//! endpoint has one proxy per discovered participant. Scanning them all whenever one proxy's ACKNACK or repair
//! fell due made discovery quadratic (100 participants: about a hundred proxies scanned about a hundred times
//! per heartbeat round, `scripts/bench-scale.sh`). Instead an endpoint queues (deadline, proxy) whenever a
//! proxy timer goes from unarmed to armed, and pops the queue when the head is due.
//!
//! Entries are not removed when a timer is cleared or its proxy goes: the popped proxy is checked against its
//! own timer, and a stale entry costs one look-up. Each entry stands for one arming, and every armed timer is
//! due within a protocol delay, so the queue stays about as long as the proxies with a timer armed.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::Instant;

use crate::rtps::types::Guid;

/// The room (in entries) a timer queue, or an endpoint's proxy map, keeps beyond what it holds once trimmed.
pub(crate) const KEPT_TIMER_ROOM: usize = 16;

/// Proxy timers of one endpoint, earliest first. An entry may be stale (its timer cleared, its proxy gone):
/// the caller checks the proxy's own timer.
#[derive(Debug, Default)]
pub(crate) struct DueQueue(BinaryHeap<Reverse<(Instant, Guid)>>);

impl DueQueue {
    /// The timer of `proxy` was armed at `t` (nothing for `None`). Call it only when the timer goes from
    /// unarmed to armed (or to an earlier time): each call adds an entry.
    pub(crate) fn arm(&mut self, t: Option<Instant>, proxy: Guid) {
        if let Some(t) = t {
            self.0.push(Reverse((t, proxy)));
        }
    }

    /// The earliest entry's deadline (a lower bound on every armed timer); `None`: no timer is armed.
    pub(crate) fn next(&self) -> Option<Instant> {
        self.0.peek().map(|Reverse((t, _))| *t)
    }

    /// Removes and returns a proxy whose entry is due at `now`, earliest first.
    pub(crate) fn pop_due(&mut self, now: Instant) -> Option<Guid> {
        if self.next()? > now {
            return None;
        }
        self.0.pop().map(|Reverse((_, g))| g)
    }

    /// Forgets every entry (when the endpoint has no proxy left) and gives back the room of a burst.
    pub(crate) fn clear(&mut self) {
        self.0 = BinaryHeap::new();
    }

    /// Gives back the room a burst left (a builtin endpoint arms one timer per new peer when many appear at
    /// once), keeping room for `keep` entries beyond those queued. Call it now and then, not per pass, so
    /// that a steady stream does not shrink and regrow the queue.
    pub(crate) fn trim(&mut self, keep: usize) {
        self.0.shrink_to(self.0.len() + keep);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtps::types::{EntityId, GuidPrefix};
    use std::time::Duration;

    fn g(i: u8) -> Guid {
        Guid::new(GuidPrefix([i; 12]), EntityId::SEDP_PUBLICATIONS_READER)
    }

    #[test]
    fn pops_in_deadline_order_only_when_due() {
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        let mut q = DueQueue::default();
        q.arm(Some(t0 + ms(5)), g(1));
        q.arm(None, g(9));
        q.arm(Some(t0 + ms(1)), g(2));
        q.arm(Some(t0 + ms(3)), g(3));
        assert_eq!(q.next(), Some(t0 + ms(1)));
        assert_eq!(q.pop_due(t0), None);
        assert_eq!(q.pop_due(t0 + ms(3)), Some(g(2)));
        assert_eq!(q.pop_due(t0 + ms(3)), Some(g(3)));
        assert_eq!(q.pop_due(t0 + ms(3)), None);
        assert_eq!(q.next(), Some(t0 + ms(5)));
        q.clear();
        assert_eq!(q.next(), None);
    }

    /// A burst of armings leaves room for them all; `trim` gives it back and keeps what is queued.
    #[test]
    fn trim_gives_back_the_room_of_a_burst() {
        let t0 = Instant::now();
        let mut q = DueQueue::default();
        for i in 0..200u8 {
            q.arm(Some(t0), g(i));
        }
        while q.pop_due(t0).is_some() {}
        q.arm(Some(t0), g(1));
        assert!(q.0.capacity() >= 200);
        q.trim(4);
        assert!(q.0.capacity() <= 8, "capacity {}", q.0.capacity());
        assert_eq!(q.pop_due(t0), Some(g(1)));
    }
}
