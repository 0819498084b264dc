//! `reachc simulate` with the interpreter backend: exit codes, the report file, skipped
//! analyses and usage errors.

mod common;

use common::{reachc, spec};

#[test]
fn simulate_linear_writes_a_passing_report() {
    let dir = std::env::temp_dir().join(format!("reachc-cli-sim-{}", std::process::id()));
    let d = dir.to_str().unwrap();
    let o = reachc(&[
        "simulate",
        &spec("linear.sde"),
        "--backend",
        "interp",
        "--analysis",
        "amgf_rule",
        "--paths",
        "2000",
        "--delta",
        "0.01",
        "-o",
        d,
    ]);
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert_eq!(o.status.code(), Some(0), "{out}\n{err}");
    assert!(out.contains("coverage: PASS"), "{out}");
    // Not a terminal: no progress bar or progress lines.
    assert!(!err.contains("reachc-progress"), "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("amgf_rule.sim.json")).unwrap())
            .unwrap();
    assert_eq!(json["model"], "linear");
    assert_eq!(json["delta"], 0.01);
    assert_eq!(json["verdict"]["status"], "pass");
    assert_eq!(json["steps"][150]["t"], 1.5);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn simulate_skips_analyses_without_a_prs_and_reports_usage_errors() {
    let dir = std::env::temp_dir().join(format!("reachc-cli-sim-skip-{}", std::process::id()));
    let d = dir.to_str().unwrap();
    let o = reachc(&[
        "simulate",
        &spec("../tests/good/unbounded_rate.sde"),
        "--backend",
        "interp",
        "--paths",
        "10",
        "-o",
        d,
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains("skipped analysis `contraction`: no PRS to check"),
        "{err}"
    );

    let linear = spec("linear.sde");
    for args in [
        &["simulate", &linear, "--backend", "interp"][..],
        &["simulate", &linear, "--backend", "interp", "--paths", "0"],
        &[
            "simulate",
            &linear,
            "--backend",
            "interp",
            "--paths",
            "5",
            "--inputs",
            "up",
        ],
        &[
            "simulate",
            &linear,
            "--backend",
            "interp",
            "--paths",
            "5",
            "--analysis",
            "x",
        ],
        &["simulate", "no/such/spec.sde", "--paths", "5"],
    ] {
        let o = reachc(args);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
