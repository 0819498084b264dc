//! The linearised Gaussian sets (method.md 8.10): against the closed form of a linear system
//! (the exact image of the initial box plus the exact covariance's box, nothing else), against
//! sampled noise-free flows of the nonlinear pendulum (the path-by-path error bound never below
//! the sampled error), against exactly sampled Ornstein-Uhlenbeck paths over whole report
//! intervals, how the default analyses use them (delta split, the better result), and the hints
//! when first-order sets lose their shape.

use reachc_compiler::driver::load;
use reachc_e2e::{
    inline, interpreter_of, linearised_member, reflection_factor, shipped, workspace,
};
use reachc_runtime::prs::{Hint, Proved, Role, Verdict};
use reachc_runtime::report::simulation::summary;
use reachc_runtime::simulate::{self, Options};
use reachc_runtime::system::Paired;
use reachc_runtime::Reach;
use reachc_test_support::flow::rk4;

/// `x'' = -2 x - 3 x' + 0.2 w` (eigenvalues -1, -2) from the box `[0.9, 1.1] x [-0.1, 0.1]`:
/// the member's box at each report time is `|e^(A t)| h + sqrt(factor Sigma_ii(t))` (`factor`
/// the squared normal quantile of the reflection bound), with `e^(A t)` and `Sigma_t` in closed
/// form. The linearisation is exact, so the only addition is the validated nominal's defect
/// (method.md 8.4; about 2e-4 here): the box is never below the
/// closed form and at most 2e-3 relative above it.
#[test]
fn a_linear_system_gets_the_exact_image_and_covariance() {
    let (sys, info) = inline(
        "model lin2\nstate x in [0.9, 1.1]\nstate v in [-0.1, 0.1]\nnoise w\n\
         drift {\n x' = v\n v' = -2 * x - 3 * v\n}\ndiffusion {\n v: 0.2 * w\n}\n\
         analysis a {\n method = contraction\n metric = auto\n delta = 1e-3\n horizon = 3\n \
         step = 0.05\n}\n",
    );
    let prs = Reach::paired(&sys, &info, "a").unwrap().run().unwrap();
    let (m, epochs) = linearised_member(&prs);
    assert_eq!(prs.delta(), 1e-3);
    assert!(m.delta() <= 5e-4 && m.delta() > 4.99e-4, "{}", m.delta());
    let factor = reflection_factor(2, epochs, m.delta());
    let h = [0.1, 0.1];
    let mut worst = 0.0f64;
    for (k, st) in m.steps().iter().enumerate().skip(1) {
        let t = st.t;
        let (e1, e2) = ((-t).exp(), (-2.0 * t).exp());
        let phi = [
            [2.0 * e1 - e2, e1 - e2],
            [-2.0 * e1 + 2.0 * e2, -e1 + 2.0 * e2],
        ];
        let i2 = |a: f64| -(-a * t).exp_m1() / a;
        let s11 = 0.04 * (i2(2.0) - 2.0 * i2(3.0) + i2(4.0));
        let s22 = 0.04 * (i2(2.0) - 4.0 * i2(3.0) + 4.0 * i2(4.0));
        let hull = m.hull_at(k).unwrap();
        for (i, s) in [s11, s22].into_iter().enumerate() {
            let exact = phi[i][0].abs() * h[0] + phi[i][1].abs() * h[1] + (factor * s).sqrt();
            let got = 0.5 * (hull[i].hi - hull[i].lo);
            assert!(
                got >= exact * (1.0 - 1e-12),
                "t = {t}, state {i}: {got} < {exact}"
            );
            worst = worst.max(got / exact - 1.0);
        }
    }
    assert!(worst <= 2e-3, "largest relative excess {worst:e}");
}

