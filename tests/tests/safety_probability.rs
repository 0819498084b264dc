//! The probability of safety (method.md 8.9): certified lower bounds against the closed forms
//! of a Brownian motion's running maximum (with and without drift), against Monte Carlo on a
//! nonlinear system, and what limits a bound.

use reachc_compiler::backend::interp::Interpreter;
use reachc_e2e::inline;
use reachc_runtime::engine::RunError;
use reachc_runtime::model::ModelInfo;
use reachc_runtime::probability::{SafetyLimit, DELTA_FLOOR, RESOLUTION};
use reachc_runtime::simulate::clopper_pearson_lower;
use reachc_runtime::{Reach, System};
use reachc_test_support::flow::euler_maruyama;
use reachc_test_support::rng::Rng;

/// `x' = mu` with noise `0.5 dW` from 0, unsafe `x >= 2`, horizon 1.
fn brownian(mu: f64) -> (Interpreter, ModelInfo) {
    inline(&format!(
        "model bm\nstate x = 0\nnoise w\ndrift {{ x' = {mu} }}\ndiffusion {{ x: 0.5 * w }}\n\
         unsafe high halfspace {{ x >= 2 }}\n\
         analysis a {{ method = contraction  delta = 0.1  horizon = 1  step = 0.05 }}\n"
    ))
}

/// The standard normal CDF (Abramowitz-Stegun 7.1.26 through erfc, error below 1.5e-7).
fn phi(x: f64) -> f64 {
    let z = x.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.3275911 * z);
    let poly = t
        * (0.254829592
            + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
    let erfc = poly * (-z * z).exp();
    if x >= 0.0 {
        1.0 - 0.5 * erfc
    } else {
        0.5 * erfc
    }
}

/// `P(max_{t <= T} (mu t + s W_t) >= b)` (reflection principle with drift).
fn crossing(mu: f64, s: f64, b: f64, horizon: f64) -> f64 {
    let sd = s * horizon.sqrt();
    1.0 - phi((b - mu * horizon) / sd)
        + (2.0 * mu * b / (s * s)).exp() * phi((-b - mu * horizon) / sd)
}

/// Both closed forms: the certified `delta` is never below the exact probability of crossing,
/// and the bisection ends within its resolution.
#[test]
fn brownian_bounds_hold_against_the_reflection_principle() {
    for (mu, within) in [(0.0, 100.0), (0.5, 100.0)] {
        let (sys, info) = brownian(mu);
        let p = Reach::paired(&sys, &info, "a")
            .unwrap()
            .safety_probability()
            .unwrap();
        let delta = p.delta.expect("a bound");
        let exact = crossing(mu, 0.5, 2.0, 1.0);
        eprintln!(
            "mu = {mu}: certified {delta:.3e}, exact {exact:.3e} ({} runs)",
            p.runs
        );
        assert!(delta >= exact, "mu = {mu}: {delta} < {exact}");
        assert!(delta <= within * exact, "mu = {mu}: {delta} vs {exact}");
        assert_eq!(p.limit, SafetyLimit::Resolution);
        let not = p.not_shown_at.unwrap();
        assert!(not < delta && delta <= not * RESOLUTION);
        assert!(p.validation.not_validated.is_empty());
        assert_eq!(p.lower_bound(), Some((1.0 - delta).next_down()));
    }
    // (mu = 0: 2 (1 - Phi(4)) = 6.33e-5.)
    assert!((crossing(0.0, 0.5, 2.0, 1.0) - 6.334e-5).abs() < 1e-7);
}

/// A nonlinear drift (contracting everywhere: its derivative is at most `-0.42`) from the
/// initial interval's worst end: the fraction of Euler-Maruyama
/// paths (`dt = 1e-3`, checked at every step) that enter the unsafe set is consistent with at
/// most the certified `delta` (Clopper-Pearson, 99.9%).
#[test]
fn a_nonlinear_bound_holds_against_monte_carlo() {
    let (sys, info) = inline(
        "model nl\nstate x in [-0.2, 0.2]\nnoise w\ndrift { x' = -x - 0.5 * sin(x) + 0.3 * cos(x) }\n\
         diffusion { x: 0.45 * w }\nunsafe high halfspace { x >= 1.3 }\n\
         analysis a { method = contraction  delta = 0.1  horizon = 2  step = 0.05 }\n",
    );
    let p = Reach::paired(&sys, &info, "a")
        .unwrap()
        .safety_probability()
        .unwrap();
    let delta = p.delta.unwrap_or_else(|| panic!("{p:?}"));
    assert!(delta > 1e-3 && delta < 0.5, "{delta}");
    let (paths, mut hits) = (4000u64, 0u64);
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for _ in 0..paths {
        let (mut x, mut t) = ([0.2], 0.0);
        while t < 2.0 - 1e-12 {
            let next = t + 1e-3;
            euler_maruyama(&sys, &mut x, &mut t, next, 1e-3, &mut rng);
            if x[0] >= 1.3 {
                hits += 1;
                break;
            }
        }
    }
    let low = clopper_pearson_lower(hits, paths, 1e-3);
    eprintln!(
        "certified {delta:.3e}, sampled {:.3e} ({hits} of {paths})",
        hits as f64 / paths as f64
    );
    assert!(low <= delta, "{low} > {delta}");
    assert_eq!(sys.n(), 1);
}

