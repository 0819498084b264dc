//! The optimal metric by semidefinite programming (cargo feature `sdp`): a reference for the
//! default optimiser of [`super::synthesize_metric`], not part of the default build.
//!
//! `min c` subject to `A_i'P + PA_i <= 2cP` for every vertex `A_i` and `P >= I` is quasi-convex
//! (convex feasibility for fixed `c`), so it is solved by bisection on `c` with one SDP
//! feasibility problem per step (`min trace(P)` over the LMIs, with Clarabel). The pendulum's
//! optimum, computed independently, is in `core/tests/data/pendulum.json`. The returned `P` is a
//! float proposal like any other metric: it must go through the certified
//! [`super::constants`] before its rate is used.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use nalgebra::{DMatrix, SymmetricEigen};

use super::contraction::{decompose, semidefinite_atoms, ConstantsError, MatrixSet};
use super::psd::IMat;
use super::{time_range, Derivatives};
use crate::model::Model;

/// Relative width of the final bisection bracket.
const TOLERANCE: f64 = 1e-7;

/// Float vertex matrices (row-major `n x n`) of the Jacobian for the SDP: all `2^K` vertices when
/// there are at most [`super::MAX_VERTEX_ATOMS`] atoms; otherwise the vertices left after fixing
/// the atoms whose symmetric part is semidefinite for `P = I` (a subset of the vertices, so the
/// SDP optimum over it is a lower bound of the true one, and equal to it when, as for the chain,
/// that subset holds the worst matrix for every metric). `None` if there are still too many.
///
/// Errors: an unbounded entry of `D_x f` (as for [`super::constants`]).
pub fn jacobian_vertices(
    model: &Model,
    d: &Derivatives,
) -> Result<Option<Vec<Vec<f64>>>, ConstantsError> {
    let n = model.states.len();
    let dec = decompose(model, &d.jac_x, "D_x f", time_range(model))?;
    let mut set = dec.all_free();
    if matches!(set, MatrixSet::Hull { .. }) {
        let mut id = vec![0.0; n * n];
        for i in 0..n {
            id[i * n + i] = 1.0;
        }
        set = dec.set(&semidefinite_atoms(&dec, &IMat::from_f64(n, n, &id)));
    }
    Ok(match set {
        MatrixSet::Vertices { vertices, .. } => Some(vertices.iter().map(IMat::mid).collect()),
        MatrixSet::Hull { .. } => None,
    })
}

/// Index of `(i, j)`, `i <= j`, in the column-major upper triangle (Clarabel's PSD triangle
/// cone ordering, also used for the unknowns `P_ij`).
fn tri(i: usize, j: usize) -> usize {
    j * (j + 1) / 2 + i
}

/// `svec` of a symmetric matrix: column-major upper triangle, off-diagonals times `sqrt(2)`.
fn svec(m: &DMatrix<f64>) -> Vec<f64> {
    let n = m.nrows();
    let mut out = vec![0.0; n * (n + 1) / 2];
    for j in 0..n {
        for i in 0..=j {
            let v = 0.5 * (m[(i, j)] + m[(j, i)]);
            out[tri(i, j)] = if i == j {
                v
            } else {
                v * std::f64::consts::SQRT_2
            };
        }
    }
    out
}

/// The symmetric basis matrix of unknown `(i, j)`: `e_i e_j' + e_j e_i'` (`e_i e_i'` on the
/// diagonal).
fn basis(n: usize, i: usize, j: usize) -> DMatrix<f64> {
    let mut e = DMatrix::zeros(n, n);
    e[(i, j)] = 1.0;
    e[(j, i)] = 1.0;
    e
}

