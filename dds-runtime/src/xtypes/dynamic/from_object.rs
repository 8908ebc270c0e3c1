//! [`DynamicType`] from XTypes type objects: a discovered type (TypeInformation + the objects of a TypeMapping,
//! a TypeLookup reply or a local store).

use std::collections::{HashMap, HashSet};
use std::sync::{Arc, Mutex, OnceLock};

use crate::cdr::Extensibility;
use crate::xtypes::store::{verify_component, MAX_COMPONENT};
use crate::xtypes::typeobject::{
    kind, Bitfield, Bitflag, EnumeratedLiteral, MemberFlag, MemberName,
    StronglyConnectedComponentId, StructMember, TypeBody, TypeFlag, TypeIdentifier,
    TypeInformation, TypeMapping, TypeObject,
};

use super::error::DynamicError;
use super::types::{
    close_forward, BitFlag, BitmaskType, DynamicType, EnumType, Enumerator, Member, Primitive,
    StructType, TypeKind, UnionCase, UnionType,
};

/// Deepest chain of type references followed (a hostile cycle of hashes ends here).
const MAX_TYPE_DEPTH: u32 = 64;

/// Where type objects come from: a type's identifier to its object (complete or minimal).
pub type TypeObjectLookup<'a> = dyn Fn(&TypeIdentifier) -> Option<Arc<TypeObject>> + 'a;

struct Resolver<'a> {
    lookup: &'a TypeObjectLookup<'a>,
    done: HashMap<TypeIdentifier, DynamicType>,
    /// The components whose objects were checked against their hash.
    verified: HashSet<StronglyConnectedComponentId>,
}

/// Recursive types imported so far, by the identifier of each type of their component: a component's objects
/// are checked against its hash before it is imported, so an identifier names one type, and importing it again
/// (a durability service resolving each writer's type, `dds subscribe` run in a loop) reuses the type instead
/// of making another cycle that would live as long as the process.
fn imported() -> &'static Mutex<HashMap<TypeIdentifier, DynamicType>> {
    static IMPORTED: OnceLock<Mutex<HashMap<TypeIdentifier, DynamicType>>> = OnceLock::new();
    IMPORTED.get_or_init(|| Mutex::new(HashMap::new()))
}

/// Most entries of [`imported`] (beyond, types are still imported, each once per resolution).
const MAX_IMPORTED: usize = 4096;

impl DynamicType {
    /// The type `id` names, its hashed parts found through `lookup`. Complete type objects give names;
    /// minimal ones give members named after their name hash (`_1a2b3c4d`) and types named `?`.
    pub fn from_type_identifier(
        id: &TypeIdentifier,
        lookup: &TypeObjectLookup<'_>,
    ) -> Result<Self, DynamicError> {
        let mut r = Resolver {
            lookup,
            done: HashMap::new(),
            verified: HashSet::new(),
        };
        let t = r.resolve(id, 0)?;
        // Only now are the forward references of every component met defined.
        let mut cache = imported().lock().unwrap_or_else(|e| e.into_inner());
        for (id, t) in r.done {
            if matches!(id, TypeIdentifier::StronglyConnected(_)) && cache.len() < MAX_IMPORTED {
                cache.entry(id).or_insert(t);
            }
        }
        Ok(t)
    }

    /// The topic type a `TypeInformation` describes, from the objects of a `TypeMapping` (complete
    /// preferred).
    pub fn from_type_mapping(
        info: &TypeInformation,
        mapping: &TypeMapping,
    ) -> Result<Self, DynamicError> {
        let mut objects: HashMap<TypeIdentifier, Arc<TypeObject>> = HashMap::new();
        for p in mapping
            .identifier_object_pair_complete
            .iter()
            .chain(&mapping.identifier_object_pair_minimal)
        {
            objects.insert(p.type_identifier.clone(), Arc::new(p.type_object.clone()));
        }
        let root = if objects.contains_key(&info.complete.typeid_with_size.type_id) {
            &info.complete.typeid_with_size.type_id
        } else {
            &info.minimal.typeid_with_size.type_id
        };
        DynamicType::from_type_identifier(root, &|id| objects.get(id).cloned())
    }
}

