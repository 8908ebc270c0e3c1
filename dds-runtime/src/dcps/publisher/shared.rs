//! Typed writes (`DataWriter::write_owned`, `write_shared`): readers of the writer's own participant
//! matched for intra-process delivery receive the sample itself, with no serialization and no decode
//! (moved to the one reader that holds the last reference, cloned for the others).
//!
//! Serialization is lazy: the sample is serialized only when something needs its bytes. That is decided
//! under the core's lock, with the write: a writer with readers on the wire or on shared memory, or a
//! durable history (late joiners), gets the bytes before the change enters its history; otherwise the
//! change carries the typed sample alone ([`Payload::local`] with length 0), and a reader that cannot take
//! the type as it is (a dynamic reader, say) serializes it when it reads the bytes.

use std::any::Any;
use std::cell::RefCell;
use std::sync::atomic::Ordering;
use std::sync::{Arc, OnceLock};
use std::time::SystemTime;

use crate::cdr::{self, ByteOrder, DdsType, XcdrVersion};
use crate::rtps::{ChangeKind, LocalSample, Payload, WriteChange};

use super::super::error::DdsResult;
use super::{wire_time, DataWriter};

/// The sample as the application handed it over.
enum Held<T> {
    Owned(T),
    Shared(Arc<T>),
}

impl<T> Held<T> {
    fn get(&self) -> &T {
        match self {
            Held::Owned(v) => v,
            Held::Shared(a) => a,
        }
    }
}

/// A written sample on its way to intra-process readers, with its serialized form once made.
struct Handover<T> {
    value: Held<T>,
    version: XcdrVersion,
    bytes: OnceLock<Payload>,
}

impl<T: DdsType + Clone> LocalSample for Handover<T> {
    fn bytes(&self) -> &[u8] {
        self.bytes.get_or_init(|| {
            let mut v = Vec::new();
            match cdr::serialize(self.value.get(), self.version, ByteOrder::NATIVE, &mut v) {
                Ok(()) => Payload::from(v),
                Err(e) => {
                    tracing::warn!(error = %e, "cannot serialize a sample written unserialized");
                    Payload::default()
                }
            }
        })
    }

    fn fits(&self, slot: &dyn Any) -> bool {
        slot.is::<Option<T>>()
    }

    fn take_into(self: Arc<Self>, slot: &mut dyn Any) {
        let Some(out) = slot.downcast_mut::<Option<T>>() else {
            return;
        };
        *out = Some(match Arc::try_unwrap(self) {
            Ok(h) => match h.value {
                Held::Owned(v) => v,
                Held::Shared(a) => Arc::unwrap_or_clone(a),
            },
            Err(shared) => shared.value.get().clone(),
        });
    }
}

impl<T: DdsType + Clone> DataWriter<T> {
    /// Publishes `sample`, handing it over: readers of this participant matched intra-process receive
    /// the sample itself (the one reader holding the last reference gets it moved, others a clone), with
    /// no serialization and no decode. It is serialized only when something needs bytes: readers in
    /// other participants or processes, or a durable writer's history.
    pub fn write_owned(&self, sample: T) -> DdsResult<()> {
        self.write_held(Held::Owned(sample), SystemTime::now())
    }

    /// Like [`write_owned`](Self::write_owned), with the given source timestamp.
    pub fn write_owned_w_timestamp(&self, sample: T, timestamp: SystemTime) -> DdsResult<()> {
        self.write_held(Held::Owned(sample), timestamp)
    }

    /// Publishes a shared `sample` without serializing it for readers of this participant (see
    /// [`write_owned`](Self::write_owned)); each of them gets a clone, or the sample itself when the
    /// application and the other readers have let go of it.
    pub fn write_shared(&self, sample: Arc<T>) -> DdsResult<()> {
        self.write_held(Held::Shared(sample), SystemTime::now())
    }

    fn write_held(&self, value: Held<T>, timestamp: SystemTime) -> DdsResult<()> {
        let key_hash = self.written_instance(value.get())?;
        let h = Arc::new(Handover {
            value,
            version: self.inner.fixed.version(),
            bytes: OnceLock::new(),
        });
        let needed = &self.inner.bytes_needed;
        // Serialize before taking the lock when the last typed write needed the bytes (the common case
        // with remote readers); the core decides again under its lock.
        if needed.load(Ordering::Relaxed) {
            self.serialize_into(&h)?;
        }
        let source_timestamp = Some(wire_time(timestamp));
        let id = self.id();
        // The writer lets go of the sample inside a successful write, under the core's lock, so that the
        // one intra-process reader (decoding after the lock is released) can have it moved.
        let held = RefCell::new(Some(h));
        let mut attempt = |c: &mut crate::rtps::Participant, now| {
            let h = held.borrow_mut().take()?;
            let needs = c.writer_needs_bytes(id);
            needed.store(needs, Ordering::Relaxed);
            let len = match h.bytes.get() {
                Some(p) => p.len(),
                None if needs => {
                    *held.borrow_mut() = Some(h);
                    return None;
                }
                None => 0,
            };
            let rejected = self.rejected_by_filters(c, Some(h.value.get()));
            let change = WriteChange {
                kind: ChangeKind::Alive,
                payload: Payload::local(h.clone(), len),
                key_hash,
                source_timestamp,
            };
            let r = c.write_filtered(now, id, change, rejected);
            if r.is_err() {
                *held.borrow_mut() = Some(h);
            }
            Some(r)
        };
        tracing::trace!(writer = ?id, "write (typed)");
        let prepare = || match held.borrow().as_ref() {
            Some(h) => self.serialize_into(h),
            None => Ok(()),
        };
        self.submit_with(&mut attempt, prepare).map(drop)
    }

    /// Serializes the hand-over's sample into a buffer of the writer's pool (errors reported here, as
    /// `write` reports them).
    fn serialize_into(&self, h: &Handover<T>) -> DdsResult<()> {
        if h.bytes.get().is_none() {
            let p = self.serialize(h.value.get())?;
            let _ = h.bytes.set(p);
        }
        Ok(())
    }
}
