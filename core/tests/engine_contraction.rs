//! The contraction-based delta-PRS engine on hand-written systems: closed forms, a Monte Carlo
//! check of the probability level, safety margins, and the paper's pendulum.

use reachc_core::engine::{self, Culprit, RunError, Setting};
use reachc_core::kappa::kappa;
use reachc_core::model::{
    Analysis, AnalysisSpec, Bounds, Constants, Guarantee, InitialSet, Integrator, Method,
    ModelInfo, ModelParts, RadiusRule, Rate, Transform, TransformSource, UnsafeSet, UnsafeShape,
};
use reachc_core::prs::{BallBound, DetSet, Prs, Span, Unproved, UnsafeKind, Verdict};
use reachc_core::system::Paired;
use reachc_core::{InputPlan, Reach, System};

use reachc_test_support::models::{model, pendulum_constants, pendulum_model, PENDULUM_METRIC};
use reachc_test_support::rng::Rng;
use reachc_test_support::systems::{Linear, Pendulum};

// ---------------------------------------------------------------------------------------------
// Model data
// ---------------------------------------------------------------------------------------------

fn identity(n: usize) -> Vec<f64> {
    (0..n * n)
        .map(|k| if k / n == k % n { 1.0 } else { 0.0 })
        .collect()
}

/// An analysis with the paper's semantics, whose closed forms these tests check: the radius
/// for each time separately, one RK4 step per report step (`validated.rs` tests the defaults:
/// validated steps and the time-uniform tube).
fn analysis(delta: f64, horizon: f64, step: f64, constants: Constants) -> Analysis {
    Analysis {
        spec: AnalysisSpec {
            name: "main".into(),
            delta,
            horizon,
            step,
            guarantee: Guarantee::Pointwise,
            integrator: Integrator::Rk4,
            rate: Rate::Global,
            ..AnalysisSpec::default()
        },
        constants: Ok(constants),
    }
}

/// The model `name` of `states` from the box `boxes`, one noise channel `w`, and an input
/// `u<j>` per range of `input_box`.
fn info(
    name: &str,
    states: &[&str],
    boxes: Vec<(f64, f64)>,
    input_box: Vec<(f64, f64)>,
) -> ModelInfo {
    ModelInfo::from_parts(ModelParts {
        inputs: (0..input_box.len()).map(|j| format!("u{j}")).collect(),
        input_box: input_box
            .into_iter()
            .map(|(a, b)| Bounds::new(a, b))
            .collect(),
        ..model(name, states, &["w"], &boxes).into_parts()
    })
}

/// System (a): `dX = -0.4 X dt + sqrt(2) dW`, n = 2, X0 = 0.
fn linear_setup(delta: f64, horizon: f64, step: f64) -> (Linear, ModelInfo, Analysis) {
    let sys = Linear {
        n: 2,
        a: -0.4,
        b: 0.0,
        s: 2f64.sqrt(),
    };
    let inf = info("linear", &["x1", "x2"], vec![(0.0, 0.0); 2], vec![]);
    let constants = Constants::given(&inf, identity(2), -0.4, 2f64.sqrt(), 0.0);
    (sys, inf, analysis(delta, horizon, step, constants))
}

/// System (b): `x' = -x + u`, `u` in `[-1, 1]`, X0 = [0.5, 1.5].
fn input_setup() -> (Linear, ModelInfo, Analysis) {
    let inf = info("input", &["x"], vec![(0.5, 1.5)], vec![(-1.0, 1.0)]);
    let constants = Constants::given(&inf, vec![1.0], -1.0, 0.1, 1.0);
    (Linear::WITH_INPUT, inf, analysis(0.01, 2.0, 0.1, constants))
}

/// System (e): the pendulum with the paper's constants.
fn pendulum_setup() -> (Pendulum, ModelInfo, Analysis) {
    let inf = pendulum_model();
    let constants = pendulum_constants(&inf);
    (Pendulum::PAPER, inf, analysis(1e-3, 4.0, 0.01, constants))
}

/// A result and the results it is intersected with.
fn members(res: &Prs) -> impl Iterator<Item = &Prs> {
    std::iter::once(res).chain(res.also())
}

fn step_at(res: &Prs, t: f64) -> usize {
    res.steps()
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
    let res = engine::run_paired(&sys, &inf, &an).unwrap();
    assert_eq!(res.steps().len(), 401);
    assert_eq!(res.steps().last().unwrap().t, 4.0);
    let k = kappa(2, delta, RadiusRule::Amgf);
    assert_eq!(res.kappa(), k);
    assert_eq!(res.r1(), 0.0);
    let (c, s2) = (-0.4f64, 2.0f64);
    let mut worst = 0.0f64;
    for st in &res.steps()[1..] {
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
        assert_eq!(st.det.radius(), 0.0);
        assert_eq!(st.nominal(), [0.0, 0.0]);
        assert!(st.prs_radius >= st.r_t);
    }
    assert_eq!(res.steps()[0].psi, 0.0);
    assert_eq!(res.steps()[0].prs_radius, 0.0);
    eprintln!("max relative deviation of Psi from the closed form: {worst:e}");
    assert_eq!(res.verdict(), Verdict::NoUnsafeSets);
    assert!(!res.validation().conditional_on_domain);
}

