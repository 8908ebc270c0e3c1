//! [`DynamicWriter`].

use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant, SystemTime};

use crate::cdr::{ByteOrder, XcdrVersion};
use crate::dcps::IncompatibleQosStatus;
use crate::qos::{DataWriterQos, Reliability, WriterQos, XCDR2_DATA_REPRESENTATION};
use crate::rtps::{ChangeKind, Event, Guid, Payload, Time, WriteChange, WriteError, WriterSpec};
use crate::xtypes::dynamic::{default_version, DynamicData};

use super::super::driver::{Endpoint, EndpointHandle};
use super::super::error::{DdsError, DdsResult};
use super::super::publisher::Publisher;
use super::super::sync::lock;
use super::DynamicTopic;

struct Owner {
    topic: DynamicTopic,
    _publisher: Publisher,
}

struct Inner {
    version: XcdrVersion,
    max_block: Duration,
    matched: Mutex<Vec<Guid>>,
    matched_cv: Condvar,
    incompatible: Mutex<IncompatibleQosStatus>,
}

impl Endpoint for Inner {
    fn on_event(self: Arc<Self>, ev: &Event) {
        match ev {
            Event::PublicationMatched {
                reader, matched, ..
            } => {
                super::record_match(&self.matched, *reader, *matched);
                self.matched_cv.notify_all();
            }
            Event::OfferedIncompatibleQos { policy, .. } => {
                lock(&self.incompatible).record(*policy)
            }
            _ => {}
        }
    }

    fn tick(self: Arc<Self>, _now: Instant) {}
}

/// Writes [`DynamicData`] samples of a [`DynamicTopic`]. Cheap to clone; deleted with its last clone.
#[derive(Clone)]
pub struct DynamicWriter {
    inner: Arc<Inner>,
    handle: Arc<EndpointHandle<Owner>>,
}

impl std::fmt::Debug for DynamicWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DynamicWriter")
            .field("topic", &self.handle.owner().topic.name())
            .finish()
    }
}

impl Publisher {
    /// Creates a writer of a dynamic topic. An empty `data_representation` means the type's default (XCDR1 for
    /// @final types without optional members, else XCDR2), as for typed writers.
    pub fn create_dynamic_writer(
        &self,
        topic: &DynamicTopic,
        qos: &DataWriterQos,
    ) -> DdsResult<DynamicWriter> {
        let driver = self.participant().driver().clone();
        let ty = topic.dynamic_type();
        let mut wq = qos.clone();
        let version = if wq.data_representation.ids().is_empty() {
            let v = default_version(ty);
            wq.data_representation = v.into();
            v
        } else if wq.data_representation.offered() == XCDR2_DATA_REPRESENTATION {
            XcdrVersion::Xcdr2
        } else {
            XcdrVersion::Xcdr1
        };
        super::super::endpoint::check_history(&wq.history)?;
        let max_block = match wq.reliability {
            Reliability::Reliable { max_blocking_time } => max_blocking_time,
            Reliability::BestEffort => Duration::ZERO,
        };
        let spec = WriterSpec {
            topic_name: topic.name().to_string(),
            type_name: topic.type_name(),
            keyed: ty.is_keyed(),
            qos: WriterQos::new(wq, self.qos(), topic.qos()),
            type_information: topic.type_information(),
            entity_name: None,
            content_filter: None,
            internal: false,
        };
        let inner = Arc::new(Inner {
            version,
            max_block,
            matched: Mutex::new(Vec::new()),
            matched_cv: Condvar::new(),
            incompatible: Mutex::new(IncompatibleQosStatus::default()),
        });
        let sink: Arc<dyn Endpoint> = inner.clone();
        let id = driver.create_endpoint(sink, |c, now| {
            topic.register_types(c);
            c.create_writer(now, spec)
        })?;
        let owner = Owner {
            topic: topic.clone(),
            _publisher: self.clone(),
        };
        tracing::info!(topic = topic.name(), type_name = %topic.type_name(), ?id, ?version, "dynamic writer created");
        Ok(DynamicWriter {
            inner,
            handle: Arc::new(EndpointHandle::new(driver, id, owner)),
        })
    }
}

fn wire_time(t: SystemTime) -> Time {
    Time::from_unix(t.duration_since(SystemTime::UNIX_EPOCH).unwrap_or_default())
}

