//! The contraction-based delta-PRS engine on hand-written systems: closed forms, a Monte Carlo
//! check of the probability level, safety margins, and the paper's pendulum.

use reachc_core::engine::{self, RunError, Verdict};
use reachc_core::interval::Interval;
use reachc_core::kappa::kappa;
use reachc_core::system::{
    Analysis, Constants, InitialSet, Integrator, Method, ModelInfo, RadiusRule, Rate, Transform,
    UnsafeSet, UnsafeShape,
};
use reachc_core::System;

// ---------------------------------------------------------------------------------------------
// Systems
// ---------------------------------------------------------------------------------------------

/// `dX = a X dt + s dW` in `R^n` (one noise channel per state).
struct Linear {
    n: usize,
    a: f64,
    s: f64,
}

impl System for Linear {
    fn n(&self) -> usize {
        self.n
    }
    fn p(&self) -> usize {
        0
    }
    fn m(&self) -> usize {
        self.n
    }
    fn drift(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        for (o, xi) in out.iter_mut().zip(x) {
            *o = self.a * xi;
        }
    }
    fn drift_interval(&self, x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        for (o, xi) in out.iter_mut().zip(x) {
            *o = self.a * *xi;
        }
    }
    fn jac_x(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        for i in 0..self.n {
            for j in 0..self.n {
                out[i * self.n + j] = if i == j { self.a } else { 0.0 };
            }
        }
    }
    fn jac_x_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        for i in 0..self.n {
            for j in 0..self.n {
                out[i * self.n + j] = Interval::point(if i == j { self.a } else { 0.0 });
            }
        }
    }
    fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, _out: &mut [f64]) {}
    fn jac_u_interval(
        &self,
        _x: &[Interval],
        _u: &[Interval],
        _t: Interval,
        _out: &mut [Interval],
    ) {
    }
    fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
        for i in 0..self.n {
            for j in 0..self.n {
                out[i * self.n + j] = if i == j { self.s } else { 0.0 };
            }
        }
    }
    fn diffusion_interval(&self, _x: &[Interval], _t: Interval, out: &mut [Interval]) {
        for i in 0..self.n {
            for j in 0..self.n {
                out[i * self.n + j] = Interval::point(if i == j { self.s } else { 0.0 });
            }
        }
    }
}

/// `dx = (-x + u) dt + 0.1 dW`, `u` in `[-1, 1]`.
struct WithInput;

impl System for WithInput {
    fn n(&self) -> usize {
        1
    }
    fn p(&self) -> usize {
        1
    }
    fn m(&self) -> usize {
        1
    }
    fn drift(&self, x: &[f64], u: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = -x[0] + u[0];
    }
    fn drift_interval(&self, x: &[Interval], u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = u[0] - x[0];
    }
    fn jac_x(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = -1.0;
    }
    fn jac_x_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::point(-1.0);
    }
    fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = 1.0;
    }
    fn jac_u_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::ONE;
    }
    fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = 0.1;
    }
    fn diffusion_interval(&self, _x: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::point(0.1);
    }
}

/// The paper's inverted pendulum with feedback: `theta' = omega`,
/// `omega' = 10 sin(theta) - 20 theta - 20 omega`, `G = [0, 0.1]'`.
struct Pendulum;

impl System for Pendulum {
    fn n(&self) -> usize {
        2
    }
    fn p(&self) -> usize {
        0
    }
    fn m(&self) -> usize {
        1
    }
    fn drift(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = x[1];
        out[1] = 10.0 * x[0].sin() - 20.0 * x[0] - 20.0 * x[1];
    }
    fn drift_interval(&self, x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = x[1];
        out[1] = 10.0 * x[0].sin() - 20.0 * x[0] - 20.0 * x[1];
    }
    fn jac_x(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out.copy_from_slice(&[0.0, 1.0, 10.0 * x[0].cos() - 20.0, -20.0]);
    }
    fn jac_x_interval(&self, x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::ZERO;
        out[1] = Interval::ONE;
        out[2] = 10.0 * x[0].cos() - 20.0;
        out[3] = Interval::point(-20.0);
    }
    fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, _out: &mut [f64]) {}
    fn jac_u_interval(
        &self,
        _x: &[Interval],
        _u: &[Interval],
        _t: Interval,
        _out: &mut [Interval],
    ) {
    }
    fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
        out.copy_from_slice(&[0.0, 0.1]);
    }
    fn diffusion_interval(&self, _x: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::ZERO;
        out[1] = Interval::point(0.1);
    }
}

