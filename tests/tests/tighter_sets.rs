//! Tighter sets (method.md sections 8.1 and 8.5): exact Gaussian radii for affine systems, the
//! Gaussian mixture bound for time-uniform results, and `metric = auto` chosen for the PRS at
//! the horizon rather than for the rate alone.

use reachc_compiler::driver::load;
use reachc_e2e::{inline, interpreter_of, shipped, shipped_specs, workspace};
use reachc_runtime::model::Method;
use reachc_runtime::prs::{Proved, Role, UniformBound};
use reachc_runtime::simulate::{
    self, clopper_pearson_lower as lower_bound, clopper_pearson_upper as upper_bound, Options,
};
use reachc_runtime::system::Paired;
use reachc_runtime::{Prs, Reach};

/// The sum of the logs of the PRS's bounding-box half-widths at the horizon.
fn log_volume(prs: &Prs) -> f64 {
    let hull = prs
        .hull(prs.horizon())
        .expect("the horizon is a report time");
    hull.iter().map(|b| (0.5 * (b.hi - b.lo)).ln()).sum()
}

/// `dX = -0.4 X dt + sqrt(2) dW` in two states from 0: `Sigma_t = 2.5 (1 - e^(-0.8 t)) I`, and
/// for n = 2 the chi-square quantile is exactly `-2 ln(delta)`.
#[test]
fn linear_pointwise_radius_is_the_exact_chi2_radius() {
    let (sys, info) = shipped("linear.sde");
    let prs = Reach::paired(&sys, &info, "amgf_rule")
        .unwrap()
        .run()
        .unwrap();
    assert!(prs.validation().rigorous.contains(&Proved::ExactGaussian));
    let q = -2.0 * 1e-3f64.ln();
    let g = prs.radius_rule().gaussian.expect("an affine system");
    assert!(
        g.quantile >= q && g.quantile <= q * (1.0 + 1e-12),
        "{}",
        g.quantile
    );
    let mut worst = 0.0f64;
    for step in &prs.steps()[1..] {
        let exact = (q * 2.5 * -(-0.8 * step.t).exp_m1()).sqrt();
        assert!(
            step.r_t >= exact * (1.0 - 1e-15),
            "t = {}: {} < {exact}",
            step.t,
            step.r_t
        );
        assert_eq!(step.r_t, step.r_pointwise);
        worst = worst.max(step.r_t / exact - 1.0);
    }
    assert!(worst <= 1e-9, "largest relative excess {worst:e}");
}

/// At delta = 0.1 the exact sets are missed by a fraction of the paths consistent with 0.1 at
/// every report time checked (Clopper-Pearson both ways), not far below it.
#[test]
fn linear_exact_sets_are_missed_at_the_nominal_rate() {
    let (sys, info) = shipped("linear.sde");
    let prs = Reach::paired(&sys, &info, "amgf_rule")
        .and_then(|r| r.with_delta(0.1))
        .and_then(|r| r.run())
        .unwrap();
    let paths = 40_000;
    let opts = Options {
        paths,
        seed: 11,
        dt: Some(0.001),
        ..Options::default()
    };
    let report =
        simulate::simulate(&Paired::new(&sys, &info), &prs, &opts, &mut |_, _| {}).unwrap();
    for step in report.steps.iter().filter(|s| s.t > 0.2) {
        let (lo, hi) = (
            lower_bound(step.outside, paths, 1e-4),
            upper_bound(step.outside, paths, 1e-4),
        );
        assert!(
            lo <= 0.1 && 0.1 <= hi,
            "t = {}: {} outside",
            step.t,
            step.outside
        );
    }
}

