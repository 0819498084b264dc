//! How a result was computed: its role in an intersection, the rates, constants, radius rule
//! and `r1` bound it used, its coordinate transform, and the hints about it.

use crate::engine::RunError;
use crate::model::{Bounds, MetricRegion, Provenance, RadiusRule, Rate, TransformSource};

/// What a result is within an intersection ([`Prs::also`](super::Prs::also)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The analysis' own result (its first metric's, with several).
    Own,
    /// A further metric's result, of the same method, at `delta / K` (method.md 8.6).
    Metric,
    /// The interval method's box of a contraction run, at the same delta (method.md 8.7).
    Box,
    /// The first-order sets of the same run, at the same delta (method.md 8.8).
    FirstOrder,
    /// The linearised Gaussian sets of the same run (method.md 8.10): first-order zonotopes
    /// holding the stochastic part too, at their own share of delta.
    Linearised,
}

impl Role {
    /// The role's name in outputs: `own`, `metric`, `box`, `first_order`, `linearised`.
    pub fn name(self) -> &'static str {
        match self {
            Role::Own => "own",
            Role::Metric => "metric",
            Role::Box => "box",
            Role::FirstOrder => "first_order",
            Role::Linearised => "linearised",
        }
    }
}

/// Where the contraction rate `c_t` came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RateUsed {
    /// Local, global, or estimated from sample paths (no guarantee).
    pub rate: Rate,
    /// The largest rate used on any step (the certified `c` for a global rate).
    pub max_c: f64,
    /// The smallest rate used on any step.
    pub min_c: f64,
    /// Local rates: the time from which no region closed and the domain's global constants
    /// took over (the result is conditional on the domain then); `None`: local throughout.
    pub global_from: Option<f64>,
}

/// One internal step `[t0, t1]` of a run with local rates: the box `D_k` that holds the
/// deterministic set and the time-uniform tube over the step, and the rates certified on it.
#[derive(Clone, Debug, PartialEq)]
pub struct RateRegion {
    /// Start of the step.
    pub t0: f64,
    /// End of the step.
    pub t1: f64,
    /// Lower corner of `D_k`.
    pub lo: Vec<f64>,
    /// Upper corner of `D_k`.
    pub hi: Vec<f64>,
    /// `c_k >= mu_P(D_x f)` over `D_k`, the input box and the step's times.
    pub c: f64,
    /// `sigma_k`, the noise level over the same.
    pub sigma: f64,
    /// `rho_k`, the input gain over the same.
    pub rho: f64,
}

/// The constants of Assumption 1, as used.
#[derive(Clone, Debug, PartialEq)]
pub struct ConstantsUsed {
    /// Contraction rate.
    pub c: f64,
    /// Noise level.
    pub sigma: f64,
    /// Input gain (0 without inputs for the contraction method).
    pub rho: f64,
    /// How the compiler bounded them.
    pub provenance: Provenance,
    /// The metric `P`, `n x n` row-major.
    pub metric: Vec<f64>,
    /// Where `P` comes from.
    pub metric_region: MetricRegion,
    /// Upper bounds of `sqrt((P^-1)_ii)`: the P-ball of radius `r` around `c` lies in the box
    /// `|x_i - c_i| <= r spread_i`.
    pub spread: Vec<f64>,
}

/// The stochastic radius rule used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RuleUsed {
    /// The rule.
    pub rule: RadiusRule,
    /// `eps` of Theorem 1 (the given one, or the minimiser), for the paper rules.
    pub eps: Option<f64>,
    /// An affine system under the amgf rule: the radii come from the exact Gaussian
    /// covariance instead (method.md section 8.1).
    pub gaussian: Option<GaussianUsed>,
}

/// The exact Gaussian route of an affine system.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussianUsed {
    /// The upper bound of `chi2_n^-1(1 - delta)` of the pointwise radii
    /// `sqrt(q lambda_max(R Sigma_t R'))`.
    pub quantile: f64,
    /// Uniform guarantee: which time-uniform bound was tighter and is used.
    pub uniform: Option<UniformBound>,
}

/// The time-uniform bound of a result: both are valid, the tighter (smaller sum of radii over
/// the report times, fixed before the fact) is used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UniformBound {
    /// The AMGF tube (method.md section 8.2).
    AmgfTube,
    /// The method-of-mixtures bound for Gaussian martingales (method.md section 8.1).
    Mixture,
    /// A discrete-time model's steps, each at `delta / K` (method.md section 8.16).
    UnionOverSteps,
}

