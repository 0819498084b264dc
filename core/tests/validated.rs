//! Validated steps against closed forms: a stiff linear system with a report step far larger
//! than its fast time constant, and a time-varying one. The exact solutions from points of the
//! initial set, sampled densely inside every report interval, lie in the interval's span (and at
//! report times in the set itself), for both methods; the unvalidated RK4 of the same report
//! step misses them. A very stiff version keeps steps of the slow dynamics' length (ROS2 nodes,
//! method.md 8.4) and holds its exact solutions too.

use reachc_core::engine::Problem;
use reachc_core::interval::Interval;
use reachc_core::model::{
    Analysis, AnalysisSpec, Constants, Guarantee, Integrator, Method, ModelInfo, ModelParts, Rate,
};
use reachc_core::prs::Prs;
use reachc_core::{Reach, System};
use reachc_test_support::models;

/// `x' = -a x + y`, `y' = -0.1 y` (`a` = 20, or 1e5 for the very stiff case): stiff, no noise.
struct Stiff {
    a: f64,
}

const B: f64 = 0.1;

/// The stiff system of the first test.
const STIFF: Stiff = Stiff { a: 20.0 };

impl System for Stiff {
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
        out[0] = -self.a * x[0] + x[1];
        out[1] = -B * x[1];
    }
    fn drift_interval(&self, x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::point(-self.a) * x[0] + x[1];
        out[1] = Interval::point(-B) * x[1];
    }
    fn jac_x(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out.copy_from_slice(&[-self.a, 1.0, 0.0, -B]);
    }
    fn jac_x_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        for (o, v) in out.iter_mut().zip([-self.a, 1.0, 0.0, -B]) {
            *o = Interval::point(v);
        }
    }
    fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, _out: &mut [f64]) {}
    fn jac_u_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, _o: &mut [Interval]) {}
    fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
        out.copy_from_slice(&[0.0, 0.0]);
    }
    fn diffusion_interval(&self, _x: &[Interval], _t: Interval, out: &mut [Interval]) {
        out.fill(Interval::ZERO);
    }
}

/// The exact solution of [`Stiff`] with fast rate `a` from `(x0, y0)` at `t`.
fn stiff_exact(a: f64, x0: f64, y0: f64, t: f64) -> [f64; 2] {
    let y = y0 * (-B * t).exp();
    let x = x0 * (-a * t).exp() + y0 * ((-B * t).exp() - (-a * t).exp()) / (a - B);
    [x, y]
}

/// The largest eigenvalue of `sym(J) = [[-a, 0.5], [0.5, -b]]`, a contraction rate of
/// [`Stiff`] for `P = I`, with a margin above rounding.
fn stiff_rate(a: f64) -> f64 {
    let (s, d) = (a + B, a - B);
    // (-s + sqrt(d^2 + 1)) / 2, in the form without cancellation.
    (s * s - d * d - 1.0) / (-2.0 * (s + (d * d + 1.0).sqrt())) + 1e-12
}

/// `x' = -2 x + 3 cos(5 t)`: time-varying, no noise.
struct Forced;

impl System for Forced {
    fn n(&self) -> usize {
        1
    }
    fn p(&self) -> usize {
        0
    }
    fn m(&self) -> usize {
        1
    }
    fn drift(&self, x: &[f64], _u: &[f64], t: f64, out: &mut [f64]) {
        out[0] = -2.0 * x[0] + 3.0 * (5.0 * t).cos();
    }
    fn drift_interval(&self, x: &[Interval], _u: &[Interval], t: Interval, out: &mut [Interval]) {
        out[0] =
            Interval::point(-2.0) * x[0] + Interval::point(3.0) * (Interval::point(5.0) * t).cos();
    }
    fn jac_x(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = -2.0;
    }
    fn jac_x_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::point(-2.0);
    }
    fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, _out: &mut [f64]) {}
    fn jac_u_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, _o: &mut [Interval]) {}
    fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = 0.0;
    }
    fn diffusion_interval(&self, _x: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::ZERO;
    }
}

/// The exact solution of [`Forced`] from `x0` at `t`: `x = x0 e^(-2t) + 3 (2 cos 5t + 5 sin 5t
/// - 2 e^(-2t)) / 29`.
fn forced_exact(x0: f64, t: f64) -> f64 {
    let e = (-2.0 * t).exp();
    x0 * e + 3.0 * (2.0 * (5.0 * t).cos() + 5.0 * (5.0 * t).sin() - 2.0 * e) / 29.0
}

