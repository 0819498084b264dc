//! `metric = auto` chooses `P` for the result, not for the rate alone (method.md section 8.5).
//!
//! Any `P > 0` is sound once `c`, `sigma`, `rho` are certified for it, so the choice only
//! affects tightness. The metric that minimises `c` can be far worse than none: for an
//! integrator chain it lowers `c` but multiplies `sigma` and `rho` by a thousand. Candidates are
//! therefore compared by the PRS they predict at the horizon, from their *certified* constants:
//! the P-ball of radius `R_T + r_T` with `R_T = e^(c T) r1 + rho (e^(c T) - 1) / c` (the
//! contraction method's deterministic radius; none for the interval method, whose box does not
//! depend on `P`) and `r_T = sqrt(kappa sigma^2 (e^(2 c T) - 1) / (2 c))`, measured by its
//! volume, `n ln(R_T + r_T) - ln det(P) / 2` (invariant under `P -> s P`).
//!
//! Candidates: the identity, the rate-optimal metric `P_c` of [`super::metric`] and the
//! geodesic between them (`P_c^a`, `a` in `(0, 1)`), diagonal geometric scalings
//! `diag(s^(2i))`, then a Nelder-Mead search over `P = R'R` (`R` upper triangular, `R_00 = 1`)
//! from the best of those for small `n`. Candidates whose condition number exceeds
//! [`MAX_CONDITION`] are not considered. The identity is a candidate, so the chosen metric never
//! predicts a larger PRS than the identity. The result is normalised to `lambda_min(P) = 1`.

use nalgebra::{DMatrix, SymmetricEigen};

use super::contraction::constants;
use super::metric::{identity, normalise};
use super::Derivatives;
use crate::model::{Method, Model};
use reachc_core::model::{AnalysisSpec, Constants};

/// Up to this many states the full `R` is searched (`n (n + 1) / 2 - 1` parameters).
const SEARCH_MAX_DIM: usize = 4;

/// Evaluations of the Nelder-Mead search.
const SEARCH_EVALS: usize = 300;

/// Up to this many initial-box coordinates `r1` is the maximum over the vertices.
const VERTEX_MAX: usize = 12;

/// The largest condition number `lambda_max(P) / lambda_min(P)` of a candidate. The predicted
/// volume is unbounded below along a direction none of the constants sees: a state with a
/// point start, no noise and no input, whose couplings into the others a heavy weight damps,
/// lets `P_ii -> infinity` shrink `-ln det(P) / 2` for nothing (the search stops at `e^60`).
/// Such a metric is flat beyond any use and out of reach of the engine's floating point: the
/// nominal's defect in that state is weighed by `sqrt(P_ii)`, so no step validates it
/// (method.md section 8.5).
const MAX_CONDITION: f64 = 1e4;

/// What a metric is chosen for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Objective {
    /// The volume of the PRS's P-ball at the horizon (`metric = auto`).
    Volume,
    /// The half-width of one state's extent at the horizon, for one of `metrics` metrics
    /// sharing `delta` (`metric = auto(states = [..])`, each at `delta / metrics`).
    Extent {
        /// The state's index.
        state: usize,
        /// The number of metrics of the analysis.
        metrics: usize,
    },
}

/// The metric among the candidates derived from the rate-optimal `rate_metric` (and the
/// identity) whose certified constants predict the smallest PRS at the horizon of `spec`, as
/// measured by `objective`.
pub fn metric_for_result(
    model: &Model,
    d: &Derivatives,
    spec: &AnalysisSpec,
    rate_metric: Vec<f64>,
    objective: Objective,
) -> Vec<f64> {
    let n = model.states.len();
    // The same for every candidate: computed once (its certified series is most of a score).
    let delta = match objective {
        Objective::Volume => spec.delta,
        Objective::Extent { metrics, .. } => spec.delta / metrics as f64,
    };
    let kappa = reachc_core::kappa::kappa(n, delta, spec.radius);
    let score = |p: &[f64]| -> f64 {
        if !conditioned(p, n) {
            return f64::INFINITY;
        }
        constants(model, d, p).map_or(f64::INFINITY, |k| {
            predicted(model, spec, p, &k, kappa, objective)
        })
    };
    let mut best = (score(&identity(n)), identity(n));
    let consider = |p: Vec<f64>, best: &mut (f64, Vec<f64>)| {
        let s = score(&p);
        if s < best.0 {
            *best = (s, p);
        }
    };
    if let Some(geodesic) = Geodesic::new(&rate_metric, n) {
        for a in [0.1, 0.25, 0.5, 0.75, 0.9, 1.0] {
            consider(geodesic.at(a), &mut best);
        }
    }
    for s in [0.25, 0.5, 0.7, 0.85, 1.2, 1.5, 2.0, 4.0] {
        consider(geometric(n, s), &mut best);
    }
    if (2..=SEARCH_MAX_DIM).contains(&n) && best.0.is_finite() {
        let start = upper_params(&best.1, n);
        if let Some(x) = start {
            let found = nelder_mead(&x, SEARCH_EVALS, |x| score(&metric_of(x, n)));
            consider(metric_of(&found, n), &mut best);
        }
    }
    // Scale-free, so normalised like every synthesised metric (`lambda_min(P) = 1`); the
    // identity stays exact.
    if best.1 == identity(n) {
        return best.1;
    }
    normalise(&DMatrix::from_row_slice(n, n, &best.1))
}

