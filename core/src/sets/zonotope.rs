//! Zonotopes `Z = {c + sum_j xi_j g_j : |xi_j| <= 1}` (the first-order sets, method.md 8.8):
//! interval hull, support function, P-radius and membership of `Z (+) B_P(r)`, each rigorous
//! in the direction it is used (hulls and supports rounded outward, membership `true` only
//! when certain). Generators are stored generator-major: `g_j = gens[j n..(j + 1) n]`.

use super::parallelotope::Frame;
use crate::interval::Interval;
use crate::lanes::Real;
use crate::model::{Transform, TransformSource};

/// The interval hull of `Z`: `c_i -+ sum_j |g_ji|`, rounded outward.
pub(crate) fn hull(center: &[f64], gens: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = center.len();
    let mut half = vec![Interval::ZERO; n];
    for g in gens.chunks(n.max(1)) {
        for (h, &v) in half.iter_mut().zip(g) {
            *h += Interval::point(v.abs());
        }
    }
    center
        .iter()
        .zip(&half)
        .map(|(&c, &h)| {
            let c = Interval::point(c);
            ((c - h).lo(), (c + h).hi())
        })
        .unzip()
}

/// An upper bound of `max_{x in Z} a . x = a . c + sum_j |a . g_j|`.
pub(crate) fn support(center: &[f64], gens: &[f64], a: &[f64]) -> f64 {
    let n = center.len();
    let dot = |v: &[f64]| {
        v.iter().zip(a).fold(Interval::ZERO, |acc, (&x, &y)| {
            acc + Interval::point(x) * Interval::point(y)
        })
    };
    let mut s = dot(center);
    for g in gens.chunks(n.max(1)) {
        s += Interval::point(dot(g).mag());
    }
    s.hi()
}

/// An upper bound of `max_{x in Z} |x - c|_P <= sum_j |g_j|_P` (`p` row-major `n x n`).
pub(crate) fn p_radius(p: &[f64], n: usize, gens: &[f64]) -> f64 {
    let mut r = Interval::ZERO;
    for g in gens.chunks(n.max(1)) {
        let mut q = Interval::ZERO;
        for i in 0..n {
            for j in 0..n {
                q += Interval::point(p[i * n + j]) * Interval::point(g[i]) * Interval::point(g[j]);
            }
        }
        r += Interval::new(0.0, q.hi().max(0.0)).sqrt();
    }
    r.hi()
}

/// Whether `x` lies in `Z (+) B_P(r)`: `true` only if certainly (see [`ZonotopeTest`], built
/// here for one question).
pub(crate) fn contains(p: &[f64], x: &[f64], center: &[f64], gens: &[f64], r: f64) -> bool {
    ZonotopeTest::new(p, center, gens).contains(x, r)
}

/// [`contains`] for one zonotope and metric, with everything that depends on them alone
/// computed once: the same answers, for callers that test many states (the Monte Carlo check).
///
/// `x` lies in `Z (+) B_P(r)` when one of two tests certifies it:
///
/// - [`ZonotopeTest::excess`] (no interval arithmetic, `O(n^2)`): when `n` of the generators
///   form a basis `G_S` (all of them for `n` generators), `x = c + G_S xi` for one `xi`, and
///   `z = c + G_S clamp(xi, -1, 1)` is a point of `Z` with
///   `|x - z|_P <= sum_s max(|xi_s| - 1, 0) |g_s|_P`: 0 inside `c + G_S [-1, 1]^n`, exact for
///   a point beyond one face. `xi` is computed in floating point with an approximate inverse
///   `M` of `G_S`, whose error `|G_S^-1 - M| <= e` entry-wise is enclosed as for a coordinate
///   transform (interval residual `I - M G_S`, see `parallelotope.rs`), every rounding bounded.
/// - a point `z = c + G xi` of `Z` near `x` in the metric, the minimiser of the convex
///   quadratic `|x - c - G xi|_P^2` over the cube (primal active-set steps from the clamped
///   `M (x - c)` or 0, [`nearest_in_cube`]; projected coordinate descent where they stop short),
///   certified to satisfy `|x - z|_P <= r` in floating point with a bound on every rounding
///   ([`ZonotopeTest::clearly_within`]), or failing that in interval arithmetic (`z` evaluated as
///   an interval, so rounding cannot put it outside `Z`).
#[derive(Clone, Debug)]
pub(crate) struct ZonotopeTest {
    /// `P`, `n x n` row-major.
    p: Vec<f64>,
    center: Vec<f64>,
    /// Generator-major, as in [`DetSet::Zonotope`](crate::prs::DetSet::Zonotope).
    gens: Vec<f64>,
    /// `G' P G`, `k x k` row-major (floating point: only the descent's candidate depends on it).
    q: Vec<f64>,
    /// `P g_j`, generator-major.
    pg: Vec<f64>,
    /// The basis of [`ZonotopeTest::excess`]; `None` with fewer than `n` generators, or none
    /// well-conditioned enough.
    basis: Option<Basis>,
}

