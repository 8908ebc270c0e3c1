//! Rendering through miette. With the `fancy` feature (on for the command line): a snippet of the right
//! file, carets, labels, help and the code. Without it (`build.rs` use): the same facts as plain sentences.
use super::{Diagnostic, Severity};
use crate::source::{FileId, SourceDb};
use miette::{LabeledSpan, MietteError, MietteSpanContents, SourceCode, SourceSpan, SpanContents};
use std::fmt;

/// How diagnostics are drawn.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    /// ANSI colours (only with the `fancy` feature).
    pub color: bool,
    /// Line width to wrap messages at (only with the `fancy` feature).
    pub width: usize,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            color: false,
            width: 100,
        }
    }
}

struct Report<'a> {
    diag: &'a Diagnostic,
    source: Option<PresumedSource<'a>>,
    file: Option<FileId>,
    help: Option<String>,
}

/// A file's text as `#line` directives present it: each snippet carries the presumed file name, and its
/// line numbers are shifted to the presumed line of the snippet's first line.
struct PresumedSource<'a> {
    db: &'a SourceDb,
    file: FileId,
}

impl SourceCode for PresumedSource<'_> {
    fn read_span<'b>(
        &'b self,
        span: &SourceSpan,
        before: usize,
        after: usize,
    ) -> Result<Box<dyn SpanContents<'b> + 'b>, MietteError> {
        let text: &'b str = &self.db.get(self.file).text;
        let inner = text.read_span(span, before, after)?;
        let start = u32::try_from(inner.span().offset()).unwrap_or(u32::MAX);
        let (name, line, _) = self.db.presumed(self.file, start);
        Ok(Box::new(MietteSpanContents::new_named(
            name.to_string(),
            inner.data(),
            *inner.span(),
            line.saturating_sub(1),
            inner.column(),
            inner.line_count(),
        )))
    }
}

impl fmt::Debug for Report<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.diag.message)
    }
}
impl fmt::Display for Report<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.diag.message)
    }
}
impl std::error::Error for Report<'_> {}

impl miette::Diagnostic for Report<'_> {
    fn code<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        Some(Box::new(self.diag.code.as_str()))
    }
    fn severity(&self) -> Option<miette::Severity> {
        Some(match self.diag.severity {
            Severity::Error => miette::Severity::Error,
            Severity::Warning => miette::Severity::Warning,
        })
    }
    fn help<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.help
            .as_ref()
            .map(|h| Box::new(h) as Box<dyn fmt::Display>)
    }
    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        self.source.as_ref().map(|s| s as &dyn SourceCode)
    }
    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        let file = self.file?;
        Some(Box::new(
            self.diag
                .labels
                .iter()
                .filter(move |l| l.loc.file == file)
                .map(|l| {
                    let span = (l.loc.start as usize, l.loc.len());
                    if l.primary {
                        LabeledSpan::new_primary_with_span(l.message.clone(), span)
                    } else {
                        LabeledSpan::new_with_span(l.message.clone(), span)
                    }
                }),
        ))
    }
}

/// Renders one diagnostic as text.
pub fn render(db: &SourceDb, diag: &Diagnostic, opts: RenderOptions) -> String {
    let file = diag.primary_loc().map(|l| l.file);
    let source = file.map(|file| PresumedSource { db, file });
    // Labels in other files cannot share a snippet: say where they are instead.
    let mut extra: Vec<String> = diag
        .labels
        .iter()
        .filter(|l| Some(l.loc.file) != file)
        .map(|l| {
            format!(
                "note: {} at {}",
                l.message.as_deref().unwrap_or("see"),
                db.describe(l.loc)
            )
        })
        .collect();
    extra.extend(diag.notes.iter().map(|n| format!("note: {n}")));
    let help = match (&diag.help, extra.is_empty()) {
        (Some(h), true) => Some(h.clone()),
        (Some(h), false) => Some(format!("{h}\n{}", extra.join("\n"))),
        (None, false) => Some(extra.join("\n")),
        (None, true) => None,
    };
    let report = Report {
        diag,
        source,
        file,
        help,
    };
    let mut out = String::new();
    if draw(&mut out, &report, opts).is_err() {
        out = format!("{}: {}", diag.code.as_str(), diag.message);
    }
    out
}

#[cfg(feature = "fancy")]
fn draw(out: &mut String, report: &Report<'_>, opts: RenderOptions) -> fmt::Result {
    use miette::{GraphicalReportHandler, GraphicalTheme};
    let theme = if opts.color {
        GraphicalTheme::unicode()
    } else {
        GraphicalTheme::unicode_nocolor()
    };
    GraphicalReportHandler::new_themed(theme)
        .with_width(opts.width)
        .with_links(false)
        .render_report(out, report)
}

#[cfg(not(feature = "fancy"))]
fn draw(out: &mut String, report: &Report<'_>, _opts: RenderOptions) -> fmt::Result {
    miette::NarratableReportHandler::new().render_report(out, report)
}

/// Renders several diagnostics, separated by blank lines.
pub fn render_all<'a>(
    db: &SourceDb,
    diags: impl IntoIterator<Item = &'a Diagnostic>,
    opts: RenderOptions,
) -> String {
    diags
        .into_iter()
        .map(|d| render(db, d, opts))
        .collect::<Vec<_>>()
        .join("\n")
}
