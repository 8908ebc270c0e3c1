//! Property: decode(encode(x)) == x for every type family, in XCDR1 and XCDR2, little and big endian; the
//! key-only encoding keeps the key; key hashes depend only on the key.

mod cdr_families;

use cdr_families::*;
use dds_runtime::cdr::{
    deserialize, deserialize_into, deserialize_key, instance_key, key_hash, serialize,
    serialize_key, ByteOrder, DdsType, XcdrVersion,
};
use proptest::prelude::*;

const VERSIONS: [XcdrVersion; 2] = [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2];
const ORDERS: [ByteOrder; 2] = [ByteOrder::LittleEndian, ByteOrder::BigEndian];

fn all_encodings<T: DdsType + PartialEq + std::fmt::Debug>(v: &T) -> Result<(), TestCaseError> {
    let mut out = Vec::new();
    // Decoded over the type's default first, then over the previous decoding (buffers reused).
    let mut reused = T::default_value();
    for version in VERSIONS {
        for order in ORDERS {
            out.clear();
            serialize(v, version, order, &mut out)
                .map_err(|e| TestCaseError::fail(e.to_string()))?;
            prop_assert_eq!(out.len() % 4, 0);
            let back = deserialize::<T>(&out)
                .map_err(|e| TestCaseError::fail(format!("{version:?} {order:?}: {e}")))?;
            prop_assert_eq!(&back, v, "{:?} {:?}", version, order);
            // Decoding in place over whatever the sample held before gives the same value.
            deserialize_into(&out, &mut reused)
                .map_err(|e| TestCaseError::fail(format!("into, {version:?} {order:?}: {e}")))?;
            prop_assert_eq!(&reused, v, "into, {:?} {:?}", version, order);
        }
    }
    Ok(())
}

macro_rules! key_props {
    ($v:expr, $t:ty) => {{
        let v = $v;
        for version in VERSIONS {
            for order in ORDERS {
                let mut k = Vec::new();
                serialize_key(&v, version, order, &mut k).unwrap();
                let back: $t = deserialize_key(&k).unwrap();
                prop_assert_eq!(back.id, v.id);
                // Non-key members are defaulted.
                prop_assert_eq!(back.s.as_str(), "");
            }
            // Same key, other members changed: same hash and instance key.
            let mut w = v.clone();
            w.s.push('x');
            w.o = w.o.wrapping_add(1);
            prop_assert_eq!(
                key_hash(&v, version).unwrap(),
                key_hash(&w, version).unwrap()
            );
            let (mut a, mut b) = (Vec::new(), Vec::new());
            instance_key(&v, &mut a).unwrap();
            instance_key(&w, &mut b).unwrap();
            prop_assert_eq!(a, b);
            // A u32 key fits 16 bytes: the hash is the big-endian key, zero-padded, whatever the
            // extensibility (the hashed stream has no headers).
            let h = key_hash(&v, version).unwrap();
            prop_assert_eq!(&h[..4], &v.id.to_be_bytes()[..]);
            prop_assert!(h[4..].iter().all(|&b| b == 0));
        }
    }};
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn final_family_round_trips(v in fam_final()) {
        all_encodings(&v)?;
        key_props!(v, FamFinal);
    }

    #[test]
    fn appendable_family_round_trips(v in fam_appendable()) {
        all_encodings(&v)?;
        key_props!(v, FamAppendable);
    }

    #[test]
    fn mutable_family_round_trips(v in fam_mutable()) {
        all_encodings(&v)?;
    }

    #[test]
    fn primitive_sequences_round_trip(
        a in proptest::collection::vec(any::<u64>(), 0..50),
        b in proptest::collection::vec(any::<i16>(), 0..50),
        c in proptest::collection::vec(any::<u8>(), 0..50),
        d in proptest::collection::vec(any::<f32>().prop_filter("finite", |v| v.is_finite()), 0..50),
    ) {
        all_encodings(&Seqs { a, b, c, d })?;
    }
}

#[derive(dds_runtime::DdsType, Debug, PartialEq)]
#[dds(final)]
struct Seqs {
    a: Vec<u64>,
    b: Vec<i16>,
    c: Vec<u8>,
    d: Vec<f32>,
}

#[derive(dds_runtime::DdsType, Debug, PartialEq, Clone)]
#[dds(mutable)]
struct Base {
    #[dds(key)]
    id: u16,
    name: String,
}

#[derive(dds_runtime::DdsType, Debug, PartialEq, Clone)]
#[dds(mutable)]
struct Derived {
    #[dds(base)]
    base: Base,
    extra: Option<Vec<i8>>,
    #[dds(id = 40)]
    late: u64,
}

#[derive(dds_runtime::DdsType, Debug, PartialEq, Clone)]
#[dds(appendable)]
struct Tree {
    label: u8,
    kids: Vec<Tree>,
    #[dds(external)]
    link: Option<Box<Tree>>,
}

fn tree() -> impl Strategy<Value = Tree> {
    let leaf = any::<u8>().prop_map(|label| Tree {
        label,
        kids: vec![],
        link: None,
    });
    leaf.prop_recursive(4, 24, 3, |inner| {
        (
            any::<u8>(),
            proptest::collection::vec(inner.clone(), 0..3),
            proptest::option::of(inner),
        )
            .prop_map(|(label, kids, link)| Tree {
                label,
                kids,
                link: link.map(Box::new),
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn inheritance_and_recursion_round_trip(
        id in any::<u16>(),
        name in "[a-z]{0,6}",
        extra in proptest::option::of(proptest::collection::vec(any::<i8>(), 0..4)),
        late in any::<u64>(),
        t in tree(),
    ) {
        let d = Derived { base: Base { id, name }, extra, late };
        all_encodings(&d)?;
        all_encodings(&t)?;
        let mut k = Vec::new();
        serialize_key(&d, XcdrVersion::Xcdr2, ByteOrder::BigEndian, &mut k).unwrap();
        let back: Derived = deserialize_key(&k).unwrap();
        prop_assert_eq!(back.base.id, id);
        let h = key_hash(&d, XcdrVersion::Xcdr2).unwrap();
        prop_assert_eq!(&h[..2], &id.to_be_bytes()[..]);
    }
}
