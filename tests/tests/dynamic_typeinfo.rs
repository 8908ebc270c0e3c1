//! Type objects built from dynamic types, against Cyclone DDS 11's bytes.
//!
//! Every fixture of `tests/fixtures/typeinfo/` (the TypeInformation and TypeMapping Cyclone 11.0.1's Python
//! binding computes, for the 67 types of the CDR golden corpus and the 47 of the idlc golden corpus) is
//! decoded into a `DynamicType` (`DynamicType::from_type_mapping`); `DynamicType::type_support` must then
//! give Cyclone's TypeInformation and TypeMapping bytes back, byte for byte. The same types built from IDL text
//! are checked in `dynamic_idl.rs`, and derived types round-trip through dynamic types in `xtypes_golden.rs`.

use std::path::PathBuf;

use dds_runtime::xtypes::dynamic::DynamicType;
use dds_runtime::xtypes::typeobject::{from_bytes, TypeInformation, TypeMapping};
use serde_json::Value as Json;

fn unhex(s: &str) -> Vec<u8> {
    (0..s.len() / 2)
        .map(|i| u8::from_str_radix(&s[2 * i..2 * i + 2], 16).expect("hex"))
        .collect()
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// The differences between what the dynamic type of a fixture builds and Cyclone's bytes (empty: identical).
fn differences(fx: &Json) -> Vec<String> {
    let info_hex = fx["type_information"].as_str().unwrap_or_default();
    let map_hex = fx["type_mapping"].as_str().unwrap_or_default();
    let info: TypeInformation = match from_bytes(&unhex(info_hex)) {
        Ok(i) => i,
        Err(e) => return vec![format!("TypeInformation does not decode: {e}")],
    };
    let map: TypeMapping = match from_bytes(&unhex(map_hex)) {
        Ok(m) => m,
        Err(e) => return vec![format!("TypeMapping does not decode: {e}")],
    };
    let ty = match DynamicType::from_type_mapping(&info, &map) {
        Ok(t) => t,
        Err(e) => return vec![format!("no dynamic type: {e}")],
    };
    let support = match ty.type_support() {
        Ok(s) => s,
        Err(e) => return vec![format!("no type support: {e}")],
    };
    let mut out = Vec::new();
    if hex(&support.information_bytes) != info_hex {
        out.push(format!(
            "TypeInformation\n    want {info_hex}\n    got  {}",
            hex(&support.information_bytes)
        ));
    }
    if hex(&support.mapping_bytes) != map_hex {
        out.push(format!(
            "TypeMapping\n    want {map_hex}\n    got  {}",
            hex(&support.mapping_bytes)
        ));
    }
    out
}

#[test]
fn cyclone_type_objects_rebuild_to_cyclone_bytes() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/typeinfo");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("fixtures")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    let mut bad = Vec::new();
    for f in &files {
        let fx: Json =
            serde_json::from_str(&std::fs::read_to_string(f).expect("fixture")).expect("JSON");
        let name = f.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
        let d = differences(&fx);
        if !d.is_empty() {
            bad.push(format!("{name}: {}", d.join("\n  ")));
        }
    }
    println!(
        "{} fixtures, {} identical",
        files.len(),
        files.len() - bad.len()
    );
    assert_eq!(files.len(), 114, "the typeinfo corpus has 114 types");
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}