/// `n` generators of a zonotope forming a basis, with what [`ZonotopeTest::excess`] needs.
#[derive(Clone, Debug)]
struct Basis {
    /// Their indices `S` among the generators.
    idx: Vec<usize>,
    /// `M`, approximately `G_S^-1`, `n x n` row-major (row `i`: the coefficient of `g_idx[i]`).
    m: Vec<f64>,
    /// `e (1 + rel)`, rounded up, with `e` a bound of every entry of `G_S^-1 - M`.
    e: f64,
    /// Half an upper bound of `|g_s|_P` per basis generator, at least `1e-270` (so products
    /// with the excess, at least `2^-52` when positive, stay normal).
    half_norms: Vec<f64>,
    /// `16 (n + 2) eps`: the rounding margin relative to the magnitudes involved.
    rel: f64,
}

impl Basis {
    /// A basis of `n` of the generators `gens` (chosen by Gaussian elimination with complete
    /// pivoting: the largest pivot first) and its inverse, or `None` when there are fewer than
    /// `n`, or the inverse cannot be enclosed (`|I - M G_S|_inf >= 1/2`).
    fn new(p: &[f64], gens: &[f64], n: usize) -> Option<Basis> {
        let k = gens.len() / n;
        if k < n {
            return None;
        }
        // A[i][j] = component i of generator j, eliminated in place.
        let mut a: Vec<f64> = (0..n * k).map(|v| gens[(v % k) * n + v / k]).collect();
        let (mut rows, mut idx) = (vec![false; n], Vec::with_capacity(n));
        for _ in 0..n {
            let mut best: Option<(usize, usize, f64)> = None;
            for i in (0..n).filter(|&i| !rows[i]) {
                for j in (0..k).filter(|j| !idx.contains(j)) {
                    let v = a[i * k + j].abs();
                    if best.is_none_or(|(_, _, b)| v > b) {
                        best = Some((i, j, v));
                    }
                }
            }
            let (i, j, v) = best?;
            if !(v > 0.0 && v.is_finite()) {
                return None;
            }
            for r in (0..n).filter(|&r| !rows[r] && r != i) {
                let f = a[r * k + j] / a[i * k + j];
                for c in 0..k {
                    a[r * k + c] -= f * a[i * k + c];
                }
            }
            rows[i] = true;
            idx.push(j);
        }
        idx.sort_unstable();
        let g_s: Vec<f64> = (0..n * n).map(|v| gens[idx[v % n] * n + v / n]).collect();
        let m = inverse(&g_s, n)?;
        let frame = Frame::new(
            &Transform {
                matrix: g_s,
                inverse: m.clone(),
                frame: 0,
                source: TransformSource::Given,
            },
            n,
        )
        .ok()?;
        let rel = 16.0 * (n as f64 + 2.0) * f64::EPSILON;
        let e = (Interval::point(frame.used().inverse_error) * Interval::point(1.0 + rel)).hi();
        let half_norms = idx
            .iter()
            .map(|&j| (0.5 * p_radius(p, n, &gens[j * n..(j + 1) * n])).max(1e-270))
            .collect();
        Some(Basis {
            idx,
            m,
            e,
            half_norms,
            rel,
        })
    }
}

/// The inverse of the row-major `n x n` matrix `a` in floating point (Gauss-Jordan with partial
/// pivoting), `None` if a pivot is 0 or a result not finite.
fn inverse(a: &[f64], n: usize) -> Option<Vec<f64>> {
    // [A | I], reduced to [I | A^-1].
    let w = 2 * n;
    let mut t: Vec<f64> = (0..n * w)
        .map(|v| {
            let (i, j) = (v / w, v % w);
            if j < n {
                a[i * n + j]
            } else {
                f64::from(u8::from(j - n == i))
            }
        })
        .collect();
    for c in 0..n {
        let piv = (c..n).max_by(|&i, &j| t[i * w + c].abs().total_cmp(&t[j * w + c].abs()))?;
        for j in 0..w {
            t.swap(c * w + j, piv * w + j);
        }
        let d = t[c * w + c];
        if d == 0.0 {
            return None;
        }
        for j in 0..w {
            t[c * w + j] /= d;
        }
        for i in (0..n).filter(|&i| i != c) {
            let f = t[i * w + c];
            for j in 0..w {
                t[i * w + j] -= f * t[c * w + j];
            }
        }
    }
    let inv: Vec<f64> = (0..n * n).map(|v| t[(v / n) * w + n + v % n]).collect();
    inv.iter().all(|v| v.is_finite()).then_some(inv)
}