/// The log-volume of the P-ball the certified constants predict at the horizon, or the log of
/// its extent in one state (see the module documentation), for the radius rule's `kappa` at the
/// objective's delta; infinite when the constants are not finite.
fn predicted(
    model: &Model,
    spec: &AnalysisSpec,
    p: &[f64],
    k: &Constants,
    kappa: f64,
    objective: Objective,
) -> f64 {
    let n = model.states.len();
    let (c, t) = (k.c(), spec.horizon);
    if !(c.is_finite() && k.sigma().is_finite() && k.rho().is_finite()) {
        return f64::INFINITY;
    }
    // (e^(x) - 1) / x, continuous at 0.
    let growth = |x: f64| if x.abs() < 1e-12 { 1.0 } else { x.exp_m1() / x };
    let psi = k.sigma() * k.sigma() * t * growth(2.0 * c * t);
    let r_t = (kappa * psi).sqrt();
    let det = match spec.method {
        Method::Contraction => (c * t).exp() * r1(model, p) + k.rho() * t * growth(c * t),
        Method::Interval => 0.0,
    };
    let Some(chol) = DMatrix::from_row_slice(n, n, p).cholesky() else {
        return f64::INFINITY;
    };
    let v = match objective {
        Objective::Volume => {
            let log_det = 2.0 * chol.l().diagonal().iter().map(|v| v.ln()).sum::<f64>();
            n as f64 * (det + r_t).ln() - 0.5 * log_det
        }
        // The ball's half-width in state i is its radius times sqrt((P^-1)_ii).
        Objective::Extent { state, .. } => {
            let mut e = DMatrix::zeros(n, 1);
            e[(state, 0)] = 1.0;
            let col = chol.solve(&e);
            (det + r_t).ln() + 0.5 * col[(state, 0)].ln()
        }
    };
    if v.is_nan() {
        f64::INFINITY
    } else {
        v
    }
}

/// `max |x0 - centre|_P` over the initial set's bounding box (its vertices for small boxes,
/// else `sqrt(sum |P_ij| h_i h_j)`).
fn r1(model: &Model, p: &[f64]) -> f64 {
    let n = model.states.len();
    let Ok(b) = model.initial.bounding_box() else {
        return f64::INFINITY;
    };
    let half: Vec<f64> = b.iter().map(|x| 0.5 * (x.hi - x.lo)).collect();
    let active: Vec<usize> = (0..n).filter(|&i| half[i] > 0.0).collect();
    let quad = |v: &[f64]| -> f64 {
        (0..n)
            .map(|i| (0..n).map(|j| v[i] * p[i * n + j] * v[j]).sum::<f64>())
            .sum()
    };
    if active.len() <= VERTEX_MAX {
        (0..1usize << active.len())
            .map(|mask| {
                let mut v = vec![0.0; n];
                for (bit, &i) in active.iter().enumerate() {
                    v[i] = if mask >> bit & 1 == 1 {
                        half[i]
                    } else {
                        -half[i]
                    };
                }
                quad(&v)
            })
            .fold(0.0, f64::max)
            .sqrt()
    } else {
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| p[i * n + j].abs() * half[i] * half[j])
                    .sum::<f64>()
            })
            .sum::<f64>()
            .sqrt()
    }
}

/// `P^a` along the geodesic from the identity to a normalised `P` (`a = 1`: `P`).
struct Geodesic {
    eig: SymmetricEigen<f64, nalgebra::Dyn>,
    n: usize,
}

impl Geodesic {
    fn new(p: &[f64], n: usize) -> Option<Geodesic> {
        let eig = SymmetricEigen::new(DMatrix::from_row_slice(n, n, p));
        (eig.eigenvalues.iter().all(|&l| l > 0.0)).then_some(Geodesic { eig, n })
    }

    fn at(&self, a: f64) -> Vec<f64> {
        let d = DMatrix::from_diagonal(&self.eig.eigenvalues.map(|l| l.powf(a)));
        let m = &self.eig.eigenvectors * d * self.eig.eigenvectors.transpose();
        symmetric(&m, self.n)
    }
}

/// Whether the symmetric `p` is positive definite with a condition number at most
/// [`MAX_CONDITION`] (from the diagonal when `p` is diagonal, else from its eigenvalues).
fn conditioned(p: &[f64], n: usize) -> bool {
    let diagonal = (0..n * n).all(|k| k / n == k % n || p[k] == 0.0);
    let (lo, hi) = if diagonal {
        (0..n)
            .map(|i| p[i * n + i])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            })
    } else {
        let e = SymmetricEigen::new(DMatrix::from_row_slice(n, n, p)).eigenvalues;
        (e.min(), e.max())
    };
    lo > 0.0 && hi <= MAX_CONDITION * lo
}

