//! Run-time failures located in the spec: every spec of tests/run_errors/ passes `check`, then
//! `reachc run` (and `simulate`) exits 1 with a diagnostic at the place its first line names
//! (`// expect: LINE:COL CULPRIT`): the setting to change, the state, or the analysis.

mod common;

use std::path::{Path, PathBuf};

use common::reachc;
use reachc_test_support::files::with_extension;

/// The specs of tests/run_errors/, sorted.
fn specs() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/run_errors");
    let v = with_extension(&dir, "sde");
    assert!(v.len() >= 5, "{v:?}");
    v
}

/// The `LINE:COL` of a spec's `// expect:` line.
fn expected_location(spec: &Path) -> String {
    let text = std::fs::read_to_string(spec).unwrap();
    let first = text.lines().next().unwrap();
    let rest = first.strip_prefix("// expect: ").unwrap();
    rest.split(' ').next().unwrap().to_string()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("reachc-run-errors-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn every_run_time_failure_is_located_in_the_spec() {
    let dir = scratch("run");
    for spec in specs() {
        let (path, at) = (spec.to_str().unwrap(), expected_location(&spec));
        let check = reachc(&["check", path]);
        assert_eq!(check.status.code(), Some(0), "{path}");
        let out = dir.join("out");
        // `simulate` skips an analysis without constants (there is no PRS to check).
        let simulate = &["simulate", "--backend", "interp", "--paths", "20"][..];
        let commands = if spec.ends_with("no_constants.sde") {
            vec![&["run", "--backend", "interp"][..]]
        } else {
            vec![&["run", "--backend", "interp"][..], simulate]
        };
        for command in commands {
            let o = reachc(&[command, &[path, "-o", out.to_str().unwrap()]].concat());
            let stderr = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(1), "{path} {command:?}: {stderr}");
            // The failure is an error diagnostic, at the expected place.
            assert!(stderr.contains("Error: analysis `"), "{path}: {stderr}");
            assert!(
                stderr.contains(&format!("╭─[ {path}:{at} ]")),
                "{path} {command:?}: expected at {at}: {stderr}"
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_failure_names_the_setting_to_change_and_the_analysis() {
    let dir = scratch("setting");
    let spec = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/run_errors/box_blows_up.sde");
    let path = spec.to_str().unwrap();
    let out = dir.join("out");
    let o = reachc(&[
        "run",
        "--backend",
        "interp",
        path,
        "-o",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(
            "Error: analysis `blows_up` could not run: numerical failure: the embedding system \
             cannot be validated at t = 1.66579467492"
        ),
        "{stderr}"
    );
    for label in [
        "the setting to change",
        "in analysis `blows_up`",
        "inclusion = jacobian",
    ] {
        assert!(stderr.contains(label), "{label}: {stderr}");
    }
    assert!(
        stderr
            .trim_end()
            .ends_with("error: 1 analysis of 2 failed (the others' files are written)"),
        "{stderr}"
    );
    // The analysis that ran is written.
    assert!(out.join("good.json").is_file() && !out.join("blows_up.json").exists());
    // A default setting: the analysis' name, and the key to set.
    let spec = spec.with_file_name("inclusion_default.sde");
    let o = reachc(&[
        "run",
        "--backend",
        "interp",
        spec.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("this analysis, with the default `inclusion`"),
        "{stderr}"
    );
    assert!(
        stderr.contains("set `inclusion = ...` in the block"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
