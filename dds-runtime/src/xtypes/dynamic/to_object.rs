//! XTypes type objects of a [`DynamicType`]: the type is lowered to the description the derive's types lower
//! to, and [`TypeSupport`] builds its objects, identifiers, `TypeInformation` and `TypeMapping` with the same
//! code (so the same rules: Cyclone DDS 11's). Typedefs keep their alias objects.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use crate::xtypes::describe::with_try_construct;
use crate::xtypes::shape::{Case, Def, Described, Member, Shape};
use crate::xtypes::typeobject::{kind, MemberFlag};
use crate::xtypes::{BuildError, TypeSupport};

use super::types::{DynamicType, Primitive, TypeKind};

impl DynamicType {
    /// The type objects, identifiers, `TypeInformation` and `TypeMapping` of this topic type (a struct or a
    /// union, possibly behind typedefs), built as for a derived type; every named type it reaches is also
    /// registered for local assignability checks. Two different named types with the same name are an error
    /// ([`BuildError::Conflict`]); recursive types get strongly connected component identifiers, as derived
    /// ones do.
    pub fn type_support(&self) -> Result<TypeSupport, BuildError> {
        let root = self.resolved();
        if !matches!(root.kind(), TypeKind::Struct(_) | TypeKind::Union(_)) {
            return Err(BuildError::NotNamed);
        }
        let mut l = Lowering::default();
        let Shape::Named(name) = l.shape(root)? else {
            return Err(BuildError::NotNamed);
        };
        TypeSupport::from_described(&Described {
            root: name,
            defs: l.defs,
        })
    }
}

/// The `TK_*` of a primitive.
fn type_kind(p: Primitive) -> u8 {
    match p {
        Primitive::Bool => kind::TK_BOOLEAN,
        Primitive::Byte => kind::TK_BYTE,
        Primitive::Int8 => kind::TK_INT8,
        Primitive::UInt8 => kind::TK_UINT8,
        Primitive::Int16 => kind::TK_INT16,
        Primitive::UInt16 => kind::TK_UINT16,
        Primitive::Int32 => kind::TK_INT32,
        Primitive::UInt32 => kind::TK_UINT32,
        Primitive::Int64 => kind::TK_INT64,
        Primitive::UInt64 => kind::TK_UINT64,
        Primitive::Float32 => kind::TK_FLOAT32,
        Primitive::Float64 => kind::TK_FLOAT64,
        Primitive::Float128 => kind::TK_FLOAT128,
        Primitive::Char8 => kind::TK_CHAR8,
        Primitive::Char16 => kind::TK_CHAR16,
    }
}

#[derive(Default)]
struct Lowering {
    defs: HashMap<String, Def>,
    /// The named types lowered already (by address): each distinct one is lowered once, so the work is
    /// linear in the type's size even when a type is reached many times.
    seen: HashSet<usize>,
}

impl Lowering {
    fn shape(&mut self, t: &DynamicType) -> Result<Shape, BuildError> {
        let bound = |b: &Option<u32>| b.unwrap_or(0);
        Ok(match t.kind() {
            TypeKind::Primitive(p) => Shape::Primitive(type_kind(*p)),
            TypeKind::String { wide, bound: b } => Shape::String {
                wide: *wide,
                bound: bound(b),
            },
            TypeKind::Sequence { element, bound: b } => Shape::Sequence {
                bound: bound(b),
                element: Box::new(self.shape(element)?),
            },
            TypeKind::Array { element, dims } => Shape::Array {
                bounds: dims.clone(),
                element: Box::new(self.shape(element)?),
            },
            TypeKind::Map {
                key,
                value,
                bound: b,
            } => Shape::Map {
                bound: bound(b),
                key: Box::new(self.shape(key)?),
                value: Box::new(self.shape(value)?),
            },
            TypeKind::Forward(r) => match r.target() {
                Some(t) => self.shape(t)?,
                None => return Err(BuildError::Unsupported("an undefined forward reference")),
            },
            TypeKind::Alias { .. }
            | TypeKind::Enum(_)
            | TypeKind::Bitmask(_)
            | TypeKind::Struct(_)
            | TypeKind::Union(_) => self.named(t)?,
        })
    }

    fn named(&mut self, t: &DynamicType) -> Result<Shape, BuildError> {
        let name = t.name();
        if !self.seen.insert(Arc::as_ptr(&t.0) as usize) {
            return Ok(Shape::Named(name));
        }
        // Another value of a name already lowered must define the same type (compared lowered: its
        // named parts by name, so the comparison is linear too).
        let def = self.def(t)?;
        match self.defs.get(&name) {
            Some(d) if *d == def => {}
            Some(_) => return Err(BuildError::Conflict(name)),
            None => {
                self.defs.insert(name.clone(), def);
            }
        }
        Ok(Shape::Named(name))
    }

