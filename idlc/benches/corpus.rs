//! Throughput of idlc (front end + Rust emission) over the whole IDL corpus on one core, next to Cyclone's
//! idlc on the same files. Plain timing, no harness: `cargo bench -p idlc --bench corpus`.
//!
//! The include-heavy folder `rti-ros-data-types` is also timed as one [`Session`] (what `idlc --check` does with
//! every file on one command line), where each included file is read and parsed once.
//!
//! The corpus comes from `$IDL_CORPUS` or the nearest `shared/idl-corpus` above the crate; without it the bench
//! prints SKIP.
use idlc::driver::{compile_file, Options, Session};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn corpus() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("IDL_CORPUS") {
        return Some(PathBuf::from(p)).filter(|p| p.is_dir());
    }
    // `shared/idl-corpus` next to the checkout or one of its parents.
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .map(|a| a.join("shared/idl-corpus"))
        .find(|p| p.is_dir())
}

fn files(root: &Path) -> Vec<(PathBuf, Options)> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "idl") {
                let mut o = Options::default();
                if let Ok(rel) = p.strip_prefix(root) {
                    if rel.starts_with("rti-ros-data-types") {
                        o.include_dirs.push(root.join("rti-ros-data-types"));
                    }
                }
                out.push((p, o));
            }
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// Best time of `rounds` sessions over the include-heavy folder, all files in one session.
fn session_rounds(root: &Path, rounds: usize) {
    let dir = root.join("rti-ros-data-types");
    let files: Vec<PathBuf> = files(root)
        .into_iter()
        .map(|(p, _)| p)
        .filter(|p| p.starts_with(&dir))
        .collect();
    let opts = Options {
        include_dirs: vec![dir],
        ..Options::default()
    };
    let mut best = Duration::MAX;
    for _ in 0..rounds {
        let t = Instant::now();
        let mut session = Session::new(opts.clone());
        for f in &files {
            let mut c = session.compile_file(f);
            std::hint::black_box(c.rust());
        }
        best = best.min(t.elapsed());
    }
    println!(
        "rti-ros-data-types, {} files in one session (front end + Rust emit): {:>8.1} ms  {:>8.0} files/s",
        files.len(),
        best.as_secs_f64() * 1e3,
        files.len() as f64 / best.as_secs_f64()
    );
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return; // `cargo bench -- --list` support
    }
    let Some(root) = corpus() else {
        println!("SKIP: IDL corpus not found (set IDL_CORPUS)");
        return;
    };
    let files = files(&root);
    let rounds: usize = std::env::var("ROUNDS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(5);
    // Warm the page cache and the allocator.
    for (f, o) in &files {
        let _ = compile_file(f, o).rust();
    }
    let mut best_front = Duration::MAX;
    let mut best_full = Duration::MAX;
    let mut accepted = 0;
    for _ in 0..rounds {
        // Each round is one cold compilation of the corpus: idlc keeps no state between compilations.
        let t = Instant::now();
        for (f, o) in &files {
            std::hint::black_box(compile_file(f, o).has_errors());
        }
        best_front = best_front.min(t.elapsed());
        let t = Instant::now();
        accepted = 0;
        for (f, o) in &files {
            let mut c = compile_file(f, o);
            if std::hint::black_box(c.rust()).is_some() {
                accepted += 1;
            }
        }
        best_full = best_full.min(t.elapsed());
    }
    let n = files.len() as f64;
    session_rounds(&root, rounds);
    println!(
        "idlc (this crate), {} files, best of {rounds} rounds, one thread:",
        files.len()
    );
    println!(
        "  front end only        {:>8.1} ms  {:>8.0} files/s",
        best_front.as_secs_f64() * 1e3,
        n / best_front.as_secs_f64()
    );
    println!(
        "  front end + Rust emit {:>8.1} ms  {:>8.0} files/s  ({accepted} files produce Rust)",
        best_full.as_secs_f64() * 1e3,
        n / best_full.as_secs_f64()
    );

    let cyclone = std::env::var("CYCLONE_IDLC").unwrap_or_else(|_| "/usr/bin/idlc".into());
    if !Path::new(&cyclone).exists() {
        println!("Cyclone idlc: not installed ({cyclone}), skipped");
        return;
    }
    let out = std::env::temp_dir().join("idlc-bench-cyclone");
    let _ = std::fs::create_dir_all(&out);
    let t = Instant::now();
    let mut ok = 0;
    for (f, o) in &files {
        // Cyclone's idlc exhausts memory on one corpus file: bound it.
        let inc = o
            .include_dirs
            .first()
            .map(|d| format!("-I '{}'", d.display()))
            .unwrap_or_default();
        let cmd = format!(
            "ulimit -v 2097152; exec timeout 20 '{cyclone}' -o '{}' {inc} '{}'",
            out.display(),
            f.display()
        );
        let st = Command::new("sh")
            .arg("-c")
            .arg(&cmd)
            .current_dir(&out)
            .output();
        if st.is_ok_and(|s| s.status.success()) {
            ok += 1;
        }
    }
    let el = t.elapsed();
    println!(
        "Cyclone idlc 0.10.2 (process per file, C output): {:>8.1} ms  {:>8.0} files/s  ({ok} files accepted)",
        el.as_secs_f64() * 1e3,
        n / el.as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&out);
}
