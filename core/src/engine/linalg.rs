//! Small dense linear algebra with rigorous bounds, for the metric `P` and the initial-set
//! metrics `M` (n is small: a few to a few dozen states).
//!
//! Everything that feeds a safety verdict or a radius is computed in [`Interval`] arithmetic on
//! top of the exact `f64` inputs, so the bounds hold for the exact real matrices:
//!
//! * quadratic forms `v' A^-1 v` and diagonals of `A^-1` go through an interval Cholesky
//!   factorisation `A = L L'` (each entry of `L` is an enclosure of the exact factor's entry,
//!   because every formula is evaluated with inclusion functions) followed by interval forward
//!   substitution, so `|L^-1 v|^2` encloses `v' A^-1 v`;
//! * `lambda_max` of a symmetric interval matrix is estimated in `f64` (Jacobi) and then
//!   *verified*: `mu` is an upper bound as soon as the interval Cholesky factorisation of
//!   `mu I - A` succeeds with certainly positive pivots (then every symmetric matrix in the
//!   enclosure satisfies `mu I - A > 0`). Gershgorin's bound is the fallback and is also used to
//!   cap the result.

use crate::interval::Interval;

/// Lower bandwidth of a square matrix: the largest `i - j` with a non-zero entry `(i, j)`.
/// Cholesky factors keep it, so banded metrics (diagonal ones in particular) cost `O(n b^2)`
/// instead of `O(n^3)`.
pub(crate) fn bandwidth(a: &[Interval], n: usize) -> usize {
    (0..n)
        .filter_map(|i| {
            (0..i)
                .find(|&j| a[i * n + j] != Interval::ZERO)
                .map(|j| i - j)
        })
        .max()
        .unwrap_or(0)
}

/// Interval Cholesky factor `L` (lower triangular, row-major `n x n`) of the symmetric matrix
/// whose lower triangle is enclosed by `a`. `None` when a pivot is not certainly positive
/// (the matrix may not be positive definite, or the enclosure is too wide to tell).
pub(crate) fn cholesky(a: &[Interval], n: usize) -> Option<Vec<Interval>> {
    debug_assert_eq!(a.len(), n * n);
    let bw = bandwidth(a, n);
    let mut l = vec![Interval::ZERO; n * n];
    for j in 0..n {
        let first = j.saturating_sub(bw);
        let mut d = a[j * n + j];
        for k in first..j {
            d -= l[j * n + k].sqr();
        }
        // (Interval ends are never NaN.)
        if d.lo() <= 0.0 || !d.is_bounded() {
            return None;
        }
        let ljj = d.sqrt();
        l[j * n + j] = ljj;
        for i in j + 1..n.min(j + bw + 1) {
            let mut s = a[i * n + j];
            for k in i.saturating_sub(bw)..j {
                s -= l[i * n + k] * l[j * n + k];
            }
            l[i * n + j] = s / ljj;
        }
    }
    Some(l)
}

/// Enclosure of `L^-1 v` by interval forward substitution (`L` from [`cholesky`], so its
/// diagonal is certainly positive).
pub(crate) fn forward_solve(l: &[Interval], n: usize, v: &[Interval]) -> Vec<Interval> {
    forward_solve_banded(l, n, bandwidth(l, n), v)
}

/// [`forward_solve`] for `L` of lower bandwidth `bw`, starting at the first non-zero of `v`.
fn forward_solve_banded(l: &[Interval], n: usize, bw: usize, v: &[Interval]) -> Vec<Interval> {
    let mut w = vec![Interval::ZERO; n];
    let start = v.iter().position(|x| *x != Interval::ZERO).unwrap_or(n);
    for i in start..n {
        let mut s = v[i];
        for k in i.saturating_sub(bw).max(start)..i {
            s -= l[i * n + k] * w[k];
        }
        w[i] = s / l[i * n + i];
    }
    w
}

/// Point matrix as intervals.
pub(crate) fn to_intervals(a: &[f64]) -> Vec<Interval> {
    a.iter().map(|&x| Interval::point(x)).collect()
}

/// Enclosure of `v' A^-1 v` given the interval Cholesky factor of `A`.
pub(crate) fn inv_quad_form(l: &[Interval], n: usize, v: &[f64]) -> Interval {
    let w = forward_solve(l, n, &to_intervals(v));
    w.iter().fold(Interval::ZERO, |acc, wi| acc + wi.sqr())
}

