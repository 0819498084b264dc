//! From the deterministic sets an engine computed on its internal steps to the result, the same
//! for every engine: the stochastic radius (pointwise, and the time-uniform tube), the PRS at
//! each report time and over each report interval, the safety margins over those intervals,
//! the verdicts.

use super::gaussian;
use super::local::Found;
use super::radius::Stochastic;
use super::safety::{Check, Context};
use super::uniform::{Scale, Tube};
use super::Run;
use crate::interval::Interval;
use crate::model::{Guarantee, Inclusion, Method, ModelInfo, RadiusRule, Rate, Split, UnsafeShape};
use crate::prs::{
    ConstantsUsed, DetSet, GaussianUsed, Proved, Prs, R1Bound, RateUsed, Role, RuleUsed, Span,
    Step, TransformUsed, UniformBound, Unproved, UnsafeVerdict, Validation, Verdict,
};
use crate::sets::parallelotope::Frame;
use crate::sweep;
use std::borrow::Cow;

/// One internal step `[t0, t1]` of the deterministic part.
pub(super) struct Piece {
    /// Its end.
    pub(super) t1: f64,
    /// `(c, sigma)` on the step.
    pub(super) rates: (f64, f64),
    /// `Rbar_(t1)` when `t1` is a report time (only those sets are reported).
    pub(super) end: Option<DetSet>,
    /// A set holding `Rbar_s` for every `s` in `[t0, t1]` (radius: a P-ball added to the box).
    pub(super) over: Span,
}

/// The deterministic part of a run.
pub(super) struct Deterministic {
    /// `Rbar_0`.
    pub(super) start: DetSet,
    /// The internal steps, in order from `t = 0`; their ends include every report time.
    pub(super) pieces: Vec<Piece>,
    /// The transform of a parallelotope result (for exact half-space support functions).
    pub(super) frame: Option<Frame>,
    /// The time-uniform tube the rates were certified with (local rates: the regions hold
    /// this tube, so the result must use it); `None`: laid out here from the scale.
    pub(super) tube: Option<Tube>,
}

/// What the result says besides the sets, as the engine determined it.
#[derive(Clone)]
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

/// The stochastic radius at each report time and its largest value over the report interval
/// ending there, for the run's guarantee; and the pointwise `Psi`, `r` at each report time.
#[derive(Clone)]
pub(super) struct Radii {
    /// Per report time after 0: `(Psi upper, pointwise r)`.
    pointwise: Vec<(f64, f64)>,
    /// Per report time after 0: `(radius at it, largest radius over its report interval)` of
    /// the guarantee.
    guaranteed: Vec<(f64, f64)>,
    /// The time-uniform bound used and its epochs (uniform guarantee).
    uniform: Option<(UniformBound, usize)>,
    /// The exact Gaussian route (affine systems under the amgf rule).
    gaussian: Option<GaussianUsed>,
}

impl Radii {
    /// The radii of a run whose deterministic part is `det`, with the factor `kappa`.
    pub(super) fn new(run: &Run, det: &Deterministic, kappa: f64) -> Radii {
        let mut stochastic = Stochastic::new(kappa);
        let mut t0 = 0.0;
        let mut pointwise = Vec::new();
        for p in &det.pieces {
            let (c, sigma) = p.rates;
            let r = stochastic.advance(Some(t0), p.t1, c, sigma);
            t0 = p.t1;
            if p.end.is_some() {
                pointwise.push(r);
            }
        }
        let times: Vec<f64> = det
            .pieces
            .iter()
            .filter(|p| p.end.is_some())
            .map(|p| p.t1)
            .collect();
        let gauss = match run.spec.radius {
            RadiusRule::Amgf => gaussian::radii(run, &times),
            _ => None,
        };
        if let Some(g) = &gauss {
            // Both radii are valid for each time; the Gaussian one is never larger in exact
            // arithmetic.
            for (pw, &r) in pointwise.iter_mut().zip(&g.pointwise) {
                pw.1 = pw.1.min(r);
            }
        }
        let used = |uniform| {
            gauss.as_ref().map(|g| GaussianUsed {
                quantile: g.quantile,
                uniform,
            })
        };
        match run.spec.guarantee {
            // Psi and Sigma are increasing, so an interval's largest radius is its end's.
            Guarantee::Pointwise => Radii {
                guaranteed: pointwise.iter().map(|&(_, r)| (r, r)).collect(),
                pointwise,
                uniform: None,
                gaussian: used(None),
            },
            Guarantee::Uniform => {
                let (tube, epochs) = amgf_tube(run, det);
                // Both bounds are valid; the one with the smaller radii (summed over the report
                // times, a deterministic choice) is used.
                let sum = |radii: &[(f64, f64)]| radii.iter().map(|r| r.0).sum::<f64>();
                let (guaranteed, uniform) = match gauss.as_ref().and_then(|g| g.uniform.clone()) {
                    Some((mix, k)) if sum(&mix) < sum(&tube) => (mix, (UniformBound::Mixture, k)),
                    _ => (tube, (UniformBound::AmgfTube, epochs)),
                };
                // The time-uniform radius at a report time holds for that time alone too
                // (method.md 8.2): it bounds the pointwise one, which can overflow where it
                // does not.
                let mut pointwise = pointwise;
                for (pw, &(r, _)) in pointwise.iter_mut().zip(&guaranteed) {
                    pw.1 = pw.1.min(r);
                }
                Radii {
                    guaranteed,
                    pointwise,
                    uniform: Some(uniform),
                    gaussian: used(Some(uniform.0)),
                }
            }
        }
    }

