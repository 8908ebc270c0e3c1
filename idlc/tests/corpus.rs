//! Corpus test: every file of the shared IDL corpus either compiles to Rust that builds against dds-runtime
//! (one scratch crate per folder), or fails with the diagnostic listed for it in
//! `tests/corpus-expected-failures.txt`. Prints a per-folder table.
//!
//! The corpus is found through `$IDL_CORPUS` or at `../shared/idl-corpus` beside the workspace; without it
//! the test prints SKIP and passes.
mod common;

use idlc::driver::{compile_file, Options};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const FOLDERS: &[&str] = &[
    "cyclonedds",
    "eprosima-dds-types-test",
    "omg-dds-rtps",
    "ros2-test-interface-files",
    "rti-ros-data-types",
];

fn idl_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(rd) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "idl") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// `path<TAB>code<TAB>reason` lines; `#` comments.
fn expected_failures() -> BTreeMap<String, (String, String)> {
    let text = include_str!("corpus-expected-failures.txt");
    text.lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .filter_map(|l| {
            let mut it = l.splitn(3, '\t');
            Some((
                it.next()?.to_string(),
                (it.next()?.to_string(), it.next().unwrap_or("").to_string()),
            ))
        })
        .collect()
}

/// A Rust module name for a corpus file path (relative to the corpus).
fn module_name(rel: &str) -> String {
    let s: String = rel
        .trim_end_matches(".idl")
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    format!("m_{s}")
}

/// One folder: compile every file, build the accepted ones in one scratch crate, compare the failures with
/// the expected list. Returns the table row.
fn run_folder(folder: &str) {
    let Some(root) = common::corpus_dir() else {
        println!("SKIP: IDL corpus not found (set IDL_CORPUS or provide ../shared/idl-corpus)");
        return;
    };
    let expected = expected_failures();
    let no_build = std::env::var_os("IDLC_CORPUS_NO_BUILD").is_some();
    let mut problems: Vec<String> = Vec::new();
    let dir = root.join(folder);
    let files = idl_files(&dir);
    let mut opts = Options::default();
    if folder == "rti-ros-data-types" {
        opts.include_dirs.push(dir.clone());
    }
    let mut krate = common::ScratchCrate::new(&folder.replace('-', "_"));
    let (mut accepted, mut failed_as_expected, mut seen_expected) = (0, 0, 0);
    for f in &files {
        let rel = f.strip_prefix(&root).unwrap_or(f).display().to_string();
        let mut c = compile_file(f, &opts);
        let code = c.rust();
        match (code, expected.get(&rel)) {
            (Some(code), None) => {
                krate.add_module(&module_name(&rel), &code);
                accepted += 1;
            }
            (Some(_), Some(_)) => problems.push(format!(
                "{rel}: listed as an expected failure but now compiles"
            )),
            (None, Some((want, _))) => {
                seen_expected += 1;
                let first = c
                    .diags
                    .iter()
                    .find(|d| d.is_error())
                    .map(|d| d.code.as_str())
                    .unwrap_or("");
                if first != want {
                    problems.push(format!("{rel}: expected {want}, first error is {first}"));
                } else {
                    failed_as_expected += 1;
                }
            }
            (None, None) => {
                let text = c.render_diagnostics(Default::default());
                problems.push(format!("{rel}: unexpected errors:\n{text}"));
            }
        }
    }
    if !no_build && accepted > 0 {
        let (ok, out) = krate.build(false);
        if !ok {
            let head: String = out.lines().take(80).collect::<Vec<_>>().join("\n");
            problems.push(format!("{folder}: generated Rust does not build:\n{head}"));
        }
    }
    let listed = expected
        .keys()
        .filter(|k| k.starts_with(&format!("{folder}/")))
        .count();
    if listed != seen_expected {
        problems.push(format!(
            "{} expected-failure entries of {folder} name files that were not seen",
            listed - seen_expected
        ));
    }
    println!("| folder | files | accepted (Rust builds) | expected failures |");
    println!(
        "| {folder} | {} | {accepted} | {failed_as_expected} |",
        files.len()
    );
    assert!(
        problems.is_empty(),
        "{} corpus problem(s):\n{}",
        problems.len(),
        problems.join("\n\n")
    );
}

#[test]
fn corpus_cyclonedds() {
    run_folder("cyclonedds");
}

#[test]
fn corpus_eprosima_dds_types_test() {
    run_folder("eprosima-dds-types-test");
}

#[test]
fn corpus_omg_dds_rtps() {
    run_folder("omg-dds-rtps");
}

#[test]
fn corpus_ros2_test_interface_files() {
    run_folder("ros2-test-interface-files");
}

#[test]
fn corpus_rti_ros_data_types() {
    run_folder("rti-ros-data-types");
}

#[test]
fn corpus_folders_are_all_covered() {
    let Some(root) = common::corpus_dir() else {
        println!("SKIP: IDL corpus not found");
        return;
    };
    for e in std::fs::read_dir(&root).expect("corpus dir").flatten() {
        if e.path().is_dir() {
            let name = e.file_name().to_string_lossy().into_owned();
            assert!(
                FOLDERS.contains(&name.as_str()),
                "corpus folder {name} has no test"
            );
        }
    }
}