#[test]
fn paper_rules_report_eps() {
    let (sys, inf, mut an) = linear_setup(1e-3, 1.0, 0.1);
    an.spec.radius = RadiusRule::Paper(1.0 / 16.0);
    let res = engine::run_paired(&sys, &inf, &an).unwrap();
    assert_eq!(res.radius_rule().rule, RadiusRule::Paper(1.0 / 16.0));
    assert_eq!(res.radius_rule().eps, Some(1.0 / 16.0));
    assert_eq!(res.kappa(), kappa(2, 1e-3, RadiusRule::Paper(1.0 / 16.0)));
    an.spec.radius = RadiusRule::PaperOptimal;
    let res = engine::run_paired(&sys, &inf, &an).unwrap();
    assert_eq!(res.radius_rule().rule, RadiusRule::PaperOptimal);
    let eps = res.radius_rule().eps.unwrap();
    assert!(eps > 0.0 && eps < 1.0);
}

// ---------------------------------------------------------------------------------------------
// (b) Input: R_t
// ---------------------------------------------------------------------------------------------

#[test]
fn input_deterministic_radius() {
    let (sys, inf, an) = input_setup();
    let res = engine::run_paired(&sys, &inf, &an).unwrap();
    assert_eq!(res.r1(), 0.5);
    assert_eq!(res.r2(), 1.0);
    assert_eq!(res.constants().rho, 1.0);
    assert_eq!(res.initial_center(), vec![1.0]);
    assert_eq!(res.input_center(), vec![0.0]);
    for t in [1.0f64, 2.0] {
        let st = &res.steps()[step_at(&res, t)];
        let expect = (-t).exp() * 0.5 + (1.0 - (-t).exp());
        assert!(st.det.radius() >= expect);
        assert!(
            (st.det.radius() - expect).abs() <= 1e-14,
            "R_{t} = {} vs {expect}",
            st.det.radius()
        );
        // Nominal x* = e^-t (u = 0), RK4 at step 0.1.
        assert!((st.nominal()[0] - (-t).exp()).abs() < 1e-6);
        assert!((st.prs_radius - (st.det.radius() + st.r_t)).abs() <= 1e-15);
    }
    // R_0 = r1.
    assert_eq!(res.steps()[0].det.radius(), 0.5);
}

#[test]
fn membership() {
    let (sys, inf, an) = input_setup();
    let res = engine::run_paired(&sys, &inf, &an).unwrap();
    let k = step_at(&res, 1.0);
    let st = &res.steps()[k];
    let (c, r) = (st.nominal()[0], st.prs_radius);
    assert!(res.contains_at(k, &[c]));
    assert!(res.contains_at(k, &[c + 0.999 * r]));
    assert!(res.contains_at(k, &[c - 0.999 * r]));
    assert!(!res.contains_at(k, &[c + 1.001 * r]));
    assert!(!res.contains_at(k, &[c - 1.001 * r]));

    // Pendulum: the P-ball boundary along an eigen-direction of P.
    let (sys, inf, an) = pendulum_setup();
    let res = engine::run_paired(&sys, &inf, &an).unwrap();
    let k = step_at(&res, 2.0);
    let st = &res.steps()[k];
    let d = [1.0, -0.5];
    let norm = (PENDULUM_METRIC[0] * d[0] * d[0]
        + 2.0 * PENDULUM_METRIC[1] * d[0] * d[1]
        + PENDULUM_METRIC[3] * d[1] * d[1])
        .sqrt();
    let at = |s: f64| {
        let f = s * st.prs_radius / norm;
        [st.nominal()[0] + f * d[0], st.nominal()[1] + f * d[1]]
    };
    assert!(res.contains_at(k, &at(0.999)));
    assert!(!res.contains_at(k, &at(1.001)));
}

// ---------------------------------------------------------------------------------------------
// (c) Monte Carlo
// ---------------------------------------------------------------------------------------------

