//! In-process C-style preprocessor for IDL: includes, macros, conditionals, `#pragma`.
//!
//! The output is one text buffer plus a [`SourceMap`] from output offsets back to the original files, so every
//! later stage reports the true file, line and column. Comments stay in the output (the grammar skips them) and
//! are also listed in [`Output::comments`] for doc comments and legacy `//@key` annotations.
mod expr;
mod lex;
mod macros;
mod vfs;

pub use vfs::{FsVfs, MemVfs, Vfs};

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::source::{FileId, Loc, SourceDb};
use lex::{is_ident_char, is_ident_start, Kind, Tok};
use macros::MacroTable;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

const MAX_INCLUDE_DEPTH: usize = 64;
const MAX_OUTPUT: usize = 256 << 20;
/// Longest single token (identifier, number, literal). Real IDL never comes close; the parser's cost per
/// byte is high, so longer tokens are refused up front.
const MAX_TOKEN: usize = 1 << 20;

/// What the preprocessor needs besides the input.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Directories searched for `#include`, in order.
    pub include_dirs: Vec<PathBuf>,
    /// `-D NAME` or `-D NAME=VALUE`, in order.
    pub defines: Vec<String>,
    /// `-U NAME`, applied after the defines.
    pub undefines: Vec<String>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct Seg {
    out: u32,
    file: FileId,
    src: u32,
    src_end: u32,
    /// Verbatim copy (offsets advance together); otherwise a macro expansion mapped to its invocation.
    linear: bool,
}

/// Maps output offsets to source locations.
#[derive(Debug, Default, Clone, PartialEq, Eq, Hash)]
pub struct SourceMap {
    segs: Vec<Seg>,
}

impl SourceMap {
    /// The map of the output range `start..end`, with offsets relative to `start`: `slice(a, b).loc(x, y)` is
    /// `loc(a + x, a + y)` for every range inside `a..b`.
    pub(crate) fn slice(&self, start: usize, end: usize) -> SourceMap {
        let i = self.segs.partition_point(|s| s.out as usize <= start);
        let mut segs = Vec::new();
        if i > 0 {
            let s = self.segs[i - 1];
            let skip = start as u32 - s.out;
            segs.push(Seg {
                out: 0,
                src: if s.linear { s.src + skip } else { s.src },
                ..s
            });
        }
        for s in self.segs[i..].iter().take_while(|s| (s.out as usize) < end) {
            segs.push(Seg {
                out: s.out - start as u32,
                ..*s
            });
        }
        SourceMap { segs }
    }

    fn seg_at(&self, off: usize) -> Option<&Seg> {
        let i = self.segs.partition_point(|s| s.out as usize <= off);
        if i == 0 {
            self.segs.first()
        } else {
            Some(&self.segs[i - 1])
        }
    }

    fn point(&self, off: usize) -> Option<(FileId, u32, u32)> {
        let s = self.seg_at(off)?;
        if s.linear {
            let p = s.src + (off as u32).saturating_sub(s.out);
            Some((s.file, p, p))
        } else {
            Some((s.file, s.src, s.src_end))
        }
    }

    /// The source location of an output range.
    pub fn loc(&self, start: usize, end: usize) -> Loc {
        let Some((f, a, a_end)) = self.point(start) else {
            return Loc::default();
        };
        let end_pt = if end > start {
            self.point(end - 1)
        } else {
            None
        };
        match end_pt {
            Some((g, b, b_end)) if g == f && b >= a => Loc {
                file: f,
                start: a,
                end: b_end.max(b + 1),
            },
            _ => Loc {
                file: f,
                start: a,
                end: a_end.max(a + 1),
            },
        }
    }

    fn push(&mut self, seg: Seg) {
        if let Some(last) = self.segs.last_mut() {
            if last.out == seg.out {
                *last = seg;
                return;
            }
            if last.linear
                && seg.linear
                && last.file == seg.file
                && last.src + (seg.out - last.out) == seg.src
            {
                last.src_end = seg.src_end;
                return;
            }
        }
        self.segs.push(seg);
    }
}

/// A comment in the output.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Comment {
    /// Output offset of the first delimiter.
    pub start: usize,
    /// Output offset one past the closing delimiter (or the end of the line for `//`).
    pub end: usize,
}

