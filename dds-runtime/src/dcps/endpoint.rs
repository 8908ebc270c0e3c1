//! What a typed writer and a typed reader share: their driver and entity id, their statuses and status
//! condition, their listener, the list of matched remote endpoints and the way back to a public handle.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock, Weak};
use std::time::Instant;

use crate::qos::History;
use crate::rtps::{CoreError, EntityId, Guid, Participant};

use super::chain::{ErasedStatus, ListenerNode, MaskedListener, ParentListener, StatusChange};
use super::condition::StatusCore;
use super::driver::{Driver, Endpoint, EndpointHandle};
use super::error::{DdsError, DdsResult};
use super::sample::InstanceHandle;
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
    /// The instance handle of the endpoint's GUID, set with `id` (the data path names it per sample).
    instance: OnceLock<InstanceHandle>,
    statuses: Mutex<S>,
    status_core: Arc<StatusCore>,
    listener: Mutex<Option<MaskedListener<L>>>,
    /// The publisher or subscriber level of the listener chain (set once, when registered).
    parent: OnceLock<Arc<ListenerNode>>,
    /// Set by an explicit `delete_*`: the entity refuses operations from then on.
    deleted: Arc<AtomicBool>,
    matched: Mutex<Vec<Guid>>,
    handle: Mutex<Weak<EndpointHandle<O>>>,
    /// Whether the endpoint is enabled (announced and matched); see `dcps::enable`.
    enabled: AtomicBool,
}

/// Where a status goes: the entity's own listener, or one of the levels above.
enum Target<L: ?Sized, H> {
    Own(Arc<L>, H),
    Parent(Arc<dyn ParentListener>),
}

