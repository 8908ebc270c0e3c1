//! The durability service: a DDS application inside the participant. It watches discovery for TRANSIENT
//! and PERSISTENT writers, subscribes to their topics with a reader of its own (untyped: it keeps the
//! serialized payloads), keeps each writer's changes within its DURABILITY_SERVICE QoS, and republishes
//! them through a stand-in writer, one per original writer, which keeps its history for late joiners as a
//! TRANSIENT_LOCAL writer does. The stand-in outlives the original writer.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, Weak};
use std::time::{Duration, Instant};

use super::history::{instance_of, Limits, StoredChange, WriterHistory};
use super::key::KeyTypes;
use super::marker;
#[cfg(feature = "persistence")]
use super::store::{Batch, PersistentStore};
use crate::dcps::driver::{CoreObserver, Driver, Endpoint, Pending};
use crate::dcps::sync::lock;
use crate::qos::{
    DataReaderQos, DataRepresentation, Durability, History, ReaderQos, Reliability, ResourceLimits,
    UserData, WriterQos,
};
use crate::rtps::discovery::WriterData;
use crate::rtps::{
    EntityId, Event, Guid, GuidPrefix, ReaderSpec, ReceivedSample, SequenceNumber, WriteChange,
    WriteError, WriterSpec,
};

/// Which writers a service keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scope {
    /// Only the participant's own writers (the service every participant runs).
    Local(GuidPrefix),
    /// Every writer of the domain (the standalone `dds-durability`).
    Domain,
}

/// A channel: one reader of the service per topic, type and partition list.
type ChannelKey = (String, String, Vec<String>);

/// What the service keeps of one original writer.
struct Kept {
    /// The original writer's announcement.
    data: WriterData,
    history: WriterHistory,
    /// The stand-in writer, once created.
    stand_in: Option<EntityId>,
    /// When the original writer was seen to go (or, after a restart, when the service loaded it).
    gone_since: Option<Instant>,
    /// The stand-in's sequence number of each kept change it republished (by the original's).
    published: HashMap<i64, SequenceNumber>,
}

impl Kept {
    fn keyed(&self) -> bool {
        self.data.guid.entity_id.is_keyed()
    }
    #[cfg_attr(not(feature = "persistence"), allow(dead_code))]
    fn persistent(&self) -> bool {
        self.data.qos.writer.durability == Durability::Persistent
    }
}

#[derive(Default)]
struct State {
    channels: HashMap<ChannelKey, Option<EntityId>>,
    kept: HashMap<Guid, Kept>,
    /// Stand-ins of other services this one aligns from -> the original writer each stands for.
    sources: HashMap<Guid, Guid>,
}

/// The running service.
pub(crate) struct Service {
    driver: Weak<Driver>,
    scope: Scope,
    /// Most changes kept per original writer, whatever its QoS says.
    cap: usize,
    #[cfg(feature = "persistence")]
    store: Option<PersistentStore>,
    state: Mutex<State>,
    /// Writers' types, for the key hashes of changes that come without one.
    key_types: KeyTypes,
    me: Weak<Service>,
}

/// The stand-in QoS: the original writer's, with the service's marker. Its history mirrors the service's
/// (`Participant::manage_history`): KEEP_ALL, bounded by the service's cap as a safety net.
fn stand_in_qos(w: &WriterData, cap: usize) -> WriterQos {
    let mut q = WriterQos::clone(&w.qos);
    q.writer.history = History::KeepAll;
    q.writer.resource_limits = ResourceLimits {
        max_samples: Some(u32::try_from(cap.saturating_add(1)).unwrap_or(u32::MAX)),
        max_instances: None,
        max_samples_per_instance: None,
    };
    q.writer.reliability = Reliability::Reliable {
        max_blocking_time: Duration::from_millis(100),
    };
    q.writer.user_data = UserData(marker::user_data(&w.guid));
    q
}

/// What a service knows of `original` from its stand-in `w`: the stand-in's announcement under the original's
/// GUID, without the stand-in's marker and name (the stand-in's QoS is the original's, with the service's
/// history and limits).
fn original_of(w: &WriterData, original: Guid) -> WriterData {
    let mut d = w.clone();
    d.guid = original;
    d.participant_guid = Some(Guid::new(original.prefix, EntityId::PARTICIPANT));
    std::sync::Arc::make_mut(&mut d.qos).writer.user_data = UserData::default();
    d.entity_name = None;
    d
}

