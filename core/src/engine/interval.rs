//! The interval-based delta-PRS (Proposition 3 with Theorem 2; method.md, section 6).
//!
//! The deterministic reachable set `Rbar_t` is a box `[x_lo, x_hi]`, the state of the
//! *embedding system*: with an inclusion function `F = [F_lo, F_hi]` of the drift
//! (`F_lo(box, ubox, t) <= f(x, u, t) <= F_hi(box, ubox, t)` for all `x` in the box, `u` in the
//! input box), evaluated on the faces of the box,
//!
//! ```text
//! x_lo_i' = F_lo_i([x_lo, x_hi] with x_i pinned to x_lo_i, U, t)
//! x_hi_i' = F_hi_i([x_lo, x_hi] with x_i pinned to x_hi_i, U, t)
//! ```
//!
//! The box of the embedding system, started from a box containing the initial set, contains
//! every deterministic trajectory with inputs in `U` (the classic mixed-monotone / face-pinned
//! argument). The PRS at time `t` is `[x_lo, x_hi] (+) B_P(r_t)` with the same stochastic radius
//! `r_t = sqrt(Psi_t kappa(n, delta))` as the contraction engine (c, sigma in the metric P of
//! the analysis' constants).
//!
//! Inclusion functions ([`Inclusion`]): the natural one (`System::drift_interval`), the
//! Jacobian-based one (mean-value form around the centre of the pinned box; the default) and the
//! mixed one. With a coordinate transform `y = T x` the embedding runs on the transformed
//! system (`System::frame`) and the set in `x` is the parallelotope `T^-1 box`.
//!
//! What is rigorous: the inclusion functions (outward-rounded interval arithmetic), kappa,
//! `Psi_t`, `r_t`, the safety margins given the box. What is not: the embedding ODE is
//! integrated numerically (RK4 or Euler, no remainder bound), so the box is an enclosure only
//! up to the time-discretisation error. The result says so.

use super::assemble::{
    assemble_with, constants_used, rate_used, Deterministic, Header, Piece, Radii,
};
use super::embedding::{BoxStep, Budget, Embedding};
use super::intersect::cut_by;
use super::{
    contraction, first_order, hints, local, memo, nominal, r1, radius, validate, Detail, Problem,
    Run, RunError, Setting,
};
use crate::interval::Interval;
use crate::model::{AnalysisSpec, Inclusion, InitialSet, Integrator, Method, ModelInfo, Rate};
use crate::prs::{DetSet, Proved, Prs, R1Bound, Span, Unproved};
use crate::sets::parallelotope::Frame;
use crate::system::System;

/// The interval PRS of a run with the given inclusion function.
pub(super) fn run(run: &Run, inclusion: Inclusion) -> Result<Prs, RunError> {
    let (mut det, mut header) = deterministic(run, inclusion, Budget::FULL)?;
    // Local rates: certified per step on the box widened by the tube.
    let local = if run.spec.rate == Rate::Local {
        let pieces = &mut det.pieces;
        let local = local::passes(run, |stepper| {
            let mut t0 = 0.0;
            let mut rates = Vec::with_capacity(pieces.len());
            for p in pieces.iter() {
                let r = stepper.step(&p.over.lo, &p.over.hi, (t0, p.t1), |_| p.over.radius)?;
                rates.push((r.c, r.sigma));
                t0 = p.t1;
            }
            let first = pieces.iter().position(|p| p.end.is_some()).unwrap_or(0) + 1;
            Ok((rates, first))
        })?;
        for (p, &r) in pieces.iter_mut().zip(&local.result) {
            p.rates = r;
        }
        let found = local::Found::of(&local);
        det.tube = Some(found.tube.clone());
        header.rate = rate_used(run.spec.rate, &det.pieces, Some(&found));
        Some(found)
    } else {
        None
    };
    // The first-order sets on the validated nominal (method.md 8.8), with the same radii.
    let first = first_order::wanted(run)
        .then(|| first_order_of(run, header.r1, &header.initial_center))
        .flatten();
    let radii = Radii::new(run, &det, header.kappa);
    let first_header = header.clone();
    let prs = assemble_with(run, det, header, local, radii.clone());
    let offered = first.map(|first| first_order::members(run, first, first_header, radii));
    let hint = hints::first_order(run, offered.as_deref());
    // Hints on what the user gets: the intersection (a box that wraps is no news where the
    // first-order set keeps the result tight).
    let mut prs = cut_by(run, prs, offered.unwrap_or_default());
    prs.hints = hints::interval(run, &prs);
    prs.hints.extend(hint);
    Ok(prs)
}

