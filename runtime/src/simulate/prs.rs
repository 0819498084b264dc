//! Distances `|x - x*_t|_P` and PRS membership of sample states.
//!
//! Membership is decided by [`engine::contains`] (the engine's own, conservative test). It
//! allocates and works in interval arithmetic, too slow for every path and step, so two
//! shortcuts answer the clear cases first, each only where it provably agrees with `contains`:
//!
//! * outside: `|x - x*_t|_P` clearly above the PRS radius. For the shapes whose PRS lies in the
//!   P-ball `B_P(x*_t, prs_radius)` (`"p_ball"`, and `"box"` with `x*_t` its centre), a point
//!   outside that ball is outside the PRS;
//! * inside: for `"p_ball"`, `|x - x*_t|_P` clearly below the radius; for `"box"`, `x` in the
//!   box (a subset of the PRS `box (+) B_P(r_t)`).
//!
//! "Clearly" means by more than a bound on the rounding errors of both computations:
//! `|q_computed - q| <= gamma * sum |w_ij d_i d_j|` with `gamma` a generous multiple of the unit
//! roundoff times the number of terms. Points in that band, and every point for other shapes,
//! go to `contains`.

use crate::engine::{self, AnalysisResult};

/// The quadratic form `d' P d` as a list of terms.
#[derive(Clone, Debug)]
pub(crate) struct Metric {
    /// `(i, j, w)` with `w = P_ii` on the diagonal and `w = P_ij + P_ji` for `i < j` (both
    /// off-diagonal entries, as `contains` uses them); zero terms dropped.
    terms: Vec<(usize, usize, f64)>,
    /// Bound factor of the rounding error of [`quad`](Self::quad), relative to its `abs_sum`.
    gamma: f64,
    /// `P` is diagonal with non-negative entries: every term is non-negative, so the error
    /// bound is relative to `q` itself and the tests reduce to comparisons with per-step
    /// constants.
    nonneg: bool,
    /// That diagonal (when `nonneg`), one entry per state.
    diag: Vec<f64>,
}

impl Metric {
    /// The metric `P` by rows.
    pub(crate) fn new(p: &[Vec<f64>]) -> Self {
        let n = p.len();
        let mut terms = Vec::new();
        for (i, row) in p.iter().enumerate() {
            if row[i] != 0.0 {
                terms.push((i, i, row[i]));
            }
            for (j, other) in p.iter().enumerate().skip(i + 1) {
                let w = row[j] + other[i];
                if w != 0.0 {
                    terms.push((i, j, w));
                }
            }
        }
        // Each term: a rounded difference per factor, two products, the doubled weight; then a
        // sum of `terms.len()` values. A factor 4 over the textbook bound covers `contains`'s
        // own (outward-rounded) evaluation.
        let gamma = 4.0 * (terms.len() as f64 + 8.0) * f64::EPSILON;
        let nonneg = terms.iter().all(|&(i, j, w)| i == j && w >= 0.0);
        let diag = (0..n).map(|i| p[i][i]).collect();
        Metric {
            terms,
            gamma,
            nonneg,
            diag,
        }
    }

    /// `(q, a)`: `q = (x - c)' P (x - c)` and `a = sum |w_ij d_i d_j|` (for the error bound).
    #[inline(always)]
    pub(crate) fn quad(&self, x: &[f64], c: &[f64]) -> (f64, f64) {
        if self.nonneg {
            // By state (not by term) so that a constant dimension unrolls the loop.
            let (w, c) = (&self.diag[..x.len()], &c[..x.len()]);
            let mut q = 0.0;
            for i in 0..x.len() {
                let d = x[i] - c[i];
                q += w[i] * d * d;
            }
            return (q, q);
        }
        let (mut q, mut a) = (0.0, 0.0);
        for &(i, j, w) in &self.terms {
            let t = w * (x[i] - c[i]) * (x[j] - c[j]);
            q += t;
            a += t.abs();
        }
        (q, a)
    }
}

/// The PRS shapes the shortcuts know.
#[derive(Clone, Debug)]
enum Shape {
    PBall,
    /// Per report step, the box's corners (flat, n per step).
    Box {
        lo: Vec<f64>,
        hi: Vec<f64>,
    },
    /// Anything else: always ask `contains`.
    Other,
}

