//! The metric of `metric = auto` in a discrete-time model. For an affine map with additive
//! noise (`x+ = A x + b(u) + G w`), `P = Sigma_K^-1`, the inverse of the deviation's covariance
//! at the horizon (`Sigma_(k+1) = A Sigma_k A' + G G'`, `K` steps): its exact Gaussian set
//! (method.md 8.16, Claim 3) is then the chi-square ellipsoid itself at the horizon. Otherwise
//! the solution `P` of the discrete Lyapunov (Stein) equation `A' P A - P = -I`, with `A = D_x f`
//! the map's Jacobian at the centre of the initial set (inputs at the centre of their box,
//! `t = 0`). When `A`'s spectral radius is below 1, `P = sum_k (A')^k A^k` is symmetric positive
//! definite and `|A v|_P^2 = |v|_P^2 - |v|^2`: the linearised map contracts in its norm.

use nalgebra::{DMatrix, Schur};

use super::Derivatives;
use crate::ir::VarValues;
use crate::model::Model;

/// Most states solved through the Kronecker form (an `n^2 x n^2` system); larger models use
/// the doubling iteration.
pub const MAX_KRONECKER_STATES: usize = 16;

/// Most squarings of the doubling iteration (`A^(2^k)` vanishes long before for a spectral
/// radius below 1 that is not within about `1e-16` of it).
const MAX_DOUBLINGS: usize = 64;

/// Largest relative residual `|A' P A - P + I| / |P|` (max norms) accepted.
const MAX_RESIDUAL: f64 = 1e-8;

/// The metric for a discrete-time model's `metric = auto`: the Stein solution for the map's
/// Jacobian at the initial set's centre, symmetrised and scaled by a power of two to a
/// largest entry in `[1, 2)` (row-major), or `None` when there is none (a Jacobian that is not
/// finite there, a spectral radius of at least 1, a solution that is not positive definite).
pub fn map_metric(model: &Model, d: &Derivatives, steps: usize) -> Option<Vec<f64>> {
    let a = centre_jacobian(model, d)?;
    let p = covariance_metric(model, d, &a, steps).or_else(|| stein(&a))?;
    let n = p.nrows();
    let rows = (0..n)
        .map(|i| (0..n).map(|j| p[(i, j)]).collect())
        .collect::<Vec<Vec<f64>>>();
    Some(crate::model::normalised_metric(rows).concat())
}

/// Most condition number of `Sigma_K` whose inverse is taken as the metric.
const MAX_COVARIANCE_CONDITION: f64 = 1e10;

/// `Sigma_K^-1` for an affine map (`A = D_x f` constant) with additive noise (`G` constant),
/// when `Sigma_K` is well conditioned: `None` otherwise.
fn covariance_metric(
    model: &Model,
    d: &Derivatives,
    a: &DMatrix<f64>,
    steps: usize,
) -> Option<DMatrix<f64>> {
    let constant = |e: &crate::ir::ExprId| model.pool.vars_of(*e).is_empty();
    let affine = d.jac_x.iter().flatten().all(constant);
    let additive = model.diffusion.iter().flatten().all(constant);
    if !affine || !additive || steps == 0 {
        return None;
    }
    let (n, m) = (model.states.len(), model.noises.len());
    let vars = VarValues {
        states: &vec![0.0; n],
        inputs: &vec![0.0; model.inputs.len()],
        noises: &[],
        time: 0.0,
    };
    let g = model
        .pool
        .eval(&model.diffusion.concat(), &vars, &model.tables);
    let g = DMatrix::from_row_slice(n, m, &g);
    let w = &g * g.transpose();
    let mut sigma = DMatrix::<f64>::zeros(n, n);
    for _ in 0..steps {
        sigma = a * &sigma * a.transpose() + &w;
    }
    let sigma = (&sigma + sigma.transpose()) * 0.5;
    let eig = sigma.clone().symmetric_eigenvalues();
    let (lo, hi) = (eig.min(), eig.max());
    if !(lo > 0.0 && hi.is_finite() && hi / lo <= MAX_COVARIANCE_CONDITION) {
        return None;
    }
    let p = sigma.try_inverse()?;
    let p = (&p + p.transpose()) * 0.5;
    p.clone().cholesky().map(|_| p)
}

/// `D_x f` at the centre of the initial set's bounding box, the inputs' centre and `t = 0`, if
/// finite.
fn centre_jacobian(model: &Model, d: &Derivatives) -> Option<DMatrix<f64>> {
    let centre = |b: &crate::model::Bounds| 0.5 * b.lo + 0.5 * b.hi;
    let x: Vec<f64> = model
        .initial
        .bounding_box()
        .ok()?
        .iter()
        .map(centre)
        .collect();
    let u: Vec<f64> = model.input_box.iter().map(centre).collect();
    let n = x.len();
    let vars = VarValues {
        states: &x,
        inputs: &u,
        noises: &[],
        time: 0.0,
    };
    let entries = d.jac_x.concat();
    let values = model.pool.eval(&entries, &vars, &model.tables);
    values
        .iter()
        .all(|v| v.is_finite())
        .then(|| DMatrix::from_row_slice(n, n, &values))
}

