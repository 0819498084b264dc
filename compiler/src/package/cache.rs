//! reachc's cache for the compiled backend (`reachc run`, `reachc simulate`): generated crates
//! that share one runtime and one cargo target directory, and build stamps so that an unchanged
//! spec runs its binary at once, without writing a file or starting cargo.
//!
//! ```text
//! <root>/
//!   runtime/<runtime id>/        the embedded runtime (install_runtime), written once
//!     reachc-core/  reachc-runtime/
//!   crates/<crate name>/         one crate per model name, see writer
//!     Cargo.toml                 reachc-runtime = { path = "../../runtime/<runtime id>/reachc-runtime" }
//!     .reachc-stamp              what the last successful build was built from
//!     ...
//!   target/                      CARGO_TARGET_DIR of every cached crate
//! ```
//!
//! The stamp holds a SHA-256 of everything the binary depends on that reachc controls (the
//! generated files, which name the runtime id, the profile, the target directory and the
//! binary's path relative to it) and the binary's size and modification time as cargo left
//! them. A later run that generates the same files, with the binary unchanged, uses the binary
//! as it is; anything else (a changed spec, another reachc, a binary rebuilt by someone else)
//! writes what changed and runs cargo.

use std::ffi::OsString;
use std::fs;
use std::path::{Path, PathBuf};
use std::time::UNIX_EPOCH;

use super::cargo::{Cargo, Profile, Progress};
use super::embedded::{install_runtime, runtime_id, RUNTIME_CRATE};
use super::fsutil;
use super::sha256::Sha256;
use super::writer::{generate_for, write_files, CrateFiles, CrateOptions, RuntimeDep};
use super::BuildError;
use crate::backend::mangle;
use crate::diagnostics::Diagnostic;
use crate::driver::Loaded;

/// The name of the stamp file in a cached crate's directory.
pub const STAMP: &str = ".reachc-stamp";

/// The first line of a stamp (its format's version).
const STAMP_HEADER: &str = "reachc build stamp 1";

/// reachc's cache: a root directory for crates and the runtime, and a cargo target directory.
#[derive(Clone, Debug)]
pub struct Cache {
    root: PathBuf,
    target: PathBuf,
    cargo_program: Option<OsString>,
}

/// A binary of the cache, ready to run.
#[derive(Clone, Debug)]
pub struct CachedBinary {
    /// The binary.
    pub path: PathBuf,
    /// The crate it was built from.
    pub crate_dir: PathBuf,
    /// Whether cargo ran (`false`: the stamp matched, nothing was written or compiled).
    pub compiled: bool,
    /// Warnings from preparing the model, to show the user with the spec's source.
    pub warnings: Vec<Diagnostic>,
}

impl Cache {
    /// The cache the environment names: with `$REACHC_TARGET_DIR` set, that is the target
    /// directory and its parent the root; else the root is `$XDG_CACHE_HOME/reachc`, else
    /// `$HOME/.cache/reachc`, with the target directory `<root>/target`. Relative paths are
    /// taken from the current directory. [`BuildError::NoCache`] when none of them is set.
    pub fn from_env() -> Result<Cache, BuildError> {
        let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
        let absolute = |p: PathBuf| std::path::absolute(&p).unwrap_or(p);
        if let Some(target) = var("REACHC_TARGET_DIR") {
            let target = absolute(PathBuf::from(target));
            let root = target
                .parent()
                .map(Path::to_path_buf)
                .unwrap_or_else(|| target.clone());
            return Ok(Cache::new(root, target));
        }
        let root = if let Some(cache) = var("XDG_CACHE_HOME") {
            Path::new(&cache).join("reachc")
        } else if let Some(home) = var("HOME") {
            Path::new(&home).join(".cache").join("reachc")
        } else {
            return Err(BuildError::NoCache);
        };
        let root = absolute(root);
        let target = root.join("target");
        Ok(Cache::new(root, target))
    }

    /// A cache at `root` with the cargo target directory `target`.
    pub fn new(root: impl Into<PathBuf>, target: impl Into<PathBuf>) -> Cache {
        Cache {
            root: root.into(),
            target: target.into(),
            cargo_program: None,
        }
    }