// ---------------------------------------------------------------------------------------------
// Model data
// ---------------------------------------------------------------------------------------------

fn identity(n: usize) -> Vec<f64> {
    (0..n * n)
        .map(|k| if k / n == k % n { 1.0 } else { 0.0 })
        .collect()
}

fn analysis(delta: f64, horizon: f64, step: f64, constants: Constants) -> Analysis {
    Analysis {
        name: "main".into(),
        method: Method::Contraction,
        delta,
        horizon,
        step,
        radius: RadiusRule::Amgf,
        rate: Rate::Certified,
        integrator: Integrator::Rk4,
        inclusion: Default::default(),
        outputs: vec![],
        constants: Some(constants),
        constants_error: None,
        transform: None,
    }
}

fn info(
    name: &str,
    states: &[&str],
    boxes: Vec<(f64, f64)>,
    input_box: Vec<(f64, f64)>,
) -> ModelInfo {
    let n = states.len();
    ModelInfo {
        name: name.into(),
        states: states.iter().map(|s| s.to_string()).collect(),
        inputs: (0..input_box.len()).map(|j| format!("u{j}")).collect(),
        noises: vec!["w".into()],
        input_box,
        initial: InitialSet {
            boxes: boxes.into_iter().map(Some).collect(),
            balls: vec![],
        },
        domain: vec![(f64::NEG_INFINITY, f64::INFINITY); n],
        has_domain: false,
        unsafe_sets: vec![],
        analyses: vec![],
    }
}

/// System (a): `dX = -0.4 X dt + sqrt(2) dW`, n = 2, X0 = 0.
fn linear_setup(delta: f64, horizon: f64, step: f64) -> (Linear, ModelInfo, Analysis) {
    let sys = Linear {
        n: 2,
        a: -0.4,
        s: 2f64.sqrt(),
    };
    let constants = Constants {
        metric: identity(2),
        c: -0.4,
        sigma: 2f64.sqrt(),
        rho: 0.0,
        how: "by hand".into(),
    };
    let inf = info("linear", &["x1", "x2"], vec![(0.0, 0.0); 2], vec![]);
    (sys, inf, analysis(delta, horizon, step, constants))
}

/// System (b): `x' = -x + u`, `u` in `[-1, 1]`, X0 = [0.5, 1.5].
fn input_setup() -> (WithInput, ModelInfo, Analysis) {
    let constants = Constants {
        metric: vec![1.0],
        c: -1.0,
        sigma: 0.1,
        rho: 1.0,
        how: "by hand".into(),
    };
    let inf = info("input", &["x"], vec![(0.5, 1.5)], vec![(-1.0, 1.0)]);
    (WithInput, inf, analysis(0.01, 2.0, 0.1, constants))
}

const PENDULUM_P: [f64; 4] = [35.68, 2.21, 2.21, 1.27];

/// System (e): the pendulum with the paper's constants.
fn pendulum_setup() -> (Pendulum, ModelInfo, Analysis) {
    let constants = Constants {
        metric: PENDULUM_P.to_vec(),
        c: -0.5,
        sigma: 0.1130,
        rho: 0.0,
        how: "paper, Sec. VIII-B".into(),
    };
    let pi10 = std::f64::consts::PI / 10.0;
    let inf = info(
        "pendulum",
        &["theta", "omega"],
        vec![(-pi10, pi10), (-0.2, 0.2)],
        vec![],
    );
    (Pendulum, inf, analysis(1e-3, 4.0, 0.01, constants))
}

fn step_at(res: &engine::AnalysisResult, t: f64) -> usize {
    res.steps
        .iter()
        .position(|s| (s.t - t).abs() < 1e-9)
        .unwrap_or_else(|| panic!("no report time {t}"))
}

// ---------------------------------------------------------------------------------------------
// (a) Linear system: Psi, r_t, R_t
// ---------------------------------------------------------------------------------------------

