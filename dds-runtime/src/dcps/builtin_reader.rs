//! The readers of the built-in subscriber (DDS 1.4 §2.2.5): a reader of built-in topic data that discovery
//! feeds directly (no CDR, no RTPS reader), with the sample, view and instance states, read conditions,
//! a status condition and a listener of any reader. History is KEEP_LAST 1 per instance, as the spec sets
//! for the built-in readers.

use std::sync::{Arc, Mutex};
use std::time::SystemTime;

use super::cache::SharedFilter;
use super::condition::{ReadCondition, ReadConditionSource, Signal, StatusCondition, StatusCore};
use super::error::{DdsError, DdsResult};
use super::sample::{
    InstanceHandle, InstanceState, InstanceStateMask, Sample, SampleInfo, SampleState,
    SampleStateMask, ViewState, ViewStateMask,
};
use super::status::StatusMask;
use super::sync::lock;
use crate::rtps::Guid;

/// Most instances one built-in reader keeps: hostile discovery data cannot grow it without bound (the
/// oldest not-alive instance goes first, then the oldest).
const MAX_INSTANCES: usize = 16 * 1024;

/// Callbacks of a [`BuiltinDataReader`]. Every method has an empty default.
#[allow(unused_variables)]
pub trait BuiltinDataReaderListener<T>: Send + Sync {
    /// Discovery changed what the reader holds (a new or changed entity, or one that left).
    fn on_data_available(&self, reader: &BuiltinDataReader<T>) {}
}

/// One instance: the latest data of a discovered entity and its state.
struct Instance<T> {
    handle: InstanceHandle,
    state: InstanceState,
    /// Whether the application has seen this instance (generation).
    seen: bool,
    /// KEEP_LAST 1: the latest valid sample, or an invalid one that reports a state change.
    sample: Option<Slot<T>>,
    disposed_generations: u32,
}

struct Slot<T> {
    data: Option<T>,
    read: bool,
    received: SystemTime,
}

struct Cache<T> {
    instances: Vec<Instance<T>>,
}

impl<T: Clone> Cache<T> {
    fn matches(
        i: &Instance<T>,
        s: SampleStateMask,
        v: ViewStateMask,
        st: InstanceStateMask,
    ) -> bool {
        let view = if i.seen {
            ViewState::NotNew
        } else {
            ViewState::New
        };
        i.sample.as_ref().is_some_and(|slot| {
            let ss = if slot.read {
                SampleState::Read
            } else {
                SampleState::NotRead
            };
            s.contains(ss) && v.contains(view) && st.contains(i.state)
        })
    }

    /// Returns (and with `take` removes) the samples in the states, of `only` when given.
    fn visit(
        &mut self,
        s: SampleStateMask,
        v: ViewStateMask,
        st: InstanceStateMask,
        only: Option<InstanceHandle>,
        take: bool,
    ) -> Vec<Sample<T>> {
        let mut out = Vec::new();
        for i in self
            .instances
            .iter_mut()
            .filter(|i| only.is_none_or(|h| h == i.handle))
        {
            if !Self::matches(i, s, v, st) {
                continue;
            }
            let view = if i.seen {
                ViewState::NotNew
            } else {
                ViewState::New
            };
            i.seen = true;
            let Some(slot) = i.sample.as_mut() else {
                continue;
            };
            let info = SampleInfo {
                sample_state: if slot.read {
                    SampleState::Read
                } else {
                    SampleState::NotRead
                },
                view_state: view,
                instance_state: i.state,
                source_timestamp: slot.received,
                reception_timestamp: slot.received,
                instance_handle: i.handle,
                publication_handle: InstanceHandle::NIL,
                publication_guid: Guid::default(),
                disposed_generation_count: i.disposed_generations,
                no_writers_generation_count: 0,
                sample_rank: 0,
                generation_rank: 0,
                absolute_generation_rank: 0,
                valid_data: slot.data.is_some(),
            };
            slot.read = true;
            let data = if take {
                i.sample.take().and_then(|s| s.data)
            } else {
                slot.data.clone()
            };
            out.push(Sample { data, info });
        }
        // A taken instance that is no longer alive is forgotten.
        self.instances
            .retain(|i| i.sample.is_some() || i.state == InstanceState::Alive);
        out
    }

