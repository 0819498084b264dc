//! The result file of `reachc run` (`DIR/<analysis>.json`), field for field in the order
//! docs/results.md documents.

use super::names::{
    GoalStatus, Guarantee, Inclusion, Integrator, Method, MetricRef, RateSource, Role, Rule, Shape,
    TransformSource, UniformBound, UnsafeKind,
};
use super::nullable;
use super::probability::{GoalMissJson, GoalProbabilityJson, ProbabilityJson};
use super::shape::ShapeJson;
use serde::{Deserialize, Serialize};

/// A result: the analysis, its constants, one record per report time, the verdicts, and the
/// members of an intersection or the pieces of a split.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ResultJson {
    /// `model NAME`.
    pub model: String,
    /// The analysis' name (also the output files' names).
    pub analysis: String,
    /// How the deterministic sets were computed.
    pub method: Method,
    /// The interval method's inclusion function.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inclusion: Option<Inclusion>,
    /// Probability level.
    pub delta: f64,
    /// Time horizon.
    pub horizon: f64,
    /// Report step.
    pub step: f64,
    /// How the deterministic part is integrated.
    pub integrator: Integrator,
    /// The sampling period of a discrete-time model (absent for continuous time).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period: Option<f64>,
    /// What `delta` is about: all times at once, or each time separately.
    #[serde(default)]
    pub guarantee: Guarantee,
    /// The engine's internal steps.
    pub internal_steps: usize,
    /// State names.
    pub states: Vec<String>,
    /// Indices of the output states.
    pub outputs: Vec<usize>,
    /// Where the rates come from (always written; older files have none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate: Option<RateJson>,
    /// The constants and the metric `P`.
    pub constants: ConstantsJson,
    /// The stochastic radius rule.
    pub radius_rule: RuleJson,
    /// `kappa(n, delta)`.
    #[serde(deserialize_with = "nullable::number")]
    pub kappa: f64,
    /// The bound of `|x0 - x*_0|_P` over the initial set.
    #[serde(deserialize_with = "nullable::number")]
    pub r1: f64,
    /// The input's radius in its norm.
    #[serde(deserialize_with = "nullable::number")]
    pub r2: f64,
    /// How `r1` was bounded, in words.
    pub r1_how: String,
    /// The coordinate transform of an interval analysis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transform: Option<TransformJson>,
    /// Centre of the initial set.
    pub initial_center: Vec<f64>,
    /// Centre of the input box.
    #[serde(deserialize_with = "nullable::numbers")]
    pub input_center: Vec<f64>,
    /// One record per report time.
    pub steps: Vec<StepJson>,
    /// Per unsafe set, its verdict.
    #[serde(default)]
    pub unsafe_sets: Vec<UnsafeJson>,
    /// Per goal set (absent without goals; method.md 8.13).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub goals: Vec<GoalJson>,
    /// The verdict.
    pub verdict: VerdictJson,
    /// The probability of safety (`reachc run --probability` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub safety_probability: Option<ProbabilityJson>,
    /// What is proved and what is not.
    pub validated: ValidationJson,
    /// Hints on what limits the result.
    pub hints: Vec<HintJson>,
    /// The members of the intersection (the PRS is the intersection:
    /// `steps[..].prs_hull_lo/hi` and the verdicts are the intersection's).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub also: Vec<ResultJson>,
    /// A member's kind; [`Role::Own`] (no `role` written) for the result itself.
    #[serde(default, skip_serializing_if = "Role::is_own")]
    pub role: Role,
    /// A member written as its PRS's bounding boxes (`MEMBERS_BUDGET`); absent otherwise.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub boxed: bool,
    /// The split (absent without one; method.md 8.11).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub split: Option<SplitJson>,
    /// With a split, each piece in brief (the PRS is their union: `steps[..].prs_hull_lo/hi`
    /// are the union's bounding boxes, the margins and verdicts the union's).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pieces: Vec<PieceJson>,
}

impl ResultJson {
    /// The report times.
    pub fn times(&self) -> Vec<f64> {
        self.steps.iter().map(|s| s.t).collect()
    }
}

/// One piece of a split (method.md 8.11), in brief: its initial box, its verdict, and per report
/// time its PRS's bounding box and margins. (Written in full, with their members' zonotopes,
/// the 64 pieces of `specs/vanderpol.sde` made files of 100 to 160 MB.)
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PieceJson {
    /// Its initial box, `[lo, hi]` per state.
    #[serde(deserialize_with = "nullable::ranges")]
    pub initial_box: Vec<[f64; 2]>,
    /// Its verdict.
    pub verdict: VerdictJson,
    /// One record per report time.
    pub steps: Vec<PieceStepJson>,
}

/// A piece's PRS at one report time.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PieceStepJson {
    /// Time.
    pub t: f64,
    /// Lower corner of the PRS's bounding box.
    #[serde(deserialize_with = "nullable::numbers")]
    pub prs_hull_lo: Vec<f64>,
    /// Upper corner.
    #[serde(deserialize_with = "nullable::numbers")]
    pub prs_hull_hi: Vec<f64>,
    /// Per unsafe set, its margin.
    #[serde(deserialize_with = "nullable::numbers")]
    pub margins: Vec<f64>,
}

