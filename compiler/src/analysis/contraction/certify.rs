//! The certified bounds over a matrix set: the metric checked, the pencil `lambda_max` proposed
//! in floating point and certified by interval LDL' (`c`, `sigma`), and `rho` over the input
//! box's corners or columns.

use nalgebra::{DMatrix, SymmetricEigen};
use reachc_core::interval::Interval;
use reachc_core::model::InputGain;

use super::vertices::MatrixSet;
use super::{ConstantsError, MAX_SIGN_INPUTS};
use crate::analysis::psd::{certify_min, is_psd, is_zero, sqrt_up, IMat, Pencil};

/// Above this dimension float eigenvalues (`O(n^3)`) are not used to propose a constant; the
/// search starts from a Rayleigh-quotient lower bound and bisects with the certified test.
const EIGEN_MAX_DIM: usize = 200;

/// Checks that `metric` is `n x n`, finite, exactly symmetric and (certifiably) positive definite.
pub(crate) fn check_metric(metric: &[f64], n: usize) -> Result<IMat, ConstantsError> {
    let bad = |reason: String| Err(ConstantsError::BadMetric { reason });
    if metric.len() != n * n {
        return bad(format!(
            "expected {n} x {n} = {} entries, found {}",
            n * n,
            metric.len()
        ));
    }
    if metric.iter().any(|v| !v.is_finite()) {
        return bad("an entry is not finite".into());
    }
    for i in 0..n {
        for j in 0..i {
            if metric[i * n + j] != metric[j * n + i] {
                return bad(format!(
                    "not symmetric: entries ({i}, {j}) and ({j}, {i}) differ"
                ));
            }
        }
    }
    let p = IMat::from_f64(n, n, metric);
    if !is_psd(&p, true) {
        return bad("not positive definite".into());
    }
    Ok(p)
}

/// Float square matrix from row-major data.
fn dmat(n: usize, data: &[f64]) -> DMatrix<f64> {
    DMatrix::from_row_slice(n, n, data)
}

/// Float estimates of `lambda_max` of the pencil `(S, P)`, i.e. of `L^-1 S L^-T` with
/// `P = L L'`, for symmetric `S` (given as row-major float data).
///
/// Large problems get the Rayleigh lower bound `max_i S_ii / P_ii` instead (the certified search
/// bisects up from it). Returns the estimates and a magnitude for the search's step sizes.
pub(crate) fn pencil_lambda_max(s_list: &[Vec<f64>], metric: &[f64], n: usize) -> (Vec<f64>, f64) {
    let mut scale = 0.0f64;
    for s in s_list {
        for i in 0..n {
            scale = scale.max((s[i * n + i] / metric[i * n + i]).abs());
        }
    }
    let chol = (n <= EIGEN_MAX_DIM)
        .then(|| nalgebra::Cholesky::new(dmat(n, metric)))
        .flatten();
    let estimates = s_list
        .iter()
        .map(|s| match &chol {
            Some(chol) => {
                let l = chol.l();
                let s = dmat(n, s);
                let x = l.solve_lower_triangular(&s).unwrap_or(s);
                let m = l
                    .solve_lower_triangular(&x.transpose())
                    .unwrap_or(x)
                    .transpose();
                let m = (&m + m.transpose()) * 0.5;
                let e = SymmetricEigen::new(m).eigenvalues;
                e.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            }
            None => (0..n)
                .map(|i| s[i * n + i] / metric[i * n + i])
                .fold(f64::NEG_INFINITY, f64::max),
        })
        .collect::<Vec<_>>();
    for e in &estimates {
        scale = scale.max(e.abs());
    }
    (estimates, scale)
}

/// The smallest `x` (certified) with `x * X - S_v` PSD for every `S_v` in `s_list`, where
/// `X` is the metric (for `c`, with `S = (A'P + PA) / 2`) or the identity (for `sigma^2`).
fn certify_pencil(
    s_list: &[IMat],
    x_mat: &IMat,
    x_float: &[f64],
    constant: &'static str,
) -> Result<f64, ConstantsError> {
    let n = x_mat.rows;
    if n == 0 || s_list.is_empty() {
        return Ok(0.0);
    }
    let mids: Vec<Vec<f64>> = s_list.iter().map(IMat::mid).collect();
    let (estimates, scale) = pencil_lambda_max(&mids, x_float, n);
    // Test the vertices with the largest estimates first: a failing one usually fails there.
    let mut order: Vec<usize> = (0..s_list.len()).collect();
    order.sort_by(|&a, &b| estimates[b].total_cmp(&estimates[a]));
    let guess = estimates.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let pencils: Vec<Pencil> = order
        .iter()
        .map(|&v| Pencil::new(&s_list[v], x_mat))
        .collect();
    let pass = |x: f64| pencils.iter().all(|q| q.psd_at(x));
    certify_min(guess, scale, pass).ok_or(ConstantsError::NotCertified { constant })
}