    /// The radii of a discrete-time run (method.md 8.16): `at[k]` is `(Psi, r)` at the end of
    /// `pieces[k]` (a map step), a report interval's radius the largest of its steps'; with
    /// `union`, the union bound over that many steps made them hold at once.
    pub(super) fn discrete(
        pieces: &[Piece],
        at: &[(f64, f64)],
        union: Option<usize>,
        gaussian: Option<GaussianUsed>,
    ) -> Radii {
        let (mut pointwise, mut guaranteed) = (Vec::new(), Vec::new());
        let mut over = 0.0f64;
        for (p, &(psi, r)) in pieces.iter().zip(at) {
            over = over.max(r);
            if p.end.is_some() {
                pointwise.push((psi, r));
                guaranteed.push((r, over));
                over = 0.0;
            }
        }
        Radii {
            pointwise,
            guaranteed,
            uniform: union.map(|steps| (UniformBound::UnionOverSteps, steps)),
            gaussian,
        }
    }

    /// No stochastic radius: for sets that hold the stochastic part themselves (method.md
    /// 8.10), at `reports` report times after 0.
    pub(super) fn inside(reports: usize) -> Radii {
        Radii {
            pointwise: vec![(0.0, 0.0); reports],
            guaranteed: vec![(0.0, 0.0); reports],
            uniform: None,
            gaussian: None,
        }
    }
}

/// The AMGF tube's radii per report time `(at it, largest over its report interval)`, and its
/// number of epochs.
fn amgf_tube(run: &Run, det: &Deterministic) -> (Vec<(f64, f64)>, usize) {
    let mut t0 = 0.0;
    let scale = Scale::new(det.pieces.iter().map(|p| {
        let h = Interval::point(p.t1) - Interval::point(t0);
        t0 = p.t1;
        (h, p.rates.0, p.rates.1)
    }));
    let tube = det.tube.clone().unwrap_or_else(|| {
        let first = det.pieces.iter().position(|p| p.end.is_some()).unwrap_or(0);
        Tube::for_scale(run.setup.n, run.spec.delta, &scale, first + 1)
    });
    // Per report interval: the radius over the hull of psi and S along it (the tube's bound
    // holds for every time whose psi and S lie in the hulls).
    let mut guaranteed = Vec::new();
    let (mut psi, mut s) = (scale.psi[0], scale.s[0]);
    for (k, p) in det.pieces.iter().enumerate() {
        psi = psi.hull(scale.psi[k + 1]);
        s = s.hull(scale.s[k + 1]);
        if p.end.is_some() {
            let end = tube.radius(scale.psi[k + 1], scale.s[k + 1]);
            guaranteed.push((end, tube.radius(psi, s).max(end)));
            (psi, s) = (scale.psi[k + 1], scale.s[k + 1]);
        }
    }
    (guaranteed, tube.epochs())
}