    /// Runs this program instead of cargo (see [`Cargo::program`]).
    pub fn with_cargo_program(mut self, program: impl Into<OsString>) -> Cache {
        self.cargo_program = Some(program.into());
        self
    }

    /// The root directory.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The cargo target directory.
    pub fn target_dir(&self) -> &Path {
        &self.target
    }

    /// Where runtimes are installed (`<root>/runtime`, one directory per runtime id).
    pub fn runtime_parent(&self) -> PathBuf {
        self.root.join("runtime")
    }

    /// The directory of the cached crate named `crate_name` (`<root>/crates/<crate_name>`).
    pub fn crate_dir(&self, crate_name: &str) -> PathBuf {
        self.root.join("crates").join(crate_name)
    }

    /// cargo for this cache's target directory and `profile`.
    pub fn cargo(&self, profile: Profile) -> Cargo {
        let mut cargo = Cargo::new(&self.target, profile);
        if let Some(program) = &self.cargo_program {
            cargo.program = program.clone();
        }
        cargo
    }

    /// The binary of `loaded`'s crate in this cache: generates the crate (depending on this
    /// cache's runtime) and, unless its stamp shows the binary is current, installs the
    /// runtime, writes what changed and compiles with cargo (`progress` sees cargo's progress;
    /// it is not called when cargo does not run).
    pub fn binary(
        &self,
        loaded: &mut Loaded,
        profile: Profile,
        progress: &mut dyn FnMut(&Progress),
    ) -> Result<CachedBinary, BuildError> {
        let crate_name = mangle::crate_name(&loaded.model.name);
        let crate_dir = self.crate_dir(&crate_name);
        let runtime_crate = self.runtime_parent().join(runtime_id()).join(RUNTIME_CRATE);
        let options = CrateOptions {
            runtime: RuntimeDep::shared_crate(&runtime_crate, &crate_dir)?,
            ..CrateOptions::default()
        };
        let files = generate_for(loaded, &options)?;
        let warnings = files.warnings.clone();
        let binary_rel = binary_path(profile, &files.crate_name);
        let key = stamp_key(&files, profile, &self.target, &binary_rel);
        if let Some(path) = self.current_binary(&crate_dir, &key) {
            return Ok(CachedBinary {
                path,
                crate_dir,
                compiled: false,
                warnings,
            });
        }

        fs::create_dir_all(&self.root).map_err(|e| {
            BuildError::io(
                format!(
                    "creating reachc's cache directory {} (set by REACHC_TARGET_DIR, \
                     XDG_CACHE_HOME or HOME)",
                    self.root.display()
                ),
                e,
            )
        })?;
        install_runtime(&self.runtime_parent(), true)?;
        let crates = crate_dir.parent().unwrap_or(&self.root);
        fs::create_dir_all(crates)
            .map_err(|e| BuildError::io(format!("creating {}", crates.display()), e))?;
        write_files(&files, &crate_dir)?;
        let path = self.cargo(profile).build(&crate_dir, progress)?;
        self.write_stamp(&crate_dir, &key, &path)?;
        Ok(CachedBinary {
            path,
            crate_dir,
            compiled: true,
            warnings,
        })
    }

    /// The binary recorded in `crate_dir`'s stamp, if the stamp has `key` and the binary is as
    /// cargo left it.
    fn current_binary(&self, crate_dir: &Path, key: &str) -> Option<PathBuf> {
        let stamp = fs::read_to_string(crate_dir.join(STAMP)).ok()?;
        let stamp = Stamp::parse(&stamp)?;
        if stamp.key != key {
            return None;
        }
        let path = self.target.join(&stamp.binary);
        (file_state(&path)? == (stamp.size, stamp.modified)).then_some(path)
    }

