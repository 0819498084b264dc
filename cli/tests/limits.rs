//! Limits through the whole command line: a spec whose IR is a small DAG but an exponentially
//! large tree goes through every command quickly with bounded output; a metric scaled near the
//! ends of the float range runs; a spec that is not UTF-8 is a located spec error.

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::{Duration, Instant};

use common::{reachc, spec};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("reachc-cli-limits-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `n` lets, each using the previous one twice: the drift is a tree of 2^n leaves.
fn doubling_lets(n: usize) -> String {
    let mut s = format!("model lets{n}\nstate x in [0, 1]\nlet a0 = x\n");
    for i in 1..=n {
        s.push_str(&format!("let a{i} = sin(a{}) + cos(a{})\n", i - 1, i - 1));
    }
    s.push_str(&format!(
        "drift {{ x' = -x + 1e-12 * a{n} }}\ndomain {{ x in [-1, 2] }}\n\
         analysis a {{ horizon = 1  step = 0.1 }}\n"
    ));
    s
}

/// Runs reachc, asserting success within `secs` seconds.
fn quick(args: &[&str], secs: u64) -> Output {
    let start = Instant::now();
    let out = reachc(args);
    assert_eq!(out.status.code(), Some(0), "{args:?}: {}", stderr(&out));
    assert!(
        start.elapsed() < Duration::from_secs(secs),
        "{args:?} took {:?}",
        start.elapsed()
    );
    out
}

/// Runs `spec` with the interpreter into `out` next to it (under 20 s); the output folder.
fn run_interp(spec: &Path) -> PathBuf {
    let out = spec.with_file_name("out");
    let args = ["run", "--backend", "interp", "-o"];
    let (out_s, spec_s) = (out.to_str().unwrap(), spec.to_str().unwrap());
    quick(&[&args[..], &[out_s, spec_s]].concat(), 20);
    out
}

#[test]
fn shared_subexpressions_stay_linear_in_every_command() {
    for n in [20, 40] {
        let dir = temp_dir(&format!("lets{n}"));
        let path = dir.join("lets.sde");
        std::fs::write(&path, doubling_lets(n)).unwrap();
        let spec = path.to_str().unwrap();

        let text = quick(&["inspect", spec], 20);
        assert!(
            text.stdout.len() < 20_000,
            "{n}: {} bytes",
            text.stdout.len()
        );
        let shown = String::from_utf8_lossy(&text.stdout);
        assert!(
            shown.contains("shared sub-expressions:\n  let _1 = "),
            "{shown}"
        );

        let json = quick(&["inspect", "--json", spec], 20);
        assert!(
            json.stdout.len() < 20_000,
            "{n}: {} bytes",
            json.stdout.len()
        );
        let j: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
        let lets = j["lets"].as_array().unwrap();
        // One let per level of the chain, as its text would repeat: `_k` uses `_(k-1)` twice.
        assert_eq!(lets[0]["name"], "_1");
        assert_eq!(
            lets[1]["expr"],
            "sin(sin(_1) + cos(_1)) + cos(sin(_1) + cos(_1))"
        );
        assert!(lets.len() >= n / 2 - 2, "{n}: {} lets", lets.len());

        let out = run_interp(&path);
        assert!(std::fs::metadata(out.join("a.json")).unwrap().len() < 100_000);

        let krate = dir.join("crate");
        quick(
            &["build", "--no-compile", "-o", krate.to_str().unwrap(), spec],
            20,
        );
        let lib = std::fs::metadata(krate.join("src/lib.rs")).unwrap().len();
        assert!(lib < 1_000_000, "{n}: lib.rs has {lib} bytes");
    }
}

#[test]
fn small_models_print_without_shared_lets() {
    let out = quick(&["inspect", "--json", &spec("pendulum.sde")], 20);
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["lets"], serde_json::json!([]));
}

/// The hull of the PRS at the horizon, from `run --backend interp`.
fn final_hull(name: &str, metric: &str) -> Vec<f64> {
    let dir = temp_dir(name);
    let path = dir.join("m.sde");
    std::fs::write(
        &path,
        format!(
            "model m\nstate x in [0, 0.1]\nstate y in [0, 0.1]\nnoise w\n\
             drift {{ x' = -x  y' = -2 * y }}\ndiffusion {{ x: 0.01 * w }}\n\
             analysis a {{ horizon = 1  step = 0.5  metric = {metric} }}\n"
        ),
    )
    .unwrap();
    let out = run_interp(&path);
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("a.json")).unwrap()).unwrap();
    let last = j["steps"].as_array().unwrap().last().unwrap().clone();
    let mut hull: Vec<f64> = serde_json::from_value(last["prs_hull_lo"].clone()).unwrap();
    hull.extend(serde_json::from_value::<Vec<f64>>(last["prs_hull_hi"].clone()).unwrap());
    hull
}

#[test]
fn metrics_scaled_near_the_float_range_run_like_the_unscaled_one() {
    // Scaled by powers of two, the normalised metrics are the same matrix bit for bit.
    let plain = final_hull("plain", "[[2, 1], [1, 3]]");
    for (name, s) in [("big", "2^996"), ("small", "2^-996")] {
        let m = format!("[[2 * {s}, {s}], [{s}, 3 * {s}]]");
        assert_eq!(final_hull(name, &m), plain, "{name}");
    }
    // Scaled by 1e300, the same sets up to the rounding of the written entries.
    let big = final_hull("e300", "[[2e300, 1e300], [1e300, 3e300]]");
    for (a, b) in big.iter().zip(&plain) {
        assert!(
            (a - b).abs() <= 1e-9 * b.abs().max(1.0),
            "{big:?} vs {plain:?}"
        );
    }
}

#[test]
fn a_spec_that_is_not_utf8_is_a_located_spec_error() {
    let path = temp_dir("utf8").join("bad.sde");
    std::fs::write(
        &path,
        b"model m\nstate x = 0 // caf\xe9\ndrift { x' = 0 }\n",
    )
    .unwrap();
    let out = reachc(&["check", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("bad.sde:2:19"), "{}", stderr(&out));
}
