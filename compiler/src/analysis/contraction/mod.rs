//! The constants of Assumption 1 (method.md section 3) for one metric `P`, certified.
//!
//! * `c`: the smallest number with `A'P + PA <= 2cP` for every Jacobian `A = D_x f(x, u, t)`.
//! * `sigma`: `G(x, t)' P G(x, t) <= sigma^2 I`.
//! * `rho`: `|D_u f v|_P <= rho |v|_U` with `|v|_U = max_j |v_j| / h_j` (input box half-widths).
//!
//! Each matrix (`D_x f`, `G`, `D_u f`) is split into atoms, `M = M0 + sum_k a_k M_k`; every
//! quantity above is convex in `M`, so its maximum over the `2^K` vertices (atoms at the ends of
//! their interval ranges) bounds it over everything the model can produce. With more than
//! [`MAX_VERTEX_ATOMS`] atoms the whole matrix is taken as an interval matrix instead.
//!
//! Floats only propose: every returned number passed an interval-arithmetic test (see
//! [`super::psd`]) computed from the exact float data of the model and the metric.
//!
//! The entry points ([`constants`], [`constants_without_rate`]) and their error are here; the
//! matrix sets (atom decomposition, vertices, semidefinite atoms fixed) are in `vertices.rs`,
//! and the certified bounds of `c`, `sigma` and `rho` over a set in `certify.rs`.

mod certify;
#[cfg(test)]
mod fixtures;
mod vertices;

pub(crate) use certify::{check_metric, contraction_rate};
use certify::{input_gain, noise_level};
use vertices::matrix_set;
pub(crate) use vertices::{decompose, jacobian_set, semidefinite_atoms, MatrixSet};

use std::fmt;

use reachc_core::interval::Interval;
use reachc_core::model::{Bounds, Constants, ConstantsParts, MetricRegion, Provenance, Region};

use super::psd::IMat;
use super::{time_range, Derivatives};
use crate::model::Model;

/// With more atoms than this, the `2^K` vertices are too many and the interval-matrix bound is
/// used instead.
pub const MAX_VERTEX_ATOMS: usize = 10;

/// With more inputs than this, `rho` is bounded column by column instead of over all `2^p` sign
/// vectors of the input box.
pub const MAX_SIGN_INPUTS: usize = 12;

/// Why the constants could not be derived.
#[derive(Clone, Debug, PartialEq)]
pub enum ConstantsError {
    /// An entry of a matrix has an unbounded range over the domain (no `domain` box, or one too
    /// large): `matrix` is `"D_x f"`, `"G"` or `"D_u f"`, `row` the state, `column` the state,
    /// noise channel or input.
    Unbounded {
        /// Which matrix.
        matrix: &'static str,
        /// Its row (an equation / state index).
        row: usize,
        /// Its column.
        column: usize,
    },
    /// The metric is not an `n x n` symmetric positive definite matrix (or could not be
    /// certified as one).
    BadMetric {
        /// What is wrong with it.
        reason: String,
    },
    /// No bound could be certified for a constant (numerically hopeless data, e.g. entries
    /// near `f64::MAX`).
    NotCertified {
        /// `"c"`, `"sigma"` or `"rho"`.
        constant: &'static str,
    },
}

impl fmt::Display for ConstantsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ConstantsError::Unbounded {
                matrix,
                row,
                column,
            } => write!(
                f,
                "entry ({row}, {column}) of {matrix} is unbounded over the domain"
            ),
            ConstantsError::BadMetric { reason } => write!(f, "invalid metric: {reason}"),
            ConstantsError::NotCertified { constant } => {
                write!(f, "could not certify a bound for {constant}")
            }
        }
    }
}

impl std::error::Error for ConstantsError {}

/// The constants of Assumption 1 for a model and one metric `P` (`n x n` row-major, symmetric
/// positive definite), each certified with interval arithmetic (never below the exact value for
/// the model's float data).
///
/// Bounds hold over the model's domain, input box and `t` in `[0, longest horizon]`.
/// Errors: an unbounded entry of `D_x f`, `G` or `D_u f` (the first in that order, row-major),
/// or a metric that is not symmetric positive definite.
pub fn constants(
    model: &Model,
    d: &Derivatives,
    metric: &[f64],
) -> Result<Constants, ConstantsError> {
    let n = model.states.len();
    let p = check_metric(metric, n)?;
    let jac = decompose(model, &d.jac_x, "D_x f", time_range(model))?;
    let jac = jacobian_set(&jac, &p);
    let c = contraction_rate(&jac, &p, metric)?;
    let mut consts = noise_and_input(model, d, metric, &p)?.into_parts();
    consts.c = c;
    if let Provenance::Certified { c, .. } = &mut consts.provenance {
        *c = Some(jac.bound());
    }
    Ok(Constants::from_parts(consts))
}

/// The constants of Assumption 1 without the contraction rate, for analyses whose rate is
/// estimated at run time ([`Rate::Empirical`](reachc_core::model::Rate::Empirical)):
/// `sigma` and `rho` as in [`constants`], `c` infinite (not bounded here).
pub fn constants_without_rate(
    model: &Model,
    d: &Derivatives,
    metric: &[f64],
) -> Result<Constants, ConstantsError> {
    let p = check_metric(metric, model.states.len())?;
    noise_and_input(model, d, metric, &p)
}

