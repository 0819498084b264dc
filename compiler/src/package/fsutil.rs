//! Atomic file system updates: whole directories written beside their destination and renamed
//! into place, single files through a temporary sibling.

use std::ffi::OsString;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use super::BuildError;

#[cfg(test)]
thread_local! {
    /// Fault injection for the tests: [`write_tree`] fails before writing this relative path.
    pub(super) static FAIL_BEFORE: std::cell::RefCell<Option<String>> =
        const { std::cell::RefCell::new(None) };
}

/// A fresh sibling of `path` for temporary use: `<name>.<tag>-<pid>-<n>`, unique within this
/// process (threads included) and across processes (the pid). A leftover of a crashed process
/// with the same name is removed.
pub(super) fn temporary_sibling(path: &Path, tag: &str) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let mut name: OsString = path.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".{tag}-{}-{n}", std::process::id()));
    let sibling = path.with_file_name(name);
    if fs::symlink_metadata(&sibling).is_ok() {
        let _ = fs::remove_dir_all(&sibling).or_else(|_| fs::remove_file(&sibling));
    }
    sibling
}

/// Creates the directory `root` (which must not exist) and writes `files` (relative,
/// `/`-separated paths) under it. On failure `root` may be partly written: the caller removes
/// it.
pub(super) fn write_tree(root: &Path, files: &[(&str, &[u8])]) -> Result<(), BuildError> {
    fs::create_dir(root).map_err(|e| BuildError::io(format!("creating {}", root.display()), e))?;
    for (rel, contents) in files {
        #[cfg(test)]
        if FAIL_BEFORE.with(|f| f.borrow().as_deref() == Some(*rel)) {
            return Err(BuildError::io(
                "injected failure",
                std::io::Error::other("injected"),
            ));
        }
        let path = root.join(rel);
        if let Some(parent) = path.parent() {
            fs::create_dir_all(parent)
                .map_err(|e| BuildError::io(format!("creating {}", parent.display()), e))?;
        }
        fs::write(&path, contents)
            .map_err(|e| BuildError::io(format!("writing {}", path.display()), e))?;
    }
    Ok(())
}

/// Puts the complete directory `new` in the place of the existing directory `dest`: `dest`
/// steps aside, `new` takes its place, then the old one is removed. Between the two renames
/// `dest` is briefly absent, never half-written. On failure `new` is removed and `dest` is left
/// as it was.
pub(super) fn replace_dir(new: &Path, dest: &Path) -> Result<(), BuildError> {
    let old = temporary_sibling(dest, "old");
    if let Err(e) = fs::rename(dest, &old) {
        let _ = fs::remove_dir_all(new);
        return Err(BuildError::io(
            format!("moving {} aside", dest.display()),
            e,
        ));
    }
    if let Err(e) = fs::rename(new, dest) {
        let _ = fs::rename(&old, dest);
        let _ = fs::remove_dir_all(new);
        return Err(BuildError::io(
            format!("renaming {} to {}", new.display(), dest.display()),
            e,
        ));
    }
    fs::remove_dir_all(&old)
        .map_err(|e| BuildError::io(format!("removing the old {}", old.display()), e))
}

/// Writes `bytes` to `path` through a temporary sibling renamed over it: readers see the old
/// contents or the new ones, never a part.
pub(super) fn write_file_atomic(path: &Path, bytes: &[u8]) -> Result<(), BuildError> {
    let tmp = temporary_sibling(path, "tmp");
    if let Err(e) = fs::write(&tmp, bytes) {
        let _ = fs::remove_file(&tmp);
        return Err(BuildError::io(format!("writing {}", tmp.display()), e));
    }
    fs::rename(&tmp, path).map_err(|e| {
        let _ = fs::remove_file(&tmp);
        BuildError::io(
            format!("renaming {} to {}", tmp.display(), path.display()),
            e,
        )
    })
}

/// The components of `p` with `.` dropped and `..` applied (`None` if it climbs above its start).
fn normal(p: &Path) -> Option<Vec<std::path::Component<'_>>> {
    use std::path::Component;
    let mut out: Vec<Component<'_>> = Vec::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if matches!(out.last(), Some(Component::Normal(_))) {
                    out.pop();
                } else {
                    return None;
                }
            }
            c => out.push(c),
        }
    }
    Some(out)
}

/// `target` relative to the directory `from` (both made absolute against the current
/// directory, compared component by component without resolving symbolic links, as cargo
/// resolves relative paths in manifests). `None` when there is no relative path (different
/// drives on Windows).
pub(super) fn relative_path(from: &Path, target: &Path) -> Option<PathBuf> {
    let (from, target) = (
        std::path::absolute(from).ok()?,
        std::path::absolute(target).ok()?,
    );
    let (from, target) = (normal(&from)?, normal(&target)?);
    let common = from.iter().zip(&target).take_while(|(a, b)| a == b).count();
    // Nothing in common (not even the root): no relative path.
    if common == 0 {
        return None;
    }
    let mut rel = PathBuf::new();
    for _ in common..from.len() {
        rel.push("..");
    }
    for c in &target[common..] {
        rel.push(c.as_os_str());
    }
    Some(rel)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths() {
        let rel = |a: &str, b: &str| relative_path(Path::new(a), Path::new(b)).unwrap();
        assert_eq!(
            rel("/c/crates/pendulum", "/c/runtime/0.1.0-x/reachc-runtime"),
            Path::new("../../runtime/0.1.0-x/reachc-runtime")
        );
        assert_eq!(rel("/a/b", "/a/b/vendor"), Path::new("vendor"));
        assert_eq!(rel("/a/./b/../b", "/a/c"), Path::new("../c"));
        assert_eq!(rel("/a", "/a"), Path::new(""));
        assert!(relative_path(Path::new("/.."), Path::new("/a")).is_none());
    }

    #[test]
    fn atomic_file_writes_leave_no_temporary() {
        let dir = std::env::temp_dir().join(format!("reachc-fsutil-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let file = dir.join("stamp");
        write_file_atomic(&file, b"one").unwrap();
        write_file_atomic(&file, b"two").unwrap();
        assert_eq!(fs::read(&file).unwrap(), b"two");
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 1);
        let err = write_file_atomic(&dir.join("missing").join("x"), b"x").unwrap_err();
        assert_eq!(err.exit_code(), 2);
        fs::remove_dir_all(&dir).unwrap();
    }
}
