//! Engines computing delta-probabilistic reachable sets (method.md, sections 2, 4-6).
//!
//! A delta-PRS at time t is the Minkowski sum of a deterministic reachable set `Rbar_t` and the
//! stochastic ball `B_P(r_t)`, `r_t = sqrt(Psi_t kappa(n, delta))` (Theorem 2). This module
//! implements the contraction-based engine (Proposition 3), where `Rbar_t` is itself a P-ball
//! `B_P(x*_t, R_t)` around the nominal trajectory, so the PRS is the P-ball
//! `B_P(x*_t, R_t + r_t)`. The interval-based engine (Proposition 4, [`run_interval`]) propagates
//! a box by an embedding system instead; its PRS is `box (+) B_P(r_t)`.
//!
//! What is rigorous: the constants come certified from the compiler; `kappa`, `Psi_t`, `r1`,
//! `R_t`, `r_t` and the safety margins are computed in outward-rounded interval arithmetic with
//! the conservative end kept. What is not: the nominal trajectory is integrated numerically
//! (RK4 or Euler) and taken as exact. The result records this in [`Validation`].

mod embedding;
mod interval;
mod linalg;
mod nominal;
mod radius;
mod rates;
mod result;
mod safety;
mod transform;

pub use interval::{reach, run_interval};
pub use radius::MAX_VERTEX_COORDS;
pub use result::{
    AnalysisResult, ConstantsReport, DetSet, RadiusRuleReport, RateReport, StepRecord,
    TransformReport, UnsafeReport, Validation, Verdict,
};

use crate::interval::Interval;
use crate::system::{Analysis, Constants, Integrator, Method, ModelInfo, RadiusRule, Rate, System};
use std::fmt;

/// Why an analysis could not run.
#[derive(Clone, Debug, PartialEq)]
pub enum RunError {
    /// The analysis asks for something this engine does not do (yet), e.g. a coordinate
    /// transform for the interval method.
    Unsupported(String),
    /// The compiler could not bound the constants of Assumption 1.
    NoConstants(String),
    /// The analysis or model data is inconsistent (bad delta, step, dimensions, metric...).
    Invalid(String),
    /// The nominal trajectory left the finite numbers.
    NonFinite(String),
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunError::Unsupported(m) => write!(f, "unsupported: {m}"),
            RunError::NoConstants(m) => write!(f, "no constants: {m}"),
            RunError::Invalid(m) => write!(f, "invalid analysis: {m}"),
            RunError::NonFinite(m) => write!(f, "numerical failure: {m}"),
        }
    }
}

impl std::error::Error for RunError {}

/// What both engines check and derive before stepping: the constants (only those `used` must be
/// finite), the dimensions, and the rigorous Cholesky factor of `P` with an enclosure of `P^-1`.
pub(crate) struct Setup<'a> {
    pub(crate) consts: &'a Constants,
    pub(crate) n: usize,
    pub(crate) p: usize,
    pub(crate) chol: Vec<Interval>,
    /// Enclosure of the diagonal of `P^-1`.
    pub(crate) p_inv_diag: Vec<Interval>,
}

/// Builds the [`Setup`] of `analysis`; `used` names the constants the engine needs
/// (`"c"`, `"sigma"`, `"rho"`).
pub(crate) fn setup<'a>(
    sys: &dyn System,
    info: &ModelInfo,
    analysis: &'a Analysis,
    used: &[&str],
) -> Result<Setup<'a>, RunError> {
    let consts = analysis.constants.as_ref().ok_or_else(|| {
        let why = analysis.constants_error.as_deref().unwrap_or(
            "the compiler could not bound them; see its diagnostics (a `domain` box may help)",
        );
        RunError::NoConstants(format!(
            "analysis `{}` has no constants ({}): {why}",
            analysis.name,
            used.join(", ")
        ))
    })?;
    let (n, p) = (sys.n(), sys.p());
    validate(info, analysis, n, p)?;
    let metric = &consts.metric;
    if metric.len() != n * n {
        return Err(RunError::Invalid(format!(
            "the metric has {} entries, expected {n} x {n}",
            metric.len()
        )));
    }
    for (what, v) in [
        ("c", consts.c),
        ("sigma", consts.sigma),
        ("rho", consts.rho),
    ] {
        if used.contains(&what) && !v.is_finite() {
            return Err(RunError::NoConstants(format!("{what} = {v} is not finite")));
        }
    }
    // Rigorous factorisation of P, used by every P^-1 quantity.
    let chol = linalg::cholesky(&linalg::to_intervals(metric), n).ok_or_else(|| {
        RunError::Invalid("the metric P is not (certifiably) symmetric positive definite".into())
    })?;
    let p_inv_diag = linalg::inverse_diagonal(&chol, n);
    Ok(Setup {
        consts,
        n,
        p,
        chol,
        p_inv_diag,
    })
}

