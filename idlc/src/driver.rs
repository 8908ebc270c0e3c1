//! The pipeline in one call: preprocess → parse → resolve → validate, then the back ends.
use crate::diag::{self, Diagnostics, RenderOptions};
use crate::emit::rust::RustOptions;
use crate::model::{Extensibility, Model};
use crate::preprocess::{self, FsVfs, MemVfs, Vfs};
use crate::source::SourceDb;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug)]
pub struct Options {
    pub include_dirs: Vec<PathBuf>,
    pub defines: Vec<String>,
    pub undefines: Vec<String>,
    pub default_extensibility: Extensibility,
    pub rust: RustOptions,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            include_dirs: vec![],
            defines: vec![],
            undefines: vec![],
            default_extensibility: Extensibility::Appendable,
            rust: RustOptions::default(),
        }
    }
}

/// The result of the front end for one input file.
#[derive(Debug)]
pub struct Compilation {
    pub db: SourceDb,
    pub model: Model,
    pub diags: Diagnostics,
    /// Preprocessed text (for `-E`).
    pub preprocessed: preprocess::Output,
    /// Every file read (the input and its includes), for dependency tracking.
    pub files: Vec<PathBuf>,
    opts: Options,
}

/// The front end recurses on nesting; run it on a thread with a generous stack so that the nesting limits,
/// not the platform's default stack size, decide what is accepted.
fn with_stack<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .stack_size(64 << 20)
            .spawn_scoped(s, f)
            .map(|h| h.join())
            .unwrap_or_else(|_| Err(Box::new("cannot spawn compiler thread")))
            .unwrap_or_else(|p| std::panic::resume_unwind(p))
    })
}

pub fn compile_file(path: &Path, opts: &Options) -> Compilation {
    with_stack(|| {
        run(path, opts, &FsVfs, |db, vfs, pp, diags| {
            preprocess::preprocess(db, vfs, pp, path, diags)
        })
    })
}

/// Compiles text held in memory; `#include` looks in `files` (by path).
pub fn compile_str(name: &str, text: &str, opts: &Options, files: &MemVfs) -> Compilation {
    let path = PathBuf::from(name);
    with_stack(|| {
        run(&path, opts, files, |db, vfs, pp, diags| {
            let id = db.add(name, name, text);
            preprocess::preprocess_file(db, vfs, pp, id, diags)
        })
    })
}

fn run(
    _path: &Path,
    opts: &Options,
    vfs: &(dyn Vfs + Sync),
    pre: impl FnOnce(
        &mut SourceDb,
        &dyn Vfs,
        &preprocess::Options,
        &mut Diagnostics,
    ) -> preprocess::Output,
) -> Compilation {
    let mut db = SourceDb::new();
    let mut diags = Diagnostics::new();
    let ppo = preprocess::Options {
        include_dirs: opts.include_dirs.clone(),
        defines: opts.defines.clone(),
        undefines: opts.undefines.clone(),
    };
    let pp = pre(&mut db, vfs, &ppo, &mut diags);
    let files = pp.files.iter().map(|f| db.get(*f).path.clone()).collect();
    let mut model = Model::default();
    if !diags.has_errors() {
        let spec = crate::parse::parse(&pp, &mut diags);
        let ropts = crate::resolve::Options {
            default_extensibility: opts.default_extensibility,
        };
        model = crate::resolve::resolve(std::slice::from_ref(&spec), &ropts, &mut diags);
        if !diags.has_errors() {
            crate::validate::validate(&model, &mut diags);
        }
    }
    Compilation {
        db,
        model,
        diags,
        preprocessed: pp,
        files,
        opts: opts.clone(),
    }
}

impl Compilation {
    pub fn has_errors(&self) -> bool {
        self.diags.has_errors()
    }

    /// Rust source for the model; `None` (with diagnostics added) when there are errors.
    pub fn rust(&mut self) -> Option<String> {
        if self.has_errors() {
            return None;
        }
        let mut ro = self.opts.rust.clone();
        if ro.source_name.is_none() {
            ro.source_name = self
                .files
                .first()
                .and_then(|p| p.file_name())
                .map(|n| n.to_string_lossy().into_owned());
        }
        let code = crate::emit::rust::emit(&self.model, &ro, &mut self.diags);
        (!self.has_errors()).then_some(code)
    }

    pub fn json(&self) -> Option<String> {
        (!self.has_errors()).then(|| crate::emit::json::emit(&self.model))
    }

    /// All diagnostics, rendered (sorted by position).
    pub fn render_diagnostics(&mut self, opts: RenderOptions) -> String {
        self.diags.sort();
        diag::render_all(&self.db, self.diags.iter(), opts)
    }
}
