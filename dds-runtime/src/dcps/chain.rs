//! The listener chain of DDS 1.4 §2.2.4.1: a status of a reader or writer goes to the most specific
//! listener enabled for it, the entity's own, else its publisher's or subscriber's, else its participant's;
//! DATA_ON_READERS (subscriber, then participant) takes precedence over DATA_AVAILABLE.
//!
//! This module knows no entity type: the levels above a reader or writer are [`ListenerNode`]s holding a
//! type-erased [`ParentListener`], which the entity modules build from the public listener traits.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use super::condition::StatusCore;
use super::sample::InstanceHandle;
use super::status::*;
use super::sync::lock;

/// A status change of one entity, as the listeners of the levels above it receive it.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum StatusChange {
    /// PUBLICATION_MATCHED of a writer.
    PublicationMatched(PublicationMatchedStatus),
    /// OFFERED_INCOMPATIBLE_QOS of a writer.
    OfferedIncompatibleQos(IncompatibleQosStatus),
    /// OFFERED_DEADLINE_MISSED of a writer.
    OfferedDeadlineMissed(DeadlineMissedStatus),
    /// LIVELINESS_LOST of a writer.
    LivelinessLost(LivelinessLostStatus),
    /// SUBSCRIPTION_MATCHED of a reader.
    SubscriptionMatched(SubscriptionMatchedStatus),
    /// REQUESTED_INCOMPATIBLE_QOS of a reader.
    RequestedIncompatibleQos(IncompatibleQosStatus),
    /// REQUESTED_DEADLINE_MISSED of a reader.
    RequestedDeadlineMissed(DeadlineMissedStatus),
    /// SAMPLE_LOST of a reader.
    SampleLost(SampleLostStatus),
    /// SAMPLE_REJECTED of a reader.
    SampleRejected(SampleRejectedStatus),
    /// LIVELINESS_CHANGED of a reader.
    LivelinessChanged(LivelinessChangedStatus),
    /// DATA_AVAILABLE of a reader.
    DataAvailable,
    /// INCONSISTENT_TOPIC of a topic.
    InconsistentTopic(InconsistentTopicStatus),
}

impl StatusChange {
    /// The status kind.
    pub fn kind(&self) -> StatusMask {
        match self {
            StatusChange::PublicationMatched(_) => StatusMask::PUBLICATION_MATCHED,
            StatusChange::OfferedIncompatibleQos(_) => StatusMask::OFFERED_INCOMPATIBLE_QOS,
            StatusChange::OfferedDeadlineMissed(_) => StatusMask::OFFERED_DEADLINE_MISSED,
            StatusChange::LivelinessLost(_) => StatusMask::LIVELINESS_LOST,
            StatusChange::SubscriptionMatched(_) => StatusMask::SUBSCRIPTION_MATCHED,
            StatusChange::RequestedIncompatibleQos(_) => StatusMask::REQUESTED_INCOMPATIBLE_QOS,
            StatusChange::RequestedDeadlineMissed(_) => StatusMask::REQUESTED_DEADLINE_MISSED,
            StatusChange::SampleLost(_) => StatusMask::SAMPLE_LOST,
            StatusChange::SampleRejected(_) => StatusMask::SAMPLE_REJECTED,
            StatusChange::LivelinessChanged(_) => StatusMask::LIVELINESS_CHANGED,
            StatusChange::DataAvailable => StatusMask::DATA_AVAILABLE,
            StatusChange::InconsistentTopic(_) => StatusMask::INCONSISTENT_TOPIC,
        }
    }
}

/// A status type that the chain can hand to a level above its entity.
pub(crate) trait ErasedStatus: Status {
    /// The change for status kind `mask` (some types serve two kinds), `None` for no known kind.
    fn erase(&self, mask: StatusMask) -> Option<StatusChange>;
}

macro_rules! erased {
    ($ty:ty { $($mask:ident => $variant:ident),* }) => {
        impl ErasedStatus for $ty {
            fn erase(&self, mask: StatusMask) -> Option<StatusChange> {
                $(if mask == StatusMask::$mask {
                    return Some(StatusChange::$variant(self.clone()));
                })*
                None
            }
        }
    };
}

