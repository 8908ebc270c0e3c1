//! Compiles a selection of the real IDL corpus (`../shared/idl-corpus`, or `$DDS_IDL_CORPUS`) with idlc for
//! `tests/idlc_golden.rs`, which checks the generated types against libddsc's bytes
//! (`tests/fixtures/idlc-golden/`).
//!
//! The corpus lives outside the repository, so everything here is optional: without it nothing is generated and
//! the test prints that it skipped. A file idlc rejects does not break the build (the other test binaries of this
//! crate share this script): its diagnostics go to `$OUT_DIR/<stem>.idlc-error` and the test for its types fails
//! with them. Each accepted file gets `--cfg idlc_ok="<stem>"`.
use std::path::{Path, PathBuf};

/// (include root relative to the corpus, file relative to that root). Stems must be unique: idlc writes
/// `<stem>.rs`.
const FILES: &[(&str, &str)] = &[
    ("omg-dds-rtps/srcCxx", "shape.idl"),
    ("cyclonedds/src/tools/ddsperf", "ddsperf_types.idl"),
    ("eprosima-dds-types-test/IDL", "structures.idl"),
    ("eprosima-dds-types-test/IDL", "inheritance.idl"),
    ("eprosima-dds-types-test/IDL", "enumerations.idl"),
    ("eprosima-dds-types-test/IDL", "unions.idl"),
    ("eprosima-dds-types-test/IDL", "key.idl"),
    ("eprosima-dds-types-test/IDL", "mutable.idl"),
    ("eprosima-dds-types-test/IDL", "member_id.idl"),
    ("eprosima-dds-types-test/IDL", "optional.idl"),
    ("eprosima-dds-types-test/IDL", "arrays.idl"),
    ("eprosima-dds-types-test/IDL", "sequences.idl"),
    ("rti-ros-data-types", "geometry_msgs/msg/PoseStamped.idl"),
    ("rti-ros-data-types", "sensor_msgs/msg/Imu.idl"),
    (
        "rti-ros-data-types",
        "diagnostic_msgs/msg/DiagnosticStatus.idl",
    ),
];

fn corpus_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("DDS_IDL_CORPUS") {
        return PathBuf::from(dir);
    }
    let manifest = PathBuf::from(
        std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"),
    );
    // tests/ -> workspace root -> its sibling `shared/idl-corpus`
    manifest.join("../../shared/idl-corpus")
}

fn stem(file: &str) -> String {
    Path::new(file)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn main() {
    println!("cargo::rustc-check-cfg=cfg(idl_corpus)");
    let stems: Vec<String> = FILES
        .iter()
        .map(|(_, f)| format!("{:?}", stem(f)))
        .collect();
    println!(
        "cargo::rustc-check-cfg=cfg(idlc_ok, values({}))",
        stems.join(", ")
    );
    println!("cargo::rerun-if-env-changed=DDS_IDL_CORPUS");
    println!("cargo::rerun-if-changed=build.rs");

    let corpus = corpus_dir();
    println!("cargo::rerun-if-changed={}", corpus.display());
    if !corpus.is_dir() {
        println!(
            "cargo::warning=IDL corpus not found at {} (set DDS_IDL_CORPUS): idlc_golden will skip",
            corpus.display()
        );
        return;
    }
    println!("cargo::rustc-cfg=idl_corpus");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    for (root, file) in FILES {
        let root = corpus.join(root);
        let path = root.join(file);
        let stem = stem(file);
        let err_path = out.join(format!("{stem}.idlc-error"));
        let _ = std::fs::remove_file(&err_path);
        // Each file alone, so one rejected file does not hide the others.
        match idlc::Builder::new().include_dir(&root).compile(&[&path]) {
            Ok(()) => println!("cargo::rustc-cfg=idlc_ok={stem:?}"),
            Err(e) => {
                println!(
                    "cargo::warning=idlc rejects {}: see {}",
                    path.display(),
                    err_path.display()
                );
                let _ = std::fs::write(&err_path, e.to_string());
            }
        }
    }
}