/// A model of `n` states from the box `x0`, with constants `c` (sigma = 0, P = I) by hand.
fn model(name: &str, x0: &[(f64, f64)], c: f64) -> ModelInfo {
    let n = x0.len();
    let mut info = ModelInfo::from_parts(ModelParts {
        states: (0..n).map(|i| format!("x{i}")).collect(),
        ..models::model(name, &[], &["w"], x0).into_parts()
    });
    let identity = (0..n * n)
        .map(|k| if k % (n + 1) == 0 { 1.0 } else { 0.0 })
        .collect();
    let constants = Constants::given(&info, identity, c, 0.0, 0.0);
    for (method, integrator) in [
        (Method::Contraction, Integrator::Validated),
        (Method::Interval, Integrator::Validated),
        (Method::Contraction, Integrator::Rk4),
    ] {
        info.analyses_mut().push(Analysis {
            spec: AnalysisSpec {
                name: format!("{}_{}", method.name(), integrator.name()),
                method,
                integrator,
                guarantee: Guarantee::Pointwise,
                horizon: 2.0,
                step: 0.1,
                rate: Rate::Global,
                ..AnalysisSpec::default()
            },
            constants: Ok(constants.clone()),
        });
    }
    info
}

/// Whether `x(t)` (exact) lies in the PRS at every report time and in the span of its report
/// interval at 40 times inside it; the first miss if not.
fn first_miss(prs: &Prs, exact: &dyn Fn(f64) -> Vec<f64>) -> Option<String> {
    for (k, st) in prs.steps().iter().enumerate() {
        if !prs.contains_at(k, &exact(st.t)) {
            return Some(format!("t = {}: not in the set", st.t));
        }
        if k == 0 {
            continue;
        }
        let t0 = prs.steps()[k - 1].t;
        for j in 1..40 {
            let t = t0 + (st.t - t0) * f64::from(j) / 40.0;
            if !prs.span_contains(k, &exact(t)) {
                return Some(format!("t = {t}: not in the span of ({t0}, {}]", st.t));
            }
        }
    }
    None
}

#[test]
fn the_stiff_system_is_enclosed_inside_every_step() {
    // The fast mode decays at rate 20 (time constant 0.05); report step 0.1; c = -0.1 for P = I
    // is not a bound here (mu(J) = (-20 - 0.1 + |...|) / 2 > -0.1), use a valid one: the
    // largest eigenvalue of sym(J) = [[-20, 0.5], [0.5, -0.1]], about -0.0875.
    let c = stiff_rate(STIFF.a);
    let info = model("stiff", &[(0.9, 1.1), (0.9, 1.1)], c);
    let corners = [(0.9, 0.9), (0.9, 1.1), (1.1, 0.9), (1.1, 1.1), (1.0, 1.0)];
    for name in ["contraction_validated", "interval_validated"] {
        let prs = Reach::paired(&STIFF, &info, name).unwrap().run().unwrap();
        assert!(prs.internal_steps() >= prs.steps().len() - 1);
        for &(x0, y0) in &corners {
            let exact = |t: f64| stiff_exact(STIFF.a, x0, y0, t).to_vec();
            assert_eq!(first_miss(&prs, &exact), None, "{name} from ({x0}, {y0})");
        }
        assert!(prs.validation().not_validated.is_empty(), "{name}");
    }
    // One unvalidated RK4 step per report step of 0.1 (h * 20 = 2): its nominal is far off,
    // and the exact solution leaves the "set" (what reachc printed before validated steps).
    let rk4 = Reach::paired(&STIFF, &info, "contraction_rk4")
        .unwrap()
        .run()
        .unwrap();
    let nominal = rk4.steps()[1].nominal()[0];
    let exact = stiff_exact(STIFF.a, 1.0, 1.0, 0.1)[0];
    assert!((nominal - exact).abs() > 0.1, "{nominal} vs {exact}");
    assert!(first_miss(&rk4, &|t| stiff_exact(STIFF.a, 1.0, 1.0, t).to_vec()).is_some());
}

