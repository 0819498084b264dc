//! First-order sets (method.md 8.8) against the truth: the zonotope plus its remainder holds
//! every sampled noise-free flow (the remainder is never below the sampled linearisation
//! error), its hull is close to the sampled hull, and on a linear system the generators are the
//! closed-form `exp(A t)` image of the initial box with a remainder at rounding level.

use reachc_core::engine;
use reachc_core::model::{Analysis, AnalysisSpec, Method, ModelInfo, ModelParts};
use reachc_core::prs::{DetSet, Prs};

use reachc_test_support::flow::rk4_step;
use reachc_test_support::models::{pendulum_constants, pendulum_model};
use reachc_test_support::systems::Pendulum;

/// The half-widths of the pendulum's initial box (centred at 0).
const HALF: [f64; 2] = [std::f64::consts::PI / 10.0, 0.2];

/// The model with the initial box `[-HALF, HALF]` and the paper's constants, and one analysis
/// of `method` with the defaults (validated steps, time-uniform tube, local rates).
fn setup(method: Method) -> (ModelInfo, Analysis) {
    let info = ModelInfo::from_parts(ModelParts {
        name: "pend".into(),
        ..pendulum_model().into_parts()
    });
    let constants = pendulum_constants(&info);
    let analysis = Analysis {
        spec: AnalysisSpec {
            name: "main".into(),
            method,
            delta: 1e-3,
            horizon: 4.0,
            step: 0.01,
            ..AnalysisSpec::default()
        },
        constants: Ok(constants),
    };
    (info, analysis)
}

/// The zonotope member of a result.
fn zonotope_member(prs: &Prs) -> &Prs {
    prs.also()
        .iter()
        .find(|m| matches!(m.steps()[1].det, DetSet::Zonotope { .. }))
        .expect("a first-order member")
}

/// The noise-free flow from `x` over `[0, t]` (RK4, step 1e-4).
fn flow(sys: &Pendulum, x: [f64; 2], t: f64) -> [f64; 2] {
    let steps = (t / 1e-4).round() as usize;
    let h = t / steps as f64;
    let mut x = x;
    for _ in 0..steps {
        rk4_step(sys, &mut x, &[], 0.0, h);
    }
    x
}

fn p_norm(p: &[f64], d: [f64; 2]) -> f64 {
    (p[0] * d[0] * d[0] + (p[1] + p[2]) * d[0] * d[1] + p[3] * d[1] * d[1]).sqrt()
}

/// Starts: the corners, the edges' middles and a grid inside, as fractions of the half-widths.
fn starts() -> Vec<[f64; 2]> {
    let f = [-1.0, -0.5, 0.0, 0.5, 1.0];
    f.iter()
        .flat_map(|&a| f.iter().map(move |&b| [a, b]))
        .collect()
}

/// For each report time in `times`: the largest sampled `|x - y|_P` (`y = c + G eta` for the
/// start's own `eta`) against the remainder, and the sampled hull against the zonotope's.
fn check(sys: &Pendulum, prs: &Prs, times: &[f64]) -> Vec<(f64, f64, [f64; 2], [f64; 2])> {
    let member = zonotope_member(prs);
    let p = &member.constants().metric;
    times
        .iter()
        .map(|&t| {
            let k = member
                .steps()
                .iter()
                .position(|s| (s.t - t).abs() < 1e-9)
                .expect("a report time");
            let DetSet::Zonotope {
                center,
                generators: g,
                remainder,
                hull_lo,
                hull_hi,
                ..
            } = &member.steps()[k].det
            else {
                panic!("a zonotope at t = {t}");
            };
            let (mut worst, mut sampled) = (0.0f64, [0.0f64; 2]);
            for eta in starts() {
                let x = flow(sys, [eta[0] * HALF[0], eta[1] * HALF[1]], t);
                let y = [
                    center[0] + g[0] * eta[0] + g[2] * eta[1],
                    center[1] + g[1] * eta[0] + g[3] * eta[1],
                ];
                worst = worst.max(p_norm(p, [x[0] - y[0], x[1] - y[1]]));
                for i in 0..2 {
                    sampled[i] = sampled[i].max((x[i] - center[i]).abs());
                }
            }
            let hull = [
                0.5 * (hull_hi[0] - hull_lo[0]),
                0.5 * (hull_hi[1] - hull_lo[1]),
            ];
            assert!(
                worst <= *remainder,
                "t = {t}: sampled linearisation error {worst} above the remainder {remainder}"
            );
            (worst, *remainder, hull, sampled)
        })
        .collect()
}

#[test]
fn pendulum_first_order_sets_hold_the_sampled_flows_both_methods() {
    let sys = Pendulum::PAPER;
    for method in [Method::Contraction, Method::Interval] {
        let (info, analysis) = setup(method);
        let prs = engine::run_paired(&sys, &info, &analysis).expect("runs");
        for (t, (worst, rem, hull, sampled)) in
            [1.0, 2.0, 4.0]
                .into_iter()
                .zip(check(&sys, &prs, &[1.0, 2.0, 4.0]))
        {
            // The zonotope's hull is the linearised image of the box: within its own remainder
            // (here a few per cent) of the true image's hull; the remainder is second order.
            let w = [0.18, 0.94];
            for i in 0..2 {
                assert!(
                    hull[i] <= 1.1 * sampled[i] + rem * w[i],
                    "{method:?} t = {t}, state {i}: hull {} vs sampled {}",
                    hull[i],
                    sampled[i]
                );
                assert!(hull[i] + rem * w[i] >= sampled[i]);
            }
            assert!(
                rem < 0.2,
                "{method:?} t = {t}: remainder {rem} (sampled {worst})"
            );
        }
    }
}

#[test]
fn linear_first_order_set_is_the_closed_form_image() {
    // A = [[0, 1], [-20, -20]]: eigenvalues l = -10 +- sqrt(80), exp(A t) in closed form.
    let sys = Pendulum { k: 0.0 };
    let (info, analysis) = setup(Method::Contraction);
    let prs = engine::run_paired(&sys, &info, &analysis).expect("runs");
    let member = zonotope_member(&prs);
    let (l1, l2) = (-10.0 + 80f64.sqrt(), -10.0 - 80f64.sqrt());
    for st in member.steps().iter().skip(1) {
        let t = st.t;
        let (e1, e2) = ((l1 * t).exp(), (l2 * t).exp());
        // exp(A t) = (e1 (A - l2 I) - e2 (A - l1 I)) / (l1 - l2).
        let a = [0.0, 1.0, -20.0, -20.0];
        let exp: Vec<f64> = (0..4)
            .map(|k| {
                let diag = if k == 0 || k == 3 { 1.0 } else { 0.0 };
                (e1 * (a[k] - l2 * diag) - e2 * (a[k] - l1 * diag)) / (l1 - l2)
            })
            .collect();
        let DetSet::Zonotope {
            generators: g,
            remainder,
            ..
        } = &st.det
        else {
            panic!("a zonotope at t = {t}");
        };
        for j in 0..2 {
            for i in 0..2 {
                let want = exp[i * 2 + j] * HALF[j];
                assert!(
                    (g[j * 2 + i] - want).abs() <= 1e-9,
                    "t = {t}: generator {j}, entry {i}: {} vs {want}",
                    g[j * 2 + i]
                );
            }
        }
        // Only the nominal's defect and rounding remain.
        assert!(*remainder <= 1e-6, "t = {t}: remainder {remainder}");
    }
    // The sampled flows hold too, the remainder at its tiny level.
    check(&sys, &prs, &[0.5, 1.0, 4.0]);
}