/// The preprocessed translation unit.
#[derive(Debug, Default)]
pub struct Output {
    /// The text, with directives blanked and macros expanded.
    pub text: String,
    /// Where each output byte came from.
    pub map: SourceMap,
    /// Every comment in the kept text, in order.
    pub comments: Vec<Comment>,
    /// Every file read, the main file first.
    pub files: Vec<FileId>,
    /// Output offsets where an included file's text begins or ends, in order. The parser splits the text there
    /// (when the split falls between definitions) and reuses the syntax tree of a piece seen before.
    pub boundaries: Vec<usize>,
}

impl Output {
    /// The text with `# line "file"` markers, as `cpp -E` prints it.
    pub fn with_line_markers(&self, db: &SourceDb) -> String {
        let mut s = String::with_capacity(self.text.len() + 256);
        let mut cur: Option<FileId> = None;
        let mut line_start = 0;
        for line in self.text.split_inclusive('\n') {
            if let Some(seg) = self.map.seg_at(line_start) {
                if cur != Some(seg.file) && !line.trim().is_empty() {
                    let at = self.map.loc(line_start, line_start + 1).start;
                    let (name, l, _) = db.presumed(seg.file, at);
                    s.push_str(&format!("# {l} \"{name}\"\n"));
                    cur = Some(seg.file);
                }
            }
            s.push_str(line);
            line_start += line.len();
        }
        s
    }
}

struct Cond {
    /// This branch's lines are kept.
    active: bool,
    /// Some branch of this #if has been taken.
    taken: bool,
    seen_else: bool,
    parent_active: bool,
    loc: Loc,
}

struct Preprocessor<'a> {
    db: &'a mut SourceDb,
    vfs: &'a dyn Vfs,
    diags: &'a mut Diagnostics,
    opts: &'a Options,
    macros: MacroTable,
    once: HashSet<PathBuf>,
    out: Output,
    in_comment: Option<usize>,
    too_big: bool,
}

/// Preprocesses `path` (read through `vfs`).
pub fn preprocess(
    db: &mut SourceDb,
    vfs: &dyn Vfs,
    opts: &Options,
    path: &Path,
    diags: &mut Diagnostics,
) -> Output {
    let mut pp = Preprocessor::new(db, vfs, opts, diags);
    let name = path.display().to_string();
    // Read before (as an include of an earlier input of the session) under the same name: keep its id, so that
    // the parse cache knows its text.
    if let Some(id) = pp
        .db
        .find_path(path)
        .filter(|id| pp.db.get(*id).name == name)
    {
        pp.run(id);
        return pp.out;
    }
    match vfs.read(path) {
        Ok(text) => {
            let id = pp.db.add(name, path, text);
            pp.run(id);
        }
        Err(e) => pp.diags.push(Diagnostic::error(
            Code::Io,
            format!("cannot read `{}`: {e}", path.display()),
        )),
    }
    pp.out
}

/// Preprocesses a file already in `db` (used for in-memory sources).
pub fn preprocess_file(
    db: &mut SourceDb,
    vfs: &dyn Vfs,
    opts: &Options,
    file: FileId,
    diags: &mut Diagnostics,
) -> Output {
    let mut pp = Preprocessor::new(db, vfs, opts, diags);
    pp.run(file);
    pp.out
}

impl<'a> Preprocessor<'a> {
    fn new(
        db: &'a mut SourceDb,
        vfs: &'a dyn Vfs,
        opts: &'a Options,
        diags: &'a mut Diagnostics,
    ) -> Self {
        let mut macros = MacroTable::default();
        // Cyclone's idlc defines __IDLC__ and IDL in the wild relies on it to hide C code from the compiler.
        for pre in ["__IDLC__ 1", "__IDLC_RS__ 1"] {
            let _ = macros.define(pre);
        }
        for d in &opts.defines {
            let text = match d.split_once('=') {
                Some((n, v)) => format!("{n} {v}"),
                None => format!("{d} 1"),
            };
            if let Err(e) = macros.define(&text) {
                diags.push(Diagnostic::error(
                    Code::Macro,
                    format!("invalid -D `{d}`: {e}"),
                ));
            }
        }
        for u in &opts.undefines {
            macros.defs.remove(u);
        }
        Preprocessor {
            db,
            vfs,
            diags,
            opts,
            macros,
            once: HashSet::new(),
            out: Output::default(),
            in_comment: None,
            too_big: false,
        }
    }

    fn run(&mut self, file: FileId) {
        self.process(file, 0);
    }

