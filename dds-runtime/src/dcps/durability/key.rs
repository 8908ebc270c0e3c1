//! Key hashes for keyed changes that arrive without one (Cyclone DDS sends none). The service decodes such a
//! payload with the writer's type, resolved from the type information the writer announced and the type
//! objects the participant's TypeLookup client fetched when the writer was discovered, and hashes its key as
//! the writer would have. Without type information (Fast DDS 2.9 announces none, but sends key hashes), or
//! before the objects arrived, the caller falls back to a digest of the payload.

use std::collections::HashMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use crate::cdr::EncapsulationHeader;
use crate::dcps::driver::Driver;
use crate::dcps::sync::lock;
use crate::rtps::{ChangeKind, Guid};
use crate::xtypes::dynamic::{DynamicData, DynamicType};
use crate::xtypes::TypeInformation;

/// How long a writer whose type could not be resolved waits before the next attempt.
const RETRY: Duration = Duration::from_secs(1);

/// Most writers whose types are remembered; past it the memory starts over.
const MAX_WRITERS: usize = 4096;

enum Resolution {
    Ready(DynamicType),
    Unavailable { retry_at: Instant },
}

/// The writers' types, as far as they are known.
#[derive(Default)]
pub(crate) struct KeyTypes {
    types: Mutex<HashMap<Guid, Resolution>>,
}

impl KeyTypes {
    /// The key hash of a change of `writer` (which announced `info`), or `None` when its type is not
    /// known (yet) or the payload does not decode as it. Takes the core lock: call it without the
    /// service's state lock.
    pub(crate) fn key_hash(
        &self,
        driver: &Driver,
        writer: Guid,
        info: Option<&TypeInformation>,
        kind: ChangeKind,
        payload: &[u8],
    ) -> Option<[u8; 16]> {
        let ty = self.type_of(driver, writer, info?)?;
        let data = if kind == ChangeKind::Alive {
            DynamicData::deserialize(&ty, payload)
        } else {
            DynamicData::deserialize_key(&ty, payload)
        };
        let version = EncapsulationHeader::parse(payload).ok()?.version().ok()?;
        data.ok()?.key_hash(version).ok()
    }

    /// Forgets a writer the service no longer keeps.
    pub(crate) fn forget(&self, writer: &Guid) {
        lock(&self.types).remove(writer);
    }

    fn type_of(
        &self,
        driver: &Driver,
        writer: Guid,
        info: &TypeInformation,
    ) -> Option<DynamicType> {
        let now = Instant::now();
        match lock(&self.types).get(&writer) {
            Some(Resolution::Ready(t)) => return Some(t.clone()),
            Some(Resolution::Unavailable { retry_at }) if now < *retry_at => return None,
            _ => {}
        }
        let resolved = info.decode().ok().and_then(|info| {
            let id = info.complete.typeid_with_size.type_id;
            driver.with_core(|c, _| {
                let store = c.type_store();
                DynamicType::from_type_identifier(&id, &|i| store.get(i)).ok()
            })
        });
        let mut types = lock(&self.types);
        if types.len() >= MAX_WRITERS && !types.contains_key(&writer) {
            types.clear();
        }
        let entry = match &resolved {
            Some(t) => Resolution::Ready(t.clone()),
            None => Resolution::Unavailable {
                retry_at: now + RETRY,
            },
        };
        types.insert(writer, entry);
        resolved
    }
}