/// The service reader's QoS for a channel of `w`: reliable, TRANSIENT_LOCAL (so that writers send their
/// history), KEEP_ALL, both representations, in `w`'s partitions.
fn channel_qos(w: &WriterData) -> ReaderQos {
    ReaderQos {
        reader: DataReaderQos::builder()
            .reliability(Reliability::RELIABLE)
            .durability(Durability::TransientLocal)
            .history(History::KeepAll)
            .data_representation(DataRepresentation::accept_both())
            .build(),
        partition: w.qos.partition.clone(),
        topic_data: w.qos.topic_data.clone(),
        ..ReaderQos::default()
    }
}

impl Service {
    /// A service on `driver` (registered as its observer by the caller).
    pub(crate) fn new(
        driver: &Arc<Driver>,
        scope: Scope,
        cap: usize,
        #[cfg(feature = "persistence")] store: Option<PersistentStore>,
    ) -> Arc<Self> {
        Arc::new_cyclic(|me| Service {
            driver: Arc::downgrade(driver),
            scope,
            cap,
            #[cfg(feature = "persistence")]
            store,
            state: Mutex::new(State::default()),
            key_types: KeyTypes::default(),
            me: me.clone(),
        })
    }

    fn in_scope(&self, w: &WriterData) -> bool {
        w.qos.writer.durability >= Durability::Transient
            && marker::stand_in_for(&w.qos.writer.user_data.0).is_none()
            && match self.scope {
                Scope::Local(p) => w.guid.prefix == p,
                Scope::Domain => true,
            }
    }

    /// The original writer `w` stands for, when `w` is another participant's stand-in that this service
    /// aligns from: a domain-wide service learns from other services what it did not see itself (it started
    /// after the original writer was gone, or missed some of its changes).
    fn aligns_from(&self, w: &WriterData) -> Option<Guid> {
        let own = self.driver.upgrade()?.guid_prefix;
        let original = marker::stand_in_for(&w.qos.writer.user_data.0)?;
        (self.scope == Scope::Domain
            && w.guid.prefix != own
            && w.qos.writer.durability >= Durability::Transient)
            .then_some(original)
    }

    /// Keeps `original` from the other service's stand-in `w` (unless already kept) and subscribes to it.
    fn align(&self, w: &WriterData, original: Guid) {
        let Some(driver) = self.driver.upgrade() else {
            return;
        };
        let known = {
            let mut st = lock(&self.state);
            st.sources.insert(w.guid, original);
            st.kept.contains_key(&original)
        };
        tracing::debug!(stand_in = ?w.guid, ?original, known, "durability: aligning");
        if !known {
            self.adopt(&original_of(w, original), Vec::new(), true);
        }
        self.open_channel(&driver, w);
    }

    /// Keeps `w` from now on: its channel reader and its stand-in.
    fn adopt(&self, w: &WriterData, changes: Vec<StoredChange>, gone: bool) {
        let Some(driver) = self.driver.upgrade() else {
            return;
        };
        {
            let mut st = lock(&self.state);
            if let Some(k) = st.kept.get_mut(&w.guid) {
                k.gone_since = None;
                return;
            }
            let mut history =
                WriterHistory::new(Limits::new(&w.qos.writer.durability_service, self.cap));
            let now = Instant::now();
            for c in changes {
                history.insert(c, now);
            }
            st.kept.insert(
                w.guid,
                Kept {
                    data: w.clone(),
                    history,
                    stand_in: None,
                    gone_since: gone.then(Instant::now),
                    published: HashMap::new(),
                },
            );
        }
        #[cfg(feature = "persistence")]
        if let Some(store) = &self.store {
            if w.qos.writer.durability == Durability::Persistent {
                if let Err(e) = store.save_writer(w) {
                    tracing::warn!(error = %e, writer = ?w.guid, "durability: writer not stored");
                }
            }
        }
        if !gone {
            self.open_channel(&driver, w);
        }
        self.create_stand_in(&driver, w);
    }

