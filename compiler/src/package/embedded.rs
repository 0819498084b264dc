//! The runtime reachc was built with, embedded in the binary by `compiler/build.rs`: the
//! sources of `reachc-core` and `reachc-runtime` (each crate's `Cargo.toml`, without the
//! sections that refer to files not embedded, and its `src/` tree) and the workspace's
//! `Cargo.lock`.
//!
//! [`install_runtime`] writes them once into a directory shared by generated crates (reachc's
//! cache); [`crate::package::writer`] copies them into a crate's `vendor/` directory.

use std::fs;
use std::path::{Path, PathBuf};

use super::fsutil;
use super::BuildError;

mod generated {
    include!(concat!(env!("OUT_DIR"), "/embedded_runtime.rs"));
}

/// The directory name of the runtime crate generated crates depend on.
pub const RUNTIME_CRATE: &str = "reachc-runtime";

/// The directory name of the core crate (a dependency of [`RUNTIME_CRATE`]).
pub const CORE_CRATE: &str = "reachc-core";

/// The embedded runtime's id, `<reachc version>-<16 hex digits of a SHA-256 of every embedded
/// file and the lock>`: equal ids mean byte-identical runtimes.
pub fn runtime_id() -> &'static str {
    generated::RUNTIME_ID
}

/// One embedded file.
#[derive(Clone, Copy, Debug)]
pub struct EmbeddedFile {
    /// The path relative to the runtime's root, `/`-separated, starting with [`CORE_CRATE`] or
    /// [`RUNTIME_CRATE`] (e.g. `reachc-core/src/lib.rs`).
    pub path: &'static str,
    /// The contents.
    pub bytes: &'static [u8],
}

/// The embedded files of both crates, sorted by path.
pub fn runtime_files() -> impl ExactSizeIterator<Item = EmbeddedFile> {
    generated::FILES
        .iter()
        .map(|&(path, bytes)| EmbeddedFile { path, bytes })
}

/// The lock file of the workspace reachc was built in (the runtime's dependencies at the
/// versions reachc was tested with); see [`super::lock::crate_lock`].
pub fn workspace_lock() -> &'static str {
    // Cargo.lock is UTF-8 (TOML); an invalid one would fail cargo anyway.
    std::str::from_utf8(generated::LOCK).unwrap_or("")
}

/// The embedded runtime written to disk: `<dir>/reachc-core` and `<dir>/reachc-runtime`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InstalledRuntime {
    dir: PathBuf,
}

impl InstalledRuntime {
    /// The directory holding both crates (`<parent>/<runtime id>`).
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The `reachc-runtime` crate, which generated crates depend on.
    pub fn runtime_crate(&self) -> PathBuf {
        self.dir.join(RUNTIME_CRATE)
    }
}

/// Whether `dir` holds every embedded file with the embedded bytes (other files are ignored).
fn is_complete(dir: &Path) -> bool {
    runtime_files().all(|f| fs::read(dir.join(f.path)).is_ok_and(|b| b == f.bytes))
}

