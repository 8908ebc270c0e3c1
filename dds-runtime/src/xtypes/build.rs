//! From a [`TypeDesc`] to type objects, identifiers, `TypeInformation` and `TypeMapping`, computed the way
//! Cyclone DDS 11 does (its Python binding's builder, whose bytes are the golden vectors):
//! - the dependency graph is gathered depth-first from the topic type (a stack; a struct's base, a union's
//!   enum discriminator, then member types in declaration order, inherited members included);
//! - the dependent types are those without dependencies of their own (in discovery order), then the others
//!   in post-order; the complete list keeps repeats, the minimal one drops them;
//! - the mapping holds the types with dependencies (topic type first), then those without.

use std::collections::HashMap;

use super::describe::{NamedRef, TypeDef, TypeDesc, TypeRef};
use super::error::BuildError;
use super::typeobject::kind::*;
use super::typeobject::*;

/// Everything XTypes says about one topic type, built once ([`TypeSupport::build`]).
#[derive(Debug, Clone)]
pub struct TypeSupport {
    /// The structured type information.
    pub information: TypeInformation,
    /// The identifier → object pairs of the type and its dependencies.
    pub mapping: TypeMapping,
    /// `information`, XCDR2 little-endian (the `PID_TYPE_INFORMATION` value).
    pub information_bytes: Vec<u8>,
    /// `mapping`, XCDR2 little-endian.
    pub mapping_bytes: Vec<u8>,
}

impl TypeSupport {
    /// Builds the type information and mapping of `root`.
    pub fn build(root: TypeRef) -> Result<Self, BuildError> {
        let TypeDesc::Named(named) = root.desc() else {
            return Err(BuildError::NotNamed);
        };
        let graph = Graph::gather(named)?;
        let mut b = Builder::default();
        let nodes: Vec<Built> = graph
            .nodes
            .iter()
            .map(|n| b.named(*n))
            .collect::<Result<_, _>>()?;
        let (inner, leaves): (Vec<usize>, Vec<usize>) =
            (0..nodes.len()).partition(|&i| !graph.edges[i].is_empty());
        let mut deps: Vec<usize> = Vec::new();
        if !inner.is_empty() {
            deps.extend(&leaves);
            graph.check_acyclic(&inner)?;
            let mut post = Vec::new();
            graph.post_order(0, &inner, &mut post);
            deps.extend(post.into_iter().filter(|&i| i != 0));
        }
        let with_size = |i: usize, complete: bool| {
            let n = &nodes[i];
            let (id, len) = if complete {
                (&n.complete_id, n.complete_len)
            } else {
                (&n.minimal_id, n.minimal_len)
            };
            TypeIdentifierWithSize {
                type_id: id.clone(),
                typeobject_serialized_size: len as u32,
            }
        };
        let mut minimal_deps: Vec<TypeIdentifierWithSize> = Vec::new();
        for &d in &deps {
            let t = with_size(d, false);
            if !minimal_deps.contains(&t) {
                minimal_deps.push(t);
            }
        }
        let complete_deps: Vec<_> = deps.iter().map(|&d| with_size(d, true)).collect();
        let information = TypeInformation {
            minimal: TypeIdentifierWithDependencies {
                typeid_with_size: with_size(0, false),
                dependent_typeid_count: minimal_deps.len() as i32,
                dependent_typeids: minimal_deps,
            },
            complete: TypeIdentifierWithDependencies {
                typeid_with_size: with_size(0, true),
                dependent_typeid_count: complete_deps.len() as i32,
                dependent_typeids: complete_deps,
            },
        };
        let order: Vec<usize> = if inner.is_empty() {
            vec![0]
        } else {
            inner.iter().chain(&leaves).copied().collect()
        };
        let mapping = TypeMapping {
            identifier_object_pair_minimal: order
                .iter()
                .map(|&i| TypeIdentifierTypeObjectPair {
                    type_identifier: nodes[i].minimal_id.clone(),
                    type_object: TypeObject::Minimal(nodes[i].minimal.clone()),
                })
                .collect(),
            identifier_object_pair_complete: order
                .iter()
                .map(|&i| TypeIdentifierTypeObjectPair {
                    type_identifier: nodes[i].complete_id.clone(),
                    type_object: TypeObject::Complete(nodes[i].complete.clone()),
                })
                .collect(),
            identifier_complete_minimal: order
                .iter()
                .map(|&i| TypeIdentifierPair {
                    type_identifier1: nodes[i].complete_id.clone(),
                    type_identifier2: nodes[i].minimal_id.clone(),
                })
                .collect(),
        };
        #[cfg(feature = "rtps")]
        super::assign::local_types().register(&mapping);
        Ok(TypeSupport {
            information_bytes: to_bytes(&information)?,
            mapping_bytes: to_bytes(&mapping)?,
            information,
            mapping,
        })
    }