/// Runs one analysis of the model.
///
/// [`Method::Interval`] runs [`run_interval`] with the analysis' inclusion function (a
/// coordinate transform needs the system's transformed frame, [`RunError::Unsupported`]
/// otherwise). The constants must be present ([`RunError::NoConstants`]). The contraction
/// rate comes from the analysis' [`Rate`]: certified by the compiler, or estimated from sample
/// paths (labelled so in the result).
pub fn run(
    sys: &dyn System,
    info: &ModelInfo,
    analysis: &Analysis,
) -> Result<AnalysisResult, RunError> {
    if analysis.method == Method::Interval {
        if analysis.rate != Rate::Certified {
            return Err(RunError::Unsupported(format!(
                "a {} rate with the interval method (it uses the certified rate)",
                analysis.rate.name()
            )));
        }
        return interval::run_interval(sys, info, analysis, analysis.inclusion);
    }
    let Setup {
        consts,
        n,
        p,
        chol,
        p_inv_diag,
    } = match analysis.rate {
        Rate::Certified => setup(sys, info, analysis, &["c", "sigma", "rho"])?,
        Rate::Empirical { .. } => setup(sys, info, analysis, &["sigma", "rho"])?,
    };
    let metric = &consts.metric;

    // Initial set and inputs.
    let (x0, half) =
        radius::initial_center_and_halfwidths(&info.initial, n).map_err(RunError::Invalid)?;
    let r1 = radius::r1_bound(metric, &half);
    let active = half.iter().filter(|&&h| h > 0.0).count();
    let r1_how = if active <= radius::MAX_VERTEX_COORDS {
        format!("max of |x0 - x*_0|_P over the vertices of the initial box ({active} non-degenerate coordinates)")
    } else {
        "sum_ij |P_ij| h_i h_j over the initial box (more than 16 coordinates)".to_string()
    } + if info.initial.balls.is_empty() {
        ""
    } else {
        "; balls replaced by their bounding boxes (conservative)"
    };
    let u_center: Vec<f64> = info
        .input_box
        .iter()
        .map(|&(lo, hi)| Interval::new(lo, hi).mid())
        .collect();
    // The input box is the U-ball of radius 1 around its centre (Constants::rho).
    let (rho, r2) = if p == 0 {
        (0.0, 0.0)
    } else {
        (consts.rho, 1.0)
    };

    // Stochastic factor, computed once.
    let (kappa, radius_rule) = radius::stochastic_factor(n, analysis);

    // Nominal trajectory (not validated).
    let grid = nominal::time_grid(analysis.horizon, analysis.step);
    let traj =
        nominal::integrate(sys, &x0, &u_center, &grid, analysis.integrator).map_err(|k| {
            RunError::NonFinite(format!(
                "the nominal trajectory is not finite at t = {}",
                grid[k]
            ))
        })?;

    // Safety checks, precomputed (they depend on P only).
    let checks =
        safety::Check::all(&info.unsafe_sets, n, &chol, &p_inv_diag).map_err(RunError::Invalid)?;

    // Per-step rates (None: the certified constant on every step).
    let rates = match analysis.rate {
        Rate::Certified => None,
        Rate::Empirical { paths } => Some(rates::empirical(
            sys, info, metric, &grid, &traj, &u_center, paths,
        )?),
    };
    let det_radii = rates
        .as_ref()
        .map(|c| rates::det_radii(c, &grid, rho, r1, r2));

    let mut stochastic = radius::Stochastic::new(kappa);
    let mut steps = Vec::with_capacity(grid.len());
    for (k, (&t, x)) in grid.iter().zip(traj).enumerate() {
        // c_t, sigma_t on the step ending at t.
        let c_k = rates.as_ref().map_or(consts.c, |c| c[k]);
        let sigma_k = consts.sigma;
        let prev = k.checked_sub(1).map(|j| grid[j]);
        let (psi_hi, r_t) = stochastic.advance(prev, t, c_k, sigma_k);
        let det = match &det_radii {
            Some(radii) => radii[k],
            None => radius::det_radius(consts.c, rho, r1, r2, t),
        };
        let prs = (Interval::point(det) + Interval::point(r_t)).hi();
        let margins = checks.iter().map(|c| c.margin(&x, prs)).collect();
        steps.push(StepRecord {
            t,
            det_set: DetSet {
                shape: "p_ball",
                center: x.clone(),
                radius: det,
                metric: "constants.metric",
                lo: None,
                hi: None,
                hull_lo: None,
                hull_hi: None,
            },
            nominal: x,
            r_t,
            psi: psi_hi,
            c: c_k,
            sigma: sigma_k,
            prs_radius: prs,
            margins,
        });
    }

    let (unsafe_sets, verdict) = verdicts(info, &checks, &steps);
    let mut not_validated = vec![format!(
        "nominal trajectory x*_t (numerical {} integration, step {}; taken as exact)",
        integrator_name(analysis.integrator),
        analysis.step
    )];
    if info.has_domain {
        not_validated.push(
            "conditional on staying in the domain: the constants hold only there, and the \
             result assumes the state does not leave it"
                .into(),
        );
    }
    let (rate, rate_rigorous) = rate_report(analysis.rate, rates.as_deref(), consts.c);
    if let Rate::Empirical { .. } = analysis.rate {
        not_validated.insert(0, rate.note.clone());
    }
    Ok(AnalysisResult {
        model: info.name.clone(),
        analysis: analysis.name.clone(),
        method: "contraction".into(),
        inclusion: None,
        delta: analysis.delta,
        horizon: analysis.horizon,
        step: analysis.step,
        integrator: integrator_name(analysis.integrator).into(),
        states: info.states.clone(),
        outputs: analysis.outputs.clone(),
        rate,
        constants: ConstantsReport {
            c: consts.c,
            sigma: consts.sigma,
            rho,
            how: consts.how.clone(),
            metric: metric.chunks(n).map(|r| r.to_vec()).collect(),
        },
        radius_rule,
        kappa,
        r1,
        r2,
        r1_how,
        transform: None,
        initial_center: x0,
        input_center: u_center,
        steps,
        unsafe_sets,
        verdict,
        validated: Validation {
            rigorous: vec![
                format!("{rate_rigorous} ({})", consts.how),
                "kappa (rounded up)".into(),
                "Psi_t (exact per-step integration in interval arithmetic, upper end)".into(),
                "radii r1, R_t, r_t, PRS radius (interval arithmetic, rounded up)".into(),
                "safety margins given the nominal (P^-1 enclosed by interval Cholesky, rounded \
                 down)"
                    .into(),
            ],
            not_validated,
            conditional_on_domain: info.has_domain,
        },
    })
}