impl ZonotopeTest {
    /// For the metric `p` (`n x n` row-major) and the zonotope with centre `center` (`n`
    /// values) and generators `gens` (generator-major).
    pub(crate) fn new(p: &[f64], center: &[f64], gens: &[f64]) -> Self {
        let n = center.len();
        let k = gens.len() / n.max(1);
        // P g_j and G' P G, in floating point (only the candidate depends on them).
        let pg: Vec<f64> = (0..k)
            .flat_map(|j| {
                let g = &gens[j * n..(j + 1) * n];
                (0..n).map(move |i| (0..n).map(|l| p[i * n + l] * g[l]).sum::<f64>())
            })
            .collect();
        let q: Vec<f64> = (0..k)
            .flat_map(|a| {
                let pg = &pg;
                (0..k).map(move |b| (0..n).map(|i| gens[a * n + i] * pg[b * n + i]).sum::<f64>())
            })
            .collect();
        ZonotopeTest {
            p: p.to_vec(),
            center: center.to_vec(),
            gens: gens.to_vec(),
            q,
            pg,
            basis: if n == 0 { None } else { Basis::new(p, gens, n) },
        }
    }

    /// An upper bound of the P-distance from `x` to `Z` by the basis (see [`ZonotopeTest`]):
    /// `excess(x) <= r` proves `x` in `Z (+) B_P(r)` (0 for `x` in `c + G_S [-1, 1]^n` farther
    /// than the rounding margins from its faces, so a radius 0 accepts it; NaN for a state with
    /// a NaN, `+inf` without a basis). Generic over [`Real`]: one state's `f64` or eight states' lanes, the same
    /// operations per lane.
    ///
    /// Per row `i`, with `d = x - c` rounded: `y = sum_j M_ij d_j` lies within
    /// `(n + 3) u s`, `s = sum_j |M_ij d_j|`, of `sum_j M_ij (x_j - c_j)`, which lies within
    /// `e |d|_1` of `xi_i` (`u` the unit roundoff, every rounding of `s` and `|d|_1` counted);
    /// `a = |y| + rel (s + 1) + e' |d|_1 - 1` (`rel = 16 (n + 2) eps`, `e' = e (1 + rel)`)
    /// then bounds `|xi_i| - 1` including its own roundings (the `+ 1` covers those of the
    /// subtraction), the smallest normal number covering underflow. `(a + |a|) / 2` is
    /// `max(a, 0)` (and NaN for NaN), the products with `|g_s|_P / 2` and their sum are
    /// rounded up by the final factor `1 + rel`.
    #[inline(always)]
    pub(crate) fn excess<T: Real>(&self, x: &[T]) -> T {
        let Some(b) = &self.basis else {
            return T::from(f64::INFINITY);
        };
        let n = self.center.len();
        let (x, c) = (&x[..n], &self.center[..n]);
        let mut l1 = T::from(0.0);
        for j in 0..n {
            l1 = l1 + (x[j] - T::from(c[j])).abs();
        }
        let slack = T::from(b.e) * l1 + T::from(f64::MIN_POSITIVE);
        let mut acc = T::from(0.0);
        for (row, &h) in b.m.chunks_exact(n).zip(&b.half_norms) {
            let (mut y, mut s) = (T::from(0.0), T::from(0.0));
            for j in 0..n {
                let t = T::from(row[j]) * (x[j] - T::from(c[j]));
                y = y + t;
                s = s + t.abs();
            }
            let a = y.abs() + T::from(b.rel) * (s + T::from(1.0)) + slack - T::from(1.0);
            acc = acc + (a + a.abs()) * T::from(h);
        }
        acc * T::from(1.0 + b.rel)
    }

    /// Whether `x` lies in `Z (+) B_P(r)`: `true` only if certainly (see [`ZonotopeTest`]).
    pub(crate) fn contains(&self, x: &[f64], r: f64) -> bool {
        let n = x.len();
        if n == 0 || r.is_nan() {
            return n == 0;
        }
        if self.excess(x) <= r {
            return true;
        }
        let (q, pg) = (&self.q, &self.pg);
        let k = self.gens.len() / n;
        let d: Vec<f64> = x.iter().zip(&self.center).map(|(a, b)| a - b).collect();
        let b: Vec<f64> = (0..k)
            .map(|j| (0..n).map(|i| pg[j * n + i] * d[i]).sum())
            .collect();
        // From the basis' clamped coefficients where there is one, then the coefficients
        // strictly inside the cube solved for with the others held (the minimiser when that
        // guess of the active faces is right, as it is for most states near one face).
        let mut xi = vec![0.0f64; k];
        if let Some(basis) = &self.basis {
            for (row, &j) in basis.m.chunks_exact(n).zip(&basis.idx) {
                let y: f64 = row.iter().zip(&d).map(|(m, d)| m * d).sum();
                if y.is_finite() {
                    xi[j] = y.clamp(-1.0, 1.0);
                }
            }
        }
        if nearest_in_cube(q, &b, &mut xi) {
            return self.certify(x, &xi, r);
        }
        // Projected coordinate descent where the active-set steps stop short. A sweep is a
        // function of `xi`'s bits: once one leaves them all unchanged, so would the rest.
        for _ in 0..100 {
            let mut moved = false;
            for j in 0..k {
                let qjj = q[j * k + j];
                if qjj.is_nan() || qjj <= 0.0 {
                    continue;
                }
                let rest: f64 = (0..k)
                    .filter(|&l| l != j)
                    .map(|l| q[j * k + l] * xi[l])
                    .sum();
                let v = ((b[j] - rest) / qjj).clamp(-1.0, 1.0);
                if v.is_finite() {
                    moved |= v.to_bits() != xi[j].to_bits();
                    xi[j] = v;
                }
            }
            if !moved {
                break;
            }
        }
        self.certify(x, &xi, r)
    }