/// The solution `P` of `A' P A - P = -I`, symmetrised, when `A`'s spectral radius is below 1
/// and `P` is positive definite with a small residual; `None` otherwise.
pub fn stein(a: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let n = a.nrows();
    if n == 0 || a.ncols() != n || spectral_radius(a)? >= 1.0 {
        return None;
    }
    let p = if n <= MAX_KRONECKER_STATES {
        kronecker(a)?
    } else {
        doubling(a)?
    };
    let p = (&p + p.transpose()) * 0.5;
    let residual = a.transpose() * &p * a - &p + DMatrix::identity(n, n);
    let scale = p.amax();
    let accepted = scale.is_finite()
        && residual.amax() <= MAX_RESIDUAL * scale
        && p.clone().cholesky().is_some();
    accepted.then_some(p)
}

/// The largest modulus of `a`'s eigenvalues, `None` if the Schur decomposition fails.
fn spectral_radius(a: &DMatrix<f64>) -> Option<f64> {
    let n = a.nrows();
    let schur = Schur::try_new(a.clone(), f64::EPSILON, 1000 * n.max(1))?;
    let radius = schur
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max);
    radius.is_finite().then_some(radius)
}

/// `vec(A' P A) = (A' (x) A') vec(P)`: the `n^2` linear equations `(A' (x) A' - I) vec(P) =
/// -vec(I)`, solved by LU.
fn kronecker(a: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let n = a.nrows();
    let at = a.transpose();
    let system = at.kronecker(&at) - DMatrix::identity(n * n, n * n);
    let minus_identity = -DMatrix::<f64>::identity(n, n);
    let rhs = nalgebra::DVector::from_column_slice(minus_identity.as_slice());
    let solution = system.lu().solve(&rhs)?;
    Some(DMatrix::from_column_slice(n, n, solution.as_slice()))
}

/// `P = sum_k (A')^k A^k` by doubling: `P <- P + B' P B`, `B <- B^2`, from `P = I`, `B = A`,
/// until `B` vanishes against `P`.
fn doubling(a: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let n = a.nrows();
    let mut p = DMatrix::identity(n, n);
    let mut b = a.clone();
    for _ in 0..MAX_DOUBLINGS {
        p = &p + b.transpose() * &p * &b;
        b = &b * &b;
        let tail = b.amax();
        if !tail.is_finite() || !p.amax().is_finite() {
            return None;
        }
        if tail * tail * (n as f64) <= f64::EPSILON {
            return Some(p);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `|A' P A - P + I|` relative to `|P|` (max norms).
    fn relative_residual(a: &DMatrix<f64>, p: &DMatrix<f64>) -> f64 {
        let n = a.nrows();
        (a.transpose() * p * a - p + DMatrix::identity(n, n)).amax() / p.amax()
    }

    /// A 2x2 rotation-and-shear with spectral radius 0.9: both solvers, to 1e-9 relative.
    #[test]
    fn two_by_two_solves_the_stein_equation() {
        let a = DMatrix::from_row_slice(2, 2, &[0.9, 0.3, -0.1, 0.7]);
        let p = stein(&a).expect("stable");
        assert!(relative_residual(&a, &p) < 1e-12, "{p}");
        assert_eq!(p[(0, 1)], p[(1, 0)]);
        let doubled = doubling(&a).unwrap();
        assert!((&doubled - &p).amax() <= 1e-9 * p.amax(), "{doubled} {p}");
        // A scalar: P = 1 / (1 - a^2).
        let p = stein(&DMatrix::from_element(1, 1, 0.5)).unwrap();
        assert!((p[(0, 0)] - 4.0 / 3.0).abs() < 1e-15);
    }

    /// A 20-state chain (doubling) and a 3-state one (Kronecker) agree with the residual.
    #[test]
    fn larger_models_use_the_doubling_iteration() {
        for n in [3, MAX_KRONECKER_STATES + 4] {
            let mut a = DMatrix::identity(n, n) * 0.8;
            for i in 1..n {
                a[(i, i - 1)] = 0.1;
            }
            let p = stein(&a).expect("stable");
            assert!(relative_residual(&a, &p) < 1e-12, "{n}");
            assert!(p.clone().cholesky().is_some());
        }
    }

    /// No metric for a map that does not contract: spectral radius 1 or more.
    #[test]
    fn unstable_maps_have_none() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 0.1, 0.0, 1.0]);
        assert!(stein(&a).is_none());
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.1, -1.1, 0.0]);
        assert!(stein(&a).is_none());
    }
}