/// Enclosure of the block of `A^-1 = L^-T L^-1` over the indices `idx` (`k x k` row-major,
/// `k = idx.len()`), given the interval Cholesky factor of `A`. Costs `k` forward solves, so
/// the whole inverse is never formed for large `n`.
pub(crate) fn inverse_block(l: &[Interval], n: usize, idx: &[usize]) -> Vec<Interval> {
    let bw = bandwidth(l, n);
    // Column j of L^-1 is L^-1 e_j.
    let cols: Vec<Vec<Interval>> = idx
        .iter()
        .map(|&j| {
            let mut e = vec![Interval::ZERO; n];
            e[j] = Interval::ONE;
            forward_solve_banded(l, n, bw, &e)
        })
        .collect();
    let k = idx.len();
    let mut out = vec![Interval::ZERO; k * k];
    for a in 0..k {
        for b in 0..=a {
            // (A^-1)_ab = sum_m (L^-1)_ma (L^-1)_mb (zero for m < max(a, b)); sqr on the
            // diagonal (tighter).
            let from = idx[a].max(idx[b]);
            let s = cols[a][from..]
                .iter()
                .zip(&cols[b][from..])
                .fold(Interval::ZERO, |acc, (&x, &y)| {
                    acc + if a == b { x.sqr() } else { x * y }
                });
            out[a * k + b] = s;
            out[b * k + a] = s;
        }
    }
    out
}

/// Enclosure of the diagonal of `A^-1`, given the interval Cholesky factor of `A`.
pub(crate) fn inverse_diagonal(l: &[Interval], n: usize) -> Vec<Interval> {
    let bw = bandwidth(l, n);
    (0..n)
        .map(|i| {
            let mut e = vec![Interval::ZERO; n];
            e[i] = Interval::ONE;
            forward_solve_banded(l, n, bw, &e)[i..]
                .iter()
                .fold(Interval::ZERO, |acc, x| acc + x.sqr())
        })
        .collect()
}

/// Eigenvalues of a symmetric `f64` matrix by the cyclic Jacobi method (an estimate only; the
/// callers verify what they use).
pub(crate) fn jacobi_eigenvalues(a: &[f64], n: usize) -> Vec<f64> {
    jacobi(a, n, None)
}

/// [`jacobi_eigenvalues`] with the eigenvectors: `(lambda, v)` with `a ~ v diag(lambda) v'`,
/// `v` row-major `n x n`, eigenvector `i` in column `i` (estimates, like the eigenvalues).
pub(crate) fn jacobi_eigen(a: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut v = vec![0.0; n * n];
    for i in 0..n {
        v[i * n + i] = 1.0;
    }
    let lambda = jacobi(a, n, Some(&mut v));
    (lambda, v)
}

/// The cyclic Jacobi iteration; the rotations are also applied to the columns of `vectors`
/// when given (starting from the identity, they accumulate the eigenvectors).
fn jacobi(a: &[f64], n: usize, mut vectors: Option<&mut [f64]>) -> Vec<f64> {
    let mut m = a.to_vec();
    for _sweep in 0..100 {
        let mut off = 0.0;
        let mut diag = 0.0;
        for i in 0..n {
            for j in 0..n {
                if i == j {
                    diag += m[i * n + i] * m[i * n + i];
                } else {
                    off += m[i * n + j] * m[i * n + j];
                }
            }
        }
        if off <= 1e-30 * diag || off == 0.0 {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = m[p * n + q];
                if apq == 0.0 {
                    continue;
                }
                let theta = (m[q * n + q] - m[p * n + p]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                // Rotate rows/columns p and q.
                for k in 0..n {
                    let mkp = m[k * n + p];
                    let mkq = m[k * n + q];
                    m[k * n + p] = c * mkp - s * mkq;
                    m[k * n + q] = s * mkp + c * mkq;
                }
                for k in 0..n {
                    let mpk = m[p * n + k];
                    let mqk = m[q * n + k];
                    m[p * n + k] = c * mpk - s * mqk;
                    m[q * n + k] = s * mpk + c * mqk;
                }
                if let Some(v) = vectors.as_deref_mut() {
                    for k in 0..n {
                        let vkp = v[k * n + p];
                        let vkq = v[k * n + q];
                        v[k * n + p] = c * vkp - s * vkq;
                        v[k * n + q] = s * vkp + c * vkq;
                    }
                }
            }
        }
    }
    (0..n).map(|i| m[i * n + i]).collect()
}

