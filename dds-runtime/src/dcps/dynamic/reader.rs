//! [`DynamicReader`].

use std::collections::VecDeque;
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant, SystemTime};

use crate::dcps::IncompatibleQosStatus;
use crate::qos::{DataReaderQos, DataRepresentation, History, ReaderQos};
use crate::rtps::{ChangeKind, Event, Guid, ReaderSpec, ReceivedSample};
use crate::xtypes::dynamic::{DynamicData, DynamicType};

use super::super::driver::{Endpoint, EndpointHandle, Pending};
use super::super::error::DdsResult;
use super::super::subscriber::Subscriber;
use super::super::sync::lock;
use super::DynamicTopic;

/// Samples kept for `take` when the history QoS is KEEP_ALL (the oldest are dropped past it).
const KEEP_ALL_LIMIT: usize = 4096;

/// One received change, decoded.
#[derive(Debug, Clone)]
pub struct DynamicSample {
    /// The sample (`Alive`), or the instance's key with defaults elsewhere (dispose, unregister); `None`
    /// when a key-only change carried no key payload.
    pub data: Option<DynamicData>,
    /// What the change does to its instance.
    pub kind: ChangeKind,
    /// The writer.
    pub writer: Guid,
    /// The writer's source timestamp.
    pub source_timestamp: Option<SystemTime>,
}

struct Owner {
    topic: DynamicTopic,
    _subscriber: Subscriber,
}

struct Inner {
    ty: DynamicType,
    limit: usize,
    queue: Mutex<VecDeque<ReceivedSample>>,
    data_cv: Condvar,
    matched: Mutex<Vec<Guid>>,
    incompatible: Mutex<IncompatibleQosStatus>,
}

impl Inner {
    fn push(&self, s: ReceivedSample) {
        let mut q = lock(&self.queue);
        if q.len() >= self.limit {
            q.pop_front();
        }
        q.push_back(s);
    }
}

impl Endpoint for Inner {
    fn enqueue(&self, item: Pending) {
        match item {
            Pending::Sample(s) => self.push(s),
            Pending::CoherentSet(set) => set.into_iter().for_each(|s| self.push(s)),
            Pending::WriterGone(_) => {}
        }
    }

    fn process(self: Arc<Self>) {
        self.data_cv.notify_all();
    }

    fn on_event(self: Arc<Self>, ev: &Event) {
        match ev {
            Event::SubscriptionMatched {
                writer, matched, ..
            } => super::record_match(&self.matched, *writer, *matched),
            Event::RequestedIncompatibleQos { policy, .. } => {
                lock(&self.incompatible).record(*policy)
            }
            _ => {}
        }
    }

    fn tick(self: Arc<Self>, _now: Instant) {}
}

/// Takes [`DynamicData`] samples of a [`DynamicTopic`]. Cheap to clone; deleted with its last clone.
#[derive(Clone)]
pub struct DynamicReader {
    inner: Arc<Inner>,
    handle: Arc<EndpointHandle<Owner>>,
}

impl std::fmt::Debug for DynamicReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DynamicReader")
            .field("topic", &self.handle.owner().topic.name())
            .finish()
    }
}

impl Subscriber {
    /// Creates a reader of a dynamic topic. An empty `data_representation` accepts XCDR1 and XCDR2. Samples
    /// wait for [`DynamicReader::take`] in arrival order, at most the history depth (4096 for KEEP_ALL).
    pub fn create_dynamic_reader(
        &self,
        topic: &DynamicTopic,
        qos: &DataReaderQos,
    ) -> DdsResult<DynamicReader> {
        let driver = self.participant().driver().clone();
        let mut rq = qos.clone();
        if rq.data_representation.ids().is_empty() {
            rq.data_representation = DataRepresentation::accept_both();
        }
        super::super::endpoint::check_history(&rq.history)?;
        let limit = match rq.history {
            History::KeepLast(n) => (n as usize).clamp(1, KEEP_ALL_LIMIT),
            History::KeepAll => KEEP_ALL_LIMIT,
        };
        let ty = topic.dynamic_type().clone();
        let spec = ReaderSpec {
            topic_name: topic.name().to_string(),
            type_name: topic.type_name(),
            keyed: ty.is_keyed(),
            qos: ReaderQos::new(rq, self.qos(), topic.qos()),
            type_information: topic.type_information(),
            entity_name: None,
            content_filter: None,
            internal: false,
        };
        let inner = Arc::new(Inner {
            ty,
            limit,
            queue: Mutex::new(VecDeque::new()),
            data_cv: Condvar::new(),
            matched: Mutex::new(Vec::new()),
            incompatible: Mutex::new(IncompatibleQosStatus::default()),
        });
        let sink: Arc<dyn Endpoint> = inner.clone();
        let id = driver.create_endpoint(sink, |c, now| {
            topic.register_types(c);
            c.create_reader(now, spec)
        })?;
        let owner = Owner {
            topic: topic.clone(),
            _subscriber: self.clone(),
        };
        tracing::info!(topic = topic.name(), type_name = %topic.type_name(), ?id, "dynamic reader created");
        Ok(DynamicReader {
            inner,
            handle: Arc::new(EndpointHandle::new(driver, id, owner)),
        })
    }
}

impl DynamicReader {
    /// The reader's GUID.
    pub fn guid(&self) -> Guid {
        self.handle.guid()
    }

    /// The topic.
    pub fn topic(&self) -> &DynamicTopic {
        &self.handle.owner().topic
    }

    /// The writers matched now.
    pub fn matched_writers(&self) -> Vec<Guid> {
        lock(&self.inner.matched).clone()
    }

    /// REQUESTED_INCOMPATIBLE_QOS: writers on the topic not matched for a policy (`TypeConsistencyEnforcement`
    /// for a type not assignable to the reader's). Resets the change count.
    pub fn requested_incompatible_qos_status(&self) -> IncompatibleQosStatus {
        super::take_incompatible(&self.inner.incompatible)
    }

    /// Waits until a change is waiting to be taken; `false` on timeout.
    pub fn wait_for_data(&self, timeout: Duration) -> bool {
        let end = Instant::now() + timeout;
        let mut q = lock(&self.inner.queue);
        while q.is_empty() {
            let left = end.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return false;
            }
            q = self
                .inner
                .data_cv
                .wait_timeout(q, left)
                .map_or_else(|e| e.into_inner().0, |r| r.0);
        }
        true
    }

    /// Takes every change received so far, decoded in arrival order. A payload that does not decode as the
    /// topic's type is dropped (and logged).
    pub fn take(&self) -> Vec<DynamicSample> {
        let raw: Vec<ReceivedSample> = lock(&self.inner.queue).drain(..).collect();
        raw.into_iter().filter_map(|s| self.decode(s)).collect()
    }

    fn decode(&self, s: ReceivedSample) -> Option<DynamicSample> {
        let data = match s.kind {
            ChangeKind::Alive => match DynamicData::deserialize(&self.inner.ty, &s.payload) {
                Ok(d) => Some(d),
                Err(e) => {
                    tracing::warn!(writer = ?s.writer, error = %e, "dynamic reader: undecodable sample dropped");
                    return None;
                }
            },
            _ if s.payload.len() > 4 => {
                DynamicData::deserialize_key(&self.inner.ty, &s.payload).ok()
            }
            _ => None,
        };
        Some(DynamicSample {
            data,
            kind: s.kind,
            writer: s.writer,
            source_timestamp: s
                .source_timestamp
                .and_then(|t| t.to_unix())
                .map(|d| SystemTime::UNIX_EPOCH + d),
        })
    }
}
