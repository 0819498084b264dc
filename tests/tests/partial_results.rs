//! Several analyses, one failing at run time: the finished ones are written (each whole), the
//! failure is reported and named as a `reachc-failure` line with `--error-lines`, exit code 1;
//! for `run` and `simulate`, through the interpreter (the generated binary's `main` on the
//! interpreter, `run_cli`) and through a generated crate compiled with cargo. Also: the failure
//! line of every spec in tests/run_errors/ names the culprit its `// expect:` line gives.

use std::path::{Path, PathBuf};
use std::process::Command;

use reachc_compiler::driver::load;
use reachc_compiler::package::{Cache, Profile};
use reachc_e2e::{interpreter_of, workspace};
use reachc_runtime::app::{run_cli, EXIT_FAILED};
use reachc_runtime::engine::{Culprit, Setting};
use reachc_runtime::failure::Failure;
use reachc_test_support::files::with_extension;

/// `x' = x^2` from [0.5, 0.6]: `good` (horizon 0.2) runs, `blows_up` (horizon 3) cannot.
fn spec() -> PathBuf {
    workspace().join("tests/run_errors/box_blows_up.sde")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("reachc-partial-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The binary's command line `args` on the interpreter of `spec`: exit code and stderr.
fn interpreted(spec: &Path, args: &[String]) -> (u8, String) {
    let (sys, _) = interpreter_of(load(spec).unwrap().model);
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = run_cli(&sys, args, &mut out, &mut err);
    (code, String::from_utf8_lossy(&err).into_owned())
}

/// The same command line on the spec's generated crate, compiled with cargo (dev profile).
fn compiled(spec: &Path, args: &[String]) -> (u8, String) {
    let cache = Cache::new(
        workspace().join("target").join("reachc-e2e-cache"),
        workspace().join("target").join("reachc-crates"),
    );
    let binary = cache
        .binary(&mut load(spec).unwrap(), Profile::Dev, &mut |_| {})
        .unwrap_or_else(|e| panic!("{e}"));
    let o = Command::new(&binary.path).args(args).output().unwrap();
    let code = o.status.code().and_then(|c| u8::try_from(c).ok()).unwrap();
    (code, String::from_utf8_lossy(&o.stderr).into_owned())
}

fn args(v: &[&str], out: &Path) -> Vec<String> {
    let mut a: Vec<String> = v.iter().map(|s| s.to_string()).collect();
    a.extend(["-o".to_string(), out.display().to_string()]);
    a
}

/// The failure lines in `stderr`.
fn failures(stderr: &str) -> Vec<Failure> {
    stderr.lines().filter_map(Failure::parse_line).collect()
}

/// `out/good.json` written whole: its boxes enclose the exact flow `x0 / (1 - x0 t)` of both
/// ends of the initial box; `blows_up` has no file.
fn check_run_outputs(out: &Path) -> serde_json::Value {
    let json = std::fs::read_to_string(out.join("good.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let steps = v["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 5);
    for s in steps {
        let t = s["t"].as_f64().unwrap();
        let (lo, hi) = (
            s["det_set"]["lo"][0].as_f64().unwrap(),
            s["det_set"]["hi"][0].as_f64().unwrap(),
        );
        let exact = |x0: f64| x0 / (1.0 - x0 * t);
        assert!(
            lo <= exact(0.5) && exact(0.6) <= hi,
            "t = {t}: [{lo}, {hi}]"
        );
        // Tight: within 1% of the exact interval at t = 0.2.
        assert!(
            hi - lo <= 1.01 * (exact(0.6) - exact(0.5)) + 1e-3,
            "t = {t}"
        );
    }
    let csv = std::fs::read_to_string(out.join("good.csv")).unwrap();
    assert_eq!(csv.lines().count(), 6);
    assert!(!out.join("blows_up.json").exists() && !out.join("blows_up.csv").exists());
    v
}

fn check_failure(stderr: &str) {
    let f = failures(stderr);
    assert_eq!(f.len(), 1, "{stderr}");
    assert_eq!(f[0].analysis, "blows_up");
    assert_eq!(f[0].culprit, Some(Culprit::Setting(Setting::Inclusion)));
    assert!(
        f[0].message
            .starts_with("could not run: numerical failure: the embedding system"),
        "{stderr}"
    );
    assert!(
        stderr.contains("error: 1 analysis of 2 failed (the others' files are written)"),
        "{stderr}"
    );
}

#[test]
fn a_failing_analysis_keeps_the_other_on_both_backends() {
    let dir = scratch("both");
    let mut results = Vec::new();
    for (backend, run) in [
        (
            "interp",
            interpreted as fn(&Path, &[String]) -> (u8, String),
        ),
        ("compiled", compiled),
    ] {
        let out = dir.join(backend);
        let (code, err) = run(&spec(), &args(&["-q", "--error-lines"], &out));
        assert_eq!(code, EXIT_FAILED, "{backend}: {err}");
        check_failure(&err);
        results.push(check_run_outputs(&out));
        // Without --error-lines: the same failure in prose.
        let (code, err) = run(
            &spec(),
            &args(&["-q"], &dir.join(format!("{backend}-prose"))),
        );
        assert_eq!(code, EXIT_FAILED, "{backend}: {err}");
        assert!(
            err.starts_with("error: analysis `blows_up` could not run: numerical failure:"),
            "{err}"
        );
        // simulate: `good`'s report is written, the failure reported the same way.
        let sim = dir.join(format!("{backend}-sim"));
        let (code, err) = run(
            &spec(),
            &args(&["simulate", "--paths", "200", "-q", "--error-lines"], &sim),
        );
        assert_eq!(code, EXIT_FAILED, "{backend}: {err}");
        check_failure(&err);
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(sim.join("good.sim.json")).unwrap())
                .unwrap();
        assert_eq!(report["analysis"], "good");
        assert_eq!(report["paths"], 200);
        assert!(!sim.join("blows_up.sim.json").exists());
    }
    // The two backends compute the same result.
    assert_eq!(results[0], results[1]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_run_error_spec_names_its_culprit() {
    let specs = with_extension(&workspace().join("tests/run_errors"), "sde");
    assert!(specs.len() >= 5);
    let out = scratch("culprits");
    for spec in specs {
        let text = std::fs::read_to_string(&spec).unwrap();
        let expect = text
            .lines()
            .next()
            .unwrap()
            .strip_prefix("// expect: ")
            .unwrap();
        let token = expect.split(' ').nth(1).unwrap();
        let culprit = (token != "-").then(|| Culprit::parse(token).unwrap());
        let (code, err) = interpreted(&spec, &args(&["-q", "--error-lines"], &out));
        assert_eq!(code, EXIT_FAILED, "{}: {err}", spec.display());
        let f = failures(&err);
        assert_eq!(f.len(), 1, "{}: {err}", spec.display());
        assert_eq!(f[0].culprit, culprit, "{}: {err}", spec.display());
    }
    std::fs::remove_dir_all(&out).unwrap();
}
