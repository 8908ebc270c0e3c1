//! The first type object in which two TypeMappings differ, for golden-test failure messages (shared by
//! `xtypes_golden.rs` and `idlc_golden.rs`).

fn unhex(s: &str) -> Vec<u8> {
    (0..s.len() / 2)
        .map(|i| u8::from_str_radix(&s[2 * i..2 * i + 2], 16).expect("hex digit"))
        .collect()
}

/// The first type object that differs between our mapping and Cyclone's, both decoded.
pub fn explain(ours: &[u8], theirs: &str) -> String {
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
