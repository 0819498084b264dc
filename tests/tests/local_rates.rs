//! Local rates on the tube (method.md section 8.3) end to end through the interpreter: the rates
//! are never below the true measure over their regions, sample paths never leave the regions, and
//! a time-varying diffusion gets its own `sigma_t` per step.

use reachc_compiler::backend::interp::Interpreter;
use reachc_compiler::driver::{check_source, load};
use reachc_e2e::{interpreter_of, shipped, workspace};
use reachc_runtime::model::{ModelInfo, Rate};
use reachc_runtime::simulate::{sample_paths, Options};
use reachc_runtime::{Prs, Reach, System};

/// `mu_P(J)` of a 2 x 2 `J`: the largest root of `det(S - lambda P) = 0`, `S = sym(P J)`.
fn mu_p(p: &[f64], j: &[f64]) -> f64 {
    let pj = |r: usize, c: usize| p[r * 2] * j[c] + p[r * 2 + 1] * j[2 + c];
    let (s11, s22, s12) = (pj(0, 0), pj(1, 1), 0.5 * (pj(0, 1) + pj(1, 0)));
    let a = p[0] * p[3] - p[1] * p[1];
    let b = -(s11 * p[3] + s22 * p[0] - 2.0 * s12 * p[1]);
    let c = s11 * s22 - s12 * s12;
    (-b + (b * b - 4.0 * a * c).max(0.0).sqrt()) / (2.0 * a)
}

fn run(sys: &Interpreter, info: &ModelInfo, analysis: &str) -> Prs {
    let prs = Reach::paired(sys, info, analysis).unwrap().run().unwrap();
    assert_eq!(prs.rate().rate, Rate::Local);
    assert!(!prs.validation().conditional_on_domain);
    assert!(prs.validation().not_validated.is_empty());
    assert_eq!(prs.regions().len(), prs.internal_steps());
    prs
}

/// On a 21 x 21 grid of every region (corners included), at both ends of its step, `mu_P` of
/// the Jacobian never exceeds the region's `c_k`.
#[test]
fn local_rates_bound_the_measure_over_their_regions() {
    let (sys, info) = shipped("vanderpol_feedback.sde");
    for analysis in ["contraction", "interval"] {
        let prs = run(&sys, &info, analysis);
        let p = &prs.constants().metric;
        let mut j = [0.0; 4];
        let mut worst_gap = f64::INFINITY;
        for r in prs.regions() {
            for a in 0..=20 {
                for b in 0..=20 {
                    let x = [
                        r.lo[0] + (r.hi[0] - r.lo[0]) * f64::from(a) / 20.0,
                        r.lo[1] + (r.hi[1] - r.lo[1]) * f64::from(b) / 20.0,
                    ];
                    for t in [r.t0, r.t1] {
                        sys.jac_x(&x, &[], t, &mut j);
                        let mu = mu_p(p, &j);
                        assert!(mu <= r.c, "{analysis}: t = {t}, x = {x:?}: {mu} > {}", r.c);
                        worst_gap = worst_gap.min(r.c - mu);
                    }
                }
            }
        }
        // Not vacuous: somewhere the bound is within 0.2 of the sampled measure.
        assert!(worst_gap < 0.2, "{analysis}: {worst_gap}");
    }
}

/// 2000 Euler-Maruyama paths on the internal steps' grid stay inside the region of every step.
#[test]
fn sampled_paths_never_leave_the_regions() {
    let (sys, info) = shipped("vanderpol_feedback.sde");
    let prs = run(&sys, &info, "contraction");
    let mut times = vec![0.0];
    times.extend(prs.regions().iter().map(|r| r.t1));
    let opts = Options {
        paths: 2000,
        seed: 7,
        ..Options::default()
    };
    let paths = sample_paths(&sys, &info, &times, None, &opts).unwrap();
    let n = 2;
    for path in &paths {
        for (k, r) in prs.regions().iter().enumerate() {
            // Both ends of step k.
            for x in [&path[k * n..(k + 1) * n], &path[(k + 1) * n..(k + 2) * n]] {
                let inside = (0..n).all(|i| r.lo[i] <= x[i] && x[i] <= r.hi[i]);
                assert!(inside, "t in [{}, {}]: {x:?} outside {r:?}", r.t0, r.t1);
            }
        }
    }
}

/// `G = 0.1 (1 + sin t)`: each step's `sigma_k` covers the diffusion over its times and follows
/// it (the global constant would be 0.2 throughout).
#[test]
fn a_time_varying_diffusion_gets_sigma_per_step() {
    let src = "model tv\nstate x in [-0.1, 0.1]\nnoise w\ndrift { x' = -x }\n\
               diffusion { x: 0.1 * (1 + sin(t)) * w }\n\
               analysis a { horizon = 6  step = 0.05 }\n";
    let (model, diags) = check_source(src, &workspace());
    let model = model.unwrap_or_else(|| panic!("{diags:?}"));
    let (sys, info) = interpreter_of(model);
    let prs = run(&sys, &info, "a");
    let g = |t: f64| 0.1 * (1.0 + t.sin());
    for r in prs.regions() {
        let top = g(r.t0).max(g(r.t1));
        assert!(r.sigma >= top, "[{}, {}]: {} < {top}", r.t0, r.t1, r.sigma);
        // Within the step's own range (sin is 1-Lipschitz) plus rounding.
        assert!(r.sigma <= top + 0.1 * (r.t1 - r.t0) + 1e-9, "{r:?}");
    }
    let (lo, hi) = prs
        .regions()
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), r| {
            (a.min(r.sigma), b.max(r.sigma))
        });
    assert!(lo < 0.01 && hi > 0.19, "{lo} {hi}");
}

/// On every shipped spec (but the 1000-state chain, whose equations chain10 has), every analysis
/// with local rates gives a PRS at the horizon no larger than the same analysis with the global
/// rate, where the compiler could bound one.
#[test]
fn local_rates_are_never_looser_than_the_global_rate() {
    for path in reachc_e2e::shipped_specs()
        .into_iter()
        .filter(|p| !p.ends_with("chain1000.sde"))
    {
        let (sys, info) = interpreter_of(load(&path).unwrap().model);
        for analysis in info
            .analyses()
            .iter()
            .filter(|a| a.spec.rate == Rate::Local)
        {
            let Ok(consts) = &analysis.constants else {
                continue;
            };
            let name = format!("{} / {}", path.display(), analysis.spec.name);
            let local = reachc_runtime::engine::run_paired(&sys, &info, analysis).unwrap();
            if !consts.c().is_finite() {
                continue;
            }
            let mut global = analysis.clone();
            global.spec.rate = Rate::Global;
            let global = reachc_runtime::engine::run_paired(&sys, &info, &global).unwrap();
            let (l, g) = (
                local.steps().last().unwrap().prs_radius,
                global.steps().last().unwrap().prs_radius,
            );
            assert!(l <= g * (1.0 + 1e-9), "{name}: {l} > {g}");
            assert!(local.rate().max_c <= consts.c(), "{name}");
        }
    }
}