/// The first-order sets of an interval run: the validated nominal from the initial set's
/// centre `x0` (the contraction method's, `r1` setting its accuracy), then
/// [`first_order::deterministic`]; `None` where either cannot be computed.
fn first_order_of(run: &Run, r1: f64, x0: &[f64]) -> Option<first_order::FirstOrder> {
    let grid = nominal::time_grid(run.spec.horizon, run.spec.step);
    let (inputs, r2) = run.nominal_inputs(&grid);
    let steps = contraction::nominal_steps(run, x0, r1, &grid, &inputs).ok()?;
    first_order::deterministic(
        run,
        &steps,
        x0,
        &grid,
        &inputs,
        r2,
        first_order::Linearised::member(run.gaussian),
    )
}

/// The deterministic part of an interval run (the embedding's boxes on its steps, with the
/// compiler's constant rates) and what its result says besides the sets.
pub(super) fn deterministic(
    run: &Run,
    inclusion: Inclusion,
    budget: Budget,
) -> Result<(Deterministic, Header), RunError> {
    let (spec, consts, n) = (run.spec, run.setup.consts, run.setup.n);
    let metric = &consts.metric;
    let grid = nominal::time_grid(spec.horizon, spec.step);
    let (inputs, _) = run.nominal_inputs(&grid);
    let input_boxes = run_inputs(run, &inputs);
    let key = memo::Key::new(spec, run.initial, &input_boxes, inclusion, budget);
    let held = run.memo.get_or(key, || {
        let computed = boxes(
            run.sys,
            run.info,
            spec,
            run.initial,
            &grid,
            &input_boxes,
            (inclusion, budget),
        );
        let size = computed.as_ref().map_or(0, Boxes::size);
        (computed, size)
    });
    let Boxes {
        frame,
        start,
        steps,
        x0,
        half0,
    } = Result::clone(&held)?;
    let (r1, r1_bound) = r1::bound(metric, run.initial, &half0);
    let (kappa, radius_rule) = radius::stochastic_factor(n, spec);
    let box_radius = radius::BoxRadius::new(metric, n);
    // The set in x of a box of the embedding: the box itself, or the parallelotope T^-1 box
    // with its hull.
    let x_box = |lo: &[f64], hi: &[f64]| match &frame {
        Some(f) => f.x_hull(lo, hi),
        None => (lo.to_vec(), hi.to_vec()),
    };
    let det_set = |(blo, bhi): (Vec<f64>, Vec<f64>)| {
        let (xlo, xhi) = x_box(&blo, &bhi);
        let ivs: Vec<Interval> = xlo
            .iter()
            .zip(&xhi)
            .map(|(&a, &b)| Interval::new(a, b))
            .collect();
        let center: Vec<f64> = ivs.iter().map(|iv| iv.mid()).collect();
        let half: Vec<f64> = ivs.iter().map(|iv| iv.rad()).collect();
        // The box lies in B_P(center, radius): an enclosing P-ball, so the step's PRS radius is
        // that of a P-ball containing the PRS (coarser than the PRS itself).
        let radius = box_radius.bound(&half);
        match frame {
            Some(_) => DetSet::Parallelotope {
                lo: blo,
                hi: bhi,
                hull_lo: xlo,
                hull_hi: xhi,
                center,
                radius,
            },
            None => DetSet::Box {
                lo: xlo,
                hi: xhi,
                center,
                radius,
            },
        }
    };
    let internal = steps.len();
    let pieces: Vec<Piece> = steps
        .into_iter()
        .map(|step| {
            let (lo, hi) = x_box(&step.over_lo, &step.over_hi);
            Piece {
                t1: step.t1,
                rates: (consts.c, consts.sigma),
                over: Span {
                    lo,
                    hi,
                    radius: 0.0,
                },
                end: (step.t1 == grid[step.interval + 1]).then(|| det_set((step.lo, step.hi))),
            }
        })
        .collect();
    let transform = frame.as_ref().map(Frame::used);
    let validated = spec.integrator == Integrator::Validated;
    let mut rigorous = vec![
        match spec.rate {
            Rate::Local => Proved::LocalRates {
                regions: internal,
                metric: consts.metric_region,
            },
            _ => Proved::Constants {
                c: true,
                rho: false,
                provenance: consts.provenance.clone(),
            },
        },
        Proved::Inclusion(inclusion),
    ];
    let mut not_validated = Vec::new();
    if validated {
        rigorous.push(Proved::ValidatedEmbedding { steps: internal });
    } else {
        not_validated.push(Unproved::Embedding {
            integrator: spec.integrator,
            step: spec.step,
        });
    }
    rigorous.extend([
        Proved::Kappa,
        Proved::Psi,
        Proved::StochasticRadius,
        Proved::Margins {
            given: Method::Interval,
        },
    ]);
    if let Some(tr) = &transform {
        rigorous.push(Proved::TransformMaps {
            inverse_error: tr.inverse_error,
        });
    }
    let det = Deterministic {
        start: det_set(start),
        pieces,
        frame,
        tube: None,
    };
    let header = Header {
        method: Method::Interval,
        inclusion: Some(inclusion),
        rate: rate_used(spec.rate, &det.pieces, None),
        constants: constants_used(run, consts.rho),
        radius_rule,
        kappa,
        r1,
        r2: 0.0,
        r1_bound: R1Bound {
            reported_only: true,
            ..r1_bound
        },
        transform,
        initial_center: x0,
        input_center: inputs.first().cloned().unwrap_or_default(),
        rigorous,
        not_validated,
    };
    Ok((det, header))
}

