//! A writer's statuses, whatever its kind: one handling of the core's writer events and of the offered
//! deadline, which raises the statuses and calls the listener, for [`DataWriter<T>`](super::DataWriter) and
//! [`DynamicWriter`](crate::dcps::DynamicWriter) alike.

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::rtps::Event;

use super::super::driver::EndpointHandle;
use super::super::endpoint::EndpointState;
use super::super::sample::InstanceHandle;
use super::super::status::{
    DeadlineMissedStatus, IncompatibleQosStatus, LivelinessLostStatus, PublicationMatchedStatus,
    StatusMask, WriterStatuses,
};
use super::super::sync::lock;
use super::WriterInstances;

/// A writer's statuses read by the application (each resets its change counts), for both kinds.
impl<L: ?Sized, O> EndpointState<WriterStatuses, L, O> {
    pub(crate) fn publication_matched_status(&self) -> PublicationMatchedStatus {
        self.take_status(StatusMask::PUBLICATION_MATCHED, |s| {
            &mut s.publication_matched
        })
    }

    pub(crate) fn offered_incompatible_qos_status(&self) -> IncompatibleQosStatus {
        self.take_status(StatusMask::OFFERED_INCOMPATIBLE_QOS, |s| {
            &mut s.offered_incompatible_qos
        })
    }

    pub(crate) fn offered_deadline_missed_status(&self) -> DeadlineMissedStatus {
        self.take_status(StatusMask::OFFERED_DEADLINE_MISSED, |s| {
            &mut s.offered_deadline_missed
        })
    }

    pub(crate) fn liveliness_lost_status(&self) -> LivelinessLostStatus {
        self.take_status(StatusMask::LIVELINESS_LOST, |s| &mut s.liveliness_lost)
    }
}

/// The calls a writer makes on its listener, whatever the listener trait (`W` is the public writer).
pub(crate) trait WriterCallbacks<W> {
    fn publication_matched(&self, w: &W, s: PublicationMatchedStatus);
    fn offered_incompatible_qos(&self, w: &W, s: IncompatibleQosStatus);
    fn offered_deadline_missed(&self, w: &W, s: DeadlineMissedStatus);
    fn liveliness_lost(&self, w: &W, s: LivelinessLostStatus);
}

/// Implements [`WriterCallbacks`] for a listener trait object whose methods have the standard names.
macro_rules! writer_callbacks {
    ($(@$g:ident: $b:path;)? $listener:ty, $writer:ty) => {
        impl$(<$g: $b>)? $crate::dcps::publisher::WriterCallbacks<$writer> for $listener {
            fn publication_matched(&self, w: &$writer, s: $crate::dcps::PublicationMatchedStatus) {
                self.on_publication_matched(w, s)
            }
            fn offered_incompatible_qos(&self, w: &$writer, s: $crate::dcps::IncompatibleQosStatus) {
                self.on_offered_incompatible_qos(w, s)
            }
            fn offered_deadline_missed(&self, w: &$writer, s: $crate::dcps::DeadlineMissedStatus) {
                self.on_offered_deadline_missed(w, s)
            }
            fn liveliness_lost(&self, w: &$writer, s: $crate::dcps::LivelinessLostStatus) {
                self.on_liveliness_lost(w, s)
            }
        }
    };
}
pub(crate) use writer_callbacks;

/// A writer's status state: `L` its listener trait object, `O` what its handle keeps alive.
pub(crate) type WriterState<L, O> = EndpointState<WriterStatuses, L, O>;

