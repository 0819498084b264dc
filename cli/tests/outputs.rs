//! Whole outputs and honest exit codes of `reachc run`, `simulate` and `plot` (interpreter
//! backend): a failed analysis keeps the others' files (each whole) and exits 1, write errors
//! are I/O errors (2) that write nothing, `--deny-unsafe` fails on "not shown safe" (3), a
//! result that is not finite is an error of its analysis (1).

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

use common::{file_names, reachc, text};

/// `x' = 400 x` from 0 with a global rate: analysis `short` runs, `long`'s radius overflows.
const GROWING: &str = "radius_overflow.sde";
/// A decay through an unsafe half-space: not shown safe, first at t = 0.3.
const THROUGH: &str = "not_shown_safe.sde";

/// A fresh directory for one test, with `spec.sde` a copy of `tests/good/SPEC`.
fn scratch(name: &str, spec: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("reachc-outputs-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let good = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/good");
    std::fs::copy(good.join(spec), dir.join("spec.sde")).unwrap();
    dir
}

/// `reachc simulate DIR/spec.sde --backend interp EXTRA...`.
fn simulate_interp(dir: &Path, extra: &[&str]) -> Output {
    let spec = dir.join("spec.sde");
    let mut args = vec!["simulate", s(&spec), "--backend", "interp"];
    args.extend_from_slice(extra);
    reachc(&args)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn run_interp(dir: &Path, extra: &[&str]) -> Output {
    let spec = dir.join("spec.sde");
    let mut args = vec!["run", s(&spec), "--backend", "interp"];
    args.extend_from_slice(extra);
    reachc(&args)
}

#[test]
fn a_failed_analysis_keeps_the_others() {
    let dir = scratch("failed", GROWING);
    let out = dir.join("out");
    let o = run_interp(&dir, &["-o", s(&out)]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    // `short` ran and is written, whole; `long` did not, and says so.
    assert_eq!(file_names(&out), ["short.csv", "short.json"]);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("short.json")).unwrap()).unwrap();
    assert_eq!(json["analysis"], "short");
    assert!(text(&o).contains("error: 1 analysis of 2 failed (the others' files are written)"));
    // Into an existing folder: the old file of `short` is replaced, no file of `long` appears.
    std::fs::remove_dir_all(&out).unwrap();
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("short.json"), "old").unwrap();
    let o = run_interp(&dir, &["-o", s(&out)]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert_eq!(file_names(&out), ["short.csv", "short.json"]);
    assert!(std::fs::read_to_string(out.join("short.json"))
        .unwrap()
        .contains("\"analysis\": \"short\""));
    // With --plot, results and pictures go together: `short` cannot be drawn (one state), so
    // neither is written.
    std::fs::remove_dir_all(&out).unwrap();
    let plots = dir.join("plots");
    let o = run_interp(&dir, &["-o", s(&out), "--plot", s(&plots)]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("a 2-D plot needs two states"),
        "{}",
        text(&o)
    );
    assert!(!plots.exists() && !out.exists());
    // The analysis that runs alone: exit 0.
    let o = run_interp(&dir, &["-o", s(&out), "--analysis", "short"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_eq!(file_names(&out), ["short.csv", "short.json"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_result_that_is_not_finite_is_an_error_of_its_analysis() {
    let dir = scratch("infinite", GROWING);
    let out = dir.join("out");
    let o = run_interp(&dir, &["-o", s(&out), "--analysis", "long"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let stderr = String::from_utf8_lossy(&o.stderr);
    let message = "the PRS is not finite from t = 1.8 on: the stochastic radius r_t = inf: \
                   Psi_t overflowed (c = 400, sigma = 1";
    assert!(stderr.contains(message), "{stderr}");
    // Located at the horizon of `long` (line 20 of tests/good/radius_overflow.sde).
    assert!(stderr.contains("spec.sde:20:5 ]"), "{stderr}");
    assert!(!out.exists());
    // simulate: the same error, nothing written.
    let o = simulate_interp(
        &dir,
        &["--paths", "10", "--analysis", "long", "-o", s(&out)],
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains(message), "{}", text(&o));
    assert!(!out.exists());
    // simulate without --analysis: `short`'s report is written.
    let o = simulate_interp(&dir, &["--paths", "10", "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert_eq!(file_names(&out), ["short.sim.json"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn write_errors_exit_2_and_write_nothing() {
    let dir = scratch("write", THROUGH);
    let file = dir.join("a-file");
    std::fs::write(&file, "mine").unwrap();
    let long = dir.join("n".repeat(300));
    for target in [file.clone(), PathBuf::from("/proc/reachc-out"), long] {
        let o = run_interp(&dir, &["-o", s(&target)]);
        assert_eq!(
            o.status.code(),
            Some(2),
            "run -o {}: {}",
            target.display(),
            text(&o)
        );
        assert!(text(&o).contains("(nothing written)"), "{}", text(&o));
        let o = simulate_interp(&dir, &["--paths", "20", "-o", s(&target)]);
        assert_eq!(
            o.status.code(),
            Some(2),
            "simulate -o {}: {}",
            target.display(),
            text(&o)
        );
    }
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "mine");
    assert_eq!(file_names(&dir), ["a-file", "spec.sde"]);
    // An analysis the spec does not have is a usage error.
    let o = run_interp(&dir, &["--analysis", "nope", "-o", s(&dir.join("out"))]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("has no analysis `nope` (available: contraction)"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn deny_unsafe_fails_on_not_shown_safe_and_writes_the_results() {
    let dir = scratch("deny", THROUGH);
    let out = dir.join("out");
    let o = run_interp(&dir, &["-o", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    // Report times print as the decimals they stand for.
    assert!(
        text(&o).contains(
            "verdict: not shown safe: the PRS over the interval ending at t = 0.3 meets `low`"
        ),
        "{}",
        text(&o)
    );
    std::fs::remove_dir_all(&out).unwrap();
    let o = run_interp(&dir, &["-o", s(&out), "--deny-unsafe"]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("error: not shown safe (--deny-unsafe)"));
    assert_eq!(file_names(&out), ["contraction.csv", "contraction.json"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--probability`: the bound and what limits it, printed and in the JSON. The decay from 1
/// crosses `x <= 0.5` at t = ln(2) / 3 without noise: no delta helps, one run.
#[test]
fn probability_prints_its_bound_and_limit() {
    let dir = scratch("probability", THROUGH);
    let out = dir.join("out");
    let o = run_interp(&dir, &["-o", s(&out), "--probability"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(
        text(&o).contains(
            "P(safe on [0, 1]): no bound (1 run; the deterministic set alone is not shown to \
             avoid `low` at t = 0.3, so no delta helps"
        ),
        "{}",
        text(&o)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("contraction.json")).unwrap())
            .unwrap();
    let p = &json["safety_probability"];
    assert_eq!(p["lower_bound"], serde_json::Value::Null);
    assert_eq!(
        (p["runs"].as_u64(), p["proved"].as_bool()),
        (Some(1), Some(true))
    );
    assert_eq!(
        (p["limit"]["kind"].as_str(), p["limit"]["set"].as_str()),
        (Some("deterministic"), Some("low"))
    );
    // Without the flag, no such field.
    let o = run_interp(&dir, &["-o", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let plain = std::fs::read_to_string(out.join("contraction.json")).unwrap();
    assert!(!plain.contains("safety_probability") && !text(&o).contains("P(safe"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn messages_count_in_the_singular_and_plural() {
    let dir = scratch("counts", THROUGH);
    let spec = dir.join("spec.sde");
    let o = reachc(&["check", s(&spec)]);
    assert_eq!(
        String::from_utf8_lossy(&o.stdout),
        "ok: model `through` (1 state, 0 inputs, 1 noise channel, 1 analysis)\n"
    );
    let o = reachc(&["check", &common::spec("linear.sde")]);
    assert_eq!(
        String::from_utf8_lossy(&o.stdout),
        "ok: model `linear` (2 states, 0 inputs, 2 noise channels, 3 analyses)\n"
    );
    let o = simulate_interp(
        &dir,
        &["--paths", "1", "--threads", "1", "-o", s(&dir.join("out"))],
    );
    let t = text(&o);
    assert!(
        t.contains(
            "  1 path (seed 0), Euler-Maruyama with dt = 0.00103092783505 to 0.01 (463 steps \
             per path; chosen by the rules h L <= 0.05 and bias <= 0.05 of the half-width)"
        ),
        "{t}"
    );
    assert!(t.contains(" path-steps/s, 1 thread)\n"), "{t}");
    std::fs::remove_dir_all(&dir).unwrap();
}