/// Gershgorin upper bound of `lambda_max` over every symmetric matrix in the enclosure `a`
/// (rounded up).
pub(crate) fn gershgorin_upper(a: &[Interval], n: usize) -> f64 {
    (0..n)
        .map(|i| {
            let mut s = Interval::point(a[i * n + i].hi());
            for j in 0..n {
                if j != i {
                    s += a[i * n + j].mag();
                }
            }
            s.hi()
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// A rigorous upper bound of `lambda_max` over every symmetric matrix whose lower triangle lies
/// in the enclosure `a` (`k x k`). See the module documentation for the method.
pub(crate) fn lambda_max_upper(a: &[Interval], k: usize) -> f64 {
    if k == 0 {
        return 0.0;
    }
    if k == 1 {
        return a[0].hi();
    }
    let centre: Vec<f64> = a.iter().map(|x| x.mid()).collect();
    verified_above(a, k, top_eigenvalue(&centre, k))
}

/// The largest eigenvalue of the symmetric `k x k` matrix `m`, estimated (Jacobi, floats).
fn top_eigenvalue(m: &[f64], k: usize) -> f64 {
    jacobi_eigenvalues(m, k)
        .into_iter()
        .fold(f64::NEG_INFINITY, f64::max)
}

/// [`lambda_max_upper`] for `k >= 2` from the estimate `est`: the first `est + margin` the
/// interval Cholesky factorisation certifies, margins from `1e-13` of the matrix's scale up by
/// tens, capped by Gershgorin's bound.
fn verified_above(a: &[Interval], k: usize, est: f64) -> f64 {
    let gersh = gershgorin_upper(a, k);
    if !est.is_finite() {
        return gersh;
    }
    // Scale of the matrix, to make the trial margins relative.
    let scale = a
        .iter()
        .map(|x| x.mag())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let mut margin = scale * 1e-13;
    for _ in 0..12 {
        let mu = est + margin;
        if mu >= gersh {
            break;
        }
        if cholesky(&shifted(a, k, mu), k).is_some() {
            return mu;
        }
        margin *= 10.0;
    }
    gersh
}

/// `A B` for interval matrices `r x k` and `k x c`.
pub(crate) fn product(
    a: &[Interval],
    b: &[Interval],
    r: usize,
    k: usize,
    c: usize,
) -> Vec<Interval> {
    let mut out = vec![Interval::ZERO; r * c];
    for i in 0..r {
        for l in 0..k {
            let ail = a[i * k + l];
            if ail == Interval::ZERO {
                continue;
            }
            for j in 0..c {
                out[i * c + j] += ail * b[l * c + j];
            }
        }
    }
    out
}

/// The interval matrix product `A B` of an `r x k` interval matrix and a `k x c` *point* matrix
/// (row-major), in midpoint-radius form without directed rounding: `A` in `<mA, rA>`, the
/// range of each entry over `A` is exactly `(mA B)_ij +- (rA |B|)_ij`. With the midpoint product
/// `m` and `T = (rA + g |mA|) |B|` computed in round-to-nearest, `g = gamma_k` (the bound
/// `|fl(x'y) - x'y| <= gamma_k |x|'|y|` of a `k`-term dot product, `gamma_k = k u / (1 - k u)`,
/// `u = 2^-53`), the entry lies in `m +- R`, `R = T (1 + 4 (k + 3) u)` rounded up plus
/// `(k + 1)` times the smallest normal number: `T` is a sum of `k` non-negative terms, each
/// rounded at most three times and summed with `k - 1` roundings, so its exact value is at most
/// `T (1 + u)^(k+3) <= T (1 + 4 (k + 3) u)`; each of the at most `4 k` operations that
/// underflow errs by at most `2^-1074`. The same bound as [`product`] up to rounding (exact
/// ranges for a point `B`), at a few floating-point operations per term (no branches, no exact
/// residuals): the first-order sets' products with their point matrices (`M`, the generators).
/// Non-finite entries, or an overflow on the way, fall back to [`product`].
pub(crate) fn product_point(
    a: &[Interval],
    b: &[f64],
    r: usize,
    k: usize,
    c: usize,
) -> Vec<Interval> {
    let endpoint = || product(a, &to_intervals(b), r, k, c);
    let finite = a.iter().all(|v| v.lo().is_finite() && v.hi().is_finite())
        && b.iter().all(|v| v.is_finite());
    if !finite {
        return endpoint();
    }
    let u = f64::EPSILON / 2.0;
    let kf = k as f64;
    let gamma = (kf * u / (1.0 - kf * u)).next_up();
    let grow = (1.0 + 4.0 * (kf + 3.0) * u).next_up();
    let floor = (kf + 1.0) * f64::MIN_POSITIVE;
    let abs_b: Vec<f64> = b.iter().map(|v| v.abs()).collect();
    let mut out = Vec::with_capacity(r * c);
    let (mut mid, mut rad) = (vec![0.0; c], vec![0.0; c]);
    for i in 0..r {
        mid.iter_mut().for_each(|v| *v = 0.0);
        rad.iter_mut().for_each(|v| *v = 0.0);
        for l in 0..k {
            let ail = a[i * k + l];
            let m = ail.mid();
            let radius = (Interval::point(ail.hi()) - Interval::point(m))
                .hi()
                .max((Interval::point(m) - Interval::point(ail.lo())).hi());
            let weight = radius + gamma * m.abs();
            let (row, abs_row) = (&b[l * c..(l + 1) * c], &abs_b[l * c..(l + 1) * c]);
            for j in 0..c {
                mid[j] += m * row[j];
                rad[j] += weight * abs_row[j];
            }
        }
        for (&m, &t) in mid.iter().zip(&rad) {
            let half = (t * grow).next_up() + floor;
            if !(m.is_finite() && half.is_finite()) {
                // An overflow: the endpoint product saturates where this cannot.
                return endpoint();
            }
            out.push(Interval::point(m) + Interval::new(-half, half));
        }
    }
    out
}

/// `(B + B') / 2`.
pub(crate) fn symmetric_part(b: &[Interval], n: usize) -> Vec<Interval> {
    let mut s = vec![Interval::ZERO; n * n];
    for i in 0..n {
        for j in 0..n {
            s[i * n + j] = (b[i * n + j] + b[j * n + i]) * Interval::point(0.5);
        }
    }
    s
}

/// A rigorous upper bound of `lambda_max` over the symmetric matrices in `s`: the smaller of
/// `lambda_max(mid) + rho(rad)` (Collatz-Wielandt with the unit vector, i.e. the largest row
/// sum of the radii: tight for wide enclosures), Gershgorin's bound, and the interval-Cholesky
/// route below them. The latter tries `mu = est + m` (`est` the midpoint's Jacobi estimate)
/// with `m` a quarter of the gap to the best bound so far, then a quarter of that while the
/// factorisation of `mu I - S` succeeds: each success is a bound within a factor 4 of the
/// margin the enclosure needs, and one failure ends the search. (Where the radii are at the
/// level of rounding, the first bound is already that tight and the route is skipped.)
pub(crate) fn lambda_max(s: &[Interval], n: usize) -> f64 {
    if n <= 1 {
        return lambda_max_upper(s, n);
    }
    let centre: Vec<f64> = s.iter().map(|v| v.mid()).collect();
    let mid: Vec<Interval> = centre.iter().map(|&c| Interval::point(c)).collect();
    let est = top_eigenvalue(&centre, n);
    let mut spread = 0.0f64;
    for i in 0..n {
        let mut row = Interval::ZERO;
        for j in 0..n {
            let v = s[i * n + j];
            // |v - mid| <= max(hi - mid, mid - lo), rounded up.
            let m = mid[i * n + j];
            row += (Interval::point(v.hi()) - m)
                .abs()
                .max((m - Interval::point(v.lo())).abs());
        }
        spread = spread.max(row.hi());
    }
    let split = (Interval::point(verified_above(&mid, n, est)) + Interval::point(spread)).hi();
    let mut best = split.min(gershgorin_upper(s, n));
    let scale = s
        .iter()
        .map(|x| x.mag())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let gap = (best - est).partial_cmp(&(1e-10 * scale));
    if !est.is_finite() || gap != Some(std::cmp::Ordering::Greater) {
        return best;
    }
    let mut margin = 0.25 * (best - est);
    while margin > 1e-13 * scale {
        let mu = est + margin;
        if mu.partial_cmp(&best) != Some(std::cmp::Ordering::Less)
            || cholesky(&shifted(s, n, mu), n).is_none()
        {
            break;
        }
        best = mu;
        margin *= 0.25;
    }
    best
}

/// `mu I - a` (`n x n`).
fn shifted(a: &[Interval], n: usize, mu: f64) -> Vec<Interval> {
    (0..n * n)
        .map(|idx| {
            let diag = if idx / n == idx % n {
                Interval::point(mu)
            } else {
                Interval::ZERO
            };
            diag - a[idx]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng::XorShift64;

    /// `product_point` against the exact ranges: entries on a grid of `2^-8` of moderate size,
    /// so every product and sum below is exact in `f64` and the exact range of each entry of
    /// `A B` over the interval matrix `A` is computed exactly (a vertex of `A` per entry). The
    /// midpoint-radius product holds it, and is wider by rounding-level terms only; so does
    /// [`product`] (the reference it replaces).
    #[test]
    fn product_point_holds_the_exact_ranges() {
        let mut rng = XorShift64(0x2545_f491);
        let mut grid =
            |lo: i64, hi: i64| (lo + rng.below((hi - lo + 1) as u64) as i64) as f64 / 256.0;
        for (r, k, c) in [(1, 1, 1), (2, 2, 2), (3, 5, 4), (10, 10, 40)] {
            let a: Vec<Interval> = (0..r * k)
                .map(|_| {
                    let lo = grid(-2048, 2048);
                    Interval::new(lo, lo + grid(0, 512))
                })
                .collect();
            let b: Vec<f64> = (0..k * c).map(|_| grid(-2048, 2048)).collect();
            let fast = product_point(&a, &b, r, k, c);
            let reference = product(&a, &to_intervals(&b), r, k, c);
            for i in 0..r {
                for j in 0..c {
                    let (mut lo, mut hi, mut scale) = (0.0, 0.0, 0.0f64);
                    for l in 0..k {
                        let (x, y) = (a[i * k + l], b[l * c + j]);
                        let (p, q) = (x.lo() * y, x.hi() * y);
                        lo += p.min(q);
                        hi += p.max(q);
                        scale += p.abs().max(q.abs());
                    }
                    let got = fast[i * c + j];
                    assert!(got.lo() <= lo && hi <= got.hi(), "{got:?} vs [{lo}, {hi}]");
                    let slack = 1e-13 * scale + 1e-300;
                    assert!(lo - got.lo() <= slack && got.hi() - hi <= slack, "{got:?}");
                    let want = reference[i * c + j];
                    assert!(want.lo() <= lo && hi <= want.hi());
                }
            }
        }
        // Non-finite entries, or an overflow, fall back to the endpoint product.
        let a = [Interval::new(0.0, f64::INFINITY)];
        assert_eq!(product_point(&a, &[2.0], 1, 1, 1)[0].hi(), f64::INFINITY);
        let huge = product_point(&[Interval::point(1e300)], &[1e300], 1, 1, 1)[0];
        assert_eq!((huge.lo(), huge.hi()), (f64::MAX, f64::INFINITY));
    }

    #[test]
    fn inverse_of_pendulum_metric_encloses_exact() {
        let p = [35.68, 2.21, 2.21, 1.27];
        let l = cholesky(&to_intervals(&p), 2).unwrap();
        let inv = inverse_block(&l, 2, &[0, 1]);
        let det = 35.68 * 1.27 - 2.21 * 2.21;
        let exact = [1.27 / det, -2.21 / det, -2.21 / det, 35.68 / det];
        for (e, i) in exact.iter().zip(&inv) {
            assert!((i.lo() - e).abs() < 1e-13 && (i.hi() - e).abs() < 1e-13);
        }
        let q = inv_quad_form(&l, 2, &[1.0, 1.0]);
        let qe = exact.iter().sum::<f64>();
        assert!(q.lo() <= qe + 1e-14 && qe - 1e-14 <= q.hi());
    }

    #[test]
    fn lambda_max_bound_is_tight_and_above() {
        let a = [2.0, 1.0, 1.0, 2.0];
        let ub = lambda_max_upper(&to_intervals(&a), 2);
        assert!((3.0..3.0 + 1e-10).contains(&ub), "{ub}");
        let a3 = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 1.0];
        let ev = jacobi_eigenvalues(&a3, 3);
        let m = ev.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let ub = lambda_max_upper(&to_intervals(&a3), 3);
        assert!(ub >= m && ub <= m + 1e-9, "{ub} {m}");
    }

    /// `lambda_max` over wide symmetric enclosures: above the largest eigenvalue of every
    /// sampled member (vertices and interior points, computed by Jacobi on the member), and
    /// within the interval route's factor 4 of the margin it needs: never above the
    /// midpoint-plus-radii bound, and below it where the enclosure allows (a tight check on
    /// the diagonal case, whose exact answer is the largest upper end).
    #[test]
    fn lambda_max_holds_sampled_members_of_wide_enclosures() {
        let mut rng = XorShift64(0x9e37_79b9);
        for n in [2usize, 3, 5] {
            for _ in 0..40 {
                let mut lo = vec![0.0; n * n];
                let mut hi = vec![0.0; n * n];
                for i in 0..n {
                    for j in 0..=i {
                        let c = rng.uniform() * 4.0 - 2.0;
                        let r = rng.uniform() * 0.3;
                        for (a, b) in [(i, j), (j, i)] {
                            lo[a * n + b] = c - r;
                            hi[a * n + b] = c + r;
                        }
                    }
                }
                let s: Vec<Interval> = lo
                    .iter()
                    .zip(&hi)
                    .map(|(&a, &b)| Interval::new(a, b))
                    .collect();
                let bound = lambda_max(&s, n);
                for _ in 0..200 {
                    let mut m = vec![0.0; n * n];
                    for i in 0..n {
                        for j in 0..=i {
                            let u = rng.uniform();
                            let u = if u < 0.3 {
                                0.0
                            } else if u > 0.7 {
                                1.0
                            } else {
                                u
                            };
                            let v = lo[i * n + j] + u * (hi[i * n + j] - lo[i * n + j]);
                            m[i * n + j] = v;
                            m[j * n + i] = v;
                        }
                    }
                    let top = jacobi_eigenvalues(&m, n)
                        .into_iter()
                        .fold(f64::NEG_INFINITY, f64::max);
                    assert!(top <= bound + 1e-12, "n = {n}: member {top} above {bound}");
                }
                let mid: Vec<Interval> = s.iter().map(|v| Interval::point(v.mid())).collect();
                let rows = (0..n)
                    .map(|i| (0..n).map(|j| s[i * n + j].rad()).sum::<f64>())
                    .fold(0.0, f64::max);
                assert!(bound <= lambda_max_upper(&mid, n) + rows + 1e-12);
            }
        }
        // A diagonal enclosure: the exact answer is the largest upper end, and the interval
        // route gets within a factor 4 of the margin the midpoint bound leaves above it (here
        // the midpoint bound is 1 + 0.5 above the midpoint's 2; the answer is 2.5).
        let s = [
            Interval::new(1.5, 2.5),
            Interval::ZERO,
            Interval::ZERO,
            Interval::new(0.0, 1.0),
        ];
        let bound = lambda_max(&s, 2);
        assert!((2.5..=2.5 + 0.25 * 0.5 + 1e-9).contains(&bound), "{bound}");
    }

    #[test]
    fn jacobi_eigenvectors_diagonalise() {
        let a = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 1.0];
        let (lambda, v) = jacobi_eigen(&a, 3);
        assert_eq!(lambda, jacobi_eigenvalues(&a, 3));
        for i in 0..3 {
            for j in 0..3 {
                let vdv: f64 = (0..3)
                    .map(|k| v[i * 3 + k] * lambda[k] * v[j * 3 + k])
                    .sum();
                assert!((vdv - a[i * 3 + j]).abs() < 1e-13, "{i} {j}: {vdv}");
            }
        }
    }

    #[test]
    fn cholesky_rejects_indefinite() {
        assert!(cholesky(&to_intervals(&[1.0, 2.0, 2.0, 1.0]), 2).is_none());
    }
}
