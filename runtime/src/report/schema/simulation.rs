//! The Monte Carlo report of `reachc simulate` (`DIR/<analysis>.sim.json`), field for field.
//! Its statistics may be `null` (not finite: a ratio of zeros, a quantile of diverged paths,
//! no finite bound of the drift's Jacobian).

use super::names::{DtSource, DtStatus, Guarantee, InputMode, Method, Status, UnsafeKind};
use super::nullable;
use serde::{Deserialize, Serialize};

/// A Monte Carlo check of a result.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SimJson {
    /// `model NAME`.
    pub model: String,
    /// The analysis checked.
    pub analysis: String,
    /// The state names (absent from reports of older versions).
    #[serde(default)]
    pub states: Vec<String>,
    /// The analysis' method.
    pub method: Method,
    /// The PRS's probability level (the quantile's level is `1 - delta`).
    pub delta: f64,
    /// The result's guarantee.
    pub guarantee: Guarantee,
    /// Number of paths.
    pub paths: u64,
    /// Their seed.
    pub seed: u64,
    /// The largest Euler-Maruyama step.
    pub dt: f64,
    /// The smallest.
    pub dt_min: f64,
    /// How the steps compare with the rules.
    pub dt_rule: DtRuleJson,
    /// Euler-Maruyama steps per path.
    pub steps_per_path: u64,
    /// How the initial states were drawn, in words.
    pub initial_states: String,
    /// How the inputs were drawn.
    pub inputs: InputsJson,
    /// How the noise was applied, in words.
    pub noise: String,
    /// What the distances and the outside counts measure, in words.
    pub compared: String,
    /// The rank of the quantile among the paths.
    pub quantile_rank: u64,
    /// The confidence of the Clopper-Pearson bounds.
    pub confidence: f64,
    /// Per report time.
    pub steps: Vec<SimStepJson>,
    /// Over the horizon.
    pub horizon: HorizonJson,
    /// The tube, all times at once (uniform results).
    pub outside_tube: Option<TubeJson>,
    /// Per unsafe set.
    pub unsafe_sets: Vec<SimUnsafeJson>,
    /// The paths that entered no unsafe set.
    pub safety: Option<SafetyJson>,
    /// Per goal set (absent without goals).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub goals: Vec<SimGoalJson>,
    /// The paths that left the domain (`null`: no domain).
    pub left_domain: Option<u64>,
    /// The paths whose state was not finite.
    pub diverged: u64,
    /// The coverage verdict.
    pub verdict: CoverageJson,
}

/// How the Euler-Maruyama steps compare with the rules `h L_k <= 0.05` and
/// `(h_k / 2) a_k tau_k <= 0.05 w_k`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DtRuleJson {
    /// Chosen by the rule or `--dt`.
    pub source: DtSource,
    /// Met, capped, or coarser.
    pub status: DtStatus,
    /// The rule's bound of `h L`.
    pub bound: f64,
    /// The largest `h L`.
    #[serde(deserialize_with = "nullable::number")]
    pub hl_max: f64,
    /// The accuracy rule's bound.
    pub accuracy: f64,
    /// The largest bias, in parts of the half-width.
    #[serde(deserialize_with = "nullable::number")]
    pub bias_max: f64,
    /// The smallest step the rules ask for.
    #[serde(deserialize_with = "nullable::number")]
    pub rule_min: f64,
    /// The report intervals where the steps are coarser than the rules ask.
    pub coarse_intervals: u64,
    /// The rule's cap of steps per report interval.
    pub max_steps: u32,
    /// A warning where they are.
    pub warning: Option<String>,
}

/// How the inputs were drawn.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct InputsJson {
    /// The mode.
    pub mode: InputMode,
    /// The hold time.
    pub hold: Option<f64>,
    /// In words.
    pub description: String,
}

/// One report time of a Monte Carlo report.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SimStepJson {
    /// Time.
    pub t: f64,
    /// The result's stochastic radius.
    pub r_t: f64,
    /// The result's PRS radius.
    pub prs_radius: f64,
    /// Empirical `(1 - delta)` quantile of `|X_t - x*_t|_P`.
    #[serde(deserialize_with = "nullable::number")]
    pub quantile: f64,
    /// The largest distance.
    #[serde(deserialize_with = "nullable::number")]
    pub max: f64,
    /// The paths outside the PRS.
    pub outside: u64,
    /// Their fraction.
    #[serde(deserialize_with = "nullable::number")]
    pub fraction: f64,
    /// Its Clopper-Pearson upper bound.
    #[serde(deserialize_with = "nullable::number")]
    pub cp_upper: f64,
    /// Uniform results only: the paths first leaving the tube in the interval ending here.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub left_tube: Option<u64>,
    /// Per state, in the order of `states` (absent from reports of older versions).
    #[serde(default)]
    pub states: Vec<SimStateJson>,
}

