//! Our TypeInformation and TypeMapping bytes against Cyclone's, for every type of the CDR golden corpus
//! (`golden/types.rs`; fixtures in `tests/fixtures/typeinfo`, written by `scripts/gen-golden` from Cyclone DDS
//! 11.0.1's Python binding, never from our encoder).
//!
//! Each type is one test. A type listed in [`KNOWN`] must differ (the reason is given there, and the test fails
//! if it starts to agree, so the list stays true); every other type must be byte-identical.

#[path = "golden/types.rs"]
#[allow(dead_code)]
mod types;

#[path = "golden/explain.rs"]
mod explain;

use explain::explain;

use std::path::PathBuf;

use dds_runtime::cdr::DdsType;
use dds_runtime::xtypes::dynamic::DynamicType;
use dds_runtime::xtypes::XTypesType;

/// Types whose Rust mirror cannot say what the Python type says, so the bytes differ for a stated reason.
const KNOWN: &[(&str, &str)] = &[];

fn fixture(name: &str) -> serde_json::Value {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("fixtures/typeinfo/{name}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).expect("json")
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// The derived type's objects -> a dynamic type -> its objects: the same bytes.
fn round_trip(name: &str, support: &dds_runtime::xtypes::TypeSupport) {
    let ty = DynamicType::from_type_mapping(&support.information, &support.mapping)
        .unwrap_or_else(|e| panic!("{name}: no dynamic type: {e}"));
    let rebuilt = ty
        .type_support()
        .unwrap_or_else(|e| panic!("{name}: no type support for the dynamic type: {e}"));
    assert_eq!(
        hex(&rebuilt.information_bytes),
        hex(&support.information_bytes),
        "{name}: TypeInformation of the dynamic type"
    );
    assert_eq!(
        hex(&rebuilt.mapping_bytes),
        hex(&support.mapping_bytes),
        "{name}: TypeMapping of the dynamic type"
    );
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
    round_trip(name, support);
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
