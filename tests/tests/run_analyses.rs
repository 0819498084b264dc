//! Contraction-based delta-PRS end to end through the interpreter backend: constants, Psi and
//! radii against closed forms and the 30-digit reference, and coverage against Monte Carlo.

use reachc_compiler::backend::{interp::Interpreter, prepare};
use reachc_compiler::driver::load;
use reachc_e2e::workspace;
use reachc_runtime::{ModelInfo, Prs, Reach, System};
use reachc_test_support::flow::euler_maruyama;
use reachc_test_support::rng::Rng;

/// Runs analysis `name` of the shipped spec `spec` with the interpreter.
fn run(spec: &str, name: &str) -> (Prs, Interpreter, ModelInfo) {
    let mut model = load(&workspace().join("specs").join(spec)).unwrap().model;
    let prepared = prepare(&mut model);
    assert!(prepared.warnings.is_empty(), "{:#?}", prepared.warnings);
    let interp = Interpreter::new(model, &prepared);
    let result = Reach::paired(&interp, &prepared.info, name)
        .unwrap()
        .run()
        .unwrap();
    (result, interp, prepared.info)
}

/// `kappa` for (n, delta) and a field of the 30-digit reference (core/tests/data/README.md).
fn reference_kappa(n: usize, delta: f64, field: &str) -> f64 {
    let path = workspace().join("core/tests/data/kappa.jsonl");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .find(|v| v["n"] == n && v["delta"].as_f64() == Some(delta))
        .and_then(|v| v[field].as_f64())
        .unwrap_or_else(|| panic!("no reference row for n = {n}, delta = {delta}"))
}

#[test]
fn linear_constants_psi_and_radius_match_closed_forms_and_reference() {
    for (analysis, field) in [
        ("paper_rule", "kappa_paper_eps_1_16"),
        ("amgf_rule", "kappa_amgf"),
    ] {
        let (r, _, _) = run("linear.sde", analysis);
        // dX = -0.4 X dt + sqrt(2) dW: c = mu(-0.4 I) exactly, sigma = sqrt(2).
        assert_eq!(r.constants().c, -0.4, "{analysis}");
        let s2 = std::f64::consts::SQRT_2;
        assert!(r.constants().sigma >= s2 && r.constants().sigma <= s2 * (1.0 + 1e-15));
        let reference = reference_kappa(2, r.delta(), field);
        assert!(
            (r.kappa() - reference).abs() <= 1e-9 * reference,
            "{} vs {reference}",
            r.kappa()
        );
        assert!(r.kappa() >= reference * (1.0 - 1e-12));
        for s in r.steps().iter().skip(1) {
            // Psi_t = sigma^2 (e^{2ct} - 1) / (2c) with sigma^2 = 2, c = -0.4.
            let closed = 2.0 * (-0.8 * s.t).exp_m1() / -0.8;
            assert!(
                s.psi >= closed && s.psi <= closed * (1.0 + 1e-12),
                "t = {}: {} vs {closed}",
                s.t,
                s.psi
            );
            // amgf on an affine model: the exact Gaussian radius, whose chi-square quantile is
            // -2 ln(delta) for n = 2 (method.md section 8.1); the paper rule keeps its kappa.
            let factor = match analysis {
                "amgf_rule" => -2.0 * r.delta().ln(),
                _ => reference,
            };
            let r_t = (closed * factor).sqrt();
            assert!(
                s.r_t >= r_t * (1.0 - 1e-12) && s.r_t <= r_t * (1.0 + 1e-9),
                "t = {}",
                s.t
            );
            // X0 = 0 exactly and no inputs: the deterministic set is the nominal point.
            assert_eq!(s.det.radius(), 0.0);
        }
        assert!((r.steps().last().unwrap().t - 1.5).abs() < 1e-12);
    }
}

/// Euler-Maruyama paths of the pendulum from random initial states in X0 stay inside the
/// contraction-based PRS (delta = 1e-3) at t = 1, 2 and 4, and the PRS is not vacuous.
#[test]
fn pendulum_prs_covers_monte_carlo_paths() {
    let (r, sys, info) = run("pendulum.sde", "contraction");
    let n = sys.n();
    let dt: f64 = 0.002;
    let checkpoints = [1.0, 2.0, 4.0];
    let step_of = |t: f64| {
        r.steps()
            .iter()
            .position(|s| (s.t - t).abs() < 1e-9)
            .unwrap()
    };
    let mut rng = Rng(42);
    let paths = 1000;
    let mut outside = [0usize; 3];
    let mut max_ratio = [0.0f64; 3];
    for _ in 0..paths {
        let mut x: Vec<f64> = info
            .initial()
            .boxes
            .iter()
            .map(|b| {
                let b = b.unwrap();
                rng.range(b.lo, b.hi)
            })
            .collect();
        let mut t = 0.0;
        for (k, &tc) in checkpoints.iter().enumerate() {
            euler_maruyama(&sys, &mut x, &mut t, tc, dt, &mut rng);
            let s = &r.steps()[step_of(tc)];
            let d: Vec<f64> = x.iter().zip(s.nominal()).map(|(a, b)| a - b).collect();
            let p = &r.constants().metric;
            let norm = (0..n)
                .map(|i| (0..n).map(|j| d[i] * p[i * n + j] * d[j]).sum::<f64>())
                .sum::<f64>()
                .sqrt();
            if norm > s.prs_radius {
                outside[k] += 1;
            }
            max_ratio[k] = max_ratio[k].max(norm / s.prs_radius);
        }
    }
    for k in 0..3 {
        // delta = 1e-3: about 1 of 1000 may fall outside; 4 is beyond 3 standard errors.
        assert!(
            outside[k] <= 4,
            "t = {}: {} of {paths} outside",
            checkpoints[k],
            outside[k]
        );
        assert!(
            max_ratio[k] > 0.2,
            "t = {}: PRS is vacuous (max ratio {})",
            checkpoints[k],
            max_ratio[k]
        );
    }
}

#[test]
fn pendulum_auto_metric_meets_the_papers_constants() {
    let (r, _, _) = run("pendulum.sde", "contraction");
    // Paper: c = -0.5, sigma = 0.1130 with P = [[35.68, 2.21], [2.21, 1.27]]; optimum c ~ -0.513.
    assert!(r.constants().c <= -0.50, "c = {}", r.constants().c);
    assert!(
        r.constants().c >= -0.5133,
        "c = {} is below the SDP optimum",
        r.constants().c
    );
    assert!(
        r.constants().sigma <= 0.114,
        "sigma = {}",
        r.constants().sigma
    );
}