#[test]
fn monte_carlo_probability_level() {
    let delta = 0.05;
    let t_end = 1.5;
    let (sys, inf, an) = linear_setup(delta, t_end, 0.01);
    let res = engine::run_paired(&sys, &inf, &an).unwrap();
    let k = step_at(&res, t_end);
    let r_t = res.steps()[k].r_t;

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
            let (z1, z2) = rng.normal_pair();
            x1 += -0.4 * x1 * dt + sq * z1;
            x2 += -0.4 * x2 * dt + sq * z2;
        }
        if !res.contains_at(k, &[x1, x2]) {
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
    *inf.unsafe_sets_mut() = vec![
        UnsafeSet {
            name: "far".into(),
            shape: UnsafeShape::HalfSpace {
                normal: vec![3.0, 4.0],
                offset: 100.0,
            },
            moving: Vec::new(),
        },
        UnsafeSet {
            name: "crossing".into(),
            shape: UnsafeShape::HalfSpace {
                normal: vec![1.0, 1.0],
                offset: 0.0,
            },
            moving: Vec::new(),
        },
    ];
    let res = engine::run_paired(&sys, &inf, &an).unwrap();
    // P = I: max of a.x over the ball is |a| R, margin = (100 - 5 R) / 5 = 20 - R.
    let far = &res.unsafe_sets()[0];
    assert!(far.safe);
    assert_eq!(far.kind, UnsafeKind::HalfSpace);
    let last = res.steps().last().unwrap();
    let expect = 20.0 - last.prs_radius;
    assert!(far.min_margin <= expect && expect - far.min_margin < 1e-12);
    assert_eq!(far.min_margin_t, 2.0);
    for st in res.steps() {
        let e = 20.0 - st.prs_radius;
        assert!(st.margins[0] <= e && e - st.margins[0] < 1e-12);
    }
    let crossing = &res.unsafe_sets()[1];
    assert!(!crossing.safe);
    assert_eq!(crossing.first_not_safe_t, Some(0.0));
    assert_eq!(
        res.verdict(),
        Verdict::NotShownSafe {
            t: 0.0,
            step: 0,
            set: 1
        }
    );
}

#[test]
fn safety_against_boxes_and_balls() {
    // Input system: x* = e^-t, PRS radius R_t + r_t, P = 1.
    let (sys, mut inf, an) = input_setup();
    *inf.unsafe_sets_mut() = vec![
        UnsafeSet {
            name: "box_far".into(),
            shape: UnsafeShape::Box(vec![(0, Bounds::new(5.0, f64::INFINITY))]),
            moving: Vec::new(),
        },
        UnsafeSet {
            name: "ball_far".into(),
            shape: UnsafeShape::Ball {
                states: vec![0],
                center: vec![-4.0],
                radius: 1.0,
            },
            moving: Vec::new(),
        },
        UnsafeSet {
            name: "box_hit".into(),
            shape: UnsafeShape::Box(vec![(0, Bounds::new(0.9, 1.1))]),
            moving: Vec::new(),
        },
    ];
    let res = engine::run_paired(&sys, &inf, &an).unwrap();
    for (k, st) in res.steps().iter().enumerate() {
        // The margins are over the report interval ending at t: its span holds the PRS at
        // both ends, [x - r, x + r] now and at the previous report time.
        let span = &st.span;
        for prev in &res.steps()[k.saturating_sub(1)..=k] {
            let (x, r) = (prev.nominal()[0], prev.prs_radius);
            assert!(span.lo[0] - span.radius <= x - r && x + r <= span.hi[0] + span.radius);
        }
        // The intersection with the interval box (method.md 8.7): the larger margin.
        let gaps = members(&res).map(|m| {
            let span = &m.steps()[k].span;
            let (lo, hi) = (span.lo[0] - span.radius, span.hi[0] + span.radius);
            (5.0 - hi, (lo + 4.0) - 1.0)
        });
        let (box_gap, ball_gap) = gaps.fold((f64::NEG_INFINITY, f64::NEG_INFINITY), |a, b| {
            (a.0.max(b.0), a.1.max(b.1))
        });
        assert!(st.margins[0] <= box_gap && box_gap - st.margins[0] < 1e-12);
        assert!(st.margins[1] <= ball_gap && ball_gap - st.margins[1] < 1e-12);
    }
    assert!(res.unsafe_sets()[0].safe && res.unsafe_sets()[1].safe);
    assert!(!res.unsafe_sets()[2].safe);
    assert!(matches!(
        res.verdict(),
        Verdict::NotShownSafe { set: 2, .. }
    ));
}

