//! PRESENTATION (DDS 1.4 §2.2.3.6): the state behind `Publisher::begin_coherent_changes` /
//! `end_coherent_changes` and `Subscriber::begin_access` / `end_access`.
//!
//! A publisher's coherent set spans all its writers: while one is open, each writer (also one created
//! meanwhile) has a coherent set open in the RTPS core, and ending it sends every writer's end-of-set
//! marker. Readers deliver each writer's part of the set whole or not at all (see `rtps::reader::coherent`).
//! With GROUP access scope the writers also share a [`WriterGroup`]: group sequence numbers on every
//! change, and a group coherent set whose parts readers deliver together (`rtps::participant::group`).

use std::sync::atomic::AtomicU64;
use std::sync::{Arc, Mutex, Weak};
use std::time::{Duration, Instant};

use crate::qos::{Presentation, PresentationAccessScope};
use crate::rtps::{EntityId, WriteError, WriterGroup};

use super::driver::Driver;
use super::error::{DdsError, DdsResult};
use super::sync::lock;

#[derive(Debug, Default)]
struct GroupState {
    writers: Vec<EntityId>,
    /// Nesting depth of begin_coherent_changes.
    depth: u32,
    /// GROUP access scope (coherent or ordered): the state the writers share on the wire.
    group: Option<WriterGroup>,
}

/// A publisher's writers and its open coherent set.
#[derive(Debug, Default)]
pub(crate) struct CoherentGroup {
    state: Mutex<GroupState>,
}

impl CoherentGroup {
    /// Records a new writer of the publisher; it joins the open set, if any. (No lock of this group is
    /// held while the core is called: listeners run from there and may call back.)
    pub(crate) fn add_writer(&self, driver: &Driver, id: EntityId, p: &Presentation) {
        let (open, group) = {
            let mut st = lock(&self.state);
            st.writers.push(id);
            if group_scoped(p) {
                st.group.get_or_insert_with(WriterGroup::default);
            }
            (st.depth > 0, st.group.clone())
        };
        let _ = driver.with_core(|c, now| {
            if let Some(g) = &group {
                c.join_writer_group(now, id, g)?;
            }
            if open {
                c.begin_coherent_set(id)?;
            }
            Ok::<_, WriteError>(())
        });
    }

    /// Opens a coherent set on every writer (nested calls only count).
    pub(crate) fn begin(&self, driver: &Driver) -> DdsResult<()> {
        driver.check_alive()?;
        let writers = {
            let mut st = lock(&self.state);
            st.depth += 1;
            if st.depth > 1 {
                return Ok(());
            }
            (st.writers.clone(), st.group.clone())
        };
        let (writers, group) = writers;
        let gone = driver.with_core(|c, _| {
            if let Some(g) = &group {
                c.begin_group_set(g);
            }
            writers
                .into_iter()
                .filter(|w| c.begin_coherent_set(*w).is_err())
                .collect::<Vec<_>>()
        });
        lock(&self.state).writers.retain(|w| !gone.contains(w));
        Ok(())
    }

    /// Closes the outermost set: every writer sends its end-of-set marker, each waiting up to
    /// `max_blocking` while flow control refuses it.
    pub(crate) fn end(&self, driver: &Driver, max_blocking: Duration) -> DdsResult<()> {
        driver.check_alive()?;
        let writers = {
            let mut st = lock(&self.state);
            if st.depth == 0 {
                return Err(DdsError::PreconditionNotMet(
                    "end_coherent_changes without begin_coherent_changes",
                ));
            }
            st.depth -= 1;
            if st.depth > 0 {
                return Ok(());
            }
            (st.writers.clone(), st.group.clone())
        };
        let (writers, group) = writers;
        let deadline = Instant::now().checked_add(max_blocking);
        // Every writer's end-of-set marker in one core call, so that they leave in one datagram per
        // destination and readers see the writers' parts of the set arrive together; writers that flow
        // control holds back end one by one after.
        let (blocked, failed) = driver.with_core(|c, now| {
            let mut blocked = Vec::new();
            let mut failed = None;
            for w in writers {
                match c.end_coherent_set(now, w) {
                    Err(WriteError::WouldBlock) => blocked.push(w),
                    Ok(_) | Err(WriteError::UnknownWriter(_)) | Err(WriteError::Deleted) => {}
                    Err(e) => failed = failed.or(Some(e)),
                }
            }
            (blocked, failed)
        });
        let r = match failed {
            Some(e) => Err(DdsError::Write(e)),
            None => blocked
                .into_iter()
                .try_for_each(|w| end_one(driver, w, deadline)),
        };
        // Closed even when a marker timed out: that part never completes, so readers discard the set.
        if let Some(g) = group {
            driver.with_core(|c, _| c.end_group_set(&g));
        }
        r
    }
}

/// Ends writer `w`'s set, waiting for flow control until `deadline`.
fn end_one(driver: &Driver, w: EntityId, deadline: Option<Instant>) -> DdsResult<()> {
    loop {
        let seen = driver.progress_generation();
        match driver.with_core(|c, now| c.end_coherent_set(now, w)) {
            Ok(_) | Err(WriteError::UnknownWriter(_)) | Err(WriteError::Deleted) => return Ok(()),
            Err(WriteError::WouldBlock) => match deadline {
                Some(d) if Instant::now() >= d => return Err(DdsError::Timeout),
                Some(d) => driver.wait_progress_change(seen, d),
                None => {
                    driver.wait_progress_change(seen, Instant::now() + Duration::from_millis(20))
                }
            },
            Err(e) => return Err(DdsError::Write(e)),
        }
        driver.check_alive()?;
    }
}

