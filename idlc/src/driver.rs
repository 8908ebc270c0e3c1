//! The pipeline in one call: preprocess → parse → resolve → validate, then the back ends.
use crate::diag::{self, Diagnostics, RenderOptions};
use crate::emit::rust::RustOptions;
use crate::model::{Extensibility, Model};
use crate::parse::ParseCache;
use crate::preprocess::{self, FsVfs, MemVfs, Vfs};
use crate::source::{FileId, SourceDb};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// What a compilation needs besides its input.
#[derive(Clone, Debug)]
pub struct Options {
    /// `-I`: directories searched for `#include`, in order.
    pub include_dirs: Vec<PathBuf>,
    /// `-D NAME` or `-D NAME=VALUE`, in order.
    pub defines: Vec<String>,
    /// `-U NAME`, applied after the defines.
    pub undefines: Vec<String>,
    /// Extensibility of types without an annotation.
    pub default_extensibility: Extensibility,
    /// Options of the Rust back end.
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
    /// Every file read in the session so far (the diagnostics point into it).
    pub db: SourceDb,
    /// The resolved model.
    pub model: Model,
    /// What the front end (and later the back ends) reported.
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

/// Compiles one file on its own. To compile several files that include each other, use a [`Session`]: it reads
/// and parses each included file once.
pub fn compile_file(path: &Path, opts: &Options) -> Compilation {
    Session::new(opts.clone()).compile_file(path)
}

/// Compiles text held in memory; `#include` looks in `files` (by path).
pub fn compile_str(name: &str, text: &str, opts: &Options, files: &MemVfs) -> Compilation {
    Session::with_vfs(opts.clone(), Box::new(files.clone())).compile_str(name, text)
}

/// Several compilations with the same options that share what they read: each file is read once, and each
/// piece of preprocessed text is parsed once (see [`crate::parse::ParseCache`] for why that is safe when a file
/// preprocesses differently from one includer to the next). The file system is taken as unchanging while the
/// session lasts.
pub struct Session {
    opts: Options,
    vfs: CachedVfs,
    db: SourceDb,
    cache: ParseCache,
}

impl Session {
    /// A session reading the real file system.
    pub fn new(opts: Options) -> Self {
        Self::with_vfs(opts, Box::new(FsVfs))
    }

    /// A session reading files through `vfs`.
    pub fn with_vfs(opts: Options, vfs: Box<dyn Vfs + Send + Sync>) -> Self {
        Session {
            opts,
            vfs: CachedVfs {
                inner: vfs,
                exists: Mutex::new(HashMap::new()),
            },
            db: SourceDb::new(),
            cache: ParseCache::new(),
        }
    }

    /// Compiles the file at `path`.
    pub fn compile_file(&mut self, path: &Path) -> Compilation {
        with_stack(|| {
            self.run(|db, vfs, pp, diags| preprocess::preprocess(db, vfs, pp, path, diags))
        })
    }

    /// Compiles `text` as if read from a file named `name`.
    pub fn compile_str(&mut self, name: &str, text: &str) -> Compilation {
        with_stack(|| {
            self.run(|db, vfs, pp, diags| {
                let id = db.add(name, name, text);
                preprocess::preprocess_file(db, vfs, pp, id, diags)
            })
        })
    }

    fn run(
        &mut self,
        pre: impl FnOnce(
            &mut SourceDb,
            &dyn Vfs,
            &preprocess::Options,
            &mut Diagnostics,
        ) -> preprocess::Output,
    ) -> Compilation {
        let opts = &self.opts;
        let mut diags = Diagnostics::new();
        let ppo = preprocess::Options {
            include_dirs: opts.include_dirs.clone(),
            defines: opts.defines.clone(),
            undefines: opts.undefines.clone(),
        };
        let pp = pre(&mut self.db, &self.vfs, &ppo, &mut diags);
        let files = pp
            .files
            .iter()
            .map(|f| self.db.get(*f).path.clone())
            .collect();
        let mut model = Model::default();
        if !diags.has_errors() {
            let specs = crate::parse::parse(&pp, &mut self.cache, &mut diags);
            let ropts = crate::resolve::Options {
                default_extensibility: opts.default_extensibility,
            };
            model = crate::resolve::resolve(specs.iter().map(|s| &**s), &ropts, &mut diags);
            if !diags.has_errors() {
                crate::validate::validate(&model, &mut diags);
            }
        }
        Compilation {
            db: self.db.clone(),
            model,
            diags,
            preprocessed: pp,
            files,
            opts: opts.clone(),
        }
    }
}

/// A [`Vfs`] that remembers which paths exist: include lookup probes the same candidates for every input.
struct CachedVfs {
    inner: Box<dyn Vfs + Send + Sync>,
    exists: Mutex<HashMap<PathBuf, bool>>,
}

impl Vfs for CachedVfs {
    fn read(&self, path: &Path) -> std::io::Result<String> {
        self.inner.read(path)
    }

    fn exists(&self, path: &Path) -> bool {
        let mut known = self.exists.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(&e) = known.get(path) {
            return e;
        }
        let e = self.inner.exists(path);
        known.insert(path.to_path_buf(), e);
        e
    }
}

impl Compilation {
    /// Some diagnostic is an error.
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

    /// JSON dump of the model; `None` when there are errors.
    pub fn json(&self) -> Option<String> {
        (!self.has_errors()).then(|| crate::emit::json::emit(&self.model))
    }

    /// All diagnostics, rendered (sorted by position: the input file first, then its includes in the order
    /// first read).
    pub fn render_diagnostics(&mut self, opts: RenderOptions) -> String {
        let rank: HashMap<FileId, usize> = self
            .preprocessed
            .files
            .iter()
            .enumerate()
            .map(|(i, f)| (*f, i))
            .collect();
        let mut list = std::mem::take(&mut self.diags).into_vec();
        list.sort_by_key(|d| {
            d.primary_loc()
                .map(|l| (rank.get(&l.file).copied().unwrap_or(usize::MAX), l.start))
                .unwrap_or_default()
        });
        for d in list {
            self.diags.push(d);
        }
        diag::render_all(&self.db, self.diags.iter(), opts)
    }
}