/// A `P >= I` with `A_i'P + PA_i <= 2cP` for every vertex (minimal trace), if the solver finds
/// one.
fn feasible(vertices: &[DMatrix<f64>], c: f64) -> Option<DMatrix<f64>> {
    let n = vertices[0].nrows();
    let dim = n * (n + 1) / 2;
    let blocks = 1 + vertices.len();
    // Columns of A (one per unknown) as (row, value) lists: s = b - A x in the cones.
    let mut colptr = vec![0usize];
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    let mut q = vec![0.0; dim];
    for j in 0..n {
        for i in 0..=j {
            let v = tri(i, j);
            if i == j {
                q[v] = 1.0;
            }
            let e = basis(n, i, j);
            let mut push_block = |block: usize, f: &DMatrix<f64>| {
                for (r, &x) in svec(f).iter().enumerate() {
                    if x != 0.0 {
                        rowval.push(block * dim + r);
                        nzval.push(-x);
                    }
                }
            };
            push_block(0, &e);
            for (k, a) in vertices.iter().enumerate() {
                let f = &e * (2.0 * c) - a.transpose() * &e - &e * a;
                push_block(k + 1, &f);
            }
            colptr.push(rowval.len());
        }
    }
    let a = CscMatrix::new(blocks * dim, dim, colptr, rowval, nzval);
    let mut b = vec![0.0; blocks * dim];
    for i in 0..n {
        // P - I >= 0: constant part -I.
        b[tri(i, i)] = -1.0;
    }
    let p_quad = CscMatrix::<f64>::zeros((dim, dim));
    let cones: Vec<SupportedConeT<f64>> = (0..blocks)
        .map(|_| SupportedConeT::PSDTriangleConeT(n))
        .collect();
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(300)
        .build()
        .ok()?;
    let mut solver = DefaultSolver::new(&p_quad, &q, &a, &b, &cones, settings).ok()?;
    solver.solve();
    if !matches!(solver.solution.status, SolverStatus::Solved) {
        return None;
    }
    let x = &solver.solution.x;
    let p = DMatrix::from_fn(n, n, |i, j| x[tri(i.min(j), i.max(j))]);
    // Accept only what the floats confirm (up to the solver's tolerance, relative to `P`).
    let scale = p.abs().max().max(1.0);
    let tol = 1e-6 * scale;
    let lmin = |m: DMatrix<f64>| SymmetricEigen::new(m).eigenvalues.min();
    let ok = lmin(&p - DMatrix::identity(n, n)) >= -tol
        && vertices.iter().all(|a| {
            let m = &p * (2.0 * c) - a.transpose() * &p - &p * a;
            lmin(m) >= -tol * (1.0 + a.abs().max() + c.abs())
        });
    ok.then_some(p)
}

/// `min c` over `P >= I` with `A_i'P + PA_i <= 2cP` for every vertex (row-major `n x n` float
/// matrices), by bisection on `c`: the optimal rate (to relative accuracy about `1e-7`) and a
/// feasible `P` for it (row-major, exactly symmetric). `None` for no vertices, inconsistent sizes
/// or a solver failure.
///
/// The `P` is a float proposal: certify it with [`super::constants`].
pub fn optimal_metric(vertices: &[Vec<f64>]) -> Option<(f64, Vec<f64>)> {
    let len = vertices.first()?.len();
    let n = (len as f64).sqrt().round() as usize;
    if n == 0 || n * n != len || vertices.iter().any(|v| v.len() != len) {
        return None;
    }
    let mats: Vec<DMatrix<f64>> = vertices
        .iter()
        .map(|v| DMatrix::from_row_slice(n, n, v))
        .collect();
    // Lower bound: mu_P(A) >= max Re lambda(A) for every P. Upper bound: P = I.
    let mut lo = mats
        .iter()
        .map(|a| {
            a.complex_eigenvalues()
                .iter()
                .map(|z| z.re)
                .fold(f64::NEG_INFINITY, f64::max)
        })
        .fold(f64::NEG_INFINITY, f64::max);
    let mut hi = mats
        .iter()
        .map(|a| {
            SymmetricEigen::new((a + a.transpose()) * 0.5)
                .eigenvalues
                .max()
        })
        .fold(f64::NEG_INFINITY, f64::max);
    let scale = mats
        .iter()
        .map(|a| a.abs().max())
        .fold(0.0, f64::max)
        .max(1e-12);
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    // P = I is feasible at `hi` up to rounding; step up until the solver agrees.
    let mut step = 1e-6 * scale;
    let mut best = loop {
        if let Some(p) = feasible(&mats, hi) {
            break p;
        }
        hi += step;
        step *= 4.0;
        if step > 1e3 * scale {
            return None;
        }
    };
    lo = lo.min(hi);
    for _ in 0..100 {
        if hi - lo <= TOLERANCE * hi.abs().max(1e-3 * scale) {
            break;
        }
        let mid = 0.5 * (lo + hi);
        match feasible(&mats, mid) {
            Some(p) => {
                hi = mid;
                best = p;
            }
            None => lo = mid,
        }
    }
    let mut out = vec![0.0; n * n];
    for i in 0..n {
        for j in i..n {
            out[i * n + j] = best[(i, j)];
            out[j * n + i] = best[(i, j)];
        }
    }
    Some((hi, out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pendulum_reference() {
        // core/tests/data/pendulum.json: sdp_optimum_c = -0.5132 for these vertices.
        let v = vec![vec![0.0, 1.0, -10.0, -20.0], vec![0.0, 1.0, -30.0, -20.0]];
        let (c, p) = optimal_metric(&v).unwrap();
        assert!((c + 0.5132).abs() < 1e-3, "c = {c}, P = {p:?}");
        assert_eq!(p[1], p[2]);
    }

    #[test]
    fn diagonal_is_exact() {
        let (c, _) = optimal_metric(&[vec![-0.4, 0.0, 0.0, -0.4]]).unwrap();
        assert!((c + 0.4).abs() < 1e-6, "{c}");
    }
}
