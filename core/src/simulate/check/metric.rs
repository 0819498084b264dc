//! The metric's quadratic form `d' P d`, and the sums of squares the hot loops compute
//! with it.

#[cfg(doc)]
use super::Tube;
use crate::lanes::Real;
use crate::simulate::paths::SMALL;

/// The quadratic form `d' P d` as a list of terms.
#[derive(Clone, Debug)]
pub(crate) struct Metric {
    /// `(i, j, w)` with `w = P_ii` on the diagonal and `w = P_ij + P_ji` for `i < j` (both
    /// off-diagonal entries, as `contains` uses them); zero terms dropped.
    terms: Vec<(usize, usize, f64)>,
    /// Bound factor of the rounding error of [`quad`](Self::quad), relative to its `abs_sum`.
    pub(super) gamma: f64,
    /// `P` is diagonal with non-negative entries: every term is non-negative, so the error
    /// bound is relative to `q` itself and the tests reduce to comparisons with per-step
    /// constants.
    pub(super) nonneg: bool,
    /// `|P_ij|`, `n x n` row-major (for bounds of a box's P-radius).
    pub(super) abs: Vec<f64>,
    /// That diagonal (when `nonneg`), one entry per state.
    pub(super) diag: Vec<f64>,
}

impl Metric {
    /// The metric `P`, `n x n` row-major.
    pub(crate) fn new(p: &[f64], n: usize) -> Self {
        let at = |i: usize, j: usize| p[i * n + j];
        let mut terms = Vec::new();
        for i in 0..n {
            if at(i, i) != 0.0 {
                terms.push((i, i, at(i, i)));
            }
            for j in i + 1..n {
                let w = at(i, j) + at(j, i);
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
        let diag = (0..n).map(|i| at(i, i)).collect();
        Metric {
            terms,
            gamma,
            nonneg,
            diag,
            abs: p.iter().map(|v| v.abs()).collect(),
        }
    }

    /// The diagonal `w` of `P` when `P` is diagonal and non-negative: then
    /// [`quad`](Self::quad) returns `(q, q)` with `q = diag_quad(w, x, c)`, which callers may
    /// compute themselves, to the same bits.
    pub(crate) fn nonneg_diagonal(&self) -> Option<&[f64]> {
        self.nonneg.then_some(&self.diag[..])
    }

    /// The terms as a dense upper triangle for models with at most [`SMALL`] states: `w[i *
    /// SMALL + j]` for `i <= j`, zero for the dropped terms (see [`quad_small`]).
    pub(crate) fn upper(&self) -> [f64; SMALL * SMALL] {
        let mut w = [0.0; SMALL * SMALL];
        for &(i, j, v) in &self.terms {
            if i < SMALL && j < SMALL {
                w[i * SMALL + j] = v;
            }
        }
        w
    }

    /// `(q, a)`: `q = (x - c)' P (x - c)` and `a = sum |w_ij d_i d_j|` (for the error bound).
    #[inline(always)]
    pub(crate) fn quad(&self, x: &[f64], c: &[f64]) -> (f64, f64) {
        if self.nonneg {
            let q = diag_quad(&self.diag, x, c);
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

    /// [`quad`](Self::quad) of the difference `d(i)` (`d(i) = x_i - c_i` gives `quad(x, c)`),
    /// the terms in the same order.
    /// Generic over [`Real`]: one path's `f64` or eight paths' lanes, the same operations.
    #[inline(always)]
    pub(super) fn quad_by<T: Real>(&self, d: impl Fn(usize) -> T) -> (T, T) {
        if self.nonneg {
            let q = (0..self.diag.len())
                .map(|i| {
                    let d = d(i);
                    T::from(self.diag[i]) * d * d
                })
                .reduce(|q, t| q + t)
                .unwrap_or(T::from(0.0));
            return (q, q);
        }
        let (mut q, mut a) = (T::from(0.0), T::from(0.0));
        for &(i, j, w) in &self.terms {
            let t = T::from(w) * d(i) * d(j);
            q = q + t;
            a = a + t.abs();
        }
        (q, a)
    }
}

/// `x` moved into `[lo, hi]` (`lo` below, `hi` above, NaN kept: then the difference to `x`
/// is NaN and no shortcut holds). The scalar form of the eight-lane clamp in
/// [`super::super::avx512`], to the bit.
#[inline(always)]
pub(crate) fn clamp(x: f64, lo: f64, hi: f64) -> f64 {
    if x < lo {
        lo
    } else if x > hi {
        hi
    } else {
        x
    }
}

/// `sum_i w_i (x_i - y_i)^2` with `y = clamp(x, lo, hi)`, in [`diag_quad`]'s order: the squared
/// P-distance of `x` to the box `[lo, hi]` for a non-negative diagonal metric `w` (the clamp is
/// the nearest point), as [`Tube`] and the eight-lane loop compute it.
#[inline(always)]
pub(crate) fn diag_quad_to_box(w: &[f64], x: &[f64], lo: &[f64], hi: &[f64]) -> f64 {
    let n = x.len();
    let (w, lo, hi) = (&w[..n], &lo[..n], &hi[..n]);
    (0..n)
        .map(|i| {
            let d = x[i] - clamp(x[i], lo[i], hi[i]);
            w[i] * d * d
        })
        .reduce(|q, t| q + t)
        .unwrap_or(0.0)
}

/// `sum_i w_i (x_i - c_i)^2` over the states of `x` in order, starting from the first term:
/// [`Metric::quad`] with a non-negative diagonal metric `w` (by state rather than by term, so
/// that a constant dimension unrolls the loop).
#[inline(always)]
pub(crate) fn diag_quad(w: &[f64], x: &[f64], c: &[f64]) -> f64 {
    let (w, c) = (&w[..x.len()], &c[..x.len()]);
    (0..x.len())
        .map(|i| {
            let d = x[i] - c[i];
            w[i] * d * d
        })
        .reduce(|q, t| q + t)
        .unwrap_or(0.0)
}

/// [`Metric::quad`] for at most [`SMALL`] states (`x.len()`), with `w` from [`Metric::upper`]:
/// the same terms in the same order, plus the zero ones, which add `+-0` to finite sums (and
/// cannot make a non-finite sum finite), so `(q, a)` is `quad`'s to the bit when finite and
/// non-finite when it is. Fixed-size weights let a small model's loops unroll. Generic over
/// [`Real`]: one path's `f64` or eight paths' lanes, the same operations.
#[inline(always)]
pub(crate) fn quad_small<T: Real>(w: &[f64; SMALL * SMALL], x: &[T], c: &[f64]) -> (T, T) {
    let n = x.len().min(SMALL);
    let (x, c) = (&x[..n], &c[..n]);
    let (mut q, mut a) = (T::from(0.0), T::from(0.0));
    for i in 0..n {
        let di = x[i] - T::from(c[i]);
        for j in i..n {
            let t = T::from(w[i * SMALL + j]) * di * (x[j] - T::from(c[j]));
            q = q + t;
            a = a + t.abs();
        }
    }
    (q, a)
}
