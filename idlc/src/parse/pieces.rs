//! Parse once per run: the translation unit is cut where an included file begins or ends, and each piece's
//! syntax tree is cached under the piece's exact preprocessed form.
//!
//! # Why the key is the preprocessed piece
//!
//! One file can preprocess differently each time it is included (other macros defined, another branch of an
//! `#if` taken, an include guard already set), so its path is no key. The key here is what the parser sees: the
//! piece's text, its source map (relative to the piece) and its comments. Equal keys give equal syntax trees with
//! equal source locations, because every location comes from that map, and file ids are stable for the whole
//! session (one [`crate::source::SourceDb`]). Preprocessing itself still runs for every input; it is a small
//! share of the time next to parsing. Diagnostics the tree builder emits for a piece are stored with it and
//! replayed on every hit, so a cached run reports exactly what an uncached one does.
//!
//! # Where the text is cut
//!
//! Only at [`Output::boundaries`] that fall outside any `{}` (so between definitions) and that no comment directly
//! precedes (a doc comment before an `#include` documents the first definition after it; other
//! comments end the search for doc comments, so they do not matter). If any piece does not
//! parse on its own, the whole text is parsed in one go instead, which also gives the usual syntax error.
use super::{build, IdlParser, Rule};
use crate::ast::Spec;
use crate::diag::{Diagnostic, Diagnostics};
use crate::preprocess::{Comment, Output};
use pest::Parser as _;
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::Arc;

/// Syntax trees of the pieces parsed so far in one session, by their preprocessed form.
#[derive(Debug, Default)]
pub struct ParseCache {
    pieces: HashMap<PieceKey, Piece>,
}

#[derive(Debug)]
struct Piece {
    spec: Arc<Spec>,
    /// What building the tree reported (warnings such as legacy `//@key`).
    diags: Vec<Diagnostic>,
}

/// A piece of preprocessed output, with offsets relative to its start.
#[derive(Debug)]
struct PieceKey(Output);

impl PartialEq for PieceKey {
    fn eq(&self, other: &Self) -> bool {
        self.0.text == other.0.text
            && self.0.map == other.0.map
            && self.0.comments == other.0.comments
    }
}

impl Eq for PieceKey {}

impl Hash for PieceKey {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.0.text.hash(state);
        self.0.map.hash(state);
        self.0.comments.hash(state);
    }
}

impl ParseCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of distinct pieces held.
    pub fn len(&self) -> usize {
        self.pieces.len()
    }

    /// No piece held yet.
    pub fn is_empty(&self) -> bool {
        self.pieces.is_empty()
    }

    /// The trees of every piece of `pp`, in order, parsing only pieces not seen before; `None` when a piece does
    /// not parse on its own (the caller then parses the whole text).
    pub(super) fn parse_pieces(
        &mut self,
        pp: &Output,
        diags: &mut Diagnostics,
    ) -> Option<Vec<Arc<Spec>>> {
        let cuts = cut_points(pp);
        let mut specs = Vec::with_capacity(cuts.len() + 1);
        let mut found = Vec::new();
        let mut start = 0;
        for end in cuts.into_iter().chain([pp.text.len()]) {
            if pp.text[start..end].trim().is_empty() {
                start = end;
                continue;
            }
            let key = PieceKey(sub_output(pp, start, end));
            let piece = match self.pieces.get(&key) {
                Some(p) => p,
                None => {
                    let piece = parse_piece(&key.0)?;
                    self.pieces.entry(key).or_insert(piece)
                }
            };
            specs.push(piece.spec.clone());
            found.extend(piece.diags.iter().cloned());
            start = end;
        }
        for d in found {
            diags.push(d);
        }
        Some(specs)
    }
}

fn parse_piece(pp: &Output) -> Option<Piece> {
    let mut pairs = IdlParser::parse(Rule::specification, &pp.text).ok()?;
    let mut d = Diagnostics::new();
    let spec = build::Builder::new(pp, &mut d).specification(pairs.next()?);
    Some(Piece {
        spec: Arc::new(spec),
        diags: d.into_vec(),
    })
}

/// The part `start..end` of `pp` as an output of its own.
fn sub_output(pp: &Output, start: usize, end: usize) -> Output {
    let from = pp.comments.partition_point(|c| c.start < start);
    let comments = pp.comments[from..]
        .iter()
        .take_while(|c| c.start < end)
        .map(|c| Comment {
            start: c.start - start,
            end: c.end.min(end) - start,
        })
        .collect();
    Output {
        text: pp.text[start..end].to_string(),
        map: pp.map.slice(start, end),
        comments,
        files: vec![],
        boundaries: vec![],
    }
}

/// The boundaries of `pp` where the text may be cut: outside braces, and not right after a comment.
fn cut_points(pp: &Output) -> Vec<usize> {
    let depths = brace_depths(&pp.text, &pp.boundaries);
    let mut cuts: Vec<usize> = Vec::with_capacity(depths.len());
    for (&at, depth) in pp.boundaries.iter().zip(depths) {
        let i = pp.comments.partition_point(|c| c.end <= at);
        let after_doc = i > 0 && {
            let c = &pp.comments[i - 1];
            let body = &pp.text[c.start..c.end];
            (body.starts_with("/**") || body.starts_with("///"))
                && pp.text[c.end..at].trim().is_empty()
        };
        if depth == 0 && !after_doc && cuts.last().is_none_or(|&c| c < at) {
            cuts.push(at);
        }
    }
    cuts
}

/// The `{}` nesting depth at each of `offsets` (ascending), skipping comments and literals.
fn brace_depths(text: &str, offsets: &[usize]) -> Vec<usize> {
    let b = text.as_bytes();
    let mut out = Vec::with_capacity(offsets.len());
    let mut next = offsets.iter().peekable();
    let mut depth = 0usize;
    let mut i = 0;
    loop {
        while let Some(&&o) = next.peek() {
            if o > i {
                break;
            }
            // Inside a comment or literal that spans the offset, any depth but 0 prevents the cut.
            out.push(if o == i { depth } else { usize::MAX });
            next.next();
        }
        if i >= b.len() {
            break;
        }
        i = match b[i] {
            b'/' if b.get(i + 1) == Some(&b'/') => b[i..]
                .iter()
                .position(|&c| c == b'\n')
                .map_or(b.len(), |p| i + p),
            b'/' if b.get(i + 1) == Some(&b'*') => {
                text[i + 2..].find("*/").map_or(b.len(), |p| i + 2 + p + 2)
            }
            q @ (b'"' | b'\'') => {
                let mut j = i + 1;
                while j < b.len() && b[j] != q && b[j] != b'\n' {
                    j += if b[j] == b'\\' { 2 } else { 1 };
                }
                (j + 1).min(b.len())
            }
            c => {
                match c {
                    b'{' => depth += 1,
                    b'}' => depth = depth.saturating_sub(1),
                    _ => {}
                }
                i + 1
            }
        };
    }
    out
}

#[cfg(test)]
mod tests {
    use super::brace_depths;

    #[test]
    fn depths_skip_comments_and_literals() {
        let t = "a { \"}\" /* } */ b } c";
        assert_eq!(brace_depths(t, &[0, 3, 18, 20]), vec![0, 1, 1, 0]);
        assert_eq!(brace_depths(t, &[10]), vec![usize::MAX]);
    }
}