/// The result of a run's deterministic part `det` with the stochastic radii `radii` (those of
/// its own pieces, [`Radii::new`], or of another deterministic part of the same run: they bound
/// the same process, so they hold for any set holding the noise-free solutions).
pub(super) fn assemble_with(
    run: &Run,
    det: Deterministic,
    header: Header,
    local: Option<Found>,
    radii: Radii,
) -> Prs {
    let setup = run.setup;
    let w = spread(run);
    let context = Context {
        w: &w,
        frame: det.frame.as_ref(),
    };
    // Moving unsafe sets (method.md 8.15): each report interval's checks against the fixed
    // sets holding every position of the moving ones over it, which are kept for the result.
    let mut swept: Vec<Vec<UnsafeShape>> = vec![Vec::new(); setup.checks.len()];
    let mut checks_over = |t: Interval| -> Cow<'_, [Check]> {
        if !run.info.unsafe_sets.iter().any(|u| !u.moving.is_empty()) {
            return Cow::Borrowed(&setup.checks);
        }
        let numbers = sweep::numbers(run.sys, run.info, t);
        let sets = sweep::unsafe_sets(run.info, &numbers);
        let moved = setup
            .checks
            .iter()
            .zip(&sets)
            .map(|(c, s)| c.moved(&s.shape));
        for ((kept, set), u) in swept.iter_mut().zip(&sets).zip(&run.info.unsafe_sets) {
            if !u.moving.is_empty() {
                kept.push(set.shape.clone());
            }
        }
        Cow::Owned(moved.collect())
    };
    let mut steps = Vec::new();
    // t = 0: the initial set, no stochastic part yet.
    let start_span = span_of(&det.start, 0.0);
    steps.push(Step {
        t: 0.0,
        prs_radius: det.start.radius(),
        margins: checks_over(Interval::ZERO)
            .iter()
            .map(|check| check.margin(&det.start, 0.0, &context))
            .collect(),
        det: det.start,
        r_t: 0.0,
        r_pointwise: 0.0,
        r_span: 0.0,
        psi: 0.0,
        c: det.pieces.first().map_or(0.0, |p| p.rates.0),
        sigma: det.pieces.first().map_or(0.0, |p| p.rates.1),
        span: start_span,
    });
    // The report interval being gathered: the hull of the steps' deterministic sets.
    let mut gathered: Option<Span> = None;
    // The largest rates over the report interval being gathered.
    let mut rates = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    let internal_steps = det.pieces.len();
    let mut report = 0;
    for piece in det.pieces {
        gathered = Some(match gathered {
            None => piece.over,
            Some(g) => g.hull(&piece.over),
        });
        rates = (rates.0.max(piece.rates.0), rates.1.max(piece.rates.1));
        let Some(end) = piece.end else {
            continue;
        };
        let (r_end, r_over) = radii.guaranteed[report];
        let (psi, r_pointwise) = radii.pointwise[report];
        report += 1;
        let mut span = gathered.take().expect("a report interval has a step");
        span.radius = (Interval::point(span.radius) + Interval::point(r_over)).hi();
        let (c, sigma) = std::mem::replace(&mut rates, (f64::NEG_INFINITY, f64::NEG_INFINITY));
        let previous = steps.last().map_or(0.0, |st: &Step| st.t);
        let margins = checks_over(Interval::new(previous, piece.t1))
            .iter()
            .map(|check| check.margin_of_span(&span, &context))
            .collect();
        steps.push(Step {
            t: piece.t1,
            prs_radius: (Interval::point(end.radius()) + Interval::point(r_end)).hi(),
            margins,
            det: end,
            r_t: r_end,
            r_pointwise,
            r_span: r_over,
            psi,
            c,
            sigma,
            span,
        });
    }
    let (unsafe_sets, verdict) = verdicts(run.info, &setup.checks, &steps, swept);
    let mut rigorous = header.rigorous;
    if radii.gaussian.is_some() {
        rigorous.push(Proved::ExactGaussian);
    }
    match radii.uniform {
        Some((UniformBound::AmgfTube, epochs)) => rigorous.push(Proved::UniformTube { epochs }),
        Some((UniformBound::Mixture, epochs)) => rigorous.push(Proved::GaussianMixture { epochs }),
        Some((UniformBound::UnionOverSteps, steps)) => {
            rigorous.push(Proved::UnionOverSteps { steps })
        }
        None => {}
    }
    let radius_rule = RuleUsed {
        gaussian: radii.gaussian,
        ..header.radius_rule
    };
    Prs {
        model: run.info.name.clone(),
        analysis: run.spec.name.clone(),
        method: header.method,
        inclusion: header.inclusion,
        delta: run.spec.delta,
        horizon: run.spec.horizon,
        step: run.spec.step,
        integrator: run.spec.integrator,
        period: run.info.time.period(),
        guarantee: run.spec.guarantee,
        internal_steps,
        states: run.info.states.clone(),
        outputs: run.spec.outputs.clone(),
        rate: header.rate,
        constants: header.constants,
        radius_rule,
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
        // (Read off the finished result by `Reach`, after any union or intersection.)
        goals: Vec::new(),
        verdict,
        validation: Validation {
            rigorous,
            not_validated: header.not_validated,
            // Local rates need no domain (the tube never leaves its regions), unless the
            // domain's constants took over.
            conditional_on_domain: run.info.has_domain
                && (run.spec.rate != Rate::Local || header.rate.global_from.is_some()),
        },
        regions: local.map(|found| found.regions).unwrap_or_default(),
        also: Vec::new(),
        role: Role::Own,
        hints: Vec::new(),
        split: Split::Off,
        pieces: Vec::new(),
    }
}

