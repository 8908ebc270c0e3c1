//! Where the preprocessor reads files from: the file system, or memory (tests, fuzzing).
use std::collections::HashMap;
use std::io;
use std::path::{Path, PathBuf};

pub trait Vfs {
    fn read(&self, path: &Path) -> io::Result<String>;
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
    pub files: HashMap<PathBuf, String>,
}

impl MemVfs {
    pub fn new() -> Self {
        Self::default()
    }
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
