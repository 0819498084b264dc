//! Which parts of a result are proved, and which are not.

use crate::model::{Inclusion, Integrator, Method, MetricRegion, Provenance};

/// Which parts of the result are proved.
#[derive(Clone, Debug, PartialEq)]
pub struct Validation {
    /// Proved parts (outward-rounded, or certified by the compiler).
    pub rigorous: Vec<Proved>,
    /// Parts that are not validated.
    pub not_validated: Vec<Unproved>,
    /// The result holds only while the state stays in the spec's domain.
    pub conditional_on_domain: bool,
}

/// A proved part of a result.
#[derive(Clone, Debug, PartialEq)]
pub enum Proved {
    /// The constants certified by the compiler: which of `c`, `sigma`, `rho` the engine used.
    Constants {
        /// `c` (certified rate).
        c: bool,
        /// `rho` (contraction method).
        rho: bool,
        /// How the compiler bounded them.
        provenance: Provenance,
    },
    /// The inclusion function of the drift on each face (interval method).
    Inclusion(Inclusion),
    /// `kappa`, rounded up.
    Kappa,
    /// `Psi_t`, exact per-step integration in interval arithmetic.
    Psi,
    /// `r1`, `R_t`, `r_t` and the PRS radius (contraction method).
    Radii,
    /// `r_t` (interval method).
    StochasticRadius,
    /// The safety margins given the deterministic set (`P^-1` enclosed by interval Cholesky).
    Margins {
        /// Given the nominal (contraction) or the box (interval).
        given: Method,
    },
    /// The transformed system, the initial box in `y = T x` and the map back to `x`. The
    /// transformed drift `T f(T^-1 y)` is built by the compiler with the exact `T^-1` and
    /// coefficients folded without rounding (enclosures where a fold is inexact), so its
    /// interval forms enclose it as the model's enclose `f`.
    TransformMaps {
        /// The bound of `T^-1`'s entries around the floating-point inverse.
        inverse_error: f64,
    },
    /// The nominal trajectory enclosed on validated steps: a defect bound of a piecewise
    /// cubic, propagated with the contraction rate into `R_t` (contraction method).
    ValidatedNominal {
        /// The number of internal steps.
        steps: usize,
        /// How many of them end on a ROS2 node instead of an RK4 one (a stiff model, method.md
        /// 8.4).
        ros2: usize,
    },
    /// The embedding system enclosed on validated steps (the comparison principle on each
    /// step's hull; interval method).
    ValidatedEmbedding {
        /// The number of internal steps.
        steps: usize,
    },
    /// Local rates: `c`, `sigma`, `rho` certified per internal step on a region holding the
    /// tube over that step (interval Jacobian, verified eigenvalue bounds); no domain needed.
    LocalRates {
        /// The number of regions (internal steps).
        regions: usize,
        /// Where the metric was synthesised.
        metric: MetricRegion,
    },
    /// The time-uniform tube: Ville's inequality on `epochs` epochs at `delta / epochs` each.
    UniformTube {
        /// The number of epochs.
        epochs: usize,
    },
    /// A discrete-time model's map (method.md 8.16): each step's image enclosed in interval
    /// arithmetic, and the map's factor `|R J R^-1|_2` and noise level bounded on each step's
    /// region (verified eigenvalue bounds).
    MapFactors {
        /// The number of steps.
        steps: usize,
        /// Where the metric was chosen.
        metric: MetricRegion,
        /// The regions are the model's domain (a pointwise guarantee), not the tube's boxes.
        over_domain: bool,
    },
    /// The union bound over a discrete-time model's `steps` steps, at `delta / steps` each.
    UnionOverSteps {
        /// The number of steps.
        steps: usize,
    },
    /// The stochastic part of an affine system from its exact Gaussian covariance (enclosed in
    /// interval arithmetic), with a rigorous chi-square quantile.
    ExactGaussian,
    /// The time-uniform Gaussian mixture bound on `epochs` epochs at `delta / epochs` each.
    GaussianMixture {
        /// The number of epochs.
        epochs: usize,
    },
    /// The linearised Gaussian sets (method.md 8.10): the linearisation's covariance along the
    /// nominal (enclosed), the reflection principle per coordinate on `epochs` epochs (one per
    /// internal step), and the linearisation's error bounded path by path on that event.
    LinearisedGaussian {
        /// The number of epochs.
        epochs: usize,
    },
}

/// A part of a result that is not proved.
#[derive(Clone, Debug, PartialEq)]
pub enum Unproved {
    /// The contraction rate is an estimate from sample paths.
    EmpiricalRate {
        /// Number of sample paths.
        paths: u64,
    },
    /// The nominal trajectory is integrated numerically and taken as exact.
    Nominal {
        /// The integrator.
        integrator: Integrator,
        /// Its step.
        step: f64,
    },
    /// The embedding system is integrated numerically (no remainder bound).
    Embedding {
        /// The integrator.
        integrator: Integrator,
        /// Its step.
        step: f64,
    },
}