#[test]
fn linear_psi_matches_closed_form_and_r_uses_kappa() {
    let delta = 1e-3;
    let (sys, inf, an) = linear_setup(delta, 4.0, 0.01);
    let res = engine::run(&sys, &inf, &an).unwrap();
    assert_eq!(res.steps.len(), 401);
    assert_eq!(res.steps.last().unwrap().t, 4.0);
    let k = kappa(2, delta, RadiusRule::Amgf);
    assert_eq!(res.kappa, k);
    assert_eq!(res.r1, 0.0);
    let (c, s2) = (-0.4f64, 2.0f64);
    let mut worst = 0.0f64;
    for st in &res.steps[1..] {
        let closed = s2 * (2.0 * c * st.t).exp_m1() / (2.0 * c);
        let rel = (st.psi - closed) / closed;
        worst = worst.max(rel.abs());
        assert!(
            rel.abs() <= 1e-12,
            "t = {}: psi {} vs {closed}",
            st.t,
            st.psi
        );
        assert!(
            st.psi >= closed,
            "t = {}: psi {} below {closed}",
            st.t,
            st.psi
        );
        let ratio = st.r_t * st.r_t / st.psi;
        assert!(
            ((ratio - k) / k).abs() <= 1e-12,
            "r^2/psi = {ratio}, kappa = {k}"
        );
        assert!(st.r_t * st.r_t >= st.psi * k * (1.0 - 1e-15));
        assert_eq!(st.det_set.radius, 0.0);
        assert_eq!(st.nominal, vec![0.0, 0.0]);
        assert!(st.prs_radius >= st.r_t);
    }
    assert_eq!(res.steps[0].psi, 0.0);
    assert_eq!(res.steps[0].prs_radius, 0.0);
    eprintln!("max relative deviation of Psi from the closed form: {worst:e}");
    assert_eq!(res.verdict, Verdict::NoUnsafeSets);
    assert!(!res.validated.conditional_on_domain);
}

#[test]
fn paper_rules_report_eps() {
    let (sys, inf, mut an) = linear_setup(1e-3, 1.0, 0.1);
    an.radius = RadiusRule::Paper(1.0 / 16.0);
    let res = engine::run(&sys, &inf, &an).unwrap();
    assert_eq!(res.radius_rule.rule, "paper");
    assert_eq!(res.radius_rule.eps, Some(1.0 / 16.0));
    assert_eq!(res.kappa, kappa(2, 1e-3, RadiusRule::Paper(1.0 / 16.0)));
    an.radius = RadiusRule::PaperOptimal;
    let res = engine::run(&sys, &inf, &an).unwrap();
    assert_eq!(res.radius_rule.rule, "paper_optimal");
    let eps = res.radius_rule.eps.unwrap();
    assert!(eps > 0.0 && eps < 1.0);
}

// ---------------------------------------------------------------------------------------------
// (b) Input: R_t
// ---------------------------------------------------------------------------------------------

#[test]
fn input_deterministic_radius() {
    let (sys, inf, an) = input_setup();
    let res = engine::run(&sys, &inf, &an).unwrap();
    assert_eq!(res.r1, 0.5);
    assert_eq!(res.r2, 1.0);
    assert_eq!(res.constants.rho, 1.0);
    assert_eq!(res.initial_center, vec![1.0]);
    assert_eq!(res.input_center, vec![0.0]);
    for t in [1.0f64, 2.0] {
        let st = &res.steps[step_at(&res, t)];
        let expect = (-t).exp() * 0.5 + (1.0 - (-t).exp());
        assert!(st.det_set.radius >= expect);
        assert!(
            (st.det_set.radius - expect).abs() <= 1e-14,
            "R_{t} = {} vs {expect}",
            st.det_set.radius
        );
        // Nominal x* = e^-t (u = 0), RK4 at step 0.1.
        assert!((st.nominal[0] - (-t).exp()).abs() < 1e-6);
        assert!((st.prs_radius - (st.det_set.radius + st.r_t)).abs() <= 1e-15);
    }
    // R_0 = r1.
    assert_eq!(res.steps[0].det_set.radius, 0.5);
}