impl DynamicWriter {
    /// The writer's GUID.
    pub fn guid(&self) -> Guid {
        self.handle.guid()
    }

    /// The topic.
    pub fn topic(&self) -> &DynamicTopic {
        &self.handle.owner().topic
    }

    /// The XCDR version samples are written with.
    pub fn data_representation(&self) -> XcdrVersion {
        self.inner.version
    }

    /// The readers matched now.
    pub fn matched_readers(&self) -> Vec<Guid> {
        lock(&self.inner.matched).clone()
    }

    /// OFFERED_INCOMPATIBLE_QOS: readers on the topic not matched for a policy (`TypeConsistencyEnforcement`
    /// for a reader type not assignable from the writer's). Resets the change count.
    pub fn offered_incompatible_qos_status(&self) -> IncompatibleQosStatus {
        super::take_incompatible(&self.inner.incompatible)
    }

    /// Waits until at least `n` readers are matched; `false` on timeout.
    pub fn wait_for_readers(&self, n: usize, timeout: Duration) -> bool {
        let end = Instant::now() + timeout;
        let mut m = lock(&self.inner.matched);
        while m.len() < n {
            let left = end.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return false;
            }
            m = self
                .inner
                .matched_cv
                .wait_timeout(m, left)
                .map_or_else(|e| e.into_inner().0, |r| r.0);
        }
        true
    }

    /// Waits until every matched reliable reader acknowledged everything written; `Timeout` past `timeout`.
    pub fn wait_for_acknowledgments(&self, timeout: Duration) -> DdsResult<()> {
        self.handle_driver()
            .wait_acknowledged(self.handle.id(), timeout)
    }

    fn check_type(&self, sample: &DynamicData) -> DdsResult<()> {
        if sample.dynamic_type() != self.topic().dynamic_type() {
            return Err(DdsError::BadParameter(format!(
                "a sample of {} for a writer of {}",
                sample.dynamic_type().name(),
                self.topic().type_name()
            )));
        }
        Ok(())
    }

    /// Publishes `sample` (of the topic's type) with the current time as source timestamp.
    pub fn write(&self, sample: &DynamicData) -> DdsResult<()> {
        self.check_type(sample)?;
        let mut buf = Vec::new();
        sample.serialize(self.inner.version, ByteOrder::NATIVE, &mut buf)?;
        self.submit(ChangeKind::Alive, sample, buf)
    }

    /// Disposes the instance of `sample` (keyed types only).
    pub fn dispose(&self, sample: &DynamicData) -> DdsResult<()> {
        self.check_type(sample)?;
        if !sample.dynamic_type().is_keyed() {
            return Err(DdsError::PreconditionNotMet("the topic type has no key"));
        }
        let mut buf = Vec::new();
        sample.serialize_key(self.inner.version, ByteOrder::NATIVE, &mut buf)?;
        self.submit(ChangeKind::Dispose, sample, buf)
    }

    fn submit(&self, kind: ChangeKind, sample: &DynamicData, payload: Vec<u8>) -> DdsResult<()> {
        let key_hash = if sample.dynamic_type().is_keyed() {
            Some(sample.key_hash(self.inner.version)?)
        } else {
            None
        };
        let change = WriteChange {
            kind,
            payload: Payload::from(payload),
            key_hash,
            source_timestamp: Some(wire_time(SystemTime::now())),
        };
        let driver = &self.handle_driver();
        let id = self.handle.id();
        let deadline = Instant::now() + self.inner.max_block;
        loop {
            driver.check_alive()?;
            let seen = driver.progress_generation();
            match driver.with_core_writing(|c, now| c.write(now, id, change.clone())) {
                Ok(_) => return Ok(()),
                Err(WriteError::WouldBlock) if Instant::now() < deadline => {
                    driver.wait_progress_change(seen, deadline)
                }
                Err(WriteError::WouldBlock) => return Err(DdsError::Timeout),
                Err(WriteError::Deleted) | Err(WriteError::UnknownWriter(_)) => {
                    return Err(DdsError::AlreadyDeleted)
                }
                Err(e) => return Err(DdsError::Write(e)),
            }
        }
    }

    fn handle_driver(&self) -> Arc<super::super::driver::Driver> {
        self.handle.owner().topic.participant().driver().clone()
    }
}