/// The input box of each report step: the model's box, or the plan's point.
fn run_inputs(run: &Run, nominal: &[Vec<f64>]) -> Vec<Vec<Interval>> {
    match run.inputs {
        super::Inputs::Box => {
            vec![super::input_intervals(run.info); nominal.len()]
        }
        super::Inputs::Plan(_) => nominal
            .iter()
            .map(|u| u.iter().map(|&v| Interval::point(v)).collect())
            .collect(),
    }
}

/// The embedding system's boxes on its steps (in `y = T x` with a transform).
#[derive(Clone)]
pub(crate) struct Boxes {
    /// The transform, if any.
    frame: Option<Frame>,
    /// The initial box `(lo, hi)`.
    start: (Vec<f64>, Vec<f64>),
    /// The steps.
    steps: Vec<BoxStep>,
    /// Centre and half-widths of the initial box in `x`.
    x0: Vec<f64>,
    half0: Vec<f64>,
}

impl Boxes {
    /// The numbers it holds (for the memo's capacity).
    fn size(&self) -> usize {
        (self.steps.len() + 1) * 6 * self.x0.len()
    }
}

/// The boxes of the embedding system with the given inclusion function, inputs in `inputs[k]`
/// on report interval `k`: from the initial box (balls replaced by their bounding boxes), or
/// with a transform from the interval hull of `T X0`; on validated steps, or one step of the
/// (unvalidated) integrator per report step when the spec asks for it.
fn boxes(
    sys: &dyn System,
    info: &ModelInfo,
    spec: &AnalysisSpec,
    initial: &InitialSet,
    grid: &[f64],
    inputs: &[Vec<Interval>],
    (inclusion, budget): (Inclusion, Budget),
) -> Result<Boxes, RunError> {
    let (n, p) = (sys.n(), sys.p());
    validate(info, spec, n, p)?;
    // With a transform, the embedding runs on the transformed system of the frame.
    let (frame, emb_sys) = match &spec.transform {
        None => (None, sys),
        Some(tr) => {
            let f = Frame::new(tr, n)?;
            let fsys = sys.frame(tr.frame).ok_or_else(|| {
                RunError::Unsupported(
                    Detail::from(Problem::NoFrame {
                        analysis: spec.name.clone(),
                        frame: tr.frame,
                    })
                    .at_setting(Setting::Transform),
                )
            })?;
            if (fsys.n(), fsys.p()) != (n, p) {
                return Err(RunError::Invalid(
                    Detail::from(Problem::FrameSize {
                        frame: tr.frame,
                        states: fsys.n(),
                        inputs: fsys.p(),
                        n,
                        p,
                    })
                    .at_setting(Setting::Transform),
                ));
            }
            (Some(f), fsys)
        }
    };
    let (x0, half0) = radius::initial_center_and_halfwidths(initial, n)
        .map_err(|e| RunError::Invalid(Problem::InitialSet(e).into()))?;
    let (mut lo, mut hi): (Vec<f64>, Vec<f64>) = (0..n)
        .map(|i| match initial.boxes[i] {
            Some(b) => (b.lo, b.hi),
            None => {
                let (c, h) = (Interval::point(x0[i]), Interval::point(half0[i]));
                ((c - h).lo(), (c + h).hi())
            }
        })
        .unzip();
    // The initial box in y: the interval hull of T X0 (computed, whatever the spec says).
    if let Some(f) = &frame {
        (lo, hi) = f.to_y(&lo, &hi);
    }
    let mut embedding = Embedding::new(emb_sys, inclusion);
    let steps = if spec.integrator == Integrator::Validated {
        // Validation may add about 1% to each box over the horizon.
        embedding.validated(
            &lo,
            &hi,
            grid,
            inputs,
            1e-2 / spec.horizon.max(f64::MIN_POSITIVE),
            budget,
        )?
    } else {
        embedding
            .integrate(&lo, &hi, grid, inputs, spec.integrator)
            .map_err(|k| {
                RunError::NonFinite(
                    Detail::from(Problem::EmbeddingNotFinite {
                        t: grid[k],
                        inclusion,
                        integrator: spec.integrator,
                        step: spec.step,
                    })
                    .at_setting(Setting::Integrator),
                )
            })?
    };
    Ok(Boxes {
        frame,
        start: (lo, hi),
        steps,
        x0,
        half0,
    })
}

