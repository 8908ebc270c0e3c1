//! Which matched readers get new data by multicast.
//!
//! A reader that can be reached on a multicast locator (`ReaderProxy::multicast()`, set at matching only when
//! the participant allows multicast user data) receives new samples and periodic heartbeats there when
//! readers at two or more different unicast locators share that multicast locator: the sample then leaves
//! once for all of them instead of once per unicast locator. Readers alone on their group (or all behind
//! one unicast locator, i.e. in one participant), or with no group, are served unicast, which reaches only
//! them (Cyclone chooses the same way). Repairs, GAPs and heartbeats addressed to one reader always go to
//! its unicast locator, so a loss seen by one reader costs the others nothing.

use std::collections::{BTreeMap, BTreeSet};

use super::Writer;
use crate::rtps::types::Locator;

impl Writer {
    /// Sets every proxy's `via_multicast` from how many unicast destinations share its multicast locator.
    pub(super) fn choose_multicast(&mut self) {
        let mut sharing: BTreeMap<Locator, BTreeSet<Option<Locator>>> = BTreeMap::new();
        for p in self.proxies.values() {
            if let Some(m) = p.multicast() {
                sharing
                    .entry(m)
                    .or_default()
                    .insert(p.destination().first().copied());
            }
        }
        for p in self.proxies.values_mut() {
            p.via_multicast = p.multicast().is_some_and(|m| {
                p.unicast().is_empty() || sharing.get(&m).is_some_and(|u| u.len() >= 2)
            });
        }
    }

    /// Where the periodic heartbeat goes: to every reliable reader that has not acknowledged everything; by
    /// multicast only where those lagging readers are more than half of the readers served by the group.
    /// A heartbeat sent to the group asks every reader there for an ACKNACK, so a group of n readers in
    /// which k lag costs 1 + n datagrams by multicast against 2k by unicast. While many participants
    /// discover each other, a few new readers lag at any time among a hundred that do not: the heartbeat
    /// then goes to those few alone. The list replaces what `d` held (a vector the writer keeps).
    pub(super) fn heartbeat_destinations(&self, d: &mut Vec<Locator>) {
        let unacked = || {
            self.proxies
                .values()
                .filter(|p| p.reliable && p.acked < self.next_sn)
        };
        // Per group: (lagging readers, readers served by it).
        let mut groups: BTreeMap<Locator, (usize, usize)> = BTreeMap::new();
        for p in self.proxies.values().filter(|p| p.via_multicast) {
            if let Some(m) = p.multicast() {
                let g = groups.entry(m).or_default();
                g.1 += 1;
                g.0 += usize::from(p.reliable && p.acked < self.next_sn);
            }
        }
        d.clear();
        d.extend(unacked().filter_map(|p| match p.data_destination() {
            Some(m) if groups.get(&m).is_some_and(|&(k, n)| k < 2 || 2 * k <= n) => {
                p.destination().first().copied().or(Some(m))
            }
            other => other,
        }));
        d.sort();
        d.dedup();
    }
}
