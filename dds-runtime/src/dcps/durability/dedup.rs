//! Keeps a reader from getting a sample twice when it reaches it both from its original writer and from a
//! durability service's stand-in for that writer (or from two services).
//!
//! Stand-ins announce the GUID of the writer they stand for in their USER_DATA (see [`super::marker`]).
//! For each (local reader, original writer) the filter remembers the newest source timestamp each source
//! delivered; a sample whose timestamp another source already reached is a repeat and is dropped. Both
//! sources deliver the original writer's changes in the original order, so this holds each change once.
//! Samples without a source timestamp are never dropped.

use std::collections::{HashMap, HashSet};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

use super::marker;
use crate::dcps::driver::CoreObserver;
use crate::dcps::sync::lock;
use crate::qos::Durability;
use crate::rtps::discovery::WriterData;
use crate::rtps::{EntityId, Event, Guid, ReceivedSample, Time};

/// Most (reader, writer) pairs remembered; past it the memory starts over (repeats may then get through).
const MAX_PAIRS: usize = 1 << 16;

#[derive(Default)]
struct State {
    /// Stand-in writer -> the writer it stands for.
    stand_ins: HashMap<Guid, Guid>,
    /// TRANSIENT and PERSISTENT writers: a service may replay what they wrote.
    durable: HashSet<Guid>,
    /// (reader, original writer) -> newest timestamp per source.
    seen: HashMap<(EntityId, Guid), Vec<(Guid, Time)>>,
}

/// The duplicate filter (one per participant, always installed).
#[derive(Default)]
pub(crate) struct ReplayFilter {
    active: AtomicBool,
    state: Mutex<State>,
}

impl CoreObserver for ReplayFilter {
    fn admit(&self, s: &ReceivedSample) -> bool {
        if !self.active.load(Ordering::Acquire) {
            return true;
        }
        let Some(ts) = s.source_timestamp else {
            return true;
        };
        let mut st = lock(&self.state);
        let original = match st.stand_ins.get(&s.writer) {
            Some(o) => *o,
            None if st.durable.contains(&s.writer) => s.writer,
            None => return true,
        };
        if st.seen.len() >= MAX_PAIRS && !st.seen.contains_key(&(s.reader, original)) {
            st.seen.clear();
        }
        let sources = st.seen.entry((s.reader, original)).or_default();
        if sources
            .iter()
            .any(|(src, max)| *src != s.writer && *max >= ts)
        {
            tracing::trace!(writer = ?s.writer, ?original, "replayed sample dropped");
            return false;
        }
        match sources.iter_mut().find(|(src, _)| *src == s.writer) {
            Some(e) => e.1 = e.1.max(ts),
            None => sources.push((s.writer, ts)),
        }
        true
    }

    fn observe_locked(&self, ev: &Event) {
        if let Event::PublicationDiscovered(w) = ev {
            self.learn(w);
        }
    }
}

impl ReplayFilter {
    /// A discovered writer: a stand-in (and the writer it stands for) or a durable writer, whose samples
    /// the filter then checks. Also called for the writers the core had discovered before the filter was
    /// installed (the participant's driver runs before its services are installed).
    pub(crate) fn learn(&self, w: &WriterData) {
        let mut st = lock(&self.state);
        if let Some(original) = marker::stand_in_for(&w.qos.writer.user_data.0) {
            st.stand_ins.insert(w.guid, original);
        } else if w.qos.writer.durability >= Durability::Transient {
            st.durable.insert(w.guid);
        } else {
            return;
        }
        self.active.store(true, Ordering::Release);
    }
}