#[test]
fn pendulum_half_space_uses_inverse_metric() {
    let (sys, mut inf, an) = pendulum_setup();
    *inf.unsafe_sets_mut() = vec![
        UnsafeSet {
            name: "theta_high".into(),
            shape: UnsafeShape::HalfSpace {
                normal: vec![1.0, 0.0],
                offset: 1.0,
            },
            moving: Vec::new(),
        },
        UnsafeSet {
            name: "omega_box".into(),
            shape: UnsafeShape::Box(vec![(1, Bounds::new(3.0, 4.0))]),
            moving: Vec::new(),
        },
        UnsafeSet {
            name: "ball".into(),
            shape: UnsafeShape::Ball {
                states: vec![0, 1],
                center: vec![0.0, 5.0],
                radius: 0.5,
            },
            moving: Vec::new(),
        },
    ];
    let res = engine::run_paired(&sys, &inf, &an).unwrap();
    let det = PENDULUM_METRIC[0] * PENDULUM_METRIC[3] - PENDULUM_METRIC[1] * PENDULUM_METRIC[2];
    let pinv = [
        PENDULUM_METRIC[3] / det,
        -PENDULUM_METRIC[1] / det,
        -PENDULUM_METRIC[2] / det,
        PENDULUM_METRIC[0] / det,
    ];
    // lambda_max of the 2x2 inverse.
    let (tr, dt) = (pinv[0] + pinv[3], pinv[0] * pinv[3] - pinv[1] * pinv[2]);
    let lmax = tr / 2.0 + (tr * tr / 4.0 - dt).sqrt();
    // Margins over the report interval: of its span, the box [lo, hi] plus the P-ball of
    // radius r (the PRS at t lies in it: checked below against its boundary).
    let want = |span: &Span| {
        let (lo, hi, r) = (&span.lo, &span.hi, span.radius);
        // A ball: the larger of two lower bounds of the gap, through the ellipse's spread
        // and through its bounding box.
        let gap = |c: f64, a: f64, b: f64| (a - c).max(c - b).max(0.0);
        let dist = |w0: f64, w1: f64| {
            (gap(0.0, lo[0] - w0, hi[0] + w0).powi(2) + gap(5.0, lo[1] - w1, hi[1] + w1).powi(2))
                .sqrt()
        };
        let by_spread = dist(0.0, 0.0) - r * lmax.sqrt() - 0.5;
        let by_box = dist(r * pinv[0].sqrt(), r * pinv[3].sqrt()) - 0.5;
        [
            1.0 - hi[0] - r * pinv[0].sqrt(),
            3.0 - (hi[1] + r * pinv[3].sqrt()),
            by_spread.max(by_box),
        ]
    };
    for (k, st) in res.steps().iter().enumerate() {
        // At t = 0 the set is the initial box itself (span radius 0), later a P-ball.
        if matches!(st.det, DetSet::Ball { .. }) {
            assert!(st.span.radius >= st.prs_radius);
        }
        // The intersection with the interval box (method.md 8.7): the larger margin.
        let wants = members(&res).map(|m| want(&m.steps()[k].span));
        let e = wants.fold([f64::NEG_INFINITY; 3], |a, b| {
            [0, 1, 2].map(|j| a[j].max(b[j]))
        });
        for (j, tol) in [(0, 1e-12), (1, 1e-12), (2, 1e-9)] {
            assert!(
                st.margins[j] <= e[j] && e[j] - st.margins[j] < tol,
                "{j}: {} {}",
                st.margins[j],
                e[j]
            );
        }
        if !matches!(st.det, DetSet::Ball { .. }) {
            continue;
        }
        let (x, r) = (&st.nominal(), st.prs_radius);
        // Sound: no point of the PRS (its boundary, sampled) is closer to the unsafe ball.
        let closest = (0..720)
            .map(|k| {
                // |d|_P = r on the ellipse: d = r L^-T (cos, sin) with P = L L'.
                let a = f64::from(k) * std::f64::consts::PI / 360.0;
                let l11 = PENDULUM_METRIC[0].sqrt();
                let l21 = PENDULUM_METRIC[2] / l11;
                let l22 = (PENDULUM_METRIC[3] - l21 * l21).sqrt();
                let (u, v) = (a.cos(), a.sin());
                let d1 = v / l22;
                let d0 = (u - l21 * d1) / l11;
                ((x[0] + r * d0).powi(2) + (x[1] + r * d1 - 5.0).powi(2)).sqrt() - 0.5
            })
            .fold(f64::INFINITY, f64::min);
        assert!(st.margins[2] <= closest, "{} > {closest}", st.margins[2]);
    }
    assert_eq!(res.verdict(), Verdict::Safe);
}

// ---------------------------------------------------------------------------------------------
// (e) Pendulum with the paper's constants
// ---------------------------------------------------------------------------------------------

#[test]
fn pendulum_radii_finite_and_decreasing() {
    let (sys, inf, an) = pendulum_setup();
    let res = engine::run_paired(&sys, &inf, &an).unwrap();
    assert_eq!(res.steps().len(), 401);
    // r1 = |(pi/10, 0.2)|_P (the vertex maximising d'Pd, both signs agree with P_12 > 0).
    let d = [std::f64::consts::PI / 10.0, 0.2];
    let r1 = (PENDULUM_METRIC[0] * d[0] * d[0]
        + 2.0 * PENDULUM_METRIC[1] * d[0] * d[1]
        + PENDULUM_METRIC[3] * d[1] * d[1])
        .sqrt();
    assert!(res.r1() >= r1 && res.r1() - r1 < 1e-14);
    for st in res.steps() {
        assert!(st.prs_radius.is_finite() && st.r_t.is_finite() && st.psi.is_finite());
        assert!(st.nominal().iter().all(|v| v.is_finite()));
    }
    for w in res.steps().windows(2) {
        // R_t decreases throughout; the PRS radius once the stochastic part has built up.
        assert!(w[1].det.radius() < w[0].det.radius());
        assert!(w[1].r_t >= w[0].r_t);
        if w[0].t >= 0.5 {
            assert!(w[1].prs_radius < w[0].prs_radius, "t = {}", w[1].t);
        }
    }
    let last = res.steps().last().unwrap();
    // R_4 = e^-2 r1; r_4 = sqrt(sigma^2 (1 - e^-4) kappa).
    assert!((last.det.radius() - (-2.0f64).exp() * r1).abs() < 1e-12);
    let psi4 = 0.1130f64.powi(2) * (-(-4.0f64).exp_m1());
    assert!((last.psi - psi4).abs() < 1e-12 * psi4);
    eprintln!(
        "pendulum t = 4: R = {:.6}, r = {:.6}, PRS radius = {:.6}, kappa = {:.6}",
        last.det.radius(),
        last.r_t,
        last.prs_radius,
        res.kappa()
    );
}

