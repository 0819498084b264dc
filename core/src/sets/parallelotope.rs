//! Coordinate transforms `y = T x` of the interval method: the box lives in `y`, the
//! deterministic reachable set in `x` is the parallelotope `{x : T x in box} = T^-1 box`.
//!
//! `T` is exact (the spec's floats). Its inverse is only known approximately (`S`, computed by
//! the compiler), so everything mapping back to `x` uses a rigorous enclosure `T^-1 in S +- e`:
//! with `R = I - S T` (interval), `T^-1 = (I - R)^-1 S`, hence
//! `|T^-1 - S|_inf <= |R|_inf |S|_inf / (1 - |R|_inf)`, which bounds every entry.
//!
//! Here too: certified membership of `T^-1 [lo, hi] (+) B_P(r)` ([`parallelotope_contains`],
//! and [`ParallelotopeTest`] with the work per metric and transform done once), which the
//! results' `contains` and the Monte Carlo check ask.

use super::boxes::{nearest_in_box, rows};
use crate::engine::{Detail, Problem, RunError, Setting};
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
            return Err(RunError::Invalid(
                Detail::from(Problem::TransformSize {
                    n,
                    matrix: tr.matrix.len(),
                    inverse: tr.inverse.len(),
                })
                .at_setting(Setting::Transform),
            ));
        }
        if tr.matrix.iter().chain(&tr.inverse).any(|v| !v.is_finite()) {
            return Err(RunError::Invalid(
                Detail::from(Problem::TransformNotFinite).at_setting(Setting::Transform),
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
            return Err(RunError::Invalid(
                Detail::from(Problem::TransformIllConditioned(norm_r))
                    .at_setting(Setting::Transform),
            ));
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

    /// Whether [`Frame::certify`] answers `true` for these arguments, decided in floating
    /// point without interval arithmetic (`false` says nothing): `q = |x - S y|_P^2` clearly
    /// below `r^2`, by more than a bound on how far `certify`'s upper bound of `q` can lie
    /// above the computed one (the Monte Carlo check asks this first for the states near a
    /// parallelotope's boundary, most of which it settles at a fraction of the cost).
    ///
    /// The bound: `certify`'s `d_i = x_i - sum_j (S_ij +- e) y_j` lies within
    /// `w_i = e sum_j |y_j| + c1 (a_i + e sum_j |y_j|)` of the computed `d_i`, with `a_i` the
    /// magnitude `|x_i| + sum_j |S_ij y_j|` and `c1 = 16 (n + 2) eps` (at most one ulp per
    /// operation of `n + 2` in both computations, eight times over; the smallest normal
    /// number covers underflow). Its quadratic form's upper end is then at most
    /// `q + sum |P_ij| (|d_i| w_j + w_i |d_j| + w_i w_j)` plus the roundings of both sums,
    /// within `c2 sum |P_ij| (|d_i| + w_i)(|d_j| + w_j)`, `c2 = 16 (n^2 + 4) eps`; and
    /// `r^2 (1 - 4 eps)` lies below `certify`'s lower bound of `r^2`.
    pub(crate) fn clearly_within(&self, p: &[Vec<f64>], x: &[f64], y: &[f64], r: f64) -> bool {
        let n = self.n;
        let eps = f64::EPSILON;
        let c1 = 16.0 * (n as f64 + 2.0) * eps;
        let c2 = 16.0 * ((n * n) as f64 + 4.0) * eps;
        let ey = self.e * y.iter().map(|v| v.abs()).sum::<f64>();
        with_buffer(2 * n, 0.0, |buf| {
            let (d, w) = buf.split_at_mut(n);
            for (i, row) in self.s.chunks_exact(n).enumerate() {
                let (mut s, mut a) = (0.0, x[i].abs());
                for (&sij, &yj) in row.iter().zip(y) {
                    let t = sij * yj;
                    s += t;
                    a += t.abs();
                }
                d[i] = x[i] - s;
                w[i] = ey + c1 * (a + ey) + f64::MIN_POSITIVE;
            }
            let (mut q, mut g, mut h) = (0.0, 0.0, 0.0);
            for (i, row) in p.iter().enumerate() {
                let (di, wi) = (d[i].abs(), w[i]);
                for (j, &pij) in row.iter().enumerate() {
                    let (dj, wj, pa) = (d[j].abs(), w[j], pij.abs());
                    q += pij * d[i] * d[j];
                    g += pa * (di * wj + wi * dj + wi * wj);
                    h += pa * (di + wi) * (dj + wj);
                }
            }
            let upper = q + 4.0 * eps * q.abs() + g * (1.0 + c2) + c2 * h;
            upper < r * r * (1.0 - 4.0 * eps)
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
        // Clearly outside in floating point first (the common answer where this is asked):
        // the sum lies within `n eps s` of the exact `(T x)_i`, `s = sum_j |t_ij x_j|`, so a
        // margin of `4 (n + 2) eps s` (and the smallest normal number, for underflow) puts the
        // exact value, and the enclosure's end nearest the box, outside `[a, b]` too.
        let (mut y, mut s) = (0.0, 0.0);
        for (&tij, &xj) in row.iter().zip(x) {
            let p = tij * xj;
            y += p;
            s += p.abs();
        }
        let margin = 4.0 * (row.len() as f64 + 2.0) * f64::EPSILON * s + f64::MIN_POSITIVE;
        if y + margin < a || y - margin > b {
            return false;
        }
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

/// Whether `x` lies in `T^-1 [lo, hi] (+) B_P(r)` for the transform `tr`: `true` only if
/// certainly (inside the parallelotope, or a point `y` of the box certified to satisfy
/// `|x - T^-1 y|_P <= r`).
pub(crate) fn parallelotope_contains(
    p: &[f64],
    tr: &TransformUsed,
    x: &[f64],
    lo: &[f64],
    hi: &[f64],
    r: f64,
) -> bool {
    ParallelotopeTest::new(p, tr, x.len()).contains(x, lo, hi, r)
}

/// [`parallelotope_contains`] for one metric and transform, with everything that depends on
/// them alone (the enclosure of `T^-1` and the metric in `y`) computed once: the same answers,
/// for callers that test many states (the Monte Carlo check).
#[derive(Clone, Debug)]
pub(crate) struct ParallelotopeTest {
    /// `T` by rows.
    t: Vec<Vec<f64>>,
    /// `P` by rows.
    p: Vec<Vec<f64>>,
    /// `T` with its inverse's enclosure and the metric `S' P S` of `y`; `None` when the
    /// transform cannot be used (then only the parallelotope itself is certain).
    frame: Option<(Frame, Vec<Vec<f64>>)>,
}

impl ParallelotopeTest {
    /// For the metric `p` (`n x n` row-major) and the transform `tr`.
    pub(crate) fn new(p: &[f64], tr: &TransformUsed, n: usize) -> Self {
        let transform = crate::model::Transform {
            matrix: tr.matrix.clone(),
            inverse: tr.inverse.clone(),
            frame: 0,
            source: tr.source,
        };
        let p = rows(p, n);
        let frame = Frame::new(&transform, n).ok().map(|f| {
            let q = f.y_metric(&p);
            (f, q)
        });
        ParallelotopeTest {
            t: rows(&tr.matrix, n),
            p,
            frame,
        }
    }

    /// Whether `x` lies in `T^-1 [lo, hi] (+) B_P(r)` (see [`parallelotope_contains`]).
    pub(crate) fn contains(&self, x: &[f64], lo: &[f64], hi: &[f64], r: f64) -> bool {
        // Inside the parallelotope (the common case): distance 0, no inverse needed.
        if inside(&self.t, x, lo, hi) {
            return true;
        }
        let Some((f, q)) = &self.frame else {
            return false;
        };
        // In y the distance is |y - T x|_Q with Q = T^-T P T^-1 (approximately).
        let n = x.len();
        with_buffer(2 * n, 0.0, |buf| {
            let (tx, y) = buf.split_at_mut(n);
            f.to_y_point(x, tx);
            nearest_in_box(q, tx, lo, hi, y);
            // Floating point first: it says `true` only where `certify` would, and settles
            // most of the states the Monte Carlo check asks about without interval arithmetic.
            f.clearly_within(&self.p, x, y, r) || f.certify(&self.p, x, y, r)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng::Rng;

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

    /// The inverse of a row-major `n x n` matrix in floating point (Gauss-Jordan with partial
    /// pivoting): an approximate `S`, as the compiler gives.
    fn inverse(m: &[f64], n: usize) -> Vec<f64> {
        let mut a: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                let mut row = m[i * n..][..n].to_vec();
                row.extend((0..n).map(|j| f64::from(u8::from(i == j))));
                row
            })
            .collect();
        for c in 0..n {
            let piv = (c..n)
                .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
                .unwrap();
            a.swap(c, piv);
            let d = a[c][c];
            a[c].iter_mut().for_each(|v| *v /= d);
            for i in (0..n).filter(|&i| i != c) {
                let f = a[i][c];
                let pivot_row = a[c].clone();
                a[i].iter_mut()
                    .zip(&pivot_row)
                    .for_each(|(v, p)| *v -= f * p);
            }
        }
        a.iter().flat_map(|row| row[n..].to_vec()).collect()
    }

    #[test]
    fn clearly_within_implies_certify_and_is_nearly_as_tight() {
        let mut rng = Rng(7);
        let mut rnd = || rng.range(-1.0, 1.0);
        let (mut settled, mut cases) = (0, 0);
        for case in 0..2000 {
            let n = 1 + case % 4;
            // A transform near the identity with an inexact inverse (e > 0), and a metric
            // `A' A + I / 2` with off-diagonal terms.
            let t: Vec<f64> = (0..n * n)
                .map(|k| f64::from(u8::from(k % (n + 1) == 0)) + 0.3 * rnd())
                .collect();
            let inv = inverse(&t, n);
            let Ok(f) = Frame::new(
                &Transform {
                    matrix: t,
                    inverse: inv,
                    frame: 0,
                    source: TransformSource::Given,
                },
                n,
            ) else {
                continue;
            };
            let a: Vec<f64> = (0..n * n).map(|_| rnd()).collect();
            let p: Vec<Vec<f64>> = (0..n)
                .map(|i| {
                    (0..n)
                        .map(|j| {
                            let aa: f64 = (0..n).map(|k| a[k * n + i] * a[k * n + j]).sum();
                            aa + if i == j { 0.5 } else { 0.0 }
                        })
                        .collect()
                })
                .collect();
            let scale = 10f64.powf(4.0 * rnd());
            let x: Vec<f64> = (0..n).map(|_| scale * rnd()).collect();
            let y: Vec<f64> = (0..n).map(|_| scale * rnd()).collect();
            // The smallest radius `certify` accepts, to a relative 1e-15 (bisection).
            let (mut lo, mut hi) = (0.0, 10.0 * scale * (n as f64));
            assert!(f.certify(&p, &x, &y, hi));
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if f.certify(&p, &x, &y, mid) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            // Near that radius, "clearly" only where `certify` agrees; a relative 1e-12 above
            // it, "clearly" settles it.
            for k in -40..40 {
                let r = hi * (1.0 + f64::from(k) * 1e-14);
                if f.clearly_within(&p, &x, &y, r) {
                    assert!(f.certify(&p, &x, &y, r), "case {case}: r = {r:e}");
                }
            }
            cases += 1;
            settled += usize::from(f.clearly_within(&p, &x, &y, hi * (1.0 + 1e-12)));
        }
        assert!(cases > 1900, "{cases}");
        assert!(settled * 100 >= cases * 99, "{settled} of {cases}");
    }

    #[test]
    fn inside_answers_as_its_enclosure_does() {
        let mut rng = Rng(11);
        let mut rnd = || rng.range(-1.0, 1.0);
        let mut near = 0;
        for case in 0..20000 {
            let n = 1 + case % 4;
            let rows: Vec<Vec<f64>> = (0..n).map(|_| (0..n).map(|_| rnd()).collect()).collect();
            let x: Vec<f64> = (0..n).map(|_| rnd()).collect();
            // Boxes with an end at the computed `T x` (on the boundary up to rounding), or
            // a little beside it.
            let (mut lo, mut hi) = (vec![0.0; n], vec![0.0; n]);
            for i in 0..n {
                let y: f64 = rows[i].iter().zip(&x).map(|(a, b)| a * b).sum();
                // Up to two ulps either way.
                let mut end = y;
                for _ in 0..(3.0 * rnd()).round() as i32 {
                    end = end.next_up();
                }
                for _ in (3.0 * rnd()).round() as i32..0 {
                    end = end.next_down();
                }
                (lo[i], hi[i]) = if rnd() < 0.0 {
                    (end, y + 1.0)
                } else {
                    (y - 1.0, end)
                };
            }
            let enclosure = rows.iter().zip(lo.iter().zip(&hi)).all(|(row, (&a, &b))| {
                let y = row.iter().zip(&x).fold(Interval::ZERO, |acc, (&t, &v)| {
                    acc + Interval::point(t) * Interval::point(v)
                });
                a <= y.lo() && y.hi() <= b
            });
            assert_eq!(inside(&rows, &x, &lo, &hi), enclosure, "case {case}");
            near += usize::from(!enclosure);
        }
        assert!(near > 1000, "{near}");
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