    fn err(&mut self, code: Code, loc: Loc, msg: impl Into<String>, label: &str) {
        self.diags.push(Diagnostic::error(code, msg).at(loc, label));
    }

    fn emit_copy(&mut self, file: FileId, text: &str, from: usize, to: usize) {
        if from >= to || self.too_big {
            return;
        }
        if self.out.text.len() + (to - from) > MAX_OUTPUT {
            self.too_big = true;
            self.err(
                Code::Limit,
                Loc::new(file, from, from + 1),
                "preprocessed output exceeds 256 MiB",
                "while copying this",
            );
            return;
        }
        let out = self.out.text.len() as u32;
        self.out.map.push(Seg {
            out,
            file,
            src: from as u32,
            src_end: to as u32,
            linear: true,
        });
        self.out.text.push_str(&text[from..to]);
    }

    fn emit_expansion(&mut self, loc: Loc, toks: &[Tok]) {
        let out = self.out.text.len() as u32;
        self.out.map.push(Seg {
            out,
            file: loc.file,
            src: loc.start,
            src_end: loc.end,
            linear: false,
        });
        for t in toks {
            self.out.text.push_str(&t.text);
        }
        // Following verbatim text starts a new segment.
        self.out.text.push(' ');
    }

    fn process(&mut self, file: FileId, depth: usize) {
        if !self.out.files.contains(&file) {
            self.out.files.push(file);
        }
        let text = self.db.get(file).text.clone();
        let bytes = text.as_bytes();
        let mut conds: Vec<Cond> = Vec::new();
        let mut pos = 0;
        self.in_comment = None;
        while pos < bytes.len() && !self.too_big {
            let line_end = memchr_nl(bytes, pos);
            let active = conds.last().is_none_or(|c| c.active);
            let trimmed = text[pos..line_end].trim_start();
            if self.in_comment.is_none() && trimmed.starts_with('#') {
                // Directive: join continuation lines.
                let mut end = line_end;
                while end > pos
                    && text[pos..end]
                        .trim_end_matches(['\n', '\r'])
                        .ends_with('\\')
                    && end < bytes.len()
                {
                    end = memchr_nl(bytes, end);
                }
                let hash = pos + (text[pos..line_end].len() - trimmed.len());
                let raw = text[hash + 1..end]
                    .replace("\\\r\n", " ")
                    .replace("\\\n", " ");
                let body = lex::strip_comments(&raw);
                let loc = Loc::new(file, hash, text[..end].trim_end().len().max(hash + 1));
                self.directive(file, &text, hash, &body, loc, &mut conds, active, depth);
                self.out.text.push('\n');
                pos = end;
                continue;
            }
            if active {
                // A macro invocation may continue on the following lines.
                pos = self.scan_line(file, &text, pos, line_end);
            } else {
                self.skip_line(&text, pos, line_end);
                pos = line_end;
            }
        }
        if let Some(start) = self.in_comment.take() {
            let end = self.out.text.len();
            let loc = self.out.map.loc(start, start + 2);
            self.out.comments.push(Comment { start, end });
            self.err(
                Code::Unterminated,
                loc,
                "unterminated block comment",
                "comment starts here",
            );
        }
        for c in conds {
            self.err(
                Code::Conditional,
                c.loc,
                "unterminated conditional directive",
                "this #if has no #endif",
            );
        }
    }

    /// Tracks block comments through inactive lines so a `#endif` inside a comment is not seen.
    fn skip_line(&mut self, text: &str, from: usize, to: usize) {
        let b = text.as_bytes();
        let mut i = from;
        while i < to {
            if self.in_comment.is_some() {
                match text[i..to].find("*/") {
                    Some(p) => {
                        i += p + 2;
                        self.in_comment = None;
                    }
                    None => return,
                }
                continue;
            }
            match b[i] {
                b'/' if b.get(i + 1) == Some(&b'/') => return,
                b'/' if b.get(i + 1) == Some(&b'*') => {
                    self.in_comment = Some(usize::MAX);
                    i += 2;
                }
                b'"' | b'\'' => i += lex::literal_len(&b[i..to]).unwrap_or(to - i),
                _ => i += 1,
            }
        }
        if self.in_comment == Some(usize::MAX) {
            // Comments in skipped text are not recorded; keep only the state.
        }
    }

