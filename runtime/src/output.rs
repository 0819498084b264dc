//! A command's output files, written whole or not at all.
//!
//! [`Files`] holds every file of one command in memory; [`Files::commit`] puts them in place:
//!
//! - a directory that does not exist yet (with its missing parents) is built under a temporary
//!   name beside its topmost missing ancestor (same file system), then renamed into place: it
//!   appears with every file or not at all;
//! - in a directory that exists, each file is written to a temporary name in that directory,
//!   then all of them are renamed over their targets; other files there are left alone. When a
//!   rename fails, the ones already done are undone (the previous versions are kept as hard links
//!   until the end), so an error leaves the old files, never a mix of old and new.
//!
//! Only a process killed during the final renames (microseconds) can leave a mix; a process
//! killed earlier leaves at most a hidden `.reachc-*` temporary entry, never a visible file.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The files of one command, in memory until [`Files::commit`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Files {
    files: Vec<(PathBuf, Vec<u8>)>,
}

/// A failure to write the files: what could not be done (nothing was changed).
#[derive(Debug)]
pub struct WriteError {
    /// The path that could not be written.
    pub path: PathBuf,
    /// Why.
    pub error: std::io::Error,
}

impl std::fmt::Display for WriteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "cannot write {}: {}", self.path.display(), self.error)
    }
}

impl std::error::Error for WriteError {}

impl Files {
    /// No files.
    pub fn new() -> Self {
        Files::default()
    }

    /// Adds a file (a later file with the same path replaces it).
    pub fn add(&mut self, path: PathBuf, bytes: Vec<u8>) {
        self.files.retain(|(p, _)| *p != path);
        self.files.push((path, bytes));
    }

    /// Adds every file of `other`.
    pub fn extend(&mut self, other: Files) {
        for (path, bytes) in other.files {
            self.add(path, bytes);
        }
    }

    /// The paths, in the order added.
    pub fn paths(&self) -> Vec<PathBuf> {
        self.files.iter().map(|(p, _)| p.clone()).collect()
    }

    /// Whether there are no files.
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    /// Reads every regular file directly in `dir` (sorted by name), as files of `target`.
    pub fn read_dir(dir: &Path, target: &Path) -> std::io::Result<Files> {
        let mut names: Vec<_> = std::fs::read_dir(dir)?
            .map(|e| e.map(|e| e.file_name()))
            .collect::<Result<_, _>>()?;
        names.sort();
        let mut files = Files::new();
        for name in names {
            let path = dir.join(&name);
            if path.is_file() {
                files.add(target.join(&name), std::fs::read(&path)?);
            }
        }
        Ok(files)
    }

    /// Writes every file, whole or not at all (see the module's documentation); returns the
    /// paths written, in the order added.
    pub fn commit(self) -> Result<Vec<PathBuf>, WriteError> {
        let paths = self.paths();
        let mut plan = Plan::default();
        if let Err(e) = plan.prepare(self.files) {
            plan.discard();
            return Err(e);
        }
        plan.install()?;
        Ok(paths)
    }
}

/// Temporary names unique within this process.
fn temporary(dir: &Path, suffix: &str) -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    dir.join(format!(".reachc-{}-{n}.{suffix}", std::process::id()))
}

/// The topmost missing ancestor of `dir` (`dir` itself when only it is missing), or `None` when
/// `dir` exists (as anything: a file there fails later, with its own error).
fn missing_top(dir: &Path) -> Option<PathBuf> {
    let mut top = None;
    let mut cur = Some(dir);
    while let Some(d) = cur.filter(|d| !d.as_os_str().is_empty()) {
        if std::fs::symlink_metadata(d).is_ok() {
            break;
        }
        top = Some(d.to_path_buf());
        cur = d.parent();
    }
    top
}

/// One rename into place and how to undo it.
#[derive(Debug)]
enum Step {
    /// A new directory tree built at `tmp`, renamed to `to`.
    Tree { tmp: PathBuf, to: PathBuf },
    /// A file written at `tmp`, renamed over `to` (whose previous version, if any, is linked
    /// at `backup`).
    File {
        tmp: PathBuf,
        to: PathBuf,
        backup: Option<PathBuf>,
    },
}

/// The temporary files and trees, then the renames.
#[derive(Debug, Default)]
struct Plan {
    steps: Vec<Step>,
}

fn at(path: &Path) -> impl FnOnce(std::io::Error) -> WriteError + '_ {
    move |error| WriteError {
        path: path.to_path_buf(),
        error,
    }
}

/// Writes `bytes` to a new file at `path` and flushes it to disk.
fn write_new(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    std::fs::File::create_new(path)
        .and_then(|mut f| f.write_all(bytes).and_then(|()| f.sync_all()))
        .map_err(at(path))
}

