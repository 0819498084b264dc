//! Coordinate transforms `y = T x` of the interval method: the box lives in `y`, the
//! deterministic reachable set in `x` is the parallelotope `{x : T x in box} = T^-1 box`.
//!
//! `T` is exact (the spec's floats). Its inverse is only known approximately (`S`, computed by
//! the compiler), so everything mapping back to `x` uses a rigorous enclosure `T^-1 in S +- e`:
//! with `R = I - S T` (interval), `T^-1 = (I - R)^-1 S`, hence
//! `|T^-1 - S|_inf <= |R|_inf |S|_inf / (1 - |R|_inf)`, which bounds every entry.

use super::RunError;
use crate::interval::Interval;
use crate::model::{Transform, TransformSource};
use crate::prs::TransformUsed;

/// A transform ready for the engine: `T` and an enclosure of `T^-1`, both n x n row-major.
#[derive(Clone, Debug)]
pub(crate) struct Frame {
    n: usize,
    t: Vec<f64>,
    /// `S` as given.
    s: Vec<f64>,
    /// Entry-wise enclosure of the exact `T^-1`: `S +- e`.
    t_inv: Vec<Interval>,
    /// The entry bound `e`.
    e: f64,
    /// Where `T` comes from (carried to the result).
    source: TransformSource,
}

/// `sum_j a_j v_j` in interval arithmetic.
fn dot(a: &[Interval], v: &[Interval]) -> Interval {
    a.iter()
        .zip(v)
        .fold(Interval::ZERO, |acc, (&x, &y)| acc + x * y)
}

/// Upper bound of the induced infinity norm (max row sum of magnitudes).
fn inf_norm(a: &[Interval], n: usize) -> f64 {
    a.chunks(n)
        .map(|row| {
            row.iter()
                .fold(Interval::ZERO, |acc, x| acc + Interval::point(x.mag()))
                .hi()
        })
        .fold(0.0, f64::max)
}

impl Frame {
    /// Checks the transform's dimensions and encloses `T^-1`.
    pub(crate) fn new(tr: &Transform, n: usize) -> Result<Frame, RunError> {
        if tr.matrix.len() != n * n || tr.inverse.len() != n * n {
            return Err(RunError::Invalid(format!(
                "the transform must be {n} x {n} (it has {} entries, its inverse {})",
                tr.matrix.len(),
                tr.inverse.len()
            )));
        }
        if tr.matrix.iter().chain(&tr.inverse).any(|v| !v.is_finite()) {
            return Err(RunError::Invalid(
                "the transform or its inverse has non-finite entries".into(),
            ));
        }
        let pt = |v: &[f64]| -> Vec<Interval> { v.iter().map(|&x| Interval::point(x)).collect() };
        let (ti, si) = (pt(&tr.matrix), pt(&tr.inverse));
        // R = I - S T.
        let mut r = vec![Interval::ZERO; n * n];
        for i in 0..n {
            for j in 0..n {
                let st = (0..n).fold(Interval::ZERO, |acc, k| acc + si[i * n + k] * ti[k * n + j]);
                let id = if i == j {
                    Interval::ONE
                } else {
                    Interval::ZERO
                };
                r[i * n + j] = id - st;
            }
        }
        let norm_r = inf_norm(&r, n);
        if norm_r >= 0.5 {
            return Err(RunError::Invalid(format!(
                "the transform's inverse is inaccurate (|I - T^-1 T| = {norm_r:.3e}): T is too \
                 ill-conditioned"
            )));
        }
        let e = if norm_r == 0.0 {
            0.0
        } else {
            (Interval::point(norm_r) * Interval::point(inf_norm(&si, n))
                / (Interval::ONE - Interval::point(norm_r)))
            .hi()
        };
        let pm = Interval::new(-e, e);
        Ok(Frame {
            n,
            t: tr.matrix.clone(),
            t_inv: tr
                .inverse
                .iter()
                .map(|&s| Interval::point(s) + pm)
                .collect(),
            s: tr.inverse.clone(),
            e,
            source: tr.source,
        })
    }

