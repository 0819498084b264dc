//! `transform = auto`: the coordinate transform `y = T x` of an interval analysis, chosen from
//! the drift's Jacobian `A` at the centre of the initial set (method.md, section 6).
//!
//! The embedding's box grows like `e^(mu t)` with `mu = mu_inf(T A T^-1)`, the logarithmic
//! infinity norm `max_i (B_ii + sum_(j != i) |B_ij|)`, so `T` is chosen to make it small:
//!
//! 1. a start from the real Schur form `A = Q U Q'`: the 2x2 block of each complex pair
//!    `a +- ib` brought to `[[a, b], [-b, a]]` (real and imaginary parts of its eigenvector),
//!    blocks of distinct eigenvalues decoupled (one small Sylvester equation per pair of
//!    blocks), and the couplings left between close eigenvalues (a defective, repeated one)
//!    scaled down by a diagonal similarity, as a scaled Jordan chain;
//! 2. a Nelder-Mead polish of `mu_inf` (over `T`'s entries for small `n`, else over a scaling
//!    of its rows), with `cond_inf(T) <= MAX_CONDITION`;
//! 3. the best-conditioned `T` within 1% of that `mu_inf`: the embedding evaluates the Jacobian
//!    over the whole box, not at the centre, and an ill-conditioned `T` amplifies its
//!    variation (a scaled Jordan chain would otherwise shrink its coupling to the cap);
//! 4. the identity unless `T` beats it.
//!
//! This is a heuristic in floating point: nothing proved depends on it (the engine encloses
//! `T^-1` rigorously whatever `T` is).

use nalgebra::{DMatrix, Schur};

use crate::ir::{ExprId, Pool, Table, Var, VarValues};

/// The largest `cond_inf(T) = |T|_inf |T^-1|_inf` a chosen transform may have.
pub const MAX_CONDITION: f64 = 1e6;

/// The most states `transform = auto` handles (the transformed drift is dense: `n^2` terms).
pub const MAX_AUTO_STATES: usize = 16;

/// Up to this many states the polish moves every entry of `T` (`n^2` parameters); above, only
/// the scaling of its rows.
const FULL_POLISH_STATES: usize = 4;

/// The conditioning step accepts `mu_inf` up to this fraction (of `|mu_inf|`) above the best.
const MU_SLACK: f64 = 0.01;

/// Blocks whose eigenvalues are closer than this (relative to `max |A_ij|`) stay coupled: the
/// Sylvester equation decoupling them would be ill-conditioned.
const SEPARATION: f64 = 1e-2;

/// The coupling (relative to `max |A_ij|`) the start scales the couplings between close
/// eigenvalues down to; the polish goes further where that pays.
const COUPLING: f64 = 1e-2;

/// Function evaluations of one Nelder-Mead run, per parameter.
const EVALS_PER_PARAMETER: usize = 400;

/// A transform chosen for a Jacobian `A`.
#[derive(Clone, Debug, PartialEq)]
pub struct AutoTransform {
    /// `T` (the identity when nothing beats it).
    pub matrix: DMatrix<f64>,
    /// `mu_inf(T A T^-1)`.
    pub log_norm: f64,
    /// `mu_inf(A)`.
    pub identity_log_norm: f64,
}