/// The rate record of a run: its kind and the range of the rates its pieces used.
pub(super) fn rate_used(rate: Rate, pieces: &[Piece], local: Option<&Found>) -> RateUsed {
    let (min_c, max_c) = pieces
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.rates.0), hi.max(p.rates.0))
        });
    RateUsed {
        rate,
        max_c,
        min_c,
        global_from: local.and_then(|found| found.global_from),
    }
}

/// The constants of a run as the result reports them, with input gain `rho`.
pub(super) fn constants_used(run: &Run, rho: f64) -> ConstantsUsed {
    let consts = run.setup.consts;
    ConstantsUsed {
        c: consts.c,
        sigma: consts.sigma,
        rho,
        provenance: consts.provenance.clone(),
        metric: consts.metric.clone(),
        metric_region: consts.metric_region,
        spread: spread(run),
    }
}

/// Upper bounds of `sqrt((P^-1)_ii)`: `B_P(r)` lies in the box `|d_i| <= r w_i`.
pub(super) fn spread(run: &Run) -> Vec<f64> {
    run.setup.p_inv_diag.iter().map(|d| d.sqrt().hi()).collect()
}

/// The span of a deterministic set widened by a P-ball of radius `r`: its box hull (the
/// centre for a ball, whose radius joins `r`).
pub(super) fn span_of(set: &DetSet, r: f64) -> Span {
    match set.box_hull() {
        Some((lo, hi)) => Span {
            lo: lo.to_vec(),
            hi: hi.to_vec(),
            radius: (Interval::point(set.ball_added()) + Interval::point(r)).hi(),
        },
        None => Span {
            lo: set.center().to_vec(),
            hi: set.center().to_vec(),
            radius: (Interval::point(set.radius()) + Interval::point(r)).hi(),
        },
    }
}

impl Span {
    /// The smallest span holding both (hull of the boxes, the larger radius).
    pub(crate) fn hull(&self, other: &Span) -> Span {
        Span {
            lo: self
                .lo
                .iter()
                .zip(&other.lo)
                .map(|(a, b)| a.min(*b))
                .collect(),
            hi: self
                .hi
                .iter()
                .zip(&other.hi)
                .map(|(a, b)| a.max(*b))
                .collect(),
            radius: self.radius.max(other.radius),
        }
    }
}

/// Per-set verdicts and the overall verdict from the per-step margins.
/// `swept`: per set, where a moving set was held still on each report interval (empty for a
/// fixed set).
pub(super) fn verdicts(
    info: &ModelInfo,
    checks: &[Check],
    steps: &[Step],
    swept: Vec<Vec<UnsafeShape>>,
) -> (Vec<UnsafeVerdict>, Verdict) {
    let mut verdicts = Vec::with_capacity(checks.len());
    // (step, set index) of the earliest failure; ties at the same step go to the first set.
    let mut first: Option<(usize, usize)> = None;
    let sets = info.unsafe_sets.iter().zip(checks).zip(swept);
    for (j, ((set, check), swept)) in sets.enumerate() {
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
            swept,
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