    /// The interval hull of `T [lo, hi]`: the initial box in `y` (sound: `T` is exact).
    pub(crate) fn to_y(&self, lo: &[f64], hi: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let bx: Vec<Interval> = lo
            .iter()
            .zip(hi)
            .map(|(&a, &b)| Interval::new(a, b))
            .collect();
        let t: Vec<Interval> = self.t.iter().map(|&v| Interval::point(v)).collect();
        t.chunks(self.n)
            .map(|row| dot(row, &bx))
            .map(|v| (v.lo(), v.hi()))
            .unzip()
    }

    /// The interval hull of the parallelotope `T^-1 [lo, hi]` (a box in `x`).
    pub(crate) fn x_hull(&self, lo: &[f64], hi: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let bx: Vec<Interval> = lo
            .iter()
            .zip(hi)
            .map(|(&a, &b)| Interval::new(a, b))
            .collect();
        self.t_inv
            .chunks(self.n)
            .map(|row| dot(row, &bx))
            .map(|v| (v.lo(), v.hi()))
            .unzip()
    }

    /// Upper bound of `max a.x` over the parallelotope `T^-1 [lo, hi]`: `a.x = (T^-T a).y`.
    pub(crate) fn support(&self, a: &[f64], lo: &[f64], hi: &[f64]) -> f64 {
        let n = self.n;
        (0..n)
            .fold(Interval::ZERO, |acc, j| {
                let v = (0..n).fold(Interval::ZERO, |s, i| {
                    s + Interval::point(a[i]) * self.t_inv[i * n + j]
                });
                let y = Interval::new(lo[j], hi[j]);
                acc + Interval::point((v * y).hi())
            })
            .hi()
    }

    /// Whether `|x - T^-1 y|_P^2 <= r^2` certainly (interval arithmetic), `p` by rows.
    pub(crate) fn certify(&self, p: &[Vec<f64>], x: &[f64], y: &[f64], r: f64) -> bool {
        with_buffer(self.n, Interval::ZERO, |d| {
            for ((di, row), &xi) in d.iter_mut().zip(self.t_inv.chunks(self.n)).zip(x) {
                // `dot(row, y)` with `y` as point intervals.
                let ty = row
                    .iter()
                    .zip(y)
                    .fold(Interval::ZERO, |acc, (&a, &b)| acc + a * Interval::point(b));
                *di = Interval::point(xi) - ty;
            }
            quad_form_at_most(p, d, r)
        })
    }

    /// `T x` in floating point, into `out`: where to look for the point of the y-box nearest
    /// to `x` (any point found is then certified by [`Frame::certify`]).
    pub(crate) fn to_y_point(&self, x: &[f64], out: &mut [f64]) {
        let n = self.n;
        for (i, o) in out.iter_mut().enumerate().take(n) {
            *o = (0..n).map(|j| self.t[i * n + j] * x[j]).sum();
        }
    }

    /// The metric `S' P S` of `y`, in floating point (with [`Frame::to_y_point`], the
    /// problem of the nearest point of a y-box).
    pub(crate) fn y_metric(&self, p: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let n = self.n;
        let s = |i: usize, j: usize| self.s[i * n + j];
        (0..n)
            .map(|a| {
                (0..n)
                    .map(|b| {
                        (0..n)
                            .flat_map(|i| (0..n).map(move |j| (i, j)))
                            .map(|(i, j)| s(i, a) * p[i][j] * s(j, b))
                            .sum()
                    })
                    .collect()
            })
            .collect()
    }

    /// The transform as used, for the result.
    pub(crate) fn used(&self) -> TransformUsed {
        TransformUsed {
            matrix: self.t.clone(),
            inverse: self.s.clone(),
            inverse_error: self.e,
            source: self.source,
        }
    }
}

/// `f` of a buffer of `n` values `zero`: on the stack for small `n` (the Monte Carlo check
/// calls the exact tests for many states; no allocation each time).
pub(crate) fn with_buffer<T: Copy, R>(n: usize, zero: T, f: impl FnOnce(&mut [T]) -> R) -> R {
    const SMALL: usize = 8;
    if n <= SMALL {
        f(&mut [zero; SMALL][..n])
    } else {
        f(&mut vec![zero; n])
    }
}

