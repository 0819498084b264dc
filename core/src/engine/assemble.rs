//! From the deterministic sets an engine computed to the result, the same for every engine:
//! the stochastic radius `r_t` per report time, the PRS radius, the safety margins, the
//! verdicts.

use super::radius::Stochastic;
use super::safety::{Check, Context};
use super::transform::Frame;
use super::Run;
use crate::interval::Interval;
use crate::model::{Inclusion, Method};
use crate::prs::{
    ConstantsUsed, DetSet, Proved, Prs, R1Bound, RateUsed, RuleUsed, Step, TransformUsed, Unproved,
    UnsafeVerdict, Validation, Verdict,
};

/// The deterministic part of a run, per report time.
pub(super) struct Deterministic {
    /// Report times.
    pub(super) grid: Vec<f64>,
    /// `Rbar_t` at each report time.
    pub(super) sets: Vec<DetSet>,
    /// `(c, sigma)` on the step ending at each report time.
    pub(super) rates: Vec<(f64, f64)>,
    /// The transform of a parallelotope result (for exact half-space support functions).
    pub(super) frame: Option<Frame>,
}

/// What the result says besides the sets, as the engine determined it.
pub(super) struct Header {
    pub(super) method: Method,
    pub(super) inclusion: Option<Inclusion>,
    pub(super) rate: RateUsed,
    pub(super) constants: ConstantsUsed,
    pub(super) radius_rule: RuleUsed,
    pub(super) kappa: f64,
    pub(super) r1: f64,
    pub(super) r2: f64,
    pub(super) r1_bound: R1Bound,
    pub(super) transform: Option<TransformUsed>,
    pub(super) initial_center: Vec<f64>,
    pub(super) input_center: Vec<f64>,
    pub(super) rigorous: Vec<Proved>,
    pub(super) not_validated: Vec<Unproved>,
}

/// The result of a run: `r_t` along the grid (exact per-step `Psi`), each step's PRS radius and
/// margins, and the verdicts.
pub(super) fn assemble(run: &Run, det: Deterministic, header: Header) -> Prs {
    let setup = run.setup;
    // Upper bounds of sqrt((P^-1)_ii): B_P(r) lies in the box |d_i| <= r w_i.
    let w: Vec<f64> = setup.p_inv_diag.iter().map(|d| d.sqrt().hi()).collect();
    let context = Context {
        w: &w,
        frame: det.frame.as_ref(),
    };
    let mut stochastic = Stochastic::new(header.kappa);
    let mut steps = Vec::with_capacity(det.grid.len());
    for (k, (set, &(c, sigma))) in det.sets.into_iter().zip(&det.rates).enumerate() {
        let t = det.grid[k];
        let prev = k.checked_sub(1).map(|j| det.grid[j]);
        let (psi, r_t) = stochastic.advance(prev, t, c, sigma);
        let prs_radius = (Interval::point(set.radius()) + Interval::point(r_t)).hi();
        let margins = setup
            .checks
            .iter()
            .map(|check| check.margin(&set, r_t, &context))
            .collect();
        steps.push(Step {
            t,
            det: set,
            r_t,
            psi,
            c,
            sigma,
            prs_radius,
            margins,
        });
    }
    let (unsafe_sets, verdict) = verdicts(run, &setup.checks, &steps);
    let mut not_validated = header.not_validated;
    if run.info.has_domain {
        not_validated.push(Unproved::Domain);
    }
    Prs {
        model: run.info.name.clone(),
        analysis: run.spec.name.clone(),
        method: header.method,
        inclusion: header.inclusion,
        delta: run.spec.delta,
        horizon: run.spec.horizon,
        step: run.spec.step,
        integrator: run.spec.integrator,
        states: run.info.states.clone(),
        outputs: run.spec.outputs.clone(),
        rate: header.rate,
        constants: header.constants,
        radius_rule: header.radius_rule,
        kappa: header.kappa,
        r1: header.r1,
        r2: header.r2,
        r1_bound: header.r1_bound,
        transform: header.transform,
        initial_center: header.initial_center,
        input_center: header.input_center,
        initial: run.initial.clone(),
        input_plan: match run.inputs {
            super::Inputs::Box => None,
            super::Inputs::Plan(plan) => Some(plan.clone()),
        },
        steps,
        unsafe_sets,
        verdict,
        validation: Validation {
            rigorous: header.rigorous,
            not_validated,
            conditional_on_domain: run.info.has_domain,
        },
    }
}

/// Per-set verdicts and the overall verdict from the per-step margins.
fn verdicts(run: &Run, checks: &[Check], steps: &[Step]) -> (Vec<UnsafeVerdict>, Verdict) {
    let mut verdicts = Vec::with_capacity(checks.len());
    // (step, set index) of the earliest failure; ties at the same step go to the first set.
    let mut first: Option<(usize, usize)> = None;
    for (j, (set, check)) in run.info.unsafe_sets.iter().zip(checks).enumerate() {
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
        verdicts.push(UnsafeVerdict {
            name: set.name.clone(),
            kind: check.kind(),
            safe: first_bad.is_none(),
            min_margin,
            min_margin_t: min_t,
            first_not_safe_t: first_bad.map(|k| steps[k].t),
        });
    }
    let verdict = if checks.is_empty() {
        Verdict::NoUnsafeSets
    } else if let Some((k, j)) = first {
        Verdict::NotShownSafe {
            t: steps[k].t,
            step: k,
            set: j,
        }
    } else {
        Verdict::Safe
    };
    (verdicts, verdict)
}