/// Raises the statuses of a core event for a writer; `writer` makes the public writer for the listener.
pub(crate) fn on_writer_event<L, O, W, F>(
    state: &WriterState<L, O>,
    ev: &Event,
    writer: impl Fn() -> F,
) where
    L: ?Sized + WriterCallbacks<W>,
    F: FnOnce(Arc<EndpointHandle<O>>) -> W,
{
    let id = state.id();
    match ev {
        Event::PublicationMatched {
            reader, matched, ..
        } => {
            tracing::info!(writer = ?id, ?reader, matched, "publication matched");
            state.record_match(
                StatusMask::PUBLICATION_MATCHED,
                |st| &mut st.publication_matched,
                (*reader, *matched),
                writer(),
                |l, w, s| l.publication_matched(w, s),
            );
        }
        Event::OfferedIncompatibleQos { policy, reader, .. } => {
            tracing::warn!(writer = ?id, ?reader, ?policy, "offered incompatible QoS");
            state.signal(
                StatusMask::OFFERED_INCOMPATIBLE_QOS,
                |st| {
                    st.offered_incompatible_qos.record(*policy);
                    &mut st.offered_incompatible_qos
                },
                writer(),
                |l, w, s| l.offered_incompatible_qos(w, s),
            );
        }
        Event::LivelinessLost { .. } => {
            tracing::info!(writer = ?id, "liveliness lost");
            state.signal_consumed(
                StatusMask::LIVELINESS_LOST,
                |st| {
                    st.liveliness_lost.record();
                    &mut st.liveliness_lost
                },
                writer(),
                |l, w, s| l.liveliness_lost(w, s),
            );
        }
        _ => {}
    }
}

/// Checks the offered deadline (`period`) of every instance in `instances` at `now` and raises
/// OFFERED_DEADLINE_MISSED for those not written within it.
pub(crate) fn check_offered_deadline<L, O, W>(
    state: &WriterState<L, O>,
    instances: &Mutex<WriterInstances>,
    period: Duration,
    now: Instant,
    writer: impl FnOnce(Arc<EndpointHandle<O>>) -> W,
) where
    L: ?Sized + WriterCallbacks<W>,
{
    if period == crate::qos::INFINITE || period.is_zero() {
        return;
    }
    let missed = lock(instances).missed_deadlines(period, now);
    if missed.is_empty() {
        return;
    }
    state.signal_consumed(
        StatusMask::OFFERED_DEADLINE_MISSED,
        |st| {
            st.offered_deadline_missed.record(&missed);
            &mut st.offered_deadline_missed
        },
        writer,
        |l, w, s| l.offered_deadline_missed(w, s),
    );
}

impl WriterInstances {
    /// The instances not written within `period` before `now` (their deadline restarts now).
    fn missed_deadlines(&mut self, period: Duration, now: Instant) -> Vec<InstanceHandle> {
        let mut missed = Vec::new();
        for (h, i) in self.by_handle.iter_mut() {
            if now.saturating_duration_since(i.last_write) >= period {
                i.last_write = now;
                missed.push(*h);
            }
        }
        if let Some(t) = self.keyless_last_write.as_mut() {
            if now.saturating_duration_since(*t) >= period {
                *t = now;
                missed.push(InstanceHandle::NIL);
            }
        }
        missed
    }
}

impl WriterInstances {
    /// Records a write at `now`, for the offered deadline, of the instance with key hash `key_hash`
    /// (`None`: the single instance of a keyless topic), known from then on by its key hash.
    pub(crate) fn record_hashed_write(&mut self, key_hash: Option<[u8; 16]>, now: Instant) {
        let Some(kh) = key_hash else {
            self.keyless_last_write = Some(now);
            return;
        };
        if let Some(i) = self
            .by_key
            .get(kh.as_slice())
            .and_then(|h| self.by_handle.get_mut(h))
        {
            i.last_write = now;
            return;
        }
        self.next += 1;
        let h = InstanceHandle(self.next);
        self.by_key.insert(kh.to_vec(), h);
        self.by_handle.insert(
            h,
            super::WriterInstance {
                key: kh.to_vec(),
                key_payload: crate::rtps::Payload::default(),
                key_hash: Some(kh),
                last_write: now,
            },
        );
    }
}
