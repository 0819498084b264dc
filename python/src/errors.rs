//! Diagnostics, errors and signals as Python sees them.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use reachc_compiler::diagnostics::{Diagnostic as Diag, Severity};
use reachc_compiler::driver::LoadError;
use reachc_runtime::engine::RunError;

use crate::{AnalysisError, SpecError};

/// One diagnostic of a spec: its severity, message, and where (1-based line and column of its
/// primary span, in characters; end exclusive).
#[pyclass(module = "reachc._native", frozen, get_all)]
#[derive(Clone)]
pub(crate) struct Diagnostic {
    severity: String,
    message: String,
    line: usize,
    column: usize,
    end_line: usize,
    end_column: usize,
    label: String,
    help: Option<String>,
    notes: Vec<String>,
}

#[pymethods]
impl Diagnostic {
    fn __repr__(&self) -> String {
        format!(
            "Diagnostic({}, {}:{}: {})",
            self.severity, self.line, self.column, self.message
        )
    }
}

/// 1-based line and column (in characters) of byte `at` of `src`.
fn line_col(src: &str, at: usize) -> (usize, usize) {
    let at = at.min(src.len());
    let at = (0..=at)
        .rev()
        .find(|&i| src.is_char_boundary(i))
        .unwrap_or(0);
    let before = &src[..at];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[start..].chars().count() + 1)
}

pub(crate) fn diagnostic(d: &Diag, src: &str) -> Diagnostic {
    let span = d.span();
    let (line, column) = line_col(src, span.start);
    let (end_line, end_column) = line_col(src, span.end);
    Diagnostic {
        severity: match d.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        }
        .into(),
        message: d.message.clone(),
        line,
        column,
        end_line,
        end_column,
        label: d
            .labels
            .first()
            .map(|l| l.message.clone())
            .unwrap_or_default(),
        help: d.help.clone(),
        notes: d.notes.clone(),
    }
}

pub(crate) fn load_error(py: Python<'_>, e: LoadError) -> PyErr {
    match &e {
        LoadError::Io(msg) => pyo3::exceptions::PyOSError::new_err(msg.clone()),
        LoadError::Spec {
            diagnostics,
            source,
            ..
        } => {
            let err = SpecError::new_err(e.report(false));
            let items: Vec<Diagnostic> =
                diagnostics.iter().map(|d| diagnostic(d, source)).collect();
            if let Err(set) = err.value(py).setattr("diagnostics", items) {
                return set;
            }
            err
        }
    }
}

pub(crate) fn run_error(e: RunError) -> PyErr {
    match e {
        RunError::UnknownAnalysis { .. } => PyValueError::new_err(e.to_string()),
        e => AnalysisError::new_err(e.to_string()),
    }
}

/// Keeps signals (Ctrl-C) pending in the interpreter from a thread without the GIL: returns the
/// error to raise.
pub(crate) fn pending_signal() -> Option<PyErr> {
    Python::attach(|py| py.check_signals().err())
}

/// The payload of the unwinding that stops a simulation on a signal.
pub(crate) struct Interrupted(pub(crate) PyErr);
