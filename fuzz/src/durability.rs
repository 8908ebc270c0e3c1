//! The durability service's key hash of a peer's change (`dds_runtime::dcps::durability::peer_key_hash`): a
//! change of a keyed writer that sent no key hash (Cyclone sends none) is decoded with the writer's type,
//! resolved from type objects the peer sent through TypeLookup, and its key hashed. Hostile type objects and
//! payloads must give `None` or a hash: never a panic, a hang or an allocation beyond the input's size.
//!
//! Input: byte 0 (bit 0: a sample, else a serialized key), the type objects' length (u32 little-endian), the
//! type objects (a `TypeMapping`, XCDR2, as a TypeLookup reply carries them), then the payload.

use std::collections::HashMap;
use std::sync::Arc;

use dds_runtime::dcps::durability::peer_key_hash;
use dds_runtime::xtypes::typeobject::{from_bytes, TypeIdentifier, TypeMapping, TypeObject};

/// One input (format above).
pub fn durability_key_one(data: &[u8]) {
    durability_key_hashes(data);
}

/// [`durability_key_one`], returning how many roots (complete, minimal) gave a key hash.
pub fn durability_key_hashes(data: &[u8]) -> usize {
    let Some((&sel, rest)) = data.split_first() else {
        return 0;
    };
    let Some((len, rest)) = rest.split_first_chunk::<4>() else {
        return 0;
    };
    let len = u32::from_le_bytes(*len) as usize;
    if len > rest.len() {
        return 0;
    }
    let (objects, payload) = rest.split_at(len);
    let Ok(mapping) = from_bytes::<TypeMapping>(objects) else {
        return 0;
    };
    let pairs = || {
        mapping
            .identifier_object_pair_complete
            .iter()
            .chain(&mapping.identifier_object_pair_minimal)
    };
    let objects: HashMap<TypeIdentifier, Arc<TypeObject>> = pairs()
        .map(|p| (p.type_identifier.clone(), Arc::new(p.type_object.clone())))
        .collect();
    // The topic type comes first in each list; try the complete and the minimal one.
    let roots = [
        mapping.identifier_object_pair_complete.first(),
        mapping.identifier_object_pair_minimal.first(),
    ];
    let lookup = |id: &TypeIdentifier| objects.get(id).cloned();
    roots
        .into_iter()
        .flatten()
        .filter_map(|root| peer_key_hash(&root.type_identifier, &lookup, sel & 1 == 1, payload))
        .count()
}

/// An input of the format above (for the seed generator).
pub fn durability_key_input(mapping: &[u8], alive: bool, payload: &[u8]) -> Vec<u8> {
    let mut out = vec![u8::from(alive)];
    out.extend_from_slice(&(mapping.len() as u32).to_le_bytes());
    out.extend_from_slice(mapping);
    out.extend_from_slice(payload);
    out
}