/// One state's spread against the PRS's bounding box at a report time.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SimStateJson {
    /// The half-width about `x*_t,i` holding `1 - delta` of the paths.
    #[serde(deserialize_with = "nullable::number")]
    pub quantile: f64,
    /// The largest.
    #[serde(deserialize_with = "nullable::number")]
    pub max: f64,
    /// The PRS's bounding-box half-width about `x*_t,i`.
    #[serde(deserialize_with = "nullable::number")]
    pub prs: f64,
    /// `prs / quantile`.
    #[serde(deserialize_with = "nullable::number")]
    pub ratio: f64,
}

/// The paths that left the tube, all times at once.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TubeJson {
    /// How many.
    pub count: u64,
    /// Their fraction.
    #[serde(deserialize_with = "nullable::number")]
    pub fraction: f64,
    /// Its Clopper-Pearson upper bound.
    #[serde(deserialize_with = "nullable::number")]
    pub cp_upper: f64,
    /// Its Clopper-Pearson lower bound.
    #[serde(deserialize_with = "nullable::number")]
    pub cp_lower: f64,
    /// The states checked per path.
    pub checks_per_path: u64,
    /// What was checked, in words.
    pub checked: String,
}

/// The paths outside the PRS at some report time.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct HorizonJson {
    /// How many.
    pub outside_any: u64,
    /// Their fraction.
    #[serde(deserialize_with = "nullable::number")]
    pub fraction: f64,
    /// Its Clopper-Pearson upper bound.
    #[serde(deserialize_with = "nullable::number")]
    pub cp_upper: f64,
}

/// The paths that entered an unsafe set.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SimUnsafeJson {
    /// Its name.
    pub name: String,
    /// Its kind.
    pub kind: UnsafeKind,
    /// The paths that entered it.
    pub hits: u64,
    /// Their fraction.
    #[serde(deserialize_with = "nullable::number")]
    pub fraction: f64,
    /// The first time a path entered it.
    pub first_hit_t: Option<f64>,
}

/// The paths that entered no unsafe set, against the certified probability of safety.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SafetyJson {
    /// How many.
    pub safe: u64,
    /// Their fraction.
    #[serde(deserialize_with = "nullable::number")]
    pub fraction: f64,
    /// Its Clopper-Pearson upper bound.
    #[serde(deserialize_with = "nullable::number")]
    pub cp_upper: f64,
    /// The certified lower bound.
    pub certified: Option<f64>,
    /// `null` without a certified bound.
    pub status: Option<Status>,
}

/// The paths whose goal event happened, against its certified probability.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SimGoalJson {
    /// The goal's name.
    pub name: String,
    /// How many.
    pub reached: u64,
    /// Their fraction.
    #[serde(deserialize_with = "nullable::number")]
    pub fraction: f64,
    /// Its Clopper-Pearson upper bound.
    #[serde(deserialize_with = "nullable::number")]
    pub cp_upper: f64,
    /// The certified lower bound.
    pub certified: Option<f64>,
    /// `null` without a certified bound.
    pub status: Option<Status>,
}

/// The coverage verdict.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CoverageJson {
    /// The verdict.
    pub status: Status,
    /// What decides it: the tube (uniform) or the report times (pointwise).
    pub decided_by: Guarantee,
    /// The per-report-time check's.
    pub pointwise_status: Status,
    /// The probability of a false failure.
    pub alpha: f64,
    /// Its share per report time.
    pub alpha_per_step: f64,
    /// The report times failing.
    pub failing_steps: usize,
    /// The worst.
    pub worst_step: usize,
    /// Its time.
    pub worst_t: f64,
    /// Its paths outside.
    pub worst_outside: u64,
    /// Its Clopper-Pearson lower bound.
    #[serde(deserialize_with = "nullable::number")]
    pub worst_cp_lower: f64,
}