    /// The minimal identifier of the topic type.
    pub fn minimal_id(&self) -> &TypeIdentifier {
        &self.information.minimal.typeid_with_size.type_id
    }

    /// The complete identifier of the topic type.
    pub fn complete_id(&self) -> &TypeIdentifier {
        &self.information.complete.typeid_with_size.type_id
    }
}

/// The named type found inside a member type (through sequences and arrays, not maps), as Cyclone looks.
fn named_inside(d: &TypeDesc) -> Option<NamedRef> {
    match d {
        TypeDesc::Named(n) => Some(*n),
        TypeDesc::Sequence { element, .. } | TypeDesc::Array { element, .. } => {
            named_inside(&element.desc())
        }
        _ => None,
    }
}

/// The dependency graph of a topic type, in discovery order (node 0 is the topic type).
struct Graph {
    nodes: Vec<NamedRef>,
    edges: Vec<Vec<usize>>,
}

impl Graph {
    fn gather(root: NamedRef) -> Result<Self, BuildError> {
        let mut g = Graph {
            nodes: vec![root],
            edges: vec![Vec::new()],
        };
        let mut index: HashMap<&'static str, usize> = HashMap::from([(root.name, 0)]);
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            for dep in direct_dependencies(&(g.nodes[i].def)())? {
                let j = *index.entry(dep.name).or_insert_with(|| {
                    g.nodes.push(dep);
                    g.edges.push(Vec::new());
                    stack.push(g.nodes.len() - 1);
                    g.nodes.len() - 1
                });
                if !g.edges[i].contains(&j) {
                    g.edges[i].push(j);
                }
            }
        }
        Ok(g)
    }

    fn check_acyclic(&self, inner: &[usize]) -> Result<(), BuildError> {
        // Colour-marking depth-first search over the types with dependencies.
        fn visit(g: &Graph, i: usize, state: &mut [u8]) -> Result<(), BuildError> {
            state[i] = 1;
            for &j in &g.edges[i] {
                match state[j] {
                    1 => return Err(BuildError::Recursive(g.nodes[j].name.to_owned())),
                    0 => visit(g, j, state)?,
                    _ => {}
                }
            }
            state[i] = 2;
            Ok(())
        }
        let mut state = vec![0u8; self.nodes.len()];
        inner.iter().try_for_each(|&i| {
            if state[i] == 0 {
                visit(self, i, &mut state)
            } else {
                Ok(())
            }
        })
    }

    /// Post-order over the types with dependencies, children in discovery order (repeats kept).
    fn post_order(&self, i: usize, inner: &[usize], out: &mut Vec<usize>) {
        let mut children: Vec<usize> = self.edges[i]
            .iter()
            .copied()
            .filter(|j| inner.contains(j))
            .collect();
        children.sort_unstable();
        for j in children {
            self.post_order(j, inner, out);
        }
        out.push(i);
    }
}

/// The named types a definition refers to, in Cyclone's gathering order.
fn direct_dependencies(def: &TypeDef) -> Result<Vec<NamedRef>, BuildError> {
    let mut out = Vec::new();
    let member = |t: &TypeRef, out: &mut Vec<NamedRef>| -> Result<(), BuildError> {
        let d = t.desc();
        if let TypeDesc::Unsupported(why) = d {
            return Err(BuildError::Unsupported(why));
        }
        out.extend(named_inside(&d));
        Ok(())
    };
    match def {
        TypeDef::Struct(s) => {
            if let Some(base) = &s.base {
                member(base, &mut out)?;
                // Inherited members count as the derived type's own when gathering.
                let mut chain = Vec::new();
                let mut cur = base.desc();
                while let TypeDesc::Named(n) = cur {
                    let TypeDef::Struct(bs) = (n.def)() else {
                        break;
                    };
                    chain.push(bs.members.clone());
                    cur = bs.base.map_or(TypeDesc::Primitive(TK_NONE), |b| b.desc());
                }
                for ms in chain.iter().rev() {
                    ms.iter().try_for_each(|m| member(&m.ty, &mut out))?;
                }
            }
            s.members.iter().try_for_each(|m| member(&m.ty, &mut out))?;
        }
        TypeDef::Union(u) => {
            if let TypeDesc::Named(n) = u.discriminator.desc() {
                out.push(n);
            }
            u.cases
                .iter()
                .filter_map(|c| c.ty.as_ref())
                .try_for_each(|t| member(t, &mut out))?;
        }
        TypeDef::Alias(t) => member(t, &mut out)?,
        TypeDef::Enum(_) | TypeDef::Bitmask(_) => {}
    }
    Ok(out)
}

