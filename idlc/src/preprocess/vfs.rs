//! Where the preprocessor reads files from: the file system, or memory (tests, fuzzing).
use std::collections::HashMap;
use std::io;
use std::path::{Path, PathBuf};

/// A source of files for `#include`.
pub trait Vfs {
    /// The text of the file at `path`.
    fn read(&self, path: &Path) -> io::Result<String>;
    /// A file exists at `path` (include lookup tries candidates in order).
    fn exists(&self, path: &Path) -> bool;
}

/// The real file system. Files larger than 512 MiB are refused.
#[derive(Default, Clone, Copy)]
pub struct FsVfs;

impl Vfs for FsVfs {
    fn read(&self, path: &Path) -> io::Result<String> {
        if std::fs::metadata(path)?.len() > 512 << 20 {
            return Err(io::Error::other("file larger than 512 MiB"));
        }
        let bytes = std::fs::read(path)?;
        // IDL is ASCII/Latin-1 in practice: decode invalid UTF-8 as Latin-1 instead of failing.
        Ok(match String::from_utf8(bytes) {
            Ok(s) => s,
            Err(e) => e.into_bytes().into_iter().map(char::from).collect(),
        })
    }
    fn exists(&self, path: &Path) -> bool {
        path.is_file()
    }
}

/// An in-memory file set.
#[derive(Default, Clone)]
pub struct MemVfs {
    /// The files, by path.
    pub files: HashMap<PathBuf, String>,
}

impl MemVfs {
    /// No files.
    pub fn new() -> Self {
        Self::default()
    }
    /// Adds a file (builder style).
    pub fn with(mut self, path: &str, text: &str) -> Self {
        self.files.insert(PathBuf::from(path), text.to_string());
        self
    }
}

impl Vfs for MemVfs {
    fn read(&self, path: &Path) -> io::Result<String> {
        self.files
            .get(path)
            .cloned()
            .ok_or_else(|| io::Error::new(io::ErrorKind::NotFound, "no such file"))
    }
    fn exists(&self, path: &Path) -> bool {
        self.files.contains_key(path)
    }
}