/// How the initial box was split.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(untagged)]
pub enum SplitJson {
    /// `split = [..]`: the counts per state.
    Counts(Vec<usize>),
    /// `split = auto(pieces = N, seconds = S)`: `{"auto": {"pieces": N, "seconds": S}}`.
    Auto {
        /// The budget.
        auto: AutoJson,
    },
}

/// The budget of `split = auto`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AutoJson {
    /// Most pieces.
    pub pieces: usize,
    /// Most seconds.
    pub seconds: Option<u64>,
}

/// Where the rates come from.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RateJson {
    /// Local, global or empirical.
    pub kind: RateSource,
    /// Where the rate came from, in words.
    pub note: String,
    /// The sample paths of an empirical rate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paths: Option<u64>,
    /// The smallest rate used.
    #[serde(deserialize_with = "nullable::number")]
    pub min_c: f64,
    /// The largest rate used.
    #[serde(deserialize_with = "nullable::number")]
    pub max_c: f64,
    /// Local rates: when the domain's global constants took over.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub global_from: Option<f64>,
}

/// The constants.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ConstantsJson {
    /// The contraction rate.
    #[serde(deserialize_with = "nullable::number")]
    pub c: f64,
    /// The noise level.
    #[serde(deserialize_with = "nullable::number")]
    pub sigma: f64,
    /// The input gain.
    #[serde(deserialize_with = "nullable::number")]
    pub rho: f64,
    /// How they were certified, in words.
    pub how: String,
    /// `P`, by rows.
    pub metric: Vec<Vec<f64>>,
    /// The region they were certified over, in words.
    pub metric_from: String,
}

/// The stochastic radius rule.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RuleJson {
    /// Its name.
    pub rule: Rule,
    /// Theorem 1's eps, where given.
    pub eps: Option<f64>,
    /// An exact Gaussian's quantile and time-uniform bound.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gaussian: Option<GaussianJson>,
}

/// The radius of an exact Gaussian.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GaussianJson {
    /// The chi-square quantile.
    #[serde(deserialize_with = "nullable::number")]
    pub chi2_quantile: f64,
    /// The time-uniform bound used.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uniform: Option<UniformBound>,
}

/// A coordinate transform `y = T x`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TransformJson {
    /// `T`, by rows.
    pub matrix: Vec<Vec<f64>>,
    /// `T^-1` (floating point, within `inverse_error` of the exact inverse).
    pub inverse: Vec<Vec<f64>>,
    /// The largest error of `inverse`'s entries.
    #[serde(deserialize_with = "nullable::number")]
    pub inverse_error: f64,
    /// Given or chosen by the compiler.
    pub source: TransformSource,
    /// An automatic transform's log norms.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log_norm_inf: Option<LogNormJson>,
}

/// The infinity log norms of the Jacobian, in the chosen coordinates and in the states.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LogNormJson {
    /// In `y = T x`.
    #[serde(deserialize_with = "nullable::number")]
    pub chosen: f64,
    /// In `x`.
    #[serde(deserialize_with = "nullable::number")]
    pub identity: f64,
}

/// A hint on what limits a result.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum HintJson {
    /// A state's set is wider than the ball alone would be.
    Wrapping {
        /// The report time.
        t: f64,
        /// The state.
        state: String,
        /// The set's half-width in it.
        #[serde(deserialize_with = "nullable::number")]
        half_width: f64,
        /// The ball's alone.
        #[serde(deserialize_with = "nullable::number")]
        ball_half_width: f64,
        /// The rate.
        #[serde(deserialize_with = "nullable::number")]
        c: f64,
    },
    /// The deterministic box leaves the spec's domain.
    LeavesDomain {
        /// The first report time.
        t: f64,
        /// The state.
        state: String,
        /// The box's range in it.
        #[serde(deserialize_with = "nullable::range")]
        range: [f64; 2],
        /// The domain in it.
        #[serde(deserialize_with = "nullable::range")]
        domain: [f64; 2],
    },
    /// The first-order remainder dominates.
    FirstOrderLoose {
        /// The report time.
        t: f64,
        /// The remainder.
        #[serde(deserialize_with = "nullable::number")]
        remainder: f64,
        /// The linear part.
        #[serde(deserialize_with = "nullable::number")]
        linear: f64,
    },
    /// The first-order remainder is not bounded.
    FirstOrderUnbounded,
    /// The linearised Gaussian set is the PRS alone.
    LinearisedAlone {
        /// Why, in words.
        why: String,
    },
}

