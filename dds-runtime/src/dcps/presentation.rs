//! PRESENTATION (DDS 1.4 §2.2.3.6): the state behind `Publisher::begin_coherent_changes` /
//! `end_coherent_changes` and `Subscriber::begin_access` / `end_access`.
//!
//! A publisher's coherent set spans all its writers: while one is open, each writer (also one created
//! meanwhile) has a coherent set open in the RTPS core, and ending it sends every writer's end-of-set
//! marker. Readers deliver each writer's part of the set whole or not at all (see `rtps::reader::coherent`).
//! With GROUP access scope the writers also share a [`WriterGroup`]: group sequence numbers on every
//! change, and a group coherent set whose parts readers deliver together (`rtps::participant::group`).

use std::sync::atomic::AtomicU64;
use std::sync::{Arc, Mutex};
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
            if p.access_scope == PresentationAccessScope::Group
                && (p.coherent_access || p.ordered_access)
            {
                st.group.get_or_insert_with(WriterGroup::default);
            }
            (st.depth > 0, st.group.clone())
        };
        let _ = driver.with_core(|c, _| {
            if let Some(g) = &group {
                c.join_writer_group(id, g)?;
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

/// A subscriber's access scope: `begin_access` / `end_access` nesting, and the counter its readers number
/// their samples from with GROUP ordered access (one order across the readers, for `get_datareaders`).
#[derive(Debug, Default)]
pub(crate) struct AccessScope {
    depth: Mutex<u32>,
    order: Arc<AtomicU64>,
}

impl AccessScope {
    /// The counter the subscriber's readers share with GROUP ordered access.
    pub(crate) fn order(&self) -> Arc<AtomicU64> {
        self.order.clone()
    }

    pub(crate) fn begin(&self) {
        *lock(&self.depth) += 1;
    }

    pub(crate) fn end(&self) -> DdsResult<()> {
        let mut d = lock(&self.depth);
        if *d == 0 {
            return Err(DdsError::PreconditionNotMet(
                "end_access without begin_access",
            ));
        }
        *d -= 1;
        Ok(())
    }

    pub(crate) fn is_open(&self) -> bool {
        *lock(&self.depth) > 0
    }
}

/// Whether reads return each instance's samples together (ordered access with INSTANCE scope) rather than
/// in reception order across instances (the default, and what TOPIC and GROUP scope ask for).
pub(crate) fn instance_ordered(p: &Presentation) -> bool {
    p.ordered_access && p.access_scope == PresentationAccessScope::Instance
}

/// Whether a subscriber's readers share one order (ordered access with GROUP scope): `get_datareaders`
/// then lists a reader once per sample, in the order the samples were received.
pub(crate) fn group_ordered(p: &Presentation) -> bool {
    p.ordered_access && p.access_scope == PresentationAccessScope::Group
}