/// A stable but non-normal drift: with the identity metric `mu(A) = 4 > 0`, so the AMGF tube
/// grows like `e^(4 t)` while `Sigma_t` stays bounded: the Gaussian mixture bound is chosen, and
/// it holds (uniformly in time) for the simulated paths.
#[test]
fn the_mixture_bound_replaces_an_exploding_tube_and_holds() {
    let (sys, info) = inline(
        "model nonnormal\n\
         state x1 = 0\nstate x2 = 0\nnoise w1\nnoise w2\n\
         drift {\n  x1' = -x1 + 10 * x2\n  x2' = -x2\n}\n\
         diffusion {\n  x1: 0.1 * w1\n  x2: 0.1 * w2\n}\n\
         analysis uniform {\n  metric = identity\n  delta = 0.1\n  horizon = 2\n  step = 0.02\n}\n",
    );
    let prs = Reach::paired(&sys, &info, "uniform")
        .unwrap()
        .run()
        .unwrap();
    let g = prs.radius_rule().gaussian.expect("an affine system");
    assert_eq!(g.uniform, Some(UniformBound::Mixture));
    assert!(prs
        .validation()
        .rigorous
        .iter()
        .any(|p| matches!(p, Proved::GaussianMixture { .. })));
    for step in &prs.steps()[1..] {
        assert!(step.r_t >= step.r_pointwise);
        assert!(step.r_t <= 3.0 * step.r_pointwise, "t = {}", step.t);
    }
    let paths = 20_000;
    let opts = Options {
        paths,
        seed: 5,
        dt: Some(0.002),
        ..Options::default()
    };
    let report =
        simulate::simulate(&Paired::new(&sys, &info), &prs, &opts, &mut |_, _| {}).unwrap();
    let tube = report.tube.as_ref().expect("a uniform result");
    assert!(tube.cp_lower <= 0.1, "{} paths left the tube", tube.outside);
    // Not vacuous: some paths do leave it at delta = 0.1.
    assert!(tube.outside > 0, "no path left the tube");
}

/// `metric = auto` never gives a larger PRS than the identity: the integrator chain, whose
/// rate-optimal metric is a thousand times worse than the identity, and every analysis of every
/// shipped spec with `metric = auto` or `auto(states = [..])` (where the compiler cannot predict
/// the PRS, the engine runs the identity too and keeps the smaller result).
#[test]
fn metric_auto_is_never_worse_than_the_identity() {
    let (sys, info) = shipped("integrator_chain.sde");
    let auto = Reach::paired(&sys, &info, "auto").unwrap().run().unwrap();
    let identity = Reach::paired(&sys, &info, "identity")
        .unwrap()
        .run()
        .unwrap();
    assert!(log_volume(&auto) <= log_volume(&identity) + 1e-9);
    let mut compared = Vec::new();
    for path in shipped_specs() {
        let source = std::fs::read_to_string(&path).unwrap();
        if !source.contains("metric = auto") {
            continue;
        }
        let (sys, info) = interpreter_of(load(&path).unwrap().model);
        // Every `metric = auto` or `metric = auto(states = [..])` line becomes the identity.
        let identity: Vec<&str> = source
            .lines()
            .map(|l| match l.trim_start().starts_with("metric = auto") {
                true => "    metric = identity",
                false => l,
            })
            .collect();
        let (id_sys, id_info) = inline(&identity.join("\n"));
        for analysis in info.analyses() {
            let name = &analysis.spec.name;
            let (Ok(a), Ok(b)) = (
                Reach::paired(&sys, &info, name).and_then(|r| r.run()),
                Reach::paired(&id_sys, &id_info, name).and_then(|r| r.run()),
            ) else {
                continue;
            };
            // Where the linearised Gaussian set (method.md 8.10) decides the result, the metric
            // enters only through the nominal's defect, bounded in the P-norm, and through the
            // shares of delta (per-state metrics: the set at delta / 3 against delta / 2 with
            // one metric): within 0.05.
            let slack = if a.also().iter().any(|m| m.role() == Role::Linearised) {
                0.05
            } else {
                1e-9
            };
            assert!(
                log_volume(&a) <= log_volume(&b) + slack,
                "{} / {name}: auto {} > identity {}",
                path.display(),
                log_volume(&a),
                log_volume(&b)
            );
            compared.push(name.clone());
        }
    }
    assert!(compared.len() >= 12, "{compared:?}");
}

/// At `t = 0` the contraction method's PRS is the initial box itself, not the P-ball around it:
/// an unsafe half-space 0.02 above the box is shown safe there (margin 0.02, the Euclidean
/// distance), where the ball reached into it.
#[test]
fn the_initial_box_is_the_set_at_time_zero() {
    let path = workspace().join("specs").join("vanderpol_feedback.sde");
    let source = std::fs::read_to_string(path).unwrap();
    let (sys, info) = inline(&source.replace("{ x >= 1.6 }", "{ x >= 1.12 }"));
    let prs = Reach::paired(&sys, &info, "contraction")
        .unwrap()
        .run()
        .unwrap();
    let start = &prs.steps()[0];
    assert!(
        (start.margins[0] - 0.02).abs() <= 1e-12,
        "{}",
        start.margins[0]
    );
    // The ball around the box reaches past the half-space.
    let w = prs.constants().spread[0];
    assert!(1.05 + start.det.radius() * w > 1.12);
    assert_eq!(prs.contains(&[1.1, 0.05], 0.0), Some(true));
    assert_eq!(prs.contains(&[1.11, 0.0], 0.0), Some(false));
}

