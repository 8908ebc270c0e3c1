//! Source files and locations. Every location points into the file the text came from, never into the
//! preprocessed buffer, so diagnostics show the file the user wrote.
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Index of a file in its [`SourceDb`]; stable for the life of the database (one [`crate::driver::Session`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct FileId(pub u32);

/// A byte range in one source file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Loc {
    /// The file the text is in.
    pub file: FileId,
    /// Byte offset of the first byte.
    pub start: u32,
    /// Byte offset one past the last byte (`>= start`).
    pub end: u32,
}

impl Loc {
    /// The range `start..end` of `file`; an `end` before `start` is taken as `start`.
    pub fn new(file: FileId, start: usize, end: usize) -> Self {
        Loc {
            file,
            start: start as u32,
            end: end.max(start) as u32,
        }
    }
    /// Length in bytes.
    pub fn len(&self) -> usize {
        (self.end - self.start) as usize
    }
    /// The range is empty (a position rather than a span).
    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }
}

/// One file as read, with its line index.
#[derive(Debug)]
pub struct SourceFile {
    /// Name shown in diagnostics (the path as given or found on the include path).
    pub name: String,
    /// Normalised path, the key under which the file is found again.
    pub path: PathBuf,
    /// The whole text.
    pub text: Arc<str>,
    line_starts: Vec<u32>,
}

impl SourceFile {
    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: u32) -> (usize, usize) {
        let line = match self.line_starts.binary_search(&offset) {
            Ok(i) => i,
            Err(i) => i - 1,
        };
        let start = self.line_starts[line] as usize;
        let end = (offset as usize).min(self.text.len());
        let col = self
            .text
            .get(start..end)
            .map(|s| s.chars().count())
            .unwrap_or(end - start);
        (line + 1, col + 1)
    }
}

/// All files read during one compilation, or during a whole [`crate::driver::Session`]: a file read once keeps
/// its [`FileId`]. Cloning is cheap (the files are shared).
#[derive(Debug, Default, Clone)]
pub struct SourceDb {
    files: Vec<Arc<SourceFile>>,
    by_path: HashMap<PathBuf, FileId>,
    /// `#line` directives seen, per file, by the physical line they take effect on.
    line_marks: HashMap<FileId, Vec<LineMark>>,
}

/// A `#line N ["name"]` directive: from physical line `from` on, lines are numbered from `line` and (when given)
/// reported under `name`.
#[derive(Clone, Debug, PartialEq, Eq)]
struct LineMark {
    from: usize,
    line: usize,
    name: Option<Arc<str>>,
}

impl SourceDb {
    /// An empty database.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a file and returns its id. A later [`SourceDb::find_path`] of the same path finds the newest one.
    pub fn add(
        &mut self,
        name: impl Into<String>,
        path: impl Into<PathBuf>,
        text: impl Into<Arc<str>>,
    ) -> FileId {
        let text: Arc<str> = text.into();
        let mut line_starts = vec![0u32];
        line_starts.extend(
            text.bytes()
                .enumerate()
                .filter(|(_, b)| *b == b'\n')
                .map(|(i, _)| i as u32 + 1),
        );
        let path: PathBuf = path.into();
        let id = FileId(self.files.len() as u32);
        self.by_path.insert(path.clone(), id);
        self.files.push(Arc::new(SourceFile {
            name: name.into(),
            path,
            text,
            line_starts,
        }));
        id
    }

    /// The file with this id. Panics on an id from another database.
    pub fn get(&self, id: FileId) -> &SourceFile {
        &self.files[id.0 as usize]
    }

    /// Every file, in the order read.
    pub fn files(&self) -> impl Iterator<Item = (FileId, &SourceFile)> {
        self.files
            .iter()
            .enumerate()
            .map(|(i, f)| (FileId(i as u32), &**f))
    }

    /// The file read from `path`, if any.
    pub fn find_path(&self, path: &Path) -> Option<FileId> {
        self.by_path.get(path).copied()
    }

    /// Records `#line line ["name"]` taking effect on physical line `from` (1-based) of `file`. Recording the same
    /// directive again (the file included twice) changes nothing.
    pub fn add_line_mark(&mut self, file: FileId, from: usize, line: usize, name: Option<&str>) {
        let mark = LineMark {
            from,
            line,
            name: name.map(Arc::from),
        };
        let marks = self.line_marks.entry(file).or_default();
        match marks.binary_search_by_key(&from, |m| m.from) {
            Ok(i) => marks[i] = mark,
            Err(i) => marks.insert(i, mark),
        }
    }

    /// The position of a byte offset as `#line` directives present it: file name, 1-based line and column.
    /// Without directives, the file's own name and line.
    pub fn presumed(&self, file: FileId, offset: u32) -> (&str, usize, usize) {
        let f = self.get(file);
        let (l, c) = f.line_col(offset);
        let marks = self.line_marks.get(&file).map_or(&[][..], Vec::as_slice);
        let i = marks.partition_point(|m| m.from <= l);
        if i == 0 {
            return (&f.name, l, c);
        }
        let m = &marks[i - 1];
        let name = marks[..i]
            .iter()
            .rev()
            .find_map(|m| m.name.as_deref())
            .unwrap_or(&f.name);
        (name, m.line + (l - m.from), c)
    }

    /// `file:line:col` of a location, as `#line` directives present it.
    pub fn describe(&self, loc: Loc) -> String {
        let (name, l, c) = self.presumed(loc.file, loc.start);
        format!("{name}:{l}:{c}")
    }

    /// The source text of a location (empty when out of range).
    pub fn snippet(&self, loc: Loc) -> &str {
        let f = self.get(loc.file);
        f.text
            .get(loc.start as usize..loc.end as usize)
            .unwrap_or("")
    }
}
