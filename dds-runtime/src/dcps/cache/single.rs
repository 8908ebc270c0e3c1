//! Read/take of a cache that holds one sample, without a query: a reader taken at every sample (a
//! ping/pong, a listener that takes what it is told of) finds its one sample with one walk of the
//! instances, where the general path (`ReaderCache::collect_with`) looks the instance up four more times
//! (to emit, to mark it not new, to remove the sample, to drop an emptied instance) and sorts its picks.

use super::{emit_sample, sample_info, Instance, ReaderCache, Selection};
use crate::dcps::sample::{InstanceState, SampleInfo, ViewState};
use crate::filter::FilterFields;

impl<T: FilterFields> ReaderCache<T> {
    /// [`collect_with`](ReaderCache::collect_with) when the cache holds exactly one sample and the
    /// selection has no query; `false` (nothing done) otherwise. The sample's ranks are 0: it is the only
    /// (so the most recent) sample of its instance in the collection.
    pub(super) fn collect_single(
        &mut self,
        sel: &Selection,
        take: bool,
        emit: &mut impl FnMut(&mut Option<T>, SampleInfo),
    ) -> bool {
        if self.total != 1 || sel.query.is_some() {
            return false;
        }
        if sel.max_samples == Some(0) {
            return true;
        }
        let found = match sel.instance {
            Some(h) => self.instances.get_mut(&h).map(|i| (h, i)),
            None => self
                .instances
                .iter_mut()
                .find(|(_, i)| !i.samples.is_empty())
                .map(|(h, i)| (*h, i)),
        };
        let Some((handle, inst)) = found else {
            return true;
        };
        let Some(s) = inst.samples.front() else {
            return true;
        };
        if !Self::matches(inst, s, sel) {
            return true;
        }
        let info = sample_info(inst, s, handle, 0, s.disposed_gen + s.no_writers_gen);
        emit_sample(inst, 0, self.key_in_invalid, info, emit);
        inst.view = ViewState::NotNew;
        if take {
            inst.samples.clear();
            self.total = 0;
            if forgettable(inst) {
                self.forget_instance(handle);
            }
        }
        true
    }
}

/// An instance with no samples, no writers and not alive: nothing left to remember.
pub(super) fn forgettable<T>(i: &Instance<T>) -> bool {
    i.samples.is_empty() && i.writers.is_empty() && i.state != InstanceState::Alive
}
