//! The XTypes type-system codec against Cyclone's bytes (tests/fixtures/typeinfo, from the Python binding of
//! Cyclone DDS 11.0.1): every TypeInformation and TypeMapping decodes, re-encodes to the same bytes, and every
//! type object in a mapping hashes to the identifier it is paired with. Truncated and corrupted input is an
//! error, never a panic.

use std::path::PathBuf;

use dds_runtime::xtypes::typeobject::{
    equivalence_hash, from_bytes, to_bytes, TypeIdentifier, TypeInformation, TypeMapping,
};
use serde_json::Value;

fn fixtures() -> Vec<(String, Value)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/typeinfo");
    let mut v: Vec<_> = std::fs::read_dir(&dir)
        .expect("tests/fixtures/typeinfo")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("read");
            (
                p.file_stem().unwrap().to_string_lossy().into_owned(),
                serde_json::from_str(&text).expect("json"),
            )
        })
        .collect();
    v.sort_by(|a, b| a.0.cmp(&b.0));
    v
}

pub fn unhex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex"))
        .collect()
}

#[test]
fn cyclone_type_information_and_mapping_round_trip() {
    let all = fixtures();
    assert!(all.len() >= 100, "only {} fixtures", all.len());
    let mut failures = Vec::new();
    for (name, doc) in &all {
        let info_bytes = unhex(doc["type_information"].as_str().unwrap());
        let map_bytes = unhex(doc["type_mapping"].as_str().unwrap());
        let info: TypeInformation = match from_bytes(&info_bytes) {
            Ok(i) => i,
            Err(e) => {
                failures.push(format!("{name}: TypeInformation: {e}"));
                continue;
            }
        };
        let map: TypeMapping = match from_bytes(&map_bytes) {
            Ok(m) => m,
            Err(e) => {
                failures.push(format!("{name}: TypeMapping: {e}"));
                continue;
            }
        };
        if to_bytes(&info).unwrap() != info_bytes {
            failures.push(format!("{name}: TypeInformation re-encodes differently"));
        }
        if to_bytes(&map).unwrap() != map_bytes {
            failures.push(format!("{name}: TypeMapping re-encodes differently"));
        }
        for p in map
            .identifier_object_pair_minimal
            .iter()
            .chain(&map.identifier_object_pair_complete)
        {
            let h = equivalence_hash(&to_bytes(&p.type_object).unwrap());
            match &p.type_identifier {
                TypeIdentifier::Minimal(x) | TypeIdentifier::Complete(x) if *x != h => {
                    failures.push(format!("{name}: an object does not hash to its identifier"))
                }
                _ => {}
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {}:\n{}",
        failures.len(),
        all.len(),
        failures.join("\n")
    );
}

#[test]
fn truncated_or_corrupted_input_is_an_error() {
    for (_, doc) in fixtures().iter().take(40) {
        let map = unhex(doc["type_mapping"].as_str().unwrap());
        let info = unhex(doc["type_information"].as_str().unwrap());
        for cut in (0..map.len()).step_by(7) {
            assert!(from_bytes::<TypeMapping>(&map[..cut]).is_err());
        }
        for cut in 0..info.len() {
            assert!(from_bytes::<TypeInformation>(&info[..cut]).is_err());
        }
        // Flip each byte: decoding may succeed or fail, but never panics or allocates without bound.
        for i in 0..map.len() {
            let mut m = map.clone();
            m[i] ^= 0xff;
            let _ = from_bytes::<TypeMapping>(&m);
        }
    }
}
