//! The certified probabilities in a result file (`reachc run --probability`, method.md 8.9,
//! 8.13): `safety_probability`, and each goal's `probability`.

use super::nullable;
use serde::{Deserialize, Serialize};

/// The `safety_probability` object of a result.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ProbabilityJson {
    /// The horizon it is about.
    pub horizon: f64,
    /// `1 - delta` rounded down; `null` without a bound.
    pub lower_bound: Option<f64>,
    /// The smallest delta shown safe.
    pub delta: Option<f64>,
    /// The largest delta tried and not shown safe.
    pub not_shown_at: Option<f64>,
    /// What limits it.
    pub limit: LimitJson,
    /// The runs of the search.
    pub runs: usize,
    /// Every part of the run behind the bound is proved (no "not validated" entry).
    pub proved: bool,
    /// It holds while the state stays in the domain.
    pub conditional_on_domain: bool,
}

/// What limits the probability of safety.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum LimitJson {
    /// The bisection's resolution.
    Resolution,
    /// Shown at the smallest delta tried.
    Floor,
    /// The stochastic radius is too large: where and which set.
    Stochastic {
        /// The report time.
        t: f64,
        /// The unsafe set.
        set: String,
    },
    /// The deterministic set alone meets a set: where and which.
    Deterministic {
        /// The report time.
        t: f64,
        /// The unsafe set.
        set: String,
    },
    /// A run failed.
    Failed {
        /// Its delta.
        delta: f64,
        /// Why, in words.
        why: String,
    },
}

/// The `probability` object of a goal.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GoalProbabilityJson {
    /// `1 - delta` rounded down; `null` without a bound.
    pub lower_bound: Option<f64>,
    /// The smallest delta at which the goal is shown reached.
    pub delta: Option<f64>,
    /// The first report time at which the goal is shown reached at `delta`.
    pub t: Option<f64>,
    /// The largest delta tried and not shown.
    pub not_shown_at: Option<f64>,
    /// What limits it.
    pub limit: GoalLimitJson,
    /// The runs of the search.
    pub runs: usize,
    /// Every part of the runs is proved.
    pub proved: bool,
    /// It holds while the state stays in the domain.
    pub conditional_on_domain: bool,
}

/// A goal probability's limit: the search's own, or the goal's miss at the largest delta tried.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(untagged)]
pub enum GoalLimitJson {
    /// The search's.
    Search(SearchLimitJson),
    /// The goal's miss.
    Miss(GoalMissJson),
}

/// What limits a search over delta.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SearchLimitJson {
    /// The bisection's resolution.
    Resolution,
    /// Shown at the smallest delta tried.
    Floor,
    /// A run failed.
    Failed {
        /// Its delta.
        delta: f64,
        /// Why, in words.
        why: String,
    },
}

/// Why a goal is not shown reached (a goal's `why`, and the limit of its probability).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum GoalMissJson {
    /// No report time lies in the window.
    NoReportTime,
    /// The PRS meets an unsafe set first.
    Unsafe {
        /// The report time.
        t: f64,
        /// The unsafe set.
        set: String,
    },
    /// The PRS is not inside the goal in the window.
    NotInside {
        /// Where the margin is largest.
        t: f64,
        /// The largest margin.
        #[serde(deserialize_with = "nullable::number")]
        margin: f64,
    },
    /// The PRS is not shown to stay in the goal.
    Leaves {
        /// The end of the report interval where it may leave.
        t: f64,
    },
}
