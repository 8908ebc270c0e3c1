//! Dynamic data without a network: the builder and accessors, JSON, and hostile bytes (errors, never panics).

use dds_runtime::cdr::{ByteOrder, Extensibility, XcdrVersion};
use dds_runtime::xtypes::dynamic::{
    DynamicData, DynamicError, DynamicType, EnumBuilder, MemberBuilder, Primitive, StructBuilder,
    UnionBuilder, Value,
};
use proptest::prelude::*;

/// A mutable struct with a base, an enum, a union, an optional member, nested sequences and a map.
fn sample_type() -> DynamicType {
    let long = DynamicType::primitive(Primitive::Int32);
    let color = EnumBuilder::new("M::Color")
        .literal("RED")
        .literal("GREEN")
        .literal("BLUE")
        .build()
        .unwrap();
    let base = StructBuilder::new("M::Base")
        .extensibility(Extensibility::Mutable)
        .with(MemberBuilder::new("id", long.clone()).key())
        .build()
        .unwrap();
    let u = UnionBuilder::new("M::U", long.clone())
        .case("num", DynamicType::primitive(Primitive::Float64), vec![1])
        .case("text", DynamicType::string(Some(8)), vec![2])
        .default_case("other", color.clone(), vec![])
        .build()
        .unwrap();
    StructBuilder::new("M::All")
        .extensibility(Extensibility::Mutable)
        .base(base)
        .member("color", color)
        .member("u", u)
        .with(MemberBuilder::new("maybe", DynamicType::string(None)).optional())
        .member(
            "grid",
            DynamicType::sequence(DynamicType::sequence(long.clone(), None), Some(4)),
        )
        .member(
            "tags",
            DynamicType::map(DynamicType::string(None), long.clone(), None),
        )
        .member("pair", DynamicType::array(long, vec![2]).unwrap())
        .build()
        .unwrap()
}

fn sample() -> DynamicData {
    let json = serde_json::json!({
        "id": 7, "color": "BLUE", "u": {"discriminator": 2, "text": "hi"}, "maybe": "yes",
        "grid": [[1, 2], [], [3]], "tags": {"a": 1, "b": 2}, "pair": [5, 6]
    });
    DynamicData::from_json(&sample_type(), &json).unwrap()
}

#[test]
fn members_by_name_and_id_and_union_cases() {
    let mut d = sample();
    assert_eq!(d.get("id"), Some(&Value::Int32(7)));
    assert_eq!(
        d.get_by_id(0),
        Some(&Value::Int32(7)),
        "the base's member is id 0"
    );
    assert_eq!(
        d.get_by_id(1),
        d.get("color"),
        "ids continue after the base"
    );
    d.set_by_id(0, Value::Int32(8)).unwrap();
    assert_eq!(d.get("id"), Some(&Value::Int32(8)));
    assert!(matches!(
        d.set("id", Value::String("x".into())),
        Err(DynamicError::Mismatch { .. })
    ));
    assert!(matches!(
        d.set("nope", Value::Int32(1)),
        Err(DynamicError::NoMember(_))
    ));
    d.clear("maybe").unwrap();
    assert_eq!(d.get("maybe"), None);
    assert!(
        d.clear("id").is_err(),
        "a non-optional member cannot be absent"
    );
    let mut u = d.member("u").unwrap();
    assert_eq!(u.case(), Some(("text", &Value::String("hi".into()))));
    u.set_case("other", Value::Enum(0)).unwrap();
    assert_eq!(
        u.discriminator(),
        Some(-1),
        "a signed default discriminator: -1, -2, ... first unused"
    );
    assert!(
        u.set_case("text", Value::String("far too long".into()))
            .is_err(),
        "bound checked"
    );
}

#[test]
fn json_round_trip_and_both_encodings() {
    let d = sample();
    assert_eq!(
        DynamicData::from_json(d.dynamic_type(), &d.to_json()).unwrap(),
        d
    );
    for v in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
        for o in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
            let mut buf = Vec::new();
            d.serialize(v, o, &mut buf).unwrap();
            assert_eq!(
                DynamicData::deserialize(d.dynamic_type(), &buf).unwrap(),
                d,
                "{v:?} {o:?}"
            );
            let mut k = Vec::new();
            d.serialize_key(v, o, &mut k).unwrap();
            let key = DynamicData::deserialize_key(d.dynamic_type(), &k).unwrap();
            assert_eq!(key.get("id"), d.get("id"));
            assert_eq!(key.key_hash(v).unwrap(), d.key_hash(v).unwrap());
        }
    }
    assert!(DynamicData::from_json(d.dynamic_type(), &serde_json::json!({"bogus": 1})).is_err());
}

#[test]
fn every_truncation_is_an_error() {
    let d = sample();
    let mut buf = Vec::new();
    d.serialize(XcdrVersion::Xcdr2, ByteOrder::LittleEndian, &mut buf)
        .unwrap();
    let body_end = buf.len() - usize::from(buf[3] & 3);
    for n in 0..body_end {
        assert!(
            DynamicData::deserialize(d.dynamic_type(), &buf[..n]).is_err(),
            "truncated at {n}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]
    #[test]
    fn hostile_bytes_never_panic(body in proptest::collection::vec(any::<u8>(), 0..256), hdr in 0u8..12) {
        let ty = sample_type();
        let mut p = vec![0, hdr, 0, 0];
        p.extend_from_slice(&body);
        let _ = DynamicData::deserialize(&ty, &p);
        let _ = DynamicData::deserialize_key(&ty, &p);
    }

    #[test]
    fn flipped_bytes_never_panic(i in 0usize..200, x in any::<u8>()) {
        let d = sample();
        let mut buf = Vec::new();
        d.serialize(XcdrVersion::Xcdr2, ByteOrder::BigEndian, &mut buf).unwrap();
        let n = buf.len();
        buf[i % n] ^= x;
        let _ = DynamicData::deserialize(d.dynamic_type(), &buf);
    }
}