/// A reader of a subscriber with GROUP access scope (coherent or ordered), as its [`AccessScope`] delivers
/// to it: what the core queued for all the subscriber's readers is stored in one step, so that a group set
/// is never seen in one reader and not yet in another.
pub(crate) trait AccessMember: Send + Sync {
    /// Under the core lock: sets aside what the core has queued for the reader so far.
    fn stage(&self);
    /// How many changes wait in the reader's queue (bounds what an open access scope holds back).
    fn held(&self) -> usize;
    /// Stores what was set aside (under the scope's gate).
    fn commit(&self);
    /// After the gate: raises the statuses and calls the listeners that the stores call for.
    fn announce(self: Arc<Self>);
}

/// Most changes the readers of one subscriber hold back while an access scope stays open: beyond it they
/// are stored anyway (memory stays bounded; the scope then sees changes arrive).
const MAX_HELD: usize = 1 << 16;

#[derive(Default)]
struct Gate {
    /// Nesting depth of `begin_access`.
    depth: u32,
    /// GROUP access scope: the subscriber's readers.
    members: Vec<Weak<dyn AccessMember>>,
}

/// A subscriber's access scope: `begin_access` / `end_access` nesting, and the counter its readers number
/// their samples from with GROUP ordered access (one order across the readers, for `get_datareaders`).
///
/// With GROUP access scope the readers store what they receive through [`AccessScope::deliver`], all of
/// them at once, and nothing while an access scope is open: inside `begin_access` / `end_access` the
/// readers' contents do not change, and a group set is in all of its readers or in none.
#[derive(Default)]
pub(crate) struct AccessScope {
    gate: Mutex<Gate>,
    order: Arc<AtomicU64>,
}

impl std::fmt::Debug for AccessScope {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AccessScope")
            .field("depth", &lock(&self.gate).depth)
            .finish()
    }
}

impl AccessScope {
    /// The counter the subscriber's readers share with GROUP ordered access.
    pub(crate) fn order(&self) -> Arc<AtomicU64> {
        self.order.clone()
    }

    /// Adds a reader that stores through [`AccessScope::deliver`].
    pub(crate) fn join(&self, member: Weak<dyn AccessMember>) {
        let mut g = lock(&self.gate);
        g.members.retain(|m| m.strong_count() > 0);
        g.members.push(member);
    }

    pub(crate) fn begin(&self) {
        lock(&self.gate).depth += 1;
    }

    /// Ends one level; the outermost delivers what the readers held back meanwhile.
    pub(crate) fn end(&self, driver: &Driver) -> DdsResult<()> {
        {
            let mut g = lock(&self.gate);
            if g.depth == 0 {
                return Err(DdsError::PreconditionNotMet(
                    "end_access without begin_access",
                ));
            }
            g.depth -= 1;
            if g.depth > 0 || g.members.is_empty() {
                return Ok(());
            }
        }
        self.deliver(driver);
        Ok(())
    }

    pub(crate) fn is_open(&self) -> bool {
        lock(&self.gate).depth > 0
    }

    /// Stores what the core queued for every reader of the subscriber, in one step: the queues are set
    /// aside together under the core lock (the core queues all parts of a group set in one hold of it),
    /// then stored under the gate, which `begin_access` also takes. Nothing is stored while an access scope
    /// is open (up to [`MAX_HELD`] changes); `end_access` delivers. Listeners run after the gate is free.
    pub(crate) fn deliver(&self, driver: &Driver) {
        let members: Vec<Arc<dyn AccessMember>> = {
            let g = lock(&self.gate);
            let members: Vec<_> = g.members.iter().filter_map(Weak::upgrade).collect();
            let held: usize = members.iter().map(|m| m.held()).sum();
            // Nothing queued: whatever is queued later comes with its own call (each reader the core
            // queues for is processed after), so the other readers of one batch cost no core lock here.
            if held == 0 {
                return;
            }
            if g.depth > 0 {
                if held < MAX_HELD {
                    return;
                }
                tracing::warn!(
                    held,
                    "access scope open too long: storing what its readers hold"
                );
            }
            driver.query_core(|_| members.iter().for_each(|m| m.stage()));
            members.iter().for_each(|m| m.commit());
            members
        };
        let _batch = super::data_on_readers::DataOnReadersBatch::start();
        for m in members {
            m.announce();
        }
    }
}

/// Whether reads return each instance's samples together (ordered access with INSTANCE scope) rather than
/// in reception order across instances (the default, and what TOPIC and GROUP scope ask for).
pub(crate) fn instance_ordered(p: &Presentation) -> bool {
    p.ordered_access && p.access_scope == PresentationAccessScope::Instance
}

/// Whether a subscriber's readers store through their [`AccessScope`] (GROUP access scope, coherent or
/// ordered).
pub(crate) fn group_scoped(p: &Presentation) -> bool {
    p.access_scope == PresentationAccessScope::Group && (p.coherent_access || p.ordered_access)
}

/// Whether a subscriber's readers share one order (ordered access with GROUP scope): `get_datareaders`
/// then lists a reader once per sample, in the order the samples were received.
pub(crate) fn group_ordered(p: &Presentation) -> bool {
    p.ordered_access && p.access_scope == PresentationAccessScope::Group
}