/// An identifier for messages: its hash (and component index).
fn describe(id: &TypeIdentifier) -> String {
    match id {
        TypeIdentifier::StronglyConnected(c) => {
            format!("component {:02x?} #{}", c.hash, c.scc_index)
        }
        _ => format!("{:02x?}", id.hash().unwrap_or(&[0; 14])),
    }
}

fn primitive(k: u8) -> Option<Primitive> {
    Some(match k {
        kind::TK_BOOLEAN => Primitive::Bool,
        kind::TK_BYTE => Primitive::Byte,
        kind::TK_INT8 => Primitive::Int8,
        kind::TK_UINT8 => Primitive::UInt8,
        kind::TK_INT16 => Primitive::Int16,
        kind::TK_UINT16 => Primitive::UInt16,
        kind::TK_INT32 => Primitive::Int32,
        kind::TK_UINT32 => Primitive::UInt32,
        kind::TK_INT64 => Primitive::Int64,
        kind::TK_UINT64 => Primitive::UInt64,
        kind::TK_FLOAT32 => Primitive::Float32,
        kind::TK_FLOAT64 => Primitive::Float64,
        kind::TK_FLOAT128 => Primitive::Float128,
        kind::TK_CHAR8 => Primitive::Char8,
        kind::TK_CHAR16 => Primitive::Char16,
        _ => return None,
    })
}

fn bound(b: u32) -> Option<u32> {
    (b != 0).then_some(b)
}

fn extensibility(f: TypeFlag) -> Extensibility {
    if f.contains(TypeFlag::IS_MUTABLE) {
        Extensibility::Mutable
    } else if f.contains(TypeFlag::IS_APPENDABLE) {
        Extensibility::Appendable
    } else {
        Extensibility::Final
    }
}

fn member_name(n: &MemberName) -> String {
    match n {
        MemberName::Name(s) => s.clone(),
        MemberName::Hash(h) => format!("_{:02x}{:02x}{:02x}{:02x}", h[0], h[1], h[2], h[3]),
    }
}

fn enum_type(
    name: String,
    flags: TypeFlag,
    bit_bound: u16,
    literals: &[EnumeratedLiteral],
) -> DynamicType {
    DynamicType::new(TypeKind::Enum(EnumType {
        name,
        extensibility: extensibility(flags),
        bit_bound,
        default: literals
            .iter()
            .position(|l| l.flags.contains(MemberFlag::IS_DEFAULT))
            .unwrap_or(0),
        literals: literals
            .iter()
            .map(|l| Enumerator {
                name: member_name(&l.detail.name),
                value: l.value,
            })
            .collect(),
    }))
}

/// A bitset is the unsigned integer that holds its bits, as the derive and `types_from_idl` make it.
fn bitset_type(fields: &[Bitfield]) -> DynamicType {
    let bits = fields
        .iter()
        .map(|f| u32::from(f.position) + u32::from(f.bitcount))
        .max()
        .unwrap_or(0);
    DynamicType::primitive(match bits {
        0..=8 => Primitive::UInt8,
        9..=16 => Primitive::UInt16,
        17..=32 => Primitive::UInt32,
        _ => Primitive::UInt64,
    })
}

fn bitmask_type(
    name: String,
    flags: TypeFlag,
    bit_bound: u16,
    bitflags: &[Bitflag],
) -> DynamicType {
    DynamicType::new(TypeKind::Bitmask(BitmaskType {
        name,
        extensibility: extensibility(flags),
        bit_bound,
        flags: bitflags
            .iter()
            .map(|f| BitFlag {
                name: member_name(&f.detail.name),
                position: f.position,
            })
            .collect(),
    }))
}

fn type_name(body: &TypeBody) -> String {
    match body.type_name() {
        "" => "?".to_string(),
        n => n.to_string(),
    }
}

