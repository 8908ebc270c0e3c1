//! An endpoint's matched proxies by GUID: boxed proxies in a vector sorted by the GUID each holds.
//!
//! A builtin endpoint has one proxy per discovered participant, so the container's own cost counts per
//! remote participant (see `docs/performance.md`, "Footprint"). A `BTreeMap<Guid, Box<_>>` spent about
//! 27 bytes of node per proxy there (the key kept beside the proxy that holds it, nodes half full after
//! ascending inserts); this spends the pointer (8 bytes, and the room a growing vector keeps until
//! [`ProxyMap::trim`]). Look-ups are a binary search; inserting and removing move pointers, a few
//! kilobytes at most for thousands of proxies, and happen only on matching.

use std::ops::RangeInclusive;

use crate::rtps::types::Guid;

/// A proxy that knows the GUID of the remote endpoint it stands for.
pub(crate) trait Keyed {
    /// The remote endpoint's GUID: the proxy's key.
    fn key(&self) -> &Guid;
}

/// Proxies sorted by [`Keyed::key`], at most one per GUID.
#[derive(Debug)]
pub(crate) struct ProxyMap<P>(Vec<Box<P>>);

impl<P> Default for ProxyMap<P> {
    fn default() -> Self {
        ProxyMap(Vec::new())
    }
}

impl<P: Keyed> ProxyMap<P> {
    /// An empty map.
    pub(crate) fn new() -> Self {
        Self::default()
    }

    fn find(&self, g: &Guid) -> Result<usize, usize> {
        self.0.binary_search_by(|p| p.key().cmp(g))
    }

    /// The proxy of `g`.
    pub(crate) fn get(&self, g: &Guid) -> Option<&P> {
        self.find(g).ok().map(|i| &*self.0[i])
    }

    /// The proxy of `g`, to change.
    pub(crate) fn get_mut(&mut self, g: &Guid) -> Option<&mut P> {
        self.find(g).ok().map(|i| &mut *self.0[i])
    }

    /// Whether `g` has a proxy.
    pub(crate) fn contains_key(&self, g: &Guid) -> bool {
        self.find(g).is_ok()
    }

    /// Adds `proxy`, replacing the one with the same key (returned).
    pub(crate) fn insert(&mut self, proxy: Box<P>) -> Option<Box<P>> {
        match self.find(proxy.key()) {
            Ok(i) => Some(std::mem::replace(&mut self.0[i], proxy)),
            Err(i) => {
                self.0.insert(i, proxy);
                None
            }
        }
    }

    /// Removes and returns the proxy of `g`.
    pub(crate) fn remove(&mut self, g: &Guid) -> Option<Box<P>> {
        self.find(g).ok().map(|i| self.0.remove(i))
    }

