//! Dynamic types and data (`dds_runtime::xtypes::dynamic`) on peer input: what `dds subscribe` and the
//! durability service do with a discovered type and a peer's payloads.
//!
//! The first input byte picks the type:
//! - below [`crate::cdr::TYPE_COUNT`] - 1: one of the `cdr_decode` types, made dynamic from its own type
//!   objects; the rest of the input is a payload, decoded both dynamically and by the derived code. When both
//!   decode, they must re-encode to identical bytes in every version and byte order, or to bytes the derived
//!   code reads as the same value (a differential check of the two decoders; see FINDINGS.md, 2026-11-27).
//! - `0xf0` and `0xf1`: the recursive types [`RecNode`] (a sequence of itself) and [`RecChain`] (an optional
//!   member of itself), made dynamic from their strongly connected component objects, decoded both ways as
//!   above: nesting ends at the depth limit with an error in both decoders.
//! - otherwise: the type comes from the input too (`u16` length and TypeInformation bytes, `u16` length and
//!   TypeMapping bytes, then the payload), as a hostile peer would announce it.
//!
//! Whatever decodes must re-encode, decode again to an equal value and re-encode to the same bytes; its JSON
//! form must convert back to an equal value; the key paths must not panic.

use std::sync::OnceLock;

use dds_runtime::cdr::{self, ByteOrder, DdsType, EncapsulationHeader, XcdrVersion};
use dds_runtime::xtypes::dynamic::{DynamicData, DynamicType};
use dds_runtime::xtypes::typeobject::{from_bytes, TypeInformation, TypeMapping};
use dds_runtime::xtypes::XTypesType;
use dds_runtime::DdsType;

use crate::cdr::{Either, MutOpt, Nest, Outer, ShapeType};

/// `@final struct Node { long value; sequence<Node> children; };`
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "Rec::Node", final)]
pub struct RecNode {
    value: i32,
    #[dds(recursive)]
    children: Vec<RecNode>,
}

/// `@mutable struct Chain { long v; @optional Chain next; };`
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "Rec::Chain", mutable)]
pub struct RecChain {
    v: i32,
    #[dds(recursive)]
    next: Option<Box<RecChain>>,
}

/// Every version and byte order a value is re-encoded in.
const ENCODINGS: [(XcdrVersion, ByteOrder); 4] = [
    (XcdrVersion::Xcdr1, ByteOrder::LittleEndian),
    (XcdrVersion::Xcdr1, ByteOrder::BigEndian),
    (XcdrVersion::Xcdr2, ByteOrder::LittleEndian),
    (XcdrVersion::Xcdr2, ByteOrder::BigEndian),
];

/// The dynamic type of a derived type, from the type objects it announces.
pub(crate) fn dynamic_of<T: XTypesType>() -> DynamicType {
    let s = T::type_support().expect("describable");
    let info: TypeInformation = from_bytes(&s.information_bytes).expect("own information");
    let mapping: TypeMapping = from_bytes(&s.mapping_bytes).expect("own mapping");
    DynamicType::from_type_mapping(&info, &mapping).expect("own types are dynamic types")
}

fn known_types() -> &'static [DynamicType; 7] {
    static TYPES: OnceLock<[DynamicType; 7]> = OnceLock::new();
    TYPES.get_or_init(|| {
        [
            dynamic_of::<ShapeType>(),
            dynamic_of::<MutOpt>(),
            dynamic_of::<Nest>(),
            dynamic_of::<Outer>(),
            dynamic_of::<Either>(),
            dynamic_of::<RecNode>(),
            dynamic_of::<RecChain>(),
        ]
    })
}

/// Decodes `payload` dynamically and as `T`; where both succeed the encodings must agree.
fn differential<T: DdsType>(ty: &DynamicType, payload: &[u8]) {
    let dynamic = DynamicData::deserialize(ty, payload);
    if let (Ok(d), Ok(v)) = (&dynamic, cdr::deserialize::<T>(payload)) {
        for (ver, order) in ENCODINGS {
            let (mut a, mut b) = (Vec::new(), Vec::new());
            let da = d.serialize(ver, order, &mut a);
            let db = cdr::serialize(&v, ver, order, &mut b);
            assert_eq!(
                da.is_ok(),
                db.is_ok(),
                "one encoder refused ({ver:?} {order:?})"
            );
            if a != b {
                // The derived type cannot hold every wire value the dynamic one keeps: a union in its
                // default case re-encodes the default label, not the discriminator that arrived. Read
                // through the derived code, the dynamic encoding must give the same bytes.
                let canonical = cdr::deserialize::<T>(&a)
                    .unwrap_or_else(|e| panic!("dynamic encoding not derived-decodable: {e}"));
                let mut c = Vec::new();
                cdr::serialize(&canonical, ver, order, &mut c).expect("re-encodes");
                assert_eq!(
                    c, b,
                    "dynamic and derived values differ ({ver:?} {order:?})"
                );
            }
        }
    }
    if let Ok(d) = dynamic {
        exercise(ty, &d, payload);
    }
}