#[test]
fn membership() {
    let (sys, inf, an) = input_setup();
    let res = engine::run(&sys, &inf, &an).unwrap();
    let k = step_at(&res, 1.0);
    let st = &res.steps[k];
    let (c, r) = (st.nominal[0], st.prs_radius);
    assert!(engine::contains(&res, k, &[c]));
    assert!(engine::contains(&res, k, &[c + 0.999 * r]));
    assert!(engine::contains(&res, k, &[c - 0.999 * r]));
    assert!(!engine::contains(&res, k, &[c + 1.001 * r]));
    assert!(!engine::contains(&res, k, &[c - 1.001 * r]));

    // Pendulum: the P-ball boundary along an eigen-direction of P.
    let (sys, inf, an) = pendulum_setup();
    let res = engine::run(&sys, &inf, &an).unwrap();
    let k = step_at(&res, 2.0);
    let st = &res.steps[k];
    let d = [1.0, -0.5];
    let norm = (PENDULUM_P[0] * d[0] * d[0]
        + 2.0 * PENDULUM_P[1] * d[0] * d[1]
        + PENDULUM_P[3] * d[1] * d[1])
        .sqrt();
    let at = |s: f64| {
        let f = s * st.prs_radius / norm;
        [st.nominal[0] + f * d[0], st.nominal[1] + f * d[1]]
    };
    assert!(engine::contains(&res, k, &at(0.999)));
    assert!(!engine::contains(&res, k, &at(1.001)));
}

// ---------------------------------------------------------------------------------------------
// (c) Monte Carlo
// ---------------------------------------------------------------------------------------------

/// xorshift64* with Box-Muller normals (the runtime has no `rand` dependency).
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in (0, 1).
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    /// Two independent standard normals.
    fn normal2(&mut self) -> (f64, f64) {
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let th = std::f64::consts::TAU * u2;
        (r * th.cos(), r * th.sin())
    }
}

#[test]
fn monte_carlo_probability_level() {
    let delta = 0.05;
    let t_end = 1.5;
    let (sys, inf, an) = linear_setup(delta, t_end, 0.01);
    let res = engine::run(&sys, &inf, &an).unwrap();
    let k = step_at(&res, t_end);
    let r_t = res.steps[k].r_t;

    let paths = 20_000;
    let dt = 0.001;
    let nsteps = (t_end / dt).round() as usize;
    let sq = 2f64.sqrt() * dt.sqrt();
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut outside = 0usize;
    let mut norms = Vec::with_capacity(paths);
    for _ in 0..paths {
        let (mut x1, mut x2) = (0.0f64, 0.0f64);
        for _ in 0..nsteps {
            let (z1, z2) = rng.normal2();
            x1 += -0.4 * x1 * dt + sq * z1;
            x2 += -0.4 * x2 * dt + sq * z2;
        }
        if !engine::contains(&res, k, &[x1, x2]) {
            outside += 1;
        }
        norms.push((x1 * x1 + x2 * x2).sqrt());
    }
    let frac = outside as f64 / paths as f64;
    let se = (delta * (1.0 - delta) / paths as f64).sqrt();
    norms.sort_by(f64::total_cmp);
    let q95 = norms[(0.95 * paths as f64) as usize];
    eprintln!(
        "MC: r_t = {r_t:.4}, outside = {frac:.4} (bound {:.4}), empirical 95% quantile of |X| = {q95:.4}",
        delta + 3.0 * se
    );
    assert!(frac < delta + 3.0 * se, "fraction outside {frac}");
    assert!(q95 >= 0.5 * r_t, "PRS too loose: q95 = {q95}, r_t = {r_t}");
}

// ---------------------------------------------------------------------------------------------
// (d) Safety
// ---------------------------------------------------------------------------------------------

#[test]
fn half_space_safety() {
    let (sys, mut inf, an) = linear_setup(1e-3, 2.0, 0.05);
    inf.unsafe_sets = vec![
        UnsafeSet {
            name: "far".into(),
            shape: UnsafeShape::HalfSpace {
                normal: vec![3.0, 4.0],
                offset: 100.0,
            },
        },
        UnsafeSet {
            name: "crossing".into(),
            shape: UnsafeShape::HalfSpace {
                normal: vec![1.0, 1.0],
                offset: 0.0,
            },
        },
    ];
    let res = engine::run(&sys, &inf, &an).unwrap();
    // P = I: max of a.x over the ball is |a| R, margin = (100 - 5 R) / 5 = 20 - R.
    let far = &res.unsafe_sets[0];
    assert!(far.safe);
    assert_eq!(far.kind, "half_space");
    let last = res.steps.last().unwrap();
    let expect = 20.0 - last.prs_radius;
    assert!(far.min_margin <= expect && expect - far.min_margin < 1e-12);
    assert_eq!(far.min_margin_t, 2.0);
    for st in &res.steps {
        let e = 20.0 - st.prs_radius;
        assert!(st.margins[0] <= e && e - st.margins[0] < 1e-12);
    }
    let crossing = &res.unsafe_sets[1];
    assert!(!crossing.safe);
    assert_eq!(crossing.first_not_safe_t, Some(0.0));
    assert_eq!(
        res.verdict,
        Verdict::NotShownSafe {
            t: 0.0,
            step: 0,
            set: "crossing".into()
        }
    );
    assert!(res.summary().contains("not shown safe"));
}

