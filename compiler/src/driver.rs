//! Reading a spec from disk through parsing and checking: the front end as one call, shared by
//! the CLI and by library users (build scripts, tests).

use std::path::{Path, PathBuf};

use crate::diagnostics::{has_errors, render, Diagnostic};
use crate::limits::MAX_SOURCE_LEN;
use crate::model::{check, Model};
use crate::syntax::parse;

/// Why a spec could not be loaded.
#[derive(Debug)]
pub enum LoadError {
    /// The file could not be read (exit code 2).
    Io(String),
    /// The spec has errors (exit code 1).
    Spec {
        /// Every diagnostic, errors and warnings.
        diagnostics: Vec<Diagnostic>,
        /// The spec's path as given (for the report).
        path: String,
        /// The spec's text (for the report).
        source: String,
    },
}

impl LoadError {
    /// The report for a user: the I/O message, or the diagnostics rendered with ariadne.
    pub fn report(&self, color: bool) -> String {
        match self {
            LoadError::Io(msg) => format!("error: {msg}\n"),
            LoadError::Spec {
                diagnostics,
                path,
                source,
            } => render(diagnostics, path, source, color),
        }
    }
}

impl std::fmt::Display for LoadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.report(false))
    }
}

impl std::error::Error for LoadError {}

/// A loaded spec: the model, its source, and any warnings.
#[derive(Debug)]
pub struct Loaded {
    /// The checked model.
    pub model: Model,
    /// The spec's path as given.
    pub path: PathBuf,
    /// The spec's text.
    pub source: String,
    /// Warnings (the spec has no errors).
    pub warnings: Vec<Diagnostic>,
}

impl Loaded {
    /// The SHA-256 of the spec's source, in hex: its identity in the parts of a sharded
    /// `reachc simulate` (parts of different sources do not merge).
    pub fn source_hash(&self) -> String {
        let mut h = crate::package::sha256::Sha256::new();
        h.update(self.source.as_bytes());
        h.finish_hex()
    }
}

/// Parses and checks spec text; CSV paths are resolved against `dir`.
/// Syntax errors stop before checking (a partial tree would give misleading follow-up errors).
pub fn check_source(source: &str, dir: &Path) -> (Option<Model>, Vec<Diagnostic>) {
    let (spec, diags) = parse(source);
    if has_errors(&diags) {
        return (None, diags);
    }
    let (model, mut more) = check(&spec, dir);
    let mut all = diags;
    all.append(&mut more);
    (model, all)
}

/// The bytes of the file at `path`, or `None` if it has more than `cap` bytes. Reads at most
/// `cap + 1` bytes, so a special file (`/dev/zero`, a FIFO fed forever) cannot exhaust memory.
pub(crate) fn read_capped(path: &Path, cap: usize) -> std::io::Result<Option<Vec<u8>>> {
    use std::io::Read;
    let mut bytes = Vec::new();
    let limit = u64::try_from(cap).map_or(u64::MAX, |c| c.saturating_add(1));
    std::fs::File::open(path)?
        .take(limit)
        .read_to_end(&mut bytes)?;
    Ok((bytes.len() <= cap).then_some(bytes))
}

/// A spec error at the first invalid byte of `bytes` (rendered over the text with invalid bytes
/// replaced, which is the same text up to that byte, so line and column are right).
fn not_utf8(path: &Path, bytes: &[u8], e: std::str::Utf8Error) -> LoadError {
    let at = e.valid_up_to();
    let source = String::from_utf8_lossy(bytes).into_owned();
    let d = Diagnostic::error(
        "the spec is not UTF-8 text",
        at..at + char::REPLACEMENT_CHARACTER.len_utf8(),
        format!("invalid byte 0x{:02x} (offset {at})", bytes[at]),
    )
    .with_help("save the file as UTF-8");
    LoadError::Spec {
        diagnostics: vec![d],
        path: path.display().to_string(),
        source,
    }
}

/// Reads, parses and checks the spec at `path`.
pub fn load(path: &Path) -> Result<Loaded, LoadError> {
    let bytes = read_capped(path, MAX_SOURCE_LEN)
        .map_err(|e| LoadError::Io(format!("cannot read {}: {e}", path.display())))?;
    let Some(bytes) = bytes else {
        return Err(LoadError::Spec {
            diagnostics: vec![crate::syntax::too_large()],
            path: path.display().to_string(),
            source: String::new(),
        });
    };
    let source =
        String::from_utf8(bytes).map_err(|e| not_utf8(path, e.as_bytes(), e.utf8_error()))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let (model, diagnostics) = check_source(&source, dir);
    match model {
        Some(model) => Ok(Loaded {
            model,
            path: path.to_path_buf(),
            source,
            warnings: diagnostics,
        }),
        None => Err(LoadError::Spec {
            diagnostics,
            path: path.display().to_string(),
            source,
        }),
    }
}
