//! Diagnostics: every error the compiler reports, with source spans, rendered with ariadne.

use std::ops::Range;

/// A byte range in the spec source.
pub type Span = Range<usize>;

/// How bad a diagnostic is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Severity {
    /// The spec cannot be used.
    Error,
    /// The spec can be used but something looks wrong.
    Warning,
}

/// A span with a message attached, shown under the source line.
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    /// Where.
    pub span: Span,
    /// What to say there (may be empty).
    pub message: String,
}

/// One problem found in a spec.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    /// Error or warning.
    pub severity: Severity,
    /// One line: what is wrong.
    pub message: String,
    /// The primary label first, then secondary ones (e.g. the earlier definition of a duplicate).
    pub labels: Vec<Label>,
    /// How to fix it, if we can say.
    pub help: Option<String>,
    /// Further context.
    pub notes: Vec<String>,
}

impl Diagnostic {
    /// An error with a primary span and label text.
    pub fn error(message: impl Into<String>, span: Span, label: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Error,
            message: message.into(),
            labels: vec![Label {
                span,
                message: label.into(),
            }],
            help: None,
            notes: Vec::new(),
        }
    }

    /// A warning with a primary span and label text.
    pub fn warning(message: impl Into<String>, span: Span, label: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            ..Diagnostic::error(message, span, label)
        }
    }

    /// Adds a secondary label.
    pub fn with_label(mut self, span: Span, message: impl Into<String>) -> Self {
        self.labels.push(Label {
            span,
            message: message.into(),
        });
        self
    }

    /// Sets the help line.
    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    /// Adds a note.
    pub fn with_note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    /// The primary span (of the first label).
    pub fn span(&self) -> Span {
        self.labels.first().map_or(0..0, |l| l.span.clone())
    }
}

/// True if any diagnostic is an error.
pub fn has_errors(diags: &[Diagnostic]) -> bool {
    diags.iter().any(|d| d.severity == Severity::Error)
}

/// Renders diagnostics for the source `src` named `path`, in source order.
/// `color` selects ANSI colours (off for tests and pipes).
pub fn render(diags: &[Diagnostic], path: &str, src: &str, color: bool) -> String {
    use ariadne::{Config, IndexType, Label as ALabel, Report, ReportKind, Source};
    let mut out = Vec::new();
    let mut sorted: Vec<&Diagnostic> = diags.iter().collect();
    sorted.sort_by_key(|d| d.span().start);
    // Spans past the end (e.g. "unexpected end of file") are clamped so ariadne can show them.
    let clamp = |s: &Span| s.start.min(src.len())..s.end.min(src.len()).max(s.start.min(src.len()));
    for d in sorted {
        let kind = match d.severity {
            Severity::Error => ReportKind::Error,
            Severity::Warning => ReportKind::Warning,
        };
        let primary = clamp(&d.span());
        let mut report = Report::build(kind, (path, primary.clone()))
            // Spans are byte offsets (ariadne counts chars unless told).
            .with_config(
                Config::default()
                    .with_color(color)
                    .with_index_type(IndexType::Byte),
            )
            .with_message(&d.message);
        for (i, l) in d.labels.iter().enumerate() {
            let mut label = ALabel::new((path, clamp(&l.span)));
            if !l.message.is_empty() {
                label = label.with_message(&l.message);
            }
            if i == 0 && color {
                label = label.with_color(ariadne::Color::Red);
            }
            report = report.with_label(label.with_order(i as i32));
        }
        if let Some(h) = &d.help {
            report = report.with_help(h);
        }
        for n in &d.notes {
            report = report.with_note(n);
        }
        report
            .finish()
            .write((path, Source::from(src)), &mut out)
            .expect("writing to a Vec cannot fail");
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The byte span of the `n`th (0-based) occurrence of `needle` in `src` (for tests of spans).
#[cfg(test)]
pub(crate) fn span_of(src: &str, needle: &str, n: usize) -> Span {
    let start = src
        .match_indices(needle)
        .nth(n)
        .unwrap_or_else(|| panic!("{needle:?} not in {src:?}"))
        .0;
    start..start + needle.len()
}