    /// Whether there is no proxy.
    pub(crate) fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The number of proxies.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.0.len()
    }

    /// The keys, in order.
    pub(crate) fn keys(&self) -> impl Iterator<Item = &Guid> + '_ {
        self.0.iter().map(|p| p.key())
    }

    /// The keys and proxies, in key order.
    pub(crate) fn iter(&self) -> impl DoubleEndedIterator<Item = (&Guid, &P)> + '_ {
        self.0.iter().map(|p| (p.key(), &**p))
    }

    /// The proxies, in key order.
    pub(crate) fn values(&self) -> impl DoubleEndedIterator<Item = &P> + '_ {
        self.0.iter().map(|p| &**p)
    }

    /// The proxies, in key order, to change.
    pub(crate) fn values_mut(&mut self) -> impl DoubleEndedIterator<Item = &mut P> + '_ {
        self.0.iter_mut().map(|p| &mut **p)
    }

    /// The proxies whose keys are in `range`, in key order, to change.
    pub(crate) fn range_mut(
        &mut self,
        range: RangeInclusive<Guid>,
    ) -> impl DoubleEndedIterator<Item = &mut P> + '_ {
        let start = self.0.partition_point(|p| p.key() < range.start());
        let end = self.0.partition_point(|p| p.key() <= range.end());
        self.0[start..end.max(start)].iter_mut().map(|p| &mut **p)
    }

    /// Gives back the room a burst of matches left, keeping room for `keep` more proxies.
    pub(crate) fn trim(&mut self, keep: usize) {
        self.0.shrink_to(self.0.len() + keep);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtps::types::{EntityId, GuidPrefix};

    #[derive(Debug, PartialEq)]
    struct P(Guid, u32);

    impl Keyed for P {
        fn key(&self) -> &Guid {
            &self.0
        }
    }

    fn g(prefix: u8, entity: EntityId) -> Guid {
        Guid::new(GuidPrefix([prefix; 12]), entity)
    }

    #[test]
    fn keeps_one_proxy_per_key_in_key_order() {
        let mut m = ProxyMap::new();
        let (r, w) = (
            EntityId::SEDP_PUBLICATIONS_READER,
            EntityId::SEDP_PUBLICATIONS_WRITER,
        );
        for (i, prefix) in [5u8, 1, 9, 3].into_iter().enumerate() {
            assert!(m.insert(Box::new(P(g(prefix, r), i as u32))).is_none());
        }
        let old = m.insert(Box::new(P(g(9, r), 7)));
        assert_eq!(old.map(|p| p.1), Some(2));
        assert_eq!(m.len(), 4);
        let keys: Vec<u8> = m.keys().map(|k| k.prefix.0[0]).collect();
        assert_eq!(keys, [1, 3, 5, 9]);
        assert_eq!(m.get(&g(9, r)).map(|p| p.1), Some(7));
        assert!(m.get(&g(9, w)).is_none() && !m.contains_key(&g(2, r)));
        m.get_mut(&g(3, r)).unwrap().1 = 30;
        assert_eq!(m.values().map(|p| p.1).collect::<Vec<_>>(), [1, 30, 0, 7]);
        assert_eq!(m.remove(&g(1, r)).map(|p| p.1), Some(1));
        assert!(m.remove(&g(1, r)).is_none());
        for p in m.values_mut() {
            p.1 += 1;
        }
        assert_eq!(m.values().map(|p| p.1).collect::<Vec<_>>(), [31, 1, 8]);
    }

    #[test]
    fn a_range_holds_the_keys_between_its_ends() {
        let mut m = ProxyMap::new();
        for prefix in 1..=6u8 {
            for e in [
                EntityId::SEDP_PUBLICATIONS_READER,
                EntityId::P2P_MESSAGE_READER,
            ] {
                m.insert(Box::new(P(g(prefix, e), u32::from(prefix))));
            }
        }
        let range =
            |p: u8| Guid::new(GuidPrefix([p; 12]), EntityId([0; 4]))..=g(p, EntityId([0xff; 4]));
        let in_3: Vec<u32> = m.range_mut(range(3)).map(|p| p.1).collect();
        assert_eq!(in_3, [3, 3]);
        assert_eq!(m.range_mut(range(7)).count(), 0);
        let empty = g(4, EntityId([0xff; 4]))..=g(4, EntityId([0; 4]));
        assert_eq!(m.range_mut(empty).count(), 0);
    }

    #[test]
    fn trim_gives_back_the_room_of_a_burst() {
        let mut m = ProxyMap::new();
        for prefix in 0..200u8 {
            m.insert(Box::new(P(
                g(prefix, EntityId::SEDP_PUBLICATIONS_READER),
                0,
            )));
        }
        for prefix in 2..200u8 {
            m.remove(&g(prefix, EntityId::SEDP_PUBLICATIONS_READER));
        }
        m.trim(4);
        assert!(m.0.capacity() <= 8, "capacity {}", m.0.capacity());
        assert_eq!(m.len(), 2);
    }
}