/// `S = (A'P + PA) / 2` in intervals (halving is exact).
fn sym_product(a: &IMat, p: &IMat) -> IMat {
    let pa = p.mul(a);
    let s = pa.add(&pa.transpose());
    IMat {
        data: s.data.iter().map(|&x| x * 0.5).collect(),
        ..s
    }
}

/// The certified contraction rate `c` for the metric `P`.
pub(crate) fn contraction_rate(
    set: &MatrixSet,
    p: &IMat,
    metric: &[f64],
) -> Result<f64, ConstantsError> {
    let s_list: Vec<IMat> = match set {
        MatrixSet::Vertices { vertices, .. } => {
            vertices.iter().map(|a| sym_product(a, p)).collect()
        }
        MatrixSet::Hull { matrix, .. } => vec![hull_pencil_matrix(matrix, p, metric)],
    };
    // `Q = 2cP - (A'P + PA) = 2 (c P - S)`: the factor 2 does not change PSD-ness.
    certify_pencil(&s_list, p, metric, "c")
}

/// For `A` in the interval matrix `[Mc - D, Mc + D]`: a symmetric interval matrix `S` with
/// `(A'P + PA) / 2 <= S` for every such `A`, so `cP - S >= 0` certifies `c`.
///
/// With `E = A - Mc`, `|E'P + PE| <= Nb = D'|P| + |P|D` entrywise. For any positive vector `v`,
/// the symmetric non-negative `Nb` satisfies `Nb <= diag(w)`, `w_i = (Nb v)_i / v_i` (the
/// difference is diagonally dominant after scaling by `v`), and `x'(E'P + PE)x <= |x|'Nb|x|`.
/// Hence `(A'P + PA)/2 <= (Mc'P + P Mc)/2 + diag(w)/2`. With `v_i = P_ii^(-1/2)` and a diagonal
/// `P` this is exactly method.md's `lambda_max(sym(Mc)) + rho(sym(D))` after the P-transform
/// (row sums bound the spectral radius); for a dense `P` it is a sound, cruder variant that
/// needs no exact square root of `P`.
fn hull_pencil_matrix(matrix: &IMat, p: &IMat, metric: &[f64]) -> IMat {
    let n = p.rows;
    let mut mc = IMat::zeros(n, n);
    let mut d = IMat::zeros(n, n);
    for (k, x) in matrix.data.iter().enumerate() {
        // `[mid - rad, mid + rad]` (exact) contains the entry.
        mc.data[k] = Interval::point(x.mid());
        d.data[k] = Interval::point(x.rad());
    }
    let abs_p = IMat::from_f64(n, n, &metric.iter().map(|x| x.abs()).collect::<Vec<_>>());
    let x = d.transpose().mul(&abs_p);
    let nb = x.add(&x.transpose());
    let v: Vec<Interval> = (0..n)
        .map(|i| Interval::point(1.0 / metric[i * n + i].sqrt()))
        .collect();
    let mut s = sym_product(&mc, p);
    for i in 0..n {
        let mut acc = Interval::ZERO;
        for (j, &vj) in v.iter().enumerate() {
            let b = nb.at(i, j);
            if !is_zero(b) {
                acc += Interval::point(b.hi()) * vj;
            }
        }
        let w = (acc / v[i]).hi();
        *s.at_mut(i, i) += Interval::point(w) * 0.5;
    }
    s
}

/// The certified `sigma` (`G'PG <= sigma^2 I`) for the metric.
pub(crate) fn noise_level(set: &MatrixSet, p: &IMat) -> Result<f64, ConstantsError> {
    let gs: Vec<&IMat> = match set {
        MatrixSet::Vertices { vertices, .. } => vertices.iter().collect(),
        MatrixSet::Hull { matrix, .. } => vec![matrix],
    };
    let m = gs.first().map_or(0, |g| g.cols);
    if m == 0 {
        return Ok(0.0);
    }
    // `G'PG` in intervals: for the hull this encloses `G'PG` for every `G` in the box (the
    // interval products over-approximate, which only loosens the bound).
    let t_list: Vec<IMat> = gs.iter().map(|g| g.transpose().mul(&p.mul(g))).collect();
    let identity: Vec<f64> = (0..m * m)
        .map(|k| if k % (m + 1) == 0 { 1.0 } else { 0.0 })
        .collect();
    let id = IMat::from_f64(m, m, &identity);
    let s2 = certify_pencil(&t_list, &id, &identity, "sigma")?;
    Ok(sqrt_up(s2))
}