    /// Whether `|x - z|_P <= r` certainly for the point `z = c + G xi` of `Z` (`xi` in the
    /// cube): [`ZonotopeTest::clearly_within`] first, then with `z` evaluated in interval
    /// arithmetic (unless floating point finds it above `r^2` by a relative `1e-9`, far beyond
    /// the roundings of either).
    fn certify(&self, x: &[f64], xi: &[f64], r: f64) -> bool {
        let (clearly, q) = self.clearly_within(x, xi, r);
        clearly || (q <= r * r * (1.0 + 1e-9) && self.within_interval(x, xi, r))
    }

    /// `(certain, q)`: whether [`ZonotopeTest::within_interval`] answers `true` for these
    /// arguments, decided in floating point (`false` says nothing), and `q`, the computed
    /// `|x - z|_P^2`.
    ///
    /// The bound: the computed `e_i = x_i - (c_i + sum_j g_ji xi_j)` lies within
    /// `w_i = c1 a_i` of the exact one, with `a_i = |x_i| + |c_i| + sum_j |g_ji xi_j|` and
    /// `c1 = 16 (k + 2) eps` (at most one ulp per operation of `k + 2`, eight times over; the
    /// smallest normal number covers underflow). The exact form is then at most
    /// `q + sum |P_ij| (|e_i| w_j + w_i |e_j| + w_i w_j)` plus the roundings of both sums,
    /// within `c2 sum |P_ij| (|e_i| + w_i)(|e_j| + w_j)`, `c2 = 16 (n^2 + 4) eps`; and
    /// `r^2 (1 - 4 eps)` lies below the exact `r^2` (the bound of `Frame::clearly_within` in
    /// `parallelotope.rs`, for a point of the zonotope instead of the parallelotope).
    fn clearly_within(&self, x: &[f64], xi: &[f64], r: f64) -> (bool, f64) {
        let n = x.len();
        let (center, gens, p) = (&self.center, &self.gens, &self.p);
        let eps = f64::EPSILON;
        let c1 = 16.0 * (xi.len() as f64 + 2.0) * eps;
        let c2 = 16.0 * ((n * n) as f64 + 4.0) * eps;
        let (e, w): (Vec<f64>, Vec<f64>) = (0..n)
            .map(|i| {
                let (mut z, mut a) = (0.0, x[i].abs() + center[i].abs());
                for (j, &v) in xi.iter().enumerate() {
                    let t = gens[j * n + i] * v;
                    z += t;
                    a += t.abs();
                }
                (x[i] - (center[i] + z), c1 * a + f64::MIN_POSITIVE)
            })
            .unzip();
        let (mut q, mut g, mut h) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let (ei, wi) = (e[i].abs(), w[i]);
            for j in 0..n {
                let (pij, ej, wj) = (p[i * n + j], e[j].abs(), w[j]);
                q += pij * e[i] * e[j];
                g += pij.abs() * (ei * wj + wi * ej + wi * wj);
                h += pij.abs() * (ei + wi) * (ej + wj);
            }
        }
        let upper = q + 4.0 * eps * q.abs() + g * (1.0 + c2) + c2 * h;
        (upper < r * r * (1.0 - 4.0 * eps), q)
    }

    /// Whether `|x - z|_P <= r` certainly for `z = c + G xi`, in interval arithmetic.
    fn within_interval(&self, x: &[f64], xi: &[f64], r: f64) -> bool {
        let n = x.len();
        let (center, gens, p) = (&self.center, &self.gens, &self.p);
        let diff: Vec<Interval> = (0..n)
            .map(|i| {
                let z = xi
                    .iter()
                    .enumerate()
                    .fold(Interval::point(center[i]), |acc, (j, &v)| {
                        acc + Interval::point(gens[j * n + i]) * Interval::point(v)
                    });
                Interval::point(x[i]) - z
            })
            .collect();
        let mut qf = Interval::ZERO;
        for i in 0..n {
            for j in 0..n {
                qf += Interval::point(p[i * n + j]) * diff[i] * diff[j];
            }
        }
        qf.hi() <= Interval::point(r).sqr().lo()
    }
}