    fn open_channel(&self, driver: &Arc<Driver>, w: &WriterData) {
        let key = (
            w.topic_name.clone(),
            w.type_name.clone(),
            w.qos.partition.0.clone(),
        );
        {
            let mut st = lock(&self.state);
            if st.channels.contains_key(&key) {
                return;
            }
            st.channels.insert(key.clone(), None);
        }
        let sink = Arc::new(ChannelSink {
            service: self.me.clone(),
            queue: Mutex::new(Vec::new()),
        });
        let mut spec = ReaderSpec::new(
            w.topic_name.clone(),
            w.type_name.clone(),
            w.guid.entity_id.is_keyed(),
            channel_qos(w),
        );
        spec.internal = true;
        match driver.create_endpoint(sink, |c, now| c.create_reader(now, spec)) {
            Ok(id) => {
                lock(&self.state).channels.insert(key, Some(id));
                tracing::info!(topic = %w.topic_name, "durability: subscribed");
            }
            Err(e) => tracing::warn!(error = %e, topic = %w.topic_name, "durability: no reader"),
        }
    }

    fn create_stand_in(&self, driver: &Arc<Driver>, w: &WriterData) {
        let sink = Arc::new(StandInSink {
            service: self.me.clone(),
            original: w.guid,
        });
        let mut spec = WriterSpec::new(
            w.topic_name.clone(),
            w.type_name.clone(),
            w.guid.entity_id.is_keyed(),
            stand_in_qos(w, self.cap),
        );
        spec.type_information = w.type_information.as_deref().cloned();
        spec.entity_name = Some(format!("durability stand-in for {}", w.topic_name));
        spec.internal = true;
        let create = |c: &mut crate::rtps::Participant, now| {
            let id = c.create_writer(now, spec)?;
            c.manage_history(id);
            Ok(id)
        };
        let id = match driver.create_endpoint(sink, create) {
            Ok(id) => id,
            Err(e) => {
                tracing::warn!(error = %e, topic = %w.topic_name, "durability: no stand-in");
                return;
            }
        };
        let backlog: Vec<Republish> = {
            let mut st = lock(&self.state);
            let Some(k) = st.kept.get_mut(&w.guid) else {
                return;
            };
            k.stand_in = Some(id);
            let keyed = k.keyed();
            let write = |c: &StoredChange| Republish::Write(id, c.seq, c.to_write(keyed));
            k.history.changes().map(write).collect()
        };
        self.republish(driver, w.guid, backlog);
    }

    /// Mirrors changes of `original`'s kept history on its stand-in, in order.
    fn republish(&self, driver: &Driver, original: Guid, ops: Vec<Republish>) {
        for op in ops {
            match op {
                Republish::Write(id, seq, ch) => {
                    let Some(sn) = write_change(driver, id, ch) else {
                        continue;
                    };
                    if let Some(k) = lock(&self.state).kept.get_mut(&original) {
                        k.published.insert(seq, sn);
                    }
                }
                Republish::Remove(seq) => {
                    let found = lock(&self.state)
                        .kept
                        .get_mut(&original)
                        .and_then(|k| Some((k.stand_in?, k.published.remove(&seq)?)));
                    if let Some((id, sn)) = found {
                        driver.with_core(|c, _| c.remove_change(id, sn));
                    }
                }
            }
        }
    }

    /// Keeps and republishes what a channel reader received.
    fn ingest(&self, mut samples: Vec<ReceivedSample>) {
        let Some(driver) = self.driver.upgrade() else {
            return;
        };
        self.fill_key_hashes(&driver, &mut samples);
        let mut out: Vec<(Guid, Vec<Republish>)> = Vec::new();
        #[cfg(feature = "persistence")]
        let mut batch = Batch::default();
        let now = Instant::now();
        {
            let mut st = lock(&self.state);
            for s in samples {
                // A change from another service's stand-in is the original writer's, numbered here.
                let original = st.sources.get(&s.writer).copied();
                let Some(k) = st.kept.get_mut(&original.unwrap_or(s.writer)) else {
                    continue;
                };
                let keyed = k.keyed();
                let c = StoredChange {
                    seq: match original {
                        Some(_) => k.history.next_seq(),
                        None => s.sequence.0,
                    },
                    kind: s.kind,
                    key_hash: instance_of(keyed, s.key_hash, &s.payload),
                    timestamp: s.source_timestamp,
                    payload: s.payload.compact(),
                };
                let ins = k.history.insert(c.clone(), now);
                let mut ops: Vec<Republish> = ins
                    .evicted
                    .iter()
                    .map(|seq| Republish::Remove(*seq))
                    .collect();
                if let (Some(id), true) = (k.stand_in, ins.kept) {
                    ops.push(Republish::Write(id, c.seq, c.to_write(keyed)));
                }
                let g = k.data.guid;
                #[cfg(feature = "persistence")]
                if k.persistent() {
                    batch
                        .evicted
                        .extend(ins.evicted.iter().map(|seq| (g, *seq)));
                    if ins.kept {
                        batch.put.push((g, c));
                    }
                }
                out.push((g, ops));
            }
        }
        #[cfg(feature = "persistence")]
        self.store_batch(&batch);
        for (g, ops) in out {
            self.republish(&driver, g, ops);
        }
    }

