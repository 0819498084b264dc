//! Helpers shared by the tests of the `reachc` binary (`mod common;` in each test file).

#![allow(dead_code)] // each test file uses some of them

use std::path::Path;
use std::process::{Command, Output};

/// Runs the `reachc` binary with `args`; its exit status and output.
pub fn reachc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_reachc"))
        .args(args)
        .output()
        .expect("the reachc binary runs")
}

/// The path of the shipped spec `specs/NAME`.
pub fn spec(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../specs")
        .join(name)
        .display()
        .to_string()
}

/// A command's stdout and stderr, one after the other (for assertions and their messages).
pub fn text(o: &Output) -> String {
    format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The names of the entries of `dir`, sorted.
pub fn file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