/// Moves `xi` (in the cube) to the minimiser of `xi' Q xi - 2 b' xi` over the cube by a
/// primal active-set method: the coefficients at a face start held there; each round solves
/// for the free ones with the held ones fixed (Cholesky of their block of `Q`, with a relative
/// `1e-12` added to its diagonal so that a singular `Q`, more generators than states, still
/// gives a near-minimiser), steps towards that solution as far as the cube allows (holding the
/// coefficient that stops it), and at the solution releases the held coefficient whose
/// gradient points most into the cube. `true` when it ends at a minimiser (no coefficient to
/// release) within `4 k` rounds; only the candidate depends on it.
fn nearest_in_cube(q: &[f64], b: &[f64], xi: &mut [f64]) -> bool {
    let k = xi.len();
    let ridge = 1e-12 * (0..k).map(|j| q[j * k + j].abs()).fold(0.0, f64::max);
    let mut held: Vec<bool> = xi.iter().map(|v| v.abs() >= 1.0).collect();
    // Each round's free coefficients, their block of Q and the right-hand side (reused).
    let (mut free, mut a, mut target) = (
        Vec::with_capacity(k),
        Vec::with_capacity(k * k),
        Vec::with_capacity(k),
    );
    for _ in 0..4 * k.max(1) {
        free.clear();
        free.extend((0..k).filter(|&j| !held[j]));
        let m = free.len();
        if m > 0 {
            a.clear();
            a.extend((0..m * m).map(|v| {
                q[free[v / m] * k + free[v % m]] + if v / m == v % m { ridge } else { 0.0 }
            }));
            target.clear();
            target.extend(free.iter().map(|&j| {
                let fixed: f64 = (0..k)
                    .filter(|&l| held[l])
                    .map(|l| q[j * k + l] * xi[l])
                    .sum();
                b[j] - fixed
            }));
            if !cholesky_solve(&mut a, m, &mut target) {
                return false;
            }
            // The longest step towards the target within the cube, and what stops it.
            let (mut alpha, mut stop) = (1.0, None);
            for (&j, &t) in free.iter().zip(&target) {
                let dir = t - xi[j];
                let room = if dir > 0.0 { 1.0 - xi[j] } else { -1.0 - xi[j] };
                if dir != 0.0 && room / dir < alpha {
                    alpha = (room / dir).max(0.0);
                    stop = Some(j);
                }
            }
            for (&j, &t) in free.iter().zip(&target) {
                xi[j] = (xi[j] + alpha * (t - xi[j])).clamp(-1.0, 1.0);
            }
            if let Some(j) = stop {
                xi[j] = xi[j].signum();
                held[j] = true;
                continue;
            }
        }
        // At the minimiser over the free coefficients: release the held one whose gradient
        // (Q xi - b) points most into the cube, if any does.
        let release = (0..k)
            .filter(|&j| held[j])
            .map(|j| {
                let g: f64 = (0..k).map(|l| q[j * k + l] * xi[l]).sum::<f64>() - b[j];
                (j, g * xi[j])
            })
            .filter(|&(_, into)| into > 0.0)
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match release {
            Some((j, _)) => held[j] = false,
            None => return true,
        }
    }
    false
}

