//! What older peers cannot read. Cyclone DDS 0.10 (Debian's `ddsperf` 0.10.2) implements the XTypes 1.2-era
//! type system: its `ddsi_xt_typeinfo.idl` has no `TK_INT8`/`TK_UINT8` (XTypes 1.3), so a type identifier of
//! either kind is "invalid" to it, it never resolves such a type, and its endpoints never match ours. Types
//! that use them announce no type information (they match such peers by name, as before).

use super::typeobject::kind::{TK_INT8, TK_UINT8};
use super::typeobject::{from_bytes, TypeBody, TypeIdentifier, TypeMapping, TypeObject};

/// Whether `id` is, or contains, `int8` or `uint8`.
fn has_int8(id: &TypeIdentifier) -> bool {
    match id {
        TypeIdentifier::Primitive(k) => *k == TK_INT8 || *k == TK_UINT8,
        TypeIdentifier::PlainSequence { element, .. }
        | TypeIdentifier::PlainArray { element, .. } => has_int8(element),
        TypeIdentifier::PlainMap { element, key, .. } => has_int8(element) || has_int8(key),
        _ => false,
    }
}

/// Whether a type object refers to `int8` or `uint8` directly (hashed member types have objects of their own).
fn object_has_int8(o: &TypeObject) -> bool {
    let body = match o {
        TypeObject::Minimal(m) => &m.0,
        TypeObject::Complete(c) => &c.0,
    };
    match body {
        TypeBody::Struct { members, .. } => members.iter().any(|m| has_int8(&m.type_id)),
        TypeBody::Union {
            disc_type, members, ..
        } => has_int8(disc_type) || members.iter().any(|m| has_int8(&m.type_id)),
        TypeBody::Alias { related_type, .. } => has_int8(related_type),
        TypeBody::Sequence { element, .. } | TypeBody::Array { element, .. } => {
            has_int8(&element.type_id)
        }
        TypeBody::Map { element, key, .. } => has_int8(&element.type_id) || has_int8(&key.type_id),
        _ => false,
    }
}

/// Whether the serialized `TypeMapping` of a type uses `int8` or `uint8` anywhere (an undecodable mapping
/// counts as yes: nothing is announced for it).
pub(super) fn uses_int8(mapping: &[u8]) -> bool {
    let Ok(m) = from_bytes::<TypeMapping>(mapping) else {
        return true;
    };
    m.identifier_object_pair_minimal
        .iter()
        .any(|p| object_has_int8(&p.type_object))
}