impl Plan {
    /// Writes every file to its temporary place.
    fn prepare(&mut self, files: Vec<(PathBuf, Vec<u8>)>) -> Result<(), WriteError> {
        // Files under one missing directory share its temporary tree.
        let mut trees: BTreeMap<PathBuf, PathBuf> = BTreeMap::new();
        for (path, bytes) in files {
            let dir = path.parent().unwrap_or(Path::new(""));
            let dir = if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            };
            match missing_top(dir) {
                Some(top) => {
                    let tmp = match trees.get(&top) {
                        Some(tmp) => tmp.clone(),
                        None => {
                            let parent = top.parent().filter(|p| !p.as_os_str().is_empty());
                            let tmp = temporary(parent.unwrap_or(Path::new(".")), "tmp");
                            std::fs::create_dir(&tmp).map_err(at(&top))?;
                            self.steps.push(Step::Tree {
                                tmp: tmp.clone(),
                                to: top.clone(),
                            });
                            trees.insert(top.clone(), tmp.clone());
                            tmp
                        }
                    };
                    // `path` lies under `top`: the same place under the temporary tree.
                    let rel = path.strip_prefix(&top).unwrap_or(&path);
                    let file = tmp.join(rel);
                    if let Some(d) = file.parent() {
                        std::fs::create_dir_all(d).map_err(at(dir))?;
                    }
                    write_new(&file, &bytes).map_err(|e| WriteError { path, ..e })?;
                }
                None => {
                    let tmp = temporary(dir, "tmp");
                    self.steps.push(Step::File {
                        tmp: tmp.clone(),
                        to: path.clone(),
                        backup: None,
                    });
                    write_new(&tmp, &bytes).map_err(|e| WriteError { path, ..e })?;
                }
            }
        }
        Ok(())
    }

    /// Removes the temporary files and trees (nothing was renamed).
    fn discard(&self) {
        for step in &self.steps {
            match step {
                Step::Tree { tmp, .. } => {
                    let _ = std::fs::remove_dir_all(tmp);
                }
                Step::File { tmp, backup, .. } => {
                    let _ = std::fs::remove_file(tmp);
                    if let Some(b) = backup {
                        let _ = std::fs::remove_file(b);
                    }
                }
            }
        }
    }

    /// Renames everything into place; on an error, undoes the renames done and removes the
    /// temporary files.
    fn install(mut self) -> Result<(), WriteError> {
        for k in 0..self.steps.len() {
            if let Err(e) = self.install_step(k) {
                for step in self.steps[..k].iter().rev() {
                    undo(step);
                }
                self.discard();
                return Err(e);
            }
        }
        for step in &self.steps {
            if let Step::File {
                backup: Some(b), ..
            } = step
            {
                let _ = std::fs::remove_file(b);
            }
        }
        Ok(())
    }

    fn install_step(&mut self, k: usize) -> Result<(), WriteError> {
        match &mut self.steps[k] {
            Step::Tree { tmp, to } => std::fs::rename(&*tmp, &*to).map_err(at(to)),
            Step::File { tmp, to, backup } => {
                if std::fs::symlink_metadata(&*to).is_ok_and(|m| m.is_file()) {
                    let dir = to.parent().unwrap_or(Path::new("."));
                    let b = temporary(dir, "old");
                    // A copy where hard links are not supported (FAT).
                    std::fs::hard_link(&*to, &b)
                        .or_else(|_| std::fs::copy(&*to, &b).map(drop))
                        .map_err(at(to))?;
                    *backup = Some(b);
                }
                std::fs::rename(&*tmp, &*to).map_err(at(to))
            }
        }
    }
}

/// Undoes an installed step.
fn undo(step: &Step) {
    match step {
        Step::Tree { to, .. } => {
            let _ = std::fs::remove_dir_all(to);
        }
        Step::File { to, backup, .. } => {
            let _ = match backup {
                Some(b) => std::fs::rename(b, to),
                None => std::fs::remove_file(to),
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh scratch directory.
    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("reachc-output-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_new_directory_appears_with_every_file() {
        let d = scratch("new");
        let mut files = Files::new();
        files.add(d.join("a/b/x.json"), b"1".to_vec());
        files.add(d.join("a/b/y.csv"), b"2".to_vec());
        files.add(d.join("a/c/z.svg"), b"3".to_vec());
        files.commit().unwrap();
        assert_eq!(entries(&d), ["a"]);
        assert_eq!(entries(&d.join("a/b")), ["x.json", "y.csv"]);
        assert_eq!(std::fs::read(d.join("a/c/z.svg")).unwrap(), b"3");
    }

    #[test]
    fn an_error_leaves_the_old_files_and_no_temporary_ones() {
        let d = scratch("old");
        std::fs::write(d.join("x.json"), "old").unwrap();
        // A directory where a file should go: its rename fails after `x.json`'s was done.
        std::fs::create_dir(d.join("y.csv")).unwrap();
        let mut files = Files::new();
        files.add(d.join("x.json"), b"new".to_vec());
        files.add(d.join("y.csv"), b"new".to_vec());
        files.add(d.join("new/z.svg"), b"new".to_vec());
        let e = files.commit().unwrap_err();
        assert_eq!(e.path, d.join("y.csv"));
        assert_eq!(std::fs::read_to_string(d.join("x.json")).unwrap(), "old");
        assert_eq!(entries(&d), ["x.json", "y.csv"]);
    }

    #[test]
    fn a_file_in_the_way_of_a_directory_writes_nothing() {
        let d = scratch("file");
        std::fs::write(d.join("out"), "a file").unwrap();
        let mut files = Files::new();
        files.add(d.join("ok/x.json"), b"1".to_vec());
        files.add(d.join("out/x.json"), b"1".to_vec());
        assert!(files.commit().is_err());
        assert_eq!(entries(&d), ["out"]);
    }

    #[test]
    fn files_in_an_existing_directory_replace_theirs_and_keep_others() {
        let d = scratch("merge");
        std::fs::write(d.join("x.json"), "old").unwrap();
        std::fs::write(d.join("other.txt"), "mine").unwrap();
        let mut files = Files::new();
        files.add(d.join("x.json"), b"new".to_vec());
        files.add(d.join("y.csv"), b"new".to_vec());
        files.commit().unwrap();
        assert_eq!(entries(&d), ["other.txt", "x.json", "y.csv"]);
        assert_eq!(std::fs::read_to_string(d.join("x.json")).unwrap(), "new");
        assert_eq!(
            std::fs::read_to_string(d.join("other.txt")).unwrap(),
            "mine"
        );
    }
}
