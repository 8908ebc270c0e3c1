//! `build.rs` API in the style of `prost-build`:
//!
//! ```no_run
//! idlc::Builder::new().include_dir("idl").compile(&["idl/shapes.idl"]).unwrap();
//! ```
//!
//! writes `$OUT_DIR/shapes.rs` and prints `cargo:rerun-if-changed` for every file read, includes too.
//! Include the result with `include!(concat!(env!("OUT_DIR"), "/shapes.rs"));`.
use crate::diag::{RenderOptions, Severity};
use crate::driver::{Options, Session};
use crate::model::Extensibility;
use std::fmt;
use std::path::{Path, PathBuf};

/// Why [`Builder::compile`] failed.
#[derive(thiserror::Error)]
pub enum Error {
    /// The IDL has errors; `rendered` holds the full diagnostics.
    #[error("{rendered}\nidlc: {count} error(s) in {file}")]
    Idl {
        /// The input file, as given.
        file: String,
        /// How many errors (warnings not counted).
        count: usize,
        /// Every diagnostic of the file, rendered as text.
        rendered: String,
    },
    /// The generated file could not be written.
    #[error("idlc: cannot write {path}: {source}")]
    Io {
        /// The file idlc tried to write.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// Neither [`Builder::out_dir`] nor `$OUT_DIR` says where to write.
    #[error(
        "idlc: OUT_DIR is not set and no out_dir was given (are we running outside build.rs?)"
    )]
    NoOutDir,
}

// `build.rs` usually ends in `.unwrap()`: make the panic message the readable report.
impl fmt::Debug for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

/// Compiles IDL files to Rust from `build.rs`: set options with the chained methods, then call
/// [`Builder::compile`].
#[derive(Clone, Debug, Default)]
pub struct Builder {
    opts: Options,
    out_dir: Option<PathBuf>,
    quiet: bool,
}

impl Builder {
    /// A builder with the defaults: no include directories or macros, `@appendable` as the default
    /// extensibility, no serde derives, `::dds_runtime` as the runtime path, output to `$OUT_DIR`.
    pub fn new() -> Self {
        Self::default()
    }
    /// Adds an `#include` search directory.
    pub fn include_dir(mut self, dir: impl AsRef<Path>) -> Self {
        self.opts.include_dirs.push(dir.as_ref().to_path_buf());
        self
    }
    /// Defines a preprocessor macro (`-D NAME=VALUE`; `value` `None` means `1`).
    pub fn define(mut self, name: &str, value: Option<&str>) -> Self {
        self.opts.defines.push(match value {
            Some(v) => format!("{name}={v}"),
            None => name.to_string(),
        });
        self
    }
    /// Extensibility of types without an annotation (default [`Extensibility::Appendable`]).
    pub fn default_extensibility(mut self, ext: Extensibility) -> Self {
        self.opts.default_extensibility = ext;
        self
    }
    /// Also derive `serde::Serialize` and `serde::Deserialize` (the crate must depend on serde).
    pub fn serde(mut self, on: bool) -> Self {
        self.opts.rust.serde = on;
        self
    }
    /// Path of the runtime crate in generated code (default `::dds_runtime`).
    pub fn runtime_crate(mut self, path: &str) -> Self {
        self.opts.rust.runtime_crate = path.to_string();
        self
    }
    /// Where to write (default `$OUT_DIR`).
    pub fn out_dir(mut self, dir: impl AsRef<Path>) -> Self {
        self.out_dir = Some(dir.as_ref().to_path_buf());
        self
    }
    /// Do not print `cargo:` lines (for use outside build scripts).
    pub fn quiet(mut self, quiet: bool) -> Self {
        self.quiet = quiet;
        self
    }

    /// Compiles each file to `<out_dir>/<stem>.rs`, in one [`Session`] so that files they share through
    /// `#include` are read and parsed once. Every file is attempted; the first failure is returned.
    pub fn compile(&self, files: &[impl AsRef<Path>]) -> Result<(), Error> {
        let out_dir = match &self.out_dir {
            Some(d) => d.clone(),
            None => std::env::var_os("OUT_DIR")
                .map(PathBuf::from)
                .ok_or(Error::NoOutDir)?,
        };
        let mut session = Session::new(self.opts.clone());
        let mut first_err = None;
        for file in files {
            let file = file.as_ref();
            if let Err(e) = self.compile_one(&mut session, file, &out_dir) {
                first_err.get_or_insert(e);
            }
        }
        first_err.map_or(Ok(()), Err)
    }

    fn compile_one(&self, session: &mut Session, file: &Path, out_dir: &Path) -> Result<(), Error> {
        let mut c = session.compile_file(file);
        if !self.quiet {
            println!("cargo:rerun-if-changed={}", file.display());
            for f in &c.files {
                println!("cargo:rerun-if-changed={}", f.display());
            }
        }
        let code = c.rust();
        if !self.quiet {
            for d in c.diags.iter().filter(|d| d.severity == Severity::Warning) {
                let at = d
                    .primary_loc()
                    .map(|l| format!("{}: ", c.db.describe(l)))
                    .unwrap_or_default();
                println!("cargo:warning={at}{} [{}]", d.message, d.code.as_str());
            }
        }
        let Some(code) = code else {
            let count = c.diags.error_count();
            let rendered = c.render_diagnostics(RenderOptions {
                color: false,
                width: 100,
            });
            return Err(Error::Idl {
                file: file.display().to_string(),
                count,
                rendered,
            });
        };
        let stem = file
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "idl".into());
        let path = out_dir.join(format!("{stem}.rs"));
        std::fs::write(&path, code).map_err(|source| Error::Io { path, source })
    }
}
