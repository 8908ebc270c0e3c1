//! WaitSet and its conditions: [`GuardCondition`], [`StatusCondition`], [`ReadCondition`] and
//! [`QueryCondition`] (a read condition with a query expression).
//!
//! Every condition owns a signal; whoever changes what a condition looks at calls `Signal::notify`,
//! which wakes the waitsets the condition is attached to. `WaitSet::wait` re-evaluates the trigger values
//! after each wakeup, so spurious notifications are harmless.

use std::sync::atomic::{AtomicBool, AtomicU32, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, RwLock, Weak};
use std::time::{Duration, Instant};

use super::cache::SharedFilter;
use super::error::{DdsError, DdsResult};
use super::sample::{InstanceStateMask, SampleStateMask, ViewStateMask};
use super::status::StatusMask;
use super::sync::{lock, read, recover, write};
use crate::filter::ContentFilter;

/// One waitset's wakeup channel: a generation counter under a mutex, and a condvar.
#[derive(Debug, Default)]
pub(crate) struct WaitSetCore {
    generation: Mutex<u64>,
    cv: Condvar,
}

impl WaitSetCore {
    fn wake(&self) {
        let mut g = lock(&self.generation);
        *g = g.wrapping_add(1);
        self.cv.notify_all();
    }
}

/// Fan-out of "something changed" to the attached waitsets.
#[derive(Debug, Default)]
pub(crate) struct Signal {
    waitsets: Mutex<Vec<Weak<WaitSetCore>>>,
    /// How many waitsets `waitsets` holds, read without the lock: most conditions (a reader's data, a
    /// subscriber's status) have no waitset, and the data path notifies them per sample. Stored under the
    /// lock, after an attach and before the waitset evaluates its conditions, so a change made before a
    /// notify that saw 0 is seen by that evaluation (both sides sequentially consistent).
    attached: AtomicUsize,
}

impl Signal {
    pub(crate) fn notify(&self) {
        if self.attached.load(Ordering::SeqCst) == 0 {
            return;
        }
        let mut ws = lock(&self.waitsets);
        ws.retain(|w| match w.upgrade() {
            Some(w) => {
                w.wake();
                true
            }
            None => false,
        });
        self.attached.store(ws.len(), Ordering::SeqCst);
    }
    fn attach(&self, w: &Arc<WaitSetCore>) {
        let mut ws = lock(&self.waitsets);
        ws.push(Arc::downgrade(w));
        self.attached.store(ws.len(), Ordering::SeqCst);
    }
    fn detach(&self, w: &Arc<WaitSetCore>) {
        let p = Arc::as_ptr(w);
        let mut ws = lock(&self.waitsets);
        ws.retain(|x| x.as_ptr() != p);
        self.attached.store(ws.len(), Ordering::SeqCst);
    }
}

/// A condition whose trigger value the application sets.
#[derive(Debug, Clone, Default)]
pub struct GuardCondition {
    inner: Arc<GuardInner>,
}

#[derive(Debug, Default)]
struct GuardInner {
    value: AtomicBool,
    signal: Signal,
}

impl GuardCondition {
    /// A new guard condition, not triggered.
    pub fn new() -> Self {
        Self::default()
    }
    /// Sets the trigger value and wakes attached waitsets.
    pub fn set_trigger_value(&self, v: bool) {
        self.inner.value.store(v, Ordering::SeqCst);
        self.inner.signal.notify();
    }
    /// The trigger value.
    pub fn trigger_value(&self) -> bool {
        self.inner.value.load(Ordering::SeqCst)
    }
}

/// The changed-status flags of one entity, shared by the entity and its [`StatusCondition`].
#[derive(Debug)]
pub(crate) struct StatusCore {
    changed: AtomicU32,
    enabled: AtomicU32,
    pub(crate) signal: Signal,
}

impl Default for StatusCore {
    fn default() -> Self {
        StatusCore {
            changed: AtomicU32::new(0),
            enabled: AtomicU32::new(StatusMask::all().bits()),
            signal: Signal::default(),
        }
    }
}