/// The report of the rate's source and the "rigorous" line for the constants.
pub(crate) fn rate_report(rate: Rate, rates: Option<&[f64]>, c: f64) -> (RateReport, String) {
    let max_c = rates.map_or(c, |r| r.iter().copied().fold(f64::NEG_INFINITY, f64::max));
    let (note, rigorous) = match rate {
        Rate::Certified => (
            "one rate c for the whole horizon, certified by the compiler over the domain".into(),
            "constants c, sigma, rho",
        ),
        Rate::Empirical { paths } => (
            format!(
                "EMPIRICAL: c_t estimated from {paths} sample paths (largest one-sided Lipschitz \
                 quotient between a sampled state and the nominal), not certified: the PRS is \
                 an estimate, not a guarantee"
            ),
            "constants sigma, rho",
        ),
    };
    let report = RateReport {
        kind: rate.name().into(),
        note,
        paths: match rate {
            Rate::Empirical { paths } => Some(paths),
            Rate::Certified => None,
        },
        max_c,
    };
    (report, rigorous.to_string())
}

/// Whether `x` lies in the PRS `B_P(x*_t, R_t + r_t)` at report step `step_index` (for an
/// interval-method result: in `box (+) B_P(r_t)`).
///
/// Decided in interval arithmetic and conservatively: `true` only if `|x - x*_t|_P^2` is
/// certainly at most the squared PRS radius (a point within rounding of the boundary counts as
/// outside). Panics if `step_index` is out of range or `x` has the wrong length.
pub fn contains(result: &AnalysisResult, step_index: usize, x: &[f64]) -> bool {
    let st = &result.steps[step_index];
    if st.det_set.lo.is_some() {
        return interval::contains(result, step_index, x);
    }
    let n = st.nominal.len();
    assert_eq!(x.len(), n, "contains: x has the wrong dimension");
    let d: Vec<Interval> = x
        .iter()
        .zip(&st.nominal)
        .map(|(&a, &b)| Interval::point(a) - Interval::point(b))
        .collect();
    let p = &result.constants.metric;
    let mut q = Interval::ZERO;
    for i in 0..n {
        q += p[i][i] * d[i].sqr();
        for j in i + 1..n {
            // Both off-diagonal entries, so a slightly asymmetric stored P is used as given.
            q += Interval::point(p[i][j]) * d[i] * d[j] + Interval::point(p[j][i]) * d[j] * d[i];
        }
    }
    q.hi() <= Interval::point(st.prs_radius).sqr().lo()
}