#[test]
fn safety_against_boxes_and_balls() {
    // Input system: x* = e^-t, PRS radius R_t + r_t, P = 1.
    let (sys, mut inf, an) = input_setup();
    inf.unsafe_sets = vec![
        UnsafeSet {
            name: "box_far".into(),
            shape: UnsafeShape::Box(vec![(0, (5.0, f64::INFINITY))]),
        },
        UnsafeSet {
            name: "ball_far".into(),
            shape: UnsafeShape::Ball {
                states: vec![0],
                center: vec![-4.0],
                radius: 1.0,
            },
        },
        UnsafeSet {
            name: "box_hit".into(),
            shape: UnsafeShape::Box(vec![(0, (0.9, 1.1))]),
        },
    ];
    let res = engine::run(&sys, &inf, &an).unwrap();
    for st in &res.steps {
        let (x, r) = (st.nominal[0], st.prs_radius);
        let box_gap = 5.0 - (x + r);
        assert!(st.margins[0] <= box_gap && box_gap - st.margins[0] < 1e-12);
        let ball_gap = (x + 4.0) - r - 1.0;
        assert!(st.margins[1] <= ball_gap && ball_gap - st.margins[1] < 1e-12);
    }
    assert!(res.unsafe_sets[0].safe && res.unsafe_sets[1].safe);
    assert!(!res.unsafe_sets[2].safe);
    assert!(matches!(&res.verdict, Verdict::NotShownSafe { set, .. } if set == "box_hit"));
}

#[test]
fn pendulum_half_space_uses_inverse_metric() {
    let (sys, mut inf, an) = pendulum_setup();
    inf.unsafe_sets = vec![
        UnsafeSet {
            name: "theta_high".into(),
            shape: UnsafeShape::HalfSpace {
                normal: vec![1.0, 0.0],
                offset: 1.0,
            },
        },
        UnsafeSet {
            name: "omega_box".into(),
            shape: UnsafeShape::Box(vec![(1, (3.0, 4.0))]),
        },
        UnsafeSet {
            name: "ball".into(),
            shape: UnsafeShape::Ball {
                states: vec![0, 1],
                center: vec![0.0, 5.0],
                radius: 0.5,
            },
        },
    ];
    let res = engine::run(&sys, &inf, &an).unwrap();
    let det = PENDULUM_P[0] * PENDULUM_P[3] - PENDULUM_P[1] * PENDULUM_P[2];
    let pinv = [
        PENDULUM_P[3] / det,
        -PENDULUM_P[1] / det,
        -PENDULUM_P[2] / det,
        PENDULUM_P[0] / det,
    ];
    // lambda_max of the 2x2 inverse.
    let (tr, dt) = (pinv[0] + pinv[3], pinv[0] * pinv[3] - pinv[1] * pinv[2]);
    let lmax = tr / 2.0 + (tr * tr / 4.0 - dt).sqrt();
    for st in &res.steps {
        let (x, r) = (&st.nominal, st.prs_radius);
        let e0 = 1.0 - x[0] - r * pinv[0].sqrt();
        assert!(
            st.margins[0] <= e0 && e0 - st.margins[0] < 1e-12,
            "{} {e0}",
            st.margins[0]
        );
        let e1 = 3.0 - (x[1] + r * pinv[3].sqrt());
        assert!(st.margins[1] <= e1 && e1 - st.margins[1] < 1e-12);
        let e2 = (x[0] * x[0] + (x[1] - 5.0).powi(2)).sqrt() - r * lmax.sqrt() - 0.5;
        assert!(
            st.margins[2] <= e2 && e2 - st.margins[2] < 1e-9,
            "{} {e2}",
            st.margins[2]
        );
    }
    assert_eq!(res.verdict, Verdict::Safe);
}

