//! Writing a generated crate to disk (`reachc build`, and the crates of reachc's cache).
//!
//! A generated crate never names an absolute path: it depends on the runtime by a relative
//! path, either to its own copy under `vendor/` ([`RuntimeDep::Vendored`], `reachc build`: the
//! directory stands alone and can be moved or copied elsewhere) or to a runtime shared by several
//! crates ([`RuntimeDep::Shared`], reachc's cache). See the [module documentation](super) for
//! the layout.
//!
//! The bytes depend only on the spec, the reachc version and where the runtime is relative to
//! the crate (no timestamps), so writing the same spec twice gives identical files. Writing is
//! atomic and lazy: a crate whose files already have the right bytes is left untouched
//! (timestamps included, so cargo has nothing to rebuild); otherwise the whole crate is written
//! to a fresh sibling directory that is renamed over the old one, which is removed only after
//! that. Any failure leaves the old crate untouched.

use std::borrow::Cow;
use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

use super::embedded::{runtime_files, workspace_lock, InstalledRuntime, RUNTIME_CRATE};
use super::{fsutil, lock, BuildError, MARKER};
use crate::backend::{codegen, mangle, prepared};
use crate::diagnostics::Diagnostic;
use crate::driver::Loaded;
use crate::model::Model;

/// The directory of a vendored runtime inside a generated crate.
pub const VENDOR_DIR: &str = "vendor";

/// Where a generated crate finds the runtime.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum RuntimeDep {
    /// Its own copy of the embedded runtime, `vendor/reachc-runtime` and `vendor/reachc-core`:
    /// the crate builds anywhere with plain cargo (the default).
    #[default]
    Vendored,
    /// A runtime outside the crate, shared with other crates (one build of the runtime for all
    /// of them): the path of its `reachc-runtime` crate relative to the crate's directory,
    /// `/`-separated (see [`RuntimeDep::shared`]).
    Shared(String),
}

impl RuntimeDep {
    /// The runtime `runtime` (see [`super::install_runtime`]) for a crate written at
    /// `crate_dir`.
    pub fn shared(runtime: &InstalledRuntime, crate_dir: &Path) -> Result<RuntimeDep, BuildError> {
        RuntimeDep::shared_crate(&runtime.runtime_crate(), crate_dir)
    }

    /// The `reachc-runtime` crate at `runtime_crate` (installed or about to be) for a crate
    /// written at `crate_dir`.
    pub(super) fn shared_crate(
        runtime_crate: &Path,
        crate_dir: &Path,
    ) -> Result<RuntimeDep, BuildError> {
        let rel = fsutil::relative_path(crate_dir, runtime_crate).ok_or_else(|| {
            BuildError::io(
                format!("referring to the runtime from {}", crate_dir.display()),
                std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    format!("no relative path to {}", runtime_crate.display()),
                ),
            )
        })?;
        Ok(RuntimeDep::Shared(rel.to_string_lossy().replace('\\', "/")))
    }
}

/// How a crate is written.
#[derive(Clone, Debug, Default)]
pub struct CrateOptions {
    /// Where the runtime comes from.
    pub runtime: RuntimeDep,
    /// The spec as named in the README (e.g. `specs/pendulum.sde`); the model name if `None`.
    pub spec_label: Option<String>,
    /// How `src/lib.rs` is generated (how large methods are split).
    pub codegen: codegen::Options,
}

/// The files of a generated crate, in memory.
#[derive(Clone, Debug, PartialEq)]
pub struct CrateFiles {
    /// The package name (`mangle::crate_name` of the model).
    pub crate_name: String,
    /// The Rust type implementing `System` in `src/lib.rs`.
    pub type_name: String,
    /// The generated files, `(path relative to the crate root, contents)` with `/`-separated
    /// paths, in a fixed order: `Cargo.toml`, `README.md`, `src/lib.rs`, `src/main.rs`.
    pub files: Vec<(String, String)>,
    /// Whether the embedded runtime is copied under `vendor/`.
    pub vendored: bool,
    /// The `Cargo.lock` written with a new crate (see [`lock::crate_lock`]); cargo owns it
    /// afterwards, so it is not compared when deciding whether a crate is up to date.
    pub lock: Option<String>,
    /// Warnings from preparing the model (e.g. an analysis whose constants are unbounded).
    pub warnings: Vec<Diagnostic>,
}