    /// Copies an active line, expanding macros and recording comments. Returns where the line ended: further
    /// on than `to` when a function-like macro's arguments continue on the next lines.
    fn scan_line(&mut self, file: FileId, text: &str, from: usize, mut to: usize) -> usize {
        let b = text.as_bytes();
        let mut i = from;
        let mut copy_from = from;
        // Output offset of the source byte `j` while nothing has been flushed since `copy_from`.
        macro_rules! out_at {
            ($j:expr) => {
                self.out.text.len() + ($j - copy_from)
            };
        }
        while i < to {
            if let Some(start) = self.in_comment {
                match text[i..to].find("*/") {
                    Some(p) => {
                        i += p + 2;
                        self.in_comment = None;
                        if start != usize::MAX {
                            let end = out_at!(i);
                            self.out.comments.push(Comment { start, end });
                        }
                    }
                    None => i = to,
                }
                continue;
            }
            let c = b[i];
            if c == b'/' && b.get(i + 1) == Some(&b'/') {
                let end = if to > from && b[to - 1] == b'\n' {
                    to - 1
                } else {
                    to
                };
                let end = if end > i && b[end - 1] == b'\r' {
                    end - 1
                } else {
                    end
                };
                self.out.comments.push(Comment {
                    start: out_at!(i),
                    end: out_at!(end),
                });
                i = to;
            } else if c == b'/' && b.get(i + 1) == Some(&b'*') {
                self.in_comment = Some(out_at!(i));
                i += 2;
            } else if c == b'"' || c == b'\'' {
                match lex::literal_len(&b[i..to]) {
                    Some(n) if n > MAX_TOKEN => {
                        self.token_too_long(file, i, n);
                        return to;
                    }
                    Some(n) => i += n,
                    None => {
                        let what = if c == b'"' {
                            "string literal"
                        } else {
                            "character literal"
                        };
                        self.err(
                            Code::Unterminated,
                            Loc::new(file, i, i + 1),
                            format!("unterminated {what}"),
                            "starts here",
                        );
                        i = to;
                    }
                }
            } else if c.is_ascii_digit() {
                let n = lex::number_len(&b[i..to]);
                if n > MAX_TOKEN {
                    self.token_too_long(file, i, n);
                    return to;
                }
                i += n;
            } else if is_ident_start(c) {
                let mut j = i + 1;
                while j < to && is_ident_char(b[j]) {
                    j += 1;
                }
                if j - i > MAX_TOKEN {
                    self.token_too_long(file, i, j - i);
                    return to;
                }
                i = if self.macros.is_defined(&text[i..j]) {
                    self.expand_at(file, text, i, j, &mut to, &mut copy_from)
                } else {
                    j
                };
            } else {
                i += 1;
            }
        }
        self.emit_copy(file, text, copy_from, to);
        to
    }

    /// Expands the invocation of the macro named `text[i..j]`: copies the text before it, then its
    /// expansion. Returns where scanning goes on; `to` moves to the end of the line where a function-like
    /// macro's arguments end, and `copy_from` past the invocation.
    fn expand_at(
        &mut self,
        file: FileId,
        text: &str,
        i: usize,
        j: usize,
        to: &mut usize,
        copy_from: &mut usize,
    ) -> usize {
        let b = text.as_bytes();
        let name = &text[i..j];
        // Find the invocation's extent, then expand just that.
        let mut inv_len = name.len();
        if self.macros.defs[name].params.is_some() {
            let (rest, k, line_to) = invocation_tokens(text, i, *to);
            match k {
                Some(k) if rest[k].is("(") => match macros::collect_args(&rest, k) {
                    Ok((_, end)) => {
                        inv_len = rest[..end].iter().map(|t| t.text.len()).sum();
                        if i + inv_len > *to {
                            // Scanning goes on after the invocation, to the end of its line.
                            *to = memchr_nl(b, i + inv_len - 1).min(line_to);
                        }
                    }
                    Err(e) => {
                        self.err(Code::Macro, Loc::new(file, i, j), e, "in this invocation");
                        return j;
                    }
                },
                _ => {
                    return j;
                }
            }
        }
        let inv_end = i + inv_len;
        let inv = lex::lex(&text[i..inv_end]);
        let loc = Loc::new(file, i, inv_end);
        match self.macros.expand(&inv) {
            Ok(toks) => {
                self.emit_copy(file, text, *copy_from, i);
                self.emit_expansion(loc, &toks);
                *copy_from = inv_end;
            }
            Err(e) => self.err(Code::Macro, loc, e, "in this macro invocation"),
        }
        inv_end
    }