erased!(PublicationMatchedStatus { PUBLICATION_MATCHED => PublicationMatched });
erased!(SubscriptionMatchedStatus { SUBSCRIPTION_MATCHED => SubscriptionMatched });
erased!(IncompatibleQosStatus {
    OFFERED_INCOMPATIBLE_QOS => OfferedIncompatibleQos,
    REQUESTED_INCOMPATIBLE_QOS => RequestedIncompatibleQos
});
erased!(DeadlineMissedStatus {
    OFFERED_DEADLINE_MISSED => OfferedDeadlineMissed,
    REQUESTED_DEADLINE_MISSED => RequestedDeadlineMissed
});
erased!(SampleLostStatus { SAMPLE_LOST => SampleLost });
erased!(SampleRejectedStatus { SAMPLE_REJECTED => SampleRejected });
erased!(LivelinessChangedStatus { LIVELINESS_CHANGED => LivelinessChanged });
erased!(LivelinessLostStatus { LIVELINESS_LOST => LivelinessLost });
erased!(InconsistentTopicStatus { INCONSISTENT_TOPIC => InconsistentTopic });

/// A listener of a level above a reader or writer (publisher, subscriber, participant), type-erased.
pub(crate) trait ParentListener: Send + Sync {
    /// Delivers a status change of the entity `entity` below this level.
    fn on_status(&self, entity: InstanceHandle, change: StatusChange);
    /// DATA_ON_READERS of the subscriber `subscriber` (this listener's, or one in its participant).
    fn on_data_on_readers(&self, subscriber: InstanceHandle);
}

type Slot = Option<(Arc<dyn ParentListener>, StatusMask)>;

/// The statuses of each of a level's two pending lists: the data statuses, then all others.
const PART: [StatusMask; 2] = [
    StatusMask::DATA_AVAILABLE.union(StatusMask::DATA_ON_READERS),
    StatusMask::all()
        .difference(StatusMask::DATA_AVAILABLE)
        .difference(StatusMask::DATA_ON_READERS),
];

/// One level of the chain: its listener with its mask, its status condition, and the level above.
pub(crate) struct ListenerNode {
    /// The entity of this level.
    pub(crate) handle: InstanceHandle,
    slot: Mutex<Slot>,
    /// Cheap check on the data path: whether a listener is installed.
    any: AtomicBool,
    /// The status condition of this level's entity.
    pub(crate) status: Arc<StatusCore>,
    /// The statuses raised on this level and not read yet, by the entity they belong to (this level's
    /// own, or one it contains): a bit of `status` is cleared only when no entity still has it pending.
    /// Two lists, by [`PART`]: the data statuses, raised and cleared per sample, are looked up among the
    /// few readers with unread data, not among every entity with a status never read.
    pending: [Mutex<Vec<(InstanceHandle, StatusMask)>>; 2],
    parent: Option<Arc<ListenerNode>>,
}

impl ListenerNode {
    /// A level with no listener under `parent` (`None` for the participant).
    pub(crate) fn new(
        handle: InstanceHandle,
        status: Arc<StatusCore>,
        parent: Option<Arc<ListenerNode>>,
    ) -> Self {
        ListenerNode {
            handle,
            slot: Mutex::new(None),
            any: AtomicBool::new(false),
            status,
            pending: [Mutex::new(Vec::new()), Mutex::new(Vec::new())],
            parent,
        }
    }

    /// Installs (or with `None` removes) this level's listener.
    pub(crate) fn set_listener(&self, l: Option<(Arc<dyn ParentListener>, StatusMask)>) {
        let mut s = lock(&self.slot);
        self.any.store(l.is_some(), Ordering::Release);
        *s = l;
    }

    /// This level's listener if it is enabled for `kind`.
    fn enabled(&self, kind: StatusMask) -> Option<Arc<dyn ParentListener>> {
        if !self.any.load(Ordering::Acquire) {
            return None;
        }
        match &*lock(&self.slot) {
            Some((l, m)) if m.contains(kind) => Some(l.clone()),
            _ => None,
        }
    }

    /// The nearest listener at this level or above enabled for `kind`.
    pub(crate) fn find(self: &Arc<Self>, kind: StatusMask) -> Option<Arc<dyn ParentListener>> {
        let mut node = Some(self);
        while let Some(n) = node {
            if let Some(l) = n.enabled(kind) {
                return Some(l);
            }
            node = n.parent.as_ref();
        }
        None
    }