/// The sets at one report time. The engine checks every number of the deterministic set, the
/// radii and the span finite (a `null` there is a damaged file); the others may be `null`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StepJson {
    /// Time.
    pub t: f64,
    /// Nominal state (interval method: the centre of the set).
    pub nominal: Vec<f64>,
    /// The deterministic set.
    pub det_set: DetSetJson,
    /// Stochastic radius.
    pub r_t: f64,
    /// The pointwise stochastic radius.
    pub r_pointwise: f64,
    /// `Psi_t`.
    #[serde(deserialize_with = "nullable::number")]
    pub psi: f64,
    /// The largest contraction rate over the report interval ending here (NaN where a file has
    /// none).
    #[serde(default = "nullable::nan", deserialize_with = "nullable::number")]
    pub c: f64,
    /// The largest noise level over the same.
    #[serde(default = "nullable::nan", deserialize_with = "nullable::number")]
    pub sigma: f64,
    /// PRS radius (interval method: a P-ball containing the PRS).
    pub prs_radius: f64,
    /// Lower corner of the PRS's bounding box.
    #[serde(deserialize_with = "nullable::numbers")]
    pub prs_hull_lo: Vec<f64>,
    /// Upper corner.
    #[serde(deserialize_with = "nullable::numbers")]
    pub prs_hull_hi: Vec<f64>,
    /// The PRS over the report interval ending here.
    pub span: SpanJson,
    /// Per unsafe set, its margin over the report interval ending here.
    #[serde(deserialize_with = "nullable::numbers")]
    pub margins: Vec<f64>,
}

/// The PRS over a report interval: a box, and a P-radius about the nominal.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SpanJson {
    /// Lower corner.
    pub lo: Vec<f64>,
    /// Upper corner.
    pub hi: Vec<f64>,
    /// The P-radius.
    pub radius: f64,
}

/// A deterministic set: `p_ball`, `box`, `parallelotope` or `zonotope` (see docs/results.md).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DetSetJson {
    /// Its shape.
    pub shape: Shape,
    /// Centre of the P-ball or of the zonotope (of the box, of the parallelotope's hull).
    pub center: Vec<f64>,
    /// Radius `R_t` of the P-ball (a box: an upper bound of its P-radius about the centre).
    pub radius: f64,
    /// The metric of `radius`.
    #[serde(default)]
    pub metric: MetricRef,
    /// Lower corner (`box`: in `x`; `parallelotope`: in `y = T x`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lo: Option<Vec<f64>>,
    /// Upper corner.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hi: Option<Vec<f64>>,
    /// The interval hull's lower corner (not for a box: its own hull).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hull_lo: Option<Vec<f64>>,
    /// Its upper corner.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hull_hi: Option<Vec<f64>>,
    /// A zonotope's generators, one array of `n` values each.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub generators: Option<Vec<Vec<f64>>>,
    /// A zonotope's remainder (the P-radius of the ball added to it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub remainder: Option<f64>,
}

/// An unsafe set's verdict.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct UnsafeJson {
    /// Its name.
    pub name: String,
    /// Its kind.
    pub kind: UnsafeKind,
    /// Shown safe.
    pub safe: bool,
    /// The smallest margin.
    #[serde(deserialize_with = "nullable::number")]
    pub min_margin: f64,
    /// Where it is.
    #[serde(deserialize_with = "nullable::number")]
    pub min_margin_t: f64,
    /// The first report time not shown safe.
    pub first_not_safe_t: Option<f64>,
    /// What the margins measure, in words.
    pub margin_unit: String,
    /// A moving set (method.md 8.15): per report time, the fixed set that held it over the
    /// report interval ending there; absent for a fixed set.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub swept: Vec<ShapeJson>,
}

/// One goal's verdict: `reached` with its time and margin, or `why` not.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GoalJson {
    /// Its name.
    pub name: String,
    /// The times at which entering counts.
    #[serde(deserialize_with = "nullable::range")]
    pub window: [f64; 2],
    /// Reach and stay.
    pub stay: bool,
    /// What is shown.
    pub status: GoalStatus,
    /// `reached`: the first report time.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t: Option<f64>,
    /// `reached`: the smallest containment margin involved.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "nullable::some_number"
    )]
    pub margin: Option<f64>,
    /// `not_shown`: why.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub why: Option<GoalMissJson>,
    /// The certified probability of reaching it (`reachc run --probability`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probability: Option<GoalProbabilityJson>,
    /// Per report time, how far the PRS lies inside it.
    #[serde(deserialize_with = "nullable::numbers")]
    pub margins: Vec<f64>,
    /// A moving goal (method.md 8.15): per report time, its parts as they are then; absent for
    /// a fixed goal.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub swept: Vec<Vec<ShapeJson>>,
}

/// The verdict of a result.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum VerdictJson {
    /// Every unsafe set is shown avoided.
    Safe,
    /// There are none.
    NoUnsafeSets,
    /// Not shown safe: the first report time, its index and the set.
    NotShownSafe {
        /// The report time.
        t: f64,
        /// Its index.
        step: usize,
        /// The unsafe set.
        set: String,
    },
}

/// What is proved and what is not, in words.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ValidationJson {
    /// The proved parts.
    pub rigorous: Vec<String>,
    /// The parts taken on trust.
    pub not_validated: Vec<String>,
    /// The result holds while the state stays in the domain.
    pub conditional_on_domain: bool,
}
