//! Discrete-time models (method.md 8.16), on hand-written maps: the exact Gaussian sets of a
//! linear map against their closed form and Monte Carlo coverage, and the sets of a nonlinear
//! map against `simulate` (the map's exact recursion).

use reachc_core::chi2::chi2_quantile_upper;
use reachc_core::interval::Interval;
use reachc_core::kappa::kappa;
use reachc_core::model::{
    Analysis, AnalysisSpec, Constants, Guarantee, Method, ModelInfo, ModelParts, RadiusRule, Rate,
    Time, UnsafeSet, UnsafeShape,
};
use reachc_core::prs::{Proved, Verdict};
use reachc_core::simulate::{simulate, DtSource, Options};
use reachc_core::system::Paired;
use reachc_core::{Reach, System};
use reachc_test_support::models::model;
use reachc_test_support::systems::Linear;

fn identity(n: usize) -> Vec<f64> {
    (0..n * n)
        .map(|k| if k / n == k % n { 1.0 } else { 0.0 })
        .collect()
}

/// A discrete-time model of `states` from `boxes`, one noise channel per state, period 1, with
/// the analysis `spec` (identity metric, constants bounded at run time).
fn discrete(states: &[&str], boxes: &[(f64, f64)], affine: bool, spec: AnalysisSpec) -> ModelInfo {
    let noises: Vec<String> = (1..=states.len()).map(|i| format!("w{i}")).collect();
    let noises: Vec<&str> = noises.iter().map(|s| s.as_str()).collect();
    let base = model("map", states, &noises, boxes);
    let mut info = ModelInfo::from_parts(ModelParts {
        time: Time::Discrete { period: 1.0 },
        affine,
        ..base.into_parts()
    });
    let n = states.len();
    let inf = f64::INFINITY;
    let constants = Constants::given(&info, identity(n), inf, inf, inf);
    *info.analyses_mut() = vec![Analysis {
        spec,
        constants: Ok(constants),
    }];
    info
}

fn spec(method: Method, guarantee: Guarantee, delta: f64, horizon: f64) -> AnalysisSpec {
    AnalysisSpec {
        name: "main".into(),
        method,
        delta,
        horizon,
        step: 1.0,
        guarantee,
        rate: Rate::Local,
        first_order: false,
        ..AnalysisSpec::default()
    }
}

/// `x_(k+1) = 0.8 x_k + 0.3 w_k` in two states from 0: `Sigma_k = 0.09 (1 - 0.64^k) / 0.36 I`.
const AR: Linear = Linear {
    n: 2,
    a: 0.8,
    b: 0.0,
    s: 0.3,
};

fn sigma2(k: usize) -> f64 {
    0.09 * (1.0 - 0.64f64.powi(k as i32)) / 0.36
}

/// The linear map's sets are the exact Gaussian's: `r_k = sqrt(q Sigma_k)` with the certified
/// chi-square quantile (pointwise at delta, uniform at delta / K), within 1e-9 and never below.
#[test]
fn linear_map_is_the_exact_gaussian() {
    for (guarantee, share) in [(Guarantee::Pointwise, 1.0f64), (Guarantee::Uniform, 10.0)] {
        let info = discrete(
            &["x1", "x2"],
            &[(0.0, 0.0); 2],
            true,
            spec(Method::Contraction, guarantee, 0.1, 10.0),
        );
        let prs = Reach::paired(&AR, &info, "main").unwrap().run().unwrap();
        assert_eq!(prs.steps().len(), 11);
        let q = chi2_quantile_upper(2, (0.1 / share).next_down());
        for (k, st) in prs.steps().iter().enumerate().skip(1) {
            // (The closed form in floating point: within a few ulps of the exact value.)
            let exact = (q * sigma2(k)).sqrt();
            assert!(
                st.r_t >= exact * (1.0 - 1e-14) && st.r_t <= exact * (1.0 + 1e-9),
                "k {k}: {} against {exact}",
                st.r_t
            );
            assert!((st.t - k as f64).abs() < 1e-12);
            // The nominal stays at 0 and the deterministic ball is a point.
            assert!(st.det.radius() < 1e-12);
        }
        assert!(prs
            .validation()
            .rigorous
            .iter()
            .any(|p| matches!(p, Proved::MapFactors { steps: 10, .. })));
    }
}

/// Monte Carlo coverage of the exact set: at delta = 0.1 the fraction of 10^5 exact paths
/// outside each step's set is 0.1 within its binomial spread, and the simulation takes one
/// step of the map per step.
#[test]
fn linear_map_coverage_is_one_minus_delta() {
    let info = discrete(
        &["x1", "x2"],
        &[(0.0, 0.0); 2],
        true,
        spec(Method::Contraction, Guarantee::Pointwise, 0.1, 10.0),
    );
    let prs = Reach::paired(&AR, &info, "main").unwrap().run().unwrap();
    let opts = Options {
        paths: 100_000,
        seed: 7,
        ..Options::default()
    };
    let report = simulate(&Paired::new(&AR, &info), &prs, &opts, &mut |_, _| {}).unwrap();
    assert_eq!(report.dt.source, DtSource::Map);
    assert_eq!(report.steps_per_path, 10);
    for st in &report.steps[1..] {
        // sd of the fraction: sqrt(0.09 / 1e5) = 0.00095; 5 sd.
        assert!(
            (st.fraction - 0.1).abs() < 0.005,
            "t {}: {}",
            st.t,
            st.fraction
        );
    }
}