/// The logarithmic infinity norm `max_i (B_ii + sum_(j != i) |B_ij|)` of a square matrix.
pub fn log_norm_inf(b: &DMatrix<f64>) -> f64 {
    b.row_iter()
        .enumerate()
        .map(|(i, row)| {
            row.iter()
                .enumerate()
                .map(|(j, &v)| if i == j { v } else { v.abs() })
                .sum::<f64>()
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// `D_x f` at the point `(x, u, t)` (floating point), for the drift `drift` over `x.len()`
/// states; entries may be non-finite (the caller decides).
pub fn jacobian_at(
    pool: &mut Pool,
    drift: &[ExprId],
    tables: &[Table],
    (x, u, t): (&[f64], &[f64], f64),
) -> DMatrix<f64> {
    let n = x.len();
    let zero = pool.num(0.0);
    let mut entries = vec![zero; n * n];
    for (i, &f) in drift.iter().enumerate() {
        // Only the states f_i uses (the others' derivative is 0).
        for v in pool.vars_of(f) {
            if let Var::State(j) = v {
                entries[i * n + j as usize] = pool.diff(f, v);
            }
        }
    }
    let vars = VarValues {
        states: x,
        inputs: u,
        noises: &[],
        time: t,
    };
    DMatrix::from_row_slice(n, n, &pool.eval(&entries, &vars, tables))
}

/// The transform for the Jacobian `a` (finite): see the module documentation.
pub fn choose_transform(a: &DMatrix<f64>) -> AutoTransform {
    let n = a.nrows();
    let identity = DMatrix::identity(n, n);
    let identity_log_norm = log_norm_inf(a);
    let fallback = AutoTransform {
        matrix: identity.clone(),
        log_norm: identity_log_norm,
        identity_log_norm,
    };
    let scale = a.amax();
    // A scalar or zero Jacobian: every T gives the same mu_inf.
    if n < 2 || scale == 0.0 || !scale.is_finite() {
        return fallback;
    }
    let objective = Objective { a };
    let best = spectral_start(a, scale)
        .into_iter()
        .chain([identity])
        .filter_map(|start| objective.polish(start, |t| objective.mu(t)))
        .filter_map(|t| Some((objective.mu(&t)?, t)))
        .min_by(|x, y| x.0.total_cmp(&y.0));
    let Some((mu, t)) = best else {
        return fallback;
    };
    if mu >= identity_log_norm {
        return fallback;
    }
    // Trade at most 1% of mu, and never the gain over the identity, for conditioning.
    let slack = (MU_SLACK * mu.abs()).min(0.5 * (identity_log_norm - mu));
    let bound = mu + slack;
    let conditioned = objective
        .polish(t.clone(), |t| {
            objective
                .mu(t)
                .filter(|&m| m <= bound)
                .and_then(|_| condition(t))
                .map(f64::ln)
        })
        .unwrap_or(t);
    let matrix = objective.round(tidy(conditioned), 0.1 * slack);
    match objective.mu(&matrix) {
        Some(log_norm) if log_norm < identity_log_norm => AutoTransform {
            matrix,
            log_norm,
            identity_log_norm,
        },
        _ => fallback,
    }
}

/// `mu_inf(T A T^-1)` as a function of `T`.
struct Objective<'a> {
    a: &'a DMatrix<f64>,
}

impl Objective<'_> {
    /// `mu_inf(T A T^-1)`, or `None` when `T` is singular or worse conditioned than
    /// [`MAX_CONDITION`].
    fn mu(&self, t: &DMatrix<f64>) -> Option<f64> {
        condition(t)?;
        let inv = t.clone().try_inverse()?;
        Some(log_norm_inf(&(t * self.a * inv))).filter(|m| m.is_finite())
    }

    /// `t` with its entries rounded to the fewest decimals (of its largest entry, about 1) that
    /// cost at most `loss` of `mu_inf`: a readable `T` that a spec can quote.
    fn round(&self, t: DMatrix<f64>, loss: f64) -> DMatrix<f64> {
        let Some(mu) = self.mu(&t) else {
            return t;
        };
        (1..=12)
            .map(|digits| {
                let unit = 10f64.powi(digits);
                t.map(|v| (v * unit).round() / unit)
            })
            .find(|r| self.mu(r).is_some_and(|m| m <= mu + loss))
            .unwrap_or(t)
    }

    /// Nelder-Mead from `start` on `value` (`None`: infeasible), over `T`'s entries for small
    /// `n`, else over the logarithms of a scaling of its rows; `None` if `start` is infeasible.
    fn polish(
        &self,
        start: DMatrix<f64>,
        value: impl Fn(&DMatrix<f64>) -> Option<f64>,
    ) -> Option<DMatrix<f64>> {
        value(&start)?;
        let n = start.nrows();
        let f = |t: &DMatrix<f64>| value(t).unwrap_or(f64::INFINITY);
        if n <= FULL_POLISH_STATES {
            let to_t = |x: &[f64]| DMatrix::from_row_slice(n, n, x);
            let x0: Vec<f64> = start.transpose().iter().copied().collect();
            let step = 0.1 * start.amax();
            Some(to_t(&nelder_mead(x0, step, |x| f(&to_t(x)))))
        } else {
            let to_t = |x: &[f64]| {
                let mut t = start.clone();
                for (mut row, &s) in t.row_iter_mut().zip(x) {
                    row *= s.exp();
                }
                t
            };
            Some(to_t(&nelder_mead(vec![0.0; n], 0.5, |x| f(&to_t(x)))))
        }
    }
}

/// `cond_inf(T)`, or `None` when `T` is singular or worse conditioned than [`MAX_CONDITION`].
fn condition(t: &DMatrix<f64>) -> Option<f64> {
    let inv = t.clone().try_inverse()?;
    let norm = |m: &DMatrix<f64>| {
        m.row_iter()
            .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    Some(norm(t) * norm(&inv)).filter(|&c| c <= MAX_CONDITION)
}

/// `T` scaled by a power of two so that its largest entry is about 1, and each row's largest
/// entry made positive: both leave `|T A T^-1|` exactly as it is, and the printed `T` readable.
fn tidy(mut t: DMatrix<f64>) -> DMatrix<f64> {
    let exponent = t.amax().log2().round() as i32;
    t *= 2f64.powi(-exponent);
    for mut row in t.row_iter_mut() {
        let largest = row
            .iter()
            .copied()
            .max_by(|x, y| x.abs().total_cmp(&y.abs()));
        if largest.is_some_and(|v| v < 0.0) {
            row.neg_mut();
        }
    }
    t
}

/// A similarity `T` bringing `a` close to block-diagonal form (see the module documentation),
/// or `None` if the Schur decomposition does not converge.
fn spectral_start(a: &DMatrix<f64>, scale: f64) -> Option<DMatrix<f64>> {
    let n = a.nrows();
    let (q, u) = Schur::try_new(a.clone(), f64::EPSILON, 1000 * n).map(Schur::unpack)?;
    // Invariant: b = t a t^-1.
    let mut t = q.transpose();
    let mut b = u;
    let mut blocks = Vec::new();
    let mut i = 0;
    while i < n {
        let size = if i + 1 < n && b[(i + 1, i)].abs() > 1e-12 * scale {
            2
        } else {
            1
        };
        blocks.push((i, size));
        i += size;
    }
    let similar =
        |m: &DMatrix<f64>, m_inv: &DMatrix<f64>, b: &mut DMatrix<f64>, t: &mut DMatrix<f64>| {
            *b = m * &*b * m_inv;
            *t = m * &*t;
        };
    // Complex pairs to [[a, b], [-b, a]].
    for &(i, size) in &blocks {
        if size == 2 {
            if let Some((s, s_inv)) = standard_pair(&b.view((i, i), (2, 2)).into_owned()) {
                let (mut m, mut m_inv) = (DMatrix::identity(n, n), DMatrix::identity(n, n));
                m.view_mut((i, i), (2, 2)).copy_from(&s);
                m_inv.view_mut((i, i), (2, 2)).copy_from(&s_inv);
                similar(&m, &m_inv, &mut b, &mut t);
            }
        }
    }
    // Decouple block pairs nearest the diagonal first: eliminating block (i, j) changes only
    // blocks farther from the diagonal (rows above i in column j, columns right of j in row i).
    for d in 1..blocks.len() {
        for k in 0..blocks.len() - d {
            let (bi, bj) = (blocks[k], blocks[k + d]);
            if let Some(z) = sylvester(&b, bi, bj, scale) {
                let (mut m, mut m_inv) = (DMatrix::identity(n, n), DMatrix::identity(n, n));
                m.view_mut((bi.0, bj.0), (bi.1, bj.1)).copy_from(&(-&z));
                m_inv.view_mut((bi.0, bj.0), (bi.1, bj.1)).copy_from(&z);
                similar(&m, &m_inv, &mut b, &mut t);
            }
        }
    }
    // What is left above the diagonal blocks couples close eigenvalues: scale it down by a
    // diagonal similarity (entry (i, j) becomes b_ij s_i / s_j), as a Jordan chain is scaled.
    let mut s = vec![1.0f64; blocks.len()];
    for j in 0..blocks.len() {
        for i in 0..j {
            let (bi, bj) = (blocks[i], blocks[j]);
            let coupling = b.view((bi.0, bj.0), (bi.1, bj.1)).amax();
            s[j] = s[j].max(s[i] * coupling / (COUPLING * scale));
        }
        // Keep the start within the conditioning cap (the polish finds the balance).
        s[j] = s[j].min(MAX_CONDITION.sqrt());
    }
    let rows: Vec<f64> = blocks
        .iter()
        .zip(&s)
        .flat_map(|(&(_, size), &v)| std::iter::repeat_n(v, size))
        .collect();
    let m = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(rows.clone()));
    let m_inv = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
        n,
        rows.iter().map(|v| 1.0 / v),
    ));
    similar(&m, &m_inv, &mut b, &mut t);
    Some(t)
}