impl CrateFiles {
    /// The contents of the generated file at `path` (relative, `/`-separated).
    pub fn get(&self, path: &str) -> Option<&str> {
        self.files
            .iter()
            .find(|(p, _)| p == path)
            .map(|(_, c)| c.as_str())
    }

    /// Every file reachc owns in the crate, `(relative path, bytes)`: the generated files, then
    /// the vendored runtime (if any). `Cargo.lock` is not among them.
    pub fn owned_files(&self) -> Vec<(Cow<'_, str>, &[u8])> {
        let mut out: Vec<(Cow<'_, str>, &[u8])> = self
            .files
            .iter()
            .map(|(p, c)| (Cow::Borrowed(p.as_str()), c.as_bytes()))
            .collect();
        if self.vendored {
            out.extend(
                runtime_files().map(|f| (Cow::Owned(format!("{VENDOR_DIR}/{}", f.path)), f.bytes)),
            );
        }
        out
    }
}

/// A crate written to disk.
#[derive(Clone, Debug, PartialEq)]
pub struct WrittenCrate {
    /// The crate's root directory (as given to [`write_crate`]).
    pub dir: PathBuf,
    /// The package name, which is also the binary's name.
    pub crate_name: String,
    /// The Rust type implementing `System`.
    pub type_name: String,
    /// The generated files, relative to `dir` (the vendored runtime is not listed).
    pub files: Vec<PathBuf>,
    /// Whether the runtime was vendored under `vendor/`.
    pub vendored: bool,
    /// Whether anything was written: `false` when the crate on disk already had these bytes.
    pub changed: bool,
    /// Warnings from preparing the model, to show the user with the spec's source.
    pub warnings: Vec<Diagnostic>,
}

/// Generates the files of the crate for `model` (prepared here; the model's pool grows by the
/// derivatives). Deterministic: the same model and options give the same bytes.
pub fn generate_files(
    model: &mut Model,
    options: &CrateOptions,
) -> Result<CrateFiles, Vec<Diagnostic>> {
    let prepared = prepared(model)?;
    let crate_name = mangle::crate_name(&model.name);
    let type_name = mangle::type_name(&model.name);
    let crate_ident = mangle::crate_ident(&crate_name);
    let runtime = match &options.runtime {
        RuntimeDep::Vendored => Runtime::Vendored,
        RuntimeDep::Shared(path) => Runtime::Shared(path.clone()),
    };
    let spec_label = options
        .spec_label
        .clone()
        .unwrap_or_else(|| format!("model `{}`", model.name));
    let lib = codegen::generate_with(model, &prepared, &options.codegen);
    let main = codegen::main_rs(&crate_ident, &type_name);
    let analyses: Vec<&str> = prepared
        .info
        .analyses()
        .iter()
        .map(|a| a.spec.name.as_str())
        .collect();
    Ok(CrateFiles {
        files: vec![
            ("Cargo.toml".to_string(), cargo_toml(&crate_name, &runtime)),
            (
                "README.md".to_string(),
                readme(
                    &crate_name,
                    &type_name,
                    &model.name,
                    &spec_label,
                    &analyses,
                    &runtime,
                ),
            ),
            ("src/lib.rs".to_string(), lib),
            ("src/main.rs".to_string(), main),
        ],
        vendored: runtime == Runtime::Vendored,
        lock: lock::crate_lock(workspace_lock(), &crate_name),
        crate_name,
        type_name,
        warnings: prepared.warnings,
    })
}

/// The runtime as the generated text names it.
#[derive(Clone, Debug, PartialEq)]
enum Runtime {
    Vendored,
    /// The relative path of the shared `reachc-runtime` crate.
    Shared(String),
}

impl Runtime {
    fn path(&self) -> String {
        match self {
            Runtime::Vendored => format!("{VENDOR_DIR}/{RUNTIME_CRATE}"),
            Runtime::Shared(path) => path.clone(),
        }
    }
}

/// The generated `Cargo.toml`.
fn cargo_toml(crate_name: &str, runtime: &Runtime) -> String {
    let version = env!("CARGO_PKG_VERSION");
    let comment = match runtime {
        Runtime::Vendored => format!(
            "# The runtime reachc {version} was built with, copied into vendor/ (reachc-runtime and\n\
             # the reachc-core it depends on): this directory builds anywhere with plain cargo."
        ),
        Runtime::Shared(_) => "# The runtime in reachc's cache, shared by the crates generated there \
             (compiled once\n# for all of them)."
            .to_string(),
    };
    format!(
        "{header}\
         [package]\n\
         name = \"{crate_name}\"\n\
         version = \"0.1.0\"\n\
         edition = \"2021\"\n\
         publish = false\n\
         \n\
         [dependencies]\n\
         {comment}\n\
         reachc-runtime = {{ path = {path} }}\n\
         \n\
         [lib]\n\
         path = \"src/lib.rs\"\n\
         \n\
         [[bin]]\n\
         name = \"{crate_name}\"\n\
         path = \"src/main.rs\"\n\
         \n\
         # The engines evaluate the model millions of times: unoptimised builds are very slow.\n\
         [profile.dev]\n\
         opt-level = 1\n\
         \n\
         # Not a member of any enclosing workspace.\n\
         [workspace]\n",
        header = codegen::generated_header("#"),
        path = toml_string(&runtime.path()),
    )
}

/// A TOML basic string (quoted, escaped).
fn toml_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The generated `README.md`.
fn readme(
    crate_name: &str,
    type_name: &str,
    model: &str,
    spec: &str,
    analyses: &[&str],
    runtime: &Runtime,
) -> String {
    let version = env!("CARGO_PKG_VERSION");
    let list = if analyses.is_empty() {
        "(none)".to_string()
    } else {
        analyses
            .iter()
            .map(|a| format!("`{a}`"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let first = analyses.first().copied().unwrap_or("NAME");
    let runtime_text = match runtime {
        Runtime::Vendored => format!(
            "- `vendor/reachc-runtime`, `vendor/reachc-core`: the runtime reachc {version} was \
             built with (engines, intervals, the command line of `src/main.rs`), copied here. \
             The crate refers to it by a relative path and to nothing else outside this \
             directory, so the directory can be moved or copied to another machine and built \
             with plain cargo; `Cargo.lock` pins the runtime's dependencies to the versions \
             reachc was tested with (`cargo build --locked` works offline once they are in \
             cargo's cache).\n"
        ),
        Runtime::Shared(path) => format!(
            "- The runtime (`reachc-runtime` and `reachc-core`, as reachc {version} was built \
             with) is not copied here: `Cargo.toml` refers to the copy in reachc's cache, \
             `{path}`, shared by every crate generated there so that it is compiled once. \
             `reachc build -o DIR` writes a crate with its own copy, which builds anywhere.\n"
        ),
    };
    format!(
        "# {crate_name}\n\
         \n\
         Generated by reachc {version} from {spec} (model `{model}`). Do not edit: change the \
         spec and build again (reachc rewrites the files it owns when their contents change).\n\
         \n\
         - `src/lib.rs`: `{type_name}`, implementing `reachc_runtime::System` (drift, diffusion, \
         Jacobians, in f64 and outward-rounded intervals), and `info()`, the spec's sets and \
         analyses with the constants derived by the compiler.\n\
         - `src/main.rs`: the command line.\n\
         {runtime_text}\
         \n\
         Analyses: {list}.\n\
         \n\
         ```sh\n\
         cargo run --release -- --analysis {first} -o out   # writes out/{first}.json and .csv\n\
         ```\n"
    )
}

/// Prepares `loaded.model`, generates its crate and writes it to `out_dir` (see the module
/// documentation). The README names the spec by its file name unless the options say.
pub fn write_crate(
    loaded: &mut Loaded,
    out_dir: &Path,
    options: &CrateOptions,
) -> Result<WrittenCrate, BuildError> {
    let files = generate_for(loaded, options)?;
    write_files(&files, out_dir)
}

/// [`generate_files`] for a loaded spec, with spec errors as a [`BuildError::Spec`].
pub(super) fn generate_for(
    loaded: &mut Loaded,
    options: &CrateOptions,
) -> Result<CrateFiles, BuildError> {
    let mut options = options.clone();
    if options.spec_label.is_none() {
        // The file name only: a generated file names no absolute path, and the crate's bytes
        // do not depend on how the spec's path was written.
        let name = loaded.path.file_name().unwrap_or(loaded.path.as_os_str());
        options.spec_label = Some(format!("`{}`", name.to_string_lossy()));
    }
    generate_files(&mut loaded.model, &options).map_err(|diagnostics| BuildError::Spec {
        diagnostics,
        path: loaded.path.display().to_string(),
        source: loaded.source.clone(),
    })
}

/// What is at a crate's destination.
enum Destination {
    /// Nothing, or an empty directory.
    Free,
    /// A crate generated by reachc (its `Cargo.toml` starts with [`MARKER`]).
    Generated,
}

/// Writes `files` as the crate at `out_dir` unless it is already there with the same bytes
/// (see the module documentation). An existing `out_dir` must be empty or a crate generated by
/// reachc; a new crate is written into a temporary sibling, then renamed over `out_dir`, whose
/// old contents are removed only once the new crate is in place (files reachc does not own,
/// such as a `target/` directory, go with them). On failure the temporary directory is removed
/// and `out_dir` is left as it was.
pub fn write_files(files: &CrateFiles, out_dir: &Path) -> Result<WrittenCrate, BuildError> {
    out_dir
        .file_name()
        .filter(|n| !n.is_empty() && *n != "." && *n != "..")
        .ok_or_else(|| {
            BuildError::io(
                format!("writing the crate to {}", out_dir.display()),
                std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "the output path must end in a directory name",
                ),
            )
        })?;
    let destination = check_destination(out_dir)?;
    let owned = files.owned_files();
    let changed = !matches!(destination, Destination::Generated) || !is_current(&owned, out_dir);
    if changed {
        let mut tree: Vec<(&str, &[u8])> = owned.iter().map(|(p, b)| (p.as_ref(), *b)).collect();
        if let Some(lock) = &files.lock {
            tree.push(("Cargo.lock", lock.as_bytes()));
        }
        let tmp = fsutil::temporary_sibling(out_dir, "tmp");
        if let Err(e) = fsutil::write_tree(&tmp, &tree) {
            let _ = fs::remove_dir_all(&tmp);
            return Err(e);
        }
        match destination {
            Destination::Generated => fsutil::replace_dir(&tmp, out_dir)?,
            Destination::Free => {
                if let Err(e) = rename_into_place(&tmp, out_dir) {
                    let _ = fs::remove_dir_all(&tmp);
                    return Err(BuildError::io(
                        format!("renaming {} to {}", tmp.display(), out_dir.display()),
                        e,
                    ));
                }
            }
        }
    }
    Ok(WrittenCrate {
        dir: out_dir.to_path_buf(),
        crate_name: files.crate_name.clone(),
        type_name: files.type_name.clone(),
        files: files.files.iter().map(|(p, _)| PathBuf::from(p)).collect(),
        vendored: files.vendored,
        changed,
        warnings: files.warnings.clone(),
    })
}

/// Whether the crate at `dir` holds exactly `owned`: each file with the same bytes, and no
/// other file under the directories reachc owns (`src/`, `vendor/`).
fn is_current(owned: &[(Cow<'_, str>, &[u8])], dir: &Path) -> bool {
    let same = owned
        .iter()
        .all(|(rel, bytes)| fs::read(dir.join(rel.as_ref())).is_ok_and(|b| b == *bytes));
    if !same {
        return false;
    }
    let expected: BTreeSet<&str> = owned.iter().map(|(p, _)| p.as_ref()).collect();
    let mut found = Vec::new();
    for sub in ["src", VENDOR_DIR] {
        if !list_files(&dir.join(sub), sub, &mut found) {
            return false;
        }
    }
    found.iter().all(|p| expected.contains(p.as_str()))
}

/// Adds the files under `dir` (as `prefix/...`) to `out`; `false` if a directory cannot be read.
/// A missing `dir` has no files.
fn list_files(dir: &Path, prefix: &str, out: &mut Vec<String>) -> bool {
    let entries = match fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) => return e.kind() == std::io::ErrorKind::NotFound,
    };
    for entry in entries {
        let Ok(entry) = entry else { return false };
        let name = entry.file_name().to_string_lossy().into_owned();
        let rel = format!("{prefix}/{name}");
        match entry.file_type() {
            Ok(t) if t.is_dir() => {
                if !list_files(&entry.path(), &rel, out) {
                    return false;
                }
            }
            Ok(_) => out.push(rel),
            Err(_) => return false,
        }
    }
    true
}

/// Renames `tmp` to `out_dir`, which is absent or an empty directory.
fn rename_into_place(tmp: &Path, out_dir: &Path) -> std::io::Result<()> {
    if out_dir.is_dir() {
        // Empty (checked): replace it. Renaming over an empty directory works on Unix but not
        // everywhere, so remove it first.
        fs::remove_dir(out_dir)?;
    }
    fs::rename(tmp, out_dir)
}

/// What `out_dir` holds; any other non-empty path is refused.
fn check_destination(out_dir: &Path) -> Result<Destination, BuildError> {
    let meta = match fs::symlink_metadata(out_dir) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Destination::Free),
        Err(e) => return Err(BuildError::io(format!("reading {}", out_dir.display()), e)),
    };
    if !meta.is_dir() {
        return Err(BuildError::NotGenerated(out_dir.to_path_buf()));
    }
    let mut entries = fs::read_dir(out_dir)
        .map_err(|e| BuildError::io(format!("reading {}", out_dir.display()), e))?;
    if entries.next().is_none() {
        return Ok(Destination::Free);
    }
    let manifest = fs::read_to_string(out_dir.join("Cargo.toml")).unwrap_or_default();
    if manifest.starts_with(MARKER) {
        Ok(Destination::Generated)
    } else {
        Err(BuildError::NotGenerated(out_dir.to_path_buf()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::package::fsutil::FAIL_BEFORE;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("reachc-writer-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn files(tag: &str) -> CrateFiles {
        CrateFiles {
            crate_name: "demo".to_string(),
            type_name: "Demo".to_string(),
            files: vec![
                ("Cargo.toml".to_string(), format!("{MARKER} test\n{tag}\n")),
                ("README.md".to_string(), format!("readme {tag}\n")),
                ("src/lib.rs".to_string(), format!("// lib {tag}\n")),
                ("src/main.rs".to_string(), format!("// main {tag}\n")),
            ],
            vendored: false,
            lock: Some(format!("# lock {tag}\n")),
            warnings: Vec::new(),
        }
    }

    fn siblings(parent: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(parent)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    fn mtimes(dir: &Path) -> Vec<(String, std::time::SystemTime)> {
        let mut out = Vec::new();
        let mut rels = Vec::new();
        list_files(dir, "", &mut rels);
        for rel in rels {
            let m = fs::metadata(dir.join(&rel[1..]))
                .unwrap()
                .modified()
                .unwrap();
            out.push((rel, m));
        }
        out.sort();
        out
    }

    #[test]
    fn writes_then_replaces_a_generated_crate() {
        let root = scratch("replace");
        let out = root.join("demo");
        let written = write_files(&files("one"), &out).unwrap();
        assert_eq!(written.files.len(), 4);
        assert!(written.changed);
        assert_eq!(
            fs::read_to_string(out.join("src/lib.rs")).unwrap(),
            "// lib one\n"
        );
        assert_eq!(
            fs::read_to_string(out.join("Cargo.lock")).unwrap(),
            "# lock one\n"
        );
        // Stale files of the old crate go away with it.
        fs::write(out.join("stale.txt"), "x").unwrap();
        write_files(&files("two"), &out).unwrap();
        assert_eq!(
            fs::read_to_string(out.join("src/main.rs")).unwrap(),
            "// main two\n"
        );
        assert!(!out.join("stale.txt").exists());
        assert_eq!(siblings(&root), ["demo"]);
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn an_unchanged_crate_is_not_written() {
        let root = scratch("unchanged");
        let out = root.join("demo");
        write_files(&files("one"), &out).unwrap();
        // cargo rewrites the lock: it is not compared, and survives.
        fs::write(out.join("Cargo.lock"), "# cargo's lock\n").unwrap();
        let before = mtimes(&out);
        std::thread::sleep(std::time::Duration::from_millis(20));
        let again = write_files(&files("one"), &out).unwrap();
        assert!(!again.changed);
        assert_eq!(mtimes(&out), before);
        assert_eq!(
            fs::read_to_string(out.join("Cargo.lock")).unwrap(),
            "# cargo's lock\n"
        );
        // An extra source file, or an edited one, makes it out of date.
        fs::write(out.join("src/extra.rs"), "").unwrap();
        assert!(write_files(&files("one"), &out).unwrap().changed);
        assert!(!out.join("src/extra.rs").exists());
        fs::write(out.join("src/lib.rs"), "edited").unwrap();
        assert!(write_files(&files("one"), &out).unwrap().changed);
        assert_eq!(
            fs::read_to_string(out.join("src/lib.rs")).unwrap(),
            "// lib one\n"
        );
        assert_eq!(siblings(&root), ["demo"]);
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn a_failure_leaves_the_old_crate_and_no_temporary() {
        let root = scratch("fail");
        let out = root.join("demo");
        write_files(&files("old"), &out).unwrap();
        for (rel, _) in files("").files {
            FAIL_BEFORE.with(|f| *f.borrow_mut() = Some(rel.clone()));
            let err = write_files(&files("new"), &out).unwrap_err();
            FAIL_BEFORE.with(|f| *f.borrow_mut() = None);
            assert!(err.to_string().contains("injected"), "{err}");
            assert_eq!(siblings(&root), ["demo"], "failing at {rel}");
            for (rel, contents) in &files("old").files {
                assert_eq!(&fs::read_to_string(out.join(rel)).unwrap(), contents);
            }
        }
        // A failure on a fresh destination leaves nothing behind either.
        let fresh = root.join("fresh");
        FAIL_BEFORE.with(|f| *f.borrow_mut() = Some("src/lib.rs".to_string()));
        assert!(write_files(&files("new"), &fresh).is_err());
        FAIL_BEFORE.with(|f| *f.borrow_mut() = None);
        assert_eq!(siblings(&root), ["demo"]);
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn an_unwritable_parent_is_an_io_error() {
        let root = scratch("parent");
        // The parent is a file: creating the temporary directory fails (works as root, unlike
        // a read-only directory).
        fs::write(root.join("file"), "x").unwrap();
        let err = write_files(&files("x"), &root.join("file").join("demo")).unwrap_err();
        assert!(matches!(err, BuildError::Io { .. }), "{err:?}");
        assert_eq!(err.exit_code(), 2);
        assert_eq!(siblings(&root), ["file"]);
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn refuses_to_replace_other_directories() {
        let root = scratch("foreign");
        let out = root.join("mine");
        fs::create_dir(&out).unwrap();
        fs::write(out.join("notes.txt"), "precious").unwrap();
        let err = write_files(&files("x"), &out).unwrap_err();
        assert!(matches!(err, BuildError::NotGenerated(_)), "{err:?}");
        assert_eq!(
            fs::read_to_string(out.join("notes.txt")).unwrap(),
            "precious"
        );
        // A file is refused too; an empty directory is used.
        fs::write(root.join("f"), "x").unwrap();
        assert!(write_files(&files("x"), &root.join("f")).is_err());
        let empty = root.join("empty");
        fs::create_dir(&empty).unwrap();
        write_files(&files("x"), &empty).unwrap();
        assert!(empty.join("src/lib.rs").is_file());
        assert!(write_files(&files("x"), Path::new("/")).is_err());
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn vendored_crates_carry_the_runtime() {
        let root = scratch("vendored");
        let out = root.join("demo");
        let mut vendored = files("v");
        vendored.vendored = true;
        write_files(&vendored, &out).unwrap();
        for f in runtime_files() {
            assert_eq!(
                fs::read(out.join(VENDOR_DIR).join(f.path)).unwrap(),
                f.bytes
            );
        }
        assert!(!write_files(&vendored, &out).unwrap().changed);
        // A stale file in vendor/ makes the crate out of date.
        fs::write(out.join("vendor/reachc-core/src/old.rs"), "").unwrap();
        assert!(write_files(&vendored, &out).unwrap().changed);
        assert!(!out.join("vendor/reachc-core/src/old.rs").exists());
        // Without vendoring, vendor/ goes.
        assert!(write_files(&files("v"), &out).unwrap().changed);
        assert!(!out.join(VENDOR_DIR).exists());
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn toml_strings_are_escaped() {
        assert_eq!(toml_string(r#"C:\a "b""#), r#""C:\\a \"b\"""#);
        assert_eq!(toml_string("/x/y"), "\"/x/y\"");
    }

    #[test]
    fn manifests_name_the_runtime_by_relative_path() {
        let vendored = cargo_toml("demo", &Runtime::Vendored);
        assert!(vendored.starts_with(MARKER));
        assert!(vendored.lines().next().unwrap().contains("@generated"));
        assert!(vendored.contains("reachc-runtime = { path = \"vendor/reachc-runtime\" }"));
        assert!(vendored.contains("\n[workspace]\n"));
        let shared = cargo_toml(
            "demo",
            &Runtime::Shared("../../runtime/x/reachc-runtime".into()),
        );
        assert!(shared.contains("reachc-runtime = { path = \"../../runtime/x/reachc-runtime\" }"));
    }
}