/// `x1' = x1 + 0.2 x2`, `x2' = x2 - 0.2 (sin x1 + x2)` (a damped pendulum sampled at 0.2),
/// noise `0.02` on each state.
struct Pendulum;

impl System for Pendulum {
    fn n(&self) -> usize {
        2
    }
    fn p(&self) -> usize {
        0
    }
    fn m(&self) -> usize {
        2
    }
    fn drift(&self, x: &[f64], _: &[f64], _: f64, out: &mut [f64]) {
        out[0] = x[0] + 0.2 * x[1];
        out[1] = x[1] - 0.2 * (x[0].sin() + x[1]);
    }
    fn drift_interval(&self, x: &[Interval], _: &[Interval], _: Interval, out: &mut [Interval]) {
        out[0] = x[0] + Interval::point(0.2) * x[1];
        out[1] = x[1] - Interval::point(0.2) * (x[0].sin() + x[1]);
    }
    fn jac_x(&self, x: &[f64], _: &[f64], _: f64, out: &mut [f64]) {
        out.copy_from_slice(&[1.0, 0.2, -0.2 * x[0].cos(), 0.8]);
    }
    fn jac_x_interval(&self, x: &[Interval], _: &[Interval], _: Interval, out: &mut [Interval]) {
        out[0] = Interval::ONE;
        out[1] = Interval::point(0.2);
        out[2] = Interval::point(-0.2) * x[0].cos();
        out[3] = Interval::point(0.8);
    }
    fn jac_u(&self, _: &[f64], _: &[f64], _: f64, _: &mut [f64]) {}
    fn jac_u_interval(&self, _: &[Interval], _: &[Interval], _: Interval, _: &mut [Interval]) {}
    fn diffusion(&self, _: &[f64], _: f64, out: &mut [f64]) {
        out.copy_from_slice(&[0.02, 0.0, 0.0, 0.02]);
    }
    fn diffusion_interval(&self, _: &[Interval], _: Interval, out: &mut [Interval]) {
        let s = Interval::point(0.02);
        out.copy_from_slice(&[s, Interval::ZERO, Interval::ZERO, s]);
    }
}

/// A nonlinear map, both methods, time-uniform: `simulate` (10^4 exact paths) finds every path
/// in every step's set, and the sets hold the noise-free images of the initial box's corners.
#[test]
fn nonlinear_map_holds_its_paths() {
    for method in [Method::Contraction, Method::Interval] {
        let mut info = discrete(
            &["x1", "x2"],
            &[(0.4, 0.6), (-0.1, 0.1)],
            false,
            spec(method, Guarantee::Uniform, 1e-2, 20.0),
        );
        *info.unsafe_sets_mut() = vec![UnsafeSet {
            name: "far".into(),
            shape: UnsafeShape::HalfSpace {
                normal: vec![1.0, 0.0],
                offset: 2.0,
            },
            moving: vec![],
        }];
        let prs = Reach::paired(&Pendulum, &info, "main")
            .unwrap()
            .run()
            .unwrap();
        assert_eq!(prs.verdict(), Verdict::Safe, "{method:?}");
        // The noise-free images of the corners lie in the deterministic sets' P-balls.
        for corner in [[0.4, -0.1], [0.4, 0.1], [0.6, -0.1], [0.6, 0.1]] {
            let mut x = corner.to_vec();
            for st in &prs.steps()[1..] {
                let mut next = [0.0; 2];
                Pendulum.drift(&x, &[], 0.0, &mut next);
                x = next.to_vec();
                let c = st.det.center();
                let d = ((x[0] - c[0]).powi(2) + (x[1] - c[1]).powi(2)).sqrt();
                assert!(
                    d <= st.det.radius() * (1.0 + 1e-12),
                    "{method:?} t {}",
                    st.t
                );
            }
        }
        let opts = Options {
            paths: 10_000,
            ..Options::default()
        };
        let report = simulate(&Paired::new(&Pendulum, &info), &prs, &opts, &mut |_, _| {}).unwrap();
        assert_eq!(report.tube.as_ref().unwrap().outside, 0, "{method:?}");
        assert!(report.steps.iter().all(|s| s.outside == 0));
    }
}

