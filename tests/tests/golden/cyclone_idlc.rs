//! Type objects against Cyclone DDS 11's idlc (`fixtures/cyclone-idlc/<stem>.json` for `tests/idl/<stem>.idl`,
//! from `scripts/golden/idlc_typeinfo.py`).

use std::collections::BTreeSet;
use std::path::PathBuf;

use dds_runtime::xtypes::typeobject::{from_bytes, TypeInformation, TypeMapping};

/// The fixture of `tests/idl/<stem>.idl`: `["types"]["Scoped::Name"]` holds each type's bytes.
pub fn fixture(stem: &str) -> serde_json::Value {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/cyclone-idlc")
        .join(format!("{stem}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).expect("json")
}

/// The items of a list as a set (Cyclone's idlc orders dependencies and mapping pairs its own way, and its
/// complete list drops repeats; the binding, whose order the builder follows, keeps them).
fn set<T: std::fmt::Debug>(items: &[T]) -> BTreeSet<String> {
    items.iter().map(|i| format!("{i:?}")).collect()
}

fn unhex(want: &serde_json::Value, key: &str) -> Vec<u8> {
    let s = want[key].as_str().expect("fixture");
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex"))
        .collect()
}

/// Our TypeInformation and TypeMapping bytes say what Cyclone idlc's (`want`) say: the same topic type
/// identifiers and sizes, dependencies, identifier → object pairs and complete → minimal pairs.
pub fn same_objects(name: &str, info: &[u8], map: &[u8], want: &serde_json::Value) {
    let ours: TypeInformation = from_bytes(info).expect("ours decodes");
    let theirs: TypeInformation =
        from_bytes(&unhex(want, "type_information")).expect("theirs decodes");
    for (o, t) in [
        (&ours.minimal, &theirs.minimal),
        (&ours.complete, &theirs.complete),
    ] {
        assert_eq!(o.typeid_with_size, t.typeid_with_size, "{name}: topic type");
        assert_eq!(
            set(&o.dependent_typeids),
            set(&t.dependent_typeids),
            "{name}: dependencies"
        );
    }
    let ours: TypeMapping = from_bytes(map).expect("ours decodes");
    let theirs: TypeMapping = from_bytes(&unhex(want, "type_mapping")).expect("theirs decodes");
    assert_eq!(
        set(&ours.identifier_object_pair_minimal),
        set(&theirs.identifier_object_pair_minimal),
        "{name}: minimal objects"
    );
    assert_eq!(
        set(&ours.identifier_object_pair_complete),
        set(&theirs.identifier_object_pair_complete),
        "{name}: complete objects"
    );
    assert_eq!(
        set(&ours.identifier_complete_minimal),
        set(&theirs.identifier_complete_minimal),
        "{name}: complete to minimal"
    );
}
