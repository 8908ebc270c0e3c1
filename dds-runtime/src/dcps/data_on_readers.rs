//! DATA_ON_READERS once per delivery batch (PRESENTATION, DDS 1.4 §2.2.3.6 with §2.2.4.1): while the driver
//! feeds one batch of core events to its readers, a subscriber's `on_data_on_readers` is held back and called
//! once when every reader of the batch stored its samples, so a coherent set (a group set spanning several
//! readers included) raises it once and the listener sees all of it.

use std::cell::RefCell;
use std::sync::Arc;

use super::chain::ListenerNode;
use super::status::StatusMask;

thread_local! {
    /// While the driver feeds one batch of core events to readers: the subscribers (listener levels) that
    /// got DATA_ON_READERS, notified once each when the batch is done.
    static DATA_ON_READERS: RefCell<Option<Vec<Arc<ListenerNode>>>> = const { RefCell::new(None) };
}

/// One batch of deliveries (`Driver::after_unlock`): DATA_ON_READERS reaches each subscriber's listener
/// once for the batch, after every reader of the batch stored its samples, rather than once per reader.
/// A coherent set (a group set spanning readers included) arrives in one batch, so `on_data_on_readers`
/// fires once per set and sees all of it. Nested batches (a listener that drives the core) join the
/// outer one.
pub(crate) struct DataOnReadersBatch {
    owner: bool,
}

impl DataOnReadersBatch {
    /// Starts a batch on this thread (or joins the one running).
    pub(crate) fn start() -> Self {
        let owner = DATA_ON_READERS.with(|d| {
            let mut d = d.borrow_mut();
            d.is_none().then(|| *d = Some(Vec::new())).is_some()
        });
        DataOnReadersBatch { owner }
    }
}

impl Drop for DataOnReadersBatch {
    fn drop(&mut self) {
        if !self.owner {
            return;
        }
        let nodes = DATA_ON_READERS
            .with(|d| d.borrow_mut().take())
            .unwrap_or_default();
        for node in nodes {
            if let Some(l) = node.find(StatusMask::DATA_ON_READERS) {
                node.clear_up(node.handle, StatusMask::DATA_ON_READERS);
                l.on_data_on_readers(node.handle);
            }
        }
    }
}

/// Inside a batch: records that `node`'s DATA_ON_READERS listener is due, and returns true (the caller
/// does not call it now). Outside a batch: false.
pub(crate) fn defer_data_on_readers(node: &Arc<ListenerNode>) -> bool {
    DATA_ON_READERS.with(|d| match &mut *d.borrow_mut() {
        Some(nodes) => {
            if !nodes.iter().any(|n| Arc::ptr_eq(n, node)) {
                nodes.push(node.clone());
            }
            true
        }
        None => false,
    })
}