// ---------------------------------------------------------------------------------------------
// Errors and options
// ---------------------------------------------------------------------------------------------

#[test]
fn errors() {
    let (sys, inf, mut an) = linear_setup(1e-3, 1.0, 0.1);
    // A coordinate transform needs the system's transformed frame, which this one lacks.
    an.spec.method = Method::Interval;
    an.spec.transform = Some(Transform {
        matrix: identity(sys.n),
        inverse: identity(sys.n),
        frame: 0,
        source: TransformSource::Given,
    });
    assert!(matches!(
        engine::run_paired(&sys, &inf, &an),
        Err(RunError::Unsupported(_))
    ));
    an.spec.transform = None;
    an.spec.method = Method::Contraction;
    let constants = std::mem::replace(
        &mut an.constants,
        Err(reachc_core::model::NoConstants::Unbounded {
            entry: "d f[x1] / d x1".into(),
            expression: "x1^2".into(),
        }),
    );
    match engine::run_paired(&sys, &inf, &an) {
        Err(RunError::NoConstants(m)) => assert!(m.to_string().contains("unbounded"), "{m}"),
        other => panic!("expected NoConstants, got {other:?}"),
    }
    an.constants = constants;
    an.spec.delta = 1.5;
    assert!(matches!(
        engine::run_paired(&sys, &inf, &an),
        Err(RunError::Invalid(_))
    ));
    an.spec.delta = 1e-3;
    // A subnormal report step (the horizon 1e-320 with the default step): refused, where the
    // validated integrator's steps used to shrink to zero and never end.
    let mut tiny = an.clone();
    (tiny.spec.horizon, tiny.spec.step) = (1e-320, 1e-322);
    match engine::run_paired(&sys, &inf, &tiny) {
        Err(RunError::Invalid(m)) => {
            assert!(m.to_string().contains("at least 1e-100"), "{m}");
            assert_eq!(m.culprit, Some(Culprit::Setting(Setting::Step)));
        }
        other => panic!("expected Invalid, got {other:?}"),
    }
    let mut bad = an.clone();
    *bad.constants.as_mut().unwrap().metric_mut() = vec![1.0, 2.0, 2.0, 1.0];
    assert!(matches!(
        engine::run_paired(&sys, &inf, &bad),
        Err(RunError::Invalid(_))
    ));
}

#[test]
fn euler_uneven_horizon_domain_and_ball() {
    let (sys, mut inf, mut an) = linear_setup(1e-2, 1.05, 0.1);
    an.spec.integrator = Integrator::Euler;
    *inf.has_domain_mut() = true;
    // Ball of radius 0.5 over both states with metric diag(4, 1): bounding box (0.25, 0.5).
    *inf.initial_mut() = InitialSet {
        boxes: vec![None, None],
        balls: vec![reachc_core::model::Ball {
            states: vec![0, 1],
            center: vec![1.0, -1.0],
            radius: 0.5,
            metric: Some(vec![4.0, 0.0, 0.0, 1.0]),
        }],
    };
    let res = engine::run_paired(&sys, &inf, &an).unwrap();
    assert_eq!(res.steps().len(), 12);
    assert_eq!(res.steps().last().unwrap().t, 1.05);
    assert_eq!(res.initial_center(), vec![1.0, -1.0]);
    // P = I: r1 = 0.5 (the ball's longest semi-axis), not the bounding box's corner
    // |(0.25, 0.5)| = 0.559.
    assert!(res.r1() >= 0.5 && res.r1() - 0.5 < 1e-14, "{}", res.r1());
    assert_eq!(res.r1_bound().balls, BallBound::Joint { balls: 1 });
    // Euler: x*_{k+1} = (1 - 0.04) x*_k on full steps.
    assert!((res.steps()[1].nominal()[0] - 0.96).abs() < 1e-15);
    assert!(res.validation().conditional_on_domain);
    // The domain is a condition, not an unproved step: only the Euler nominal is listed.
    assert!(matches!(
        res.validation().not_validated[..],
        [Unproved::Nominal { .. }]
    ));
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
        let exact = certified.constants.as_ref().unwrap().c();
        let mut empirical = certified.clone();
        empirical.spec.rate = Rate::Empirical { paths: 50 };
        // The compiler leaves c unbounded for an empirical analysis.
        *empirical.constants.as_mut().unwrap().c_mut() = f64::INFINITY;
        let want = engine::run_paired(sys.as_ref(), &inf, &certified).unwrap();
        let got = engine::run_paired(sys.as_ref(), &inf, &empirical).unwrap();
        assert_eq!(got.rate().rate, Rate::Empirical { paths: 50 });
        assert_eq!(
            got.validation().not_validated[0],
            Unproved::EmpiricalRate { paths: 50 }
        );
        assert!(
            (got.rate().max_c - exact).abs() < 1e-12,
            "{}",
            got.rate().max_c
        );
        for (a, b) in want.steps().iter().zip(got.steps()) {
            assert!((b.c - exact).abs() < 1e-12, "t = {}: c = {}", b.t, b.c);
            let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * x.abs().max(1e-12);
            assert!(close(a.r_t, b.r_t), "t = {}: {} vs {}", a.t, a.r_t, b.r_t);
            assert!(close(a.det.radius(), b.det.radius()), "t = {}", a.t);
        }
    }
}