impl<S: Default, L: ?Sized, O> EndpointState<S, L, O> {
    /// The state of an endpoint not yet created in the core.
    pub(crate) fn new(driver: Arc<Driver>) -> Self {
        EndpointState {
            driver,
            id: OnceLock::new(),
            instance: OnceLock::new(),
            statuses: Mutex::new(S::default()),
            status_core: Arc::new(StatusCore::default()),
            listener: Mutex::new(None),
            parent: OnceLock::new(),
            deleted: Arc::new(AtomicBool::new(false)),
            matched: Mutex::new(Vec::new()),
            handle: Mutex::new(Weak::new()),
            enabled: AtomicBool::new(true),
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
        let mut owner = Some(owner);
        let mut handle = None;
        self.driver.create_endpoint(sink, |c, now| {
            let id = create(c, now)?;
            // Set once, here, under the core lock: the core reports nothing for the endpoint before `create`
            // returns, and its first events (matches with known peers, a late joiner's history) are handed
            // to listeners only after the lock is released. So a listener installed before creation gets
            // them with a valid handle.
            let _ = self.id.set(id);
            let _ = self.instance.set(InstanceHandle::from_guid(Guid::new(
                self.driver.guid_prefix,
                id,
            )));
            if let Some(owner) = owner.take() {
                let h = Arc::new(EndpointHandle::new(self.driver.clone(), id, owner));
                *lock(&self.handle) = Arc::downgrade(&h);
                handle = Some(h);
            }
            Ok(id)
        })?;
        handle.ok_or(DdsError::PreconditionNotMet(
            "endpoint created without a handle",
        ))
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

    /// Installs (or with `None` removes) the listener, enabled for every status.
    pub(crate) fn set_listener(&self, l: Option<Arc<L>>) {
        self.set_listener_with_mask(l, StatusMask::all());
    }

    /// Installs (or with `None` removes) the listener, enabled for the statuses in `mask` only; the
    /// others go to the levels above (DDS 1.4 §2.2.4.1).
    pub(crate) fn set_listener_with_mask(&self, l: Option<Arc<L>>, mask: StatusMask) {
        *lock(&self.listener) = l.map(|listener| MaskedListener { listener, mask });
    }

    /// Links the entity to its publisher or subscriber level of the listener chain (once).
    pub(crate) fn set_parent(&self, node: Arc<ListenerNode>) {
        let _ = self.parent.set(node);
    }

    /// The flag an explicit delete sets (shared with the participant's entity registry).
    pub(crate) fn deleted_flag(&self) -> &Arc<AtomicBool> {
        &self.deleted
    }

    /// An explicit `delete_*`: the entity refuses operations from then on and leaves the core (a writer
    /// unregisters its instances first). `AlreadyDeleted` when it was deleted before.
    pub(crate) fn delete(&self) -> DdsResult<()> {
        self.check_alive()?;
        if self.deleted.swap(true, Ordering::AcqRel) {
            return Err(DdsError::AlreadyDeleted);
        }
        if let Some(parent) = self.parent.get() {
            parent.forget(self.instance());
        }
        self.driver.delete_endpoint(self.id());
        Ok(())
    }

    /// `Err(NotEnabled)` while the endpoint is disabled (after `check_alive`).
    pub(crate) fn check_enabled(&self) -> DdsResult<()> {
        self.check_alive()?;
        if !self.enabled.load(Ordering::Acquire) {
            return Err(DdsError::NotEnabled);
        }
        Ok(())
    }

    /// Records that the endpoint was created disabled (before it is visible to the application).
    pub(crate) fn set_created_disabled(&self) {
        self.enabled.store(false, Ordering::Release);
    }

    /// `enable()` of a reader or writer: `PreconditionNotMet` while one of its `parents` (group, topic) is
    /// disabled in `registry`, else [`EndpointState::enable_in_core`].
    pub(crate) fn enable_under(
        &self,
        registry: &super::registry::Registry,
        parents: impl FnOnce() -> DdsResult<[InstanceHandle; 2]>,
    ) -> DdsResult<()> {
        self.check_alive()?;
        registry.check_parents_enabled(&parents()?)?;
        self.enable_in_core()
    }

    /// Enables an endpoint created disabled: the core announces and matches it. Nothing when enabled.
    pub(crate) fn enable_in_core(&self) -> DdsResult<()> {
        self.check_alive()?;
        if !self.enabled.swap(true, Ordering::AcqRel) {
            let id = self.id();
            self.driver.with_core(|c, now| c.enable_endpoint(now, id));
        }
        Ok(())
    }

    /// `Err(AlreadyDeleted)` once the entity or its participant was deleted.
    pub(crate) fn check_alive(&self) -> DdsResult<()> {
        if self.deleted.load(Ordering::Acquire) {
            return Err(DdsError::AlreadyDeleted);
        }
        self.driver.check_alive()
    }

    /// The entity's own listener if it is enabled for `kind`.
    fn own_listener(&self, kind: StatusMask) -> Option<Arc<L>> {
        match &*lock(&self.listener) {
            Some(m) if m.mask.contains(kind) => Some(m.listener.clone()),
            _ => None,
        }
    }

    /// The most specific listener enabled for `kind` (DDS 1.4 §2.2.4.1), with the public handle when it is
    /// the entity's own.
    fn target(&self, kind: StatusMask) -> Option<Target<L, Arc<EndpointHandle<O>>>> {
        if let Some(l) = self.own_listener(kind) {
            return Some(Target::Own(l, self.handle()?));
        }
        self.parent.get()?.find(kind).map(Target::Parent)
    }

    /// A read or take: the subscriber's DATA_ON_READERS is reset (DDS 1.4 §2.2.4.1).
    pub(crate) fn data_read(&self) {
        if let Some(parent) = self.parent.get() {
            parent.clear_all_up(&[
                (self.instance(), StatusMask::DATA_AVAILABLE),
                (parent.handle, StatusMask::DATA_ON_READERS),
            ]);
        }
    }

    /// The GUID of the endpoint.
    fn guid(&self) -> Guid {
        Guid::new(self.driver.guid_prefix, self.id())
    }

    /// The endpoint's instance handle, as the levels above know it.
    fn instance(&self) -> InstanceHandle {
        match self.instance.get() {
            Some(h) => *h,
            None => InstanceHandle::from_guid(self.guid()),
        }
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
        if let Some(parent) = self.parent.get() {
            parent.clear_up(self.instance(), mask);
        }
        out
    }

    /// Records a status change with `update`, raises `mask` and calls the listener, if any, with the entity
    /// (built from the handle by `entity`) and the status.
    pub(crate) fn signal<T: ErasedStatus, E>(
        &self,
        mask: StatusMask,
        update: impl FnOnce(&mut S) -> &mut T,
        entity: impl FnOnce(Arc<EndpointHandle<O>>) -> E,
        call: impl FnOnce(&L, &E, T),
    ) {
        if let Some((target, status)) = self.update(mask, |s| Some(update(s)), false) {
            self.deliver(mask, target, status, entity, call);
        }
    }

    /// [`EndpointState::signal`] when `update` changed the status (returns it), nothing otherwise.
    pub(crate) fn signal_if<T: ErasedStatus, E>(
        &self,
        mask: StatusMask,
        update: impl FnOnce(&mut S) -> Option<&mut T>,
        entity: impl FnOnce(Arc<EndpointHandle<O>>) -> E,
        call: impl FnOnce(&L, &E, T),
    ) {
        if let Some((target, status)) = self.update(mask, update, false) {
            self.deliver(mask, target, status, entity, call);
        }
    }

    /// [`EndpointState::signal`] for a status whose listener consumes the change counts (DDS 1.4 §2.2.4.2.1),
    /// as the deadline statuses do: each callback reports only what happened since the previous one.
    pub(crate) fn signal_consumed<T: ErasedStatus, E>(
        &self,
        mask: StatusMask,
        update: impl FnOnce(&mut S) -> &mut T,
        entity: impl FnOnce(Arc<EndpointHandle<O>>) -> E,
        call: impl FnOnce(&L, &E, T),
    ) {
        if let Some((target, status)) = self.update(mask, |s| Some(update(s)), true) {
            self.deliver(mask, target, status, entity, call);
        }
    }

    /// Records that `remote` matched or unmatched (see [`EndpointState::signal`]); a listener consumes the
    /// change counts.
    pub(crate) fn record_match<T: MatchedStatus + ErasedStatus, E>(
        &self,
        mask: StatusMask,
        field: impl FnOnce(&mut S) -> &mut T,
        (remote, matched): (Guid, bool),
        entity: impl FnOnce(Arc<EndpointHandle<O>>) -> E,
        call: impl FnOnce(&L, &E, T),
    ) {
        let updated = {
            let mut list = lock(&self.matched);
            self.update(
                mask,
                |st| {
                    let s = field(st);
                    s.record_match(&mut list, remote, matched);
                    Some(s)
                },
                true,
            )
        };
        if let Some((target, status)) = updated {
            self.deliver(mask, target, status, entity, call);
        }
    }

    /// Applies `update` to a status (`None`: it did not change). With `consume`, a listener consumes the
    /// change counts (DDS 2.2.4.2.1): the next callback reports only what happened since this one.
    #[allow(clippy::type_complexity)]
    fn update<T: ErasedStatus>(
        &self,
        mask: StatusMask,
        update: impl FnOnce(&mut S) -> Option<&mut T>,
        consume: bool,
    ) -> Option<(Option<Target<L, Arc<EndpointHandle<O>>>>, T)> {
        let target = self.target(mask);
        let mut st = lock(&self.statuses);
        let s = update(&mut st)?;
        let out = s.clone();
        if consume && target.is_some() {
            s.reset_changes();
        }
        Some((target, out))
    }

    /// Raises `mask`, then (no lock held) calls the listener chosen by [`EndpointState::target`].
    fn deliver<T: ErasedStatus, E>(
        &self,
        mask: StatusMask,
        target: Option<Target<L, Arc<EndpointHandle<O>>>>,
        status: T,
        entity: impl FnOnce(Arc<EndpointHandle<O>>) -> E,
        call: impl FnOnce(&L, &E, T),
    ) {
        self.status_core.raise(mask);
        if let Some(parent) = self.parent.get() {
            parent.raise_up(self.instance(), mask);
        }
        match target {
            Some(Target::Own(l, h)) => call(&l, &entity(h), status),
            Some(Target::Parent(l)) => {
                if let Some(change) = status.erase(mask) {
                    l.on_status(InstanceHandle::from_guid(self.guid()), change);
                }
            }
            None => {}
        }
    }

    /// Calls the entity's own listener, if any (`notify_datareaders`), regardless of the levels above.
    pub(crate) fn call_own_listener<E>(
        &self,
        entity: impl FnOnce(Arc<EndpointHandle<O>>) -> E,
        call: impl FnOnce(&L, &E),
    ) {
        let l = lock(&self.listener).as_ref().map(|m| m.listener.clone());
        if let (Some(l), Some(h)) = (l, self.handle()) {
            call(&l, &entity(h));
        }
    }

    /// New data arrived (DATA_AVAILABLE): raises DATA_ON_READERS on the subscriber and calls, by DDS 1.4
    /// §2.2.4.1 precedence, the nearest `on_data_on_readers` (subscriber, participant), else the reader's
    /// own `on_data_available` (`call`), else the nearest level's.
    pub(crate) fn call_listener<E>(
        &self,
        entity: impl FnOnce(Arc<EndpointHandle<O>>) -> E,
        call: impl FnOnce(&L, &E),
    ) {
        if let Some(parent) = self.parent.get() {
            parent.raise_all_up(&[
                (self.instance(), StatusMask::DATA_AVAILABLE),
                (parent.handle, StatusMask::DATA_ON_READERS),
            ]);
            if let Some(l) = parent.find(StatusMask::DATA_ON_READERS) {
                if super::data_on_readers::defer_data_on_readers(parent) {
                    return;
                }
                parent.clear_up(parent.handle, StatusMask::DATA_ON_READERS);
                l.on_data_on_readers(parent.handle);
                return;
            }
        }
        match self.target(StatusMask::DATA_AVAILABLE) {
            Some(Target::Own(l, h)) => call(&l, &entity(h)),
            Some(Target::Parent(l)) => l.on_status(
                InstanceHandle::from_guid(self.guid()),
                StatusChange::DataAvailable,
            ),
            None => {}
        }
    }
}
