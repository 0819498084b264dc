//! The interval-based delta-PRS (Proposition 4 with Theorem 2; method.md, section 6).
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
//! Inclusion functions ([`Inclusion`]): the natural one (`System::drift_interval`) and the
//! Jacobian-based one (mean-value form around the centre of the pinned box), the default.
//! Coordinate transforms are not supported yet: an analysis with a transform is refused.
//!
//! What is rigorous: the inclusion functions (outward-rounded interval arithmetic), kappa,
//! `Psi_t`, `r_t`, the safety margins given the box. What is not: the embedding ODE is
//! integrated numerically (RK4 or Euler, no remainder bound), so the box is an enclosure only
//! up to the time-discretisation error. The result says so.

use super::embedding::Embedding;
use super::result::{AnalysisResult, ConstantsReport, DetSet, StepRecord, Validation};
use super::{integrator_name, nominal, radius, safety, transform, verdicts, RunError};
use crate::interval::Interval;
use crate::system::{Analysis, Inclusion, ModelInfo, Rate, System};

/// Runs an interval-method analysis with the given inclusion function.
///
/// [`super::run`] calls this with the analysis' own inclusion. Needs the constants `c`, `sigma`
/// and the metric `P` for the stochastic radius ([`RunError::NoConstants`] otherwise); an
/// analysis with a coordinate transform needs the system's transformed frame
/// ([`RunError::Unsupported`] otherwise). [`reach`] gives the boxes alone.
pub fn run_interval(
    sys: &dyn System,
    info: &ModelInfo,
    analysis: &Analysis,
    inclusion: Inclusion,
) -> Result<AnalysisResult, RunError> {
    let super::Setup {
        consts,
        n,
        chol,
        p_inv_diag,
        ..
    } = super::setup(sys, info, analysis, &["c", "sigma"])?;
    let metric = &consts.metric;
    let Deterministic {
        frame,
        grid,
        boxes,
        x0,
        half0,
    } = deterministic(sys, info, analysis, inclusion)?;
    // Upper bounds of sqrt((P^-1)_ii): B_P(r) lies in the box |d_i| <= r w_i.
    let w: Vec<f64> = p_inv_diag.iter().map(|d| d.sqrt().hi()).collect();
    let r1 = radius::r1_bound(metric, &half0);
    let r1_how = String::from(
        "P-radius of the initial box around its centre (reported only: the interval method \
         propagates the box itself)",
    ) + if info.initial.balls.is_empty() {
        ""
    } else {
        "; initial balls replaced by their bounding boxes (conservative)"
    };
    let u_center: Vec<f64> = info
        .input_box
        .iter()
        .map(|&(a, b)| Interval::new(a, b).mid())
        .collect();
    let (kappa, radius_rule) = radius::stochastic_factor(n, analysis);

    let checks =
        safety::Check::all(&info.unsafe_sets, n, &chol, &p_inv_diag).map_err(RunError::Invalid)?;

    let box_radius = radius::BoxRadius::new(metric, n);
    let mut stochastic = radius::Stochastic::new(kappa);
    let mut steps = Vec::with_capacity(grid.len());
    for (k, (&t, (blo, bhi))) in grid.iter().zip(boxes).enumerate() {
        let (c_k, sigma_k) = (consts.c, consts.sigma);
        let prev = k.checked_sub(1).map(|j| grid[j]);
        let (psi_hi, r_t) = stochastic.advance(prev, t, c_k, sigma_k);
        // The set in x: the box itself, or the parallelotope T^-1 box with its hull.
        let (xlo, xhi) = match &frame {
            Some((f, _)) => f.x_hull(&blo, &bhi),
            None => (blo.clone(), bhi.clone()),
        };
        let ivs: Vec<Interval> = xlo
            .iter()
            .zip(&xhi)
            .map(|(&a, &b)| Interval::new(a, b))
            .collect();
        let center: Vec<f64> = ivs.iter().map(|iv| iv.mid()).collect();
        let half: Vec<f64> = ivs.iter().map(|iv| iv.rad()).collect();
        // The box lies in B_P(center, det): an enclosing P-ball, so `prs_radius` is the radius
        // of a P-ball containing the PRS (coarser than the PRS itself).
        let det = box_radius.bound(&half);
        let prs = (Interval::point(det) + Interval::point(r_t)).hi();
        let margins = checks
            .iter()
            .map(|c| {
                // A half-space has an exact support function on the parallelotope.
                let support = match (c, &frame) {
                    (safety::Check::HalfSpace { normal, .. }, Some((f, _))) => {
                        Some(f.support(normal, &blo, &bhi))
                    }
                    _ => None,
                };
                box_margin(c, &xlo, &xhi, r_t, &w, support)
            })
            .collect();
        let (shape, hull_lo, hull_hi) = if frame.is_some() {
            ("parallelotope", Some(xlo), Some(xhi))
        } else {
            ("box", None, None)
        };
        steps.push(StepRecord {
            t,
            det_set: DetSet {
                shape,
                center: center.clone(),
                radius: det,
                metric: "constants.metric",
                lo: Some(blo),
                hi: Some(bhi),
                hull_lo,
                hull_hi,
            },
            nominal: center,
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
        "time discretisation of the embedding system (numerical {} integration, step {}, no \
         remainder bound): the box encloses the deterministic reachable set only up to the \
         integration error",
        integrator_name(analysis.integrator),
        analysis.step
    )];
    let mut rigorous = vec![
        format!("constants c, sigma ({})", consts.how),
        format!(
            "{} inclusion function of the drift on each face (outward-rounded interval \
             arithmetic)",
            inclusion.name()
        ),
        "kappa (rounded up)".into(),
        "Psi_t (exact per-step integration in interval arithmetic, upper end)".into(),
        "r_t (interval arithmetic, rounded up)".into(),
        "safety margins given the box (P^-1 enclosed by interval Cholesky, rounded down)".into(),
    ];
    if let Some((f, _)) = &frame {
        let e = f.report().inverse_error;
        rigorous.push(format!(
            "the initial box in y = T x (interval hull of T X0) and the map back to x (T^-1 \
             enclosed entry-wise within {e:.1e} of the floating-point inverse)"
        ));
        not_validated.push(
            "the transformed drift T f(T^-1 y) is formed symbolically with T^-1 and the \
             combined coefficients rounded to floating point (relative errors ~1e-16, not \
             bounded; far below the integration error)"
                .into(),
        );
    }
    if info.has_domain {
        not_validated.push(
            "conditional on staying in the domain: the constants hold only there, and the \
             result assumes the state does not leave it"
                .into(),
        );
    }
    Ok(AnalysisResult {
        model: info.name.clone(),
        analysis: analysis.name.clone(),
        method: "interval".into(),
        inclusion: Some(inclusion.name().into()),
        delta: analysis.delta,
        horizon: analysis.horizon,
        step: analysis.step,
        integrator: integrator_name(analysis.integrator).into(),
        states: info.states.clone(),
        outputs: analysis.outputs.clone(),
        rate: super::rate_report(Rate::Certified, None, consts.c).0,
        constants: ConstantsReport {
            c: consts.c,
            sigma: consts.sigma,
            rho: consts.rho,
            how: consts.how.clone(),
            metric: metric.chunks(n).map(|r| r.to_vec()).collect(),
        },
        radius_rule,
        kappa,
        r1,
        r2: 0.0,
        r1_how,
        transform: frame.as_ref().map(|(f, _)| f.report()),
        initial_center: x0,
        input_center: u_center,
        steps,
        unsafe_sets,
        verdict,
        validated: Validation {
            rigorous,
            not_validated,
            conditional_on_domain: info.has_domain,
        },
    })
}

/// The deterministic part of an interval analysis: the boxes of the embedding system at the
/// report times (in `y = T x` with a transform).
struct Deterministic<'a> {
    /// The transform and the transformed system, if any.
    frame: Option<(transform::Frame, &'a dyn System)>,
    /// Report times.
    grid: Vec<f64>,
    /// Per report time, the box `(lo, hi)`.
    boxes: Vec<(Vec<f64>, Vec<f64>)>,
    /// Centre and half-widths of the initial box in `x`.
    x0: Vec<f64>,
    half0: Vec<f64>,
}

/// The boxes of the embedding system of `analysis` with the given inclusion function: from the
/// initial box (balls replaced by their bounding boxes), or with a transform from the interval
/// hull of `T X0`, integrated over the report grid (not validated in time).
fn deterministic<'a>(
    sys: &'a dyn System,
    info: &ModelInfo,
    analysis: &Analysis,
    inclusion: Inclusion,
) -> Result<Deterministic<'a>, RunError> {
    let (n, p) = (sys.n(), sys.p());
    super::validate(info, analysis, n, p)?;
    // With a transform, the embedding runs on the transformed system of the frame.
    let frame = match &analysis.transform {
        None => None,
        Some(tr) => {
            let f = transform::Frame::new(tr, n)?;
            let fsys = sys.frame(tr.frame).ok_or_else(|| {
                RunError::Unsupported(format!(
                    "analysis `{}` has a coordinate transform but the system has no frame {} \
                     (code generated by an older reachc: regenerate it)",
                    analysis.name, tr.frame
                ))
            })?;
            if (fsys.n(), fsys.p()) != (n, p) {
                return Err(RunError::Invalid(format!(
                    "frame {} has {} states and {} inputs, the system {n} and {p}",
                    tr.frame,
                    fsys.n(),
                    fsys.p()
                )));
            }
            Some((f, fsys))
        }
    };
    let (x0, half0) =
        radius::initial_center_and_halfwidths(&info.initial, n).map_err(RunError::Invalid)?;
    let mut lo = vec![0.0; n];
    let mut hi = vec![0.0; n];
    for i in 0..n {
        match info.initial.boxes[i] {
            Some((a, b)) => {
                lo[i] = a;
                hi[i] = b;
            }
            None => {
                let (c, h) = (Interval::point(x0[i]), Interval::point(half0[i]));
                lo[i] = (c - h).lo();
                hi[i] = (c + h).hi();
            }
        }
    }
    // The initial box in y: the interval hull of T X0 (computed, whatever the spec says).
    if let Some((f, _)) = &frame {
        (lo, hi) = f.to_y(&lo, &hi);
    }
    let ubox: Vec<Interval> = info
        .input_box
        .iter()
        .map(|&(a, b)| Interval::new(a, b))
        .collect();
    let grid = nominal::time_grid(analysis.horizon, analysis.step);
    let emb_sys = frame.as_ref().map_or(sys, |(_, fsys)| *fsys);
    let boxes = Embedding::new(emb_sys, inclusion, &ubox)
        .integrate(&lo, &hi, &grid, analysis.integrator)
        .map_err(|k| {
            RunError::NonFinite(format!(
                "the embedding system's box is not finite at t = {} (the {} inclusion diverged; \
                 try the other inclusion, a smaller step or a coordinate transform)",
                grid[k],
                inclusion.name()
            ))
        })?;
    Ok(Deterministic {
        frame,
        grid,
        boxes,
        x0,
        half0,
    })
}

