//! The default metric optimiser against the SDP optimum (cargo feature `sdp`, needs the system
//! OpenBLAS): `cargo test -p reachc-compiler --features sdp --test sdp`.
#![cfg(feature = "sdp")]

use std::path::PathBuf;

use reachc_compiler::analysis::sdp::{jacobian_vertices, optimal_metric};
use reachc_compiler::analysis::{constants, synthesize_metric, Derivatives};

fn spec(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../specs")
        .join(name)
}

/// The pendulum's optimal rate over all metrics, from core/tests/data/pendulum.json.
fn sdp_optimum_reference() -> f64 {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../core/tests/data/pendulum.json");
    let text = std::fs::read_to_string(path).unwrap();
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value["checked_independently"]["sdp_optimum_c"]
        .as_f64()
        .unwrap()
}

/// `(c default, c sdp, certified c of the SDP's P)` for one spec.
fn compare(name: &str) -> (f64, f64, f64) {
    let mut model = reachc_compiler::driver::load(&spec(name)).unwrap().model;
    let d = Derivatives::of(&mut model);
    let p = synthesize_metric(&model, &d).unwrap();
    let c_default = constants(&model, &d, &p).unwrap().c();
    let vertices = jacobian_vertices(&model, &d)
        .unwrap()
        .expect("few enough free atoms for vertices");
    let (c_sdp, p_sdp) = optimal_metric(&vertices).expect("SDP solved");
    // Never use the SDP's P unchecked: its rate is the certified one.
    let c_sdp_certified = constants(&model, &d, &p_sdp).unwrap().c();
    (c_default, c_sdp, c_sdp_certified)
}

#[test]
fn default_optimiser_is_within_2_percent_of_the_sdp_optimum() {
    let mut table =
        String::from("spec           c default        c sdp            gap %    c sdp certified\n");
    let mut failures = Vec::new();
    for name in [
        "linear.sde",
        "linear_n.sde",
        "pendulum.sde",
        "chain10.sde",
        "vanderpol.sde",
        "duffing.sde",
    ] {
        let (c_default, c_sdp, c_cert) = compare(name);
        let gap = c_default - c_sdp;
        let allowed = if c_sdp.abs() < 1e-6 {
            1e-6
        } else {
            0.02 * c_sdp.abs()
        };
        let pct = 100.0 * gap / c_sdp.abs().max(1e-300);
        table += &format!("{name:<15}{c_default:<17.10}{c_sdp:<17.10}{pct:<9.4}{c_cert:.10}\n");
        // The certified rate of the SDP's metric is a true bound: never below the optimum
        // (beyond the bisection's tolerance).
        assert!(
            c_cert >= c_sdp - 1e-6 * c_sdp.abs().max(1.0),
            "{name}: {c_cert} < {c_sdp}"
        );
        if gap > allowed {
            failures.push(format!("{name}: default {c_default} vs SDP {c_sdp}"));
        }
        if name == "pendulum.sde" {
            // The independent optimum (core/tests/data/pendulum.json): -0.513167.
            let reference = sdp_optimum_reference();
            assert!(
                (c_sdp - reference).abs() < 5e-4,
                "pendulum SDP optimum {c_sdp} vs {reference}"
            );
        }
    }
    eprintln!("{table}");
    assert!(failures.is_empty(), "{failures:?}\n{table}");
}
