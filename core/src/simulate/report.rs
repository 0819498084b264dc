//! The result of a Monte Carlo validation, as typed data (renderings: `reachc-runtime`'s
//! `report`).

use super::dt::DtUsed;
use super::inputs::InputMode;
use crate::model::{Guarantee, Method};
use crate::prs::UnsafeKind;

/// Everything a simulation measured, ready to be serialised. The same seed and options give the
/// same report (and JSON) whatever the number of threads.
#[derive(Clone, Debug, PartialEq)]
pub struct SimReport {
    /// `model NAME`.
    pub model: String,
    /// The analysis whose PRS is checked.
    pub analysis: String,
    /// The state names, in order (as [`SimStep::states`]).
    pub states: Vec<String>,
    /// Its method.
    pub method: Method,
    /// The PRS's probability level: the tube should hold the whole path (uniform), or each PRS
    /// `X_t` (pointwise), with probability `>= 1 - delta`.
    pub delta: f64,
    /// What the probability level of the analysis is about, and so what the verdict tests.
    pub guarantee: Guarantee,
    /// Number of sample paths.
    pub paths: u64,
    /// Random seed.
    pub seed: u64,
    /// The Euler-Maruyama steps (each report interval is split into equal steps): the
    /// smallest and largest, and how they compare with the rule `h L_k <= 0.05`.
    pub dt: DtUsed,
    /// Euler-Maruyama steps per path.
    pub steps_per_path: u64,
    /// How initial states were drawn.
    pub initial_states: InitialSampling,
    /// How inputs were drawn.
    pub inputs: InputsReport,
    /// How the noise was applied (additive or state-dependent).
    pub noise: NoiseKind,
    /// The quantile is the `quantile_rank`-th largest distance of the `paths` at each step (the
    /// `ceil((1 - delta) paths)`-th smallest).
    pub quantile_rank: u64,
    /// Confidence level of the Clopper-Pearson bounds.
    pub confidence: f64,
    /// One record per report time.
    pub steps: Vec<SimStep>,
    /// Violations over the whole horizon.
    pub horizon: HorizonReport,
    /// For a uniform result, the paths that left the tube (`None` for a pointwise result).
    pub tube: Option<TubeReport>,
    /// Per unsafe set, the paths that entered it.
    pub unsafe_sets: Vec<UnsafeHits>,
    /// With unsafe sets: the paths that entered none, against a certified bound if given.
    pub safety: Option<SafetyCheck>,
    /// Per goal set, its event's paths against the certified probability, where given.
    pub goals: Vec<GoalCheck>,
    /// Paths that left the spec's domain at some Euler step (`None` without a domain).
    pub left_domain: Option<u64>,
    /// Paths whose state became non-finite (counted outside from then on).
    pub diverged: u64,
    /// The coverage check.
    pub verdict: Coverage,
}

/// The inputs of the paths.
#[derive(Clone, Debug, PartialEq)]
pub struct InputsReport {
    /// How they were drawn.
    pub mode: InputMode,
    /// Hold time of the piecewise-constant inputs (`None` without inputs or for `centre`).
    pub hold: Option<f64>,
    /// The model has inputs.
    pub any: bool,
    /// The hold time the description uses (the option, or the analysis' step).
    pub hold_shown: f64,
}

/// Statistics at one report time.
#[derive(Clone, Debug, PartialEq)]
pub struct SimStep {
    /// Time.
    pub t: f64,
    /// The analysis' stochastic radius `r_t`.
    pub r_t: f64,
    /// The analysis' PRS radius (the coverage check compares the quantile with it).
    pub prs_radius: f64,
    /// Empirical `(1 - delta)` quantile of `|X_t - x*_t|_P`.
    pub quantile: f64,
    /// Largest `|X_t - x*_t|_P`.
    pub max: f64,
    /// Paths outside the PRS.
    pub outside: u64,
    /// `outside / paths`.
    pub fraction: f64,
    /// One-sided Clopper-Pearson upper bound of the violation probability at `confidence`.
    pub cp_upper: f64,
    /// For a uniform result, the paths that left the tube for the first time in the report
    /// interval ending here (`(t_{k-1}, t_k]`; at `t = 0`, at the start); `None` for a
    /// pointwise result.
    pub left_tube: Option<u64>,
    /// Per state: the paths' spread against the PRS's bounding box (tightness per coordinate).
    pub states: Vec<StateSpread>,
}