/// The deterministic reachable boxes of an interval analysis without the stochastic part (no
/// constants needed): per report time `(t, lo, hi)`, in the coordinates `y = T x` when the
/// analysis has a transform. The boxes enclose every deterministic trajectory from the initial
/// set with inputs in the input box, up to the (not validated) time discretisation.
#[allow(clippy::type_complexity)]
pub fn reach(
    sys: &dyn System,
    info: &ModelInfo,
    analysis: &Analysis,
) -> Result<Vec<(f64, Vec<f64>, Vec<f64>)>, RunError> {
    let d = deterministic(sys, info, analysis, analysis.inclusion)?;
    Ok(d.grid
        .into_iter()
        .zip(d.boxes)
        .map(|(t, (lo, hi))| (t, lo, hi))
        .collect())
}

/// Lower bound of the distance from `c` to the box `[lo, hi]` over `states`.
fn dist_to_box(states: &[usize], center: &[f64], lo: &[f64], hi: &[f64]) -> f64 {
    states
        .iter()
        .zip(center)
        .fold(Interval::ZERO, |acc, (&s, &c)| {
            let c = Interval::point(c);
            let gap = (Interval::point(lo[s]) - c)
                .lo()
                .max((c - Interval::point(hi[s])).lo())
                .max(0.0);
            acc + Interval::point(gap).sqr()
        })
        .sqrt()
        .lo()
}