    fn token_too_long(&mut self, file: FileId, at: usize, len: usize) {
        self.err(
            Code::Limit,
            Loc::new(file, at, at + 16),
            format!("token of {len} bytes exceeds the {MAX_TOKEN}-byte limit"),
            "this token",
        );
        self.too_big = true;
    }

    #[allow(clippy::too_many_arguments)]
    fn directive(
        &mut self,
        file: FileId,
        text: &str,
        hash: usize,
        body: &str,
        loc: Loc,
        conds: &mut Vec<Cond>,
        active: bool,
        depth: usize,
    ) {
        let b = body.trim_start();
        let name_len = b.bytes().take_while(|c| is_ident_char(*c)).count();
        let name = &b[..name_len];
        let rest = b[name_len..].trim();
        // Location of the directive name, for carets.
        let name_off = text[hash + 1..]
            .find(name)
            .map(|p| hash + 1 + p)
            .unwrap_or(hash);
        let name_loc = Loc::new(file, name_off, name_off + name.len().max(1));
        match name {
            "if" | "ifdef" | "ifndef" => {
                let value = active && self.condition(name, rest, loc);
                conds.push(Cond {
                    active: value,
                    taken: value,
                    seen_else: false,
                    parent_active: active,
                    loc,
                });
            }
            "elif" | "else" => self.next_branch(name, rest, loc, name_loc, conds),
            "endif" => {
                if conds.pop().is_none() {
                    self.err(
                        Code::Conditional,
                        name_loc,
                        "#endif without #if",
                        "no matching #if",
                    );
                }
            }
            _ if !active => {}
            "" => {} // null directive
            "define" => {
                if let Err(e) = self.macros.define(rest) {
                    self.err(Code::Macro, loc, e, "in this definition");
                }
            }
            "undef" => {
                self.macros
                    .defs
                    .remove(rest.split_whitespace().next().unwrap_or(""));
            }
            "include" => self.include(file, rest, loc, depth),
            "error" => self.err(
                Code::ErrorDirective,
                loc,
                format!("#error {rest}"),
                "reached here",
            ),
            "warning" => self.diags.push(
                Diagnostic::warning(Code::WarningDirective, format!("#warning {rest}"))
                    .at(loc, "here"),
            ),
            "line" => self.line_directive(file, rest, loc),
            "pragma" => self.pragma(file, text, hash, rest, loc),
            _ => self.err(
                Code::BadDirective,
                name_loc,
                format!("unknown preprocessor directive `#{name}`"),
                "not a directive",
            ),
        }
    }

    /// The value of the condition of an active `#if`, `#ifdef` or `#ifndef`.
    fn condition(&mut self, name: &str, rest: &str, loc: Loc) -> bool {
        if name == "if" {
            return self.eval_cond(rest, loc);
        }
        let id: String = rest
            .bytes()
            .take_while(|c| is_ident_char(*c))
            .map(char::from)
            .collect();
        if id.is_empty() {
            self.err(
                Code::BadDirective,
                loc,
                format!("#{name} needs a macro name"),
                "here",
            );
        }
        self.macros.is_defined(&id) == (name == "ifdef")
    }

    /// `#elif` or `#else`: the innermost conditional's next branch is taken if none was before it.
    fn next_branch(&mut self, name: &str, rest: &str, loc: Loc, name_loc: Loc, conds: &mut [Cond]) {
        let Some(c) = conds.last_mut() else {
            return self.err(
                Code::Conditional,
                name_loc,
                format!("#{name} without #if"),
                "no matching #if",
            );
        };
        if c.seen_else {
            return self.err(
                Code::Conditional,
                name_loc,
                format!("#{name} after #else"),
                "unexpected here",
            );
        }
        let (parent, taken) = (c.parent_active, c.taken);
        let value = if name == "else" {
            c.seen_else = true;
            true
        } else if parent && !taken {
            self.eval_cond(rest, loc)
        } else {
            false
        };
        let c = conds.last_mut().expect("checked");
        c.active = parent && !taken && value;
        c.taken |= value;
    }