/// Decides PRS membership at each report step of `result`.
#[derive(Clone, Debug)]
pub(crate) struct Membership<'a> {
    result: &'a AnalysisResult,
    shape: Shape,
    /// Squared PRS radius per step.
    r2: Vec<f64>,
    /// With a non-negative diagonal metric: `q` above `q_out[k]` is clearly outside the P-ball,
    /// below `q_in[k]` clearly inside (the error bound solved for `q` once per step).
    q_out: Vec<f64>,
    q_in: Vec<f64>,
    nonneg: bool,
    n: usize,
}

impl<'a> Membership<'a> {
    /// For `result` (its steps), with `metric` built from its metric.
    pub(crate) fn new(result: &'a AnalysisResult, metric: &Metric) -> Self {
        let n = result.states.len();
        let shape = match result.steps.first().map(|s| s.det_set.shape) {
            Some("p_ball") if result.steps.iter().all(|s| s.det_set.lo.is_none()) => Shape::PBall,
            Some("box") => {
                let corners = |f: fn(&engine::DetSet) -> &Option<Vec<f64>>| {
                    result
                        .steps
                        .iter()
                        .map(|s| f(&s.det_set).as_ref().filter(|v| v.len() == n))
                        .collect::<Option<Vec<_>>>()
                        .map(|v| v.into_iter().flatten().copied().collect::<Vec<f64>>())
                };
                match (corners(|d| &d.lo), corners(|d| &d.hi)) {
                    (Some(lo), Some(hi)) => Shape::Box { lo, hi },
                    _ => Shape::Other,
                }
            }
            _ => Shape::Other,
        };
        let r2: Vec<f64> = result
            .steps
            .iter()
            .map(|s| s.prs_radius * s.prs_radius)
            .collect();
        // q (1 - gamma) > r2 (1 + 8 eps) and q (1 + gamma) < r2 (1 - 8 eps), with 16 eps for
        // the roundings of these two formulas.
        let eps16 = 16.0 * f64::EPSILON;
        let q_out = r2
            .iter()
            .map(|r| r * (1.0 + eps16) / (1.0 - metric.gamma))
            .collect();
        let q_in = r2
            .iter()
            .map(|r| r * (1.0 - eps16) / (1.0 + metric.gamma))
            .collect();
        Membership {
            result,
            shape,
            r2,
            q_out,
            q_in,
            nonneg: metric.nonneg,
            n,
        }
    }

    /// Whether `x` is in the PRS of step `k`, given the centre `c = x*_k` and
    /// `(q, a) = metric.quad(x, c)`.
    #[inline(always)]
    pub(crate) fn inside(
        &self,
        metric: &Metric,
        k: usize,
        x: &[f64],
        c: &[f64],
        q: f64,
        a: f64,
    ) -> bool {
        let (clearly_out, clearly_in) = if self.nonneg {
            (q > self.q_out[k], q < self.q_in[k])
        } else {
            let (r2, err) = (
                self.r2[k],
                metric.gamma * a + 8.0 * f64::EPSILON * self.r2[k],
            );
            (q - err > r2, q + err < r2)
        };
        match &self.shape {
            Shape::PBall => {
                if clearly_out {
                    return false;
                }
                // x = x*_t exactly (a point initial set at t = 0, where the radius may be 0):
                // `contains` finds |x - x*_t|_P = 0 exactly.
                if clearly_in || (q == 0.0 && x == c) {
                    return true;
                }
            }
            Shape::Box { lo, hi } => {
                if clearly_out {
                    return false;
                }
                let (lo, hi) = (&lo[k * self.n..][..self.n], &hi[k * self.n..][..self.n]);
                if x.iter()
                    .zip(lo.iter().zip(hi))
                    .all(|(v, (l, h))| l <= v && v <= h)
                {
                    return true;
                }
            }
            Shape::Other => {}
        }
        engine::contains(self.result, k, x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interval::Interval;
    use crate::simulate::rng::PathRng;
    use crate::system::*;

    /// `dx = A x dt + 0.2 dW` with a non-symmetric stable `A`.
    struct Sys;

    const A: [f64; 4] = [-1.0, 0.5, -0.3, -0.8];

    impl System for Sys {
        fn n(&self) -> usize {
            2
        }
        fn p(&self) -> usize {
            0
        }
        fn m(&self) -> usize {
            2
        }
        fn drift(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
            out[0] = A[0] * x[0] + A[1] * x[1];
            out[1] = A[2] * x[0] + A[3] * x[1];
        }
        fn drift_interval(
            &self,
            x: &[Interval],
            _u: &[Interval],
            _t: Interval,
            o: &mut [Interval],
        ) {
            let p = Interval::point;
            o[0] = p(A[0]) * x[0] + p(A[1]) * x[1];
            o[1] = p(A[2]) * x[0] + p(A[3]) * x[1];
        }
        fn jac_x(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
            out.copy_from_slice(&A);
        }
        fn jac_x_interval(
            &self,
            _x: &[Interval],
            _u: &[Interval],
            _t: Interval,
            o: &mut [Interval],
        ) {
            for (o, a) in o.iter_mut().zip(A) {
                *o = Interval::point(a);
            }
        }
        fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, _out: &mut [f64]) {}
        fn jac_u_interval(
            &self,
            _x: &[Interval],
            _u: &[Interval],
            _t: Interval,
            _o: &mut [Interval],
        ) {
        }
        fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
            out.copy_from_slice(&[0.2, 0.0, 0.0, 0.2]);
        }
        fn diffusion_interval(&self, _x: &[Interval], _t: Interval, o: &mut [Interval]) {
            for (o, g) in o.iter_mut().zip([0.2, 0.0, 0.0, 0.2]) {
                *o = Interval::point(g);
            }
        }
    }

