//! What the derive computes at compile time, computed from a [`DynamicType`]: the layout the XCDR rules see,
//! whether XCDR1 carries it by default, the key-stream size scan and whether a mutable type is on the key path.

use std::collections::HashSet;
use std::sync::Arc;

use crate::cdr::members::prim_end;
use crate::cdr::{Extensibility, Layout, XcdrVersion};

use super::types::{DynamicType, Primitive, TypeKind};

/// Key-size scans give up past this (the key is then hashed).
const KEY_SCAN_LIMIT: usize = 64;

/// The type's [`Layout`] (as `CdrType::LAYOUT` of the derived type).
pub(super) fn layout(ty: &DynamicType) -> Layout {
    match ty.resolved().kind() {
        TypeKind::Primitive(p) => Layout::Primitive(p.size() as u8),
        TypeKind::String { .. } => Layout::String,
        TypeKind::Enum(e) => Layout::Enumerated(e.size() as u8),
        TypeKind::Bitmask(b) => Layout::Enumerated(b.size() as u8),
        TypeKind::Sequence { element, .. } => match layout(element) {
            Layout::Primitive(n) => Layout::PrimitiveSequence(n),
            _ => Layout::Delimited,
        },
        TypeKind::Array { element, .. } => match layout(element) {
            Layout::Primitive(_) | Layout::PrimitiveArray => Layout::PrimitiveArray,
            _ => Layout::DelimitedArray,
        },
        TypeKind::Map { key, value, .. } => {
            if layout(key).is_primitive() && layout(value).is_primitive() {
                Layout::Other
            } else {
                Layout::Delimited
            }
        }
        TypeKind::Struct(_)
        | TypeKind::Union(_)
        | TypeKind::Alias { .. }
        | TypeKind::Forward(_) => Layout::Other,
    }
}

/// Whether XCDR1 carries the type as Cyclone does by default (final, no optional members, all the way down):
/// the derive's `XCDR1_PLAIN`. External members count as plain.
pub(super) fn xcdr1_plain(ty: &DynamicType) -> bool {
    plain_in(ty, &mut HashSet::new())
}

/// Whether `ty` was met before in this walk (a struct or union, by address): a recursive type's cycle is
/// then cut there, its answer being the one the rest of the walk gives (as the derive leaves a recursive
/// member out of its constants).
fn met(ty: &DynamicType, seen: &mut HashSet<usize>) -> bool {
    !seen.insert(Arc::as_ptr(&ty.0) as usize)
}

fn plain_in(ty: &DynamicType, seen: &mut HashSet<usize>) -> bool {
    let ty = ty.resolved();
    match ty.kind() {
        TypeKind::Struct(_) | TypeKind::Union(_) if met(ty, seen) => true,
        TypeKind::Struct(s) => {
            s.extensibility == Extensibility::Final
                && s.members
                    .iter()
                    .all(|m| !m.optional && (m.external || plain_in(&m.ty, seen)))
        }
        TypeKind::Union(u) => {
            u.extensibility == Extensibility::Final
                && u.cases.iter().all(|c| c.external || plain_in(&c.ty, seen))
        }
        TypeKind::Sequence { element, .. } | TypeKind::Array { element, .. } => {
            plain_in(element, seen)
        }
        TypeKind::Map { key, value, .. } => plain_in(key, seen) && plain_in(value, seen),
        _ => true,
    }
}

/// The XCDR version a writer uses when its QoS names none (the derive's `DEFAULT_VERSION`).
pub fn default_version(ty: &DynamicType) -> XcdrVersion {
    if xcdr1_plain(ty) {
        XcdrVersion::Xcdr1
    } else {
        XcdrVersion::Xcdr2
    }
}

/// Whether a @mutable type lies on the key path (the derive's `KEY_HAS_MUTABLE`); external members do not
/// count.
pub(super) fn key_has_mutable(ty: &DynamicType) -> bool {
    mutable_in(ty, &mut HashSet::new())
}