    /// New or changed data of instance `h`.
    fn upsert(&mut self, h: InstanceHandle, data: T) {
        let slot = Slot {
            data: Some(data),
            read: false,
            received: SystemTime::now(),
        };
        match self.instances.iter_mut().find(|i| i.handle == h) {
            Some(i) => {
                if i.state != InstanceState::Alive {
                    // A new generation of the instance.
                    i.seen = false;
                    i.disposed_generations += u32::from(i.state == InstanceState::NotAliveDisposed);
                }
                i.state = InstanceState::Alive;
                i.sample = Some(slot);
            }
            None => {
                self.bound();
                self.instances.push(Instance {
                    handle: h,
                    state: InstanceState::Alive,
                    seen: false,
                    sample: Some(slot),
                    disposed_generations: 0,
                });
            }
        }
    }

    /// Instance `h` left (`NotAliveDisposed`). Whether it was alive.
    fn dispose(&mut self, h: InstanceHandle) -> bool {
        let Some(i) = self
            .instances
            .iter_mut()
            .find(|i| i.handle == h && i.state == InstanceState::Alive)
        else {
            return false;
        };
        i.state = InstanceState::NotAliveDisposed;
        // The application learns of it through an unread sample: the kept data if unread, else an invalid one.
        let unread = i.sample.as_ref().is_some_and(|s| !s.read);
        if !unread {
            i.sample = Some(Slot {
                data: None,
                read: false,
                received: SystemTime::now(),
            });
        }
        true
    }

    fn bound(&mut self) {
        if self.instances.len() < MAX_INSTANCES {
            return;
        }
        let victim = self
            .instances
            .iter()
            .position(|i| i.state != InstanceState::Alive)
            .unwrap_or(0);
        self.instances.remove(victim);
    }
}

struct Inner<T> {
    topic_name: &'static str,
    cache: Mutex<Cache<T>>,
    status: Arc<StatusCore>,
    data_signal: Signal,
    listener: Mutex<Option<Arc<dyn BuiltinDataReaderListener<T>>>>,
}

/// A reader of the built-in subscriber: reads `DCPSParticipant`, `DCPSPublication`, `DCPSSubscription` or
/// `DCPSTopic` data ([`super::ParticipantBuiltinTopicData`], [`super::PublicationBuiltinTopicData`],
/// [`super::SubscriptionBuiltinTopicData`], [`super::TopicBuiltinTopicData`]). Each discovered entity is
/// an instance (its handle is the entity's, as `get_matched_*_data` takes it); an entity that leaves is
/// disposed. Cheap to clone.
pub struct BuiltinDataReader<T> {
    inner: Arc<Inner<T>>,
}

impl<T> Clone for BuiltinDataReader<T> {
    fn clone(&self) -> Self {
        BuiltinDataReader {
            inner: self.inner.clone(),
        }
    }
}

impl<T> std::fmt::Debug for BuiltinDataReader<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BuiltinDataReader")
            .field("topic", &self.inner.topic_name)
            .finish()
    }
}

