//! Diagnostics: one value per problem, with a stable code, labels in source files and optional help.
//! Every stage pushes into a [`Diagnostics`] sink and carries on, so one run reports every error.
mod codes;
mod render;

pub use codes::Code;
pub use render::{render, render_all, RenderOptions};

use crate::source::Loc;

/// How bad a diagnostic is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
pub enum Severity {
    /// Reported; the output is still generated.
    Warning,
    /// No output is generated for the file.
    Error,
}

/// A marked place in the source.
#[derive(Clone, Debug)]
pub struct Label {
    /// The marked text.
    pub loc: Loc,
    /// What is said about it.
    pub message: Option<String>,
    /// The place the diagnostic is about (others add context).
    pub primary: bool,
}

/// One problem found in the input.
#[derive(Clone, Debug)]
pub struct Diagnostic {
    /// Error or warning.
    pub severity: Severity,
    /// Stable code.
    pub code: Code,
    /// One-line summary.
    pub message: String,
    /// Places in the source, the primary one first by convention.
    pub labels: Vec<Label>,
    /// How to fix it.
    pub help: Option<String>,
    /// Further explanations.
    pub notes: Vec<String>,
}

impl Diagnostic {
    /// An error, not yet located.
    pub fn error(code: Code, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Error,
            code,
            message: message.into(),
            labels: vec![],
            help: None,
            notes: vec![],
        }
    }
    /// A warning, not yet located.
    pub fn warning(code: Code, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            ..Self::error(code, message)
        }
    }
    /// The primary location, with a label text.
    pub fn at(mut self, loc: Loc, label: impl Into<String>) -> Self {
        self.labels.push(Label {
            loc,
            message: Some(label.into()),
            primary: true,
        });
        self
    }
    /// A secondary location.
    pub fn also(mut self, loc: Loc, label: impl Into<String>) -> Self {
        self.labels.push(Label {
            loc,
            message: Some(label.into()),
            primary: false,
        });
        self
    }
    /// Sets the help text.
    pub fn help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }
    /// Adds a note.
    pub fn note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }
    /// The primary label's location, else the first label's.
    pub fn primary_loc(&self) -> Option<Loc> {
        self.labels
            .iter()
            .find(|l| l.primary)
            .or(self.labels.first())
            .map(|l| l.loc)
    }
    /// Whether this is an error (not a warning).
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

/// Collects diagnostics from all stages.
#[derive(Debug, Default)]
pub struct Diagnostics {
    list: Vec<Diagnostic>,
}

impl Diagnostics {
    /// An empty sink.
    pub fn new() -> Self {
        Self::default()
    }
    /// Adds a diagnostic (beyond 1000, further ones are dropped).
    pub fn push(&mut self, d: Diagnostic) {
        // Cap the count so hostile input cannot make us build millions of reports.
        if self.list.len() < 1000 {
            self.list.push(d);
        }
    }
    /// Whether any diagnostic is an error.
    pub fn has_errors(&self) -> bool {
        self.list.iter().any(|d| d.is_error())
    }
    /// How many diagnostics are errors.
    pub fn error_count(&self) -> usize {
        self.list.iter().filter(|d| d.is_error()).count()
    }
    /// The diagnostics in the order pushed (or sorted, after [`Diagnostics::sort`]).
    pub fn iter(&self) -> impl Iterator<Item = &Diagnostic> {
        self.list.iter()
    }
    /// The diagnostics as a vector.
    pub fn into_vec(self) -> Vec<Diagnostic> {
        self.list
    }
    /// Moves every diagnostic of `other` in.
    pub fn extend(&mut self, other: Diagnostics) {
        for d in other.list {
            self.push(d);
        }
    }
    /// Sorted by file and position, errors of one place before warnings; stable output for tests.
    pub fn sort(&mut self) {
        self.list.sort_by_key(|d| {
            d.primary_loc()
                .map(|l| (l.file, l.start))
                .unwrap_or_default()
        });
    }
}

/// "did you mean" suggestion among candidate names (Jaro-Winkler, as rustc does with Levenshtein).
pub fn suggest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let mut best: Option<(&str, f64)> = None;
    for c in candidates {
        if c == name {
            continue;
        }
        let score = if c.eq_ignore_ascii_case(name) {
            1.0
        } else {
            strsim::jaro_winkler(name, c)
        };
        let lev = strsim::levenshtein(&name.to_ascii_lowercase(), &c.to_ascii_lowercase());
        if (score >= 0.85 || lev <= (name.len().max(3) / 3)) && best.is_none_or(|(_, s)| score > s)
        {
            best = Some((c, score));
        }
    }
    best.map(|(c, _)| c)
}