impl StatusCore {
    pub(crate) fn raise(&self, m: StatusMask) {
        self.changed.fetch_or(m.bits(), Ordering::SeqCst);
        self.signal.notify();
    }
    /// Raises `m`, waking the attached waitsets only when some bit of `m` was not raised yet (a waitset
    /// never sleeps on a raised, enabled status).
    pub(crate) fn raise_new(&self, m: StatusMask) {
        let prev = self.changed.fetch_or(m.bits(), Ordering::SeqCst);
        if prev & m.bits() != m.bits() {
            self.signal.notify();
        }
    }
    pub(crate) fn clear(&self, m: StatusMask) {
        self.changed.fetch_and(!m.bits(), Ordering::SeqCst);
    }
    pub(crate) fn changed(&self) -> StatusMask {
        StatusMask::from_bits_truncate(self.changed.load(Ordering::SeqCst))
    }
}

/// Triggers when one of its enabled statuses of its entity has changed since it was last read.
#[derive(Debug, Clone)]
pub struct StatusCondition {
    pub(crate) core: Arc<StatusCore>,
}

impl StatusCondition {
    /// Chooses the statuses that trigger this condition (all by default).
    pub fn set_enabled_statuses(&self, m: StatusMask) {
        self.core.enabled.store(m.bits(), Ordering::SeqCst);
        self.core.signal.notify();
    }
    /// The enabled statuses.
    pub fn enabled_statuses(&self) -> StatusMask {
        StatusMask::from_bits_truncate(self.core.enabled.load(Ordering::SeqCst))
    }
    /// Statuses that changed since last read (regardless of the enabled set).
    pub fn changed_statuses(&self) -> StatusMask {
        self.core.changed()
    }
    /// Whether an enabled status has changed.
    pub fn trigger_value(&self) -> bool {
        !(self.core.changed() & self.enabled_statuses()).is_empty()
    }
}

/// What a [`ReadCondition`] asks its reader.
pub(crate) trait ReadConditionSource: Send + Sync {
    /// Whether a sample is in the states and, with a query, carries data the query accepts.
    fn has_matching(
        &self,
        s: SampleStateMask,
        v: ViewStateMask,
        i: InstanceStateMask,
        query: Option<&SharedFilter>,
    ) -> bool;
    fn data_signal(&self) -> &Signal;
}

/// Triggers while its reader holds a sample in the given states.
#[derive(Clone)]
pub struct ReadCondition {
    pub(crate) source: Arc<dyn ReadConditionSource>,
    /// Sample states selected.
    pub sample_states: SampleStateMask,
    /// View states selected.
    pub view_states: ViewStateMask,
    /// Instance states selected.
    pub instance_states: InstanceStateMask,
    /// The query of a [`QueryCondition`].
    pub(crate) query: Option<SharedFilter>,
}

impl std::fmt::Debug for ReadCondition {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ReadCondition")
            .field("sample_states", &self.sample_states)
            .field("view_states", &self.view_states)
            .field("instance_states", &self.instance_states)
            .field(
                "query",
                &self
                    .query
                    .as_ref()
                    .map(|q| read(q).expression().to_string()),
            )
            .finish()
    }
}

impl ReadCondition {
    /// A read condition (no query) on `source` for samples in the given states.
    pub(crate) fn on(
        source: Arc<dyn ReadConditionSource>,
        sample_states: SampleStateMask,
        view_states: ViewStateMask,
        instance_states: InstanceStateMask,
    ) -> Self {
        ReadCondition {
            source,
            sample_states,
            view_states,
            instance_states,
            query: None,
        }
    }

    /// Whether the reader holds a matching sample.
    pub fn trigger_value(&self) -> bool {
        self.source.has_matching(
            self.sample_states,
            self.view_states,
            self.instance_states,
            self.query.as_ref(),
        )
    }

    /// Whether this is the read condition of a [`QueryCondition`].
    pub fn is_query(&self) -> bool {
        self.query.is_some()
    }
}