/// A lower bound of the safety margin of the PRS `[lo, hi] (+) B_P(r)` (same units as
/// [`safety::Check::margin`]; `> 0` means shown safe).
///
/// `B_P(r)` lies in the box `|d_i| <= r w_i` (`w_i >= sqrt((P^-1)_ii)`), so the PRS lies in the
/// inflated box `[lo - r w, hi + r w]`. Half-spaces use the exact support function
/// `max_box a.x + r sqrt(a' P^-1 a)` (and the inflated box, whichever bound is smaller); boxes
/// the per-coordinate gaps to the inflated box; balls the larger of two lower bounds of the
/// distance, `dist(c, inflated box)` and `dist(c, box) - r spread`.
///
/// `support`, for a half-space, is another upper bound of `max a.x` over the deterministic set
/// (exact for a parallelotope whose hull is `[lo, hi]`); the smaller bound is used.
fn box_margin(
    check: &safety::Check,
    lo: &[f64],
    hi: &[f64],
    r: f64,
    w: &[f64],
    support: Option<f64>,
) -> f64 {
    let r = Interval::point(r);
    let inf_lo = |i: usize| (Interval::point(lo[i]) - r * Interval::point(w[i])).lo();
    let inf_hi = |i: usize| (Interval::point(hi[i]) + r * Interval::point(w[i])).hi();
    match check {
        safety::Check::HalfSpace {
            normal,
            offset,
            dual_norm,
            norm,
        } => {
            if norm.hi() == 0.0 {
                return if *offset > 0.0 {
                    f64::INFINITY
                } else {
                    f64::NEG_INFINITY
                };
            }
            let mut over_box = Interval::ZERO;
            let mut over_inflated = Interval::ZERO;
            for (i, &a) in normal.iter().enumerate() {
                if a == 0.0 {
                    continue;
                }
                let ai = Interval::point(a);
                let (b, ib) = if a > 0.0 {
                    (hi[i], inf_hi(i))
                } else {
                    (lo[i], inf_lo(i))
                };
                over_box += ai * Interval::point(b);
                over_inflated += ai * Interval::point(ib);
            }
            let over_set = support.map_or(over_box, |s| Interval::point(s.min(over_box.hi())));
            let exact = over_set + r * Interval::point(*dual_norm);
            let reach = exact.hi().min(over_inflated.hi());
            ((Interval::point(*offset) - Interval::point(reach)) / *norm).lo()
        }
        safety::Check::Box { coords } => coords
            .iter()
            .map(|&(i, (ulo, uhi), wi)| {
                let half = r * Interval::point(wi);
                let below = if ulo == f64::NEG_INFINITY {
                    f64::NEG_INFINITY
                } else {
                    (Interval::point(ulo) - (Interval::point(hi[i]) + half)).lo()
                };
                let above = if uhi == f64::INFINITY {
                    f64::NEG_INFINITY
                } else {
                    ((Interval::point(lo[i]) - half) - Interval::point(uhi)).lo()
                };
                below.max(above)
            })
            .fold(f64::NEG_INFINITY, f64::max),
        safety::Check::Ball {
            states,
            center,
            radius,
            spread,
        } => {
            let (ilo, ihi): (Vec<f64>, Vec<f64>) =
                (0..lo.len()).map(|i| (inf_lo(i), inf_hi(i))).unzip();
            let rad = Interval::point(*radius);
            let m1 = (Interval::point(dist_to_box(states, center, &ilo, &ihi)) - rad).lo();
            let m2 = (Interval::point(dist_to_box(states, center, lo, hi))
                - r * Interval::point(*spread)
                - rad)
                .lo();
            m1.max(m2)
        }
    }
}