/// For a 2x2 block with complex eigenvalues `a +- ib`: `S` and `S^-1` with
/// `S M S^-1 = [[a, b], [-b, a]]` (`S^-1 = [Re v, Im v]`, `v` the eigenvector of `a + ib`).
fn standard_pair(m: &DMatrix<f64>) -> Option<(DMatrix<f64>, DMatrix<f64>)> {
    let (p, q, r, s) = (m[(0, 0)], m[(0, 1)], m[(1, 0)], m[(1, 1)]);
    let half = 0.5 * (p - s);
    let disc = half * half + q * r;
    if disc >= 0.0 || disc.is_nan() {
        return None;
    }
    let (alpha, beta) = (0.5 * (p + s), (-disc).sqrt());
    // (M - (a + ib)) v = 0 by its first row: v = (q, a - p + ib); q != 0 as qr < 0.
    let v = DMatrix::from_row_slice(2, 2, &[q, 0.0, alpha - p, beta]);
    let s = v.clone().try_inverse()?;
    Some((s, v))
}

/// `Z` with `B_ii Z - Z B_jj = -B_ij` for the diagonal blocks `i = (start, size)` and `j` of
/// `b`, or `None` when their eigenvalues are too close ([`SEPARATION`]).
fn sylvester(
    b: &DMatrix<f64>,
    i: (usize, usize),
    j: (usize, usize),
    scale: f64,
) -> Option<DMatrix<f64>> {
    let (p, q) = (i.1, j.1);
    let bii = b.view((i.0, i.0), (p, p));
    let bjj = b.view((j.0, j.0), (q, q));
    // vec(B_ii Z - Z B_jj) = (I_q (x) B_ii - B_jj' (x) I_p) vec(Z), column-major.
    let mut k = DMatrix::<f64>::zeros(p * q, p * q);
    for c in 0..q {
        for r in 0..p {
            for l in 0..p {
                k[(r + p * c, l + p * c)] += bii[(r, l)];
            }
            for l in 0..q {
                k[(r + p * c, r + p * l)] -= bjj[(l, c)];
            }
        }
    }
    let smallest = k.singular_values().min();
    if smallest.is_nan() || smallest <= SEPARATION * scale {
        return None;
    }
    let rhs = -b.view((i.0, j.0), (p, q)).into_owned();
    let z = k
        .lu()
        .solve(&nalgebra::DVector::from_column_slice(rhs.as_slice()))?;
    Some(DMatrix::from_column_slice(p, q, z.as_slice()))
}