/// `diag(s^(2i))`: weights falling (or rising) geometrically along the states.
fn geometric(n: usize, s: f64) -> Vec<f64> {
    let mut p = vec![0.0; n * n];
    for i in 0..n {
        p[i * n + i] = s.powi(2 * i as i32);
    }
    p
}

/// `(M + M') / 2`, row-major.
fn symmetric(m: &DMatrix<f64>, n: usize) -> Vec<f64> {
    let mut out = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            out[i * n + j] = 0.5 * (m[(i, j)] + m[(j, i)]);
        }
    }
    out
}

/// The parameters of `P = R'R` (`R = L'`, scaled to `R_00 = 1`): the log-diagonal after the
/// first entry, then the upper off-diagonal entries by rows.
fn upper_params(p: &[f64], n: usize) -> Option<Vec<f64>> {
    let l = DMatrix::from_row_slice(n, n, p).cholesky()?.l();
    let s = l[(0, 0)];
    let mut x: Vec<f64> = (1..n).map(|i| (l[(i, i)] / s).ln()).collect();
    for i in 0..n {
        for j in i + 1..n {
            x.push(l[(j, i)] / s);
        }
    }
    Some(x)
}

/// The metric of [`upper_params`]' parameters.
fn metric_of(x: &[f64], n: usize) -> Vec<f64> {
    let mut r = DMatrix::zeros(n, n);
    r[(0, 0)] = 1.0;
    for i in 1..n {
        r[(i, i)] = x[i - 1].clamp(-30.0, 30.0).exp();
    }
    let mut k = n - 1;
    for i in 0..n {
        for j in i + 1..n {
            r[(i, j)] = x[k];
            k += 1;
        }
    }
    symmetric(&(r.transpose() * &r), n)
}

/// Nelder-Mead minimisation from `x0` within `evals` evaluations of `f`; returns the best point.
fn nelder_mead(x0: &[f64], evals: usize, mut f: impl FnMut(&[f64]) -> f64) -> Vec<f64> {
    let d = x0.len();
    let mut simplex: Vec<(f64, Vec<f64>)> = (0..=d)
        .map(|i| {
            let mut x = x0.to_vec();
            if i > 0 {
                x[i - 1] += 0.5;
            }
            (f(&x), x)
        })
        .collect();
    let mut used = d + 1;
    let point = |c: &[f64], w: &[f64], t: f64| -> Vec<f64> {
        c.iter().zip(w).map(|(a, b)| a + t * (b - a)).collect()
    };
    while used < evals {
        simplex.sort_by(|a, b| a.0.total_cmp(&b.0));
        let worst = simplex[d].clone();
        let centroid: Vec<f64> = (0..d)
            .map(|k| simplex[..d].iter().map(|(_, x)| x[k]).sum::<f64>() / d as f64)
            .collect();
        let reflected = point(&centroid, &worst.1, -1.0);
        let fr = f(&reflected);
        used += 1;
        if fr < simplex[0].0 {
            let expanded = point(&centroid, &worst.1, -2.0);
            let fe = f(&expanded);
            used += 1;
            simplex[d] = if fe < fr {
                (fe, expanded)
            } else {
                (fr, reflected)
            };
        } else if fr < simplex[d - 1].0 {
            simplex[d] = (fr, reflected);
        } else {
            let contracted = point(&centroid, &worst.1, 0.5);
            let fc = f(&contracted);
            used += 1;
            if fc < worst.0 {
                simplex[d] = (fc, contracted);
            } else {
                // Shrink towards the best vertex.
                let best = simplex[0].1.clone();
                for v in simplex.iter_mut().skip(1) {
                    let x = point(&best, &v.1, 0.5);
                    *v = (f(&x), x);
                }
                used += d;
            }
        }
    }
    simplex
        .into_iter()
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, x)| x)
        .unwrap_or_else(|| x0.to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_condition_bound_is_exact_for_diagonal_and_full_metrics() {
        // Diagonal: the ratio of the extreme diagonal entries.
        assert!(conditioned(&[1.0, 0.0, 0.0, 1e4], 2));
        assert!(!conditioned(&[1.0, 0.0, 0.0, 1.0001e4], 2));
        assert!(!conditioned(&[1.0, 0.0, 0.0, 0.0], 2));
        // [[a, b], [b, a]] has the eigenvalues a - b and a + b: a = 1, b = 0.9998 gives
        // 1.9998 / 0.0002 = 9999, b = 0.99985 gives 13332.3.
        assert!(conditioned(&[1.0, 0.9998, 0.9998, 1.0], 2));
        assert!(!conditioned(&[1.0, 0.99985, 0.99985, 1.0], 2));
        // Not positive definite.
        assert!(!conditioned(&[1.0, 2.0, 2.0, 1.0], 2));
    }
}