/// Checks the analysis parameters and the model dimensions.
fn validate(info: &ModelInfo, a: &Analysis, n: usize, p: usize) -> Result<(), RunError> {
    let bad = |m: String| Err(RunError::Invalid(m));
    if !(a.delta > 0.0 && a.delta < 1.0) {
        return bad(format!("delta = {} must lie in (0, 1)", a.delta));
    }
    if !(a.step > 0.0 && a.step.is_finite()) {
        return bad(format!("step = {} must be positive and finite", a.step));
    }
    if !(a.horizon >= 0.0 && a.horizon.is_finite()) {
        return bad(format!(
            "horizon = {} must be non-negative and finite",
            a.horizon
        ));
    }
    if a.horizon / a.step > 1e8 {
        return bad(format!(
            "horizon / step = {} report steps is too many",
            a.horizon / a.step
        ));
    }
    if let RadiusRule::Paper(eps) = a.radius {
        if !(eps > 0.0 && eps < 1.0) {
            return bad(format!("the paper rule's eps = {eps} must lie in (0, 1)"));
        }
    }
    if n == 0 {
        return bad("the model has no states".into());
    }
    if info.states.len() != n {
        return bad(format!(
            "the model info names {} states, the system has {n}",
            info.states.len()
        ));
    }
    if info.input_box.len() != p {
        return bad(format!(
            "the input box has {} ranges, the system has {p} inputs",
            info.input_box.len()
        ));
    }
    for (j, &(lo, hi)) in info.input_box.iter().enumerate() {
        if Interval::try_new(lo, hi).is_none_or(|iv| !iv.is_bounded()) {
            return bad(format!(
                "input box of input {j} is [{lo}, {hi}] (must be bounded)"
            ));
        }
    }
    if let Some(&i) = a.outputs.iter().find(|&&i| i >= n) {
        return bad(format!("output state index {i} is out of range (n = {n})"));
    }
    Ok(())
}

/// Per-set verdicts and the overall verdict from the per-step margins.
fn verdicts(
    info: &ModelInfo,
    checks: &[safety::Check],
    steps: &[StepRecord],
) -> (Vec<UnsafeReport>, Verdict) {
    let mut reports = Vec::with_capacity(checks.len());
    // (step, set index) of the earliest failure; ties at the same step go to the first set.
    let mut first: Option<(usize, usize)> = None;
    for (j, (set, check)) in info.unsafe_sets.iter().zip(checks).enumerate() {
        let mut min_margin = f64::INFINITY;
        let mut min_t = 0.0;
        let mut first_bad: Option<usize> = None;
        for (k, st) in steps.iter().enumerate() {
            let m = st.margins[j];
            // NaN (not expected: margins are interval ends) must never count as safe.
            if (m.is_nan() || m <= 0.0) && first_bad.is_none() {
                first_bad = Some(k);
            }
            if m < min_margin || (m.is_nan() && !min_margin.is_nan()) {
                min_margin = m;
                min_t = st.t;
            }
        }
        if let Some(k) = first_bad {
            if first.is_none_or(|(fk, _)| k < fk) {
                first = Some((k, j));
            }
        }
        reports.push(UnsafeReport {
            name: set.name.clone(),
            kind: check.kind().into(),
            safe: first_bad.is_none(),
            min_margin,
            min_margin_t: min_t,
            first_not_safe_t: first_bad.map(|k| steps[k].t),
            margin_unit: match check {
                safety::Check::Box { .. } => {
                    "largest per-coordinate gap between the PRS's bounding box and the box".into()
                }
                _ => "Euclidean distance".into(),
            },
        });
    }
    let verdict = if checks.is_empty() {
        Verdict::NoUnsafeSets
    } else if let Some((k, j)) = first {
        Verdict::NotShownSafe {
            t: steps[k].t,
            step: k,
            set: info.unsafe_sets[j].name.clone(),
        }
    } else {
        Verdict::Safe
    };
    (reports, verdict)
}

fn integrator_name(i: Integrator) -> &'static str {
    match i {
        Integrator::Rk4 => "rk4",
        Integrator::Euler => "euler",
    }
}