/// The pendulum without noise: the member is the first-order set with its error bounded per
/// coordinate. Sampled flows (RK4 of the model's drift, h = 1e-4) from the initial box's corners, edges' midpoints
/// and centre lie in its box at every report time checked, and the box is at most 1.3x their
/// spread (the error bound is second order and damped by the flow itself).
#[test]
fn noise_free_flows_lie_in_the_member_and_fill_it() {
    let source = std::fs::read_to_string(workspace().join("specs/pendulum.sde")).unwrap();
    let source = source.replace("omega: 0.1 * w", "omega: 0 * w");
    let (sys, info) = inline(&source);
    let prs = Reach::paired(&sys, &info, "contraction")
        .unwrap()
        .run()
        .unwrap();
    let (m, _) = linearised_member(&prs);
    let a = std::f64::consts::PI / 10.0;
    let starts: Vec<[f64; 2]> = [-1.0, 0.0, 1.0]
        .iter()
        .flat_map(|&s| [-1.0, 0.0, 1.0].map(|r| [s * a, r * 0.2]))
        .collect();
    for t in [0.5, 1.0, 2.0, 4.0] {
        let k = m.step_index(t).unwrap();
        let hull = m.hull_at(k).unwrap();
        let mut spread = [0.0f64; 2];
        let centre = m.steps()[k].det.center().to_vec();
        for &x0 in &starts {
            let (mut x, mut s) = (x0, 0.0);
            rk4(&sys, &mut x, &mut s, t, 1e-4);
            for i in 0..2 {
                assert!(
                    hull[i].lo <= x[i] && x[i] <= hull[i].hi,
                    "t = {t}, start {x0:?}: state {i} = {} outside {:?}",
                    x[i],
                    hull[i]
                );
                spread[i] = spread[i].max((x[i] - centre[i]).abs());
            }
            assert!(m.contains_at(k, &x), "t = {t}, start {x0:?}: {x:?}");
        }
        for i in 0..2 {
            let half = 0.5 * (hull[i].hi - hull[i].lo);
            assert!(
                half <= 1.3 * spread[i],
                "t = {t}, state {i}: {half} against the sampled {}",
                spread[i]
            );
        }
    }
}

/// The shipped pendulum's default analyses use the member: the rest of the run at delta / 2,
/// the member at delta / 2, the PRS their intersection at delta; omega's half-width at t = 4
/// at most 0.1065, 1.5x the Monte Carlo truth of issue 27 (0.071; without the member 0.579).
/// `first_order = off` turns it off with the first-order sets.
#[test]
fn the_default_analyses_split_delta_with_the_member() {
    let (sys, info) = shipped("pendulum.sde");
    for analysis in ["contraction", "interval"] {
        let prs = Reach::paired(&sys, &info, analysis).unwrap().run().unwrap();
        let (m, epochs) = linearised_member(&prs);
        assert_eq!(prs.delta(), 1e-3);
        assert_eq!(m.delta(), (1e-3f64 / 2.0).next_down());
        assert_eq!(epochs, m.internal_steps());
        for other in prs.also().iter().filter(|o| o.role() != Role::Linearised) {
            assert_eq!(other.delta(), (1e-3f64 / 2.0).next_down());
        }
        let k = prs.steps().len() - 1;
        let omega = 0.5 * (prs.hull_at(k).unwrap()[1].hi - prs.hull_at(k).unwrap()[1].lo);
        assert!(omega <= 0.1065, "{analysis}: omega {omega}");
        assert!(m.steps().iter().all(|s| s.r_t == 0.0));
    }
    let source = std::fs::read_to_string(workspace().join("specs/pendulum.sde")).unwrap();
    let source = source.replace(
        "    step = 0.01\n}",
        "    step = 0.01\n    first_order = off\n}",
    );
    let (sys, info) = inline(&source);
    let prs = Reach::paired(&sys, &info, "contraction")
        .unwrap()
        .run()
        .unwrap();
    assert!(prs.also().iter().all(|m| m.role() != Role::Linearised));
    assert_eq!(prs.delta(), 1e-3);
}