    #[cfg(feature = "persistence")]
    fn store_batch(&self, batch: &Batch) {
        if let (Some(store), false) = (&self.store, batch.is_empty()) {
            if let Err(e) = store.apply(batch) {
                tracing::warn!(error = %e, "durability: changes not stored");
            }
        }
    }

    /// The original writer left: its data stays; `service_cleanup_delay` starts.
    fn writer_gone(&self, g: &Guid) {
        tracing::debug!(writer = ?g, "durability: original writer gone");
        if let Some(k) = lock(&self.state).kept.get_mut(g) {
            k.gone_since.get_or_insert_with(Instant::now);
        }
    }

    /// Keyed changes that come without a key hash get the one their writer's type gives (see
    /// [`KeyTypes`]); without the type they keep none, and are kept under a digest of their payload.
    fn fill_key_hashes(&self, driver: &Driver, samples: &mut [ReceivedSample]) {
        let needs = |s: &ReceivedSample| s.key_hash.is_none() && s.writer.entity_id.is_keyed();
        for s in samples.iter_mut().filter(|s| needs(s)) {
            let info = {
                let st = lock(&self.state);
                let original = st.sources.get(&s.writer).copied().unwrap_or(s.writer);
                st.kept
                    .get(&original)
                    .and_then(|k| k.data.type_information.clone())
            };
            s.key_hash =
                self.key_types
                    .key_hash(driver, s.writer, info.as_deref(), s.kind, &s.payload);
        }
    }

    /// Whether `original` was learnt from another service's stand-in that is still discovered: its
    /// history may be on its way (over shared memory, it comes once the channel is connected), so an
    /// empty history does not mean that nothing is left.
    fn aligning(&self, original: &Guid) -> bool {
        let sources: Vec<Guid> = lock(&self.state)
            .sources
            .iter()
            .filter(|(_, o)| *o == original)
            .map(|(s, _)| *s)
            .collect();
        !sources.is_empty()
            && self.driver.upgrade().is_some_and(|d| {
                d.query_core(|c| c.publications().any(|w| sources.contains(&w.guid)))
            })
    }

    /// Purges `original`'s instances that have been disposed, with no live writer, for its
    /// `service_cleanup_delay` (DDS 1.4 §2.2.3.5), and forgets `original` once it is gone and nothing of it
    /// is left.
    fn cleanup(&self, original: &Guid, now: Instant) {
        let aligning = self.aligning(original);
        let (purged, stand_in, forget, persistent) = {
            let mut st = lock(&self.state);
            let Some(k) = st.kept.get_mut(original) else {
                return;
            };
            let delay = k.data.qos.writer.durability_service.service_cleanup_delay;
            let purged = k.history.purge(now, k.gone_since, delay);
            let forget = !aligning
                && k.history.is_empty()
                && k.gone_since
                    .is_some_and(|t| t.checked_add(delay).is_some_and(|d| now >= d));
            let (stand_in, persistent) = (k.stand_in, k.persistent());
            if forget {
                st.kept.remove(original);
            }
            (purged, stand_in, forget, persistent)
        };
        if !purged.is_empty() {
            tracing::debug!(writer = ?original, changes = purged.len(), "durability: instances purged");
            #[cfg(feature = "persistence")]
            if persistent {
                self.store_batch(&Batch {
                    evicted: purged.iter().map(|seq| (*original, *seq)).collect(),
                    ..Batch::default()
                });
            }
        }
        #[cfg(not(feature = "persistence"))]
        let _ = persistent;
        let Some(driver) = self.driver.upgrade() else {
            return;
        };
        if !forget {
            let ops = purged.into_iter().map(Republish::Remove).collect();
            self.republish(&driver, *original, ops);
            return;
        }
        self.key_types.forget(original);
        tracing::info!(writer = ?original, "durability: cleaned up");
        #[cfg(feature = "persistence")]
        if let Some(store) = &self.store {
            if let Err(e) = store.remove_writer(original) {
                tracing::warn!(error = %e, "durability: writer not removed from the store");
            }
        }
        if let Some(id) = stand_in {
            driver.delete_endpoint(id);
        }
    }