/// Several metrics at once (method.md section 8.6): on the pendulum, one metric for theta and
/// one for omega, each at delta / 2, bring both half-widths at t = 4 below what one metric can
/// (theta at most 0.12 while omega at most 0.60; one metric: 0.109 and 0.814, or 0.241 and
/// 0.561). The PRS is the intersection: its box is the intersection of the members' boxes, and
/// a point in the first metric's set but outside the second's is outside.
#[test]
fn several_metrics_intersect_their_sets() {
    let (sys, info) = shipped("pendulum.sde");
    let prs = Reach::paired(&sys, &info, "per_state")
        .unwrap()
        .run()
        .unwrap();
    // The second metric's ball, and each metric's first-order set (8.8); both keep the flow's
    // shape (remainder at most a tenth of the linear part, with the sliced mean-value Jacobian
    // of method.md 8.8), so neither run computes an interval box (section 8.7).
    let balls: Vec<&Prs> = prs
        .also()
        .iter()
        .filter(|m| m.role() == Role::Metric)
        .collect();
    let count = |role: Role| prs.also().iter().filter(|m| m.role() == role).count();
    assert_eq!(
        (balls.len(), count(Role::Box), count(Role::FirstOrder)),
        (1, 0, 2)
    );
    assert_eq!(balls[0].method(), Method::Contraction);
    assert_eq!(prs.delta(), 1e-3);
    for m in prs.also() {
        assert_eq!(m.delta(), (1e-3f64 / 2.0).next_down());
    }
    let k = prs.steps().len() - 1;
    let hull = prs.hull_at(k).unwrap();
    let (theta, omega) = (
        0.5 * (hull[0].hi - hull[0].lo),
        0.5 * (hull[1].hi - hull[1].lo),
    );
    assert!(
        theta <= 0.12 && omega <= 0.60,
        "theta {theta}, omega {omega}"
    );
    let theirs = balls[0].hull_at(k).unwrap();
    assert!(theirs[1].hi >= hull[1].hi && theirs[0].hi >= hull[0].hi);
    // A point of the first metric's ball along omega, beyond the intersection's box.
    let st = &prs.steps()[k];
    let c = st.det.center();
    let p = &prs.constants().metric;
    let omega_far = st.prs_radius / p[3].sqrt() * 0.999;
    let x = [c[0], c[1] + omega_far];
    assert!(omega_far > 0.6, "{omega_far}");
    assert!(!prs.contains_at(k, &x));
    assert!(prs.contains_at(k, c));
    // The CSV carries the intersection's box after the first metric's radii.
    let mut csv = Vec::new();
    reachc_runtime::report::write_csv(&prs, &mut csv).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    assert_eq!(header[header.len() - 2..], ["prs_omega_lo", "prs_omega_hi"]);
    let last: Vec<f64> = csv
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(last[last.len() - 1], hull[1].hi);
}