/// The member's Gaussian box over whole report intervals, against sampled paths: `x' = -20 x +
/// w` (an Ornstein-Uhlenbeck process with a 0.05 s correlation time, so its supremum over the
/// horizon is well above any one time's spread) from the worst start, sampled exactly on a
/// grid of `1e-4` (the Gaussian recursion of the linear SDE, no discretisation error at grid
/// points). At `delta = 0.2` the member holds at `0.1`: the fraction of paths that leave its
/// span at some grid point must stay below that (measured: 0.0495, so the bound is sharp to a
/// factor of two in probability), while a band at one time's 0.9 quantile is left by every
/// path somewhere (checked, so the test can tell).
#[test]
fn sampled_paths_stay_in_the_member_between_report_times() {
    let (sys, info) = inline(
        "model ou\nstate x in [-0.01, 0.01]\nnoise w\ndrift {\n x' = -20 * x\n}\n\
         diffusion {\n x: w\n}\nanalysis a {\n method = contraction\n metric = auto\n \
         delta = 0.2\n horizon = 2\n step = 0.05\n}\n",
    );
    let prs = Reach::paired(&sys, &info, "a").unwrap().run().unwrap();
    let (m, _) = linearised_member(&prs);
    assert!(m.delta() <= 0.1);
    let (rate, dt, per) = (20.0f64, 1e-4f64, 500usize);
    let decay = (-rate * dt).exp();
    let sd = ((1.0 - decay * decay) / (2.0 * rate)).sqrt();
    let paths = 4000;
    let mut rng = reachc_test_support::rng::Rng(0x05ee_d0f0);
    let (mut left_member, mut left_pointwise) = (0usize, 0usize);
    // In one dimension the member's span and set are intervals (its zonotope's hull is exact).
    let bounds: Vec<((f64, f64), (f64, f64))> = (1..m.steps().len())
        .map(|k| {
            let span = &m.steps()[k].span;
            assert_eq!(span.radius, 0.0);
            let set = m.hull_at(k).unwrap()[0];
            ((span.lo[0], span.hi[0]), (set.lo, set.hi))
        })
        .collect();
    // The pointwise 0.9 band of the stationary spread: |x| <= 1.645 sqrt(1 / 40).
    let pointwise = 1.6449 * (1.0 / (2.0 * rate)).sqrt();
    for _ in 0..paths {
        let mut x = 0.01f64;
        let (mut out_m, mut out_p) = (false, false);
        for ((lo, hi), (set_lo, set_hi)) in &bounds {
            for _ in 0..per {
                x = decay * x + sd * rng.normal();
                out_m |= x <= *lo || x >= *hi;
                out_p |= x.abs() > pointwise;
            }
            out_m |= x <= *set_lo || x >= *set_hi;
        }
        left_member += usize::from(out_m);
        left_pointwise += usize::from(out_p);
    }
    let (fm, fp) = (
        left_member as f64 / paths as f64,
        left_pointwise as f64 / paths as f64,
    );
    assert!(fm <= m.delta(), "{fm} of the paths left the member");
    assert!(
        fp > 0.5,
        "only {fp} left the pointwise band: the test cannot tell"
    );
}

/// A pendulum-like flow from a wide box: the first-order sets' second-order remainder outgrows
/// their linear part at `t = 1.25` (at `0.55` before the mean-value Jacobian was sliced,
/// method.md 8.8), and the result says so (a hint, with both P-radii). From a box a quarter as
/// wide (remainder about 16 times smaller, linear part 4 times) the remainder overtakes the
/// linear part only where both are below a tenth of the set's P-radius (the stochastic radius
/// dominates), so no hint. The shipped Van der Pol oscillator's `contraction` analysis cannot bound them at
/// all, and says that instead.
#[test]
fn first_order_sets_that_lose_their_shape_say_so() {
    let wide = "model wide\nstate x in [-1.2, 1.2]\nstate v in [-1, 1]\nnoise w\n\
         drift {\n x' = v\n v' = -4 * sin(x) - 0.5 * v\n}\ndiffusion {\n v: 0.05 * w\n}\n\
         analysis c {\n method = contraction\n metric = auto\n delta = 1e-3\n horizon = 3\n \
         step = 0.05\n}\n";
    let loose = |source: &str| {
        let (sys, info) = inline(source);
        let prs = Reach::paired(&sys, &info, "c").unwrap().run().unwrap();
        prs.hints().iter().find_map(|h| match *h {
            Hint::FirstOrderLoose {
                t,
                remainder,
                linear,
            } => Some((t, remainder, linear)),
            _ => None,
        })
    };
    let (t, remainder, linear) = loose(wide).expect("a hint");
    assert!((t - 1.25).abs() < 1e-9, "{t}");
    assert!(remainder > linear && linear > 0.0, "{remainder} {linear}");
    let quarter = wide
        .replace("[-1.2, 1.2]", "[-0.3, 0.3]")
        .replace("[-1, 1]", "[-0.25, 0.25]");
    assert_eq!(loose(&quarter), None);
    // (The shipped spec splits its box, method.md 8.11: here the whole box, unsplit.)
    let whole = std::fs::read_to_string(reachc_e2e::workspace().join("specs/vanderpol.sde"))
        .unwrap()
        .replace("split = [8, 8]", "");
    let (sys, info) = inline(&whole);
    let prs = Reach::paired(&sys, &info, "contraction")
        .unwrap()
        .run()
        .unwrap();
    assert!(
        prs.hints().contains(&Hint::FirstOrderUnbounded),
        "{:?}",
        prs.hints()
    );
}