/// What limits a bound: the deterministic set alone crossing (no delta helps, one run), a set
/// far away (shown safe at the floor, two runs), and where no bound is defined.
#[test]
fn limits_and_refusals_are_reported() {
    let spec = |unsafe_at: f64, guarantee: &str| {
        format!(
            "model ramp\nstate x in [0, 0.1]\nnoise w\ndrift {{ x' = 1 }}\n\
             diffusion {{ x: 0.05 * w }}\nunsafe far halfspace {{ x >= {unsafe_at} }}\n\
             analysis a {{ method = contraction  horizon = 1  step = 0.05 {guarantee} }}\n"
        )
    };
    let (sys, info) = inline(&spec(0.5, ""));
    let p = Reach::paired(&sys, &info, "a")
        .unwrap()
        .safety_probability()
        .unwrap();
    assert_eq!((p.delta, p.runs), (None, 1));
    // The deterministic set [t, 0.1 + t] reaches 0.5 at t = 0.4: the first report time at
    // which it is not shown to avoid it is 0.4 (or the interval ending at 0.45).
    match p.limit {
        SafetyLimit::Deterministic { t, set: 0 } => assert!((0.4..=0.45).contains(&t), "{t}"),
        other => panic!("{other:?}"),
    }
    let (sys, info) = inline(&spec(100.0, ""));
    let p = Reach::paired(&sys, &info, "a")
        .unwrap()
        .safety_probability()
        .unwrap();
    assert_eq!(
        (p.delta, p.limit.clone(), p.runs),
        (Some(DELTA_FLOOR), SafetyLimit::Floor, 2)
    );
    let (sys, info) = inline(&spec(100.0, "guarantee = pointwise"));
    assert!(matches!(
        Reach::paired(&sys, &info, "a")
            .unwrap()
            .safety_probability(),
        Err(RunError::Unsupported(_))
    ));
    let (sys, info) = inline(
        "model free\nstate x = 0\nnoise w\ndrift { x' = -x }\ndiffusion { x: 0.1 * w }\n\
         analysis a { method = contraction  horizon = 1  step = 0.1 }\n",
    );
    assert!(matches!(
        Reach::paired(&sys, &info, "a")
            .unwrap()
            .safety_probability(),
        Err(RunError::Unsupported(_))
    ));
}

/// `reachc simulate --probability`'s check (`simulate::Options::safety_bound`): the certified
/// bound of the Brownian motion with drift against 20,000 Euler-Maruyama paths passes (the
/// paths that entered no unsafe set are at least the bound, statistically), and a bound of 1
/// fails the report, which says why, in its text and JSON.
#[test]
fn simulate_checks_the_certified_bound_against_the_paths() {
    use reachc_runtime::report::simulation::{summary, to_json};
    use reachc_runtime::simulate::{simulate, Options};
    use reachc_runtime::system::Paired;
    let (sys, info) = brownian(0.5);
    let reach = Reach::paired(&sys, &info, "a").unwrap();
    let bound = reach.safety_probability().unwrap().lower_bound().unwrap();
    let prs = reach.run().unwrap();
    let check = |b: f64| {
        let opts = Options {
            paths: 20_000,
            seed: 3,
            safety_bound: Some(b),
            ..Options::default()
        };
        simulate(&Paired::new(&sys, &info), &prs, &opts, &mut |_, _| {}).unwrap()
    };
    let rep = check(bound);
    let s = rep.safety.clone().expect("a model with unsafe sets");
    assert_eq!(
        s.safe,
        20_000 - rep.unsafe_sets[0].hits,
        "one set: safe = not hit"
    );
    assert!(
        s.safe < 20_000,
        "some paths cross (exact probability 2.2e-3)"
    );
    assert!(
        s.passed && s.cp_upper >= bound && rep.passed(),
        "{}",
        summary(&rep)
    );
    assert!(summary(&rep).contains("is not above it: PASS"));
    let too_high = check(1.0);
    let s = too_high.safety.clone().unwrap();
    assert!(!s.passed && !too_high.passed() && too_high.verdict.passed);
    assert!(summary(&too_high).contains("FAIL (the bound is too high)"));
    let json: serde_json::Value = serde_json::from_str(&to_json(&too_high)).unwrap();
    assert_eq!(json["safety"]["status"], "fail");
    assert_eq!(json["safety"]["certified"], 1.0);
    assert_eq!(
        json["verdict"]["status"], "pass",
        "the coverage itself passes"
    );
}