    /// `#line N ["name"]`: the next line is line `N` (of `name`) in reported positions.
    fn line_directive(&mut self, file: FileId, rest: &str, loc: Loc) {
        let mut words = rest.splitn(2, char::is_whitespace);
        let number = words
            .next()
            .filter(|n| !n.is_empty() && n.bytes().all(|c| c.is_ascii_digit()))
            .and_then(|n| n.parse::<usize>().ok());
        let Some(number) = number else {
            return self.err(Code::BadDirective, loc, "#line needs a line number", "here");
        };
        let name = words.next().map(str::trim).filter(|s| !s.is_empty());
        let name = match name {
            None => None,
            Some(n) => match n.strip_prefix('"').and_then(|n| n.strip_suffix('"')) {
                Some(n) => Some(n),
                None => {
                    return self.err(
                        Code::BadDirective,
                        loc,
                        "#line expects a file name in double quotes",
                        "here",
                    )
                }
            },
        };
        // The directive may span lines (continuations): the mark applies after its last one.
        let (last, _) = self.db.get(file).line_col(loc.end.saturating_sub(1));
        self.db.add_line_mark(file, last + 1, number, name);
    }

    fn pragma(&mut self, file: FileId, text: &str, hash: usize, rest: &str, loc: Loc) {
        let word = rest.split_whitespace().next().unwrap_or("");
        match word {
            "once" => {
                let p = self.db.get(file).path.clone();
                self.once.insert(p);
            }
            "keylist" => {
                // Hand it to the grammar, which knows the scope it appears in.
                let end = loc.end as usize;
                self.emit_copy(file, text, hash, end);
            }
            _ => self.diags.push(
                Diagnostic::warning(
                    Code::PragmaIgnored,
                    format!("unknown pragma `{word}` ignored"),
                )
                .at(loc, "ignored")
                .help("idlc understands `#pragma once` and `#pragma keylist <type> <member>...`"),
            ),
        }
    }

    fn eval_cond(&mut self, expr: &str, loc: Loc) -> bool {
        let toks = lex::lex(expr);
        // Replace defined(X) / defined X before expansion.
        let mut pre = Vec::with_capacity(toks.len());
        let mut i = 0;
        while i < toks.len() {
            if toks[i].kind == Kind::Ident && toks[i].text == "defined" {
                let sig: Vec<usize> = (i + 1..toks.len())
                    .filter(|&k| toks[k].kind != Kind::Ws)
                    .take(3)
                    .collect();
                let (name, next) = match sig.as_slice() {
                    [a, b, c, ..] if toks[*a].is("(") && toks[*c].is(")") => {
                        (toks[*b].text.clone(), c + 1)
                    }
                    [a, ..] if toks[*a].kind == Kind::Ident => (toks[*a].text.clone(), a + 1),
                    _ => {
                        self.err(
                            Code::PpExpr,
                            loc,
                            "`defined` needs a macro name",
                            "in this condition",
                        );
                        return false;
                    }
                };
                let v = if self.macros.is_defined(&name) {
                    "1"
                } else {
                    "0"
                };
                pre.push(Tok::new(Kind::Number, v));
                i = next;
            } else {
                pre.push(toks[i].clone());
                i += 1;
            }
        }
        let expanded = match self.macros.expand(&pre) {
            Ok(t) => t,
            Err(e) => {
                self.err(Code::Macro, loc, e, "in this condition");
                return false;
            }
        };
        match expr::eval(&expanded) {
            Ok(v) => v != 0,
            Err(e) => {
                self.err(Code::PpExpr, loc, e, "in this condition");
                false
            }
        }
    }

    fn include(&mut self, file: FileId, rest: &str, loc: Loc, depth: usize) {
        let Some((name, quoted)) = self.include_name(rest) else {
            return self.err(
                Code::BadDirective,
                loc,
                "#include expects \"FILE\" or <FILE>",
                "malformed include",
            );
        };
        if depth >= MAX_INCLUDE_DEPTH {
            return self.diags.push(
                Diagnostic::error(
                    Code::IncludeDepth,
                    format!("#include nested more than {MAX_INCLUDE_DEPTH} deep"),
                )
                .at(loc, "included from here")
                .help("this is usually an include cycle: add an include guard or `#pragma once`"),
            );
        }
        let Some(found) = self.find_include(file, &name, quoted, loc) else {
            return;
        };
        let found = normalize(&found);
        if self.once.contains(&found) {
            return;
        }
        let id = match self.db.find_path(&found) {
            Some(id) => id,
            None => match self.vfs.read(&found) {
                Ok(text) => self.db.add(found.display().to_string(), &found, text),
                Err(e) => {
                    return self.err(
                        Code::Io,
                        loc,
                        format!("cannot read `{}`: {e}", found.display()),
                        "included here",
                    );
                }
            },
        };
        let saved = self.in_comment.take();
        // Keep tokens of the includer and the included file apart.
        self.out.text.push('\n');
        self.out.boundaries.push(self.out.text.len());
        self.process(id, depth + 1);
        self.out.text.push('\n');
        self.out.boundaries.push(self.out.text.len());
        self.in_comment = saved;
    }

