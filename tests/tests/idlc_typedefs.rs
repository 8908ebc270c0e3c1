//! Typedefs through our idlc and derive against Cyclone DDS 11's idlc: `tests/idl/typedefs.idl` uses typedefs
//! in every member position (`build.rs` compiles it with our idlc), and each of its types must have the
//! type identifiers and objects that Cyclone's idlc writes for it (`fixtures/cyclone-idlc/typedefs.json`,
//! from `scripts/golden/idlc_typeinfo.py`). Only the order of the lists differs: Cyclone's idlc and its Python
//! binding (whose bytes the other golden tests hold, and whose order we follow) disagree on it. The same IDL
//! read as dynamic types gives the same bytes, and the typedefs change the type objects only, not the encoding.

dds_tests::generated!(gen, "own/typedefs");

dds_tests::generated!(
    /// `tests/idl/nested_base.idl`: structs deriving from `@nested` structs.
    gen_nested,
    "own/nested_base"
);

dds_tests::generated!(
    /// `tests/idl/no-peer/bitsets.idl`: bitsets (no peer reference).
    gen_bitsets,
    "own/bitsets"
);

#[path = "golden/cyclone_idlc.rs"]
mod cyclone_idlc;

use dds_runtime::cdr::{self, BoundedString, ByteOrder, DdsType, XcdrVersion};
use dds_runtime::xtypes::dynamic::types_from_idl;
use gen::m;

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// The TypeMapping of the dynamic type read from the same IDL.
fn dynamic_mapping(name: &str) -> String {
    let idl = include_str!("../idl/typedefs.idl");
    let types = types_from_idl("typedefs.idl", idl).expect("the IDL reads as dynamic types");
    hex(&types[name]
        .type_support()
        .expect("dynamic type support")
        .mapping_bytes)
}

/// `T`'s objects are Cyclone idlc's (see [`cyclone_idlc::same_objects`]); the dynamic type read from the same
/// IDL has the same bytes as `T`.
fn same_as_cyclone<T: DdsType>(name: &str) {
    let fx = cyclone_idlc::fixture("typedefs");
    let (info, map) = (T::type_information(), T::type_mapping());
    let (info, map) = (info.expect("type information"), map.expect("type mapping"));
    cyclone_idlc::same_objects(name, info, map, &fx["types"][name]);
    assert_eq!(
        dynamic_mapping(name),
        hex(map),
        "{name}: dynamic TypeMapping"
    );
}

#[test]
fn a_struct_with_typedefs_everywhere() {
    same_as_cyclone::<m::S>("M::S");
}

/// Cyclone's idlc numbers union members from 0 in the type objects, as its Python binding does, and so do
/// the derive and the dynamic types for final and appendable unions (`UnionType::first_member_id`).
#[test]
fn a_union_with_typedef_cases() {
    same_as_cyclone::<m::U>("M::U");
}

#[test]
fn a_mutable_struct_with_a_typedef_key_and_optional() {
    same_as_cyclone::<m::Mut>("M::Mut");
}

#[test]
fn a_struct_without_typedefs() {
    same_as_cyclone::<m::Inner>("M::Inner");
}

/// The XTypes description does not reach the encoding: a sample encodes as the same type written without
/// typedefs (every member spelled as its Rust type) does.
#[test]
fn typedefs_leave_the_encoding_alone() {
    #[derive(dds_runtime::DdsType, Debug, Clone, PartialEq)]
    #[dds(name = "M::Mut", mutable)]
    struct Plain {
        #[dds(key)]
        kind: m::E,
        #[dds(bound = 2)]
        names: Option<Vec<BoundedString<5>>>,
        plain: i32,
    }
    let typed = m::Mut {
        kind: m::E::B,
        names: Some(vec![BoundedString::from("ab")]),
        plain: 7,
    };
    let plain = Plain {
        kind: m::E::B,
        names: Some(vec![BoundedString::from("ab")]),
        plain: 7,
    };
    for v in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
        let (mut a, mut b) = (Vec::new(), Vec::new());
        cdr::serialize(&typed, v, ByteOrder::LittleEndian, &mut a).expect("encodes");
        cdr::serialize(&plain, v, ByteOrder::LittleEndian, &mut b).expect("encodes");
        assert_eq!(a, b);
        assert_eq!(cdr::deserialize::<m::Mut>(&a).expect("decodes"), typed);
    }
}