/// Laub-Loomis (`specs/arch/laub_loomis.sde`, 7 states, no contracting metric) to `t = 4`: the
/// ball's local rates cannot close a region from `t = 2.95` on, so the result is the linearised
/// Gaussian set alone at the full delta (method.md 8.12), labelled so. Noise-free flows (RK4)
/// from the initial box's corners lie in its sets, 400 simulated paths stay in its tube (the
/// default Euler-Maruyama steps), and it shows the ARCH property `x4 < 4.5`.
#[test]
fn the_linearised_set_alone_where_the_ball_cannot_be_bounded() {
    let path = workspace().join("specs/arch/laub_loomis.sde");
    let (sys, mut info) = interpreter_of(load(&path).unwrap().model);
    info.analyses_mut()[0].spec.horizon = 4.0;
    let prs = Reach::paired(&sys, &info, "contraction")
        .unwrap()
        .run()
        .unwrap();
    assert_eq!(prs.role(), Role::Linearised);
    assert!(prs.also().is_empty());
    assert_eq!(prs.delta(), 1e-2);
    let why = prs
        .hints()
        .iter()
        .find_map(|h| match h {
            Hint::LinearisedAlone { failed } => Some(failed.to_string()),
            _ => None,
        })
        .expect("the hint says why");
    assert!(
        why.contains("the local rates cannot be certified at t = 2.95"),
        "{why}"
    );
    assert!(prs.validation().not_validated.is_empty());
    assert!(prs
        .validation()
        .rigorous
        .iter()
        .any(|p| matches!(p, Proved::LinearisedGaussian { .. })));
    assert!(matches!(prs.verdict(), Verdict::Safe));
    // Noise-free flows from the corners (a sample of 16 of the 128) and the centre.
    let bounds = prs.initial().bounding_box().unwrap();
    let mut starts: Vec<Vec<f64>> = (0..16u32)
        .map(|c| {
            (0..7)
                .map(|i| match (c >> (i % 4)) & 1 {
                    0 => bounds[i].lo,
                    _ => bounds[i].hi,
                })
                .collect()
        })
        .collect();
    starts.push(bounds.iter().map(|b| 0.5 * (b.lo + b.hi)).collect());
    for start in starts {
        let (mut x, mut t) = (start, 0.0);
        for (k, st) in prs.steps().iter().enumerate().skip(1).step_by(8) {
            rk4(&sys, &mut x, &mut t, st.t, 1e-3);
            assert!(prs.contains_at(k, &x), "t = {}: {x:?}", st.t);
        }
    }
    let opts = Options {
        paths: 400,
        seed: 3,
        ..Options::default()
    };
    let report =
        simulate::simulate(&Paired::new(&sys, &info), &prs, &opts, &mut |_, _| {}).unwrap();
    assert!(report.passed(), "{}", summary(&report));
    assert_eq!(report.tube.as_ref().map(|t| t.outside), Some(0));
}

/// Where the linearised set alone cannot be bounded either, the analysis fails with the first
/// diagnostic, noted so: `x' = x^2` from `[2, 3]` leaves every bound before `t = 1 / 3`.
#[test]
fn the_linearised_set_alone_that_cannot_be_bounded_either_says_so() {
    let (sys, info) = inline(
        "model blow\nstate x in [2, 3]\nnoise w\ndrift { x' = x^2 }\n\
         diffusion { x: 0.01 * w }\nanalysis a { horizon = 0.33 }\n",
    );
    let err = Reach::paired(&sys, &info, "a").unwrap().run().unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains(
            "(the linearised Gaussian set alone (method.md 8.12) could not be bounded over the \
             horizon either)"
        ),
        "{text}"
    );
}