/// Intersect what is known (method.md section 8.7): the pendulum's contraction ball is cut by
/// the interval box of the same run, widened by the same radii at the same delta. At t = 1.2
/// omega's half-width falls from 1.9 (the ball) to 0.8; a point of the ball outside the box
/// is outside the PRS; and the intersection holds for simulated paths at delta = 0.1. (With
/// `first_order = off`: by default the first-order sets keep the pendulum's shape over the
/// horizon, and then the run computes no box; see the next test.)
#[test]
fn the_contraction_ball_is_cut_by_the_interval_box() {
    let source = std::fs::read_to_string(workspace().join("specs/pendulum.sde")).unwrap();
    let source = source.replace(
        "    step = 0.01\n}",
        "    step = 0.01\n    first_order = off\n}",
    );
    let (sys, info) = inline(&source);
    let reach = Reach::paired(&sys, &info, "contraction").unwrap();
    let prs = reach.run().unwrap();
    let roles = |p: &Prs| p.also().iter().map(|m| m.role()).collect::<Vec<_>>();
    assert_eq!(roles(&prs), [Role::Box]);
    let boxes = &prs.also()[0];
    assert_eq!(
        (boxes.method(), boxes.delta()),
        (Method::Interval, prs.delta())
    );
    // The same stochastic radii widen both sets.
    for (a, b) in prs.steps().iter().zip(boxes.steps()) {
        assert_eq!((a.t, a.r_t), (b.t, b.r_t));
    }
    let k = prs.step_index(1.2).unwrap();
    let ball = prs.clone().without_members();
    let half = |p: &Prs| {
        let h = p.hull_at(k).unwrap();
        (0.5 * (h[0].hi - h[0].lo), 0.5 * (h[1].hi - h[1].lo))
    };
    let (own, cut) = (half(&ball), half(&prs));
    assert!(
        own.1 > 1.8 && cut.1 < 0.85,
        "ball {own:?}, intersection {cut:?}"
    );
    assert!(cut.0 <= own.0);
    // Along omega from the nominal state: in the ball, beyond the box.
    let c = prs.steps()[k].det.center().to_vec();
    let x = [c[0], c[1] + 1.5 * cut.1];
    assert!(ball.contains_at(k, &x) && !prs.contains_at(k, &x));
    assert!(prs.contains_at(k, &c));

    let prs = reach.with_delta(0.1).unwrap().run().unwrap();
    assert_eq!(roles(&prs), [Role::Box]);
    let paths = 4000;
    let opts = Options {
        paths,
        seed: 5,
        ..Options::default()
    };
    let report =
        simulate::simulate(&Paired::new(&sys, &info), &prs, &opts, &mut |_, _| {}).unwrap();
    for step in &report.steps {
        assert!(
            lower_bound(step.outside, paths, 1e-4) <= 0.1,
            "t = {}: {} of {paths} outside",
            step.t,
            step.outside
        );
    }
}

/// The interval box of a contraction run (method.md 8.7) is computed only where the first-order
/// sets do not keep the flow's shape: not for the pendulum (they do; the box took most of the
/// run's time and changed none of its sets, docs/benchmarks.md), but from the wide box of a
/// pendulum-like flow, where their remainder outgrows their linear part at `t = 0.55`
/// (tests/tests/linearised.rs) and the box cuts the ball.
#[test]
fn the_box_is_computed_only_where_first_order_sets_lose_their_shape() {
    let roles = |p: &Prs| p.also().iter().map(|m| m.role()).collect::<Vec<_>>();
    let (sys, info) = shipped("pendulum.sde");
    let prs = Reach::paired(&sys, &info, "contraction")
        .unwrap()
        .run()
        .unwrap();
    assert_eq!(roles(&prs), [Role::FirstOrder, Role::Linearised]);
    let (sys, info) = inline(
        "model wide\nstate x in [-1.2, 1.2]\nstate v in [-1, 1]\nnoise w\n\
         drift {\n x' = v\n v' = -4 * sin(x) - 0.5 * v\n}\ndiffusion {\n v: 0.05 * w\n}\n\
         analysis c {\n method = contraction\n metric = auto\n delta = 1e-3\n horizon = 3\n \
         step = 0.05\n}\n",
    );
    let prs = Reach::paired(&sys, &info, "c").unwrap().run().unwrap();
    assert!(roles(&prs).contains(&Role::Box), "{:?}", roles(&prs));
}