/// The deterministic reachable boxes of an interval analysis without the stochastic part (no
/// constants needed): per report time `(t, lo, hi)`, in the coordinates `y = T x` when the
/// analysis has a transform. The boxes enclose every deterministic trajectory from the model's
/// initial set with inputs in the input box (on validated steps; with `integrator = rk4` or
/// `euler`, up to the time discretisation).
#[allow(clippy::type_complexity)]
pub fn interval_boxes(
    sys: &dyn System,
    info: &ModelInfo,
    spec: &AnalysisSpec,
) -> Result<Vec<(f64, Vec<f64>, Vec<f64>)>, RunError> {
    let grid = nominal::time_grid(spec.horizon, spec.step);
    let ubox: Vec<Interval> = info
        .input_box
        .iter()
        .map(|b| Interval::new(b.lo, b.hi))
        .collect();
    let inputs = vec![ubox; grid.len()];
    let d = boxes(
        sys,
        info,
        spec,
        &info.initial,
        &grid,
        &inputs,
        (spec.inclusion, Budget::FULL),
    )?;
    let mut out = vec![(0.0, d.start.0, d.start.1)];
    out.extend(
        d.steps
            .into_iter()
            .filter(|s| s.t1 == grid[s.interval + 1])
            .map(|s| (s.t1, s.lo, s.hi)),
    );
    Ok(out)
}