/// A [`ReadCondition`] that also requires the sample's data to satisfy a query expression (DDS 1.4 Annex B:
/// a condition, optionally followed by `ORDER BY`), made by `DataReader::create_querycondition`.
/// `read_w_condition`/`take_w_condition` given a query condition return only the samples it accepts, sorted
/// by its ORDER BY (equal keys in reception order). It dereferences to its read condition; in a [`WaitSet`]
/// it appears as [`Condition::Read`] with [`ReadCondition::is_query`] true.
#[derive(Debug, Clone)]
pub struct QueryCondition {
    read: ReadCondition,
}

impl QueryCondition {
    pub(crate) fn new(read: ReadCondition, query: ContentFilter) -> Self {
        QueryCondition {
            read: ReadCondition {
                query: Some(Arc::new(RwLock::new(query))),
                ..read
            },
        }
    }

    fn query(&self) -> &SharedFilter {
        self.read
            .query
            .as_ref()
            .expect("a query condition always has a query")
    }

    /// The query expression.
    pub fn query_expression(&self) -> String {
        read(self.query()).expression().to_string()
    }

    /// The current query parameters.
    pub fn query_parameters(&self) -> Vec<String> {
        read(self.query()).parameters().to_vec()
    }

    /// Replaces the query parameters (`%n`); refused when the expression uses one beyond the new list. Attached
    /// waitsets re-evaluate the condition.
    pub fn set_query_parameters<S: AsRef<str>>(&self, params: &[S]) -> DdsResult<()> {
        write(self.query()).set_parameters(params)?;
        self.read.source.data_signal().notify();
        Ok(())
    }

    /// Whether the reader holds a sample in the states that the query accepts.
    pub fn trigger_value(&self) -> bool {
        self.read.trigger_value()
    }
}

impl std::ops::Deref for QueryCondition {
    type Target = ReadCondition;
    fn deref(&self) -> &ReadCondition {
        &self.read
    }
}

impl From<QueryCondition> for Condition {
    fn from(c: QueryCondition) -> Self {
        Condition::Read(c.read)
    }
}

/// Anything a [`WaitSet`] can wait on.
#[derive(Debug, Clone)]
pub enum Condition {
    /// A guard condition.
    Guard(GuardCondition),
    /// An entity's status condition.
    Status(StatusCondition),
    /// A reader's read condition.
    Read(ReadCondition),
}

impl Condition {
    /// The current trigger value.
    pub fn trigger_value(&self) -> bool {
        match self {
            Condition::Guard(g) => g.trigger_value(),
            Condition::Status(s) => s.trigger_value(),
            Condition::Read(r) => r.trigger_value(),
        }
    }
    fn signal(&self) -> &Signal {
        match self {
            Condition::Guard(g) => &g.inner.signal,
            Condition::Status(s) => &s.core.signal,
            Condition::Read(r) => r.source.data_signal(),
        }
    }
    fn same(&self, other: &Condition) -> bool {
        match (self, other) {
            (Condition::Guard(a), Condition::Guard(b)) => Arc::ptr_eq(&a.inner, &b.inner),
            (Condition::Status(a), Condition::Status(b)) => Arc::ptr_eq(&a.core, &b.core),
            (Condition::Read(a), Condition::Read(b)) => {
                Arc::ptr_eq(&a.source, &b.source)
                    && same_query(a.query.as_ref(), b.query.as_ref())
                    && a.sample_states == b.sample_states
                    && a.view_states == b.view_states
                    && a.instance_states == b.instance_states
            }
            _ => false,
        }
    }
}

fn same_query(a: Option<&SharedFilter>, b: Option<&SharedFilter>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => Arc::ptr_eq(a, b),
        (a, b) => a.is_none() && b.is_none(),
    }
}

impl From<GuardCondition> for Condition {
    fn from(c: GuardCondition) -> Self {
        Condition::Guard(c)
    }
}
impl From<StatusCondition> for Condition {
    fn from(c: StatusCondition) -> Self {
        Condition::Status(c)
    }
}
impl From<ReadCondition> for Condition {
    fn from(c: ReadCondition) -> Self {
        Condition::Read(c)
    }
}