impl Resolver<'_> {
    fn resolve(&mut self, id: &TypeIdentifier, depth: u32) -> Result<DynamicType, DynamicError> {
        if depth > MAX_TYPE_DEPTH {
            return Err(DynamicError::Unresolved(
                "type references nested too deeply".into(),
            ));
        }
        let d = depth + 1;
        Ok(match id {
            TypeIdentifier::None => return Err(DynamicError::Unresolved("TK_NONE".into())),
            TypeIdentifier::Primitive(k) => DynamicType::primitive(
                primitive(*k)
                    .ok_or_else(|| DynamicError::Unresolved(format!("type kind {k:#x}")))?,
            ),
            TypeIdentifier::String8 { bound: b } => DynamicType::string(bound(*b)),
            TypeIdentifier::String16 { bound: b } => DynamicType::wstring(bound(*b)),
            TypeIdentifier::PlainSequence {
                bound: b, element, ..
            } => DynamicType::sequence(self.resolve(element, d)?, bound(*b)),
            TypeIdentifier::PlainArray {
                bounds, element, ..
            } => DynamicType::array(self.resolve(element, d)?, bounds.clone())?,
            TypeIdentifier::PlainMap {
                bound: b,
                element,
                key,
                ..
            } => DynamicType::map(self.resolve(key, d)?, self.resolve(element, d)?, bound(*b)),
            TypeIdentifier::StronglyConnected(_)
            | TypeIdentifier::Minimal(_)
            | TypeIdentifier::Complete(_) => self.named(id, d)?,
        })
    }

    /// A hashed type, or one type of a strongly connected component (a recursive type): while its object is
    /// turned into a type, a reference back to it (a cycle of the component) gets a forward reference, which
    /// the type then defines.
    fn named(&mut self, id: &TypeIdentifier, d: u32) -> Result<DynamicType, DynamicError> {
        if let Some(t) = self.done.get(id) {
            return Ok(t.clone());
        }
        if let TypeIdentifier::StronglyConnected(c) = id {
            let known = imported()
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .get(id)
                .cloned();
            if let Some(t) = known {
                return Ok(t);
            }
            self.verify(*c)?;
        }
        let obj = (self.lookup)(id).ok_or_else(|| {
            DynamicError::Unresolved(format!("no type object for {}", describe(id)))
        })?;
        let body = match &*obj {
            TypeObject::Minimal(m) => &m.0,
            TypeObject::Complete(c) => &c.0,
        };
        let forward = matches!(id, TypeIdentifier::StronglyConnected(_)).then(|| {
            let f = DynamicType::forward(type_name(body));
            self.done.insert(id.clone(), f.clone());
            f
        });
        let t = self.body(body, d);
        match (&t, forward) {
            (Ok(t), Some(f)) => {
                self.done.insert(id.clone(), t.clone());
                close_forward(f, t)?;
            }
            (Ok(t), None) => {
                self.done.insert(id.clone(), t.clone());
            }
            (Err(_), _) => {
                self.done.remove(id);
            }
        }
        t
    }

    /// Checks the objects of component `c` against its hash (once per component).
    fn verify(&mut self, c: StronglyConnectedComponentId) -> Result<(), DynamicError> {
        let whole = StronglyConnectedComponentId { scc_index: 0, ..c };
        if self.verified.contains(&whole) {
            return Ok(());
        }
        if !(1..=MAX_COMPONENT).contains(&c.scc_length) {
            return Err(DynamicError::Unresolved(format!(
                "a component of {} types",
                c.scc_length
            )));
        }
        let objects = (1..=c.scc_length)
            .map(|i| {
                let id = TypeIdentifier::StronglyConnected(StronglyConnectedComponentId {
                    scc_index: i,
                    ..c
                });
                (self.lookup)(&id).ok_or_else(|| {
                    DynamicError::Unresolved(format!("no type object for {}", describe(&id)))
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let refs: Vec<&TypeObject> = objects.iter().map(|o| &**o).collect();
        verify_component(c, &refs)
            .map_err(|e| DynamicError::Unresolved(format!("component {:02x?}: {e}", c.hash)))?;
        self.verified.insert(whole);
        Ok(())
    }

    fn body(&mut self, body: &TypeBody, d: u32) -> Result<DynamicType, DynamicError> {
        Ok(match body {
            TypeBody::Alias { related_type, .. } => {
                DynamicType::alias(type_name(body), self.resolve(related_type, d)?)
            }
            TypeBody::Struct {
                flags,
                base,
                members,
                ..
            } => self.struct_body(type_name(body), *flags, base, members, d)?,
            TypeBody::Union {
                flags,
                disc_flags,
                disc_type,
                members,
                ..
            } => {
                let mut cases = Vec::with_capacity(members.len());
                for m in members {
                    cases.push(UnionCase {
                        name: member_name(&m.detail.name),
                        id: m.id,
                        ty: self.resolve(&m.type_id, d)?,
                        labels: m.labels.iter().map(|l| i64::from(*l)).collect(),
                        is_default: m.flags.contains(MemberFlag::IS_DEFAULT),
                        external: m.flags.contains(MemberFlag::IS_EXTERNAL),
                    });
                }
                DynamicType::new(TypeKind::Union(UnionType {
                    name: type_name(body),
                    extensibility: extensibility(*flags),
                    discriminator: self.resolve(disc_type, d)?,
                    disc_key: disc_flags.contains(MemberFlag::IS_KEY),
                    cases,
                    nested: flags.contains(TypeFlag::IS_NESTED),
                }))
            }
            TypeBody::Sequence {
                bound: b, element, ..
            } => DynamicType::sequence(self.resolve(&element.type_id, d)?, bound(*b)),
            TypeBody::Array {
                bounds, element, ..
            } => DynamicType::array(self.resolve(&element.type_id, d)?, bounds.clone())?,
            TypeBody::Map {
                bound: b,
                key,
                element,
                ..
            } => DynamicType::map(
                self.resolve(&key.type_id, d)?,
                self.resolve(&element.type_id, d)?,
                bound(*b),
            ),
            TypeBody::Enum {
                flags,
                bit_bound,
                literals,
                ..
            } => enum_type(type_name(body), *flags, *bit_bound, literals),
            TypeBody::Bitset { fields, .. } => bitset_type(fields),
            TypeBody::Bitmask {
                flags,
                bit_bound,
                bitflags,
                ..
            } => bitmask_type(type_name(body), *flags, *bit_bound, bitflags),
        })
    }

    /// A struct: its base's members (and inheritance levels) first, then its own.
    fn struct_body(
        &mut self,
        name: String,
        flags: TypeFlag,
        base: &TypeIdentifier,
        members: &[StructMember],
        d: u32,
    ) -> Result<DynamicType, DynamicError> {
        let base = match base {
            TypeIdentifier::None => None,
            b => Some(self.resolve(b, d)?),
        };
        let (mut all, mut levels) = match base.as_ref().map(|b| b.resolved().kind()) {
            None => (Vec::new(), Vec::new()),
            Some(TypeKind::Struct(s)) => (s.members.clone(), s.levels.clone()),
            Some(_) => {
                return Err(DynamicError::Invalid(
                    "a struct's base is not a struct".into(),
                ))
            }
        };
        for m in members {
            all.push(Member {
                name: member_name(&m.detail.name),
                id: m.id,
                ty: self.resolve(&m.type_id, d)?,
                key: m.flags.contains(MemberFlag::IS_KEY),
                optional: m.flags.contains(MemberFlag::IS_OPTIONAL),
                external: m.flags.contains(MemberFlag::IS_EXTERNAL),
                must_understand: m.flags.contains(MemberFlag::IS_MUST_UNDERSTAND),
                hash_id: m
                    .detail
                    .ann_builtin
                    .as_ref()
                    .and_then(|a| a.hash_id.clone()),
                use_default: m.flags.contains(MemberFlag::TRY_CONSTRUCT2),
            });
        }
        levels.push(all.len());
        Ok(DynamicType::new(TypeKind::Struct(StructType {
            name,
            extensibility: extensibility(flags),
            base,
            members: all,
            autoid_hash: flags.contains(TypeFlag::IS_AUTOID_HASH),
            nested: flags.contains(TypeFlag::IS_NESTED),
            levels,
        })))
    }
}
