//! The description the object builder works on ([`super::build`], [`super::objects`]): every named type of a
//! topic type by name, with owned names. A derived type's [`TypeDesc`] (followed through its function
//! pointers) and a dynamic type (`dynamic/to_object.rs`) both lower to it, so one builder makes the type
//! objects of both, with the same rules.

use std::collections::{HashMap, HashSet};

use crate::cdr::Extensibility;

use super::describe::{NamedRef, TypeDef, TypeDesc, TypeRef};
use super::error::BuildError;
use super::typeobject::MemberFlag;

/// A member's type: anonymous types spelled out, named ones by name.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Shape {
    /// A primitive (`TK_*`).
    Primitive(u8),
    /// `string`/`wstring`, bound 0 for none.
    String { wide: bool, bound: u32 },
    /// `sequence<T, bound>`, bound 0 for none.
    Sequence { bound: u32, element: Box<Shape> },
    /// An array of a non-array element, every dimension.
    Array {
        bounds: Vec<u32>,
        element: Box<Shape>,
    },
    /// `map<K, V, bound>`, bound 0 for none.
    Map {
        bound: u32,
        key: Box<Shape>,
        value: Box<Shape>,
    },
    /// A named type of [`Described::defs`].
    Named(String),
}

/// A struct member.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Member {
    pub(crate) name: String,
    pub(crate) id: u32,
    /// Every flag, try-construct included.
    pub(crate) flags: MemberFlag,
    pub(crate) ty: Shape,
    /// `@hashid` (its string, empty for the member name).
    pub(crate) hash_id: Option<String>,
}

/// A union case.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Case {
    pub(crate) name: String,
    pub(crate) id: u32,
    pub(crate) labels: Vec<i32>,
    pub(crate) is_default: bool,
    pub(crate) external: bool,
    pub(crate) ty: Shape,
}

/// A named type's definition.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Def {
    Struct {
        extensibility: Extensibility,
        autoid_hash: bool,
        nested: bool,
        base: Option<Shape>,
        /// Own members, in declaration order.
        members: Vec<Member>,
    },
    Union {
        extensibility: Extensibility,
        nested: bool,
        discriminator: Shape,
        discriminator_key: bool,
        cases: Vec<Case>,
    },
    Enum {
        extensibility: Extensibility,
        bit_bound: u16,
        /// Name, value, whether it is the default.
        literals: Vec<(String, i32, bool)>,
    },
    Bitmask {
        extensibility: Extensibility,
        bit_bound: u16,
        /// Name, position.
        flags: Vec<(String, u16)>,
    },
    Alias(Shape),
}

/// A topic type and every named type it reaches.
#[derive(Debug, Clone, Default)]
pub(crate) struct Described {
    /// The topic type's name (a key of `defs`).
    pub(crate) root: String,
    pub(crate) defs: HashMap<String, Def>,
}

impl Described {
    /// The definition of a named type the description holds.
    pub(crate) fn def(&self, name: &str) -> &Def {
        // Lowering puts every name a shape uses into `defs`.
        &self.defs[name]
    }

    /// Lowers a derived type's description (recursive types end at names already seen).
    pub(crate) fn from_desc(root: TypeRef) -> Result<Self, BuildError> {
        let TypeDesc::Named(n) = root.desc() else {
            return Err(BuildError::NotNamed);
        };
        let mut l = DescLowering::default();
        l.named(n)?;
        Ok(Described {
            root: n.name.to_owned(),
            defs: l.defs,
        })
    }
}

#[derive(Default)]
struct DescLowering {
    defs: HashMap<String, Def>,
    seen: HashSet<&'static str>,
}

impl DescLowering {
    fn named(&mut self, n: NamedRef) -> Result<Shape, BuildError> {
        if self.seen.insert(n.name) {
            let def = self.def((n.def)())?;
            self.defs.insert(n.name.to_owned(), def);
        }
        Ok(Shape::Named(n.name.to_owned()))
    }

    fn shape(&mut self, t: &TypeRef) -> Result<Shape, BuildError> {
        Ok(match t.desc() {
            TypeDesc::Primitive(k) => Shape::Primitive(k),
            TypeDesc::String { wide, bound } => Shape::String { wide, bound },
            TypeDesc::Sequence { bound, element } => Shape::Sequence {
                bound,
                element: Box::new(self.shape(&element)?),
            },
            TypeDesc::Array { bounds, element } => Shape::Array {
                bounds,
                element: Box::new(self.shape(&element)?),
            },
            TypeDesc::Map { bound, key, value } => Shape::Map {
                bound,
                key: Box::new(self.shape(&key)?),
                value: Box::new(self.shape(&value)?),
            },
            TypeDesc::Named(n) => self.named(n)?,
            TypeDesc::Unsupported(why) => return Err(BuildError::Unsupported(why)),
        })
    }

    fn def(&mut self, def: TypeDef) -> Result<Def, BuildError> {
        Ok(match def {
            TypeDef::Struct(s) => Def::Struct {
                extensibility: s.extensibility,
                autoid_hash: s.autoid_hash,
                nested: s.nested,
                base: s.base.map(|b| self.shape(&b)).transpose()?,
                members: s
                    .members
                    .iter()
                    .map(|m| {
                        Ok(Member {
                            name: m.name.to_owned(),
                            id: m.id,
                            flags: m.flags,
                            ty: self.shape(&m.ty)?,
                            hash_id: m.hash_id.map(str::to_owned),
                        })
                    })
                    .collect::<Result<_, BuildError>>()?,
            },
            TypeDef::Union(u) => {
                let mut cases = Vec::with_capacity(u.cases.len());
                for c in &u.cases {
                    // A case without a member has no place in a type object.
                    let Some(ty) = &c.ty else { continue };
                    cases.push(Case {
                        name: c.name.to_owned(),
                        id: c.id,
                        labels: c.labels.clone(),
                        is_default: c.is_default,
                        external: c.external,
                        ty: self.shape(ty)?,
                    });
                }
                Def::Union {
                    extensibility: u.extensibility,
                    nested: u.nested,
                    discriminator: self.shape(&u.discriminator)?,
                    discriminator_key: u.discriminator_key,
                    cases,
                }
            }
            TypeDef::Enum(e) => Def::Enum {
                extensibility: e.extensibility,
                bit_bound: e.bit_bound,
                literals: e
                    .literals
                    .iter()
                    .map(|(n, v, d)| ((*n).to_owned(), *v, *d))
                    .collect(),
            },
            TypeDef::Bitmask(b) => Def::Bitmask {
                extensibility: b.extensibility,
                bit_bound: b.bit_bound,
                flags: b.flags,
            },
            TypeDef::Alias(t) => Def::Alias(self.shape(&t)?),
        })
    }
}