/// Blocks a thread until one of its attached conditions triggers.
#[derive(Debug, Default)]
pub struct WaitSet {
    core: Arc<WaitSetCore>,
    conditions: Mutex<Vec<Condition>>,
}

impl WaitSet {
    /// An empty waitset.
    pub fn new() -> Self {
        Self::default()
    }

    /// Attaches a condition (attaching the same one twice is a no-op).
    pub fn attach_condition(&self, c: impl Into<Condition>) {
        let c = c.into();
        let mut cs = lock(&self.conditions);
        if cs.iter().any(|x| x.same(&c)) {
            return;
        }
        c.signal().attach(&self.core);
        cs.push(c);
        self.core.wake();
    }

    /// Detaches a condition; `BadParameter` if it was not attached.
    pub fn detach_condition(&self, c: impl Into<Condition>) -> DdsResult<()> {
        let c = c.into();
        let mut cs = lock(&self.conditions);
        let Some(pos) = cs.iter().position(|x| x.same(&c)) else {
            return Err(DdsError::BadParameter("condition not attached".into()));
        };
        let removed = cs.remove(pos);
        removed.signal().detach(&self.core);
        Ok(())
    }

    /// The attached conditions.
    pub fn conditions(&self) -> Vec<Condition> {
        lock(&self.conditions).clone()
    }

    /// Waits until at least one attached condition triggers and returns the triggered ones;
    /// `Err(Timeout)` when none did within `timeout`.
    pub fn wait(&self, timeout: Duration) -> DdsResult<Vec<Condition>> {
        let deadline = Instant::now().checked_add(timeout);
        loop {
            let seen = *lock(&self.core.generation);
            let triggered: Vec<Condition> = self
                .conditions()
                .into_iter()
                .filter(|c| c.trigger_value())
                .collect();
            if !triggered.is_empty() {
                return Ok(triggered);
            }
            let g = lock(&self.core.generation);
            if *g != seen {
                continue;
            }
            let left = match deadline {
                Some(d) => match d.checked_duration_since(Instant::now()) {
                    Some(l) if !l.is_zero() => l,
                    _ => return Err(DdsError::Timeout),
                },
                None => Duration::from_secs(3600),
            };
            let _unused = recover(self.core.cv.wait_timeout(g, left));
        }
    }
}

impl Drop for WaitSet {
    fn drop(&mut self) {
        let cs = std::mem::take(&mut *lock(&self.conditions));
        for c in cs {
            c.signal().detach(&self.core);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn guard_condition_wakes_a_waiting_thread() {
        let ws = WaitSet::new();
        let g = GuardCondition::new();
        ws.attach_condition(g.clone());
        assert!(matches!(
            ws.wait(Duration::from_millis(20)),
            Err(DdsError::Timeout)
        ));
        let g2 = g.clone();
        let t = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(30));
            g2.set_trigger_value(true);
        });
        let start = Instant::now();
        let got = ws.wait(Duration::from_secs(5)).unwrap();
        assert!(start.elapsed() < Duration::from_secs(4));
        assert_eq!(got.len(), 1);
        t.join().unwrap();
        ws.detach_condition(g.clone()).unwrap();
        assert!(ws.detach_condition(g).is_err());
    }

    #[test]
    fn status_condition_respects_enabled_mask() {
        let core = Arc::new(StatusCore::default());
        let sc = StatusCondition { core: core.clone() };
        sc.set_enabled_statuses(StatusMask::DATA_AVAILABLE);
        core.raise(StatusMask::PUBLICATION_MATCHED);
        assert!(!sc.trigger_value());
        core.raise(StatusMask::DATA_AVAILABLE);
        assert!(sc.trigger_value());
        core.clear(StatusMask::DATA_AVAILABLE);
        assert!(!sc.trigger_value());
    }
}
