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

/// A scratch directory for one test (emptied first).
fn scratch(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("reachc-cli-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `reachc simulate SPEC --backend interp --analysis uniform --paths 1000 ARGS`.
fn simulate_linear(spec: &str, args: &[&str]) -> std::process::Output {
    let base = [
        "simulate",
        spec,
        "--backend",
        "interp",
        "--analysis",
        "uniform",
        "--paths",
        "1000",
        "--delta",
        "0.05",
    ];
    let o = reachc(&[&base[..], args].concat());
    assert_eq!(o.status.code(), Some(0), "{args:?}: {o:?}");
    o
}

/// The parts of `K` shards of the linear example's uniform analysis, in `dir/parts-K`.
fn shards(dir: &std::path::Path, k: u64, more: &[&str]) -> Vec<String> {
    let parts = dir.join(format!("parts-{k}{}", more.join("")));
    (0..k)
        .map(|i| {
            let shard = format!("{i}/{k}");
            let o = simulate_linear(
                &spec("linear.sde"),
                &[&["--shard", &shard, "-o", parts.to_str().unwrap()], more].concat(),
            );
            let out = String::from_utf8_lossy(&o.stdout);
            let (lo, hi) = (i * 1000 / k, (i + 1) * 1000 / k);
            assert!(
                out.contains(&format!(
                    "simulated `uniform`, shard {shard}: paths {lo}..{hi} of 1000"
                )),
                "{out}"
            );
            let file = parts.join(format!("uniform.shard-{i}-of-{k}.part"));
            assert!(out.contains(&format!("wrote {}", file.display())), "{out}");
            file.display().to_string()
        })
        .collect()
}

#[test]
fn merged_shards_are_the_unsharded_report_byte_for_byte() {
    let dir = scratch("shards");
    let whole = dir.join("whole");
    simulate_linear(&spec("linear.sde"), &["-q", "-o", whole.to_str().unwrap()]);
    let want = std::fs::read(whole.join("uniform.sim.json")).unwrap();
    for k in [1, 3, 4, 7] {
        let mut parts = shards(&dir, k, &[]);
        parts.reverse();
        let merged = dir.join(format!("merged-{k}"));
        let args = [
            &["simulate", "merge"][..],
            &parts.iter().map(String::as_str).collect::<Vec<_>>(),
            &["-o", merged.to_str().unwrap()],
        ]
        .concat();
        let o = reachc(&args);
        let out = String::from_utf8_lossy(&o.stdout);
        assert_eq!(o.status.code(), Some(0), "{o:?}");
        assert!(out.contains("coverage: PASS"), "{out}");
        assert!(
            std::fs::read(merged.join("uniform.sim.json")).unwrap() == want,
            "{k} shards: the merged report differs"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn merge_refuses_parts_that_do_not_belong_together() {
    let dir = scratch("bad-shards");
    let parts = shards(&dir, 3, &[]);
    let seed = shards(&dir, 3, &["--seed", "9"]);
    let paths = {
        let p = dir.join("paths");
        let shard = [
            "--shard",
            "1/3",
            "--paths",
            "999",
            "-o",
            p.to_str().unwrap(),
        ];
        let o = reachc(
            &[
                &[
                    "simulate",
                    &spec("linear.sde"),
                    "--backend",
                    "interp",
                    "--analysis",
                    "uniform",
                    "--delta",
                    "0.05",
                ][..],
                &shard,
            ]
            .concat(),
        );
        assert_eq!(o.status.code(), Some(0), "{o:?}");
        p.join("uniform.shard-1-of-3.part").display().to_string()
    };
    // The same spec with one more comment: another SHA-256.
    let other_spec = dir.join("linear.sde");
    let source = std::fs::read_to_string(spec("linear.sde")).unwrap();
    std::fs::write(&other_spec, source + "// a copy\n").unwrap();
    let other = {
        let p = dir.join("other");
        simulate_linear(
            other_spec.to_str().unwrap(),
            &["--shard", "1/3", "-o", p.to_str().unwrap()],
        );
        p.join("uniform.shard-1-of-3.part").display().to_string()
    };
    let json = dir.join("report.sim.json");
    std::fs::write(&json, "{}\n").unwrap();
    let truncated = dir.join("truncated.part");
    let bytes = std::fs::read(&parts[1]).unwrap();
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let (json, truncated) = (json.display().to_string(), truncated.display().to_string());
    let missing = dir.join("nope.part").display().to_string();
    let (p0, p1, p2) = (parts[0].as_str(), parts[1].as_str(), parts[2].as_str());
    for (files, message) in [
        (vec![p0, p2], "error: analysis `uniform`: missing shard 1/3 (have 2 of 3)".to_string()),
        (vec![p0, p1, p1, p2], format!("error: `{p1}` and `{p1}` are both shard 1/3")),
        (
            vec![p0, &seed[1], p2],
            format!("error: `{}` and `{p0}` are not parts of the same simulation: seed 9 there, 0 in the first part", seed[1]),
        ),
        (
            vec![p0, &paths, p2],
            format!("error: `{paths}` and `{p0}` are not parts of the same simulation: paths 999 there, 1000 in the first part"),
        ),
        (vec![p0, &other, p2], format!("error: `{other}` and `{p0}` are parts of different specs")),
        (vec![p0, &json, p2], format!("error: {json}: not a reachc simulate part file")),
        (vec![p0, &truncated, p2], format!("error: {truncated}: corrupt or truncated")),
        (vec![p0, &missing], format!("error: cannot read {missing}: ")),
    ] {
        let out = dir.join("merged");
        let o = reachc(&[&["simulate", "merge", "-o", out.to_str().unwrap()][..], &files].concat());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{files:?}: {err}");
        assert!(err.starts_with(&message), "{files:?}: {err}");
        assert!(err.trim_end().ends_with("(nothing written)"), "{err}");
        assert!(!out.exists());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 26: a stiff system (`x' = -20 x + y`, report step 0.1) whose PRS is correct. With the
/// default steps (`h L <= 0.05`: `L = min(||J||_inf, ||J||_1) = 20`, so `h = 0.0025`, 40 steps
/// per report step) the check passes; `--dt 0.1`, the old default, is honoured with a
/// warning (`h L = 2`), and its Euler-Maruyama error shows as paths outside.
#[test]
fn simulate_chooses_dt_from_the_dynamics_on_a_stiff_system() {
    let dir = std::env::temp_dir().join(format!("reachc-cli-sim-stiff-{}", std::process::id()));
    let d = dir.to_str().unwrap();
    let stiff = spec("../tests/good/stiff.sde");
    let sim = |extra: &[&str]| {
        let mut args = vec![
            "simulate",
            &stiff,
            "--backend",
            "interp",
            "--paths",
            "4000",
            "-o",
            d,
        ];
        args.extend_from_slice(extra);
        let o = reachc(&args);
        let json: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.join("contraction.sim.json")).unwrap(),
        )
        .unwrap();
        (o, json)
    };
    let (o, json) = sim(&[]);
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert_eq!(o.status.code(), Some(0), "{out}\n{err}");
    assert!(
        out.contains(
            "Euler-Maruyama with dt = 0.0025 (800 steps per path; chosen by the rules h L <= \
             0.05 and bias <= 0.05 of the half-width)"
        ),
        "{out}"
    );
    assert!(!err.contains("warning"), "{err}");
    assert_eq!(json["verdict"]["status"], "pass");
    // The linearised member's Gaussian box is sharp (method.md 8.10): a few paths of 4000 may
    // leave the tube (4 measured, 0.1%) against delta = 1%; a wrong step leaves far more.
    let outside = json["outside_tube"]["count"].as_u64().unwrap();
    assert!(outside <= 10, "{outside} paths outside");
    assert_eq!(json["steps_per_path"], 800);
    let rule = &json["dt_rule"];
    assert_eq!(rule["source"], "rule");
    assert_eq!(rule["status"], "met");
    assert_eq!(rule["coarse_intervals"], 0);
    assert_eq!(rule["rule_min"], 0.0025);
    let hl = rule["hl_max"].as_f64().unwrap();
    assert!((hl - 0.05).abs() < 1e-12, "{hl}");
    let dt = json["dt"].as_f64().unwrap();
    assert!((dt - 0.0025).abs() < 1e-15, "{dt}");

    let (o, json) = sim(&["--dt", "0.1"]);
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert_eq!(o.status.code(), Some(1), "{out}\n{err}");
    assert!(
        err.contains(
            "warning: analysis `contraction`: --dt 0.1 is coarser than the rules h L <= 0.05 \
             and bias <= 0.05 of the half-width ask on 20 report intervals (h L up to 2.000, \
             Euler-Maruyama's bias up to 0.762 of the sets' half-width; the rules' step: 0.0025)"
        ),
        "{err}"
    );
    assert!(out.contains("  warning: --dt 0.1 is coarser"), "{out}");
    assert_eq!(json["dt_rule"]["status"], "coarser");
    assert_eq!(json["dt_rule"]["coarse_intervals"], 20);
    assert_eq!(json["steps_per_path"], 20);
    assert_eq!(json["verdict"]["status"], "fail");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A small set moving fast (`x' = 2 - x` from a box of half-width 0.01, noise 0.002,
/// tests/good/drift_bias.sde): the stability rule alone (`L = 1`) takes `h = 0.05`, where
/// Euler-Maruyama's drift error on every path, about `(h / 2) |f' f| t`, is larger than the
/// exact Gaussian PRS: every path is outside. The bias rule (method.md, the Euler-Maruyama step)
/// takes steps down to 0.0011 and the check passes.
#[test]
fn simulate_keeps_euler_maruyama_bias_small_against_the_set() {
    let dir = std::env::temp_dir().join(format!("reachc-cli-sim-bias-{}", std::process::id()));
    let d = dir.to_str().unwrap();
    let bias = spec("../tests/good/drift_bias.sde");
    let sim = |extra: &[&str]| {
        let mut args = vec![
            "simulate",
            &bias,
            "--backend",
            "interp",
            "--paths",
            "2000",
            "-o",
            d,
        ];
        args.extend_from_slice(extra);
        let o = reachc(&args);
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("exact.sim.json")).unwrap())
                .unwrap();
        (o, json)
    };
    let (o, json) = sim(&[]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{out}");
    assert_eq!(json["verdict"]["status"], "pass");
    assert_eq!(json["outside_tube"]["count"], 0);
    let rule = &json["dt_rule"];
    assert_eq!(rule["status"], "met");
    assert_eq!(rule["accuracy"], 0.05);
    let bias_max = rule["bias_max"].as_f64().unwrap();
    assert!(bias_max <= 0.05 * (1.0 + 1e-9), "{bias_max}");
    let dt_min = json["dt_min"].as_f64().unwrap();
    assert!(dt_min < 0.002, "{dt_min}");
    // The stability rule's step alone: every path outside.
    let (o, json) = sim(&["--dt", "0.05"]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(json["dt_rule"]["status"], "coarser");
    let hl = json["dt_rule"]["hl_max"].as_f64().unwrap();
    assert!((hl - 0.05).abs() < 1e-12, "{hl}");
    assert_eq!(json["outside_tube"]["count"], 2000);
    std::fs::remove_dir_all(&dir).unwrap();
}