fn mutable_in(ty: &DynamicType, seen: &mut HashSet<usize>) -> bool {
    let ty = ty.resolved();
    match ty.kind() {
        TypeKind::Struct(_) | TypeKind::Union(_) if met(ty, seen) => false,
        TypeKind::Struct(s) => {
            if s.extensibility == Extensibility::Mutable {
                return true;
            }
            // Per level: the level's own keys, or all its members when it has none.
            let mut start = 0;
            for &end in &s.levels {
                let level = &s.members[start..end];
                let own_keys = level.iter().any(|m| m.key);
                if level
                    .iter()
                    .filter(|m| !own_keys || m.key)
                    .any(|m| !m.external && mutable_in(&m.ty, seen))
                {
                    return true;
                }
                start = end;
            }
            false
        }
        TypeKind::Union(u) => {
            u.extensibility == Extensibility::Mutable
                || u.cases
                    .iter()
                    .any(|c| !c.external && mutable_in(&c.ty, seen))
        }
        TypeKind::Sequence { element, .. } | TypeKind::Array { element, .. } => {
            mutable_in(element, seen)
        }
        TypeKind::Map { key, value, .. } => mutable_in(key, seen) || mutable_in(value, seen),
        _ => false,
    }
}

/// The furthest end of `n` elements in a row from `start` (a sequence's or an array's), or `None` past
/// [`KEY_SCAN_LIMIT`].
fn repeated_max_end(
    element: &DynamicType,
    start: usize,
    n: usize,
    version: XcdrVersion,
) -> Option<usize> {
    let mut p = start;
    for _ in 0..n {
        p = key_max_end(element, p, version, None)?;
        if p > KEY_SCAN_LIMIT {
            return None;
        }
    }
    Some(p)
}

/// The largest end offset of the plain key stream of `ty` from `start` (`None`: unbounded, or past the scan
/// limit): the derive's `key_max_end`.
pub(super) fn key_max_end(
    ty: &DynamicType,
    start: usize,
    version: XcdrVersion,
    bound: Option<usize>,
) -> Option<usize> {
    let align4 = |p: usize| (p + 3) & !3;
    match ty.resolved().kind() {
        TypeKind::Primitive(Primitive::Float128) => {
            let a = version.max_align();
            Some(start.div_ceil(a) * a + 16)
        }
        TypeKind::Primitive(p) => Some(prim_end(start, p.size(), version)),
        TypeKind::Enum(e) => Some(prim_end(start, e.size(), version)),
        TypeKind::Bitmask(b) => Some(prim_end(start, b.size(), version)),
        TypeKind::String {
            wide: false,
            bound: b,
        } => b
            .or(bound.map(|x| x as u32))
            .map(|b| align4(start) + 4 + b as usize + 1),
        TypeKind::String {
            wide: true,
            bound: b,
        } => b
            .or(bound.map(|x| x as u32))
            .map(|b| align4(start) + 4 + 2 * b as usize),
        TypeKind::Sequence { element, bound: b } => {
            let bound = b.map(|b| b as usize).or(bound)?;
            if start > KEY_SCAN_LIMIT || bound > KEY_SCAN_LIMIT {
                return None;
            }
            repeated_max_end(element, align4(start) + 4, bound, version)
        }
        TypeKind::Array { element, dims } => {
            let n: usize = dims
                .iter()
                .try_fold(1usize, |a, d| a.checked_mul(*d as usize))?;
            if start > KEY_SCAN_LIMIT || n > KEY_SCAN_LIMIT {
                return None;
            }
            repeated_max_end(element, start, n, version)
        }
        TypeKind::Map { .. } => None,
        TypeKind::Struct(s) if start <= KEY_SCAN_LIMIT => {
            let keys = s.has_keys();
            let mut p = start;
            for m in s
                .by_id()
                .into_iter()
                .map(|i| &s.members[i])
                .filter(|m| !keys || m.key)
            {
                if m.optional {
                    p = if version == XcdrVersion::Xcdr2 {
                        p + 1
                    } else {
                        align4(p) + 12
                    };
                }
                p = key_max_end(&m.ty, p, version, None)?;
            }
            Some(p)
        }
        TypeKind::Struct(_) => None,
        TypeKind::Union(u) => {
            if start > KEY_SCAN_LIMIT {
                return None;
            }
            let p = key_max_end(&u.discriminator, start, version, None)?;
            let mut end = p;
            for c in &u.cases {
                end = end.max(key_max_end(&c.ty, p, version, None)?);
            }
            Some(end)
        }
        TypeKind::Alias { .. } | TypeKind::Forward(_) => None,
    }
}
