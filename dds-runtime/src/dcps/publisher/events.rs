//! A writer's statuses, whatever its kind: one handling of the core's writer events and of the offered
//! deadline, which raises the statuses and calls the listener, for [`DataWriter<T>`](super::DataWriter) and
//! [`DynamicWriter`](crate::dcps::DynamicWriter) alike.

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime};

use crate::qos::{ChangeableQos, DataWriterQos, QosPolicyId};
use crate::rtps::{ChangeKind, Event, Payload, WriteChange};

use super::super::driver::EndpointHandle;
use super::super::endpoint::EndpointState;
use super::super::error::{DdsError, DdsResult};
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

/// The instances a writer knows, whatever its kind: each by its serialized key (`instance_key` output), with
/// the key payload (`serialize_key` output) and key hash that dispose, unregister and the deleted writer's
/// farewell send.
impl WriterInstances {
    /// The instance with serialized key `key` and its key hash, if registered; with `written`, records a
    /// write at that time (for the offered deadline).
    pub(crate) fn lookup(
        &mut self,
        key: &[u8],
        written: Option<Instant>,
    ) -> Option<(InstanceHandle, Option<[u8; 16]>)> {
        let found = match &self.last {
            (k, Some(found)) if k.as_slice() == key => *found,
            _ => {
                let found = self.by_key.get(key).copied()?;
                self.last.0.clear();
                self.last.0.extend_from_slice(key);
                self.last.1 = Some(found);
                found
            }
        };
        if let Some(now) = written {
            self.by_handle.get_mut(&found.0)?.last_write = now;
        }
        Some(found)
    }

    /// Registers the instance with serialized key `key` (or returns it, when another thread registered it
    /// first); `key_payload` and `key_hash` are what its key-only changes carry.
    pub(crate) fn register(
        &mut self,
        key: Vec<u8>,
        key_payload: Payload,
        key_hash: Option<[u8; 16]>,
        now: Instant,
    ) -> (InstanceHandle, Option<[u8; 16]>) {
        if let Some(found) = self.lookup(&key, None) {
            return found;
        }
        self.next += 1;
        let h = InstanceHandle(self.next);
        self.by_key.insert(key.clone(), (h, key_hash));
        self.by_handle.insert(
            h,
            super::WriterInstance {
                key,
                key_payload,
                key_hash,
                last_write: now,
            },
        );
        (h, key_hash)
    }

    /// Counts every instance's offered deadline from `now` (a deadline set by `set_qos` counts from then).
    pub(crate) fn restart_deadlines(&mut self, now: Instant) {
        self.by_handle.values_mut().for_each(|i| i.last_write = now);
        if self.keyless_last_write.is_some() {
            self.keyless_last_write = Some(now);
        }
    }

    /// Records a write of the single instance of a keyless topic at `now`.
    pub(crate) fn keyless_written(&mut self, now: Instant) {
        self.keyless_last_write = Some(now);
    }

    /// The key-only change of `kind` (dispose, unregister) for the instance `h` with source timestamp `ts`;
    /// `BadParameter` for an instance not registered.
    pub(crate) fn key_change(
        &self,
        h: InstanceHandle,
        kind: ChangeKind,
        ts: SystemTime,
    ) -> DdsResult<WriteChange> {
        let i = self
            .by_handle
            .get(&h)
            .ok_or_else(|| DdsError::BadParameter(format!("unknown instance handle {h:?}")))?;
        Ok(WriteChange {
            kind,
            payload: i.key_payload.clone(),
            key_hash: i.key_hash,
            source_timestamp: Some(super::wire_time(ts)),
        })
    }

    /// After a key-only change of `kind` was sent for `h`: an unregistered instance is forgotten.
    pub(crate) fn key_change_sent(&mut self, h: InstanceHandle, kind: ChangeKind) {
        if matches!(kind, ChangeKind::Unregister | ChangeKind::DisposeUnregister) {
            if let Some(i) = self.by_handle.remove(&h) {
                self.by_key.remove(&i.key);
                if self.last.1.is_some_and(|(l, _)| l == h) {
                    self.last.1 = None;
                }
            }
        }
    }

    /// The key payload of the instance `h` (`get_key_value`); `BadParameter` for an unknown handle.
    pub(crate) fn key_payload(&self, h: InstanceHandle) -> DdsResult<Payload> {
        self.by_handle
            .get(&h)
            .map(|i| i.key_payload.clone())
            .ok_or_else(|| DdsError::BadParameter(format!("unknown instance handle {h:?}")))
    }

    /// What a deleted writer sends (DDS 1.4 §2.2.2.4.1.6): an unregister of every instance it knows, not a
    /// dispose, whatever `autodispose_unregistered_instances` says (as Cyclone DDS does; it leaves
    /// TRANSIENT data to the durability service).
    pub(crate) fn farewell(&self) -> Vec<WriteChange> {
        let ts = Some(super::wire_time(SystemTime::now()));
        self.by_handle
            .values()
            .map(|i| WriteChange {
                kind: ChangeKind::Unregister,
                payload: i.key_payload.clone(),
                key_hash: i.key_hash,
                source_timestamp: ts,
            })
            .collect()
    }
}

/// Whether `qos` offers a deadline (a finite, non-zero DEADLINE period).
pub(crate) fn offers_deadline(qos: &DataWriterQos) -> bool {
    let period = qos.deadline.0;
    period != crate::qos::INFINITE && !period.is_zero()
}

/// The change an unregister makes with these QoS: a dispose too with `autodispose_unregistered_instances`.
pub(crate) fn unregister_kind(qos: &DataWriterQos) -> ChangeKind {
    if qos.writer_data_lifecycle.autodispose_unregistered_instances {
        ChangeKind::DisposeUnregister
    } else {
        ChangeKind::Unregister
    }
}

/// The QoS `set_qos(qos)` asks for over `current` (an empty data representation keeps the current one),
/// and the first immutable policy it changes, if any.
pub(crate) fn requested_qos(
    current: &DataWriterQos,
    qos: &DataWriterQos,
) -> (DataWriterQos, Option<QosPolicyId>) {
    let mut new = qos.clone();
    if new.data_representation.ids().is_empty() {
        new.data_representation = current.data_representation.clone();
    }
    let immutable = current.immutable_change(&new);
    (new, immutable)
}
