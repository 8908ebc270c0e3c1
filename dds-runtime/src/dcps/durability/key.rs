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
use crate::xtypes::dynamic::{DynamicData, DynamicType, TypeObjectLookup};
use crate::xtypes::typeobject::TypeIdentifier;
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
        key_hash_of(&ty, kind == ChangeKind::Alive, payload)
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

/// The key hash of a change whose payload (a sample when `alive`, else a serialized key: dispose,
/// unregistration) is of type `ty`, as its writer computes it (XCDR version of the payload's encapsulation).
/// `None` when the payload does not decode as `ty`. Bounded: a hostile payload is an error.
pub(crate) fn key_hash_of(ty: &DynamicType, alive: bool, payload: &[u8]) -> Option<[u8; 16]> {
    let version = EncapsulationHeader::parse(payload).ok()?.version().ok()?;
    let data = if alive {
        DynamicData::deserialize(ty, payload)
    } else {
        DynamicData::deserialize_key(ty, payload)
    };
    data.ok()?.key_hash(version).ok()
}

/// The key hash the durability service gives a keyed change that arrived without one (Cyclone DDS sends
/// none): `payload` (a sample when `alive`, else a serialized key) decoded as the type `root` names, its parts
/// resolved through `lookup` (type objects a peer sent through TypeLookup), and its key hashed as the writer
/// would have. `None` when the type does not resolve or the payload does not decode: hostile type objects and
/// payloads are errors, never panics. Public for the fuzz target (`fuzz/`, `durability_key`).
pub fn peer_key_hash(
    root: &TypeIdentifier,
    lookup: &TypeObjectLookup<'_>,
    alive: bool,
    payload: &[u8],
) -> Option<[u8; 16]> {
    let ty = DynamicType::from_type_identifier(root, lookup).ok()?;
    key_hash_of(&ty, alive, payload)
}

/// Hostile peers: truncated and garbage payloads, type objects that are missing, cyclic or describe
/// enormous collections of nothing. Each is an error (`None`), never a panic, a hang or an allocation beyond
/// the payload's size.
#[cfg(test)]
mod tests {
    use std::collections::HashMap;
    use std::sync::Arc;
    use std::time::{Duration, Instant};

    use super::*;
    use crate::cdr::{ByteOrder, XcdrVersion};
    use crate::xtypes::typeobject::{TypeBody, TypeObject};
    use crate::xtypes::XTypesType;
    use crate::DdsType;

    #[derive(DdsType, Debug, Clone, PartialEq, Default)]
    #[dds(final, name = "Leaf")]
    struct Leaf {
        v: u8,
    }

    #[derive(DdsType, Debug, Clone, PartialEq, Default)]
    #[dds(appendable, name = "KeyedShape")]
    struct KeyedShape {
        #[dds(key)]
        color: String,
        x: i32,
        #[dds(key)]
        id: u32,
        leaves: Vec<Leaf>,
    }

    type Objects = HashMap<TypeIdentifier, Arc<TypeObject>>;

    /// The topic type's complete identifier and its objects, as TypeLookup would store them.
    fn objects() -> (TypeIdentifier, Objects) {
        let s = KeyedShape::type_support().expect("describable");
        let objects = s
            .mapping
            .identifier_object_pair_complete
            .iter()
            .map(|p| (p.type_identifier.clone(), Arc::new(p.type_object.clone())))
            .collect();
        (
            s.information.complete.typeid_with_size.type_id.clone(),
            objects,
        )
    }

    fn sample() -> KeyedShape {
        KeyedShape {
            color: "BLUE".into(),
            x: 7,
            id: 42,
            leaves: vec![Leaf { v: 1 }, Leaf { v: 2 }],
        }
    }

    fn payload(version: XcdrVersion, key_only: bool) -> Vec<u8> {
        let mut out = Vec::new();
        let order = ByteOrder::LittleEndian;
        if key_only {
            crate::cdr::serialize_key(&sample(), version, order, &mut out).unwrap();
        } else {
            crate::cdr::serialize(&sample(), version, order, &mut out).unwrap();
        }
        out
    }

    fn hash(root: &TypeIdentifier, objects: &Objects, alive: bool, p: &[u8]) -> Option<[u8; 16]> {
        peer_key_hash(root, &|id| objects.get(id).cloned(), alive, p)
    }

