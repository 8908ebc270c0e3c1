//! Which matched readers get new data by multicast.
//!
//! A reader that can be reached on a multicast locator (`ReaderProxy::multicast`, set at matching only when
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
            if let Some(m) = p.multicast {
                sharing
                    .entry(m)
                    .or_default()
                    .insert(p.destination().first().copied());
            }
        }
        for p in self.proxies.values_mut() {
            p.via_multicast = p.multicast.is_some_and(|m| {
                p.locators.is_empty() || sharing.get(&m).is_some_and(|u| u.len() >= 2)
            });
        }
    }

    /// Where the periodic heartbeat goes: to every reliable reader that has not acknowledged everything; by
    /// multicast only where two or more of those share the group. A heartbeat sent to the group asks every
    /// reader there for an ACKNACK, so a group in which one reader lags (common once discovery among many
    /// participants settles) is served by unicast to that reader alone.
    pub(super) fn heartbeat_destinations(&self) -> Vec<Locator> {
        let unacked = || {
            self.proxies
                .values()
                .filter(|p| p.reliable && p.acked < self.next_sn)
        };
        let mut lagging: BTreeMap<Locator, usize> = BTreeMap::new();
        for m in unacked()
            .filter(|p| p.via_multicast)
            .filter_map(|p| p.multicast)
        {
            *lagging.entry(m).or_default() += 1;
        }
        let mut d: Vec<Locator> = unacked()
            .filter_map(|p| match p.data_destination() {
                Some(m) if lagging.get(&m).is_some_and(|&n| n < 2) => {
                    p.destination().first().copied().or(Some(m))
                }
                other => other,
            })
            .collect();
        d.sort();
        d.dedup();
        d
    }
}