/// An empirical analysis does not need a certified c, and the interval method refuses it.
#[test]
fn empirical_rate_needs_no_certified_c_and_not_the_interval_method() {
    let (sys, inf, mut an) = linear_setup(1e-3, 1.0, 0.1);
    *an.constants.as_mut().unwrap().c_mut() = f64::NAN;
    assert!(matches!(
        engine::run_paired(&sys, &inf, &an),
        Err(RunError::NoConstants(_))
    ));
    an.spec.rate = Rate::Empirical { paths: 20 };
    assert!(engine::run_paired(&sys, &inf, &an).is_ok());
    an.spec.method = Method::Interval;
    assert!(matches!(
        engine::run_paired(&sys, &inf, &an),
        Err(RunError::Unsupported(_))
    ));
}

// ---------------------------------------------------------------------------------------------
// The `Reach` handle
// ---------------------------------------------------------------------------------------------

/// `from_box` is the run from that box; `at`, `contains` and `hull` answer at report times.
#[test]
fn reach_from_a_box_is_the_run_from_that_box() {
    let (sys, mut inf, an) = pendulum_setup();
    *inf.analyses_mut() = vec![an];
    let reach = Reach::paired(&sys, &inf, "main").unwrap();
    let x0 = [Bounds::new(0.1, 0.2), Bounds::new(-0.05, 0.0)];
    let prs = reach.from_box(&x0).unwrap();
    // The ball's own questions (the interval box it is intersected with is checked in
    // tests/tests/tighter_sets.rs).
    let prs = prs.without_members();
    let mut moved = inf.clone();
    *moved.initial_mut() = InitialSet::from_box(&x0);
    let direct = engine::run_paired(&sys, &moved, &moved.analyses()[0]).unwrap();
    assert_eq!(prs.steps(), direct.steps());
    assert_eq!(prs.r1(), direct.r1());
    // The spec's own initial set gives another (larger) PRS.
    assert!(reach.run().unwrap().r1() > prs.r1());
    // Report times only, found from a literal time.
    let st = prs.at(0.3).unwrap();
    assert_eq!(st.t, prs.steps()[30].t);
    assert!(prs.at(0.305).is_none() && prs.contains(&[0.0, 0.0], 0.305).is_none());
    assert_eq!(prs.contains(st.nominal(), 0.3), Some(true));
    // The hull: the P-ball's extent along each axis, r sqrt((P^-1)_ii), rounded outward.
    let det = PENDULUM_METRIC[0] * PENDULUM_METRIC[3] - PENDULUM_METRIC[1] * PENDULUM_METRIC[2];
    let spread = [PENDULUM_METRIC[3] / det, PENDULUM_METRIC[0] / det].map(f64::sqrt);
    let hull = prs.hull(0.3).unwrap();
    for i in 0..2 {
        let (c, e) = (st.nominal()[i], st.prs_radius * spread[i]);
        assert!(
            hull[i].lo <= c - e && c - e - hull[i].lo < 1e-12,
            "{hull:?}"
        );
        assert!(
            hull[i].hi >= c + e && hull[i].hi - (c + e) < 1e-12,
            "{hull:?}"
        );
        // The hull is tight: the P-ball's extreme point along axis i, c + r P^-1 e_i /
        // sqrt((P^-1)_ii), is in the PRS when pulled in slightly, not when pushed out.
        let pinv_col = [
            [PENDULUM_METRIC[3] / det, -PENDULUM_METRIC[2] / det],
            [-PENDULUM_METRIC[1] / det, PENDULUM_METRIC[0] / det],
        ][i];
        for (s, inside) in [(0.999, true), (1.001, false)] {
            let x: Vec<f64> = (0..2)
                .map(|j| st.nominal()[j] + s * st.prs_radius * pinv_col[j] / spread[i])
                .collect();
            assert_eq!(prs.contains(&x, 0.3), Some(inside), "axis {i}, {s}");
        }
    }
}