    /// Records that `binary`, under the target directory, was built from the crate with `key`.
    /// A binary elsewhere (a cargo configuration placing it there) is not recorded: the crate is
    /// then compiled on every run.
    fn write_stamp(&self, crate_dir: &Path, key: &str, binary: &Path) -> Result<(), BuildError> {
        let stamp_path = crate_dir.join(STAMP);
        let recorded = binary.strip_prefix(&self.target).ok().and_then(|rel| {
            let rel = rel.to_str()?.replace('\\', "/");
            let (size, modified) = file_state(binary)?;
            Some(Stamp {
                key: key.to_string(),
                binary: rel,
                size,
                modified,
            })
        });
        match recorded {
            Some(stamp) => fsutil::write_file_atomic(&stamp_path, stamp.render().as_bytes()),
            None => match fs::remove_file(&stamp_path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(BuildError::io(
                    format!("removing {}", stamp_path.display()),
                    e,
                )),
                _ => Ok(()),
            },
        }
    }
}

/// The binary's path relative to the target directory, as cargo places it without `--target`.
fn binary_path(profile: Profile, crate_name: &str) -> String {
    let dir = match profile {
        Profile::Dev => "debug",
        Profile::Release => "release",
    };
    format!("{dir}/{crate_name}{}", std::env::consts::EXE_SUFFIX)
}

/// The stamp key of a crate: a SHA-256 of the reachc version, the generated files (which name
/// the runtime id), the profile, the target directory and the binary's relative path.
fn stamp_key(files: &CrateFiles, profile: Profile, target: &Path, binary: &str) -> String {
    let mut h = Sha256::new();
    h.field(STAMP_HEADER.as_bytes());
    h.field(env!("CARGO_PKG_VERSION").as_bytes());
    h.field(runtime_id().as_bytes());
    h.field(profile.name().as_bytes());
    h.field(target.as_os_str().as_encoded_bytes());
    h.field(binary.as_bytes());
    for (path, bytes) in files.owned_files() {
        h.field(path.as_bytes());
        h.field(bytes);
    }
    h.finish_hex()
}

/// A file's size and modification time (nanoseconds since the epoch).
fn file_state(path: &Path) -> Option<(u64, u128)> {
    let meta = fs::metadata(path).ok()?;
    let modified = meta.modified().ok()?.duration_since(UNIX_EPOCH).ok()?;
    meta.is_file().then_some((meta.len(), modified.as_nanos()))
}

/// The contents of a stamp file.
#[derive(Clone, Debug, PartialEq)]
struct Stamp {
    key: String,
    /// Relative to the target directory, `/`-separated.
    binary: String,
    size: u64,
    modified: u128,
}

impl Stamp {
    fn render(&self) -> String {
        format!(
            "{STAMP_HEADER}: the binary below was built from this crate; delete this file to \
             rebuild\nkey {}\nbinary {}\nsize {}\nmodified {}\n",
            self.key, self.binary, self.size, self.modified
        )
    }

    fn parse(text: &str) -> Option<Stamp> {
        let mut lines = text.lines();
        if !lines.next()?.starts_with(STAMP_HEADER) {
            return None;
        }
        let mut field = |name: &str| -> Option<String> {
            lines
                .next()?
                .strip_prefix(name)?
                .strip_prefix(' ')
                .map(str::to_string)
        };
        Some(Stamp {
            key: field("key")?,
            binary: field("binary")?,
            size: field("size")?.parse().ok()?,
            modified: field("modified")?.parse().ok()?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stamps_round_trip() {
        let stamp = Stamp {
            key: "ab".repeat(32),
            binary: "release/pendulum".into(),
            size: 123,
            modified: 1_700_000_000_123_456_789,
        };
        assert_eq!(Stamp::parse(&stamp.render()), Some(stamp.clone()));
        assert_eq!(Stamp::parse("something else\n"), None);
        assert_eq!(
            Stamp::parse(&stamp.render().replace("size 123", "size x")),
            None
        );
    }

    #[test]
    fn binaries_are_where_cargo_puts_them() {
        let exe = std::env::consts::EXE_SUFFIX;
        assert_eq!(
            binary_path(Profile::Release, "pendulum"),
            format!("release/pendulum{exe}")
        );
        assert_eq!(binary_path(Profile::Dev, "x"), format!("debug/x{exe}"));
    }
}