    /// Adopts the writers discovery already knows (for a service started after its participant).
    pub(crate) fn adopt_known(&self) {
        let Some(driver) = self.driver.upgrade() else {
            return;
        };
        let known: Vec<WriterData> = driver.query_core(|c| c.publications().cloned().collect());
        for w in known {
            self.discovered(&w);
        }
    }

    /// A writer discovered: one in scope is adopted; another service's stand-in is aligned from.
    fn discovered(&self, w: &WriterData) {
        if self.in_scope(w) {
            self.adopt(w, Vec::new(), false);
        } else if let Some(original) = self.aligns_from(w) {
            self.align(w, original);
        }
    }

    /// Re-adopts what the persistent store holds (at start).
    #[cfg(feature = "persistence")]
    pub(crate) fn restore(&self) -> Result<usize, super::store::StoreError> {
        let Some(store) = &self.store else {
            return Ok(0);
        };
        let writers = store.load()?;
        let n = writers.len();
        for w in writers {
            tracing::info!(writer = ?w.data.guid, changes = w.changes.len(), "durability: restored");
            self.adopt(&w.data, w.changes, true);
        }
        Ok(n)
    }
}

/// A change to mirror on a stand-in.
enum Republish {
    /// Write the kept change with this (original) sequence number to the stand-in.
    Write(EntityId, i64, WriteChange),
    /// Remove the kept change with this sequence number from the stand-in's history.
    Remove(i64),
}

/// Writes a change to a stand-in, waiting (at most 2 s) while flow control holds it back; its sequence
/// number on the stand-in, unless it could not be written.
fn write_change(driver: &Driver, id: EntityId, ch: WriteChange) -> Option<SequenceNumber> {
    let deadline = Instant::now() + Duration::from_secs(2);
    loop {
        match driver.with_core(|core, now| core.write(now, id, ch.clone())) {
            Err(WriteError::WouldBlock) if Instant::now() < deadline => {
                let seen = driver.progress_generation();
                driver.wait_progress_change(seen, Instant::now() + Duration::from_millis(20));
            }
            Err(e) => {
                tracing::warn!(error = %e, "durability: change not republished");
                return None;
            }
            Ok(sn) => return Some(sn),
        }
    }
}

impl CoreObserver for Service {
    fn on_event(&self, ev: &Event) {
        match ev {
            Event::PublicationDiscovered(w) => self.discovered(w),
            Event::PublicationRemoved { guid } => self.writer_gone(guid),
            Event::WriterDeleted { writer } => {
                if let Some(d) = self.driver.upgrade() {
                    self.writer_gone(&Guid::new(d.guid_prefix, *writer));
                }
            }
            _ => {}
        }
    }
}

/// The driver-facing side of a channel reader.
struct ChannelSink {
    service: Weak<Service>,
    queue: Mutex<Vec<ReceivedSample>>,
}

impl Endpoint for ChannelSink {
    fn enqueue(&self, item: Pending) {
        if let Pending::Sample(s) = item {
            lock(&self.queue).push(s);
        }
    }
    fn process(self: Arc<Self>) {
        let samples = std::mem::take(&mut *lock(&self.queue));
        if let (Some(svc), false) = (self.service.upgrade(), samples.is_empty()) {
            svc.ingest(samples);
        }
    }
    fn on_event(self: Arc<Self>, _ev: &Event) {}
    fn tick(self: Arc<Self>, _now: Instant) {}
}

/// The driver-facing side of a stand-in writer: runs the cleanup check of its original writer.
struct StandInSink {
    service: Weak<Service>,
    original: Guid,
}

impl Endpoint for StandInSink {
    fn on_event(self: Arc<Self>, _ev: &Event) {}
    fn tick(self: Arc<Self>, now: Instant) {
        if let Some(svc) = self.service.upgrade() {
            svc.cleanup(&self.original, now);
        }
    }
}
