//! Sharing of announced values that nearly every peer announces alike (QoS, type information): one
//! allocation per distinct value instead of one per discovered endpoint.

use std::sync::Arc;

/// How many distinct values an [`Interner`] remembers. Peers announce few distinct QoS sets; a value beyond
/// these is simply stored on its own, so a peer announcing many distinct values costs no more than without
/// interning.
const CAPACITY: usize = 16;

/// A small, bounded set of shared values, most recently used first.
///
/// [`intern`](Self::intern) returns the shared copy of an equal value it already holds, else keeps the new one
/// (dropping the least recently used beyond [`CAPACITY`]). Lookups compare by value over at most
/// [`CAPACITY`] entries: no hashing is needed, so any `PartialEq` value can be interned.
#[derive(Debug)]
pub(crate) struct Interner<T: ?Sized> {
    values: Vec<Arc<T>>,
}

impl<T: ?Sized> Default for Interner<T> {
    fn default() -> Self {
        Interner { values: Vec::new() }
    }
}

impl<T: ?Sized + PartialEq> Interner<T> {
    /// The shared copy of `v`: an equal value held already, else `v` itself, then held.
    pub(crate) fn intern(&mut self, v: Arc<T>) -> Arc<T> {
        self.hit(&v).unwrap_or_else(|| self.keep(v))
    }

    /// The held value equal to `v`, moved to the front.
    fn hit(&mut self, v: &T) -> Option<Arc<T>> {
        let i = self.values.iter().position(|x| **x == *v)?;
        self.values[..=i].rotate_right(1);
        Some(self.values[0].clone())
    }

    /// Holds `v` in front, dropping the least recently used beyond [`CAPACITY`].
    fn keep(&mut self, v: Arc<T>) -> Arc<T> {
        self.values.truncate(CAPACITY - 1);
        self.values.insert(0, v.clone());
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_values_share_one_allocation() {
        let mut i = Interner::default();
        let a = i.intern(Arc::new(String::from("x")));
        let b = i.intern(Arc::new(String::from("x")));
        assert!(Arc::ptr_eq(&a, &b));
        let c = i.intern(Arc::new(String::from("y")));
        assert!(!Arc::ptr_eq(&a, &c));
        assert_eq!(i.values.len(), 2);
    }

    #[test]
    fn bounded_and_most_recent_kept() {
        let mut i = Interner::default();
        let first = i.intern(Arc::new(0usize));
        for n in 1..100usize {
            i.intern(Arc::new(n));
        }
        assert_eq!(i.values.len(), CAPACITY);
        // 0 was evicted long ago: a new copy is stored, not the first one.
        assert!(!Arc::ptr_eq(&first, &i.intern(Arc::new(0))));
        // The most recent ones are still shared.
        let a = i.intern(Arc::new(99));
        assert!(Arc::ptr_eq(&a, &i.intern(Arc::new(99))));
    }
}