/// The objects and identifiers of one named type.
#[derive(Clone)]
struct Built {
    minimal: MinimalTypeObject,
    complete: CompleteTypeObject,
    minimal_id: TypeIdentifier,
    complete_id: TypeIdentifier,
    minimal_len: usize,
    complete_len: usize,
}

/// Builds named types once each (by name), recursing into member types.
#[derive(Default)]
struct Builder {
    done: HashMap<&'static str, Built>,
    busy: Vec<&'static str>,
}

impl Builder {
    fn named(&mut self, n: NamedRef) -> Result<Built, BuildError> {
        if let Some(b) = self.done.get(n.name) {
            return Ok(b.clone());
        }
        if self.busy.contains(&n.name) {
            return Err(BuildError::Recursive(n.name.to_owned()));
        }
        self.busy.push(n.name);
        let def = (n.def)();
        let minimal = MinimalTypeObject(self.body(n.name, &def, false)?);
        let complete = CompleteTypeObject(self.body(n.name, &def, true)?);
        self.busy.pop();
        let mb = to_bytes(&TypeObject::Minimal(minimal.clone()))?;
        let cb = to_bytes(&TypeObject::Complete(complete.clone()))?;
        let built = Built {
            minimal_id: TypeIdentifier::Minimal(equivalence_hash(&mb)),
            complete_id: TypeIdentifier::Complete(equivalence_hash(&cb)),
            minimal_len: mb.len(),
            complete_len: cb.len(),
            minimal,
            complete,
        };
        self.done.insert(n.name, built.clone());
        Ok(built)
    }

    fn identifier(&mut self, t: &TypeRef, complete: bool) -> Result<TypeIdentifier, BuildError> {
        let kind = |fully: bool| match (fully, complete) {
            (true, _) => EquivalenceKind::Both,
            (false, false) => EquivalenceKind::Minimal,
            (false, true) => EquivalenceKind::Complete,
        };
        Ok(match t.desc() {
            TypeDesc::Primitive(k) => TypeIdentifier::Primitive(k),
            TypeDesc::String { wide: false, bound } => TypeIdentifier::String8 { bound },
            TypeDesc::String { wide: true, bound } => TypeIdentifier::String16 { bound },
            TypeDesc::Sequence { bound, element } => {
                let element = self.identifier(&element, complete)?;
                let header = PlainCollectionHeader {
                    equiv_kind: kind(element.is_fully_descriptive()),
                    element_flags: MemberFlag::TRY_CONSTRUCT1,
                };
                TypeIdentifier::PlainSequence {
                    header,
                    bound,
                    element: Box::new(element),
                }
            }
            TypeDesc::Array { bounds, element } => {
                let element = self.identifier(&element, complete)?;
                let header = PlainCollectionHeader {
                    equiv_kind: kind(element.is_fully_descriptive()),
                    element_flags: MemberFlag::TRY_CONSTRUCT1,
                };
                TypeIdentifier::PlainArray {
                    header,
                    bounds,
                    element: Box::new(element),
                }
            }
            TypeDesc::Map { bound, key, value } => {
                let element = self.identifier(&value, complete)?;
                let key = self.identifier(&key, complete)?;
                let fully = element.is_fully_descriptive() && key.is_fully_descriptive();
                let header = PlainCollectionHeader {
                    equiv_kind: kind(fully),
                    element_flags: MemberFlag::empty(),
                };
                // Cyclone writes every map in the large form, unbounded as u32::MAX.
                let bound = if bound == 0 { u32::MAX } else { bound };
                TypeIdentifier::PlainMap {
                    header,
                    bound,
                    element: Box::new(element),
                    key_flags: MemberFlag::empty(),
                    key: Box::new(key),
                }
            }
            TypeDesc::Named(n) => {
                let b = self.named(n)?;
                if complete {
                    b.complete_id
                } else {
                    b.minimal_id
                }
            }
            TypeDesc::Unsupported(why) => return Err(BuildError::Unsupported(why)),
        })
    }

    fn body(
        &mut self,
        name: &'static str,
        def: &TypeDef,
        complete: bool,
    ) -> Result<TypeBody, BuildError> {
        super::objects::body(self_identifier(self), name, def, complete)
    }
}

/// Gives [`super::objects`] a way to resolve member types without seeing the builder's internals.
fn self_identifier(
    b: &mut Builder,
) -> impl FnMut(&TypeRef, bool) -> Result<TypeIdentifier, BuildError> + '_ {
    move |t, complete| b.identifier(t, complete)
}