/// The round trips every decoded sample must survive.
fn exercise(ty: &DynamicType, d: &DynamicData, payload: &[u8]) {
    for (ver, order) in ENCODINGS {
        let mut out = Vec::new();
        if d.serialize(ver, order, &mut out).is_err() {
            // Values a version cannot carry (e.g. XCDR1 limits) are refused, not mangled.
            continue;
        }
        let back = DynamicData::deserialize(ty, &out)
            .unwrap_or_else(|e| panic!("own encoding does not decode ({ver:?} {order:?}): {e}"));
        let mut again = Vec::new();
        back.serialize(ver, order, &mut again)
            .expect("a decoded re-encoding encodes");
        assert_eq!(out, again, "encoding not stable through {ver:?} {order:?}");
    }
    let json = d.to_json();
    if let Ok(from) = DynamicData::from_json(ty, &json) {
        let (mut a, mut b) = (Vec::new(), Vec::new());
        if d.serialize(XcdrVersion::Xcdr2, ByteOrder::LittleEndian, &mut a)
            .is_ok()
        {
            from.serialize(XcdrVersion::Xcdr2, ByteOrder::LittleEndian, &mut b)
                .expect("JSON round trip encodes");
            assert_eq!(a, b, "value changed through JSON: {json}");
        }
    }
    let version = EncapsulationHeader::parse(payload)
        .ok()
        .and_then(|h| h.version().ok())
        .unwrap_or(XcdrVersion::Xcdr2);
    let _ = d.key_hash(version);
    let mut k = Vec::new();
    if d.serialize_key(version, ByteOrder::LittleEndian, &mut k)
        .is_ok()
    {
        let _ = DynamicData::deserialize_key(ty, &k);
    }
    let mut ik = Vec::new();
    let _ = d.instance_key(&mut ik);
}

/// Splits a `u16`-length-prefixed part off the front of `data`.
fn part(data: &[u8]) -> Option<(&[u8], &[u8])> {
    let (len, rest) = data.split_first_chunk::<2>()?;
    let n = usize::from(u16::from_le_bytes(*len));
    (rest.len() >= n).then(|| rest.split_at(n))
}

/// A type a peer announces: TypeInformation and TypeMapping bytes, then the payload.
fn announced(data: &[u8]) {
    let Some((info, rest)) = part(data) else {
        return;
    };
    let Some((mapping, payload)) = part(rest) else {
        return;
    };
    let (Ok(info), Ok(mapping)) = (
        from_bytes::<TypeInformation>(info),
        from_bytes::<TypeMapping>(mapping),
    ) else {
        return;
    };
    let Ok(ty) = DynamicType::from_type_mapping(&info, &mapping) else {
        return;
    };
    let _ = ty.to_idl();
    let _ = ty.type_support();
    if let Ok(d) = DynamicData::deserialize(&ty, payload) {
        exercise(&ty, &d, payload);
    }
    let _ = DynamicData::deserialize_key(&ty, payload);
}

/// Runs one fuzz input (see the module documentation).
pub fn dynamic_one(data: &[u8]) {
    let Some((&sel, rest)) = data.split_first() else {
        return;
    };
    let types = known_types();
    match sel {
        0xf0 => return differential::<RecNode>(&types[5], rest),
        0xf1 => return differential::<RecChain>(&types[6], rest),
        _ => {}
    }
    match sel % 6 {
        0 => differential::<ShapeType>(&types[0], rest),
        1 => differential::<MutOpt>(&types[1], rest),
        2 => differential::<Nest>(&types[2], rest),
        3 => differential::<Outer>(&types[3], rest),
        4 => differential::<Either>(&types[4], rest),
        _ => announced(rest),
    }
}
