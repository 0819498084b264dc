//! The certified probabilities of safety and of reaching a goal.

use pyo3::prelude::*;

/// A certified lower bound of the probability of safety (`Reach.safety_probability`): the
/// fields of the JSON's `safety_probability`, the limit flattened (`limit_t` is the time of a
/// `stochastic` or `deterministic` limit and the `delta` of a `failed` one), and `text` the
/// summary's line.
#[pyclass(module = "reachc._native", frozen, get_all, name = "SafetyProbability")]
pub(crate) struct SafetyProbabilityPy {
    pub(crate) horizon: f64,
    pub(crate) lower_bound: Option<f64>,
    pub(crate) delta: Option<f64>,
    pub(crate) not_shown_at: Option<f64>,
    pub(crate) limit: String,
    pub(crate) limit_t: Option<f64>,
    pub(crate) limit_set: Option<String>,
    pub(crate) limit_why: Option<String>,
    pub(crate) runs: usize,
    pub(crate) proved: bool,
    pub(crate) conditional_on_domain: bool,
    pub(crate) text: String,
}

#[pymethods]
impl SafetyProbabilityPy {
    fn __repr__(&self) -> String {
        self.text.clone()
    }
}

/// A certified lower bound of the probability of reaching a goal (`Reach.goal_probability`):
/// the fields of the JSON's `goals[].probability`, the limit flattened (`limit` one of
/// `resolution`, `floor`, `failed`, `no_report_time`, `unsafe`, `not_inside`, `leaves`;
/// `limit_t` its time, or the `delta` of a `failed` one), and `text` the summary's line.
#[pyclass(module = "reachc._native", frozen, get_all, name = "GoalProbability")]
pub(crate) struct GoalProbabilityPy {
    pub(crate) goal: String,
    pub(crate) lower_bound: Option<f64>,
    pub(crate) delta: Option<f64>,
    pub(crate) t: Option<f64>,
    pub(crate) not_shown_at: Option<f64>,
    pub(crate) limit: String,
    pub(crate) limit_t: Option<f64>,
    pub(crate) limit_set: Option<String>,
    pub(crate) limit_why: Option<String>,
    pub(crate) runs: usize,
    pub(crate) proved: bool,
    pub(crate) conditional_on_domain: bool,
    pub(crate) text: String,
}

#[pymethods]
impl GoalProbabilityPy {
    fn __repr__(&self) -> String {
        self.text.clone()
    }
}
