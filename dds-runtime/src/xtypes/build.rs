//! From a type's lowered description ([`Described`], made from a derived type's `TypeDesc` or from a dynamic
//! type) to type objects, identifiers, `TypeInformation` and `TypeMapping`, computed the way Cyclone DDS 11
//! does (its Python binding's builder, whose bytes are the golden vectors):
//! - the dependency graph is gathered depth-first from the topic type (a stack; a struct's base, a union's
//!   enum discriminator, then member types in declaration order, inherited members included);
//! - the dependent types are those without dependencies of their own (in discovery order), then the others
//!   in post-order; the complete list keeps repeats, the minimal one drops them;
//! - the mapping holds the types with dependencies (topic type first), then those without.
//!
//! Recursive types (XTypes 1.3 §7.3.4.9) as the binding builds them: the types of a strongly connected
//! component (`super::scc`: more than one type, or one that depends on itself) are sorted by name and numbered
//! from 1; their objects are made with `StronglyConnectedComponentId`s of a zero hash for each other, the
//! sequence of those objects (XCDR2, as a `@final` struct holding `sequence<TypeObject>`) is hashed, and each
//! type's identifier is the component id with that hash and its number; its objects then carry the hash too.
//! In dependency lists a component stands as a whole (number 0, the size of that sequence), after the
//! components it depends on; the mapping lists each of its types.

use std::collections::HashMap;

use super::describe::TypeRef;
use super::error::BuildError;
use super::scc::Components;
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
            placeholders: HashMap::new(),
        };
        let (inner, leaves): (Vec<usize>, Vec<usize>) =
            (0..graph.nodes.len()).partition(|&i| !graph.edges[i].is_empty());
        let comps = Components::find(&graph.edges, &inner);
        let mut post = Vec::new();
        if !inner.is_empty() {
            comps.post_order(0, &mut post);
        }
        // Recursive components first, those they depend on before them.
        let mut wholes = vec![None; comps.members.len()];
        for &c in &post {
            if comps.recursive[c] && wholes[c].is_none() {
                let names: Vec<&str> = comps.members[c].iter().map(|&i| graph.nodes[i]).collect();
                wholes[c] = Some(b.component(names)?);
            }
        }
        let nodes: Vec<Built> = graph
            .nodes
            .iter()
            .map(|&n| b.named(n))
            .collect::<Result<_, _>>()?;
        let mut deps: Vec<[TypeIdentifierWithSize; 2]> = Vec::new();
        if !inner.is_empty() {
            deps.extend(leaves.iter().map(|&i| both_with_size(&nodes[i])));
            for c in post {
                match &wholes[c] {
                    Some(whole) => deps.push(whole.clone()),
                    None if comps.members[c] != [0] => {
                        deps.push(both_with_size(&nodes[comps.members[c][0]]))
                    }
                    None => {}
                }
            }
        }
        let information = information(&nodes[0], &deps);
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

/// A type's minimal and complete identifiers with their objects' sizes.
fn both_with_size(n: &Built) -> [TypeIdentifierWithSize; 2] {
    [with_size(n, false), with_size(n, true)]
}