/// One state's spread over the paths at a report time, next to the PRS's bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateSpread {
    /// The half-width of the smallest interval centred on the nominal state `x*_t,i` that
    /// holds `1 - delta` of the paths' `X_t,i` (the `quantile_rank`-th largest deviation
    /// `|X_t,i - x*_t,i|`); `NaN` when fewer paths than the rank were simulated.
    pub quantile: f64,
    /// The largest deviation over the paths.
    pub max: f64,
    /// The half-width of the PRS's bounding box about `x*_t,i` (the larger of its two sides;
    /// `NaN` for a result without one).
    pub prs: f64,
}

impl StateSpread {
    /// How many times the empirical spread the PRS's half-width is (`prs / quantile`: 1 is
    /// as tight as the sample allows; `NaN` or `inf` where undefined).
    pub fn ratio(&self) -> f64 {
        self.prs / self.quantile
    }
}

/// Paths outside the PRS at one report time at least. A pointwise PRS bounds the probability
/// at each time, not uniformly in time, so this may exceed `delta` without contradicting it;
/// for a uniform result these paths left the tube (see [`TubeReport`]).
#[derive(Clone, Debug, PartialEq)]
pub struct HorizonReport {
    /// Paths outside at one report time or more.
    pub outside_any: u64,
    /// `outside_any / paths`.
    pub fraction: f64,
    /// One-sided Clopper-Pearson upper bound at `confidence`.
    pub cp_upper: f64,
}

/// The time-uniform check: the paths whose state left the tube at some time. Every
/// Euler-Maruyama state of report interval `(t_{k-1}, t_k]` is checked against the result's
/// span `k` ([`Prs::span_contains`](crate::prs::Prs::span_contains), the tube over that
/// interval; the initial state against span 0), and the state at each report time against that
/// time's PRS as well (the tube there); a non-finite state is outside.
#[derive(Clone, Debug, PartialEq)]
pub struct TubeReport {
    /// Paths that left the tube at least once.
    pub outside: u64,
    /// `outside / paths`.
    pub fraction: f64,
    /// One-sided Clopper-Pearson upper bound of the probability of leaving, at `confidence`.
    pub cp_upper: f64,
    /// One-sided Clopper-Pearson lower bound at `confidence`: the uniform coverage check
    /// fails when it exceeds `delta`.
    pub cp_lower: f64,
    /// States checked per path: the initial one and one per Euler-Maruyama step.
    pub checks_per_path: u64,
}

/// One unsafe set's hits.
#[derive(Clone, Debug, PartialEq)]
pub struct UnsafeHits {
    /// Its name.
    pub name: String,
    /// Its kind.
    pub kind: UnsafeKind,
    /// Paths that entered it at some Euler step.
    pub hits: u64,
    /// `hits / paths`.
    pub fraction: f64,
    /// Earliest entry over all paths.
    pub first_hit_t: Option<f64>,
}