/// What the constants were certified for cannot be changed: another domain or input box in
/// the model data, or an initial set outside the spec's domain, is refused.
#[test]
fn reach_refuses_what_the_constants_do_not_cover() {
    let (sys, mut inf, an) = input_setup();
    *inf.analyses_mut() = vec![an];
    assert!(Reach::paired(&sys, &inf, "main").is_ok());
    assert!(matches!(
        Reach::paired(&sys, &inf, "other"),
        Err(RunError::UnknownAnalysis { .. })
    ));
    let mut wider = inf.clone();
    *wider.input_box_mut() = vec![Bounds::new(-2.0, 2.0)];
    match Reach::paired(&sys, &wider, "main").map(|_| ()) {
        Err(RunError::Invalid(m)) => assert!(m.to_string().contains("input box"), "{m}"),
        other => panic!("expected Invalid, got {other:?}"),
    }
    let mut bounded = inf.clone();
    *bounded.domain_mut() = vec![Bounds::new(-5.0, 5.0)];
    *bounded.has_domain_mut() = true;
    assert!(matches!(
        engine::run_paired(&sys, &bounded, &bounded.analyses()[0]),
        Err(RunError::Invalid(m)) if m.to_string().contains("domain")
    ));
    // With constants certified over that domain: initial sets inside it run, others do not.
    let constants = Constants::given(&bounded, vec![1.0], -1.0, 0.1, 1.0);
    bounded.analyses_mut()[0].constants = Ok(constants);
    let reach = Reach::paired(&sys, &bounded, "main").unwrap();
    assert!(reach.from_box(&[Bounds::new(4.0, 5.0)]).is_ok());
    match reach.from_box(&[Bounds::new(4.0, 5.5)]).map(|_| ()) {
        Err(RunError::Invalid(m)) => {
            assert!(m.to_string().contains("leaves the domain"), "{m}");
            assert_eq!(m.culprit, Some(Culprit::State(0)));
        }
        other => panic!("expected Invalid, got {other:?}"),
    }
    // A longer horizon than certified.
    let mut longer = inf.clone();
    longer.analyses_mut()[0]
        .constants
        .as_mut()
        .unwrap()
        .region_mut()
        .time = Bounds::new(0.0, 1.0);
    assert!(Reach::paired(&sys, &longer, "main").is_err());
}

/// A known input: no input uncertainty (`R_t = e^(ct) r1`), the nominal follows the plan, and
/// a plan outside the input box is refused.
#[test]
fn reach_under_an_input_plan() {
    let (sys, mut inf, an) = input_setup();
    *inf.analyses_mut() = vec![an];
    let reach = Reach::paired(&sys, &inf, "main").unwrap();
    let x0 = [Bounds::new(0.9, 1.1)];
    let plan = InputPlan::steps(vec![0.0, 1.0], vec![vec![0.5], vec![-0.5]]).unwrap();
    let prs = reach.from_box_with(&x0, &plan).unwrap();
    let free = reach.from_box(&x0).unwrap();
    assert_eq!(prs.r2(), 0.0);
    assert_eq!(prs.input_center(), [0.5]);
    for (st, any) in prs.steps().iter().zip(free.steps()) {
        // x' = -x + u from x0 = 1 (RK4 with step 0.1: within 1e-6 of the exact solution).
        let x = if st.t <= 1.0 {
            0.5 + 0.5 * (-st.t).exp()
        } else {
            let x1 = 0.5 + 0.5 * (-1.0f64).exp();
            -0.5 + (x1 + 0.5) * (-(st.t - 1.0)).exp()
        };
        assert!((st.nominal()[0] - x).abs() < 1e-6, "t = {}", st.t);
        let r = (-st.t).exp() * 0.1;
        assert!(st.det.radius() >= r && st.det.radius() - r < 1e-12);
        // The free input's set also covers the input's uncertainty.
        assert!(any.det.radius() >= st.det.radius());
    }
    let outside = InputPlan::constant(&[1.5]);
    assert!(matches!(
        reach.from_box_with(&x0, &outside),
        Err(RunError::Invalid(m)) if m.to_string().contains("input box")
    ));
    assert!(InputPlan::steps(vec![0.5], vec![vec![0.0]]).is_err());
    // A plan is not simulated with random inputs: the simulator refuses it.
    let opts = reachc_core::simulate::Options::default();
    assert!(
        reachc_core::simulate::simulate(&Paired::new(&sys, &inf), &prs, &opts, &mut |_, _| {})
            .is_err()
    );
}

/// Another delta changes the stochastic radius only, by the ratio of the kappas.
#[test]
fn reach_at_another_delta() {
    let (sys, mut inf, an) = linear_setup(1e-3, 1.0, 0.1);
    *inf.analyses_mut() = vec![an];
    let base = Reach::paired(&sys, &inf, "main").unwrap().run().unwrap();
    let wide = Reach::paired(&sys, &inf, "main")
        .unwrap()
        .with_delta(0.1)
        .unwrap()
        .run()
        .unwrap();
    let ratio = (kappa(2, 0.1, RadiusRule::Amgf) / kappa(2, 1e-3, RadiusRule::Amgf)).sqrt();
    let (a, b) = (&base.steps()[10], &wide.steps()[10]);
    assert!((b.r_t / a.r_t - ratio).abs() < 1e-12);
    assert_eq!(wide.delta(), 0.1);
    assert!(Reach::paired(&sys, &inf, "main")
        .unwrap()
        .with_delta(1.0)
        .is_err());
}

