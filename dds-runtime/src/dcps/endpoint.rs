//! What a typed writer and a typed reader share: their driver and entity id, their statuses and status
//! condition, their listener, the list of matched remote endpoints and the way back to a public handle.

use std::sync::{Arc, Mutex, OnceLock, Weak};
use std::time::Instant;

use crate::qos::History;
use crate::rtps::{CoreError, EntityId, Guid, Participant};

use super::condition::StatusCore;
use super::driver::{Driver, Endpoint, EndpointHandle};
use super::error::{DdsError, DdsResult};
use super::status::{MatchedStatus, Status, StatusMask};
use super::sync::lock;

/// Refuses a KEEP_LAST history of depth 0, for a reader as for a writer.
pub(crate) fn check_history(h: &History) -> DdsResult<()> {
    match h {
        History::KeepLast(0) => Err(DdsError::BadParameter("history depth 0".into())),
        _ => Ok(()),
    }
}

/// The side-independent state of an endpoint. `S` holds its statuses, `L` is its listener trait and `O` what
/// its handle keeps alive (see [`EndpointHandle`]).
pub(crate) struct EndpointState<S, L: ?Sized, O> {
    pub(crate) driver: Arc<Driver>,
    id: OnceLock<EntityId>,
    statuses: Mutex<S>,
    status_core: Arc<StatusCore>,
    listener: Mutex<Option<Arc<L>>>,
    matched: Mutex<Vec<Guid>>,
    handle: Mutex<Weak<EndpointHandle<O>>>,
}

impl<S: Default, L: ?Sized, O> EndpointState<S, L, O> {
    /// The state of an endpoint not yet created in the core.
    pub(crate) fn new(driver: Arc<Driver>) -> Self {
        EndpointState {
            driver,
            id: OnceLock::new(),
            statuses: Mutex::new(S::default()),
            status_core: Arc::new(StatusCore::default()),
            listener: Mutex::new(None),
            matched: Mutex::new(Vec::new()),
            handle: Mutex::new(Weak::new()),
        }
    }
}

impl<S, L: ?Sized, O> EndpointState<S, L, O> {
    /// Creates the endpoint in the core with `create` (see [`Driver::create_endpoint`]), with `sink` as
    /// its driver-facing side, and returns its handle.
    pub(crate) fn create(
        &self,
        sink: Arc<dyn Endpoint>,
        owner: O,
        create: impl FnOnce(&mut Participant, Instant) -> Result<EntityId, CoreError>,
    ) -> DdsResult<Arc<EndpointHandle<O>>> {
        let id = self.driver.create_endpoint(sink, |c, now| {
            let id = create(c, now)?;
            // Set once, here: the core reports nothing for the endpoint before `create` returns.
            let _ = self.id.set(id);
            Ok(id)
        })?;
        let handle = Arc::new(EndpointHandle::new(self.driver.clone(), id, owner));
        *lock(&self.handle) = Arc::downgrade(&handle);
        Ok(handle)
    }

    /// The entity id (`UNKNOWN` until created).
    pub(crate) fn id(&self) -> EntityId {
        self.id.get().copied().unwrap_or(EntityId::UNKNOWN)
    }

    /// The public handle, while some clone of the entity exists.
    pub(crate) fn handle(&self) -> Option<Arc<EndpointHandle<O>>> {
        lock(&self.handle).upgrade()
    }

    /// The status condition's state.
    pub(crate) fn status_core(&self) -> &Arc<StatusCore> {
        &self.status_core
    }

    /// Installs (or with `None` removes) the listener.
    pub(crate) fn set_listener(&self, l: Option<Arc<L>>) {
        *lock(&self.listener) = l;
    }

    /// The GUIDs of the matched remote endpoints.
    pub(crate) fn matched(&self) -> Vec<Guid> {
        lock(&self.matched).clone()
    }