/// `first_order = on` (the default) cuts the pendulum's contraction ball by the first-order set
/// (a member of role `FirstOrder`, method.md 8.8), which makes omega's bound at the horizon
/// tighter; `first_order = off` gives the ball cut by the interval box of role `Box`;
/// a value other than `on` / `off` is refused (tests/bad/first_order_value.sde).
#[test]
fn first_order_sets_are_on_by_default_and_can_be_turned_off() {
    let spec = |extra: &str| {
        format!(
            "model p\nconst g = 10\nstate theta in [-pi/10, pi/10]\nstate omega in [-0.2, 0.2]\n\
             noise w\ndrift {{\n  theta' = omega\n  omega' = g * sin(theta) - 20 * theta - 20 * omega\n}}\n\
             diffusion {{ omega: 0.1 * w }}\n\
             analysis a {{ metric = auto  horizon = 2  step = 0.02 {extra} }}\n"
        )
    };
    let run = |extra: &str| {
        let (sys, info) = inline(&spec(extra));
        assert_eq!(
            info.analyses()[0].spec.first_order,
            extra != "first_order = off"
        );
        Reach::paired(&sys, &info, "a").unwrap().run().unwrap()
    };
    let (on, written, off) = (run(""), run("first_order = on"), run("first_order = off"));
    let roles = |p: &Prs| p.also().iter().map(|m| m.role()).collect::<Vec<_>>();
    // The first-order sets keep the flow's shape (remainder at most a tenth of the linear
    // part), so the run computes no interval box (method.md 8.7), and the noise is constant:
    // the linearised Gaussian set (8.10) comes with the first-order one. Without them the
    // box is computed.
    assert_eq!(roles(&on), [Role::FirstOrder, Role::Linearised]);
    assert_eq!(roles(&written), roles(&on));
    assert_eq!(roles(&off), [Role::Box]);
    assert_eq!(on.role(), Role::Own);
    let (h_on, h_off) = (on.hull(2.0).unwrap(), off.hull(2.0).unwrap());
    eprintln!("omega at t = 2: on {:?}, off {:?}", h_on[1], h_off[1]);
    // Every bound of the cut set inside the ball's, omega's at least a fifth tighter.
    for (a, b) in h_on.iter().zip(&h_off) {
        assert!(a.lo >= b.lo && a.hi <= b.hi, "{a:?} vs {b:?}");
    }
    assert!(h_on[1].hi - h_on[1].lo <= 0.8 * (h_off[1].hi - h_off[1].lo));
}

/// A point start (method.md 8.7): the box of the contraction run has no width at `t = 0`, so
/// its accuracy target is out of reach and only the floor of `1/64` of the report step stops
/// the shortening (the analysis' own boxes go down to `2^-12`: 4096 steps per report interval,
/// which the box's budget of 256 used to refuse, dropping it). The box is kept within that
/// floor, cuts the ball, and holds the noise-free solutions from the corners of the input box
/// (RK4 at `h = 1e-4`), at and between the report times.
#[test]
fn a_point_start_keeps_its_interval_box_within_the_floor() {
    let (sys, info) = inline(
        "model point_start\nstate x = 0\nstate y = 1\ninput u in [-0.01, 0.01]\nnoise w\n\
         drift {\n  x' = -x + sin(3 * t) + u\n  y' = -2 * y + x\n}\n\
         diffusion {\n  x: 0.05 * w\n  y: 0.05 * w\n}\n\
         analysis a { method = contraction  metric = auto  horizon = 2  step = 0.05 }\n",
    );
    let prs = Reach::paired(&sys, &info, "a").unwrap().run().unwrap();
    let boxes = prs
        .also()
        .iter()
        .find(|m| m.role() == Role::Box)
        .expect("the box is kept");
    let reports = prs.steps().len() - 1;
    assert!(
        boxes.internal_steps() > reports && boxes.internal_steps() <= 64 * reports,
        "{} internal steps over {reports} report intervals",
        boxes.internal_steps()
    );
    // Noise-free solutions for u = -0.01, 0, 0.01: inside the box at every report time and in
    // its span over each report interval.
    let f = |t: f64, s: [f64; 2], u: f64| [-s[0] + (3.0 * t).sin() + u, -2.0 * s[1] + s[0]];
    for u in [-0.01, 0.0, 0.01] {
        let (mut s, mut t, h) = ([0.0f64, 1.0], 0.0f64, 1e-4f64);
        for k in 1..=reports {
            let end = prs.steps()[k].t;
            while t < end - 1e-12 {
                let h = h.min(end - t);
                let k1 = f(t, s, u);
                let k2 = f(
                    t + h / 2.0,
                    [s[0] + h / 2.0 * k1[0], s[1] + h / 2.0 * k1[1]],
                    u,
                );
                let k3 = f(
                    t + h / 2.0,
                    [s[0] + h / 2.0 * k2[0], s[1] + h / 2.0 * k2[1]],
                    u,
                );
                let k4 = f(t + h, [s[0] + h * k3[0], s[1] + h * k3[1]], u);
                for i in 0..2 {
                    s[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                }
                t += h;
                assert!(boxes.span_contains(k, &s), "u = {u}, t = {t}: {s:?}");
            }
            let (lo, hi) = boxes.steps()[k].det.box_hull().expect("a box");
            for i in 0..2 {
                assert!(lo[i] <= s[i] && s[i] <= hi[i], "u = {u}, t = {end}: {s:?}");
            }
        }
    }
}