    /// The members of the struct object `id` names.
    fn members_of<'a>(
        objects: &'a mut Objects,
        id: &TypeIdentifier,
    ) -> &'a mut Vec<crate::xtypes::typeobject::StructMember> {
        let obj = Arc::make_mut(objects.get_mut(id).expect("object"));
        let TypeObject::Complete(c) = obj else {
            panic!("complete object expected")
        };
        let TypeBody::Struct { members, .. } = &mut c.0 else {
            panic!("struct expected")
        };
        members
    }

    #[test]
    fn the_key_hash_is_the_writers() {
        let (root, objects) = objects();
        for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
            let want = crate::cdr::key_hash(&sample(), version).unwrap();
            assert_eq!(
                hash(&root, &objects, true, &payload(version, false)),
                Some(want)
            );
            assert_eq!(
                hash(&root, &objects, false, &payload(version, true)),
                Some(want)
            );
        }
    }

    #[test]
    fn truncated_and_garbage_payloads_are_errors() {
        let (root, objects) = objects();
        for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
            for key_only in [false, true] {
                let p = payload(version, key_only);
                for n in 0..p.len() {
                    // The key members come first: a payload cut after them may still hash; never differently.
                    let got = hash(&root, &objects, !key_only, &p[..n]);
                    let want = crate::cdr::key_hash(&sample(), version).unwrap();
                    assert!(got.is_none() || got == Some(want), "cut at {n}");
                }
            }
        }
        // Garbage after a valid header (xorshift, deterministic), and lengths far beyond the payload.
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for i in 0..2000 {
            let mut p = vec![0x00, [0x01, 0x07, 0x09][i % 3], 0, 0];
            for _ in 0..(i % 64) {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                p.push(x as u8);
            }
            let _ = hash(&root, &objects, i % 2 == 0, &p);
        }
        let mut huge = payload(XcdrVersion::Xcdr2, false);
        huge[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        assert_eq!(
            hash(&root, &objects, true, &huge),
            None,
            "string length beyond the payload"
        );
    }

    #[test]
    fn missing_and_cyclic_type_objects_are_errors() {
        let (root, objects) = objects();
        let p = payload(XcdrVersion::Xcdr2, false);
        assert_eq!(hash(&root, &HashMap::new(), true, &p), None, "no objects");
        assert_eq!(
            hash(&TypeIdentifier::None, &objects, true, &p),
            None,
            "no type"
        );
        // The leaf's member refers back to the topic type: a cycle of hashes.
        let mut cyclic = objects.clone();
        let leaf = match &members_of(&mut cyclic, &root)[3].type_id {
            TypeIdentifier::PlainSequence { element, .. } => (**element).clone(),
            other => panic!("sequence expected, got {other:?}"),
        };
        members_of(&mut cyclic, &leaf)[0].type_id = root.clone();
        let _ = hash(&root, &cyclic, true, &p);
        // A member whose type is the struct itself, directly.
        let mut own = objects;
        members_of(&mut own, &root)[1].type_id = root.clone();
        let _ = hash(&root, &own, true, &p);
    }

    /// An array of 2^64 elements of an empty struct: each element takes no byte of the payload, so only a
    /// bound on the elements (not on the bytes) keeps the decoder from trying to build them all.
    #[test]
    fn huge_collections_of_nothing_are_errors() {
        let (root, mut objects) = objects();
        let leaf = match &members_of(&mut objects, &root)[3].type_id {
            TypeIdentifier::PlainSequence { element, .. } => (**element).clone(),
            other => panic!("sequence expected, got {other:?}"),
        };
        members_of(&mut objects, &leaf).clear();
        let header = match &members_of(&mut objects, &root)[3].type_id {
            TypeIdentifier::PlainSequence { header, .. } => *header,
            _ => unreachable!(),
        };
        members_of(&mut objects, &root)[3].type_id = TypeIdentifier::PlainArray {
            header,
            bounds: vec![u32::MAX, u32::MAX],
            element: Box::new(leaf),
        };
        let started = Instant::now();
        for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
            let got = hash(&root, &objects, true, &payload(version, false));
            let want = crate::cdr::key_hash(&sample(), version).unwrap();
            assert!(got.is_none() || got == Some(want));
        }
        assert!(
            started.elapsed() < Duration::from_secs(5),
            "{:?}",
            started.elapsed()
        );
    }
}
