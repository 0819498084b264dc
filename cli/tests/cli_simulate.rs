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

/// The linear example (the model of specs/linear.sde) with its amgf analysis time-uniform
/// (written here, so that the test does not depend on which analyses the shipped spec makes
/// uniform): `reachc simulate` with 20000 paths through the interpreter passes the uniform
/// check, with a fraction of paths leaving the tube well below delta, at the analysis' step
/// and with four Euler-Maruyama steps per report interval.
#[test]
fn simulate_linear_checks_the_uniform_tube() {
    let dir = std::env::temp_dir().join(format!("reachc-cli-sim-tube-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let spec = dir.join("linear.sde");
    std::fs::write(
        &spec,
        "model linear\n\
         const a = -0.4\n\
         const s = sqrt(2)\n\
         state x1 = 0\n\
         state x2 = 0\n\
         noise w1\n\
         noise w2\n\
         drift {\n    x1' = a * x1\n    x2' = a * x2\n}\n\
         diffusion {\n    x1: s * w1\n    x2: s * w2\n}\n\
         analysis amgf_rule {\n    method = contraction\n    delta = 1e-3\n    horizon = 1.5\n    \
         step = 0.01\n    radius = amgf\n    guarantee = uniform\n}\n",
    )
    .unwrap();
    let (spec, d) = (spec.to_str().unwrap(), dir.to_str().unwrap());
    for (dt, checks) in [(None, 151), (Some("0.0025"), 601)] {
        let mut args = vec![
            "simulate",
            spec,
            "--analysis",
            "amgf_rule",
            "--paths",
            "20000",
            "--backend",
            "interp",
            "-o",
            d,
        ];
        if let Some(dt) = dt {
            args.extend(["--dt", dt]);
        }
        let o = reachc(&args);
        let (out, err) = (
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr),
        );
        assert_eq!(o.status.code(), Some(0), "{out}\n{err}");
        assert!(out.contains("coverage: PASS (uniform: "), "{out}");
        assert!(out.contains("tube, all times at once: "), "{out}");
        assert!(!out.contains("each time separately"), "{out}");
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("amgf_rule.sim.json")).unwrap())
                .unwrap();
        assert_eq!(json["guarantee"], "uniform");
        assert_eq!(json["verdict"]["decided_by"], "uniform");
        let tube = &json["outside_tube"];
        assert_eq!(tube["checks_per_path"], checks);
        // delta = 1e-3: about 1e-4 of the paths leave (a handful of the 20000).
        let fraction = tube["fraction"].as_f64().unwrap();
        assert!(fraction < 4e-4, "{tube}");
        assert!(tube["cp_lower"].as_f64().unwrap() < 1e-4, "{tube}");
        // Every path outside the PRS at a report time has left the tube.
        assert!(tube["count"].as_u64() >= json["horizon"]["outside_any"].as_u64());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
