//! The contraction-based deterministic part (Proposition 2): `Rbar_t = B_P(p_t, R_t)`, a P-ball
//! around a nominal curve `p_t`, with `R' = c R + rho r2 + |d|_P` (`d` the nominal's defect,
//! zero for an exact solution): on validated steps by default (`defect.rs`), or one
//! unvalidated RK4 or Euler step per report step when the spec asks for it.

use super::assemble::{
    assemble_with, constants_used, rate_used, Deterministic, Header, Piece, Radii,
};
use super::defect::{Nominal, NominalStep};
use super::embedding::Budget;
use super::intersect::cut_by;
use super::radius::expm1_over;
use super::{
    first_order, hints, interval, local, nominal, r1, radius, rates, Detail, Problem, Run,
    RunError, Setting,
};
use crate::interval::Interval;
use crate::model::{Integrator, Method, Rate};
use crate::prs::{DetSet, Proved, Prs, Role, Span, Unproved};

/// The largest model whose contraction runs also compute the interval box (method.md 8.7):
/// the embedding evaluates `2 n` faces per step, beyond this it costs far more than the ball.
pub const MAX_BOX_STATES: usize = 100;

/// The most internal steps the interval box of a contraction run may take per report interval,
/// on average (method.md 8.7): it is an extra cut of the ball, not worth many times the ball's
/// own cost. (The shipped specs' boxes take at most 59.)
const BOX_STEPS_PER_REPORT: usize = 256;

/// The shortest step of that box that accuracy alone may ask for, as a fraction of the report
/// step: a box of no width (a point start) keeps the accuracy target out of reach, and the
/// analysis' own boxes then go down to `2^-12` of it (4096 steps per report interval, 110 s
/// spent on `specs/unicycle_lookahead.sde` before the box was dropped for its budget); so does
/// a contracting model's box over a long horizon (it shrinks faster than validation's padding).
const BOX_ACCURACY_STEPS: usize = 16;

/// The fewest report intervals for which a run with local rates first certifies them on the
/// first interval alone (the pilot costs one interval's nominal and rates again: at most a
/// sixteenth of the run).
const PILOT_INTERVALS: usize = 16;

