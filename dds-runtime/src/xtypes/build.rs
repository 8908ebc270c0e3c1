//! From a type's lowered description ([`Described`], made from a derived type's `TypeDesc` or from a dynamic
//! type) to type objects, identifiers, `TypeInformation` and `TypeMapping`, computed the way Cyclone DDS 11
//! does (its Python binding's builder, whose bytes are the golden vectors):
//! - the dependency graph is gathered depth-first from the topic type (a stack; a struct's base, a union's
//!   enum discriminator, then member types in declaration order, inherited members included);
//! - the dependent types are those without dependencies of their own (in discovery order), then the others
//!   in post-order; the complete list keeps repeats, the minimal one drops them;
//! - the mapping holds the types with dependencies (topic type first), then those without.

use std::collections::HashMap;

use super::describe::TypeRef;
use super::error::BuildError;
use super::shape::{Def, Described, Shape};
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
        Self::from_described(&Described::from_desc(root)?)
    }

    /// Builds the type information and mapping of a lowered description (a derived or a dynamic type).
    pub(crate) fn from_described(d: &Described) -> Result<Self, BuildError> {
        let graph = Graph::gather(d);
        let mut b = Builder {
            described: d,
            done: HashMap::new(),
            busy: Vec::new(),
        };
        let nodes: Vec<Built> = graph
            .nodes
            .iter()
            .map(|&n| b.named(n))
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
        let information = information(&nodes, &deps);
        let order: Vec<usize> = if inner.is_empty() {
            vec![0]
        } else {
            inner.iter().chain(&leaves).copied().collect()
        };
        let mapping = mapping(&nodes, &order);
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

fn with_size(n: &Built, complete: bool) -> TypeIdentifierWithSize {
    let (id, len) = if complete {
        (&n.complete_id, n.complete_len)
    } else {
        (&n.minimal_id, n.minimal_len)
    };
    TypeIdentifierWithSize {
        type_id: id.clone(),
        typeobject_serialized_size: len as u32,
    }
}

/// The `TypeInformation` of node 0 with these dependencies (repeats dropped from the minimal list only).
fn information(nodes: &[Built], deps: &[usize]) -> TypeInformation {
    let mut minimal_deps: Vec<TypeIdentifierWithSize> = Vec::new();
    for &d in deps {
        let t = with_size(&nodes[d], false);
        if !minimal_deps.contains(&t) {
            minimal_deps.push(t);
        }
    }
    let complete_deps: Vec<_> = deps.iter().map(|&d| with_size(&nodes[d], true)).collect();
    TypeInformation {
        minimal: TypeIdentifierWithDependencies {
            typeid_with_size: with_size(&nodes[0], false),
            dependent_typeid_count: minimal_deps.len() as i32,
            dependent_typeids: minimal_deps,
        },
        complete: TypeIdentifierWithDependencies {
            typeid_with_size: with_size(&nodes[0], true),
            dependent_typeid_count: complete_deps.len() as i32,
            dependent_typeids: complete_deps,
        },
    }
}

/// The `TypeMapping` of the nodes in `order`.
fn mapping(nodes: &[Built], order: &[usize]) -> TypeMapping {
    TypeMapping {
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
    }
}

/// The named type found inside a member type (through sequences and arrays, not maps), as Cyclone looks.
fn named_inside(s: &Shape) -> Option<&str> {
    match s {
        Shape::Named(n) => Some(n),
        Shape::Sequence { element, .. } | Shape::Array { element, .. } => named_inside(element),
        _ => None,
    }
}

/// The dependency graph of a topic type, in discovery order (node 0 is the topic type).
struct Graph<'a> {
    nodes: Vec<&'a str>,
    edges: Vec<Vec<usize>>,
}

