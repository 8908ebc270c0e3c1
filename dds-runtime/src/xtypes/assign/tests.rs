//! One test per assignability rule (XTypes 1.3 §7.2.4), on types the derive describes, and on hand-made type
//! objects where the derive cannot say it (aliases, hostile objects).

use std::sync::Arc;

use super::*;
use crate::qos::TypeConsistencyEnforcement as Tce;
use crate::xtypes::typeobject::*;
use crate::xtypes::XTypesType;
use crate::DdsType;

fn check_with<R: XTypesType, W: XTypesType>(tce: &Tce) -> Result<(), NotAssignable> {
    let r = R::type_support().expect("reader type support");
    let w = W::type_support().expect("writer type support");
    is_assignable(r.minimal_id(), w.minimal_id(), tce, local_types())
}

fn check<R: XTypesType, W: XTypesType>() -> Result<(), NotAssignable> {
    check_with::<R, W>(&Tce::default())
}

/// Both directions assignable.
fn both<A: XTypesType, B: XTypesType>() {
    assert_eq!(check::<A, B>(), Ok(()));
    assert_eq!(check::<B, A>(), Ok(()));
}

mod v {
    //! Versions of a shape-like type.
    #![allow(dead_code)]
    use super::DdsType;

    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct App1 {
        #[dds(key)]
        pub(super) color: String,
        pub(super) x: i32,
        pub(super) y: i32,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct App2 {
        #[dds(key)]
        pub(super) color: String,
        pub(super) x: i32,
        pub(super) y: i32,
        pub(super) size: i32,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct AppMiddle {
        #[dds(key)]
        pub(super) color: String,
        pub(super) x: i32,
        pub(super) z: i32,
        pub(super) y: i32,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct AppShort {
        #[dds(key)]
        pub(super) color: String,
        pub(super) x: i16,
        pub(super) y: i32,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct AppOptY {
        #[dds(key)]
        pub(super) color: String,
        pub(super) x: i32,
        #[dds(optional)]
        pub(super) y: Option<i32>,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct AppNoKey {
        pub(super) color: String,
        pub(super) x: i32,
        pub(super) y: i32,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct AppRenamed {
        #[dds(key)]
        pub(super) color: String,
        pub(super) x: i32,
        pub(super) w: i32,
    }
    #[derive(DdsType)]
    #[dds(final)]
    pub(super) struct Fin1 {
        #[dds(key)]
        pub(super) color: String,
        pub(super) x: i32,
        pub(super) y: i32,
    }
    #[derive(DdsType)]
    #[dds(final)]
    pub(super) struct Fin2 {
        #[dds(key)]
        pub(super) color: String,
        pub(super) x: i32,
        pub(super) y: i32,
        pub(super) size: i32,
    }
    #[derive(DdsType)]
    #[dds(final)]
    pub(super) struct FinBase {
        #[dds(key)]
        pub(super) color: String,
        pub(super) x: i32,
    }
    #[derive(DdsType)]
    #[dds(final)]
    pub(super) struct FinDerived {
        #[dds(base)]
        pub(super) base: FinBase,
        pub(super) y: i32,
    }
    #[derive(DdsType)]
    #[dds(mutable)]
    pub(super) struct Mut1 {
        #[dds(key, id = 10)]
        pub(super) color: String,
        #[dds(id = 20)]
        pub(super) x: i32,
        #[dds(id = 30)]
        pub(super) y: i32,
    }
    #[derive(DdsType)]
    #[dds(mutable)]
    pub(super) struct MutReordered {
        #[dds(id = 30)]
        pub(super) y: i32,
        #[dds(id = 40)]
        pub(super) size: i32,
        #[dds(key, id = 10)]
        pub(super) color: String,
        #[dds(id = 20)]
        pub(super) x: i32,
    }
    #[derive(DdsType)]
    #[dds(mutable)]
    pub(super) struct MutRenumbered {
        #[dds(key, id = 10)]
        pub(super) color: String,
        #[dds(id = 21)]
        pub(super) x: i32,
        #[dds(id = 30)]
        pub(super) y: i32,
    }
    #[derive(DdsType)]
    #[dds(mutable)]
    pub(super) struct MutMustUnderstand {
        #[dds(key, id = 10)]
        pub(super) color: String,
        #[dds(id = 20)]
        pub(super) x: i32,
        #[dds(id = 30)]
        pub(super) y: i32,
        #[dds(id = 50, must_understand)]
        pub(super) critical: i32,
    }
    #[derive(DdsType)]
    #[dds(mutable)]
    pub(super) struct MutOptional {
        #[dds(key, id = 10)]
        pub(super) color: String,
        #[dds(id = 20)]
        pub(super) x: i32,
        #[dds(id = 30)]
        pub(super) y: i32,
        #[dds(id = 60, optional)]
        pub(super) note: Option<i32>,
    }
    #[derive(DdsType)]
    #[dds(mutable)]
    pub(super) struct MutDisjoint {
        #[dds(id = 70)]
        pub(super) a: i32,
    }
    #[derive(DdsType)]
    #[dds(mutable)]
    pub(super) struct MutDisjoint2 {
        #[dds(id = 80)]
        pub(super) b: i32,
    }

    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct Str8 {
        #[dds(bound = 8)]
        pub(super) s: String,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct Str16 {
        #[dds(bound = 16)]
        pub(super) s: String,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct Seq8 {
        #[dds(bound = 8)]
        pub(super) s: Vec<i32>,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct SeqUnbounded {
        pub(super) s: Vec<i32>,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct SeqShort {
        pub(super) s: Vec<i16>,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct Arr3 {
        pub(super) a: [i32; 3],
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct Arr4 {
        pub(super) a: [i32; 4],
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct MapA {
        pub(super) m: std::collections::BTreeMap<i32, String>,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct MapB {
        pub(super) m: std::collections::BTreeMap<i64, String>,
    }

    #[derive(DdsType, Clone, Copy, Debug, PartialEq)]
    #[dds(appendable, name = "E")]
    pub(super) enum Ea {
        Red,
        Green,
    }
    #[derive(DdsType, Clone, Copy, Debug, PartialEq)]
    #[dds(appendable, name = "E")]
    pub(super) enum Eb {
        Red,
        Green,
        Blue,
    }
    #[derive(DdsType, Clone, Copy, Debug, PartialEq)]
    #[dds(appendable, name = "E")]
    pub(super) enum Ec {
        Red,
        Lime,
    }
    #[derive(DdsType, Clone, Copy, Debug, PartialEq)]
    #[dds(final, name = "E")]
    pub(super) enum Fa {
        Red,
        Green,
    }
    #[derive(DdsType, Clone, Copy, Debug, PartialEq)]
    #[dds(final, name = "E")]
    pub(super) enum Fb {
        Red,
        Green,
        Blue,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct HoldEa {
        pub(super) e: Ea,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct HoldEb {
        pub(super) e: Eb,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct HoldEc {
        pub(super) e: Ec,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct HoldFa {
        pub(super) e: Fa,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct HoldFb {
        pub(super) e: Fb,
    }

    #[derive(DdsType)]
    #[dds(appendable, discriminator = i32, name = "U")]
    pub(super) enum Ua {
        #[dds(case = 1)]
        A(i32),
        #[dds(case = 2)]
        B(String),
    }
    #[derive(DdsType)]
    #[dds(appendable, discriminator = i32, name = "U")]
    pub(super) enum Ub {
        #[dds(case = 1)]
        A(i32),
        #[dds(case = 2)]
        B(String),
        #[dds(case = 3)]
        C(f64),
    }
    #[derive(DdsType)]
    #[dds(appendable, discriminator = i32, name = "U")]
    pub(super) enum Uc {
        #[dds(case = 1)]
        A(i16),
        #[dds(case = 2)]
        B(String),
    }
    #[derive(DdsType)]
    #[dds(final, discriminator = i32, name = "U")]
    pub(super) enum Fua {
        #[dds(case = 1)]
        A(i32),
        #[dds(case = 2)]
        B(String),
    }
    #[derive(DdsType)]
    #[dds(final, discriminator = i32, name = "U")]
    pub(super) enum Fub {
        #[dds(case = 1)]
        A(i32),
        #[dds(case = 2)]
        B(String),
        #[dds(case = 3)]
        C(f64),
    }
    #[derive(DdsType)]
    #[dds(appendable, discriminator = i16, name = "U")]
    pub(super) enum Ud {
        #[dds(case = 1)]
        A(i32),
        #[dds(case = 2)]
        B(String),
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct HoldUa {
        pub(super) u: Ua,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct HoldUb {
        pub(super) u: Ub,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct HoldUc {
        pub(super) u: Uc,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct HoldUd {
        pub(super) u: Ud,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct HoldFua {
        pub(super) u: Fua,
    }
    #[derive(DdsType)]
    #[dds(appendable)]
    pub(super) struct HoldFub {
        pub(super) u: Fub,
    }
}
use v::*;

#[test]
fn equal_types_are_assignable() {
    both::<App1, App1>();
    both::<Mut1, Mut1>();
}

/// §7.2.4.4.8: appendable: a member added at the end, in both directions.
#[test]
fn appendable_member_added_at_the_end() {
    both::<App1, App2>();
}

/// §7.2.4.4.8: appendable: members with the same index have the same id; a member inserted in the middle moves
/// the ids (and pairs the same name with another id).
#[test]
fn appendable_member_inserted_in_the_middle() {
    assert!(check::<App1, AppMiddle>().is_err());
    assert!(check::<AppMiddle, App1>().is_err());
}

/// §7.2.4.1 table: a member's primitive type must be the same (no widening in XTypes 1.3).
#[test]
fn primitive_member_types_must_be_equal() {
    assert_eq!(check::<App1, AppShort>(), Err(NotAssignable::Kind));
}

/// §7.2.4.4.8: appendable: members at the same index agree on `optional`.
#[test]
fn optional_must_agree_at_the_same_index() {
    assert_eq!(
        check::<App1, AppOptY>(),
        Err(NotAssignable::Member { id: 2 })
    );
}

/// §7.2.4.4.8: key members appear in both types.
#[test]
fn key_members_must_agree() {
    assert_eq!(check::<App1, AppNoKey>(), Err(NotAssignable::Key));
    assert_eq!(check::<AppNoKey, App1>(), Err(NotAssignable::Key));
}

/// §7.2.4.4.8: same id, same name (unless `ignore_member_names`).
#[test]
fn member_names_and_ids_pair_up() {
    assert_eq!(
        check::<App1, AppRenamed>(),
        Err(NotAssignable::MemberName { id: 2 })
    );
    let tce = Tce {
        ignore_member_names: true,
        ..Tce::default()
    };
    assert_eq!(check_with::<App1, AppRenamed>(&tce), Ok(()));
    assert!(check::<Mut1, MutRenumbered>().is_err());
}

/// §7.2.4.4.8: final: the same members, nothing added.
#[test]
fn final_structs_need_the_same_members() {
    assert_eq!(check::<Fin1, Fin1>(), Ok(()));
    assert!(check::<Fin1, Fin2>().is_err());
    assert!(check::<Fin2, Fin1>().is_err());
}

/// §7.2.4.4.8 and §7.2.2.4.5: a base type counts as its members, first (as Cyclone expands it).
#[test]
fn base_types_are_flattened() {
    both::<Fin1, FinDerived>();
}

/// §7.2.4.4.8: the extensibility kinds are the same.
#[test]
fn extensibility_must_agree() {
    assert_eq!(check::<App1, Fin1>(), Err(NotAssignable::Extensibility));
    assert_eq!(check::<Mut1, App1>(), Err(NotAssignable::Extensibility));
}

/// §7.2.4.4.8: mutable: members matched by id whatever their order; members one side lacks are skipped or
/// defaulted.
#[test]
fn mutable_members_match_by_id_in_any_order() {
    both::<Mut1, MutReordered>();
}

/// §7.2.4.4.8: a non-optional must_understand member appears in both types.
#[test]
fn must_understand_members_must_appear_in_both() {
    assert_eq!(
        check::<Mut1, MutMustUnderstand>(),
        Err(NotAssignable::MustUnderstand { id: 50 })
    );
    assert_eq!(
        check::<MutMustUnderstand, Mut1>(),
        Err(NotAssignable::MustUnderstand { id: 50 })
    );
}

/// §7.6.3.4.1 prevent_type_widening: the reader's non-optional members must all be in the writer's type
/// (an optional member may still be missing).
#[test]
fn prevent_type_widening() {
    let tce = Tce {
        prevent_type_widening: true,
        ..Tce::default()
    };
    assert_eq!(check_with::<Mut1, MutReordered>(&tce), Ok(()));
    assert!(check_with::<MutReordered, Mut1>(&tce).is_err());
    assert_eq!(check_with::<MutOptional, Mut1>(&tce), Ok(()));
    assert_eq!(check_with::<App1, App2>(&tce), Ok(()));
    assert!(check_with::<App2, App1>(&tce).is_err());
}

/// §7.2.4.4.8: at least one member in common.
#[test]
fn disjoint_structs_are_not_assignable() {
    assert_eq!(
        check::<MutDisjoint, MutDisjoint2>(),
        Err(NotAssignable::NoOverlap)
    );
}

/// §7.6.3.4.1 DISALLOW_TYPE_COERCION: only equal types.
#[test]
fn disallow_type_coercion_needs_equal_types() {
    let tce = Tce {
        kind: crate::qos::TypeConsistencyKind::DisallowTypeCoercion,
        ..Tce::default()
    };
    assert_eq!(check_with::<App1, App1>(&tce), Ok(()));
    assert_eq!(check_with::<App1, App2>(&tce), Err(NotAssignable::NotEqual));
}

/// §7.2.4.3: string bounds count only without ignore_string_bounds; a larger reader bound holds a smaller one.
#[test]
fn string_bounds() {
    both::<Str8, Str16>();
    let tce = Tce {
        ignore_string_bounds: false,
        ..Tce::default()
    };
    assert_eq!(check_with::<Str16, Str8>(&tce), Ok(()));
    assert_eq!(check_with::<Str8, Str16>(&tce), Err(NotAssignable::Bound));
}

/// §7.2.4.4.3: sequence bounds count only without ignore_sequence_bounds; the elements are strongly assignable.
#[test]
fn sequence_bounds_and_elements() {
    both::<Seq8, SeqUnbounded>();
    let tce = Tce {
        ignore_sequence_bounds: false,
        ..Tce::default()
    };
    assert_eq!(check_with::<SeqUnbounded, Seq8>(&tce), Ok(()));
    assert_eq!(
        check_with::<Seq8, SeqUnbounded>(&tce),
        Err(NotAssignable::Bound)
    );
    assert_eq!(check::<SeqUnbounded, SeqShort>(), Err(NotAssignable::Kind));
}

/// §7.2.4.4.4: arrays need equal bounds.
#[test]
fn array_bounds_must_be_equal() {
    assert_eq!(check::<Arr3, Arr4>(), Err(NotAssignable::Bound));
}

/// §7.2.4.4.5: map keys and values strongly assignable.
#[test]
fn map_keys_must_be_assignable() {
    assert_eq!(check::<MapA, MapA>(), Ok(()));
    assert_eq!(check::<MapA, MapB>(), Err(NotAssignable::Kind));
}

/// §7.2.4.4.2: enums: an appendable enum may gain literals; literals of the same value keep their name; a final
/// enum keeps the same literals.
#[test]
fn enums() {
    both::<HoldEa, HoldEb>();
    assert!(check::<HoldEa, HoldEc>().is_err());
    assert!(check::<HoldFa, HoldFb>().is_err());
    assert_eq!(check::<HoldFa, HoldFa>(), Ok(()));
    assert_eq!(check::<HoldEa, HoldFa>(), Err(NotAssignable::Extensibility));
}

/// §7.2.4.4.7: unions: an appendable union may gain cases; the case types of shared labels are assignable; the
/// discriminators are strongly assignable; a final union keeps the same cases.
#[test]
fn unions() {
    both::<HoldUa, HoldUb>();
    assert_eq!(check::<HoldUa, HoldUc>(), Err(NotAssignable::Kind));
    assert_eq!(check::<HoldUa, HoldUd>(), Err(NotAssignable::Kind));
    assert!(check::<HoldFua, HoldFub>().is_err());
    assert_eq!(check::<HoldFua, HoldFua>(), Ok(()));
}

/// §7.2.4.1: a bitmask and the unsigned integer of its size.
#[test]
fn bitmask_and_unsigned_integers() {
    use kind::*;
    assert_eq!(simple_bitmask_uint(8, TK_UINT8), Ok(()));
    assert_eq!(simple_bitmask_uint(9, TK_UINT8), Err(NotAssignable::Bound));
    assert_eq!(simple_bitmask_uint(40, TK_UINT64), Ok(()));
    assert_eq!(simple_bitmask_uint(8, TK_INT8), Err(NotAssignable::Kind));
}

fn simple_bitmask_uint(bits: u16, k: u8) -> Result<(), NotAssignable> {
    let mask = TypeObject::Minimal(MinimalTypeObject(TypeBody::Bitmask {
        flags: TypeFlag::IS_APPENDABLE,
        bit_bound: bits,
        detail: TypeDetail::default(),
        bitflags: Vec::new(),
    }));
    let id = TypeIdentifier::Minimal([7; 14]);
    let obj = Arc::new(mask);
    let resolver =
        move |i: &TypeIdentifier| (i == &TypeIdentifier::Minimal([7; 14])).then(|| obj.clone());
    is_assignable(
        &id,
        &TypeIdentifier::Primitive(k),
        &Tce::default(),
        &resolver,
    )
}

/// §7.2.4.1: an alias is assignable as the type it names (both sides, chains included).
#[test]
fn aliases_are_resolved() {
    use kind::*;
    let alias = |to: TypeIdentifier| {
        Arc::new(TypeObject::Minimal(MinimalTypeObject(TypeBody::Alias {
            flags: TypeFlag::empty(),
            detail: TypeDetail::default(),
            related_flags: MemberFlag::empty(),
            related_type: to,
            ann_builtin: None,
            ann_custom: None,
        })))
    };
    let (a1, a2) = (
        TypeIdentifier::Minimal([1; 14]),
        TypeIdentifier::Minimal([2; 14]),
    );
    let (o1, o2) = (
        alias(TypeIdentifier::Primitive(TK_INT32)),
        alias(a1.clone()),
    );
    let k1 = a1.clone();
    let resolver = move |i: &TypeIdentifier| {
        if *i == k1 {
            Some(o1.clone())
        } else if *i == TypeIdentifier::Minimal([2; 14]) {
            Some(o2.clone())
        } else {
            None
        }
    };
    let tce = Tce::default();
    let i32_id = TypeIdentifier::Primitive(TK_INT32);
    assert_eq!(is_assignable(&a2, &i32_id, &tce, &resolver), Ok(()));
    assert_eq!(is_assignable(&i32_id, &a1, &tce, &resolver), Ok(()));
    assert_eq!(
        is_assignable(&a2, &TypeIdentifier::Primitive(TK_INT16), &tce, &resolver),
        Err(NotAssignable::Kind)
    );
    // A type the resolver does not know: the answer is unknown, not "incompatible".
    let unknown = TypeIdentifier::Minimal([9; 14]);
    assert_eq!(
        is_assignable(&unknown, &i32_id, &tce, &resolver),
        Err(NotAssignable::Unresolved(unknown.clone()))
    );
}

/// Hostile type objects: an alias loop and a struct that is its own base end in an error, not a hang.
#[test]
fn loops_in_type_objects_are_errors() {
    let id = TypeIdentifier::Minimal([3; 14]);
    let looped = Arc::new(TypeObject::Minimal(MinimalTypeObject(TypeBody::Alias {
        flags: TypeFlag::empty(),
        detail: TypeDetail::default(),
        related_flags: MemberFlag::empty(),
        related_type: id.clone(),
        ann_builtin: None,
        ann_custom: None,
    })));
    let k = id.clone();
    let resolver = move |i: &TypeIdentifier| (*i == k).then(|| looped.clone());
    let tce = Tce::default();
    let other = TypeIdentifier::Primitive(kind::TK_INT32);
    assert_eq!(
        is_assignable(&id, &other, &tce, &resolver),
        Err(NotAssignable::TooDeep)
    );

    let sid = TypeIdentifier::Minimal([4; 14]);
    let selfbase = Arc::new(TypeObject::Minimal(MinimalTypeObject(TypeBody::Struct {
        flags: TypeFlag::IS_APPENDABLE,
        base: sid.clone(),
        detail: TypeDetail::default(),
        members: Vec::new(),
    })));
    let k = sid.clone();
    let resolver = move |i: &TypeIdentifier| (*i == k).then(|| selfbase.clone());
    let other = TypeIdentifier::Minimal([5; 14]);
    assert!(is_assignable(&sid, &other, &tce, &resolver).is_err());
}