// ---------------------------------------------------------------------------------------------
// Results that are not finite
// ---------------------------------------------------------------------------------------------

/// `dX = a X dt + dW` in `R^1` from `X0 = x0`, with the certified rate `c = a`.
fn growing(a: f64, x0: f64, horizon: f64, guarantee: Guarantee) -> (Linear, ModelInfo) {
    let sys = Linear {
        n: 1,
        a,
        b: 0.0,
        s: 1.0,
    };
    let mut inf = info("growing", &["x"], vec![(x0, x0)], vec![]);
    let constants = Constants::given(&inf, vec![1.0], a, 1.0, 0.0);
    let mut an = analysis(1e-2, horizon, 0.1, constants);
    an.spec.guarantee = guarantee;
    *inf.analyses_mut() = vec![an];
    (sys, inf)
}

/// `Psi_t = (e^(2 c t) - 1) / (2 c)` overflows once `2 c t > ln(2 c f64::MAX)`: with `c = 400`
/// between 0.8 and 0.9 (`t = 0.8957`). The API refuses the result there instead of handing out
/// `r_t = inf`, and says which quantity and from when.
#[test]
fn a_radius_that_overflows_is_an_error_not_an_infinite_set() {
    let (sys, inf) = growing(400.0, 0.0, 2.0, Guarantee::Pointwise);
    let t_over = (800.0f64.ln() + f64::MAX.ln()) / 800.0;
    assert!(0.8 < t_over && t_over < 0.9, "{t_over}");
    match Reach::paired(&sys, &inf, "main").unwrap().run() {
        Err(RunError::NonFinite(d)) => {
            let m = &d.to_string();
            assert!(
                m.contains("the PRS is not finite from t = 0.9 on")
                    && m.contains("r_t = inf")
                    && m.contains("Psi_t overflowed (c = 400, sigma = 1"),
                "{m}"
            );
            assert_eq!(
                d.culprit,
                Some(reachc_core::engine::Culprit::Setting(
                    reachc_core::engine::Setting::Horizon
                ))
            );
        }
        other => panic!("expected NonFinite, got {other:?}"),
    }
    // A horizon before the overflow: a finite result, r_t = sqrt(Psi kappa) at 0.8.
    let (sys, inf) = growing(400.0, 0.0, 0.8, Guarantee::Pointwise);
    let res = Reach::paired(&sys, &inf, "main").unwrap().run().unwrap();
    let last = res.steps().last().unwrap();
    let psi = (800.0f64 * 0.8).exp_m1() / 800.0;
    assert!((last.psi / psi - 1.0).abs() < 1e-9, "{} vs {psi}", last.psi);
    assert!(last.r_t.is_finite());
}

/// A nominal trajectory that overflows (`x' = 400 x` from 1) is an error of the run too, naming
/// the time, and never a set with NaN or infinite numbers.
#[test]
fn a_nominal_that_blows_up_is_an_error() {
    let (sys, inf) = growing(400.0, 1.0, 3.0, Guarantee::Uniform);
    match Reach::paired(&sys, &inf, "main").unwrap().run() {
        Err(RunError::NonFinite(d)) => assert!(d.to_string().contains("t = "), "{d}"),
        other => panic!("expected NonFinite, got {other:?}"),
    }
}

/// Under the time-uniform guarantee the tube's radius `r_t` holds at each time alone too, so it
/// bounds the pointwise radius: with `c = 40` the pointwise `Psi_t` overflows after
/// `t = 8.95`, the tube's radius (`e^(psi_t)` times a bounded factor, `psi_t = 40 t`) does not,
/// and `r_pointwise` is `r_t` there; before, it is the closed form `sqrt(Psi_t kappa)`.
#[test]
fn r_pointwise_is_at_most_the_uniform_radius() {
    let (sys, inf) = growing(40.0, 0.0, 10.0, Guarantee::Uniform);
    let res = Reach::paired(&sys, &inf, "main").unwrap().run().unwrap();
    let last = res.steps().last().unwrap();
    assert_eq!(last.t, 10.0);
    assert!(last.psi.is_infinite(), "Psi_10 = e^800 / 80 overflows");
    assert!(last.r_t.is_finite() && last.r_t > 1e170, "{}", last.r_t);
    assert_eq!(last.r_pointwise, last.r_t);
    let k = kappa(1, 1e-2, RadiusRule::Amgf);
    for st in &res.steps()[1..] {
        assert!(st.r_pointwise <= st.r_t, "t = {}", st.t);
    }
    let st = &res.steps()[step_at(&res, 1.0)];
    let closed = ((80.0f64).exp_m1() / 80.0 * k).sqrt();
    assert!(
        (st.r_pointwise / closed - 1.0).abs() < 1e-9,
        "{} vs {closed}",
        st.r_pointwise
    );
    assert!(st.r_pointwise < st.r_t);
}
