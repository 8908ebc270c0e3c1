//! Generated code: snapshots of representative inputs, and a round trip of generated types through every
//! encoding (XCDR1/XCDR2 × big/little endian) in a scratch crate built against dds-runtime.
mod common;

use idlc::driver::{compile_file, Options};
use std::path::{Path, PathBuf};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

fn generate(path: &Path, include: &Path) -> String {
    let mut opts = Options::default();
    opts.include_dirs.push(include.to_path_buf());
    let mut c = compile_file(path, &opts);
    let code = c.rust();
    let diags = c.render_diagnostics(Default::default());
    code.unwrap_or_else(|| panic!("{} failed:\n{diags}", path.display()))
}

#[test]
fn showcase_snapshot() {
    let code = generate(&fixtures().join("showcase.idl"), &fixtures());
    insta::assert_snapshot!("showcase", code);
}

#[test]
fn shapes_snapshot() {
    let root = common::workspace_root().join("idl");
    insta::assert_snapshot!("shapes", generate(&root.join("shapes.idl"), &root));
}

#[test]
fn ddsperf_snapshot() {
    let root = common::workspace_root().join("idl");
    insta::assert_snapshot!(
        "ddsperf_types",
        generate(&root.join("ddsperf_types.idl"), &root)
    );
}

#[test]
fn corpus_samples_snapshot() {
    let Some(corpus) = common::corpus_dir() else {
        println!("SKIP: IDL corpus not found");
        return;
    };
    for (name, rel) in [
        ("eprosima_unions", "eprosima-dds-types-test/IDL/unions.idl"),
        (
            "eprosima_bitsets",
            "eprosima-dds-types-test/IDL/bitsets.idl",
        ),
        (
            "ros2_idl_only_types",
            "ros2-test-interface-files/idl/IdlOnlyTypes.idl",
        ),
        (
            "rti_ros_header",
            "rti-ros-data-types/std_msgs/msg/Header.idl",
        ),
    ] {
        let path = corpus.join(rel);
        if !path.exists() {
            continue;
        }
        let include = if rel.starts_with("rti") {
            corpus.join("rti-ros-data-types")
        } else {
            path.parent().unwrap().to_path_buf()
        };
        insta::assert_snapshot!(name, generate(&path, &include));
    }
}

#[test]
fn generated_code_is_deterministic() {
    let a = generate(&fixtures().join("showcase.idl"), &fixtures());
    let b = generate(&fixtures().join("showcase.idl"), &fixtures());
    assert_eq!(a, b);
}

/// Builds the showcase types with the real derive and round-trips sample values through every encoding.
#[test]
fn showcase_round_trips_through_every_encoding() {
    let code = generate(&fixtures().join("showcase.idl"), &fixtures());
    let mut krate = common::ScratchCrate::new("roundtrip");
    krate.add_module("generated", &code);
    krate.add_lib_code(include_str!("fixtures/roundtrip_tests.rs"));
    let (ok, out) = krate.build(true);
    assert!(ok, "round trip failed:\n{out}");
    assert!(out.contains("test result: ok"), "no tests ran:\n{out}");
}
