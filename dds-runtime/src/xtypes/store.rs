//! The participant's type store: every type object we own (the types of our endpoints) or have learnt (from
//! TypeLookup replies, each checked against its hash), keyed by [`TypeIdentifier`].
//!
//! A recursive type's objects (a strongly connected component, XTypes 1.3 §7.3.4.9) are learnt whole: every type
//! of the component, checked together against the component's hash ([`TypeStore::insert_component`]).
//!
//! Bounded: learnt objects are limited in number and in serialized bytes ([`StoreLimits`]); what does not fit
//! is refused, never evicting an owned type. A hostile peer cannot make the store grow without bound.

use std::collections::HashMap;
use std::sync::Arc;

use thiserror::Error;

use super::typeobject::{
    kind, to_bytes, EquivalenceKind, StronglyConnectedComponentId, TypeIdentifier,
    TypeIdentifierWithSize, TypeInformation, TypeMapping, TypeObject,
};

/// Most types in one learnt strongly connected component.
pub(crate) const MAX_COMPONENT: i32 = 256;

/// Whether the store and the TypeLookup service deal in `id`: a hash, or a strongly connected component's.
pub fn is_lookup_id(id: &TypeIdentifier) -> bool {
    id.hash().is_some() || matches!(id, TypeIdentifier::StronglyConnected(_))
}

/// The component `id` names (with its index set to 0: the component as a whole), if it is a component id.
pub fn component_of(id: &TypeIdentifier) -> Option<StronglyConnectedComponentId> {
    match id {
        TypeIdentifier::StronglyConnected(c) => {
            Some(StronglyConnectedComponentId { scc_index: 0, ..*c })
        }
        _ => None,
    }
}

fn member_id(c: StronglyConnectedComponentId, index: i32) -> TypeIdentifier {
    TypeIdentifier::StronglyConnected(StronglyConnectedComponentId {
        scc_index: index,
        ..c
    })
}

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
    /// A strongly connected component's objects are not all there, repeated, or not of one component.
    #[error("strongly connected component incomplete or inconsistent")]
    Incomplete,
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

    /// Whether the store holds the object of `id` (for a whole component, index 0: the objects of its types).
    pub fn contains(&self, id: &TypeIdentifier) -> bool {
        match component_of(id) {
            Some(c) if c.scc_length > 0 => self.objects.contains_key(&member_id(c, 1)),
            _ => self.objects.contains_key(id),
        }
    }

    /// The objects `id` names, with their identifiers: its own, or for any type of a strongly connected
    /// component (or the component as a whole) those of every type of the component, by index. `None` if any
    /// is missing.
    pub fn objects_of(
        &self,
        id: &TypeIdentifier,
    ) -> Option<Vec<(TypeIdentifier, Arc<TypeObject>)>> {
        let Some(c) = component_of(id) else {
            return self.get(id).map(|o| vec![(id.clone(), o)]);
        };
        if !(1..=MAX_COMPONENT).contains(&c.scc_length) {
            return None;
        }
        (1..=c.scc_length)
            .map(|i| {
                let id = member_id(c, i);
                self.get(&id).map(|o| (id, o))
            })
            .collect()
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

    /// Stores the objects of every type of one strongly connected component, received together: each
    /// identifier is of the component (same kind, hash and length, every index from 1 once), each object of
    /// its kind, and the objects, serialized with the component's hash zeroed where they name each other and
    /// put in a sequence by index, hash to the component's hash (how `TypeSupport` builds them). `Ok(false)`:
    /// already held.
    pub fn insert_component(
        &mut self,
        pairs: &[(TypeIdentifier, TypeObject)],
    ) -> Result<bool, StoreError> {
        let c = pairs
            .first()
            .and_then(|(id, _)| component_of(id))
            .ok_or(StoreError::NotHashed)?;
        if !(1..=MAX_COMPONENT).contains(&c.scc_length) || pairs.len() != c.scc_length as usize {
            return Err(StoreError::Incomplete);
        }
        let mut by_index: Vec<Option<&TypeObject>> = vec![None; pairs.len()];
        for (id, object) in pairs {
            let TypeIdentifier::StronglyConnected(m) = id else {
                return Err(StoreError::Incomplete);
            };
            if component_of(id) != Some(c) || m.scc_index < 1 || m.scc_index > c.scc_length {
                return Err(StoreError::Incomplete);
            }
            let minimal = matches!(object, TypeObject::Minimal(_));
            if minimal != (c.kind == EquivalenceKind::Minimal) {
                return Err(StoreError::KindMismatch);
            }
            let slot = &mut by_index[m.scc_index as usize - 1];
            if slot.replace(object).is_some() {
                return Err(StoreError::Incomplete);
            }
        }
        if self.contains(&member_id(c, 0)) {
            return Ok(false);
        }
        let objects: Vec<&TypeObject> = by_index.iter().flatten().copied().collect();
        let sizes = verify_component(c, &objects)?;
        let total: usize = sizes.iter().sum();
        if self.learnt + pairs.len() > self.limits.max_learnt
            || self.learnt_bytes + total > self.limits.max_learnt_bytes
        {
            return Err(StoreError::Full);
        }
        for (i, (o, size)) in by_index.into_iter().flatten().zip(sizes).enumerate() {
            self.learnt += 1;
            self.learnt_bytes += size;
            self.objects.insert(
                member_id(c, i as i32 + 1),
                Entry {
                    object: Arc::new(o.clone()),
                    size,
                    owned: false,
                },
            );
        }
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

/// Checks that the objects of the types of component `c`, by index, hash to its hash (serialized with the
/// hash zeroed where they name each other, in a sequence: how `TypeSupport` builds them). Their serialized
/// sizes.
pub(crate) fn verify_component(
    c: StronglyConnectedComponentId,
    objects: &[&TypeObject],
) -> Result<Vec<usize>, StoreError> {
    let ek = match c.kind {
        EquivalenceKind::Minimal => kind::EK_MINIMAL,
        _ => kind::EK_COMPLETE,
    };
    let mut sizes = Vec::with_capacity(objects.len());
    let mut zeroed = Vec::with_capacity(objects.len());
    for o in objects {
        let bytes = to_bytes(*o).map_err(|_| StoreError::Unencodable)?;
        sizes.push(bytes.len());
        zeroed.push(zero_hash(bytes, ek, &c.hash));
    }
    let whole = super::build::component_sequence(&zeroed);
    if super::typeobject::equivalence_hash(&whole) != c.hash {
        return Err(StoreError::HashMismatch);
    }
    Ok(sizes)
}

/// `bytes` with each `ek` octet followed by `hash` (a component identifier naming its own component) turned
/// into `ek` and a zero hash: the objects as they were when the component's hash was computed.
fn zero_hash(mut bytes: Vec<u8>, ek: u8, hash: &[u8; 14]) -> Vec<u8> {
    let mut i = 0;
    while i + 15 <= bytes.len() {
        if bytes[i] == ek && bytes[i + 1..i + 15] == hash[..] {
            bytes[i + 1..i + 15].fill(0);
            i += 15;
        } else {
            i += 1;
        }
    }
    bytes
}
