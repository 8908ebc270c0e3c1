//! The dynamic writer's instances: registered by serialized key in the typed writer's
//! [`WriterInstances`](super::WriterInstances), looked up, disposed and unregistered by value or handle.

use std::time::{Instant, SystemTime};

use crate::cdr::ByteOrder;
use crate::rtps::{ChangeKind, Payload};
use crate::xtypes::dynamic::DynamicData;

use super::super::super::error::{DdsError, DdsResult};
use super::super::super::publisher::unregister_kind;
use super::super::super::sample::InstanceHandle;
use super::super::super::sync::{lock, read};
use super::DynamicWriter;

impl DynamicWriter {
    /// The instance of `sample` (by serialized key) and its key hash; registers it when `create`, and
    /// records a write when `written`.
    pub(super) fn instance_of(
        &self,
        sample: &DynamicData,
        create: bool,
        written: bool,
    ) -> DdsResult<Option<(InstanceHandle, Option<[u8; 16]>)>> {
        self.check_type(sample)?;
        let mut key = Vec::new();
        sample.instance_key(&mut key)?;
        let now = Instant::now();
        if let Some(found) = lock(&self.inner.instances).lookup(&key, written.then_some(now)) {
            return Ok(Some(found));
        }
        if !create {
            return Ok(None);
        }
        let version = self.inner.version;
        let mut key_payload = Vec::new();
        sample.serialize_key(version, ByteOrder::NATIVE, &mut key_payload)?;
        let key_hash = sample.key_hash(version)?;
        let mut inst = lock(&self.inner.instances);
        Ok(Some(inst.register(
            key,
            Payload::from(key_payload),
            Some(key_hash),
            now,
        )))
    }

    /// Registers the instance of `sample` and returns its handle (nothing is sent); `NIL` for a keyless
    /// type.
    pub fn register_instance(&self, sample: &DynamicData) -> DdsResult<InstanceHandle> {
        if !self.keyed() {
            self.check_type(sample)?;
            return Ok(InstanceHandle::NIL);
        }
        Ok(self
            .instance_of(sample, true, false)?
            .map_or(InstanceHandle::NIL, |(h, _)| h))
    }

    /// The handle of the instance of `sample`, if registered or written.
    pub fn lookup_instance(&self, sample: &DynamicData) -> DdsResult<Option<InstanceHandle>> {
        if !self.keyed() {
            self.check_type(sample)?;
            return Ok(None);
        }
        Ok(self.instance_of(sample, false, false)?.map(|(h, _)| h))
    }

    /// The key of the instance `handle`: a sample whose key members are set and whose other members have
    /// their defaults. `BadParameter` for an unknown handle.
    pub fn get_key_value(&self, handle: InstanceHandle) -> DdsResult<DynamicData> {
        self.inner.state.check_alive()?;
        let payload = lock(&self.inner.instances).key_payload(handle)?;
        Ok(DynamicData::deserialize_key(
            self.topic().dynamic_type(),
            &payload,
        )?)
    }

    /// Sends a key-only change of `kind` for the instance of `sample`, or else of `handle`.
    fn key_change(
        &self,
        kind: ChangeKind,
        sample: Option<&DynamicData>,
        handle: InstanceHandle,
        ts: SystemTime,
    ) -> DdsResult<()> {
        if !self.keyed() {
            return Err(DdsError::PreconditionNotMet("the topic type has no key"));
        }
        let h = match sample {
            Some(s) => self
                .instance_of(s, true, false)?
                .map_or(InstanceHandle::NIL, |(h, _)| h),
            None => handle,
        };
        let change = lock(&self.inner.instances).key_change(h, kind, ts)?;
        self.submit(change)?;
        lock(&self.inner.instances).key_change_sent(h, kind);
        Ok(())
    }

    /// Disposes the instance of `sample` (keyed types only; `PreconditionNotMet` otherwise).
    pub fn dispose(&self, sample: &DynamicData) -> DdsResult<()> {
        self.key_change(
            ChangeKind::Dispose,
            Some(sample),
            InstanceHandle::NIL,
            SystemTime::now(),
        )
    }

    /// Disposes the instance `handle`; `BadParameter` for an instance not registered.
    pub fn dispose_w_handle(&self, handle: InstanceHandle) -> DdsResult<()> {
        self.key_change(ChangeKind::Dispose, None, handle, SystemTime::now())
    }

    /// Unregisters the instance of `sample`; with `autodispose_unregistered_instances` (the default) it is
    /// disposed too. The writer forgets the instance.
    pub fn unregister_instance(&self, sample: &DynamicData) -> DdsResult<()> {
        let kind = unregister_kind(&read(&self.inner.current));
        self.key_change(kind, Some(sample), InstanceHandle::NIL, SystemTime::now())
    }

    /// Unregisters the instance `handle` (see [`unregister_instance`](Self::unregister_instance)).
    pub fn unregister_instance_w_handle(&self, handle: InstanceHandle) -> DdsResult<()> {
        let kind = unregister_kind(&read(&self.inner.current));
        self.key_change(kind, None, handle, SystemTime::now())
    }
}