    fn result(method: Method, metric: Vec<f64>) -> AnalysisResult {
        let analysis = Analysis {
            name: "a".into(),
            method,
            delta: 0.01,
            horizon: 1.0,
            step: 0.1,
            radius: RadiusRule::Amgf,
            rate: Rate::Certified,
            integrator: Integrator::Rk4,
            inclusion: Inclusion::Jacobian,
            outputs: vec![],
            transform: None,
            // Valid for P = I and for the skewed P below (generous c, sigma).
            constants: Some(Constants {
                metric,
                c: -0.2,
                sigma: 0.5,
                rho: 0.0,
                how: "test".into(),
            }),
            constants_error: None,
        };
        let info = ModelInfo {
            name: "m".into(),
            states: vec!["x".into(), "y".into()],
            inputs: vec![],
            noises: vec!["w1".into(), "w2".into()],
            input_box: vec![],
            initial: InitialSet {
                boxes: vec![Some((0.9, 1.1)), Some((-0.1, 0.2))],
                balls: vec![],
            },
            domain: vec![(f64::NEG_INFINITY, f64::INFINITY); 2],
            has_domain: false,
            unsafe_sets: vec![],
            analyses: vec![],
        };
        engine::run(&Sys, &info, &analysis).unwrap()
    }

    /// Points at relative P-distances from far inside to far outside, many within rounding of
    /// the boundary: the shortcuts never disagree with `engine::contains`.
    #[test]
    fn shortcuts_agree_with_contains() {
        let mut rng = PathRng::new(5, 0);
        for (method, metric) in [
            (Method::Contraction, vec![1.0, 0.0, 0.0, 1.0]),
            (Method::Contraction, vec![2.0, 0.7, 0.7, 1.0]),
            (Method::Interval, vec![1.0, 0.0, 0.0, 1.0]),
            (Method::Interval, vec![2.0, 0.7, 0.7, 1.0]),
        ] {
            let r = result(method, metric);
            let m = Metric::new(&r.constants.metric);
            let mem = Membership::new(&r, &m);
            for (k, st) in r.steps.iter().enumerate() {
                let c = &st.nominal;
                for i in 0..400 {
                    // A random direction, scaled to a P-distance s * prs_radius.
                    let dir = [rng.uniform() - 0.5, rng.uniform() - 0.5];
                    let (q1, _) = m.quad(&[c[0] + dir[0], c[1] + dir[1]], c);
                    let s = match i % 4 {
                        0 => 1.0 + (rng.uniform() - 0.5) * 1e-12,
                        1 => 1.0 + (rng.uniform() - 0.5) * 1e-6,
                        2 => rng.uniform() * 2.0,
                        _ => 0.9 + rng.uniform() * 0.2,
                    };
                    let scale = s * st.prs_radius / q1.sqrt();
                    let x = [c[0] + scale * dir[0], c[1] + scale * dir[1]];
                    let (q, a) = m.quad(&x, c);
                    let fast = mem.inside(&m, k, &x, c, q, a);
                    assert_eq!(
                        fast,
                        engine::contains(&r, k, &x),
                        "{method:?} k = {k} s = {s}"
                    );
                }
            }
        }
    }
}