// ---------------------------------------------------------------------------------------------
// (e) Pendulum with the paper's constants
// ---------------------------------------------------------------------------------------------

#[test]
fn pendulum_radii_finite_and_decreasing() {
    let (sys, inf, an) = pendulum_setup();
    let res = engine::run(&sys, &inf, &an).unwrap();
    assert_eq!(res.steps.len(), 401);
    // r1 = |(pi/10, 0.2)|_P (the vertex maximising d'Pd, both signs agree with P_12 > 0).
    let d = [std::f64::consts::PI / 10.0, 0.2];
    let r1 = (PENDULUM_P[0] * d[0] * d[0]
        + 2.0 * PENDULUM_P[1] * d[0] * d[1]
        + PENDULUM_P[3] * d[1] * d[1])
        .sqrt();
    assert!(res.r1 >= r1 && res.r1 - r1 < 1e-14);
    for st in &res.steps {
        assert!(st.prs_radius.is_finite() && st.r_t.is_finite() && st.psi.is_finite());
        assert!(st.nominal.iter().all(|v| v.is_finite()));
    }
    for w in res.steps.windows(2) {
        // R_t decreases throughout; the PRS radius once the stochastic part has built up.
        assert!(w[1].det_set.radius < w[0].det_set.radius);
        assert!(w[1].r_t >= w[0].r_t);
        if w[0].t >= 0.5 {
            assert!(w[1].prs_radius < w[0].prs_radius, "t = {}", w[1].t);
        }
    }
    let last = res.steps.last().unwrap();
    // R_4 = e^-2 r1; r_4 = sqrt(sigma^2 (1 - e^-4) kappa).
    assert!((last.det_set.radius - (-2.0f64).exp() * r1).abs() < 1e-12);
    let psi4 = 0.1130f64.powi(2) * (-(-4.0f64).exp_m1());
    assert!((last.psi - psi4).abs() < 1e-12 * psi4);
    eprintln!(
        "pendulum t = 4: R = {:.6}, r = {:.6}, PRS radius = {:.6}, kappa = {:.6}",
        last.det_set.radius, last.r_t, last.prs_radius, res.kappa
    );
    // The outputs render.
    let json = res.to_json();
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["model"], "pendulum");
    assert_eq!(v["steps"].as_array().unwrap().len(), 401);
    let mut csv = Vec::new();
    res.write_csv(&mut csv).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    assert_eq!(
        csv.lines().next().unwrap(),
        "t,theta,omega,det_radius,r_t,psi,c,sigma,prs_radius"
    );
    assert_eq!(csv.lines().count(), 402);
    let summary = res.summary();
    assert!(summary.contains("kappa") && summary.contains("amgf"));
    eprintln!("{summary}");
}

// ---------------------------------------------------------------------------------------------
// Errors and options
// ---------------------------------------------------------------------------------------------

#[test]
fn errors() {
    let (sys, inf, mut an) = linear_setup(1e-3, 1.0, 0.1);
    // A coordinate transform needs the system's transformed frame, which this one lacks.
    an.method = Method::Interval;
    an.transform = Some(Transform {
        matrix: identity(sys.n),
        inverse: identity(sys.n),
        frame: 0,
    });
    assert!(matches!(
        engine::run(&sys, &inf, &an),
        Err(RunError::Unsupported(_))
    ));
    an.transform = None;
    an.method = Method::Contraction;
    let constants = an.constants.take();
    an.constants_error = Some("d f[x1]/d x1 is unbounded".into());
    match engine::run(&sys, &inf, &an) {
        Err(RunError::NoConstants(m)) => assert!(m.contains("unbounded"), "{m}"),
        other => panic!("expected NoConstants, got {other:?}"),
    }
    an.constants = constants;
    an.delta = 1.5;
    assert!(matches!(
        engine::run(&sys, &inf, &an),
        Err(RunError::Invalid(_))
    ));
    an.delta = 1e-3;
    let mut bad = an.clone();
    bad.constants.as_mut().unwrap().metric = vec![1.0, 2.0, 2.0, 1.0];
    assert!(matches!(
        engine::run(&sys, &inf, &bad),
        Err(RunError::Invalid(_))
    ));
}

