//! The participant's type store: every type object we own (the types of our endpoints) or have learnt (from
//! TypeLookup replies, each checked against its hash), keyed by [`TypeIdentifier`].
//!
//! Bounded: learnt objects are limited in number and in serialized bytes ([`StoreLimits`]); what does not fit
//! is refused, never evicting an owned type. A hostile peer cannot make the store grow without bound.

use std::collections::HashMap;
use std::sync::Arc;

use thiserror::Error;

use super::typeobject::{
    to_bytes, TypeIdentifier, TypeIdentifierWithSize, TypeInformation, TypeMapping, TypeObject,
};

/// Dependencies kept per type (a peer's list beyond it is cut: the store stays bounded).
const MAX_DEPENDENCIES: usize = 256;

/// How much a store may learn from peers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StoreLimits {
    /// Most learnt type objects.
    pub max_learnt: usize,
    /// Most serialized bytes of learnt type objects.
    pub max_learnt_bytes: usize,
}

impl Default for StoreLimits {
    fn default() -> Self {
        StoreLimits {
            max_learnt: 4096,
            max_learnt_bytes: 8 << 20,
        }
    }
}

/// Why a received type object was not stored.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum StoreError {
    /// The identifier is not a minimal or complete hash.
    #[error("type identifier is not a hash")]
    NotHashed,
    /// A minimal identifier with a complete object, or the reverse.
    #[error("type object kind does not match its identifier")]
    KindMismatch,
    /// The object's serialization does not hash to its identifier.
    #[error("type object does not hash to its identifier")]
    HashMismatch,
    /// The object cannot be serialized (so not hashed either).
    #[error("type object cannot be serialized")]
    Unencodable,
    /// The store's limits are reached.
    #[error("type store full")]
    Full,
}

#[derive(Debug)]
struct Entry {
    object: Arc<TypeObject>,
    size: usize,
    owned: bool,
}

/// The type store. See the module documentation.
#[derive(Debug, Default)]
pub struct TypeStore {
    objects: HashMap<TypeIdentifier, Entry>,
    /// The dependencies of the topic types we know a `TypeInformation` of (for `getTypeDependencies`).
    dependencies: HashMap<TypeIdentifier, Arc<[TypeIdentifierWithSize]>>,
    learnt: usize,
    learnt_bytes: usize,
    limits: StoreLimits,
}

impl TypeStore {
    /// An empty store with these limits.
    pub fn new(limits: StoreLimits) -> Self {
        TypeStore {
            limits,
            ..TypeStore::default()
        }
    }

    /// The type object of `id`, if owned or learnt.
    pub fn get(&self, id: &TypeIdentifier) -> Option<Arc<TypeObject>> {
        self.objects.get(id).map(|e| e.object.clone())
    }

    /// Whether the store holds the object of `id`.
    pub fn contains(&self, id: &TypeIdentifier) -> bool {
        self.objects.contains_key(id)
    }

    /// Number of objects held (owned and learnt).
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether the store is empty.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// Serialized bytes of the object of `id` (0 if not held).
    pub fn serialized_size(&self, id: &TypeIdentifier) -> usize {
        self.objects.get(id).map_or(0, |e| e.size)
    }

    /// Serialized bytes of the learnt objects.
    pub fn learnt_bytes(&self) -> usize {
        self.learnt_bytes
    }

    /// Adds the types of one of our own endpoints: every object of its mapping (never evicted, not counted
    /// against the limits) and its dependency lists.
    pub fn add_owned(&mut self, information: &TypeInformation, mapping: &TypeMapping) {
        let pairs = mapping
            .identifier_object_pair_minimal
            .iter()
            .chain(&mapping.identifier_object_pair_complete);
        for p in pairs {
            let size = to_bytes(&p.type_object).map_or(0, |b| b.len());
            if let Some(old) = self.objects.insert(
                p.type_identifier.clone(),
                Entry {
                    object: Arc::new(p.type_object.clone()),
                    size,
                    owned: true,
                },
            ) {
                if !old.owned {
                    self.learnt -= 1;
                    self.learnt_bytes -= old.size;
                }
            }
        }
        self.add_dependencies(information);
    }

    /// Records the dependency lists of a `TypeInformation` (owned, or announced by a peer), bounded like the
    /// learnt objects.
    pub fn add_dependencies(&mut self, information: &TypeInformation) {
        for d in [&information.minimal, &information.complete] {
            let id = &d.typeid_with_size.type_id;
            if id.hash().is_none() || self.dependencies.contains_key(id) {
                continue;
            }
            if self.dependencies.len() >= self.limits.max_learnt {
                return;
            }
            let deps: Vec<TypeIdentifierWithSize> = d
                .dependent_typeids
                .iter()
                .take(MAX_DEPENDENCIES)
                .cloned()
                .collect();
            self.dependencies.insert(id.clone(), deps.into());
        }
    }

    /// The known dependencies of `id` (empty if none are known).
    pub fn dependencies(&self, id: &TypeIdentifier) -> Arc<[TypeIdentifierWithSize]> {
        self.dependencies
            .get(id)
            .cloned()
            .unwrap_or_else(|| Arc::from(Vec::new()))
    }

    /// Stores a received object after checking that it is of its identifier's kind and that its XCDR2
    /// serialization hashes to the identifier. `Ok(false)`: already held.
    pub fn insert_verified(
        &mut self,
        id: TypeIdentifier,
        object: TypeObject,
    ) -> Result<bool, StoreError> {
        let (hash, minimal) = match &id {
            TypeIdentifier::Minimal(h) => (h, true),
            TypeIdentifier::Complete(h) => (h, false),
            _ => return Err(StoreError::NotHashed),
        };
        if minimal != matches!(object, TypeObject::Minimal(_)) {
            return Err(StoreError::KindMismatch);
        }
        if self.objects.contains_key(&id) {
            return Ok(false);
        }
        let bytes = to_bytes(&object).map_err(|_| StoreError::Unencodable)?;
        if &super::typeobject::equivalence_hash(&bytes) != hash {
            return Err(StoreError::HashMismatch);
        }
        if self.learnt >= self.limits.max_learnt
            || self.learnt_bytes + bytes.len() > self.limits.max_learnt_bytes
        {
            return Err(StoreError::Full);
        }
        self.learnt += 1;
        self.learnt_bytes += bytes.len();
        self.objects.insert(
            id,
            Entry {
                object: Arc::new(object),
                size: bytes.len(),
                owned: false,
            },
        );
        Ok(true)
    }

    /// The hashed identifiers a `TypeInformation` names (both topic types and their listed dependencies)
    /// whose objects the store lacks, each once.
    pub fn missing(&self, information: &TypeInformation) -> Vec<TypeIdentifier> {
        let mut out: Vec<TypeIdentifier> = Vec::new();
        for d in [&information.complete, &information.minimal] {
            let ids = std::iter::once(&d.typeid_with_size).chain(&d.dependent_typeids);
            for t in ids {
                let id = &t.type_id;
                if id.hash().is_some() && !self.contains(id) && !out.contains(id) {
                    out.push(id.clone());
                }
            }
        }
        out
    }
}
