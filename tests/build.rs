//! Compiles a selection of the real IDL corpus (`../shared/idl-corpus`, or `$DDS_IDL_CORPUS`) with idlc for
//! `tests/idlc_golden.rs`, which checks the generated types against libddsc's bytes
//! (`tests/fixtures/idlc-golden/`).
//!
//! The corpus lives outside the repository, so everything here is optional: without it nothing is generated and
//! the test prints that it skipped. A file idlc rejects does not break the build (the other test binaries of this
//! crate share this script): its diagnostics go to `$OUT_DIR/<stem>.idlc-error` and the test for its types fails
//! with them. Each accepted file gets `--cfg idlc_ok="<stem>"` (`"final/<stem>"` for the second compilation).
use std::path::{Path, PathBuf};

/// (include root relative to the corpus, file relative to that root). idlc writes `<stem>.rs`, so stems must be
/// unique.
const FILES: &[(&str, &str)] = &[
    ("omg-dds-rtps/srcCxx", "shape.idl"),
    ("cyclonedds/src/tools/ddsperf", "ddsperf_types.idl"),
    ("eprosima-dds-types-test/IDL", "structures.idl"),
    ("eprosima-dds-types-test/IDL", "inheritance.idl"),
    ("eprosima-dds-types-test/IDL", "enumerations.idl"),
    ("eprosima-dds-types-test/IDL", "unions.idl"),
    ("eprosima-dds-types-test/IDL", "key.idl"),
    ("eprosima-dds-types-test/IDL", "mutable.idl"),
    ("eprosima-dds-types-test/IDL", "final.idl"),
    ("eprosima-dds-types-test/IDL", "member_id.idl"),
    ("eprosima-dds-types-test/IDL", "optional.idl"),
    ("eprosima-dds-types-test/IDL", "arrays.idl"),
    ("eprosima-dds-types-test/IDL", "sequences.idl"),
    ("cyclonedds/src/core/ddsc/tests", "CdrStreamKeyExt.idl"),
    ("cyclonedds/src/core/ddsc/tests", "CdrStreamSignedUnion.idl"),
    ("cyclonedds/src/tools/idlc/xtests", "test_struct_keys.idl"),
    (
        "cyclonedds/src/tools/idlc/xtests",
        "test_struct_inherit_mutable_keys.idl",
    ),
    ("rti-ros-data-types", "geometry_msgs/msg/PoseStamped.idl"),
    ("rti-ros-data-types", "sensor_msgs/msg/Imu.idl"),
    (
        "rti-ros-data-types",
        "diagnostic_msgs/msg/DiagnosticStatus.idl",
    ),
];

/// Compiled a second time with unannotated types @final (Cyclone idlc's default, so what a ROS 2 node on
/// rmw_cyclonedds uses), into `$OUT_DIR/final/`.
const FINAL_FILES: &[(&str, &str)] = &[
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

/// Compiles one file; `key` (`<stem>` or `final/<stem>`) names its output under `$OUT_DIR` and its cfg value.
fn compile(corpus: &Path, out: &Path, (root, file): (&str, &str), key: &str, final_default: bool) {
    let root = corpus.join(root);
    let path = root.join(file);
    let err_path = out.join(format!("{key}.idlc-error"));
    let _ = std::fs::remove_file(&err_path);
    let out_dir = err_path.parent().unwrap_or(out).to_path_buf();
    let _ = std::fs::create_dir_all(&out_dir);
    let mut builder = idlc::Builder::new().include_dir(&root).out_dir(&out_dir);
    if final_default {
        builder = builder.default_extensibility(idlc::model::Extensibility::Final);
    }
    match builder.compile(&[&path]) {
        Ok(()) => println!("cargo::rustc-cfg=idlc_ok={key:?}"),
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

/// Our own IDL (`tests/idl/`), always compiled, into `$OUT_DIR/own/` (`tests/idlc_typedefs.rs`).
fn own_idl() {
    let dir =
        PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it")).join("idl");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR")).join("own");
    println!("cargo::rerun-if-changed={}", dir.display());
    let _ = std::fs::create_dir_all(&out);
    for stem in ["typedefs", "nested_base", "no-peer/bitsets"] {
        if let Err(e) = idlc::Builder::new()
            .out_dir(&out)
            .compile(&[dir.join(format!("{stem}.idl"))])
        {
            panic!("idlc rejects tests/idl/{stem}.idl: {e}");
        }
    }
}

fn main() {
    let keys: Vec<String> = FILES
        .iter()
        .map(|(_, f)| stem(f))
        .chain(
            FINAL_FILES
                .iter()
                .map(|(_, f)| format!("final/{}", stem(f))),
        )
        .collect();
    let values: Vec<String> = keys.iter().map(|k| format!("{k:?}")).collect();
    println!("cargo::rustc-check-cfg=cfg(idl_corpus)");
    println!(
        "cargo::rustc-check-cfg=cfg(idlc_ok, values({}))",
        values.join(", ")
    );
    println!("cargo::rerun-if-env-changed=DDS_IDL_CORPUS");
    println!("cargo::rerun-if-changed=build.rs");
    own_idl();

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
    // Each file alone, so that one rejected file does not hide the others.
    for &entry in FILES {
        compile(&corpus, &out, entry, &stem(entry.1), false);
    }
    for &entry in FINAL_FILES {
        compile(
            &corpus,
            &out,
            entry,
            &format!("final/{}", stem(entry.1)),
            true,
        );
    }
}