/// Whether `x` lies in the interval PRS `set (+) B_P(r_t)` at the step, where the set is the
/// box `[lo, hi]` or, with a transform, the parallelotope `T^-1 [lo, hi]`: `true` only if
/// certainly (a point `y` of the box, found by projected coordinate descent, is certified in
/// interval arithmetic to satisfy `|x - y|_P <= r_t`, resp. `|x - T^-1 y|_P <= r_t`).
pub(crate) fn contains(result: &AnalysisResult, step_index: usize, x: &[f64]) -> bool {
    let st = &result.steps[step_index];
    let (Some(lo), Some(hi)) = (&st.det_set.lo, &st.det_set.hi) else {
        return false;
    };
    let n = lo.len();
    assert_eq!(x.len(), n, "contains: x has the wrong dimension");
    let p = &result.constants.metric;
    match &result.transform {
        None => {
            let y = nearest_in_box(p, x, lo, hi);
            let d: Vec<Interval> = x
                .iter()
                .zip(&y)
                .map(|(&a, &b)| Interval::point(a) - Interval::point(b))
                .collect();
            transform::quad_form_at_most(p, &d, st.r_t)
        }
        Some(tr) => {
            // Inside the parallelotope (the common case): distance 0, no inverse needed.
            if transform::inside(&tr.matrix, x, lo, hi) {
                return true;
            }
            let flat = |m: &[Vec<f64>]| m.iter().flatten().copied().collect();
            let t = crate::system::Transform {
                matrix: flat(&tr.matrix),
                inverse: flat(&tr.inverse),
                frame: 0,
            };
            let Ok(f) = transform::Frame::new(&t, n) else {
                return false;
            };
            // In y the distance is |y - T x|_Q with Q = T^-T P T^-1 (approximately).
            let (tx, q) = f.y_problem(p, x);
            let y = nearest_in_box(&q, &tx, lo, hi);
            f.certify(p, x, &y, st.r_t)
        }
    }
}

/// A point of the box `[lo, hi]` near the minimiser of `(y - x)' P (y - x)` (projected
/// coordinate descent; the problem is convex, and any point of the box is a valid candidate, so
/// a few sweeps suffice).
fn nearest_in_box(p: &[Vec<f64>], x: &[f64], lo: &[f64], hi: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mut y: Vec<f64> = (0..n).map(|i| x[i].clamp(lo[i], hi[i])).collect();
    for _ in 0..50 {
        for i in 0..n {
            if p[i][i] <= 0.0 {
                continue;
            }
            let s: f64 = (0..n)
                .filter(|&j| j != i)
                .map(|j| p[i][j] * (y[j] - x[j]))
                .sum();
            let yi = x[i] - s / p[i][i];
            if yi.is_finite() {
                y[i] = yi.clamp(lo[i], hi[i]);
            }
        }
    }
    y
}
