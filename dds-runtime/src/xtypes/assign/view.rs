//! A type identifier seen through its type object: aliases resolved (§7.2.4.1: an alias is assignable as its
//! aliased type), collections written as type objects folded into the same shape as plain ones.

use std::sync::Arc;

use super::{Checker, NotAssignable, MAX_DEPTH};
use crate::xtypes::typeobject::{StructMember, TypeBody, TypeFlag, TypeIdentifier, TypeObject};

/// What a type is, for assignability.
pub(super) enum View {
    /// A primitive `TK_*` kind.
    Primitive(u8),
    /// `string<bound>` (0: unbounded).
    String8(u32),
    /// `wstring<bound>`.
    String16(u32),
    /// `sequence<element, bound>`.
    Sequence { bound: u32, element: TypeIdentifier },
    /// An array.
    Array {
        bounds: Vec<u32>,
        element: TypeIdentifier,
    },
    /// `map<key, element, bound>`.
    Map {
        key: TypeIdentifier,
        element: TypeIdentifier,
    },
    /// A struct, union, enum or bitmask type object.
    Object(Arc<TypeObject>),
}

/// The body of a type object, minimal or complete.
pub(super) fn body(o: &TypeObject) -> &TypeBody {
    match o {
        TypeObject::Minimal(m) => &m.0,
        TypeObject::Complete(c) => &c.0,
    }
}

/// The extensibility bits of a type's flags.
pub(super) fn extensibility(flags: TypeFlag) -> TypeFlag {
    flags & (TypeFlag::IS_FINAL | TypeFlag::IS_APPENDABLE | TypeFlag::IS_MUTABLE)
}

/// Whether a struct or union is final (no extensibility flag counts as final, the IDL 4 default).
pub(super) fn is_final(flags: TypeFlag) -> bool {
    let e = extensibility(flags);
    e.contains(TypeFlag::IS_FINAL) || e.is_empty()
}

impl Checker<'_> {
    /// The view of an identifier, aliases resolved.
    pub(super) fn view(&mut self, id: &TypeIdentifier) -> Result<View, NotAssignable> {
        let mut id = id.clone();
        for _ in 0..MAX_DEPTH {
            let obj = match &id {
                TypeIdentifier::Primitive(k) => return Ok(View::Primitive(*k)),
                TypeIdentifier::String8 { bound } => return Ok(View::String8(*bound)),
                TypeIdentifier::String16 { bound } => return Ok(View::String16(*bound)),
                TypeIdentifier::PlainSequence { bound, element, .. } => {
                    return Ok(View::Sequence {
                        bound: *bound,
                        element: (**element).clone(),
                    })
                }
                TypeIdentifier::PlainArray {
                    bounds, element, ..
                } => {
                    return Ok(View::Array {
                        bounds: bounds.clone(),
                        element: (**element).clone(),
                    })
                }
                TypeIdentifier::PlainMap { element, key, .. } => {
                    return Ok(View::Map {
                        key: (**key).clone(),
                        element: (**element).clone(),
                    })
                }
                TypeIdentifier::None => return Err(NotAssignable::Malformed),
                TypeIdentifier::StronglyConnected(_)
                | TypeIdentifier::Minimal(_)
                | TypeIdentifier::Complete(_) => self
                    .resolver
                    .resolve(&id)
                    .ok_or_else(|| NotAssignable::Unresolved(id.clone()))?,
            };
            id = match body(&obj) {
                TypeBody::Alias { related_type, .. } => related_type.clone(),
                TypeBody::Sequence { bound, element, .. } => {
                    return Ok(View::Sequence {
                        bound: *bound,
                        element: element.type_id.clone(),
                    })
                }
                TypeBody::Array {
                    bounds, element, ..
                } => {
                    return Ok(View::Array {
                        bounds: bounds.clone(),
                        element: element.type_id.clone(),
                    })
                }
                TypeBody::Map { key, element, .. } => {
                    return Ok(View::Map {
                        key: key.type_id.clone(),
                        element: element.type_id.clone(),
                    })
                }
                _ => return Ok(View::Object(obj)),
            };
        }
        Err(NotAssignable::TooDeep)
    }

    /// A struct's members with its bases' first (the "hypothetical flat type" of §7.2.2.4.5, as Cyclone
    /// expands base types before comparing).
    pub(super) fn flat_members(
        &mut self,
        base: &TypeIdentifier,
        own: &[StructMember],
    ) -> Result<Vec<StructMember>, NotAssignable> {
        let mut chain: Vec<Arc<TypeObject>> = Vec::new();
        let mut next = base.clone();
        while next != TypeIdentifier::None {
            if chain.len() >= MAX_DEPTH {
                return Err(NotAssignable::TooDeep);
            }
            let View::Object(o) = self.view(&next)? else {
                return Err(NotAssignable::Malformed);
            };
            let TypeBody::Struct { base, .. } = body(&o) else {
                return Err(NotAssignable::Malformed);
            };
            next = base.clone();
            chain.push(o);
        }
        let mut all = Vec::new();
        for o in chain.iter().rev() {
            if let TypeBody::Struct { members, .. } = body(o) {
                all.extend(members.iter().cloned());
            }
        }
        all.extend(own.iter().cloned());
        Ok(all)
    }

    /// Whether a type is delimited (§7.2.4.2, as Cyclone: everything but final aggregates with a non-delimited
    /// member).
    pub(super) fn is_delimited(
        &mut self,
        id: &TypeIdentifier,
        depth: usize,
    ) -> Result<bool, NotAssignable> {
        if depth >= MAX_DEPTH {
            return Err(NotAssignable::TooDeep);
        }
        Ok(match self.view(id)? {
            View::Primitive(_) | View::String8(_) | View::String16(_) => true,
            View::Sequence { element, .. } | View::Array { element, .. } => {
                self.is_delimited(&element, depth + 1)?
            }
            View::Map { key, element } => {
                self.is_delimited(&key, depth + 1)? && self.is_delimited(&element, depth + 1)?
            }
            View::Object(o) => match body(&o) {
                TypeBody::Struct {
                    flags,
                    base,
                    members,
                    ..
                } if is_final(*flags) => {
                    let all = self.flat_members(base, members)?;
                    let mut ok = true;
                    for m in &all {
                        ok = ok && self.is_delimited(&m.type_id, depth + 1)?;
                    }
                    ok
                }
                TypeBody::Union {
                    flags,
                    disc_type,
                    members,
                    ..
                } if is_final(*flags) => {
                    let mut ok = self.is_delimited(disc_type, depth + 1)?;
                    for m in members {
                        ok = ok && self.is_delimited(&m.type_id, depth + 1)?;
                    }
                    ok
                }
                _ => true,
            },
        })
    }
}
