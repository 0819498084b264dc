//! Helpers shared by the tests of the `reachc` binary (`mod common;` in each test file).

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
