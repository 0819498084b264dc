//! The `reachc` binary: exit codes, diagnostics on stderr, and `inspect --json` values.

mod common;

use std::path::PathBuf;
use std::process::Output;

use common::{reachc, spec};

fn temp_spec(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("reachc-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn check_exit_codes() {
    let ok = reachc(&["check", &spec("pendulum.sde")]);
    assert_eq!(ok.status.code(), Some(0), "{}", stderr(&ok));
    assert!(String::from_utf8_lossy(&ok.stdout).contains("model `pendulum` (2 states"));

    let bad = temp_spec("bad.sde", "model m\nstate x in [0, 1]\ndrift { x' = -y }\n");
    let out = reachc(&["check", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("undefined name `y`"), "{err}");
    assert!(
        err.contains("bad.sde:3:"),
        "diagnostic names file and line: {err}"
    );

    let missing = reachc(&["check", "/no/such/file.sde"]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(stderr(&missing).contains("cannot read /no/such/file.sde"));

    assert_eq!(reachc(&["frobnicate"]).status.code(), Some(2));
    assert_eq!(reachc(&["check"]).status.code(), Some(2));
}

#[test]
fn hostile_input_gives_diagnostics_not_crashes() {
    let deep = format!(
        "model m\nstate x in [0, 1]\ndrift {{ x' = {}x{} }}\n",
        "(".repeat(10_000),
        ")".repeat(10_000)
    );
    let out = reachc(&["check", temp_spec("deep.sde", &deep).to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("nested too deeply"),
        "{}",
        stderr(&out)
    );

    let minus = format!(
        "model m\nstate x in [0, 1]\ndrift {{ x' = {}x }}\n",
        "-".repeat(10_000)
    );
    let out = reachc(&["check", temp_spec("minus.sde", &minus).to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));

    let mut huge = String::from("model m\nstate x in [0, 1]\ndrift { x' = -x }\n");
    while huge.len() < 10 << 20 {
        huge.push_str("// padding padding padding padding padding padding padding padding\n");
    }
    let out = reachc(&["check", temp_spec("huge.sde", &huge).to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));

    let binary = temp_spec("binary.sde", "");
    std::fs::write(&binary, [0xff, 0xfe, 0x00, 0x41]).unwrap();
    // Not UTF-8: a spec error at the first bad byte (docs/language.md, "Limits").
    let out = reachc(&["check", binary.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("binary.sde:1:1"), "{}", stderr(&out));
}

fn inspect_json(name: &str) -> serde_json::Value {
    let out = reachc(&["inspect", "--json", &spec(name)]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    serde_json::from_slice(&out.stdout).expect("inspect --json prints JSON")
}

#[test]
fn pendulum_inspect_json_has_the_papers_vertex_matrices() {
    let j = inspect_json("pendulum.sde");
    assert_eq!(j["model"], "pendulum");
    assert_eq!(j["jacobian_x"][0][0], "0");
    assert_eq!(j["jacobian_x"][0][1], "1");
    assert_eq!(j["jacobian_x"][1][1], "-20");
    // d/dtheta (10 sin(theta) - 20 theta - 20 omega), within [-30, -10] for every theta.
    let b = &j["bounds"]["jacobian_x"][1][0];
    let (lo, hi) = (b[0].as_f64().unwrap(), b[1].as_f64().unwrap());
    assert!((-30.0 - 1e-9..=-30.0).contains(&lo), "{lo}");
    assert!((-10.0..-10.0 + 1e-9).contains(&hi), "{hi}");
    // One atom, cos(theta) in [-1, 1] with coefficient 10: the paper's conv{A1, A2}.
    let atoms = &j["atoms"]["jacobian_x"];
    assert_eq!(
        atoms["constant"],
        serde_json::json!([[0.0, 1.0], [-20.0, -20.0]])
    );
    assert_eq!(atoms["atoms"].as_array().unwrap().len(), 1);
    assert_eq!(atoms["atoms"][0]["expr"], "cos(theta)");
    assert_eq!(
        atoms["atoms"][0]["entries"],
        serde_json::json!([[1, 0, 10.0]])
    );
    let r = &atoms["atoms"][0]["range"];
    assert!(r[0].as_f64().unwrap() <= -1.0 && r[1].as_f64().unwrap() >= 1.0);
    assert_eq!(j["diffusion"], serde_json::json!([["0"], ["0.1"]]));
    assert_eq!(j["unbounded"], serde_json::json!([]));
}

/// A discrete-time model: its time and period, the map printed as next values (`x = ..`).
#[test]
fn inspect_shows_a_discrete_time_model() {
    let path = temp_spec(
        "chain.sde",
        "model chain\ndiscrete { period = 0.1 }\nstate x1 in [-1, 1]\nstate x2 = 0\n\
         input u in [-0.1, 0.1]\nnoise w1\n\
         update { x1 = x1 + 0.1 * x2  x2 = 0.9 * x2 - 0.1 * x1 + u }\n\
         diffusion { x2: 0.05 * w1 }\nanalysis a { horizon = 0.3 }\n",
    );
    let path = path.to_str().unwrap();
    let out = reachc(&["inspect", "--json", path]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["time"], serde_json::json!({"discrete": {"period": 0.1}}));
    assert_eq!(
        j["drift"],
        serde_json::json!(["x1 + 0.1*x2", "0.9*x2 - 0.1*x1 + u"])
    );
    assert_eq!(j["analyses"][0]["horizon"], 3.0 * 0.1);
    assert_eq!(j["analyses"][0]["step"], 0.1);
    let text = reachc(&["inspect", path]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains("discrete time: one step every period 0.1"),
        "{text}"
    );
    assert!(
        text.contains("update (simplified):\n  x1 = x1 + 0.1*x2\n"),
        "{text}"
    );
    assert_eq!(inspect_json("pendulum.sde")["time"], "continuous");
}

#[test]
fn unbounded_entries_are_reported() {
    // Van der Pol's Jacobian is polynomial: bounded only because the spec gives a domain.
    let vdp = inspect_json("vanderpol.sde");
    assert_eq!(vdp["domain_given"], true);
    assert_eq!(vdp["unbounded"], serde_json::json!([]));
    // The unicycle's tracking controller differentiates atan2 of the position error.
    let uni = inspect_json("unicycle.sde");
    let unbounded = uni["unbounded"].as_array().unwrap();
    assert!(
        unbounded.iter().any(|u| u["matrix"] == "jacobian_x"),
        "{unbounded:?}"
    );
    let text = reachc(&["inspect", &spec("unicycle.sde")]);
    assert!(String::from_utf8_lossy(&text.stdout).contains("help: add a `domain"));
}

#[test]
fn run_with_the_interpreter_writes_results_and_reports_failures() {
    let out = std::env::temp_dir().join(format!("reachc-run-{}", std::process::id()));
    let dir = out.to_str().unwrap();
    let ok = reachc(&["run", "--backend", "interp", &spec("linear.sde"), "-o", dir]);
    assert_eq!(ok.status.code(), Some(0), "{}", stderr(&ok));
    let summary = String::from_utf8_lossy(&ok.stdout);
    assert!(summary.contains("c = -0.400000"), "{summary}");
    for name in ["paper_rule", "amgf_rule"] {
        let json = std::fs::read_to_string(out.join(format!("{name}.json"))).unwrap();
        let v: serde_json::Value = serde_json::from_str(&json).unwrap();
        assert_eq!(v["constants"]["c"], -0.4);
        assert!(out.join(format!("{name}.csv")).is_file());
    }
    // atan2 at the origin admits no global contraction rate: a diagnostic, exit 1.
    let uni = reachc(&[
        "run",
        "--backend",
        "interp",
        &spec("../tests/good/unbounded_rate.sde"),
        "-o",
        dir,
    ]);
    assert_eq!(uni.status.code(), Some(1));
    let err = stderr(&uni);
    assert!(
        err.contains("is unbounded over the domain") && err.contains("domain {"),
        "{err}"
    );
    let bad = reachc(&[
        "run",
        "--backend",
        "interp",
        &spec("linear.sde"),
        "--analysis",
        "nope",
    ]);
    assert_eq!(bad.status.code(), Some(2));
    std::fs::remove_dir_all(&out).unwrap();
}
