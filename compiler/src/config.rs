//! Compiling specs from a build script, in the style of `prost-build`.
//!
//! ```no_run
//! // build.rs of a crate depending on `reachc-runtime` (and on `reachc` as a build-dependency)
//! fn main() -> Result<(), Box<dyn std::error::Error>> {
//!     reachc_compiler::Config::new().compile(&["specs/pendulum.sde"])?;
//!     Ok(())
//! }
//! ```
//!
//! Each spec becomes `<OUT_DIR>/<crate name, `-` as `_`>.rs`, the generated crate's `src/lib.rs`
//! (the `System` implementation and `info()`), to include with
//! `mod pendulum { reachc_runtime::include_sde!("pendulum"); }`. cargo is told to rerun the
//! build script when a spec or a CSV table it reads changes.

use std::collections::BTreeMap;
use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::backend::{codegen, mangle, prepared};
use crate::diagnostics::render;
use crate::driver::load;
use crate::syntax::{ast::Item, parse};

/// Options for compiling specs to Rust source in a build script.
#[derive(Clone, Debug)]
pub struct Config {
    out_dir: Option<PathBuf>,
    cargo_instructions: bool,
}

impl Default for Config {
    fn default() -> Self {
        Config::new()
    }
}

/// Why [`Config::compile`] failed: the report for a user (rendered diagnostics, or an I/O
/// message). `Debug` prints the same text, so `fn main() -> Result<(), Box<dyn Error>>` in a
/// build script shows readable diagnostics.
pub struct Error {
    message: String,
}

impl Error {
    fn new(message: impl Into<String>) -> Error {
        Error {
            message: message.into(),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.message.trim_end())
    }
}

impl fmt::Debug for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Multi-line diagnostics would be unreadable as a quoted string.
        write!(f, "\n{}", self.message.trim_end())
    }
}

impl std::error::Error for Error {}

impl Config {
    /// The defaults: output to `$OUT_DIR`, print cargo instructions.
    pub fn new() -> Config {
        Config {
            out_dir: None,
            cargo_instructions: true,
        }
    }

    /// Writes the generated files to `path` instead of `$OUT_DIR`.
    pub fn out_dir(&mut self, path: impl Into<PathBuf>) -> &mut Config {
        self.out_dir = Some(path.into());
        self
    }

    /// Whether to print cargo instructions (default: yes): `cargo:rerun-if-changed=` for each
    /// spec and CSV table it reads, and a `cargo:warning=` line per warning of a spec.
    pub fn cargo_instructions(&mut self, yes: bool) -> &mut Config {
        self.cargo_instructions = yes;
        self
    }

    /// Compiles each spec to `<out_dir>/<crate name with `_`>.rs`. Paths are relative to the
    /// current directory (a build script runs in its package's directory). Stops at the first
    /// spec with errors; warnings become `cargo:warning` lines (one line each).
    pub fn compile(&self, specs: &[impl AsRef<Path>]) -> Result<(), Error> {
        let mut stdout = std::io::stdout().lock();
        self.compile_reporting(specs, &mut stdout).map(|_| ())
    }

