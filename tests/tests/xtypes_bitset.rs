//! `TK_BITSET` type objects (`CompleteBitsetType`, `MinimalBitsetType`): decoded and encoded by our type-object
//! codec exactly as Cyclone DDS 11.0.1's Python binding serializes them with its own type-object IDL
//! (`tests/fixtures/typeobject-bitset`, written by `scripts/golden/bitset_typeobject.py`). No peer makes such
//! objects from IDL (Cyclone's idlc rejects `bitset`, fastddsgen 2.3.0 fails on it), so the objects are written
//! by hand there and only the codec's layout has a peer reference. Hostile input: truncations, byte flips and
//! impossible bit fields are errors, never panics.

use std::path::PathBuf;

use dds_runtime::xtypes::typeobject::{
    from_bytes, kind, name_hash, to_bytes, MemberName, TypeBody, TypeObject,
};

fn fixture() -> serde_json::Value {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/typeobject-bitset/bitsets.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).expect("json")
}

fn unhex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

fn body(o: &TypeObject) -> &TypeBody {
    match o {
        TypeObject::Minimal(m) => &m.0,
        TypeObject::Complete(c) => &c.0,
    }
}

#[test]
fn the_bindings_bitset_objects_decode_and_encode_to_the_same_bytes() {
    let fx = fixture();
    let want: Vec<(u16, &str, u8, u8)> = fx["fields"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f[0].as_u64().unwrap() as u16,
                f[1].as_str().unwrap(),
                f[2].as_u64().unwrap() as u8,
                f[3].as_u64().unwrap() as u8,
            )
        })
        .collect();
    for form in ["complete", "minimal"] {
        let bytes = unhex(fx[form].as_str().unwrap());
        let o: TypeObject = from_bytes(&bytes).unwrap_or_else(|e| panic!("{form}: {e}"));
        assert_eq!(body(&o).kind(), kind::TK_BITSET);
        let TypeBody::Bitset { fields, detail, .. } = body(&o) else {
            panic!("{form}: not a bitset")
        };
        assert_eq!(fields.len(), want.len());
        for (f, (pos, name, bits, holder)) in fields.iter().zip(&want) {
            assert_eq!(
                (f.position, f.bitcount, f.holder_type),
                (*pos, *bits, *holder)
            );
            match (&f.detail.name, form) {
                (MemberName::Name(n), "complete") => assert_eq!(n, name),
                (MemberName::Hash(h), "minimal") => assert_eq!(*h, name_hash(name)),
                (other, _) => panic!("{form}: {other:?}"),
            }
        }
        if form == "complete" {
            assert_eq!(detail.type_name, "Bits::Flags");
        }
        assert_eq!(to_bytes(&o).unwrap(), bytes, "{form}: re-encoded");
    }
}

#[test]
fn hostile_bitset_objects_are_errors() {
    let fx = fixture();
    for form in ["complete", "minimal"] {
        let bytes = unhex(fx[form].as_str().unwrap());
        for n in 0..bytes.len() {
            assert!(
                from_bytes::<TypeObject>(&bytes[..n]).is_err(),
                "{form}: cut at {n}"
            );
        }
        for i in 0..bytes.len() {
            for x in [0x01, 0x80, 0xff] {
                let mut b = bytes.clone();
                b[i] ^= x;
                let _ = from_bytes::<TypeObject>(&b);
            }
        }
    }
    // The minimal object's first field: position 0, flags 0, then bit count and holder. A bit count of 0, or
    // a field past bit 64, is refused.
    let bytes = unhex(fx["minimal"].as_str().unwrap());
    let count_at = bytes
        .windows(6)
        .position(|w| w == [0, 0, 0, 0, 1, 1])
        .expect("first field")
        + 4;
    for (count, ok) in [(0u8, false), (64, true), (65, false)] {
        let mut b = bytes.clone();
        b[count_at] = count;
        assert_eq!(
            from_bytes::<TypeObject>(&b).is_ok(),
            ok,
            "bit count {count}"
        );
    }
}