/// How `r1` was bounded (method.md section 6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct R1Bound {
    /// How the box part was bounded: the initial boxes and points, and the balls' bounding
    /// boxes too when `balls` is [`BallBound::BoundingBoxes`].
    pub boxes: R1Method,
    /// How the initial balls entered.
    pub balls: BallBound,
    /// `r1` is reported only: the interval method propagates the initial set's bounding box.
    pub reported_only: bool,
}

/// The bound over the box part of the initial set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum R1Method {
    /// The maximum over the box's vertices (exact up to rounding).
    Vertices {
        /// Non-degenerate coordinates of the box part.
        active: usize,
    },
    /// `sum_ij |P_ij| h_i h_j` (more than [`crate::engine::MAX_VERTEX_COORDS`] coordinates).
    AbsoluteSum,
}

/// How the initial balls entered `r1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BallBound {
    /// No initial ball of positive radius.
    NoBalls,
    /// Jointly with the box part's vertices: per vertex, the S-lemma bound minimised over its
    /// multiplier. Exact (up to rounding) for one ball; for several, the S-procedure with one
    /// multiplier per ball, an upper bound that need not be exact.
    Joint {
        /// Balls of positive radius.
        balls: usize,
    },
    /// Separately from the box part, `|b + y|_P <= |b|_P + |y|_P` (more than
    /// [`crate::engine::MAX_VERTEX_COORDS`] box coordinates, or a box part and more than
    /// [`crate::engine::MAX_BALL_STATES`] ball states); the balls' part as in `Joint`.
    Separate {
        /// Balls of positive radius.
        balls: usize,
    },
    /// Replaced by their bounding boxes: the balls' own bound was not smaller (or could not be
    /// certified).
    BoundingBoxes,
}

/// A coordinate transform `y = T x`, as used.
#[derive(Clone, Debug, PartialEq)]
pub struct TransformUsed {
    /// `T`, `n x n` row-major.
    pub matrix: Vec<f64>,
    /// `T^-1` computed in floating point, `n x n` row-major (`x = T^-1 y`).
    pub inverse: Vec<f64>,
    /// A rigorous bound of `|(T^-1)_ij - inverse_ij|` over all entries (0 when exact).
    pub inverse_error: f64,
    /// Written in the spec or chosen by the compiler.
    pub source: TransformSource,
}

/// Advice on a result, read off its own numbers (advisory: plain floating point, no guarantee
/// rests on it).
#[derive(Clone, Debug, PartialEq)]
pub enum Hint {
    /// The box wraps: at time `t` the PRS's bounding box in `state` is more than
    /// [`WRAPPING_FACTOR`](crate::engine::WRAPPING_FACTOR) times wider than that of the P-ball
    /// the result's own constants give from the initial set (`R_t = e^(ct) r1 + rho r2
    /// (e^(ct) - 1) / c` plus the same `r_t`, the contraction method's set), the largest such
    /// ratio over the report times and states.
    Wrapping {
        /// The report time.
        t: f64,
        /// The state (index into [`Prs::states`](super::Prs::states)).
        state: usize,
        /// Half-width of the PRS's bounding box in `state` (the box's hull plus `r_t`).
        half_width: f64,
        /// Half-width of the P-ball's bounding box in `state`.
        ball_half_width: f64,
        /// The contraction rate `c` of the result's constants.
        c: f64,
    },
    /// The deterministic box leaves the spec's domain (first report time and state).
    LeavesDomain {
        /// The report time.
        t: f64,
        /// The state (index into [`Prs::states`](super::Prs::states)).
        state: usize,
        /// The box's hull in `state`.
        range: Bounds,
        /// The domain in `state`.
        domain: Bounds,
    },
    /// From report time `t` on, the first-order sets' (method.md 8.8) second-order remainder
    /// exceeds their linear part: the initial set (or the input box) is too wide for one
    /// linearisation over the horizon; smaller pieces shrink the remainder quadratically.
    FirstOrderLoose {
        /// The report time.
        t: f64,
        /// The remainder's P-radius.
        remainder: f64,
        /// The P-radius of the linear part (the zonotope around the nominal).
        linear: f64,
    },
    /// The first-order sets (method.md 8.8) were wanted but could not be bounded on some
    /// internal step (the a-priori remainder did not hold its own bound).
    FirstOrderUnbounded,
    /// The analysis' own sets (its ball or box) could not be bounded: the PRS is the linearised
    /// Gaussian set alone at the full delta (method.md 8.12).
    LinearisedAlone {
        /// What stopped the analysis' own run.
        failed: RunError,
    },
}