/// The `TypeInformation` of `top` with these dependencies, minimal and complete (repeats dropped from the
/// minimal list only).
fn information(top: &Built, deps: &[[TypeIdentifierWithSize; 2]]) -> TypeInformation {
    let mut minimal_deps: Vec<TypeIdentifierWithSize> = Vec::new();
    for [t, _] in deps {
        if !minimal_deps.contains(t) {
            minimal_deps.push(t.clone());
        }
    }
    let complete_deps: Vec<_> = deps.iter().map(|[_, t]| t.clone()).collect();
    TypeInformation {
        minimal: TypeIdentifierWithDependencies {
            typeid_with_size: with_size(top, false),
            dependent_typeid_count: minimal_deps.len() as i32,
            dependent_typeids: minimal_deps,
        },
        complete: TypeIdentifierWithDependencies {
            typeid_with_size: with_size(top, true),
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
    /// While a recursive component is built: the identifiers its types have for each other (minimal,
    /// complete).
    placeholders: HashMap<&'a str, [TypeIdentifier; 2]>,
}

/// The identifiers of the `index`th type (from 1; 0: the whole) of a component of `len` types whose objects
/// hash to `hashes` (minimal, complete).
fn component_ids(hashes: [EquivalenceHash; 2], len: usize, index: usize) -> [TypeIdentifier; 2] {
    let id = |kind, hash| {
        TypeIdentifier::StronglyConnected(StronglyConnectedComponentId {
            kind,
            hash,
            scc_length: len as i32,
            scc_index: index as i32,
        })
    };
    [
        id(EquivalenceKind::Minimal, hashes[0]),
        id(EquivalenceKind::Complete, hashes[1]),
    ]
}

/// A component's objects as the binding hashes them: a `@final` struct holding `sequence<TypeObject>`, XCDR2
/// little endian without encapsulation header (DHEADER, count, each object 4-aligned).
fn component_bytes(objects: &[TypeObject]) -> Result<Vec<u8>, BuildError> {
    let serialized: Vec<Vec<u8>> = objects.iter().map(to_bytes).collect::<Result<_, _>>()?;
    Ok(component_sequence(&serialized))
}

/// [`component_bytes`] of objects serialized already (each XCDR2 LE, no header).
pub(super) fn component_sequence(serialized: &[Vec<u8>]) -> Vec<u8> {
    let mut body = Vec::new();
    for o in serialized {
        body.resize(body.len().next_multiple_of(4), 0);
        body.extend_from_slice(o);
    }
    let mut out = Vec::with_capacity(body.len() + 8);
    out.extend(((body.len() + 4) as u32).to_le_bytes());
    out.extend((serialized.len() as u32).to_le_bytes());
    out.extend(body);
    out
}

impl<'a> Builder<'a> {
    /// Builds the types of a recursive component (see the module documentation); returns the identifiers
    /// and sizes of the component as a whole (minimal, complete).
    fn component(
        &mut self,
        mut names: Vec<&'a str>,
    ) -> Result<[TypeIdentifierWithSize; 2], BuildError> {
        names.sort_unstable();
        let len = names.len();
        let mut hashes = [[0u8; 14]; 2];
        let mut sizes = [0usize; 2];
        // Twice: with zero hashes for the hash, then with the hash for the objects.
        for pass in 0..2 {
            for (k, &n) in names.iter().enumerate() {
                self.placeholders
                    .insert(n, component_ids(hashes, len, k + 1));
            }
            let mut objects: [Vec<TypeObject>; 2] = [Vec::new(), Vec::new()];
            for &n in &names {
                let def = self.described.def(n);
                objects[0].push(TypeObject::Minimal(MinimalTypeObject(
                    self.body(n, def, false)?,
                )));
                objects[1].push(TypeObject::Complete(CompleteTypeObject(
                    self.body(n, def, true)?,
                )));
            }
            if pass == 0 {
                for e in 0..2 {
                    let bytes = component_bytes(&objects[e])?;
                    sizes[e] = bytes.len();
                    hashes[e] = equivalence_hash(&bytes);
                }
                continue;
            }
            let [minimal, complete] = objects;
            for (k, (m, c)) in minimal.into_iter().zip(complete).enumerate() {
                let (TypeObject::Minimal(minimal), TypeObject::Complete(complete)) = (m, c) else {
                    unreachable!("built as minimal and complete")
                };
                let [minimal_id, complete_id] = component_ids(hashes, len, k + 1);
                let built = Built {
                    minimal_len: to_bytes(&TypeObject::Minimal(minimal.clone()))?.len(),
                    complete_len: to_bytes(&TypeObject::Complete(complete.clone()))?.len(),
                    minimal,
                    complete,
                    minimal_id,
                    complete_id,
                };
                self.done.insert(names[k], built);
            }
        }
        for n in &names {
            self.placeholders.remove(n);
        }
        let [m, c] = component_ids(hashes, len, 0);
        Ok([
            TypeIdentifierWithSize {
                type_id: m,
                typeobject_serialized_size: sizes[0] as u32,
            },
            TypeIdentifierWithSize {
                type_id: c,
                typeobject_serialized_size: sizes[1] as u32,
            },
        ])
    }

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
            Shape::Named(n) if self.placeholders.contains_key(n.as_str()) => {
                self.placeholders[n.as_str()][usize::from(complete)].clone()
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
