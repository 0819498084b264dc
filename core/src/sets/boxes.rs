//! Boxes `[lo, hi]` and their P-balls: certified membership of `[lo, hi] (+) B_P(r)`, through
//! the box's point nearest in the metric.

use super::parallelotope::quad_form_at_most;
use crate::interval::Interval;

/// Whether `x` lies in `[lo, hi] (+) B_P(r)` (`p` the `n x n` metric, row-major): `true` only
/// if certainly (a point `y` of the box, found by projected coordinate descent, is certified in
/// interval arithmetic to satisfy `|x - y|_P <= r`).
pub(crate) fn box_contains(p: &[f64], n: usize, x: &[f64], lo: &[f64], hi: &[f64], r: f64) -> bool {
    let p = rows(p, n);
    let mut y = vec![0.0; n];
    nearest_in_box(&p, x, lo, hi, &mut y);
    let d: Vec<Interval> = x
        .iter()
        .zip(&y)
        .map(|(&a, &b)| Interval::point(a) - Interval::point(b))
        .collect();
    quad_form_at_most(&p, &d, r)
}

/// A row-major `n x n` matrix by rows.
pub(super) fn rows(m: &[f64], n: usize) -> Vec<Vec<f64>> {
    m.chunks(n).map(<[f64]>::to_vec).collect()
}

/// A point `y` of the box `[lo, hi]` near the minimiser of `(y - x)' P (y - x)` (projected
/// coordinate descent; the problem is convex, and any point of the box is a valid candidate, so
/// a few sweeps suffice).
///
/// A sweep is a function of `y`'s bits alone: once one leaves them all unchanged, so would the
/// rest of the 50, and the loop stops there with the same point (the Monte Carlo check calls
/// this for every sample state near a set's boundary, most of which converge in a few sweeps).
pub(super) fn nearest_in_box(p: &[Vec<f64>], x: &[f64], lo: &[f64], hi: &[f64], y: &mut [f64]) {
    let n = x.len();
    for i in 0..n {
        y[i] = x[i].clamp(lo[i], hi[i]);
    }
    for _ in 0..50 {
        let mut moved = false;
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
                let yi = yi.clamp(lo[i], hi[i]);
                moved |= yi.to_bits() != y[i].to_bits();
                y[i] = yi;
            }
        }
        if !moved {
            break;
        }
    }
}