/// The contraction PRS of a run.
pub(super) fn run(run: &Run) -> Result<Prs, RunError> {
    let (spec, consts, n) = (run.spec, run.setup.consts, run.setup.n);
    let metric = &consts.metric;

    // Initial set and inputs.
    let (x0, half) = radius::initial_center_and_halfwidths(run.initial, n)
        .map_err(|e| RunError::Invalid(Problem::InitialSet(e).into()))?;
    let (r1, r1_bound) = r1::bound(metric, run.initial, &half);
    let grid = nominal::time_grid(spec.horizon, spec.step);
    let (inputs, r2) = run.nominal_inputs(&grid);
    let rho = if run.setup.p == 0 { 0.0 } else { consts.rho };
    let (kappa, radius_rule) = radius::stochastic_factor(n, spec);

    // Local rates that cannot be certified on the first report interval stop the run there,
    // before the nominal is integrated over the whole horizon (a stiff or blowing-up model
    // spent seconds on it first): the first pass of `local::passes` on the first interval, the
    // same steps and regions as the whole run's first pass begins with.
    if spec.rate == Rate::Local && grid.len() > PILOT_INTERVALS {
        let pilot = nominal_steps(run, &x0, r1, &grid[..2], &inputs[..1])?;
        local::pilot(run, |stepper| {
            local_pass(stepper, &pilot, &grid[..2], r1, r2)
        })?;
    }

    // The nominal on its internal steps, each with its report interval.
    let steps = nominal_steps(run, &x0, r1, &grid, &inputs)?;
    let validated = spec.integrator == Integrator::Validated;

    // The rates on each step: certified per step on the tube (local), the compiler's
    // constant, or estimated per report interval (empirical).
    let (pieces, local) = match spec.rate {
        Rate::Local => {
            let local = local::passes(run, |stepper| local_pass(stepper, &steps, &grid, r1, r2))?;
            let found = local::Found::of(&local);
            (local.result, Some(found))
        }
        Rate::Global => (
            along(&steps, &grid, r1, r2, |_, _, _, _| {
                Ok((consts.c, consts.sigma, rho))
            })?,
            None,
        ),
        Rate::Empirical { paths } => {
            let mut traj = vec![x0.clone()];
            traj.extend(
                steps
                    .iter()
                    .filter(|(s, k)| s.t1 == grid[k + 1])
                    .map(|(s, _)| s.x1.clone()),
            );
            let c = rates::empirical(run, metric, &grid, &traj, &inputs, paths)?;
            (
                along(&steps, &grid, r1, r2, |_, k, _, _| {
                    Ok((c[k + 1], consts.sigma, rho))
                })?,
                None,
            )
        }
    };
    let internal = pieces.len();
    let det = Deterministic {
        start: initial_set(run, &x0, r1),
        pieces,
        frame: None,
        tube: local.as_ref().map(|found| found.tube.clone()),
    };
    let mut rigorous = vec![match spec.rate {
        Rate::Local => Proved::LocalRates {
            regions: internal,
            metric: consts.metric_region,
        },
        rate => Proved::Constants {
            c: rate == Rate::Global,
            rho: true,
            provenance: consts.provenance.clone(),
        },
    }];
    let mut not_validated = Vec::new();
    if validated {
        rigorous.push(Proved::ValidatedNominal {
            steps: internal,
            ros2: steps.iter().filter(|(s, _)| s.ros2).count(),
        });
    } else {
        not_validated.push(Unproved::Nominal {
            integrator: spec.integrator,
            step: spec.step,
        });
    }
    if let Rate::Empirical { paths } = spec.rate {
        not_validated.insert(0, Unproved::EmpiricalRate { paths });
    }
    rigorous.extend([
        Proved::Kappa,
        Proved::Psi,
        Proved::Radii,
        Proved::Margins {
            given: Method::Contraction,
        },
    ]);
    let header = Header {
        method: Method::Contraction,
        inclusion: None,
        rate: rate_used(spec.rate, &det.pieces, local.as_ref()),
        constants: constants_used(run, rho),
        radius_rule,
        kappa,
        r1,
        r2,
        r1_bound,
        transform: None,
        initial_center: x0,
        input_center: inputs.first().cloned().unwrap_or_default(),
        rigorous,
        not_validated,
    };
    // The first-order sets (method.md 8.8), on the same nominal, with the same radii.
    let first = validated
        .then(|| {
            first_order::deterministic(
                run,
                &steps,
                &header.initial_center,
                &grid,
                &inputs,
                r2,
                first_order::Linearised::member(run.gaussian),
            )
        })
        .flatten();
    // The interval method's boxes of the same run, when they cut the ball somewhere
    // (method.md section 8.7): both sets hold the noise-free solutions, so the same stochastic
    // radii widen both and the PRS is their intersection at the same delta.
    // (Validated runs only: the box must not add an unproved step.)
    // (Within BOX_STEPS_PER_REPORT: where the embedding needs far more, the ball alone is the
    // result.)
    // (Only where the first-order sets do not keep their shape: where they do, they hold the
    // flow far tighter than a box, which then costs most of the run for nothing.)
    let box_wanted = first.as_ref().is_none_or(|f| !f.keeps_shape());
    let boxes = (validated && n <= MAX_BOX_STATES && box_wanted)
        .then(|| {
            let budget = Budget::helper(
                grid.len().saturating_sub(1),
                BOX_STEPS_PER_REPORT,
                BOX_ACCURACY_STEPS,
            );
            interval::deterministic(run, spec.inclusion, budget).ok()
        })
        .flatten();
    let radii = Radii::new(run, &det, header.kappa);
    let rate = header.rate;
    let rates_proved = header.rigorous[0].clone();
    let first_header = header.clone();
    let ball = assemble_with(run, det, header, local, radii.clone());
    let mut members = Vec::new();
    if let Some((det, mut header)) = boxes {
        header.rate = rate;
        header.rigorous[0] = rates_proved;
        members.push(assemble_with(run, det, header, None, radii.clone()).with_role(Role::Box));
    }
    let offered = first.map(|first| first_order::members(run, first, first_header, radii));
    let hint = hints::first_order(run, offered.as_deref());
    members.extend(offered.unwrap_or_default());
    let mut prs = cut_by(run, ball, members);
    prs.hints.extend(hint);
    Ok(prs)
}

