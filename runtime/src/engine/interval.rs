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

use super::result::{AnalysisResult, ConstantsReport, DetSet, StepRecord, Validation};
use super::{integrator_name, nominal, radius, safety, verdicts, RunError};
use crate::interval::Interval;
use crate::system::{Analysis, Inclusion, Integrator, ModelInfo, System};

/// Runs an interval-method analysis with the given inclusion function.
///
/// [`super::run`] calls this with the analysis' own inclusion. Needs the constants `c`, `sigma` and the metric `P` for the
/// stochastic radius ([`RunError::NoConstants`] otherwise); refuses analyses with a coordinate
/// transform ([`RunError::Unsupported`]).
pub fn run_interval(
    sys: &dyn System,
    info: &ModelInfo,
    analysis: &Analysis,
    inclusion: Inclusion,
) -> Result<AnalysisResult, RunError> {
    if analysis.transform.is_some() {
        return Err(RunError::Unsupported(format!(
            "analysis `{}` uses a coordinate transform, which the interval engine does not \
             support yet",
            analysis.name
        )));
    }
    let super::Setup {
        consts,
        n,
        p,
        chol,
        p_inv,
    } = super::setup(sys, info, analysis, &["c", "sigma"])?;
    let metric = &consts.metric;
    // Upper bounds of sqrt((P^-1)_ii): B_P(r) lies in the box |d_i| <= r w_i.
    let w: Vec<f64> = (0..n).map(|i| p_inv[i * n + i].sqrt().hi()).collect();

    // Initial box: the initial boxes as given, balls replaced by their bounding boxes.
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
    let r1 = radius::r1_bound(metric, &half0);
    let r1_how = String::from(
        "P-radius of the initial box around its centre (reported only: the interval method \
         propagates the box itself)",
    ) + if info.initial.balls.is_empty() {
        ""
    } else {
        "; initial balls replaced by their bounding boxes (conservative)"
    };
    let ubox: Vec<Interval> = info
        .input_box
        .iter()
        .map(|&(a, b)| Interval::new(a, b))
        .collect();
    let u_center: Vec<f64> = ubox.iter().map(|u| u.mid()).collect();

    let (kappa, radius_rule) = radius::stochastic_factor(n, analysis);

    // The embedding system (not validated in time).
    let grid = nominal::time_grid(analysis.horizon, analysis.step);
    let emb = Embedding {
        sys,
        inclusion,
        ubox: &ubox,
        uc: &u_center,
        n,
        p,
    };
    let boxes = emb
        .integrate(&lo, &hi, &grid, analysis.integrator)
        .map_err(|k| {
            RunError::NonFinite(format!(
                "the embedding system's box is not finite at t = {} (the {} inclusion diverged; \
                 try the other inclusion, a smaller step or a coordinate transform)",
                grid[k],
                inclusion.name()
            ))
        })?;

    let checks =
        safety::Check::all(&info.unsafe_sets, n, &chol, &p_inv).map_err(RunError::Invalid)?;

    let mut stochastic = radius::Stochastic::new(kappa);
    let mut steps = Vec::with_capacity(grid.len());
    for (k, (&t, (blo, bhi))) in grid.iter().zip(boxes).enumerate() {
        let (c_k, sigma_k) = (consts.c, consts.sigma);
        let prev = k.checked_sub(1).map(|j| grid[j]);
        let (psi_hi, r_t) = stochastic.advance(prev, t, c_k, sigma_k);
        let ivs: Vec<Interval> = blo
            .iter()
            .zip(&bhi)
            .map(|(&a, &b)| Interval::new(a, b))
            .collect();
        let center: Vec<f64> = ivs.iter().map(|iv| iv.mid()).collect();
        let half: Vec<f64> = ivs.iter().map(|iv| iv.rad()).collect();
        // The box lies in B_P(center, det): an enclosing P-ball, so `prs_radius` is the radius
        // of a P-ball containing the PRS (coarser than the PRS itself).
        let det = radius::r1_bound(metric, &half);
        let prs = (Interval::point(det) + Interval::point(r_t)).hi();
        let margins = checks
            .iter()
            .map(|c| box_margin(c, &blo, &bhi, r_t, &w))
            .collect();
        steps.push(StepRecord {
            t,
            det_set: DetSet {
                shape: "box",
                center: center.clone(),
                radius: det,
                metric: "constants.metric",
                lo: Some(blo),
                hi: Some(bhi),
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
        initial_center: x0,
        input_center: u_center,
        steps,
        unsafe_sets,
        verdict,
        validated: Validation {
            rigorous: vec![
                format!("constants c, sigma ({})", consts.how),
                format!(
                    "{} inclusion function of the drift on each face (outward-rounded interval \
                     arithmetic)",
                    inclusion.name()
                ),
                "kappa (rounded up)".into(),
                "Psi_t (exact per-step integration in interval arithmetic, upper end)".into(),
                "r_t (interval arithmetic, rounded up)".into(),
                "safety margins given the box (P^-1 enclosed by interval Cholesky, rounded \
                 down)"
                    .into(),
            ],
            not_validated,
            conditional_on_domain: info.has_domain,
        },
    })
}

/// The embedding system of an inclusion function on boxes `(lo, hi)`.
struct Embedding<'a> {
    sys: &'a dyn System,
    inclusion: Inclusion,
    ubox: &'a [Interval],
    uc: &'a [f64],
    n: usize,
    p: usize,
}

/// `out[k] += J[k][j] (v_j - c_j)` for the columns `j` in `cols` of the `n x width` matrix `jac`.
fn add_columns(
    out: &mut [Interval],
    jac: &[Interval],
    width: usize,
    v: &[Interval],
    c: &[Interval],
    cols: std::ops::Range<usize>,
) {
    for j in cols {
        let d = v[j] - c[j];
        // A pinned (or point) coordinate contributes exactly 0; skipping it also avoids
        // 0 * inf when the Jacobian column is unbounded.
        if d == Interval::ZERO {
            continue;
        }
        for (k, o) in out.iter_mut().enumerate() {
            *o += jac[k * width + j] * d;
        }
    }
}

impl Embedding<'_> {
    /// The inclusion function on the box `x` at time `t`.
    fn eval(&self, x: &[Interval], t: Interval, out: &mut [Interval]) {
        let (n, p) = (self.n, self.p);
        match self.inclusion {
            Inclusion::Natural => self.sys.drift_interval(x, self.ubox, t, out),
            Inclusion::Jacobian => {
                // Mean value theorem on the segment from (xc, uc) to (x, u), which stays in the
                // (convex) box x U: f(x, u) in f(xc, uc) + Jx([x], U)(x - xc) + Ju([x], U)(u - uc).
                let (xcp, ucp) = self.centre(x, t, out);
                let mut jx = vec![Interval::ZERO; n * n];
                self.sys.jac_x_interval(x, self.ubox, t, &mut jx);
                add_columns(out, &jx, n, x, &xcp, 0..n);
                if p > 0 {
                    let mut ju = vec![Interval::ZERO; n * p];
                    self.sys.jac_u_interval(x, self.ubox, t, &mut ju);
                    add_columns(out, &ju, p, self.ubox, &ucp, 0..p);
                }
            }
            Inclusion::Mixed => {
                // One coordinate at a time (immrax's mjacif): f(x, u) - f(xc, uc) telescopes over
                // the states (inputs at uc) and then the inputs (states in their box); term j is
                // in column j of the Jacobian over the box whose coordinates before j are boxes,
                // j its box, and after j their centres. Tighter than one Jacobian over the whole
                // box, at the cost of one Jacobian evaluation per coordinate.
                let (xcp, ucp) = self.centre(x, t, out);
                let mut jx = vec![Interval::ZERO; n * n];
                let mut b = xcp.clone();
                for j in 0..n {
                    b[j] = x[j];
                    if x[j] != xcp[j] {
                        self.sys.jac_x_interval(&b, &ucp, t, &mut jx);
                        add_columns(out, &jx, n, x, &xcp, j..j + 1);
                    }
                }
                let mut ju = vec![Interval::ZERO; n * p];
                let mut bu = ucp.clone();
                for j in 0..p {
                    bu[j] = self.ubox[j];
                    if self.ubox[j] != ucp[j] {
                        self.sys.jac_u_interval(x, &bu, t, &mut ju);
                        add_columns(out, &ju, p, self.ubox, &ucp, j..j + 1);
                    }
                }
            }
        }
    }

    /// Writes the enclosure of `f(xc, uc)` at the box's centre into `out`; returns the centres
    /// as point intervals.
    fn centre(
        &self,
        x: &[Interval],
        t: Interval,
        out: &mut [Interval],
    ) -> (Vec<Interval>, Vec<Interval>) {
        let xcp: Vec<Interval> = x.iter().map(|v| Interval::point(v.mid())).collect();
        let ucp: Vec<Interval> = self.uc.iter().map(|&v| Interval::point(v)).collect();
        self.sys.drift_interval(&xcp, &ucp, t, out);
        (xcp, ucp)
    }

    /// The embedding vector field: `d = (x_lo', x_hi')` at the box `z = (x_lo, x_hi)`.
    ///
    /// Intermediate integrator stages may (numerically) invert a coordinate; the box used is
    /// then the hull of the two ends.
    fn rhs(&self, z: &[f64], t: f64, d: &mut [f64]) {
        let n = self.n;
        let (lo, hi) = z.split_at(n);
        let bx: Vec<Interval> = lo
            .iter()
            .zip(hi)
            .map(|(&a, &b)| Interval::try_new(a.min(b), a.max(b)).unwrap_or(Interval::ENTIRE))
            .collect();
        let t = Interval::point(t);
        let mut face = bx.clone();
        let mut out = vec![Interval::ZERO; n];
        for i in 0..n {
            face[i] = Interval::point(lo[i]);
            self.eval(&face, t, &mut out);
            d[i] = out[i].lo();
            face[i] = Interval::point(hi[i]);
            self.eval(&face, t, &mut out);
            d[n + i] = out[i].hi();
            face[i] = bx[i];
        }
    }

    /// Integrates the embedding system over the grid; per grid time the box `(lo, hi)`.
    /// `Err(k)` if the box is not finite at grid index `k`.
    #[allow(clippy::type_complexity)]
    fn integrate(
        &self,
        lo: &[f64],
        hi: &[f64],
        grid: &[f64],
        integrator: Integrator,
    ) -> Result<Vec<(Vec<f64>, Vec<f64>)>, usize> {
        let n = self.n;
        let m = 2 * n;
        let mut z: Vec<f64> = lo.iter().chain(hi).copied().collect();
        let mut out = Vec::with_capacity(grid.len());
        out.push((lo.to_vec(), hi.to_vec()));
        let mut k1 = vec![0.0; m];
        let mut k2 = vec![0.0; m];
        let mut k3 = vec![0.0; m];
        let mut k4 = vec![0.0; m];
        let mut tmp = vec![0.0; m];
        for (idx, win) in grid.windows(2).enumerate() {
            let (t, h) = (win[0], win[1] - win[0]);
            match integrator {
                Integrator::Euler => {
                    self.rhs(&z, t, &mut k1);
                    for i in 0..m {
                        z[i] += h * k1[i];
                    }
                }
                Integrator::Rk4 => {
                    self.rhs(&z, t, &mut k1);
                    for i in 0..m {
                        tmp[i] = z[i] + 0.5 * h * k1[i];
                    }
                    self.rhs(&tmp, t + 0.5 * h, &mut k2);
                    for i in 0..m {
                        tmp[i] = z[i] + 0.5 * h * k2[i];
                    }
                    self.rhs(&tmp, t + 0.5 * h, &mut k3);
                    for i in 0..m {
                        tmp[i] = z[i] + h * k3[i];
                    }
                    self.rhs(&tmp, t + h, &mut k4);
                    for i in 0..m {
                        z[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                    }
                }
            }
            if z.iter().any(|v| !v.is_finite()) {
                return Err(idx + 1);
            }
            let (l, u) = z.split_at(n);
            let (l, u): (Vec<f64>, Vec<f64>) =
                l.iter().zip(u).map(|(&a, &b)| (a.min(b), a.max(b))).unzip();
            out.push((l, u));
        }
        Ok(out)
    }
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
fn box_margin(check: &safety::Check, lo: &[f64], hi: &[f64], r: f64, w: &[f64]) -> f64 {
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
            let exact = over_box + r * Interval::point(*dual_norm);
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

/// Whether `x` lies in the interval PRS `[lo, hi] (+) B_P(r_t)` at the step: `true` only if
/// certainly (a point `y` of the box, found by projected coordinate descent on `|x - y|_P`, is
/// certified in interval arithmetic to satisfy `|x - y|_P <= r_t`).
pub(crate) fn contains(result: &AnalysisResult, step_index: usize, x: &[f64]) -> bool {
    let st = &result.steps[step_index];
    let (Some(lo), Some(hi)) = (&st.det_set.lo, &st.det_set.hi) else {
        return false;
    };
    let n = lo.len();
    assert_eq!(x.len(), n, "contains: x has the wrong dimension");
    let p = &result.constants.metric;
    // Minimise (y - x)' P (y - x) over the box, coordinate by coordinate (convex, so this
    // converges; any y in the box is a valid certificate, so a few sweeps suffice).
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
    let d: Vec<Interval> = x
        .iter()
        .zip(&y)
        .map(|(&a, &b)| Interval::point(a) - Interval::point(b))
        .collect();
    let mut q = Interval::ZERO;
    for i in 0..n {
        for j in 0..n {
            q += Interval::point(p[i][j]) * d[i] * d[j];
        }
    }
    q.hi() <= Interval::point(st.r_t).sqr().lo()
}
