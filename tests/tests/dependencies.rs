//! The crates keep their jobs: what a build script pulls in with `reachc-compiler`, and what a
//! generated crate pulls in with `reachc-runtime` (no default features) or `reachc-core`, never
//! reaches the CLI's dependencies (`cargo tree` on the locked workspace).

use reachc_e2e::workspace;
use std::process::Command;

/// The normal dependencies of `package` with only `features` (no default features),
/// transitively, by name, the package first.
fn dependencies(package: &str, features: &[&str]) -> Vec<String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(workspace())
        .args([
            "tree",
            "--locked",
            "--offline",
            "-e",
            "normal",
            "--prefix",
            "none",
        ])
        .args(["--format", "{p}", "-p", package, "--no-default-features"]);
    if !features.is_empty() {
        cmd.args(["--features", &features.join(",")]);
    }
    let out = cmd.output().expect("cargo tree runs");
    assert!(
        out.status.success(),
        "cargo tree -p {package}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_string)
        .collect()
}

const CLI_ONLY: [&str; 5] = ["clap", "plotters", "indicatif", "png", "ab_glyph"];

#[test]
fn the_compiler_library_has_none_of_the_clis_dependencies() {
    let deps = dependencies("reachc-compiler", &[]);
    assert!(deps.iter().any(|d| d == "reachc-core"), "{deps:?}");
    for cli in CLI_ONLY {
        assert!(
            !deps.iter().any(|d| d == cli),
            "reachc-compiler depends on {cli}"
        );
    }
    assert!(!deps.iter().any(|d| d == "reachc-runtime"), "{deps:?}");
}

#[test]
fn the_core_and_the_light_runtime_have_no_dependencies() {
    assert_eq!(dependencies("reachc-core", &[]), ["reachc-core"]);
    assert_eq!(
        dependencies("reachc-runtime", &[]),
        ["reachc-runtime", "reachc-core"]
    );
    // The report feature adds serde; Monte Carlo adds rayon; neither adds the CLI's crates.
    let full = dependencies("reachc-runtime", &["app"]);
    assert!(full.iter().any(|d| d == "serde_json") && full.iter().any(|d| d == "rayon"));
    for cli in CLI_ONLY {
        assert!(
            !full.iter().any(|d| d == cli),
            "reachc-runtime depends on {cli}"
        );
    }
}
