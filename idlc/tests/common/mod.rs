//! Helpers shared by the integration tests.
#![allow(dead_code)]
use std::path::{Path, PathBuf};

pub(crate) fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("idlc lives in the workspace")
        .to_path_buf()
}

/// The shared IDL corpus: `$IDL_CORPUS`, else `../shared/idl-corpus` next to the workspace.
pub(crate) fn corpus_dir() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("IDL_CORPUS") {
        let p = PathBuf::from(p);
        return p.is_dir().then_some(p);
    }
    let p = workspace_root().join("../shared/idl-corpus");
    p.is_dir().then(|| p.canonicalize().unwrap_or(p))
}

pub(crate) fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join("target"))
}

/// A scratch crate depending on dds-runtime, holding generated modules; built with the workspace's target dir.
pub(crate) struct ScratchCrate {
    pub(crate) dir: PathBuf,
    modules: Vec<(String, String)>,
    extra_lib: String,
    dev: bool,
}

impl ScratchCrate {
    pub(crate) fn new(name: &str) -> Self {
        let dir = target_dir().join("idlc-scratch").join(name);
        let _ = std::fs::remove_dir_all(dir.join("src"));
        std::fs::create_dir_all(dir.join("src/gen")).expect("create scratch dir");
        ScratchCrate {
            dir,
            modules: vec![],
            extra_lib: String::new(),
            dev: false,
        }
    }

    pub(crate) fn add_module(&mut self, name: &str, code: &str) {
        std::fs::write(self.dir.join("src/gen").join(format!("{name}.rs")), code)
            .expect("write module");
        self.modules.push((name.to_string(), name.to_string()));
    }

    pub(crate) fn add_lib_code(&mut self, code: &str) {
        self.extra_lib.push_str(code);
    }

    /// Builds (`cargo build`, or `cargo test` with `test`); returns (success, combined output).
    pub(crate) fn build(&self, test: bool) -> (bool, String) {
        let name = self
            .dir
            .file_name()
            .expect("name")
            .to_string_lossy()
            .replace('_', "-");
        let runtime = workspace_root().join("dds-runtime");
        let manifest = format!(
            "[package]\nname = \"idlc-scratch-{name}\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n\
             [dependencies]\ndds-runtime = {{ path = {:?} }}\n\n[workspace]\n",
            runtime.display().to_string()
        );
        std::fs::write(self.dir.join("Cargo.toml"), manifest).expect("write manifest");
        // Same versions as the workspace: nothing new to resolve or build.
        let _ = std::fs::copy(
            workspace_root().join("Cargo.lock"),
            self.dir.join("Cargo.lock"),
        );
        let mut lib = String::from("#![deny(warnings)]\n#![allow(clippy::all)]\n");
        for (m, file) in &self.modules {
            lib.push_str(&format!("#[path = \"gen/{file}.rs\"]\npub mod {m};\n"));
        }
        lib.push_str(&self.extra_lib);
        std::fs::write(self.dir.join("src/lib.rs"), lib).expect("write lib.rs");
        let _ = self.dev;
        let out =
            std::process::Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
                .arg(if test { "test" } else { "build" })
                .arg("--offline")
                .arg("--quiet")
                .arg("--manifest-path")
                .arg(self.dir.join("Cargo.toml"))
                .arg("--target-dir")
                .arg(target_dir())
                .env_remove("RUSTFLAGS")
                .output()
                .expect("run cargo");
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        (out.status.success(), text)
    }
}
