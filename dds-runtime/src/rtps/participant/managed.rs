//! Writers whose history their owner manages: a durability service's stand-in mirrors the history the
//! service keeps (`dcps::durability`), so that a late joiner gets an instance's kept samples and then its
//! final state, unregistration included, which a writer's own KEEP_LAST history and unregistered-instance
//! pruning would drop.

use crate::rtps::types::{EntityId, SequenceNumber};

use super::Participant;

impl Participant {
    /// Hands local writer `writer`'s history over to its owner: unregistered instances stay in it, and the
    /// owner removes changes with [`Participant::remove_change`]. Give the writer KEEP_ALL history, with a
    /// `max_samples` bound as a safety net.
    pub fn manage_history(&mut self, writer: EntityId) {
        if let Some(w) = self.writers.get_mut(&writer) {
            w.manage_history();
        }
    }

    /// Removes change `sn` from local writer `writer`'s history: late joiners no longer get it, and readers
    /// that miss it get a GAP. Whether it was there.
    pub fn remove_change(&mut self, writer: EntityId, sn: SequenceNumber) -> bool {
        self.timers_changed();
        let mut ev = std::collections::VecDeque::new();
        let removed = self
            .writers
            .get_mut(&writer)
            .is_some_and(|w| w.remove_change(sn, &mut ev));
        self.events.extend(ev);
        removed
    }
}