    /// [`Config::compile`] printing the cargo instructions to `out`; returns the files written.
    fn compile_reporting(
        &self,
        specs: &[impl AsRef<Path>],
        out: &mut dyn Write,
    ) -> Result<Vec<PathBuf>, Error> {
        let out_dir = match &self.out_dir {
            Some(dir) => dir.clone(),
            None => std::env::var_os("OUT_DIR")
                .map(PathBuf::from)
                .ok_or_else(|| {
                    Error::new(
                        "error: OUT_DIR is not set (run from a build script, or call `out_dir`)",
                    )
                })?,
        };
        std::fs::create_dir_all(&out_dir)
            .map_err(|e| Error::new(format!("error: creating {}: {e}", out_dir.display())))?;
        let mut seen: BTreeMap<String, PathBuf> = BTreeMap::new();
        let mut written = Vec::new();
        for spec in specs {
            let spec = spec.as_ref();
            if self.cargo_instructions {
                for path in std::iter::once(spec.to_path_buf()).chain(csv_inputs(spec)) {
                    writeln!(out, "cargo:rerun-if-changed={}", path.display())
                        .map_err(|e| Error::new(format!("error: writing to stdout: {e}")))?;
                }
            }
            let mut loaded = load(spec).map_err(|e| Error::new(e.report(false)))?;
            let prepared = prepared(&mut loaded.model).map_err(|diags| {
                let path = loaded.path.display().to_string();
                Error::new(render(&diags, &path, &loaded.source, false))
            })?;
            if self.cargo_instructions {
                // cargo shows `cargo:warning` lines; one line per diagnostic.
                for w in loaded.warnings.iter().chain(&prepared.warnings) {
                    writeln!(out, "cargo:warning={}: {}", spec.display(), w.message)
                        .map_err(|e| Error::new(format!("error: writing to stdout: {e}")))?;
                }
            }
            let ident = mangle::crate_ident(&mangle::crate_name(&loaded.model.name));
            if let Some(other) = seen.insert(ident.clone(), spec.to_path_buf()) {
                return Err(Error::new(format!(
                    "error: {} and {} both generate `{ident}.rs` (same model name)",
                    other.display(),
                    spec.display()
                )));
            }
            let code = codegen::generate(&loaded.model, &prepared);
            let path = out_dir.join(format!("{ident}.rs"));
            // Unchanged output keeps its timestamp (no needless recompilation).
            if std::fs::read(&path).ok().as_deref() != Some(code.as_bytes()) {
                std::fs::write(&path, code)
                    .map_err(|e| Error::new(format!("error: writing {}: {e}", path.display())))?;
            }
            written.push(path);
        }
        Ok(written)
    }
}

/// The CSV files a spec reads (`table NAME = csv("...")`), resolved against its directory.
/// Best effort: an unreadable or unparsable spec gives what could be found (its errors are
/// reported by the load that follows).
fn csv_inputs(spec: &Path) -> Vec<PathBuf> {
    let Ok(source) = std::fs::read_to_string(spec) else {
        return Vec::new();
    };
    let dir = spec.parent().unwrap_or(Path::new(""));
    parse(&source)
        .0
        .items
        .iter()
        .filter_map(|item| match item {
            Item::Table { path, .. } => Some(dir.join(path)),
            _ => None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../specs")
            .join(name)
    }

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("reachc-config-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn writes_one_file_per_spec_and_rerun_lines() {
        let dir = scratch("ok");
        let mut out = Vec::new();
        let specs = [spec("pendulum.sde"), spec("unicycle.sde")];
        let written = Config::new()
            .out_dir(&dir)
            .compile_reporting(&specs, &mut out)
            .unwrap();
        let names: Vec<String> = written
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["pendulum.rs", "unicycle.rs"]);
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text
            .lines()
            .filter(|l| !l.starts_with("cargo:warning="))
            .collect();
        assert_eq!(lines.len(), 3, "{text}");
        assert!(lines[0].ends_with("pendulum.sde"));
        assert!(lines[1].ends_with("unicycle.sde"));
        assert!(lines[2].ends_with("unicycle_ref.csv"));
        assert!(lines
            .iter()
            .all(|l| l.starts_with("cargo:rerun-if-changed=")));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn spec_errors_are_rendered_diagnostics() {
        let dir = scratch("bad");
        let bad = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/bad/csv_missing.sde");
        let mut out = Vec::new();
        let err = Config::new()
            .out_dir(&dir)
            .compile_reporting(&[&bad], &mut out)
            .unwrap_err();
        let text = err.to_string();
        assert!(text.contains("error"), "{text}");
        assert!(format!("{err:?}").contains(&text));
        // The spec and its (missing) table are still watched, so fixing either reruns.
        let watched = String::from_utf8(out).unwrap();
        assert_eq!(watched.lines().count(), 2, "{watched}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn without_out_dir_or_env_it_is_an_error() {
        if std::env::var_os("OUT_DIR").is_none() {
            let err = Config::new().compile(&["x.sde"]).unwrap_err();
            assert!(err.to_string().contains("OUT_DIR"));
        }
    }
}