impl<'a> Graph<'a> {
    fn gather(d: &'a Described) -> Self {
        let root = d.root.as_str();
        let mut g = Graph {
            nodes: vec![root],
            edges: vec![Vec::new()],
        };
        let mut index: HashMap<&str, usize> = HashMap::from([(root, 0)]);
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            for dep in direct_dependencies(d, d.def(g.nodes[i])) {
                let j = *index.entry(dep).or_insert_with(|| {
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
        g
    }

    fn check_acyclic(&self, inner: &[usize]) -> Result<(), BuildError> {
        // Colour-marking depth-first search over the types with dependencies.
        fn visit(g: &Graph, i: usize, state: &mut [u8]) -> Result<(), BuildError> {
            state[i] = 1;
            for &j in &g.edges[i] {
                match state[j] {
                    1 => return Err(BuildError::Recursive(g.nodes[j].to_owned())),
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
fn direct_dependencies<'a>(d: &'a Described, def: &'a Def) -> Vec<&'a str> {
    let mut out = Vec::new();
    match def {
        Def::Struct { base, members, .. } => {
            if let Some(base) = base {
                out.extend(named_inside(base));
                // Inherited members count as the derived type's own when gathering.
                let mut chain = Vec::new();
                let mut cur = Some(base);
                while let Some(Shape::Named(n)) = cur {
                    let Def::Struct { base, members, .. } = d.def(n) else {
                        break;
                    };
                    chain.push(members);
                    cur = base.as_ref();
                }
                for ms in chain.iter().rev() {
                    out.extend(ms.iter().filter_map(|m| named_inside(&m.ty)));
                }
            }
            out.extend(members.iter().filter_map(|m| named_inside(&m.ty)));
        }
        Def::Union {
            discriminator,
            cases,
            ..
        } => {
            if let Shape::Named(n) = discriminator {
                out.push(n.as_str());
            }
            out.extend(cases.iter().filter_map(|c| named_inside(&c.ty)));
        }
        Def::Alias(t) => out.extend(named_inside(t)),
        Def::Enum { .. } | Def::Bitmask { .. } => {}
    }
    out
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
struct Builder<'a> {
    described: &'a Described,
    done: HashMap<&'a str, Built>,
    busy: Vec<&'a str>,
}

impl<'a> Builder<'a> {
    fn named(&mut self, name: &'a str) -> Result<Built, BuildError> {
        if let Some(b) = self.done.get(name) {
            return Ok(b.clone());
        }
        if self.busy.contains(&name) {
            return Err(BuildError::Recursive(name.to_owned()));
        }
        self.busy.push(name);
        let def = self.described.def(name);
        let minimal = MinimalTypeObject(self.body(name, def, false)?);
        let complete = CompleteTypeObject(self.body(name, def, true)?);
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
        self.done.insert(name, built.clone());
        Ok(built)
    }

    fn identifier(&mut self, t: &'a Shape, complete: bool) -> Result<TypeIdentifier, BuildError> {
        let kind = |fully: bool| match (fully, complete) {
            (true, _) => EquivalenceKind::Both,
            (false, false) => EquivalenceKind::Minimal,
            (false, true) => EquivalenceKind::Complete,
        };
        Ok(match t {
            Shape::Primitive(k) => TypeIdentifier::Primitive(*k),
            Shape::String { wide: false, bound } => TypeIdentifier::String8 { bound: *bound },
            Shape::String { wide: true, bound } => TypeIdentifier::String16 { bound: *bound },
            Shape::Sequence { bound, element } => {
                let element = self.identifier(element, complete)?;
                let header = PlainCollectionHeader {
                    equiv_kind: kind(element.is_fully_descriptive()),
                    element_flags: MemberFlag::TRY_CONSTRUCT1,
                };
                TypeIdentifier::PlainSequence {
                    header,
                    bound: *bound,
                    element: Box::new(element),
                }
            }
            Shape::Array { bounds, element } => {
                let element = self.identifier(element, complete)?;
                let header = PlainCollectionHeader {
                    equiv_kind: kind(element.is_fully_descriptive()),
                    element_flags: MemberFlag::TRY_CONSTRUCT1,
                };
                TypeIdentifier::PlainArray {
                    header,
                    bounds: bounds.clone(),
                    element: Box::new(element),
                }
            }
            Shape::Map { bound, key, value } => {
                let element = self.identifier(value, complete)?;
                let key = self.identifier(key, complete)?;
                let fully = element.is_fully_descriptive() && key.is_fully_descriptive();
                let header = PlainCollectionHeader {
                    equiv_kind: kind(fully),
                    element_flags: MemberFlag::empty(),
                };
                // Cyclone writes every map in the large form, unbounded as u32::MAX.
                let bound = if *bound == 0 { u32::MAX } else { *bound };
                TypeIdentifier::PlainMap {
                    header,
                    bound,
                    element: Box::new(element),
                    key_flags: MemberFlag::empty(),
                    key: Box::new(key),
                }
            }
            Shape::Named(n) => {
                let b = self.named(n)?;
                if complete {
                    b.complete_id
                } else {
                    b.minimal_id
                }
            }
        })
    }

    fn body(&mut self, name: &str, def: &'a Def, complete: bool) -> Result<TypeBody, BuildError> {
        super::objects::body(|t, c| self.identifier(t, c), name, def, complete)
    }
}
