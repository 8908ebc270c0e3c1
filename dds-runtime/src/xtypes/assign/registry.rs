//! The types this process built type support for: always resolvable, so matching two local endpoints (or a
//! remote endpoint whose type this process also has) never waits for the TypeLookup service.

use std::collections::HashMap;
use std::sync::{Arc, OnceLock, RwLock};

use super::TypeResolver;
use crate::xtypes::typeobject::{TypeIdentifier, TypeMapping, TypeObject};

/// A process-wide map from type identifiers (minimal and complete hashes) to type objects, filled by
/// [`TypeSupport::build`](crate::xtypes::TypeSupport::build) for every type the process compiled in.
#[derive(Debug, Default)]
pub struct LocalTypes {
    map: RwLock<HashMap<TypeIdentifier, Arc<TypeObject>>>,
}

impl LocalTypes {
    /// Adds the objects of a type and its dependencies.
    pub fn register(&self, mapping: &TypeMapping) {
        let pairs = mapping
            .identifier_object_pair_minimal
            .iter()
            .chain(&mapping.identifier_object_pair_complete);
        let mut map = self.map.write().unwrap_or_else(|e| e.into_inner());
        for p in pairs {
            map.entry(p.type_identifier.clone())
                .or_insert_with(|| Arc::new(p.type_object.clone()));
        }
    }

    /// The object of `id`, if this process knows it.
    pub fn get(&self, id: &TypeIdentifier) -> Option<Arc<TypeObject>> {
        self.map
            .read()
            .unwrap_or_else(|e| e.into_inner())
            .get(id)
            .cloned()
    }
}

impl TypeResolver for LocalTypes {
    fn resolve(&self, id: &TypeIdentifier) -> Option<Arc<TypeObject>> {
        self.get(id)
    }
}

/// The process-wide registry of local types.
pub fn local_types() -> &'static LocalTypes {
    static TYPES: OnceLock<LocalTypes> = OnceLock::new();
    TYPES.get_or_init(LocalTypes::default)
}
