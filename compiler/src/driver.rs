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

/// Why [`read_capped`] returned no bytes.
#[derive(Debug)]
pub(crate) enum ReadError {
    /// The file could not be opened or read.
    Io(std::io::Error),
    /// The path names something other than a regular file (what it is, e.g. "a FIFO").
    NotRegular(&'static str),
    /// The file has more bytes than the cap.
    TooLarge,
}

/// What a non-regular file is, for the message that refuses it.
fn kind_of(t: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "an unknown kind of file"
    }
}

/// Opens `path` for reading without waiting: on unix with `O_NONBLOCK`, so that opening a FIFO
/// with no writer returns at once (the handle's type is checked before anything is read).
fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    options.open(path)
}

/// The bytes of the regular file at `path`, at most `cap` of them. Anything but a regular file
/// (a FIFO, a device, a directory) is refused before a byte is read: the file is opened without
/// blocking and its handle's type checked (`fstat`, so the file checked is the file read). Reads
/// at most `cap + 1` bytes.
pub(crate) fn read_capped(path: &Path, cap: usize) -> Result<Vec<u8>, ReadError> {
    use std::io::Read;
    let file = open_nonblocking(path).map_err(ReadError::Io)?;
    let kind = file.metadata().map_err(ReadError::Io)?.file_type();
    if !kind.is_file() {
        return Err(ReadError::NotRegular(kind_of(kind)));
    }
    let mut bytes = Vec::new();
    let limit = u64::try_from(cap).map_or(u64::MAX, |c| c.saturating_add(1));
    file.take(limit)
        .read_to_end(&mut bytes)
        .map_err(ReadError::Io)?;
    if bytes.len() > cap {
        return Err(ReadError::TooLarge);
    }
    Ok(bytes)
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
    let bytes = match read_capped(path, MAX_SOURCE_LEN) {
        Ok(bytes) => bytes,
        Err(ReadError::Io(e)) => {
            return Err(LoadError::Io(format!(
                "cannot read {}: {e}",
                path.display()
            )))
        }
        Err(ReadError::NotRegular(kind)) => {
            return Err(LoadError::Io(format!(
                "cannot read {}: not a regular file ({kind}); give the path of a .sde file",
                path.display()
            )))
        }
        Err(ReadError::TooLarge) => {
            return Err(LoadError::Spec {
                diagnostics: vec![crate::syntax::too_large()],
                path: path.display().to_string(),
                source: String::new(),
            })
        }
    };
    let source =
        String::from_utf8(bytes).map_err(|e| not_utf8(path, e.as_bytes(), e.utf8_error()))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    load_source(path, source, dir)
}

/// Parses and checks spec text that the caller already has (a string from Python, an editor
/// buffer): `path` names it in the diagnostics and in [`Loaded::path`], CSV paths are resolved
/// against `dir`. Text longer than the limit of [`load`] is the same spec error.
pub fn load_source(path: &Path, source: String, dir: &Path) -> Result<Loaded, LoadError> {
    if source.len() > MAX_SOURCE_LEN {
        return Err(LoadError::Spec {
            diagnostics: vec![crate::syntax::too_large()],
            path: path.display().to_string(),
            source: String::new(),
        });
    }
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