/// One pass of the local rates along the nominal's `steps` (see [`local::passes`]): the pieces
/// and the index of the first report time.
fn local_pass(
    stepper: &mut local::Stepper,
    steps: &[(NominalStep, usize)],
    grid: &[f64],
    r1: f64,
    r2: f64,
) -> Result<(Vec<Piece>, usize), RunError> {
    let pieces = along(steps, grid, r1, r2, |step, _, t0, r| {
        let h = Interval::point(step.t1) - Interval::point(t0);
        let rates = stepper.step(&step.lo, &step.hi, (t0, step.t1), |q| {
            let next = advance(r, (q.c, q.rho), r2, step.defect, h);
            r.hi().max(next.hi())
        })?;
        Ok((rates.c, rates.sigma, rates.rho))
    })?;
    let first = pieces.iter().position(|p| p.end.is_some()).unwrap_or(0) + 1;
    Ok((pieces, first))
}

/// The pieces along the nominal's steps, `R` following `R' = c R + rho r2 + |d|_P` with the
/// rates `rates(step, report interval, t0, R at t0)` gives for each step (`c`, `sigma`, `rho`).
fn along(
    steps: &[(NominalStep, usize)],
    grid: &[f64],
    r1: f64,
    r2: f64,
    mut rates: impl FnMut(&NominalStep, usize, f64, Interval) -> Result<(f64, f64, f64), RunError>,
) -> Result<Vec<Piece>, RunError> {
    let mut r = Interval::point(r1);
    let mut t0 = 0.0;
    let mut pieces = Vec::with_capacity(steps.len());
    for (step, k) in steps {
        let (c, sigma, rho) = rates(step, *k, t0, r)?;
        let h = Interval::point(step.t1) - Interval::point(t0);
        let r_prev = r.hi();
        r = advance(r, (c, rho), r2, step.defect, h);
        // R is monotone on the step (a linear ODE with constant forcing): its largest value
        // is at one end.
        pieces.push(Piece {
            t1: step.t1,
            rates: (c, sigma),
            over: Span {
                lo: step.lo.clone(),
                hi: step.hi.clone(),
                radius: r_prev.max(r.hi()),
            },
            end: (step.t1 == grid[k + 1]).then(|| DetSet::Ball {
                center: step.x1.clone(),
                radius: r.hi(),
            }),
        });
        t0 = step.t1;
    }
    Ok(pieces)
}

/// `R` after a step of length `h` from `r`: `R' = c R + rho r2 + defect` (upper bound).
fn advance(r: Interval, (c, rho): (f64, f64), r2: f64, defect: f64, h: Interval) -> Interval {
    if !c.is_finite() {
        return Interval::point(f64::INFINITY);
    }
    let forcing = Interval::point(rho) * Interval::point(r2) + Interval::point(defect);
    Interval::point((r * (Interval::point(c) * h).exp() + forcing * expm1_over(c, h)).hi())
}

