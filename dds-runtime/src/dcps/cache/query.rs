//! Query conditions in the reader cache: which samples a query selects, and its ORDER BY.

use std::sync::{Arc, RwLock, RwLockReadGuard};

use super::{Instance, ReaderCache, Selection, Stored, Touched};
use crate::dcps::sync::read;
use crate::filter::{ContentFilter, FilterFields};

/// A query expression shared by its condition (which may change the parameters) and the selections made
/// from it.
pub(crate) type SharedFilter = Arc<RwLock<ContentFilter>>;

/// The selection's query, read-locked for one pass over the cache.
pub(super) fn read_query(sel: &Selection) -> Option<RwLockReadGuard<'_, ContentFilter>> {
    sel.query.as_ref().map(|q| read(q))
}

impl<T: FilterFields> ReaderCache<T> {
    /// In the masks and, with a query, carrying data the query accepts.
    pub(super) fn selected(
        inst: &Instance<T>,
        s: &Stored<T>,
        sel: &Selection,
        q: Option<&ContentFilter>,
    ) -> bool {
        Self::matches(inst, s, sel)
            && q.is_none_or(|q| s.data.as_ref().is_some_and(|d| q.matches(d)))
    }

    /// Sorts the picked `(seq, touched index, sample index)` by the query's ORDER BY; the sort is stable,
    /// so equal keys keep reception order.
    pub(super) fn order_by(
        &self,
        q: Option<&ContentFilter>,
        picked: &mut [(u64, usize, usize)],
        touched: &[Touched],
    ) {
        let Some(q) = q.filter(|q| q.has_order_by()) else {
            return;
        };
        let data = |&(_, t, i): &(u64, usize, usize)| {
            self.instances
                .get(&touched[t].handle)
                .and_then(|inst| inst.samples.get(i))
                .and_then(|s| s.data.as_ref())
        };
        picked.sort_by(|a, b| match (data(a), data(b)) {
            (Some(x), Some(y)) => q.compare(x, y),
            (x, y) => x.is_some().cmp(&y.is_some()),
        });
    }
}
