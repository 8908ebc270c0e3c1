//! The rules for primitives, strings, collections, enums and bitmasks (XTypes 1.3 §7.2.4.1 table 13,
//! §7.2.4.3, §7.2.4.4.2-6), and the dispatch on the kinds of both sides.

use super::view::{body, extensibility, View};
use super::{Checker, NotAssignable};
use crate::xtypes::typeobject::kind::*;
use crate::xtypes::typeobject::{Bitflag, EnumeratedLiteral, TypeBody, TypeFlag};

/// `rd_bound` holds everything `wr_bound` allows (0 is unbounded).
fn bound_fits(rd_bound: u32, wr_bound: u32) -> bool {
    rd_bound == 0 || (wr_bound != 0 && rd_bound >= wr_bound)
}

impl Checker<'_> {
    /// T1 is-assignable-from T2 for two resolved types.
    pub(super) fn assignable_resolved(
        &mut self,
        v1: &View,
        v2: &View,
    ) -> Result<(), NotAssignable> {
        match (v1, v2) {
            // §7.2.4.1: a bitmask is assignable from/to the unsigned integer of its size, in either direction.
            (View::Object(o), View::Primitive(k)) | (View::Primitive(k), View::Object(o)) => {
                match body(o) {
                    TypeBody::Bitmask { bit_bound, .. } => bitmask_uint(*bit_bound, *k),
                    _ => Err(NotAssignable::Kind),
                }
            }
            // §7.2.4.1: primitives only from the same primitive (XTypes 1.3 has no widening).
            (View::Primitive(a), View::Primitive(b)) => {
                if a == b {
                    Ok(())
                } else {
                    Err(NotAssignable::Kind)
                }
            }
            // §7.2.4.3: strings of the same character type; the bound unless ignore_string_bounds.
            (View::String8(a), View::String8(b)) | (View::String16(a), View::String16(b)) => {
                if self.tce.ignore_string_bounds || bound_fits(*a, *b) {
                    Ok(())
                } else {
                    Err(NotAssignable::Bound)
                }
            }
            // §7.2.4.4.3-4: collections: the element strongly assignable; arrays of equal bounds; sequences
            // bounded unless ignore_sequence_bounds.
            (
                View::Sequence {
                    bound: a,
                    element: e1,
                },
                View::Sequence {
                    bound: b,
                    element: e2,
                },
            ) => {
                if !(self.tce.ignore_sequence_bounds || bound_fits(*a, *b)) {
                    return Err(NotAssignable::Bound);
                }
                self.strongly_assignable(e1, e2)
            }
            (
                View::Array {
                    bounds: a,
                    element: e1,
                },
                View::Array {
                    bounds: b,
                    element: e2,
                },
            ) => {
                if a != b {
                    return Err(NotAssignable::Bound);
                }
                self.strongly_assignable(e1, e2)
            }
            // §7.2.4.4.5: maps: key and value strongly assignable. Cyclone 11 does not compare map bounds; nor
            // do we.
            (
                View::Map {
                    key: k1,
                    element: e1,
                },
                View::Map {
                    key: k2,
                    element: e2,
                },
            ) => {
                self.strongly_assignable(k1, k2)?;
                self.strongly_assignable(e1, e2)
            }
            (View::Object(o1), View::Object(o2)) => self.assignable_objects(body(o1), body(o2)),
            _ => Err(NotAssignable::Kind),
        }
    }

    fn assignable_objects(&mut self, b1: &TypeBody, b2: &TypeBody) -> Result<(), NotAssignable> {
        match (b1, b2) {
            (
                TypeBody::Enum {
                    flags: f1,
                    literals: l1,
                    ..
                },
                TypeBody::Enum {
                    flags: f2,
                    literals: l2,
                    ..
                },
            ) => enum_assignable(*f1, l1, *f2, l2),
            (
                TypeBody::Bitmask {
                    bit_bound: a,
                    bitflags: f1,
                    ..
                },
                TypeBody::Bitmask {
                    bit_bound: b,
                    bitflags: f2,
                    ..
                },
            ) => bitmask_assignable(*a, f1, *b, f2),
            (TypeBody::Struct { .. }, TypeBody::Struct { .. }) => self.struct_assignable(b1, b2),
            (TypeBody::Union { .. }, TypeBody::Union { .. }) => self.union_assignable(b1, b2),
            _ => Err(NotAssignable::Kind),
        }
    }
}

/// §7.2.4.1: a bitmask and an unsigned integer: the integer's size holds the bit bound.
fn bitmask_uint(bit_bound: u16, k: u8) -> Result<(), NotAssignable> {
    let ok = match k {
        TK_UINT8 => (1..=8).contains(&bit_bound),
        TK_UINT16 => (9..=16).contains(&bit_bound),
        TK_UINT32 => (17..=32).contains(&bit_bound),
        TK_UINT64 => (33..=64).contains(&bit_bound),
        _ => return Err(NotAssignable::Kind),
    };
    if ok {
        Ok(())
    } else {
        Err(NotAssignable::Bound)
    }
}

/// §7.2.4.4.2 (bitmask): the same bit bound. Flags at the same position with different names do not make the
/// types unassignable (the positions are what is on the wire), as in Cyclone.
fn bitmask_assignable(
    a: u16,
    _f1: &[Bitflag],
    b: u16,
    _f2: &[Bitflag],
) -> Result<(), NotAssignable> {
    if a == b {
        Ok(())
    } else {
        Err(NotAssignable::Bound)
    }
}

/// §7.2.4.4.2 (enum): the same extensibility; literals with the same value have the same name; a final enum
/// has exactly the same literals. (Cyclone 11 does not compare `bit_bound`; neither do we.)
fn enum_assignable(
    f1: TypeFlag,
    l1: &[EnumeratedLiteral],
    f2: TypeFlag,
    l2: &[EnumeratedLiteral],
) -> Result<(), NotAssignable> {
    if extensibility(f1) != extensibility(f2) {
        return Err(NotAssignable::Extensibility);
    }
    let is_final = f1.contains(TypeFlag::IS_FINAL);
    for a in l1 {
        match l2.iter().find(|b| b.value == a.value) {
            Some(b) if a.detail.name.hash() != b.detail.name.hash() => {
                return Err(NotAssignable::MemberName { id: a.value as u32 })
            }
            None if is_final => return Err(NotAssignable::MissingCase),
            _ => {}
        }
    }
    if is_final && l1.len() != l2.len() {
        return Err(NotAssignable::MissingCase);
    }
    Ok(())
}