/// The nominal's steps with their report interval: validated internal steps, or one step of
/// the unvalidated integrator per report step (defect taken as 0, labelled so).
pub(super) fn nominal_steps(
    run: &Run,
    x0: &[f64],
    r1: f64,
    grid: &[f64],
    inputs: &[Vec<f64>],
) -> Result<Vec<(NominalStep, usize)>, RunError> {
    let spec = run.spec;
    if spec.integrator == Integrator::Validated {
        let consts = run.setup.consts;
        // The defect may add about 1% of the PRS's natural size (the initial radius, the
        // stochastic radius sqrt(sigma^2 T kappa), or what the input adds, rho r2 T) over the
        // horizon, or a floor at the nominal's floating point for a spec without any of them
        // (method.md section 8.4).
        let (kappa, _) = radius::stochastic_factor(run.setup.n, spec);
        let sigma = if consts.sigma.is_finite() {
            consts.sigma
        } else {
            noise_scale(run, x0)
        };
        // (rho r2 is 0 without inputs or with a known input plan; an unbounded global rho,
        // left to the local rates, sets no scale.)
        let input = run.input_radius() * consts.rho * spec.horizon;
        let scale = r1
            .max(sigma * (spec.horizon * kappa).sqrt())
            .max(if input.is_finite() { input } else { 0.0 });
        let tolerance =
            (1e-2 * scale).max(floor(&consts.metric, x0)) / spec.horizon.max(f64::MIN_POSITIVE);
        // Local rates need no domain (the regions follow the tube).
        let domain =
            (run.info.has_domain && spec.rate != Rate::Local).then_some(&run.info.domain[..]);
        return Nominal::new(run.sys, &consts.metric, tolerance, domain).steps(x0, grid, inputs);
    }
    let traj = nominal::integrate(run.sys, x0, inputs, grid, spec.integrator).map_err(|k| {
        RunError::NonFinite(
            Detail::from(Problem::NominalNotFinite {
                t: grid[k],
                integrator: spec.integrator,
                step: spec.step,
            })
            .at_setting(Setting::Integrator),
        )
    })?;
    Ok(traj
        .windows(2)
        .enumerate()
        .map(|(k, w)| {
            let lo = w[0].iter().zip(&w[1]).map(|(a, b)| a.min(*b)).collect();
            let hi = w[0].iter().zip(&w[1]).map(|(a, b)| a.max(*b)).collect();
            (
                NominalStep {
                    t1: grid[k + 1],
                    x1: w[1].clone(),
                    defect: 0.0,
                    ros2: false,
                    lo,
                    hi,
                },
                k,
            )
        })
        .collect())
}

/// The smallest defect integral the nominal is asked for: `1e-9 max(1, |x0|_inf)` in the
/// heaviest coordinate of the metric `p`, `sqrt(max_i P_ii)` times that (a relative error
/// of `1e-9` in the state, a thousand times what RK4's cubic can be validated to in double
/// precision near such steps; without it a spec with no uncertainty asked for `1e-11` and
/// stopped, the rounding of `p'` growing like `1 / h` as the steps shrank).
fn floor(p: &[f64], x0: &[f64]) -> f64 {
    let n = x0.len();
    let heaviest = (0..n).map(|i| p[i * n + i]).fold(0.0f64, f64::max);
    1e-9 * x0.iter().fold(1.0f64, |m, v| m.max(v.abs())) * heaviest.sqrt()
}

/// A noise level for accuracy targets when the compiler could not bound `sigma`:
/// `sqrt(trace(P G G'))` at the initial centre and `t = 0` (at least `|P^(1/2) G|_2` there).
fn noise_scale(run: &Run, x0: &[f64]) -> f64 {
    let (n, m) = (run.setup.n, run.sys.m());
    let metric = &run.setup.consts.metric;
    let mut g = vec![0.0; n * m];
    run.sys.diffusion(x0, 0.0, &mut g);
    let mut trace = 0.0;
    for l in 0..m {
        for i in 0..n {
            for j in 0..n {
                trace += metric[i * n + j] * g[i * m + l] * g[j * m + l];
            }
        }
    }
    trace.max(0.0).sqrt()
}

/// `Rbar_0`: the initial set itself where it is a box (inside the ball `B_P(x0, r1)`, which
/// is all the contraction method propagates), else that ball. Every over-approximation of the
/// deterministic set is sound, so the smaller one is reported and checked at `t = 0`.
pub(super) fn initial_set(run: &Run, x0: &[f64], r1: f64) -> DetSet {
    match run.initial.bounding_box() {
        Ok(b) if run.initial.balls.is_empty() => DetSet::Box {
            lo: b.iter().map(|x| x.lo).collect(),
            hi: b.iter().map(|x| x.hi).collect(),
            center: x0.to_vec(),
            radius: r1,
        },
        _ => DetSet::Ball {
            center: x0.to_vec(),
            radius: r1,
        },
    }
}