    /// Raises `kind`, a status of the entity `source` (this level's or one it contains), on the status
    /// conditions of this level and every level above: a publisher's, subscriber's or participant's
    /// condition triggers when a status of an entity it contains changes.
    pub(crate) fn raise_up(&self, source: InstanceHandle, kind: StatusMask) {
        self.raise_all_up(&[(source, kind)]);
    }

    /// [`raise_up`](Self::raise_up) for each `(source, kind)` of `changes`, in one pass over the levels
    /// (the data path raises two statuses per sample).
    pub(crate) fn raise_all_up(&self, changes: &[(InstanceHandle, StatusMask)]) {
        let all = changes
            .iter()
            .fold(StatusMask::empty(), |acc, (_, k)| acc | *k);
        let mut node = Some(self);
        while let Some(n) = node {
            for (list, part) in n.pending.iter().zip(PART) {
                if !all.intersects(part) {
                    continue;
                }
                let mut p = lock(list);
                for &(source, kind) in changes {
                    let kind = kind & part;
                    if kind.is_empty() {
                        continue;
                    }
                    match p.iter_mut().find(|(h, _)| *h == source) {
                        Some((_, m)) => *m |= kind,
                        None => p.push((source, kind)),
                    }
                }
            }
            n.status.raise_new(all);
            node = n.parent.as_deref();
        }
    }

    /// The application read `kind` of the entity `source`: clears it on this level and every level above,
    /// except where another entity still has it pending (reading one writer's status leaves its
    /// publisher's condition raised for a sibling's).
    pub(crate) fn clear_up(&self, source: InstanceHandle, kind: StatusMask) {
        self.clear_all_up(&[(source, kind)]);
    }

    /// [`clear_up`](Self::clear_up) for each `(source, kind)` of `changes`, in one pass over the levels.
    pub(crate) fn clear_all_up(&self, changes: &[(InstanceHandle, StatusMask)]) {
        let all = changes
            .iter()
            .fold(StatusMask::empty(), |acc, (_, k)| acc | *k);
        let mut node = Some(self);
        while let Some(n) = node {
            let mut still = StatusMask::empty();
            for (list, part) in n.pending.iter().zip(PART) {
                if !all.intersects(part) {
                    continue;
                }
                lock(list).retain_mut(|(h, m)| {
                    for &(source, kind) in changes {
                        if *h == source {
                            m.remove(kind);
                        }
                    }
                    still |= *m;
                    !m.is_empty()
                });
            }
            n.status.clear(all - still);
            node = n.parent.as_deref();
        }
    }

    /// Forgets what the entity `source` (deleted) had pending, as if it had been read.
    pub(crate) fn forget(&self, source: InstanceHandle) {
        self.clear_up(source, StatusMask::all());
    }
}

/// A listener and its status mask, as an entity keeps its own.
pub(crate) struct MaskedListener<L: ?Sized> {
    pub(crate) listener: Arc<L>,
    pub(crate) mask: StatusMask,
}

impl<L: ?Sized> Clone for MaskedListener<L> {
    fn clone(&self) -> Self {
        MaskedListener {
            listener: self.listener.clone(),
            mask: self.mask,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_status_stays_pending_while_any_entity_has_it() {
        let core = Arc::new(StatusCore::default());
        let node = ListenerNode::new(InstanceHandle(1), core.clone(), None);
        let (a, b) = (InstanceHandle(7), InstanceHandle(3));
        let da = StatusMask::DATA_AVAILABLE;
        node.raise_all_up(&[(a, da), (node.handle, StatusMask::DATA_ON_READERS)]);
        node.raise_up(b, da | StatusMask::SAMPLE_LOST);
        node.raise_up(b, da);
        assert_eq!(
            core.changed(),
            da | StatusMask::DATA_ON_READERS | StatusMask::SAMPLE_LOST
        );
        node.clear_all_up(&[(a, da), (node.handle, StatusMask::DATA_ON_READERS)]);
        assert_eq!(
            core.changed(),
            da | StatusMask::SAMPLE_LOST,
            "b still has DATA_AVAILABLE"
        );
        node.clear_up(a, da);
        assert_eq!(
            core.changed(),
            da | StatusMask::SAMPLE_LOST,
            "clearing twice is harmless"
        );
        node.clear_up(b, da);
        assert_eq!(core.changed(), StatusMask::SAMPLE_LOST);
        node.forget(b);
        assert_eq!(core.changed(), StatusMask::empty());
        assert!(node.pending.iter().all(|p| lock(p).is_empty()));
    }
}
