//! Files for tests: scratch folders to write in, and the files of a folder by extension.

use std::path::{Path, PathBuf};

/// A fresh, empty folder `reachc-NAME-PID` in the temporary directory, removed on drop.
pub struct Scratch(pub PathBuf);

impl Scratch {
    /// The folder for `name` (unique per test and worker), emptied if it is left over.
    pub fn new(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("reachc-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("the temporary folder is writable");
        Scratch(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The files `*.EXTENSION` in `dir`, sorted; panics (naming `dir`) when it cannot be read.
pub fn with_extension(dir: &Path, extension: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == extension))
        .collect();
    files.sort();
    files
}