/// The stochastic radius of a nonlinear map follows `Psi_(k+1) = L_k^2 Psi_k + s_k^2`, with
/// `L_k` at least the largest `|J|_2` sampled on the step's region (the ball of the previous
/// step's set and radius) and within 5% of it, and `s_k = 0.02`.
#[test]
fn nonlinear_factors_bound_sampled_jacobians() {
    let info = discrete(
        &["x1", "x2"],
        &[(0.4, 0.6), (-0.1, 0.1)],
        false,
        spec(Method::Contraction, Guarantee::Uniform, 1e-2, 20.0),
    );
    let prs = Reach::paired(&Pendulum, &info, "main")
        .unwrap()
        .run()
        .unwrap();
    let k = kappa(2, (1e-2f64 / 20.0).next_down(), RadiusRule::Amgf);
    let norm = |x1: f64| {
        let (a, b, c, d) = (1.0, 0.2, -0.2 * x1.cos(), 0.8);
        let (p, q, s) = (a * a + c * c, a * b + c * d, b * b + d * d);
        (0.5 * (p + s) + (0.25 * (p - s) * (p - s) + q * q).sqrt()).sqrt()
    };
    let mut psi = 0.0f64;
    for w in prs.steps().windows(2) {
        let (prev, st) = (&w[0], &w[1]);
        let l = st.c;
        assert!((st.sigma - 0.02).abs() < 1e-12);
        let (c0, rad) = (prev.nominal()[0], prev.det.radius() + prev.r_t);
        let sampled = (0..=100)
            .map(|j| norm(c0 - rad + 2.0 * rad * j as f64 / 100.0))
            .fold(0.0f64, f64::max);
        assert!(
            l >= sampled && l <= 1.05 * sampled,
            "t {}: L {l}, sampled {sampled}",
            st.t
        );
        psi = l * l * psi + 0.02 * 0.02;
        let r = (psi * k).sqrt();
        assert!(
            st.r_t >= r * (1.0 - 1e-12) && st.r_t <= r * (1.0 + 1e-9),
            "t {}",
            st.t
        );
    }
}

/// `x_(k+1) = exp(x_k)` from `[0, 1]`, noise `0.01`: its factor is unbounded within a few steps.
struct Exp;

impl System for Exp {
    fn n(&self) -> usize {
        1
    }
    fn p(&self) -> usize {
        0
    }
    fn m(&self) -> usize {
        1
    }
    fn drift(&self, x: &[f64], _: &[f64], _: f64, out: &mut [f64]) {
        out[0] = x[0].exp();
    }
    fn drift_interval(&self, x: &[Interval], _: &[Interval], _: Interval, out: &mut [Interval]) {
        out[0] = x[0].exp();
    }
    fn jac_x(&self, x: &[f64], _: &[f64], _: f64, out: &mut [f64]) {
        out[0] = x[0].exp();
    }
    fn jac_x_interval(&self, x: &[Interval], _: &[Interval], _: Interval, out: &mut [Interval]) {
        out[0] = x[0].exp();
    }
    fn jac_u(&self, _: &[f64], _: &[f64], _: f64, _: &mut [f64]) {}
    fn jac_u_interval(&self, _: &[Interval], _: &[Interval], _: Interval, _: &mut [Interval]) {}
    fn diffusion(&self, _: &[f64], _: f64, out: &mut [f64]) {
        out[0] = 0.01;
    }
    fn diffusion_interval(&self, _: &[Interval], _: Interval, out: &mut [Interval]) {
        out[0] = Interval::point(0.01);
    }
}

/// A map whose factor becomes unbounded (`exp` of `exp` ...) stops with the map's own
/// diagnostic, naming the step and its region, even when its analysis asks for first-order
/// sets and its noise is additive (no continuous-time set stands in for it).
#[test]
fn a_blowing_up_map_stops_with_its_diagnostic() {
    let info = discrete(
        &["x"],
        &[(0.0, 1.0)],
        false,
        AnalysisSpec {
            first_order: true,
            ..spec(Method::Contraction, Guarantee::Uniform, 1e-2, 10.0)
        },
    );
    let info = ModelInfo::from_parts(ModelParts {
        constant_diffusion: true,
        ..info.into_parts()
    });
    let err = Reach::paired(&Exp, &info, "main")
        .unwrap()
        .run()
        .unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("the map's factor or noise level cannot be bounded on the step from t = "),
        "{text}"
    );
    assert!(text.contains("region: x in ["), "{text}");
}

/// A horizon of more map steps than a run may take (each step keeps its sets) is refused at
/// the horizon before any step is taken, not run out of memory.
#[test]
fn too_many_map_steps_are_refused_at_the_horizon() {
    let info = discrete(
        &["x1", "x2"],
        &[(0.0, 0.0); 2],
        true,
        spec(Method::Contraction, Guarantee::Pointwise, 0.1, 3e6),
    );
    let err = Reach::paired(&AR, &info, "main")
        .unwrap()
        .run()
        .unwrap_err();
    assert_eq!(
        err.culprit(),
        Some(reachc_core::engine::Culprit::Setting(
            reachc_core::engine::Setting::Horizon
        ))
    );
    assert!(
        err.to_string()
            .contains("the horizon is 3000000 steps of the map, more than the 2000000"),
        "{err}"
    );
}
