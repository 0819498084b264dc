//! Helpers for the workspace-level end-to-end tests: where the shipped specs and the bad-spec
//! corpus live, and a renderer that names files relative to the workspace (stable snapshots).

use std::path::{Path, PathBuf};

/// The workspace root.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the workspace")
        .to_path_buf()
}

/// Every shipped spec, sorted by name.
pub fn shipped_specs() -> Vec<PathBuf> {
    let mut specs: Vec<PathBuf> = std::fs::read_dir(workspace().join("specs"))
        .expect("specs/ exists")
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "sde"))
        .collect();
    specs.sort();
    specs
}

/// The path of `p` relative to the workspace, with `/` separators (for snapshot stability).
pub fn relative(p: &Path) -> String {
    p.strip_prefix(workspace())
        .unwrap_or(p)
        .to_string_lossy()
        .replace('\\', "/")
}
