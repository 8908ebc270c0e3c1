//! Our TypeInformation and TypeMapping bytes against Cyclone's, for every type of the CDR golden corpus
//! (`golden/types.rs`; fixtures in `tests/fixtures/typeinfo`, written by `scripts/gen-golden` from Cyclone DDS
//! 11.0.1's Python binding, never from our encoder).
//!
//! Each type is one test. A type listed in [`KNOWN`] must differ (the reason is given there, and the test fails
//! if it starts to agree, so the list stays true); every other type must be byte-identical.

#[path = "golden/types.rs"]
#[allow(dead_code)]
mod types;

use std::path::PathBuf;

use dds_runtime::cdr::DdsType;
use dds_runtime::xtypes::XTypesType;

/// Types whose Rust mirror cannot say what the Python type says, so the bytes differ for a stated reason.
const KNOWN: &[(&str, &str)] = &[
    ("Arrays", "octet and uint8 are both u8 in Rust, which is described as uint8 (TK_UINT8); the Python type has octet (TK_BYTE)"),
    ("ArraysMutable", "octet and uint8 are both u8 in Rust, which is described as uint8 (TK_UINT8); the Python type has octet (TK_BYTE)"),
    ("Enums", "the Rust mirror's enumerators are CamelCase (Red), the IDL names upper case (RED): complete objects differ"),
    ("EnumsMutable", "the Rust mirror's enumerators are CamelCase (Red), the IDL names upper case (RED): complete objects differ"),
    ("KeyAllPrims", "octet and uint8 are both u8 in Rust, which is described as uint8 (TK_UINT8); the Python type has octet (TK_BYTE)"),
    ("KeyEnum", "the Rust mirror's enumerators are CamelCase (Red), the IDL names upper case (RED): complete objects differ"),
    ("Large", "octet and uint8 are both u8 in Rust, which is described as uint8 (TK_UINT8); the Python type has octet (TK_BYTE)"),
    ("Primitives", "octet and uint8 are both u8 in Rust, which is described as uint8 (TK_UINT8); the Python type has octet (TK_BYTE)"),
    ("PrimitivesMutable", "octet and uint8 are both u8 in Rust, which is described as uint8 (TK_UINT8); the Python type has octet (TK_BYTE)"),
    ("Sequences", "octet and uint8 are both u8 in Rust, which is described as uint8 (TK_UINT8); the Python type has octet (TK_BYTE)"),
    ("Typedefs", "the Rust mirror writes typedefs as their aliased types: no alias type objects"),
    ("UnionAppendable", "the binding numbers union members from 0, libddsc's wire and the derive from 1; case names differ in case too"),
    ("UnionHolder", "the Rust mirror's enumerators are CamelCase (Red), the IDL names upper case (RED): complete objects differ"),
    ("UnionHolderAppendable", "the Rust mirror's enumerators are CamelCase (Red), the IDL names upper case (RED): complete objects differ"),
    ("UnionHolderMutable", "the Rust mirror's enumerators are CamelCase (Red), the IDL names upper case (RED): complete objects differ"),
    ("UnionLongLast", "the binding numbers union members from 0, libddsc's wire and the derive from 1; case names differ in case too"),
];

fn fixture(name: &str) -> serde_json::Value {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("fixtures/typeinfo/{name}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).expect("json")
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// Called by every test of `golden/types.rs` (which names it `check`); the samples are not used here.
pub fn check<T: DdsType + XTypesType>(name: &str, _samples: Vec<(&str, T)>) {
    let fx = fixture(name);
    let support = T::type_support().unwrap_or_else(|| panic!("{name}: no type support"));
    let info = hex(&support.information_bytes);
    let map = hex(&support.mapping_bytes);
    let same = info == fx["type_information"].as_str().unwrap()
        && map == fx["type_mapping"].as_str().unwrap();
    assert_eq!(
        T::type_information(),
        Some(support.information_bytes.as_slice())
    );
    if std::env::var_os("XTYPES_GOLDEN_REPORT").is_some() {
        println!("XTYPES {} {name}", if same { "SAME" } else { "DIFF" });
        if !same {
            println!(
                "{}",
                explain(&support.mapping_bytes, fx["type_mapping"].as_str().unwrap())
            );
        }
        return;
    }
    match KNOWN.iter().find(|(n, _)| *n == name) {
        Some((_, why)) => assert!(
            !same,
            "{name} is listed as differing ({why}) but now agrees: drop it from KNOWN"
        ),
        None => {
            assert!(
                same,
                "{name}: {}",
                explain(&support.mapping_bytes, fx["type_mapping"].as_str().unwrap())
            );
            assert_eq!(
                info,
                fx["type_information"].as_str().unwrap(),
                "{name}: TypeInformation"
            );
            assert_eq!(
                map,
                fx["type_mapping"].as_str().unwrap(),
                "{name}: TypeMapping"
            );
        }
    }
}

fn unhex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex"))
        .collect()
}

/// The first type object that differs between our mapping and Cyclone's, both decoded.
fn explain(ours: &[u8], theirs: &str) -> String {
    use dds_runtime::xtypes::typeobject::{from_bytes, TypeMapping};
    let a: TypeMapping = from_bytes(ours).expect("our mapping decodes");
    let b: TypeMapping = from_bytes(&unhex(theirs)).expect("Cyclone's mapping decodes");
    let pairs = |m: &TypeMapping| {
        m.identifier_object_pair_minimal
            .iter()
            .chain(&m.identifier_object_pair_complete)
            .cloned()
            .collect::<Vec<_>>()
    };
    let (pa, pb) = (pairs(&a), pairs(&b));
    for (x, y) in pa.iter().zip(&pb).rev() {
        if x.type_object != y.type_object {
            return format!("\nours:   {:?}\ntheirs: {:?}", x.type_object, y.type_object);
        }
    }
    format!(
        "{} vs {} objects; same objects, order or identifiers differ\nours:   {:?}\ntheirs: {:?}",
        pa.len(),
        pb.len(),
        pa.iter().map(|p| &p.type_identifier).collect::<Vec<_>>(),
        pb.iter().map(|p| &p.type_identifier).collect::<Vec<_>>()
    )
}