    /// A status read by the application: returned, its change counts reset and its condition cleared.
    pub(crate) fn take_status<T: Status>(
        &self,
        mask: StatusMask,
        field: impl FnOnce(&mut S) -> &mut T,
    ) -> T {
        let mut st = lock(&self.statuses);
        let s = field(&mut st);
        let out = s.clone();
        s.reset_changes();
        self.status_core.clear(mask);
        out
    }

    /// Records a status change with `update`, raises `mask` and calls the listener, if any, with the entity
    /// (built from the handle by `entity`) and the status.
    pub(crate) fn signal<T: Status, E>(
        &self,
        mask: StatusMask,
        update: impl FnOnce(&mut S) -> &mut T,
        entity: impl FnOnce(Arc<EndpointHandle<O>>) -> E,
        call: impl FnOnce(&L, &E, T),
    ) {
        let (target, status) = self.update(update, false);
        self.deliver(mask, target, status, entity, call);
    }

    /// [`EndpointState::signal`] for a status whose listener consumes the change counts (DDS 1.4 §2.2.4.2.1),
    /// as the deadline statuses do: each callback reports only what happened since the previous one.
    pub(crate) fn signal_consumed<T: Status, E>(
        &self,
        mask: StatusMask,
        update: impl FnOnce(&mut S) -> &mut T,
        entity: impl FnOnce(Arc<EndpointHandle<O>>) -> E,
        call: impl FnOnce(&L, &E, T),
    ) {
        let (target, status) = self.update(update, true);
        self.deliver(mask, target, status, entity, call);
    }

    /// Records that `remote` matched or unmatched (see [`EndpointState::signal`]); a listener consumes the
    /// change counts.
    pub(crate) fn record_match<T: MatchedStatus, E>(
        &self,
        mask: StatusMask,
        field: impl FnOnce(&mut S) -> &mut T,
        (remote, matched): (Guid, bool),
        entity: impl FnOnce(Arc<EndpointHandle<O>>) -> E,
        call: impl FnOnce(&L, &E, T),
    ) {
        let (target, status) = {
            let mut list = lock(&self.matched);
            self.update(
                |st| {
                    let s = field(st);
                    s.record_match(&mut list, remote, matched);
                    s
                },
                true,
            )
        };
        self.deliver(mask, target, status, entity, call);
    }

    /// Applies `update` to a status. With `consume`, a listener consumes the change counts (DDS 2.2.4.2.1):
    /// the next callback reports only what happened since this one.
    #[allow(clippy::type_complexity)]
    fn update<T: Status>(
        &self,
        update: impl FnOnce(&mut S) -> &mut T,
        consume: bool,
    ) -> (Option<(Arc<L>, Arc<EndpointHandle<O>>)>, T) {
        let target = lock(&self.listener)
            .clone()
            .and_then(|l| Some((l, self.handle()?)));
        let mut st = lock(&self.statuses);
        let s = update(&mut st);
        let out = s.clone();
        if consume && target.is_some() {
            s.reset_changes();
        }
        (target, out)
    }

    /// Raises `mask`, then (no lock held) calls the listener.
    fn deliver<T, E>(
        &self,
        mask: StatusMask,
        target: Option<(Arc<L>, Arc<EndpointHandle<O>>)>,
        status: T,
        entity: impl FnOnce(Arc<EndpointHandle<O>>) -> E,
        call: impl FnOnce(&L, &E, T),
    ) {
        self.status_core.raise(mask);
        if let Some((l, h)) = target {
            call(&l, &entity(h), status);
        }
    }

    /// Calls the listener, if any, with the entity, without a status (DATA_AVAILABLE).
    pub(crate) fn call_listener<E>(
        &self,
        entity: impl FnOnce(Arc<EndpointHandle<O>>) -> E,
        call: impl FnOnce(&L, &E),
    ) {
        let l = lock(&self.listener).clone();
        if let (Some(l), Some(h)) = (l, self.handle()) {
            call(&l, &entity(h));
        }
    }
}