/// `sigma` and `rho` (with `c` infinite) and how they were obtained.
fn noise_and_input(
    model: &Model,
    d: &Derivatives,
    metric: &[f64],
    p: &IMat,
) -> Result<Constants, ConstantsError> {
    let time = time_range(model);
    let diffusion = matrix_set(model, &model.diffusion, "G", time)?;
    let jac_u = matrix_set(model, &d.jac_u, "D_u f", time)?;
    let sigma = noise_level(&diffusion, p)?;
    let h: Vec<Interval> = model
        .input_box
        .iter()
        .map(|&b| match b {
            b if b.lo.is_finite() && b.hi.is_finite() => {
                (Interval::point(b.hi) - Interval::point(b.lo)) * 0.5
            }
            _ => Interval::ENTIRE,
        })
        .collect();
    let (rho, gain) = input_gain(&jac_u, p, &h)?;
    Ok(Constants::from_parts(ConstantsParts {
        metric: metric.to_vec(),
        // A caller that synthesised the metric says where.
        metric_region: MetricRegion::Given,
        c: f64::INFINITY,
        sigma,
        rho,
        provenance: Provenance::Certified {
            c: None,
            sigma: diffusion.bound(),
            rho: gain,
        },
        also: Vec::new(),
        alternatives: Vec::new(),
        region: Region {
            domain: model.domain.clone(),
            input_box: model.input_box.clone(),
            time: Bounds::new(time.lo(), time.hi()),
        },
    }))
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;

    use super::fixtures::{model_of, spec, PAPER_P};

    /// The pendulum's reference values (core/tests/data/README.md).
    fn pendulum_reference() -> serde_json::Value {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../core/tests/data/pendulum.json");
        let text = std::fs::read_to_string(&path).unwrap();
        serde_json::from_str(&text).unwrap()
    }

    #[test]
    fn pendulum_paper_metric() {
        let (model, d) = model_of(&spec("pendulum.sde"));
        let k = constants(&model, &d, &PAPER_P).unwrap();
        // Independent check (core/tests/data/pendulum.json): mu_P of the vertices -0.50747,
        // -1.31608; sigma = 0.1 sqrt(1.27) = 0.11269427...
        let reference = pendulum_reference();
        let checked = &reference["checked_independently"];
        let mu = checked["mu_P_of_vertices_with_paper_P"][0]
            .as_f64()
            .unwrap();
        // (The reference is for the decimal P, the model uses its nearest floats: 1e-14.)
        assert!(
            k.c() >= mu - 1e-14 && k.c() < mu + 1e-9,
            "c = {} vs {mu}",
            k.c()
        );
        let exact = checked["sigma_with_paper_P"].as_f64().unwrap();
        assert!(
            k.sigma() >= exact * (1.0 - 1e-14) && k.sigma() < exact * (1.0 + 1e-14),
            "{}",
            k.sigma()
        );
        assert_eq!(k.rho(), 0.0);
        assert!(
            k.provenance().to_string().contains("2 vertex matrices"),
            "{}",
            k.provenance()
        );
    }

    #[test]
    fn linear_is_exact() {
        let (model, d) = model_of(&spec("linear.sde"));
        let k = constants(&model, &d, &[1.0, 0.0, 0.0, 1.0]).unwrap();
        assert_eq!(k.c(), -0.4);
        let s = 2f64.sqrt();
        assert!(
            k.sigma() >= s && (k.sigma() - s) / s <= 1e-15,
            "{}",
            k.sigma()
        );
    }

    #[test]
    fn input_gain_identity() {
        let (model, d) = model_of(
            "model u1\nstate x in [0, 1]\ninput u in [-0.5, 0.5]\n\
             drift {\n x' = -x + 2 * u\n}\n",
        );
        let k = constants(&model, &d, &[1.0]).unwrap();
        assert_eq!(k.rho(), 1.0);
        assert_eq!(k.c(), -1.0);
        assert_eq!(k.sigma(), 0.0);
        // Two inputs: |B diag(h) s|_P over the corners, B = [[1, 1], [0, 3]], h = [1, 0.5].
        let (model, d) = model_of(
            "model u2\nstate x in [0, 1]\nstate y in [0, 1]\ninput u in [-1, 1]\n\
             input v in [0, 1]\ndrift {\n x' = -x + u + v\n y' = -y + 3 * v\n}\n",
        );
        let k = constants(&model, &d, &[1.0, 0.0, 0.0, 1.0]).unwrap();
        // Corners (1, 0.5) -> (1.5, 1.5), (1, -0.5) -> (0.5, -1.5): max norm sqrt(4.5).
        let exact = 4.5f64.sqrt();
        assert!(k.rho() >= exact && k.rho() < exact * (1.0 + 1e-15));
    }

    #[test]
    fn unbounded_names_entry() {
        let (model, d) = model_of("model cubic\nstate x in [0, 1]\ndrift {\n x' = -x^3\n}\n");
        assert_eq!(
            constants(&model, &d, &[1.0]),
            Err(ConstantsError::Unbounded {
                matrix: "D_x f",
                row: 0,
                column: 0
            })
        );
        let (model, d) = model_of(
            "model cubic\nstate x in [0, 1]\ndrift {\n x' = -x^3\n}\n\
             domain {\n x in [-2, 2]\n}\n",
        );
        let k = constants(&model, &d, &[1.0]).unwrap();
        assert_eq!(k.c(), 0.0);
    }

    #[test]
    fn bad_metric() {
        let (model, d) = model_of(&spec("linear.sde"));
        for m in [
            vec![1.0, 0.0, 0.0],
            vec![1.0, 0.5, 0.0, 1.0],
            vec![1.0, 2.0, 2.0, 1.0],
        ] {
            assert!(matches!(
                constants(&model, &d, &m),
                Err(ConstantsError::BadMetric { .. })
            ));
        }
    }
}
