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

pub fn module_name(rel: &str) -> String {
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

#[test]
fn corpus() {
    let Some(root) = common::corpus_dir() else {
        println!("SKIP: IDL corpus not found (set IDL_CORPUS or provide ../shared/idl-corpus)");
        return;
    };
    let expected = expected_failures();
    let only: Option<String> = std::env::var("IDLC_CORPUS_FOLDER").ok();
    let no_build = std::env::var_os("IDLC_CORPUS_NO_BUILD").is_some();
    let mut problems: Vec<String> = Vec::new();
    let mut table = String::from(
        "| folder | files | accepted (Rust builds) | expected failures |\n|---|---:|---:|---:|\n",
    );
    let mut seen_expected = 0;
    for folder in FOLDERS {
        if only.as_deref().is_some_and(|o| o != *folder) {
            continue;
        }
        let dir = root.join(folder);
        let files = idl_files(&dir);
        let mut opts = Options::default();
        if *folder == "rti-ros-data-types" {
            opts.include_dirs.push(dir.clone());
        }
        let mut krate = common::ScratchCrate::new(&folder.replace('-', "_"));
        let (mut accepted, mut failed_as_expected) = (0, 0);
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
        table.push_str(&format!(
            "| {folder} | {} | {accepted} | {failed_as_expected} |\n",
            files.len()
        ));
    }
    println!("{table}");
    let _ = std::fs::write(
        common::target_dir().join("idlc-scratch/corpus-table.md"),
        &table,
    );
    if only.is_none() && seen_expected != expected.len() {
        problems.push(format!(
            "{} expected-failure entries name files that were not seen",
            expected.len() - seen_expected
        ));
    }
    assert!(
        problems.is_empty(),
        "{} corpus problem(s):\n{}",
        problems.len(),
        problems.join("\n\n")
    );
}