/// `@nested` is not inherited: a struct deriving from a `@nested` struct is not nested unless it says so, in
/// Cyclone 11's idlc (which writes objects and a topic descriptor for `Mid`, `Top` and `Keyed`) as in our
/// idlc, derive and dynamic types. Cyclone's Python binding differs here (its subclasses inherit `@nested`);
/// the two idlc-corpus types of this shape are listed in `idlc_golden.rs` for that reason.
#[test]
fn structs_deriving_from_nested_structs_are_not_nested() {
    use gen_nested::nb;
    let fx = cyclone_idlc::fixture("nested_base");
    let idl = include_str!("../idl/nested_base.idl");
    let types = types_from_idl("nested_base.idl", idl).expect("the IDL reads as dynamic types");
    for (name, info, map) in [
        (
            "NB::Mid",
            nb::Mid::type_information(),
            nb::Mid::type_mapping(),
        ),
        (
            "NB::Top",
            nb::Top::type_information(),
            nb::Top::type_mapping(),
        ),
        (
            "NB::Keyed",
            nb::Keyed::type_information(),
            nb::Keyed::type_mapping(),
        ),
    ] {
        let (info, map) = (info.expect("type information"), map.expect("type mapping"));
        cyclone_idlc::same_objects(name, info, map, &fx["types"][name]);
        let dynamic = types[name].type_support().expect("dynamic type support");
        assert_eq!(
            hex(&dynamic.mapping_bytes),
            hex(map),
            "{name}: dynamic TypeMapping"
        );
    }
}

/// Bitsets have no peer reference (Cyclone 11's idlc and Fast DDS 2.9's fastddsgen reject them), so this is
/// self-consistency: idlc's bitset (an integer newtype) and the dynamic type read from the same IDL (the
/// storage integer) have the same type objects and bytes in both versions, and IDL -> type -> IDL -> type is
/// a fixed point.
#[test]
fn bitsets_agree_between_the_derive_and_dynamic_types() {
    use dds_runtime::xtypes::dynamic::DynamicData;
    use gen_bitsets::bs;
    let idl = include_str!("../idl/no-peer/bitsets.idl");
    let types = types_from_idl("bitsets.idl", idl).expect("the IDL reads as dynamic types");
    let h = bs::Holder {
        id: 7,
        s: bs::Small(0x55),
        m: bs::Mid(0x0abc),
        w: bs::Wide(0x00ab_cdef_1234),
        ms: vec![bs::Mid(1), bs::Mid(0x0fff)],
    };
    let m = bs::MHolder {
        m: bs::Mid(0x0123),
        w: Some(bs::Wide(0x00ff_0000_00ff)),
    };
    fn check<T: DdsType + std::fmt::Debug + PartialEq>(
        name: &str,
        v: &T,
        types: &std::collections::BTreeMap<String, dds_runtime::xtypes::dynamic::DynamicType>,
    ) {
        let ty = &types[name];
        let s = ty.type_support().expect("dynamic type support");
        assert_eq!(
            Some(s.information_bytes.as_slice()),
            T::type_information(),
            "{name}"
        );
        assert_eq!(
            Some(s.mapping_bytes.as_slice()),
            T::type_mapping(),
            "{name}"
        );
        for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
            for order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
                let mut ours = Vec::new();
                cdr::serialize(v, version, order, &mut ours).expect("encodes");
                let d = DynamicData::deserialize(ty, &ours).expect("decodes dynamically");
                let mut again = Vec::new();
                d.serialize(version, order, &mut again).expect("re-encodes");
                assert_eq!(hex(&again), hex(&ours), "{name} {version:?} {order:?}");
                assert_eq!(&cdr::deserialize::<T>(&again).expect("decodes"), v);
            }
        }
        let text = ty.to_idl();
        let back = types_from_idl("again.idl", &text).expect("to_idl reads back");
        assert_eq!(&back[name], ty, "{name}: IDL -> type -> IDL -> type");
        assert_eq!(back[name].to_idl(), text, "{name}: to_idl is a fixed point");
    }
    check("BS::Holder", &h, &types);
    check("BS::MHolder", &m, &types);
}