    /// The file an `#include` names (its macros expanded unless it is quoted or bracketed already), and
    /// whether it was quoted.
    fn include_name(&self, rest: &str) -> Option<(String, bool)> {
        let mut spec = rest.to_string();
        if !(spec.starts_with('"') || spec.starts_with('<')) {
            if let Ok(t) = self.macros.expand(&lex::lex(rest)) {
                spec = t
                    .iter()
                    .map(|t| t.text.as_str())
                    .collect::<String>()
                    .trim()
                    .to_string();
            }
        }
        if let Some(s) = spec.strip_prefix('"').and_then(|s| s.split('"').next()) {
            Some((s.to_string(), true))
        } else {
            let s = spec.strip_prefix('<').and_then(|s| s.split('>').next())?;
            Some((s.to_string(), false))
        }
    }

    /// Where an included file is: the including file's directory first for a quoted name, last for a
    /// bracketed one, the `-I` directories in their order. `None`, with a diagnostic, when it is nowhere.
    fn find_include(
        &mut self,
        file: FileId,
        name: &str,
        quoted: bool,
        loc: Loc,
    ) -> Option<PathBuf> {
        let cur_dir = self
            .db
            .get(file)
            .path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let mut candidates: Vec<PathBuf> = Vec::new();
        if quoted {
            candidates.push(cur_dir.join(name));
        }
        candidates.extend(self.opts.include_dirs.iter().map(|d| d.join(name)));
        if !quoted {
            candidates.push(cur_dir.join(name));
        }
        if let Some(found) = candidates.into_iter().find(|p| self.vfs.exists(p)) {
            return Some(found);
        }
        let d = Diagnostic::error(
            Code::IncludeNotFound,
            format!("cannot find include file `{name}`"),
        )
        .at(loc, "included here");
        self.diags.push(if self.opts.include_dirs.is_empty() {
            d.help("add the directory that holds it with `-I <dir>`")
        } else {
            let dirs: Vec<String> = self
                .opts
                .include_dirs
                .iter()
                .map(|d| d.display().to_string())
                .collect();
            d.help(format!(
                "searched the including file's directory and: {}",
                dirs.join(", ")
            ))
        });
        None
    }
}

/// Most lines a function-like macro's arguments may span.
const MAX_INVOCATION_LINES: usize = 64;

/// Tokens of a function-like macro invocation starting at `at` (the macro name) on the line ending at `to`: the
/// tokens up to the end of the line, extended line by line (at most [`MAX_INVOCATION_LINES`]) while the `(` or the
/// closing `)` is still missing. Returns the tokens, the index of the first token after the name that is not
/// whitespace, and the end of the last line lexed.
fn invocation_tokens(text: &str, at: usize, to: usize) -> (Vec<Tok>, Option<usize>, usize) {
    let mut line_to = to;
    let mut extra_lines = 0;
    loop {
        let rest = lex::lex(&text[at..line_to]);
        let k = rest
            .iter()
            .skip(1)
            .position(|t| t.kind != Kind::Ws)
            .map(|p| p + 1);
        let complete = match k {
            None => false,
            Some(k) => !rest[k].is("(") || macros::collect_args(&rest, k).is_ok(),
        };
        if complete || line_to >= text.len() || extra_lines == MAX_INVOCATION_LINES {
            return (rest, k, line_to);
        }
        line_to = memchr_nl(text.as_bytes(), line_to);
        extra_lines += 1;
    }
}

fn memchr_nl(b: &[u8], from: usize) -> usize {
    b[from..]
        .iter()
        .position(|&c| c == b'\n')
        .map(|p| from + p + 1)
        .unwrap_or(b.len())
}

/// Lexical normalisation (no filesystem access): removes `.` and `x/..` components.
fn normalize(p: &Path) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            c => out.push(c),
        }
    }
    out
}