impl<T: Clone + Send + Sync + 'static> BuiltinDataReader<T> {
    pub(crate) fn new(topic_name: &'static str) -> Self {
        BuiltinDataReader {
            inner: Arc::new(Inner {
                topic_name,
                cache: Mutex::new(Cache {
                    instances: Vec::new(),
                }),
                status: Arc::new(StatusCore::default()),
                data_signal: Signal::default(),
                listener: Mutex::new(None),
            }),
        }
    }

    /// The built-in topic's name (`DCPSParticipant`, ...).
    pub fn topic_name(&self) -> &'static str {
        self.inner.topic_name
    }

    /// Every sample, left in the reader (`read`).
    pub fn read(&self) -> DdsResult<Vec<Sample<T>>> {
        Ok(self.visit(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ANY,
            None,
            false,
        ))
    }

    /// Every sample, removed from the reader (`take`).
    pub fn take(&self) -> DdsResult<Vec<Sample<T>>> {
        Ok(self.visit(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ANY,
            None,
            true,
        ))
    }

    /// The samples of instance `h` (`read_instance`); `BadParameter` for an unknown instance.
    pub fn read_instance(&self, h: InstanceHandle) -> DdsResult<Vec<Sample<T>>> {
        self.check_instance(h)?;
        Ok(self.visit(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ANY,
            Some(h),
            false,
        ))
    }

    /// The samples of instance `h`, removed (`take_instance`); `BadParameter` for an unknown instance.
    pub fn take_instance(&self, h: InstanceHandle) -> DdsResult<Vec<Sample<T>>> {
        self.check_instance(h)?;
        Ok(self.visit(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ANY,
            Some(h),
            true,
        ))
    }

    /// The samples in the states (`read` with masks).
    pub fn read_with_states(
        &self,
        s: SampleStateMask,
        v: ViewStateMask,
        i: InstanceStateMask,
    ) -> DdsResult<Vec<Sample<T>>> {
        Ok(self.visit(s, v, i, None, false))
    }

    /// The samples in the states, removed (`take` with masks).
    pub fn take_with_states(
        &self,
        s: SampleStateMask,
        v: ViewStateMask,
        i: InstanceStateMask,
    ) -> DdsResult<Vec<Sample<T>>> {
        Ok(self.visit(s, v, i, None, true))
    }

    /// A read condition on this reader, for a [`super::WaitSet`] and `read_w_condition`.
    pub fn create_readcondition(
        &self,
        sample_states: SampleStateMask,
        view_states: ViewStateMask,
        instance_states: InstanceStateMask,
    ) -> ReadCondition {
        ReadCondition::on(
            self.inner.clone(),
            sample_states,
            view_states,
            instance_states,
        )
    }

    /// The samples in `rc`'s states (`read_w_condition`).
    pub fn read_w_condition(&self, rc: &ReadCondition) -> DdsResult<Vec<Sample<T>>> {
        self.check_condition(rc)?;
        self.read_with_states(rc.sample_states, rc.view_states, rc.instance_states)
    }

    /// The samples in `rc`'s states, removed (`take_w_condition`).
    pub fn take_w_condition(&self, rc: &ReadCondition) -> DdsResult<Vec<Sample<T>>> {
        self.check_condition(rc)?;
        self.take_with_states(rc.sample_states, rc.view_states, rc.instance_states)
    }

    /// The reader's status condition (DATA_AVAILABLE; cleared by a read or take).
    pub fn status_condition(&self) -> StatusCondition {
        StatusCondition {
            core: self.inner.status.clone(),
        }
    }

    /// Installs the listener.
    pub fn set_listener(&self, l: Box<dyn BuiltinDataReaderListener<T>>) {
        *lock(&self.inner.listener) = Some(Arc::from(l));
    }

    /// Removes the listener.
    pub fn clear_listener(&self) {
        *lock(&self.inner.listener) = None;
    }

    fn visit(
        &self,
        s: SampleStateMask,
        v: ViewStateMask,
        i: InstanceStateMask,
        only: Option<InstanceHandle>,
        take: bool,
    ) -> Vec<Sample<T>> {
        self.inner.status.clear(StatusMask::DATA_AVAILABLE);
        lock(&self.inner.cache).visit(s, v, i, only, take)
    }

    fn check_instance(&self, h: InstanceHandle) -> DdsResult<()> {
        if lock(&self.inner.cache)
            .instances
            .iter()
            .any(|i| i.handle == h)
        {
            Ok(())
        } else {
            Err(DdsError::BadParameter(format!("no instance {h:?}")))
        }
    }

    fn check_condition(&self, rc: &ReadCondition) -> DdsResult<()> {
        let ours: Arc<dyn ReadConditionSource> = self.inner.clone();
        if rc.query.is_some() || !std::ptr::addr_eq(Arc::as_ptr(&rc.source), Arc::as_ptr(&ours)) {
            return Err(DdsError::PreconditionNotMet(
                "the condition belongs to another reader",
            ));
        }
        Ok(())
    }

    /// Discovery learnt new data of instance `h`.
    pub(crate) fn upsert(&self, h: InstanceHandle, data: T) {
        lock(&self.inner.cache).upsert(h, data);
        self.notify();
    }

    /// Whether instance `h` is known and alive.
    pub(crate) fn has_alive_instance(&self, h: InstanceHandle) -> bool {
        lock(&self.inner.cache)
            .instances
            .iter()
            .any(|i| i.handle == h && i.state == InstanceState::Alive)
    }

    /// The entity of instance `h` left.
    pub(crate) fn dispose(&self, h: InstanceHandle) {
        if lock(&self.inner.cache).dispose(h) {
            self.notify();
        }
    }

    fn notify(&self) {
        self.inner.status.raise(StatusMask::DATA_AVAILABLE);
        self.inner.data_signal.notify();
        let l = lock(&self.inner.listener).clone();
        if let Some(l) = l {
            l.on_data_available(self);
        }
    }
}

impl<T: Clone + Send + Sync + 'static> ReadConditionSource for Inner<T> {
    fn has_matching(
        &self,
        s: SampleStateMask,
        v: ViewStateMask,
        i: InstanceStateMask,
        _query: Option<&SharedFilter>,
    ) -> bool {
        lock(&self.cache)
            .instances
            .iter()
            .any(|x| Cache::matches(x, s, v, i))
    }

    fn data_signal(&self) -> &Signal {
        &self.data_signal
    }
}