/// The coverage check. For a uniform result it fails when the probability of leaving the
/// tube is, with confidence, above `delta` ([`TubeReport::cp_lower`], one event: no
/// correction); for a pointwise result, when some report time's violation probability is
/// (Bonferroni over the report times). The per-report-time statistics are reported for both.
#[derive(Clone, Debug, PartialEq)]
pub struct Coverage {
    /// The check passed: the uniform one for a uniform result, the per-report-time one for a
    /// pointwise result.
    pub passed: bool,
    /// Which check decides [`passed`](Self::passed) (the result's guarantee).
    pub decided_by: Guarantee,
    /// No report time fails the per-report-time check (the verdict of a pointwise result).
    pub pointwise_passed: bool,
    /// `1 - confidence`: the probability of a false failure when every PRS is valid.
    pub alpha: f64,
    /// `alpha / (report times)`: the level of each step's lower bound (Bonferroni).
    pub alpha_per_step: f64,
    /// Report times whose lower bound exceeds `delta`.
    pub failing_steps: usize,
    /// The step with the most paths outside (the earliest of equals).
    pub worst_step: usize,
    /// Its time.
    pub worst_t: f64,
    /// Its paths outside.
    pub worst_outside: u64,
    /// Its one-sided Clopper-Pearson lower bound at `1 - alpha_per_step`.
    pub worst_cp_lower: f64,
}

impl SimReport {
    /// Whether the coverage check passed, and the probability-of-safety check where there is
    /// one.
    pub fn passed(&self) -> bool {
        self.verdict.passed
            && self.safety.as_ref().is_none_or(|s| s.passed)
            && self.goals.iter().all(|g| g.passed)
    }
}

/// The paths that entered no unsafe set at any Euler-Maruyama step, an estimate of the
/// probability of safety on the horizon, against a certified lower bound. A path can cross a
/// set between two steps unseen, so the paths overestimate that probability a little: the
/// check can miss a bound that is too high by that much, never fail a valid one by it.
#[derive(Clone, Debug, PartialEq)]
pub struct SafetyCheck {
    /// Paths that entered no unsafe set.
    pub safe: u64,
    /// `safe / paths`.
    pub fraction: f64,
    /// One-sided Clopper-Pearson upper bound of the probability of safety at `confidence`.
    pub cp_upper: f64,
    /// The certified lower bound tested (`None`: none was given, nothing is tested).
    pub certified: Option<f64>,
    /// The bound is not above `cp_upper` (true without a bound): a valid bound fails with
    /// probability at most `1 - confidence`.
    pub passed: bool,
}

/// The paths whose goal event happened (method.md 8.13: in the goal at an Euler-Maruyama step
/// in the window with no unsafe set entered at a step before; with `stay`, in it at every step
/// from one no later than the window's end to the horizon, no unsafe set entered at any step),
/// an estimate of its probability, against a certified lower bound. Between steps a path can
/// cross an unsafe set or the goal's boundary unseen, in either direction, so the estimate
/// carries the Euler-Maruyama grid's error (small at the steps `dt` chooses).
#[derive(Clone, Debug, PartialEq)]
pub struct GoalCheck {
    /// The goal's name.
    pub name: String,
    /// Paths whose event happened.
    pub reached: u64,
    /// `reached / paths`.
    pub fraction: f64,
    /// One-sided Clopper-Pearson upper bound of the event's probability at `confidence`.
    pub cp_upper: f64,
    /// The certified lower bound tested (`None`: nothing is tested).
    pub certified: Option<f64>,
    /// The bound is not above `cp_upper` (true without a bound).
    pub passed: bool,
}

/// How the initial states of the paths were drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InitialSampling {
    /// The initial set is a single point.
    Point,
    /// Uniform in the initial box.
    Box,
    /// Uniform in the initial ball(s).
    Balls,
    /// Uniform in the initial box and ball(s).
    BoxAndBalls,
}

/// How the noise `G dW` was applied.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoiseKind {
    /// Additive: a constant diagonal `G`, evaluated once.
    AdditiveDiagonal,
    /// Additive: a constant `G`, evaluated once.
    Additive {
        /// Its non-zero entries.
        entries: usize,
    },
    /// State-dependent: `G` evaluated at every step.
    StateDependent {
        /// Its entries that are not identically zero.
        entries: usize,
    },
}