/// Whether `x` certainly lies in the parallelotope `{x : lo <= T x <= hi}`, `T` by rows (`T`
/// is exact, so no inverse is involved).
pub(crate) fn inside(t: &[Vec<f64>], x: &[f64], lo: &[f64], hi: &[f64]) -> bool {
    t.iter().zip(lo.iter().zip(hi)).all(|(row, (&a, &b))| {
        let y = row.iter().zip(x).fold(Interval::ZERO, |acc, (&tij, &xj)| {
            acc + Interval::point(tij) * Interval::point(xj)
        });
        a <= y.lo() && y.hi() <= b
    })
}

/// Whether `d' P d <= r^2` certainly, for an interval vector `d` and `P` by rows.
pub(crate) fn quad_form_at_most(p: &[Vec<f64>], d: &[Interval], r: f64) -> bool {
    let n = d.len();
    let mut q = Interval::ZERO;
    for i in 0..n {
        for j in 0..n {
            q += Interval::point(p[i][j]) * d[i] * d[j];
        }
    }
    q.hi() <= Interval::point(r).sqr().lo()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pendulum() -> Frame {
        Frame::new(
            &Transform {
                matrix: vec![1.0, 0.2, 1.0, 0.0],
                inverse: vec![0.0, 1.0, 5.0, -5.0],
                frame: 0,
                source: TransformSource::Given,
            },
            2,
        )
        .unwrap()
    }

    #[test]
    fn inverse_enclosure_contains_the_exact_inverse() {
        // The float 0.2 is 0.2 + 1.1e-17, so the exact inverse's second row is
        // (1/0.2f, -1/0.2f) = (5 - 2.8e-16, ...): not S, but within e of it.
        let f = pendulum();
        assert!(f.e > 0.0 && f.e < 1e-14, "e = {}", f.e);
        let exact = 1.0 / 0.2_f64; // rounded; the exact value differs from 5 by ~2.8e-16
        assert!(f.t_inv[2].contains(exact) && f.t_inv[2].contains(5.0));
        assert!(f.t_inv[3].contains(-5.0));
        // An exactly invertible T (a permutation) gets e = 0.
        let p = Frame::new(
            &Transform {
                matrix: vec![0.0, 1.0, 1.0, 0.0],
                inverse: vec![0.0, 1.0, 1.0, 0.0],
                frame: 0,
                source: TransformSource::Given,
            },
            2,
        )
        .unwrap();
        assert_eq!(p.e, 0.0);
    }

    #[test]
    fn initial_box_hull_and_support() {
        let f = pendulum();
        let a = std::f64::consts::PI / 10.0;
        let (lo, hi) = f.to_y(&[-a, -0.2], &[a, 0.2]);
        // y1 = theta + 0.2 omega in +-(pi/10 + 0.04), y2 = theta in +-pi/10.
        assert!(hi[0] >= a + 0.04 && hi[0] - (a + 0.04) < 1e-15);
        assert!(lo[1] == -a && hi[1] == a);
        // Back to x: the hull contains X0 (the parallelotope T^-1 T X0 does).
        let (xlo, xhi) = f.x_hull(&lo, &hi);
        assert!(xlo[0] <= -a && xhi[0] >= a && xlo[1] <= -0.2 && xhi[1] >= 0.2);
        // max theta over the parallelotope is max y2 = pi/10 (not the hull's looser bound).
        let s = f.support(&[1.0, 0.0], &lo, &hi);
        assert!(s >= a && s - a < 1e-14, "{s}");
    }

    #[test]
    fn certify_distance() {
        let f = pendulum();
        let p = vec![vec![1.0, 0.0], vec![0.0, 1.0]];
        // y = (0.2, 0) is x = T^-1 y = (0, 1).
        assert!(f.certify(&p, &[0.0, 1.5], &[0.2, 0.0], 0.5 + 1e-12));
        assert!(!f.certify(&p, &[0.0, 1.5], &[0.2, 0.0], 0.5 - 1e-12));
        // x = (0, 1) is T^-1 (0.2, 0): inside a box around (0.2, 0), outside one next to it.
        let t = [vec![1.0, 0.2], vec![1.0, 0.0]];
        assert!(inside(&t, &[0.0, 1.0], &[0.1, -0.1], &[0.3, 0.1]));
        assert!(!inside(&t, &[0.0, 1.0], &[0.21, -0.1], &[0.3, 0.1]));
    }
}