/// The certified `rho` for the metric and the input box half-widths `h` (intervals enclosing
/// the exact half-widths, so whichever rounding the runtime uses for `h` is covered).
///
/// `rho = max over B and sign vectors s of |B diag(h) s|_P` (the U-ball's vertices; the norm is
/// convex), evaluated directly in interval arithmetic; with more than [`MAX_SIGN_INPUTS`] inputs
/// the sound column bound `sum_j h_j max_B |B e_j|_P` is used.
pub(crate) fn input_gain(
    set: &MatrixSet,
    p: &IMat,
    h: &[Interval],
) -> Result<(f64, InputGain), ConstantsError> {
    let bs: Vec<&IMat> = match set {
        MatrixSet::Vertices { vertices, .. } => vertices.iter().collect(),
        MatrixSet::Hull { matrix, .. } => vec![matrix],
    };
    let n = p.rows;
    let np = h.len();
    if np == 0 || bs.is_empty() {
        return Ok((0.0, InputGain::NoInputs));
    }
    for b in &bs {
        for (j, hj) in h.iter().enumerate() {
            if !hj.is_bounded() {
                if let Some(row) = (0..n).find(|&i| !is_zero(b.at(i, j))) {
                    return Err(ConstantsError::Unbounded {
                        matrix: "D_u f",
                        row,
                        column: j,
                    });
                }
            }
        }
    }
    let quad = |v: &[Interval]| {
        let mut q = Interval::ZERO;
        for i in 0..n {
            if is_zero(v[i]) {
                continue;
            }
            for j in 0..n {
                let pij = p.at(i, j);
                if !is_zero(pij) && !is_zero(v[j]) {
                    q += v[i] * pij * v[j];
                }
            }
        }
        q.hi()
    };
    // Bounded columns times finite (or zero) half-widths: drop columns with `h_j` unbounded
    // (they are zero columns, checked above).
    let column = |b: &IMat, j: usize, sign: f64| -> Vec<Interval> {
        if !h[j].is_bounded() {
            return vec![Interval::ZERO; n];
        }
        (0..n).map(|i| b.at(i, j) * h[j] * sign).collect()
    };
    if np > MAX_SIGN_INPUTS {
        let mut total = Interval::ZERO;
        for j in 0..np {
            let worst = bs
                .iter()
                .map(|b| quad(&column(b, j, 1.0)))
                .fold(0.0, f64::max);
            total += Interval::point(sqrt_up(worst));
        }
        return Ok((total.hi(), InputGain::Columns(set.bound())));
    }
    let mut worst = 0.0f64;
    for b in &bs {
        let cols: Vec<Vec<Interval>> = (0..np).map(|j| column(b, j, 1.0)).collect();
        // `s` and `-s` give the same norm: fix the last sign.
        for bits in 0..1usize << (np - 1) {
            let mut v = vec![Interval::ZERO; n];
            for (j, col) in cols.iter().enumerate() {
                let negative = j + 1 < np && bits >> j & 1 == 1;
                for i in 0..n {
                    v[i] = if negative {
                        v[i] - col[i]
                    } else {
                        v[i] + col[i]
                    };
                }
            }
            worst = worst.max(quad(&v));
        }
    }
    Ok((sqrt_up(worst), InputGain::Corners(set.bound())))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Float `max_v lambda_max(sym(R A_v R^-1))`, `P = R'R`, for the property test.
    fn float_mu(vertices: &[Vec<f64>], p: &[f64], n: usize) -> f64 {
        let l = nalgebra::Cholesky::new(dmat(n, p)).unwrap().l();
        let r = l.transpose();
        let r_inv = r.clone().try_inverse().unwrap();
        vertices
            .iter()
            .map(|a| {
                let t = &r * dmat(n, a) * &r_inv;
                let s = (&t + t.transpose()) * 0.5;
                SymmetricEigen::new(s).eigenvalues.max()
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(200))]
        #[test]
        fn certified_c_is_tight_and_sound(
            n in 2usize..4,
            seeds in proptest::collection::vec(-3.0f64..3.0, 64),
            nv in 1usize..5,
        ) {
            // Vertices `-2 I + small random`, a random SPD metric `P = M M' + I / 2`.
            let mut it = seeds.iter().cycle().copied();
            let vertices: Vec<Vec<f64>> = (0..nv)
                .map(|_| (0..n * n).map(|k| {
                    let x = it.next().unwrap();
                    if k % (n + 1) == 0 { x - 4.0 } else { x }
                }).collect())
                .collect();
            let m: Vec<f64> = (0..n * n).map(|_| it.next().unwrap() / 2.0).collect();
            let mut p = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    let mut s = if i == j { 0.5 } else { 0.0 };
                    for k in 0..n {
                        s += m[i * n + k] * m[j * n + k];
                    }
                    p[i * n + j] = s;
                }
            }
            for i in 0..n {
                for j in 0..i {
                    p[i * n + j] = p[j * n + i];
                }
            }
            let set = MatrixSet::Vertices {
                vertices: vertices.iter().map(|v| IMat::from_f64(n, n, v)).collect(),
                atoms: 0,
                fixed: 0,
            };
            let pi = check_metric(&p, n).unwrap();
            let c = contraction_rate(&set, &pi, &p).unwrap();
            let truth = float_mu(&vertices, &p, n);
            let scale = truth.abs().max(1.0);
            // Never below the truth (up to the float reference's own error), at most 1e-9 above.
            proptest::prop_assert!(c >= truth - 1e-12 * scale, "c = {c}, truth = {truth}");
            proptest::prop_assert!(c <= truth + 1e-9 * scale, "c = {c}, truth = {truth}");
        }
    }
}