/// Solves `A v = rhs` in place for the symmetric `m x m` row-major `A` by Cholesky in floating
/// point: `false` (and `rhs` unchanged in meaning) unless every pivot is positive and the
/// solution finite.
fn cholesky_solve(a: &mut [f64], m: usize, rhs: &mut [f64]) -> bool {
    for j in 0..m {
        let mut s = a[j * m + j];
        for l in 0..j {
            s -= a[j * m + l] * a[j * m + l];
        }
        if s.is_nan() || s <= 0.0 {
            return false;
        }
        let pivot = s.sqrt();
        a[j * m + j] = pivot;
        for i in j + 1..m {
            let mut t = a[i * m + j];
            for l in 0..j {
                t -= a[i * m + l] * a[j * m + l];
            }
            a[i * m + j] = t / pivot;
        }
    }
    // L y = rhs, then L' v = y.
    for i in 0..m {
        let s: f64 = (0..i).map(|l| a[i * m + l] * rhs[l]).sum();
        rhs[i] = (rhs[i] - s) / a[i * m + i];
    }
    for i in (0..m).rev() {
        let s: f64 = (i + 1..m).map(|l| a[l * m + i] * rhs[l]).sum();
        rhs[i] = (rhs[i] - s) / a[i * m + i];
    }
    rhs.iter().all(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng::{Lcg64, Rng};

    /// A parallelogram: centre (1, 0), generators (1, 0.5) and (0, 0.2).
    fn set() -> (Vec<f64>, Vec<f64>) {
        (vec![1.0, 0.0], vec![1.0, 0.5, 0.0, 0.2])
    }

    #[test]
    fn hull_and_support_are_the_vertices_extremes() {
        let (c, g) = set();
        let (lo, hi) = hull(&c, &g);
        assert!(lo[0] <= 0.0 && lo[0] > -1e-15 && hi[0] >= 2.0 && hi[0] < 2.0 + 1e-15);
        assert!(lo[1] <= -0.7 && lo[1] > -0.7 - 1e-15 && hi[1] >= 0.7 && hi[1] < 0.7 + 1e-15);
        // max over the vertices (1 +- 1, +-0.5 +- 0.2) of x - y: (2, 0.5 - 0.2)... = 2 - (-0.7)
        // at xi = (1, -1)? x - y = 2 - 0.3 = 1.7; at xi = (-1, -1): 0 + 0.7 = 0.7; so 1.7.
        let s = support(&c, &g, &[1.0, -1.0]);
        assert!((1.7..1.7 + 1e-14).contains(&s), "{s}");
    }

    #[test]
    fn membership_is_exact_up_to_rounding_and_conservative() {
        let (c, g) = set();
        let p = [1.0, 0.0, 0.0, 1.0];
        // Vertices and the centre are inside with r = 0+; points beyond a face are out.
        assert!(contains(&p, &[2.0, 0.7], &c, &g, 1e-12));
        assert!(contains(&p, &[1.0, 0.0], &c, &g, 0.0));
        assert!(!contains(&p, &[2.1, 0.7], &c, &g, 0.05));
        assert!(contains(&p, &[2.1, 0.7], &c, &g, 0.1 + 1e-9));
        // Against sampling: every sampled point of Z (+) B(r) is reported inside.
        let mut rng = Lcg64(1);
        let mut next = || rng.range(-1.0, 1.0);
        for _ in 0..2000 {
            let (a, b) = (next(), next());
            let ang = std::f64::consts::PI * next();
            let rad = 0.3 * next().abs();
            let x = [
                c[0] + a * g[0] + b * g[2] + rad * ang.cos(),
                c[1] + a * g[1] + b * g[3] + rad * ang.sin(),
            ];
            assert!(contains(&p, &x, &c, &g, 0.3 * (1.0 + 1e-9)), "{x:?}");
        }
    }

    #[test]
    fn p_radius_bounds_every_vertex() {
        let (_, g) = set();
        let p = [2.0, 0.5, 0.5, 1.0];
        let r = p_radius(&p, 2, &g);
        for (a, b) in [(1.0, 1.0), (1.0, -1.0)] {
            let v = [a * g[0] + b * g[2], a * g[1] + b * g[3]];
            let q = p[0] * v[0] * v[0] + 2.0 * p[1] * v[0] * v[1] + p[3] * v[1] * v[1];
            assert!(q.sqrt() <= r);
        }
    }

    /// A metric `A' A + I / 2`, a centre and `k` generators in `n` states, from `rnd`.
    fn random(rnd: &mut impl FnMut() -> f64, n: usize, k: usize) -> [Vec<f64>; 3] {
        let a: Vec<f64> = (0..n * n).map(|_| rnd()).collect();
        let p = (0..n * n)
            .map(|v| {
                let (i, j) = (v / n, v % n);
                let aa: f64 = (0..n).map(|l| a[l * n + i] * a[l * n + j]).sum();
                aa + if i == j { 0.5 } else { 0.0 }
            })
            .collect();
        let center = (0..n).map(|_| 10.0 * rnd()).collect();
        let gens = (0..n * k).map(|_| rnd()).collect();
        [p, center, gens]
    }

    /// Random zonotopes of 1 to 12 states with `n` to `n + 2` generators and random points
    /// `x = c + G_S xi` over the basis: `excess` is 0 in the basis' parallelotope (to within
    /// a relative 1e-6 of its faces), at least the triangle bound
    /// `sum_s max(|xi_s| - 1, 0) |g_s|_P` of the distance to `c + G_S clamp(xi)` outside it, and
    /// within a relative 1e-6 of that bound; eight states in lanes give the same bits; NaN
    /// states are never within any radius.
    #[test]
    fn excess_is_zero_inside_the_basis_and_bounds_the_distance_outside() {
        use crate::lanes::X8;
        let mut rng = Rng(11);
        let mut rnd = || rng.range(-1.0, 1.0);
        let (mut inexact, mut outside) = (0, 0);
        for case in 0..240 {
            let (n, extra) = (1 + case % 12, case / 12 % 3);
            let [p, c, g] = random(&mut rnd, n, n + extra);
            let test = ZonotopeTest::new(&p, &c, &g);
            let basis = test.basis.as_ref().expect("random generators hold a basis");
            assert_eq!(basis.idx.len(), n);
            inexact += usize::from(basis.e > 0.0);
            let norm = |j: usize| {
                let g = &g[j * n..(j + 1) * n];
                (0..n * n)
                    .map(|v| p[v] * g[v / n] * g[v % n])
                    .sum::<f64>()
                    .sqrt()
            };
            let mut states = Vec::new();
            for i in 0..24 {
                let scale = if i % 3 == 0 { 1.0 - 1e-6 } else { 1.5 };
                let xi: Vec<f64> = (0..n).map(|_| scale * rnd()).collect();
                let x: Vec<f64> = (0..n)
                    .map(|d| {
                        let gx: f64 = basis
                            .idx
                            .iter()
                            .zip(&xi)
                            .map(|(&j, v)| g[j * n + d] * v)
                            .sum();
                        c[d] + gx
                    })
                    .collect();
                let e = test.excess(&x);
                let bound: f64 = basis
                    .idx
                    .iter()
                    .zip(&xi)
                    .map(|(&j, v)| (v.abs() - 1.0).max(0.0) * norm(j))
                    .sum();
                if bound == 0.0 {
                    assert_eq!(e, 0.0, "case {case}: {xi:?}");
                    assert!(test.contains(&x, 0.0));
                } else {
                    outside += 1;
                    assert!(e >= bound * (1.0 - 1e-9), "case {case}: {e} < {bound}");
                    assert!(e <= bound * (1.0 + 1e-6), "case {case}: {e} vs {bound}");
                }
                states.push((x, e));
            }
            for chunk in states.chunks_exact(8) {
                let x8: Vec<X8> = (0..n)
                    .map(|d| X8(std::array::from_fn(|l| chunk[l].0[d])))
                    .collect();
                let e8 = test.excess(&x8);
                for (l, (_, e)) in chunk.iter().enumerate() {
                    assert_eq!(e8.0[l].to_bits(), e.to_bits(), "case {case}, lane {l}");
                }
            }
            let mut nan = c.clone();
            nan[n - 1] = f64::NAN;
            assert!(test.excess(&nan).is_nan() && !test.contains(&nan, 1e300));
        }
        // Not vacuous: inverses with an error to bound, and points beyond the faces.
        assert!(inexact > 100 && outside > 2000, "{inexact} {outside}");
    }

    /// Fewer generators than states, or generators without a basis among them: no `excess`
    /// bound (infinite), and the descent alone certifies.
    #[test]
    fn without_a_basis_the_descent_decides() {
        let p = [1.0, 0.0, 0.0, 1.0];
        for gens in [vec![1.0, 0.5], vec![1.0, 0.5, -2.0, -1.0]] {
            let test = ZonotopeTest::new(&p, &[0.0, 0.0], &gens);
            assert!(test.basis.is_none());
            assert_eq!(test.excess(&[0.0, 0.0]), f64::INFINITY);
            // (1, 0.5) + (0.1, -0.2): at distance sqrt(0.05) from the segment's end.
            assert!(test.contains(&[1.1, 0.3], 0.2237));
            assert!(!test.contains(&[1.1, 0.3], 0.2236));
        }
    }

    /// Random zonotopes and points (scales from 1 to 1e4): the floating-point certificate
    /// never accepts a radius the interval one refuses, and accepts every radius above the
    /// interval one's smallest by a relative 1e-9.
    #[test]
    fn clearly_within_implies_the_interval_test_and_is_nearly_as_tight() {
        let mut rng = Rng(5);
        let mut rnd = || rng.range(-1.0, 1.0);
        for case in 0..600 {
            let (n, k) = (1 + case % 6, 1 + case % 8);
            let [p, c, g] = random(&mut rnd, n, k);
            let test = ZonotopeTest::new(&p, &c, &g);
            let scale = 10f64.powf(4.0 * rnd().abs());
            let x: Vec<f64> = (0..n).map(|_| scale * rnd()).collect();
            let xi: Vec<f64> = (0..k).map(|_| rnd()).collect();
            // The smallest radius the interval test accepts, to a relative 1e-15.
            let (mut lo, mut hi) = (0.0, 100.0 * scale * (n + k) as f64);
            assert!(test.within_interval(&x, &xi, hi));
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if test.within_interval(&x, &xi, mid) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            for r in [lo, lo * (1.0 - 1e-12), hi, hi * (1.0 + 1e-9)] {
                let (clearly, q) = test.clearly_within(&x, &xi, r);
                if clearly {
                    assert!(test.within_interval(&x, &xi, r), "case {case}: r = {r}");
                }
                assert!(
                    (q.sqrt() - hi).abs() <= 1e-9 * hi,
                    "case {case}: {q} vs {hi}"
                );
            }
            assert!(
                test.clearly_within(&x, &xi, hi * (1.0 + 1e-9)).0,
                "case {case}"
            );
        }
    }

    /// The active-set steps end at the minimiser over the cube: no coordinate step improves
    /// on them (the projected coordinate descent's fixed point, up to rounding), for random
    /// positive definite problems of 1 to 12 generators with minimisers on many faces.
    #[test]
    fn the_active_set_steps_find_the_minimiser() {
        let mut rng = Rng(3);
        let mut rnd = || rng.range(-1.0, 1.0);
        for case in 0..300 {
            let k = 1 + case % 12;
            let [q, _, _] = random(&mut rnd, k, 0);
            let b: Vec<f64> = (0..k).map(|_| 3.0 * rnd()).collect();
            let mut xi: Vec<f64> = (0..k).map(|_| (2.0 * rnd()).clamp(-1.0, 1.0)).collect();
            assert!(nearest_in_cube(&q, &b, &mut xi), "case {case}");
            let f = |xi: &[f64]| {
                (0..k * k)
                    .map(|v| xi[v / k] * q[v] * xi[v % k])
                    .sum::<f64>()
                    - 2.0 * (0..k).map(|j| b[j] * xi[j]).sum::<f64>()
            };
            for j in 0..k {
                let rest: f64 = (0..k)
                    .filter(|&l| l != j)
                    .map(|l| q[j * k + l] * xi[l])
                    .sum();
                let best = ((b[j] - rest) / q[j * k + j]).clamp(-1.0, 1.0);
                let mut moved = xi.clone();
                moved[j] = best;
                assert!(f(&moved) >= f(&xi) - 1e-9, "case {case}, coordinate {j}");
            }
        }
    }

    /// The safety margins of `Z (+) B_P(remainder) (+) B_P(r_t)` (`safety.rs`) for the
    /// parallelogram of [`set`] with a skewed metric: a half-space's is the distance from the
    /// set's support `a . c + sum_j |a . g_j| + (remainder + r_t) sqrt(a' P^-1 a)` to the
    /// offset, a box's the gap to the hull widened by `(remainder + r_t) sqrt((P^-1)_ii)`, both
    /// rounded down by no more than rounding.
    #[test]
    fn margins_use_the_support_and_the_hull_with_both_balls() {
        use crate::engine::linalg;
        use crate::engine::safety::{Check, Context};
        use crate::model::{Bounds, UnsafeSet, UnsafeShape};
        use crate::prs::DetSet;
        let (c, g) = set();
        let p = [2.0, 0.5, 0.5, 1.0];
        // P^-1 = [[1, -0.5], [-0.5, 2]] / 1.75.
        let p_inv = [1.0 / 1.75, -0.5 / 1.75, -0.5 / 1.75, 2.0 / 1.75];
        let (remainder, r_t) = (0.05, 0.1);
        let (hull_lo, hull_hi) = hull(&c, &g);
        let det = DetSet::Zonotope {
            center: c.clone(),
            generators: g.clone(),
            remainder,
            hull_lo: hull_lo.clone(),
            hull_hi: hull_hi.clone(),
            radius: p_radius(&p, 2, &g) + remainder,
        };
        let l = linalg::cholesky(&linalg::to_intervals(&p), 2).unwrap();
        let diag = linalg::inverse_diagonal(&l, 2);
        let w: Vec<f64> = diag.iter().map(|d| d.sqrt().hi()).collect();
        let context = Context { w: &w, frame: None };
        let check = |shape: UnsafeShape| {
            let set = UnsafeSet {
                name: "u".into(),
                shape,
                moving: Vec::new(),
            };
            Check::new(&set, 2, &l, &diag)
                .unwrap()
                .margin(&det, r_t, &context)
        };
        let r = remainder + r_t;
        // x - y >= 2.5: the support of Z is 1.7 (see above), the ball's
        // sqrt(a' P^-1 a) = sqrt((1 + 1 + 2) / 1.75).
        let a: [f64; 2] = [1.0, -1.0];
        let dual =
            (a[0] * a[0] * p_inv[0] + 2.0 * a[0] * a[1] * p_inv[1] + a[1] * a[1] * p_inv[3]).sqrt();
        let exact = (2.5 - 1.7 - r * dual) / 2f64.sqrt();
        let m = check(UnsafeShape::HalfSpace {
            normal: a.to_vec(),
            offset: 2.5,
        });
        assert!(m <= exact && m > exact - 1e-14, "{m} vs {exact}");
        // x >= 2.3: the hull's 2 plus r sqrt((P^-1)_00), against the box [2.3, 5] in x.
        let exact = 2.3 - (2.0 + r * p_inv[0].sqrt());
        let m = check(UnsafeShape::Box(vec![(0, Bounds::new(2.3, 5.0))]));
        assert!(m <= exact && m > exact - 1e-14, "{m} vs {exact}");
    }
}