#[test]
fn euler_uneven_horizon_domain_and_ball() {
    let (sys, mut inf, mut an) = linear_setup(1e-2, 1.05, 0.1);
    an.integrator = Integrator::Euler;
    inf.has_domain = true;
    // Ball of radius 0.5 over both states with metric diag(4, 1): bounding box (0.25, 0.5).
    inf.initial = InitialSet {
        boxes: vec![None, None],
        balls: vec![reachc_core::system::InitialBall {
            states: vec![0, 1],
            center: vec![1.0, -1.0],
            radius: 0.5,
            metric: Some(vec![4.0, 0.0, 0.0, 1.0]),
        }],
    };
    let res = engine::run(&sys, &inf, &an).unwrap();
    assert_eq!(res.steps.len(), 12);
    assert_eq!(res.steps.last().unwrap().t, 1.05);
    assert_eq!(res.initial_center, vec![1.0, -1.0]);
    // P = I: r1 = |(0.25, 0.5)| (bounding box corner), conservative vs the true 0.5.
    let r1 = (0.25f64 * 0.25 + 0.25).sqrt();
    assert!(res.r1 >= r1 && res.r1 - r1 < 1e-14);
    // Euler: x*_{k+1} = (1 - 0.04) x*_k on full steps.
    assert!((res.steps[1].nominal[0] - 0.96).abs() < 1e-15);
    assert!(res.validated.conditional_on_domain);
    assert!(res
        .validated
        .not_validated
        .iter()
        .any(|s| s.contains("domain")));
}

// ---------------------------------------------------------------------------------------------
// Empirical rates
// ---------------------------------------------------------------------------------------------

/// On a linear drift `a x` every sampled quotient `(X - x*)' (f(X) - f(x*)) / |X - x*|^2` is
/// exactly `a`, so the empirical rate is the certified one and so are the radii; the result
/// says that it is an estimate.
#[test]
fn empirical_rate_of_a_linear_drift_is_its_rate() {
    for (sys, inf, certified) in [
        {
            let (s, i, a) = linear_setup(1e-3, 2.0, 0.05);
            (Box::new(s) as Box<dyn System>, i, a)
        },
        {
            let (s, i, a) = input_setup();
            (Box::new(s) as Box<dyn System>, i, a)
        },
    ] {
        let exact = certified.constants.as_ref().unwrap().c;
        let mut empirical = certified.clone();
        empirical.rate = Rate::Empirical { paths: 50 };
        // The compiler leaves c unbounded for an empirical analysis.
        empirical.constants.as_mut().unwrap().c = f64::INFINITY;
        let want = engine::run(sys.as_ref(), &inf, &certified).unwrap();
        let got = engine::run(sys.as_ref(), &inf, &empirical).unwrap();
        assert_eq!(got.rate.kind, "empirical");
        assert_eq!(got.rate.paths, Some(50));
        assert!(got.rate.note.contains("not a guarantee"));
        assert!(got.validated.not_validated[0].starts_with("EMPIRICAL"));
        assert!(got.summary().contains("rate: EMPIRICAL"));
        assert!((got.rate.max_c - exact).abs() < 1e-12, "{}", got.rate.max_c);
        for (a, b) in want.steps.iter().zip(&got.steps) {
            assert!((b.c - exact).abs() < 1e-12, "t = {}: c = {}", b.t, b.c);
            let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * x.abs().max(1e-12);
            assert!(close(a.r_t, b.r_t), "t = {}: {} vs {}", a.t, a.r_t, b.r_t);
            assert!(close(a.det_set.radius, b.det_set.radius), "t = {}", a.t);
        }
    }
}

/// An empirical analysis does not need a certified c, and the interval method refuses it.
#[test]
fn empirical_rate_needs_no_certified_c_and_not_the_interval_method() {
    let (sys, inf, mut an) = linear_setup(1e-3, 1.0, 0.1);
    an.constants.as_mut().unwrap().c = f64::NAN;
    assert!(matches!(
        engine::run(&sys, &inf, &an),
        Err(RunError::NoConstants(_))
    ));
    an.rate = Rate::Empirical { paths: 20 };
    assert!(engine::run(&sys, &inf, &an).is_ok());
    an.method = Method::Interval;
    assert!(matches!(
        engine::run(&sys, &inf, &an),
        Err(RunError::Unsupported(_))
    ));
}