/// Writes the embedded runtime to `<parent>/<runtime id>` unless it is already there.
///
/// The directory is written as a whole into a temporary sibling and renamed into place, so it
/// is either absent or complete, and concurrent processes installing the same id do not
/// interfere (the first rename wins, the others discard their copy). With `verify`, an existing
/// directory is compared byte for byte with the embedded files and replaced (atomically again)
/// if it differs; without, its presence is enough.
pub fn install_runtime(parent: &Path, verify: bool) -> Result<InstalledRuntime, BuildError> {
    let dir = parent.join(runtime_id());
    let installed = InstalledRuntime { dir: dir.clone() };
    let present = dir.is_dir();
    if present && (!verify || is_complete(&dir)) {
        return Ok(installed);
    }
    fs::create_dir_all(parent)
        .map_err(|e| BuildError::io(format!("creating {}", parent.display()), e))?;
    let files: Vec<(&str, &[u8])> = runtime_files().map(|f| (f.path, f.bytes)).collect();
    let tmp = fsutil::temporary_sibling(&dir, "tmp");
    if let Err(e) = fsutil::write_tree(&tmp, &files) {
        let _ = fs::remove_dir_all(&tmp);
        return Err(e);
    }
    if present {
        // Damaged (files edited or removed): replace it.
        fsutil::replace_dir(&tmp, &dir)?;
        return Ok(installed);
    }
    match fs::rename(&tmp, &dir) {
        Ok(()) => Ok(installed),
        // Another process installed it in the meantime: its copy has the same bytes.
        Err(_) if dir.is_dir() => {
            let _ = fs::remove_dir_all(&tmp);
            Ok(installed)
        }
        Err(e) => {
            let _ = fs::remove_dir_all(&tmp);
            Err(BuildError::io(
                format!("renaming {} to {}", tmp.display(), dir.display()),
                e,
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_crates_are_embedded_with_rewritten_manifests() {
        let paths: Vec<&str> = runtime_files().map(|f| f.path).collect();
        for krate in [CORE_CRATE, RUNTIME_CRATE] {
            assert!(paths.contains(&format!("{krate}/Cargo.toml").as_str()));
            assert!(paths.contains(&format!("{krate}/src/lib.rs").as_str()));
        }
        assert!(paths.windows(2).all(|w| w[0] < w[1]), "sorted, unique");
        assert!(paths
            .iter()
            .all(|p| p.starts_with("reachc-core/") || p.starts_with("reachc-runtime/")));
        let manifest = |krate: &str| {
            let f = runtime_files()
                .find(|f| f.path == format!("{krate}/Cargo.toml"))
                .unwrap();
            std::str::from_utf8(f.bytes).unwrap()
        };
        for krate in [CORE_CRATE, RUNTIME_CRATE] {
            let m = manifest(krate);
            assert!(m.starts_with("# Embedded in reachc "), "{m}");
            assert!(m.contains(&format!("name = \"{krate}\"")), "{m}");
            for gone in ["[dev-dependencies]", "[[bench]]", "[[test]]", "[[example]]"] {
                assert!(!m.contains(gone), "{krate}: {gone} kept:\n{m}");
            }
        }
        let runtime = manifest(RUNTIME_CRATE);
        assert!(runtime.contains("path = \"../reachc-core\""), "{runtime}");
        assert!(!runtime.contains("../core\""), "{runtime}");
        // The sources are embedded as they are.
        let lib = runtime_files()
            .find(|f| f.path == "reachc-core/src/lib.rs")
            .unwrap();
        let on_disk =
            fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../core/src/lib.rs")).unwrap();
        assert_eq!(lib.bytes, on_disk.as_slice());
        assert!(workspace_lock().contains("name = \"reachc-runtime\""));
    }

    #[test]
    fn the_runtime_id_is_the_version_and_a_hash() {
        let id = runtime_id();
        let (version, hash) = id.rsplit_once('-').unwrap();
        assert_eq!(version, env!("CARGO_PKG_VERSION"));
        assert_eq!(hash.len(), 16);
        assert!(hash.bytes().all(|b| b.is_ascii_hexdigit()));
    }

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("reachc-embedded-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        dir
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn installs_once_and_repairs_when_verifying() {
        let root = scratch("install");
        let installed = install_runtime(&root, false).unwrap();
        assert_eq!(installed.dir(), root.join(runtime_id()));
        assert!(is_complete(installed.dir()));
        assert_eq!(entries(&root), [runtime_id()]);
        assert_eq!(
            entries(installed.dir()),
            [CORE_CRATE.to_string(), RUNTIME_CRATE.to_string()]
        );
        // Present: nothing is written (a damaged file stays unless verifying).
        let lib = installed.runtime_crate().join("src/lib.rs");
        fs::write(&lib, "damaged").unwrap();
        install_runtime(&root, false).unwrap();
        assert_eq!(fs::read_to_string(&lib).unwrap(), "damaged");
        install_runtime(&root, true).unwrap();
        assert!(is_complete(installed.dir()));
        assert_eq!(entries(&root), [runtime_id()]);
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn concurrent_installs_give_one_complete_copy() {
        let root = scratch("concurrent");
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| install_runtime(&root, false).unwrap());
            }
        });
        assert_eq!(entries(&root), [runtime_id()]);
        assert!(is_complete(&root.join(runtime_id())));
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn an_unwritable_parent_is_an_io_error() {
        let root = scratch("unwritable");
        fs::create_dir_all(&root).unwrap();
        fs::write(root.join("file"), "x").unwrap();
        let err = install_runtime(&root.join("file").join("runtime"), false).unwrap_err();
        assert!(matches!(err, BuildError::Io { .. }), "{err:?}");
        assert_eq!(err.exit_code(), 2);
        fs::remove_dir_all(&root).unwrap();
    }
}