/// Minimises `f` from `x0` by Nelder-Mead (initial simplex `x0 + step e_k`), restarted from its
/// best point while that improves (a restart unsticks a collapsed simplex, which the kinks of
/// a max of absolute values invite). Deterministic.
fn nelder_mead(x0: Vec<f64>, step: f64, f: impl Fn(&[f64]) -> f64) -> Vec<f64> {
    let dim = x0.len();
    let mut best = (not_nan(f(&x0)), x0);
    for _ in 0..4 {
        let (value, x) = nelder_mead_run(&best.1, step, &f, EVALS_PER_PARAMETER * dim);
        if value >= best.0 {
            break;
        }
        best = (value, x);
    }
    best.1
}

/// `v`, with NaN as infinity (so comparisons order every point).
fn not_nan(v: f64) -> f64 {
    if v.is_nan() {
        f64::INFINITY
    } else {
        v
    }
}

/// One Nelder-Mead run (reflection 1, expansion 2, contraction and shrink 1/2) of at most
/// `max_evals` evaluations: the best point and its value.
fn nelder_mead_run(
    x0: &[f64],
    step: f64,
    f: &impl Fn(&[f64]) -> f64,
    max_evals: usize,
) -> (f64, Vec<f64>) {
    let dim = x0.len();
    let eval = |x: Vec<f64>| (not_nan(f(&x)), x);
    let mut simplex: Vec<(f64, Vec<f64>)> = vec![eval(x0.to_vec())];
    for k in 0..dim {
        let mut x = x0.to_vec();
        x[k] += step;
        simplex.push(eval(x));
    }
    let mut evals = dim + 1;
    let along = |from: &[f64], to: &[f64], s: f64| -> Vec<f64> {
        from.iter().zip(to).map(|(a, b)| a + s * (b - a)).collect()
    };
    while evals < max_evals {
        simplex.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (lo, hi) = (simplex[0].0, simplex[dim].0);
        if hi - lo <= 1e-13 * (1.0 + lo.abs()) {
            break;
        }
        let mut centroid = vec![0.0; dim];
        for (_, x) in &simplex[..dim] {
            for (c, v) in centroid.iter_mut().zip(x) {
                *c += v / dim as f64;
            }
        }
        let worst = simplex[dim].1.clone();
        let reflected = eval(along(&centroid, &worst, -1.0));
        evals += 1;
        if reflected.0 < lo {
            let expanded = eval(along(&centroid, &worst, -2.0));
            evals += 1;
            simplex[dim] = if expanded.0 < reflected.0 {
                expanded
            } else {
                reflected
            };
        } else if reflected.0 < simplex[dim - 1].0 {
            simplex[dim] = reflected;
        } else {
            let outside = reflected.0 < hi;
            let contracted = if outside {
                eval(along(&centroid, &reflected.1, 0.5))
            } else {
                eval(along(&centroid, &worst, 0.5))
            };
            evals += 1;
            if contracted.0 < reflected.0.min(hi) {
                simplex[dim] = contracted;
            } else {
                let best = simplex[0].1.clone();
                for point in &mut simplex[1..] {
                    *point = eval(along(&best, &point.1, 0.5));
                }
                evals += dim;
            }
        }
    }
    simplex
        .into_iter()
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap_or((f64::INFINITY, x0.to_vec()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mat(n: usize, v: &[f64]) -> DMatrix<f64> {
        DMatrix::from_row_slice(n, n, v)
    }

    fn mu_of(t: &DMatrix<f64>, a: &DMatrix<f64>) -> f64 {
        log_norm_inf(&(t * a * t.clone().try_inverse().unwrap()))
    }

    #[test]
    fn log_norm_is_the_largest_row_sum_with_signed_diagonal() {
        assert_eq!(log_norm_inf(&mat(2, &[0.0, 1.0, -4.0, -2.0])), 2.0);
        assert_eq!(log_norm_inf(&mat(2, &[-3.0, 1.0, -1.0, -1.0])), 0.0);
    }

    /// Distinct real eigenvalues: the eigenvector basis, `mu_inf` = the largest eigenvalue.
    #[test]
    fn real_eigenvalues_reach_the_spectral_abscissa() {
        // The pendulum at 0: eigenvalues -10 +- sqrt(90).
        let a = mat(2, &[0.0, 1.0, -10.0, -20.0]);
        let chosen = choose_transform(&a);
        let lambda = -10.0 + 90f64.sqrt();
        assert_eq!(chosen.identity_log_norm, 1.0);
        assert!(
            chosen.log_norm <= lambda * (1.0 - MU_SLACK) + 1e-9,
            "{chosen:?}"
        );
        assert!((mu_of(&chosen.matrix, &a) - chosen.log_norm).abs() <= 1e-12);
        assert!(condition(&chosen.matrix).is_some());
    }

    /// A complex pair `a +- ib`: `a + |b|` is the best any `T` does for a 2x2 block.
    #[test]
    fn complex_pair_reaches_its_bound() {
        // x'' + 2 x' + 1.5 x = 0: -1 +- i / sqrt(2).
        let a = mat(2, &[0.0, 1.0, -1.5, -2.0]);
        let chosen = choose_transform(&a);
        let bound = -1.0 + 0.5f64.sqrt();
        assert!(chosen.log_norm >= bound - 1e-9, "{chosen:?}");
        assert!(chosen.log_norm <= bound + MU_SLACK + 1e-9, "{chosen:?}");
        let (s, s_inv) = standard_pair(&a).unwrap();
        let b = &s * &a * &s_inv;
        let want = mat(2, &[-1.0, 0.5f64.sqrt(), -(0.5f64.sqrt()), -1.0]);
        assert!((b - want).amax() <= 1e-12);
    }

    /// A defective eigenvalue (critical damping, -1 twice): a scaled Jordan chain, within the
    /// slack of -1 and well conditioned.
    #[test]
    fn defective_eigenvalue_scales_its_chain() {
        let a = mat(2, &[0.0, 1.0, -1.0, -2.0]);
        let chosen = choose_transform(&a);
        assert!(chosen.log_norm < -0.95, "{chosen:?}");
        let cond = condition(&chosen.matrix).unwrap();
        assert!(cond < 1e4, "cond {cond}");
    }

    /// Mixed blocks in 5 dimensions (row-scaling polish): the start decouples them.
    #[test]
    fn larger_systems_decouple_blocks() {
        let a = mat(
            5,
            &[
                -1.0, 3.0, 0.5, 0.0, 0.2, //
                -3.0, -1.0, 0.0, 0.4, 0.0, //
                0.3, 0.0, -2.0, 1.0, 0.0, //
                0.0, 0.2, 0.0, -4.0, 0.5, //
                0.1, 0.0, 0.0, 0.0, -5.0,
            ],
        );
        // The complex pair near -1 +- 3i keeps mu_inf near -1 + 3 (the identity: 2.7); the
        // start reaches about that, the conditioning step gives up at most 1%.
        let start = spectral_start(&a, a.amax()).unwrap();
        assert!(mu_of(&start, &a) < 2.0, "{start}");
        let chosen = choose_transform(&a);
        assert_eq!(chosen.identity_log_norm, 2.7);
        assert!(chosen.log_norm < 2.0 * (1.0 + MU_SLACK), "{chosen:?}");
    }

    /// Nothing beats the identity for a diagonal matrix, and a scalar has nothing to choose.
    #[test]
    fn identity_when_nothing_beats_it() {
        for a in [
            mat(2, &[-1.0, 0.0, 0.0, -3.0]),
            mat(1, &[2.0]),
            mat(2, &[0.0; 4]),
        ] {
            let chosen = choose_transform(&a);
            let n = a.nrows();
            assert_eq!(chosen.matrix, DMatrix::identity(n, n));
            assert_eq!(chosen.log_norm, chosen.identity_log_norm);
        }
    }
}