/// The fast mode at rate 1e5 (time constant 1e-5) against report steps of 0.1: RK4 is stable
/// only below steps of about 2.8e-5, so RK4 nodes alone took at least 70,000 steps here; the
/// nominal's ROS2 nodes follow the slow dynamics in a few dozen, and every exact solution from
/// the initial box (corners 0.1 off the slow manifold `x = y / (a - b)`, where its centre is:
/// the ball absorbs their fast transients) stays in the sets and spans.
#[test]
fn a_very_stiff_system_keeps_long_steps_and_its_solutions() {
    let sys = Stiff { a: 1e5 };
    let x = 1.0 / (sys.a - B);
    let info = model(
        "very_stiff",
        &[(x - 0.1, x + 0.1), (0.9, 1.1)],
        stiff_rate(sys.a),
    );
    let prs = Reach::paired(&sys, &info, "contraction_validated")
        .unwrap()
        .run()
        .unwrap();
    assert!(
        prs.internal_steps() < 200,
        "{} internal steps",
        prs.internal_steps()
    );
    for (x0, y0) in [(-0.1, 0.9), (-0.1, 1.1), (0.1, 0.9), (0.1, 1.1), (0.0, 1.0)] {
        let x0 = x + x0;
        let exact = |t: f64| stiff_exact(sys.a, x0, y0, t).to_vec();
        assert_eq!(first_miss(&prs, &exact), None, "from ({x0}, {y0})");
    }
    assert!(prs.validation().not_validated.is_empty());
    // Not vacuous: the ball's radius stays about the initial box's half-diagonal (0.14).
    let last = prs.steps().last().unwrap();
    assert!(last.det.radius() < 0.15, "{}", last.det.radius());
}

#[test]
fn a_time_varying_drift_is_enclosed_inside_every_step() {
    let info = model("forced", &[(-0.5, 0.5)], -2.0);
    for name in ["contraction_validated", "interval_validated"] {
        let prs = Reach::paired(&Forced, &info, name).unwrap().run().unwrap();
        for x0 in [-0.5, -0.2, 0.0, 0.3, 0.5] {
            let exact = |t: f64| vec![forced_exact(x0, t)];
            assert_eq!(first_miss(&prs, &exact), None, "{name} from {x0}");
        }
        // Not vacuous: at t = 2 the set is about the initial width times e^(-4).
        let last = prs.steps().last().unwrap();
        let hull = prs.hull_at(prs.steps().len() - 1).unwrap();
        assert!(
            hull[0].hi - hull[0].lo < 0.05,
            "{name}: {hull:?} at t = {}",
            last.t
        );
    }
}

/// `x' = -x` whose interval forms give up where a contraction run's checks would: the Jacobian
/// is unbounded on any box wider than 0.05 (every region of the local rates: they hold the ball
/// of the initial box, 0.2 wide), and the drift's enclosure is unbounded after `t = 1` (the
/// validated nominal cannot go on there).
struct GivesUp;

impl System for GivesUp {
    fn n(&self) -> usize {
        1
    }
    fn p(&self) -> usize {
        0
    }
    fn m(&self) -> usize {
        1
    }
    fn drift(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = -x[0];
    }
    fn drift_interval(&self, x: &[Interval], _u: &[Interval], t: Interval, out: &mut [Interval]) {
        out[0] = if t.hi() > 1.0 {
            Interval::ENTIRE
        } else {
            -x[0]
        };
    }
    fn jac_x(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = -1.0;
    }
    fn jac_x_interval(&self, x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = if x[0].width() > 0.05 {
            Interval::ENTIRE
        } else {
            Interval::point(-1.0)
        };
    }
    fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, _out: &mut [f64]) {}
    fn jac_u_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, _o: &mut [Interval]) {}
    fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = 0.1;
    }
    fn diffusion_interval(&self, _x: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::point(0.1);
    }
}

/// Local rates that cannot be certified in the first report interval stop the run there, with
/// their own error, before the nominal is integrated over the horizon: here the nominal would
/// fail first, at `t = 1`, and the run used to report that, after integrating up to it.
#[test]
fn local_rates_failing_at_the_start_stop_the_run_before_the_nominal() {
    let mut info = models::model("gives_up", &["x"], &["w"], &[(0.9, 1.1)]);
    // No global rate (as for a model without a contracting metric): only local ones.
    let constants = Constants::given(&info, vec![1.0], f64::INFINITY, 0.1, 0.0);
    info.analyses_mut().push(Analysis {
        spec: AnalysisSpec {
            name: "local".into(),
            method: Method::Contraction,
            integrator: Integrator::Validated,
            rate: Rate::Local,
            guarantee: Guarantee::Uniform,
            horizon: 2.0,
            step: 0.05,
            ..AnalysisSpec::default()
        },
        constants: Ok(constants),
    });
    let err = Reach::paired(&GivesUp, &info, "local")
        .unwrap()
        .run()
        .unwrap_err();
    match err.problem() {
        Some(Problem::LocalRates { t, .. }) => assert!(*t <= 0.05, "at t = {t}"),
        other => panic!("{other:?}"),
    }
}