    fn def(&mut self, t: &DynamicType) -> Result<Def, BuildError> {
        Ok(match t.kind() {
            TypeKind::Alias { target, .. } => Def::Alias(self.shape(target)?),
            TypeKind::Struct(s) => Def::Struct {
                extensibility: s.extensibility,
                autoid_hash: s.autoid_hash,
                nested: s.nested,
                base: s.base.as_ref().map(|b| self.shape(b)).transpose()?,
                members: s
                    .own_members()
                    .iter()
                    .map(|m| self.member(m))
                    .collect::<Result<_, _>>()?,
            },
            TypeKind::Union(u) => Def::Union {
                extensibility: u.extensibility,
                nested: u.nested,
                discriminator: self.shape(&u.discriminator)?,
                discriminator_key: u.disc_key,
                cases: u
                    .cases
                    .iter()
                    .map(|c| {
                        Ok(Case {
                            name: c.name.clone(),
                            id: c.id,
                            // Type objects hold 32-bit labels.
                            labels: c.labels.iter().map(|l| *l as i32).collect(),
                            is_default: c.is_default,
                            external: c.external,
                            ty: self.shape(&c.ty)?,
                        })
                    })
                    .collect::<Result<_, BuildError>>()?,
            },
            TypeKind::Enum(e) => Def::Enum {
                extensibility: e.extensibility,
                bit_bound: e.bit_bound,
                literals: e
                    .literals
                    .iter()
                    .enumerate()
                    .map(|(i, l)| (l.name.clone(), l.value, i == e.default))
                    .collect(),
            },
            TypeKind::Bitmask(b) => Def::Bitmask {
                extensibility: b.extensibility,
                bit_bound: b.bit_bound,
                flags: b
                    .flags
                    .iter()
                    .map(|f| (f.name.clone(), f.position))
                    .collect(),
            },
            _ => return Err(BuildError::NotNamed),
        })
    }

    fn member(&mut self, m: &super::types::Member) -> Result<Member, BuildError> {
        let mut flags = MemberFlag::empty();
        flags.set(MemberFlag::TRY_CONSTRUCT2, m.use_default);
        flags.set(MemberFlag::IS_KEY, m.key);
        flags.set(MemberFlag::IS_OPTIONAL, m.optional);
        flags.set(MemberFlag::IS_EXTERNAL, m.external);
        flags.set(MemberFlag::IS_MUST_UNDERSTAND, m.must_understand);
        Ok(Member {
            name: m.name.clone(),
            id: m.id,
            flags: with_try_construct(flags),
            ty: self.shape(&m.ty)?,
            hash_id: m.hash_id.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::{MemberBuilder, StructBuilder};
    use super::*;

    fn long() -> DynamicType {
        DynamicType::primitive(Primitive::Int32)
    }

    #[test]
    fn only_structs_and_unions_are_topic_types() {
        assert_eq!(long().type_support().err(), Some(BuildError::NotNamed));
        let seq = DynamicType::sequence(long(), None);
        assert_eq!(seq.type_support().err(), Some(BuildError::NotNamed));
    }

    #[test]
    fn two_types_of_one_name_are_refused() {
        let a1 = StructBuilder::new("A").member("x", long()).build().unwrap();
        let a2 = StructBuilder::new("A")
            .member("y", DynamicType::string(None))
            .build()
            .unwrap();
        let top = StructBuilder::new("Top")
            .member("a", a1.clone())
            .member("b", a2)
            .build()
            .unwrap();
        assert_eq!(
            top.type_support().err(),
            Some(BuildError::Conflict("A".into()))
        );
        let same = StructBuilder::new("Top")
            .member("a", a1.clone())
            .member("b", a1)
            .build()
            .unwrap();
        let s = same.type_support().unwrap();
        assert_eq!(s.information.complete.dependent_typeid_count, 1);
    }

    #[test]
    fn a_type_reached_many_times_is_lowered_once_per_value() {
        // 40 levels, each with two members of the level below (built twice: equal values, other
        // addresses): 2^40 paths, which a walk per path (or a comparison per path) would never finish.
        let level = |below: Option<DynamicType>, i: usize| {
            let b = StructBuilder::new(format!("L{i}"));
            match below {
                None => b.member("x", long()),
                Some(t) => b.member("a", t.clone()).member("b", t),
            }
            .build()
            .unwrap()
        };
        let (mut one, mut other) = (level(None, 0), level(None, 0));
        for i in 1..40 {
            one = level(Some(one), i);
            other = level(Some(other), i);
        }
        let top = StructBuilder::new("Top")
            .member("one", one)
            .member("other", other)
            .build()
            .unwrap();
        let s = top.type_support().unwrap();
        assert_eq!(s.mapping.identifier_object_pair_minimal.len(), 41);
    }

    #[test]
    fn a_typedef_topic_type_is_its_struct_and_members_keep_their_aliases() {
        let inner = DynamicType::alias("M::Count", long());
        let s = StructBuilder::new("M::S")
            .with(MemberBuilder::new("n", inner).key())
            .build()
            .unwrap();
        let direct = s.type_support().unwrap();
        let aliased = DynamicType::alias("M::T", s).type_support().unwrap();
        assert_eq!(direct.information_bytes, aliased.information_bytes);
        // The alias is a dependency with an object of its own.
        assert_eq!(direct.information.minimal.dependent_typeid_count, 1);
        assert_eq!(direct.mapping.identifier_object_pair_complete.len(), 2);
    }
}
