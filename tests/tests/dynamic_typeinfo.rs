//! Type objects built from dynamic types, against Cyclone DDS 11's bytes.
//!
//! Every fixture of `tests/fixtures/typeinfo/` (the TypeInformation and TypeMapping Cyclone 11.0.1's Python
//! binding computes, for the 67 types of the CDR golden corpus and the 47 of the idlc golden corpus) is
//! decoded into a `DynamicType` (`DynamicType::from_type_mapping`); `DynamicType::type_support` must then
//! give Cyclone's TypeInformation and TypeMapping bytes back, byte for byte; and so must the type its IDL
//! (`DynamicType::to_idl`, what `dds typeof` prints) compiles back to (`types_from_idl`). The idlc corpus's own
//! IDL files are checked in `dynamic_idl.rs`, and derived types round-trip through dynamic types in
//! `xtypes_golden.rs` and `idlc_golden.rs`.

#[path = "golden/cyclone_idlc.rs"]
mod cyclone_idlc;

use std::path::PathBuf;

use dds_runtime::xtypes::dynamic::{types_from_idl, DynamicType};
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

/// The dynamic type of a fixture: from Cyclone's objects, or (`through_idl`) from their IDL text.
fn dynamic_type(fx: &Json, through_idl: bool) -> Result<DynamicType, String> {
    let info: TypeInformation =
        from_bytes(&unhex(fx["type_information"].as_str().unwrap_or_default()))
            .map_err(|e| format!("TypeInformation does not decode: {e}"))?;
    let map: TypeMapping = from_bytes(&unhex(fx["type_mapping"].as_str().unwrap_or_default()))
        .map_err(|e| format!("TypeMapping does not decode: {e}"))?;
    let ty =
        DynamicType::from_type_mapping(&info, &map).map_err(|e| format!("no dynamic type: {e}"))?;
    if !through_idl {
        return Ok(ty);
    }
    let idl = ty.to_idl();
    types_from_idl("typeof.idl", &idl)
        .map_err(|e| format!("{e}\n{idl}"))?
        .remove(&ty.name())
        .ok_or_else(|| format!("no {} in\n{idl}", ty.name()))
}

/// The differences between what the dynamic type of a fixture builds and Cyclone's bytes (empty: identical).
fn differences(fx: &Json, through_idl: bool) -> Vec<String> {
    let info_hex = fx["type_information"].as_str().unwrap_or_default();
    let map_hex = fx["type_mapping"].as_str().unwrap_or_default();
    let ty = match dynamic_type(fx, through_idl) {
        Ok(t) => t,
        Err(e) => return vec![e],
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

/// Every fixture: its name and the differences.
fn run(through_idl: bool) -> Vec<(String, Vec<String>)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/typeinfo");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("fixtures")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 114, "the typeinfo corpus has 114 types");
    files
        .iter()
        .map(|f| {
            let fx: Json =
                serde_json::from_str(&std::fs::read_to_string(f).expect("fixture")).expect("JSON");
            let name = f.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
            (name.to_string(), differences(&fx, through_idl))
        })
        .collect()
}

#[test]
fn cyclone_type_objects_rebuild_to_cyclone_bytes() {
    let all = run(false);
    let bad: Vec<String> = all
        .iter()
        .filter(|(_, d)| !d.is_empty())
        .map(|(n, d)| format!("{n}: {}", d.join("\n  ")))
        .collect();
    println!(
        "{} fixtures, {} identical",
        all.len(),
        all.len() - bad.len()
    );
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// Fixtures whose IDL text cannot say everything their objects say.
const KNOWN_IDL: &[(&str, &str)] = &[(
    "SeqOfArrays",
    "IDL cannot spell a sequence of anonymous arrays (`sequence<long[2]>`): `to_idl` writes a typedef, whose \
     alias object the original type does not have",
)];

#[test]
fn cyclone_types_through_their_idl_rebuild_to_cyclone_bytes() {
    let all = run(true);
    let mut bad = Vec::new();
    for (name, d) in &all {
        match (KNOWN_IDL.iter().find(|(n, _)| n == name), d.is_empty()) {
            (None, true) | (Some(_), false) => {}
            (None, false) => bad.push(format!("{name}: {}", d.join("\n  "))),
            (Some((_, why)), true) => bad.push(format!("{name}: listed ({why}) but agrees")),
        }
    }
    let same = all.iter().filter(|(_, d)| d.is_empty()).count();
    println!("{} fixtures through IDL text, {same} identical", all.len());
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// `to_idl` of a sequence of anonymous arrays (Cyclone's `SeqOfArrays`, from its objects) writes a typedef
/// for the array, which IDL needs (`tests/idl/seq_of_arrays.idl` is that text); Cyclone 11's idlc gives that
/// IDL the type objects we give it. From there IDL -> type -> IDL -> type is a fixed point: the same text,
/// equal types and the same type objects.
#[test]
fn a_sequence_of_anonymous_arrays_gets_a_typedef_in_idl() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/typeinfo/SeqOfArrays.json");
    let fx: Json =
        serde_json::from_str(&std::fs::read_to_string(path).expect("fixture")).expect("JSON");
    let original = dynamic_type(&fx, false).expect("dynamic type");
    let idl = original.to_idl();
    assert!(idl.contains("typedef long long_array_2[2];"), "{idl}");
    assert!(idl.contains("sequence<long_array_2> rows;"), "{idl}");
    assert_eq!(idl, include_str!("../idl/seq_of_arrays.idl"));
    let name = original.name();
    let first = types_from_idl("first.idl", &idl)
        .expect("valid IDL")
        .remove(&name)
        .expect("type");
    let again = first.to_idl();
    assert_eq!(again, idl);
    let second = types_from_idl("second.idl", &again)
        .expect("valid IDL")
        .remove(&name)
        .expect("type");
    assert_eq!(first, second);
    let (a, b) = (
        first.type_support().expect("objects"),
        second.type_support().expect("objects"),
    );
    assert_eq!(a.mapping_bytes, b.mapping_bytes);
    assert_eq!(a.information_bytes, b.information_bytes);
    let fx = cyclone_idlc::fixture("seq_of_arrays");
    cyclone_idlc::same_objects(
        &name,
        &a.information_bytes,
        &a.mapping_bytes,
        &fx["types"][&name],
    );
}
