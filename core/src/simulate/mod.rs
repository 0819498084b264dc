//! Monte Carlo validation of a delta-PRS: Euler-Maruyama sample paths of the SDE, checked
//! against the sets an analysis computed.
//!
//! For every report time `t_k` of an [`Prs`] the simulation counts the paths whose
//! state `X_{t_k}` lies outside the PRS (decided by [`Prs::contains_at`](crate::prs::Prs::contains_at))
//! and computes the empirical `(1 - delta)` quantile of `|X_{t_k} - x*_{t_k}|_P` (the P-norm of
//! the analysis' metric around the result's centre `steps[k].nominal()`), to be read against the
//! PRS radius and `r_t`.
//!
//! What the coverage check tests follows the result's [`Guarantee`]:
//!
//! * uniform (one event of probability `>= 1 - delta` on which the path stays in the tube at
//!   all times): every path's state after every Euler-Maruyama step of report interval
//!   `(t_{k-1}, t_k]` is checked against the tube over that interval (the span `k`, decided by
//!   [`Prs::span_contains`](crate::prs::Prs::span_contains) with shortcuts), the initial state
//!   against span 0, and the states at report times against their PRS too. The check fails when
//!   the one-sided Clopper-Pearson lower bound of the fraction of paths that left the tube
//!   exceeds `delta` (one event: no correction for multiplicity);
//! * pointwise (each `X_t` with probability `1 - delta` separately): it fails when some report
//!   time's violation probability is, with confidence, above `delta` (Clopper-Pearson lower
//!   bound, Bonferroni over the report times). Such a PRS says nothing about whole paths, so
//!   the horizon-wide count is reported but not checked.
//!
//! Paths: initial states uniform in the initial set, inputs piecewise constant (uniform in the
//! box, random corners, or the centre; see [`InputMode`]), one random stream per path derived
//! from `(seed, path index)`. Paths run in parallel (rayon) in fixed-size chunks; statistics are
//! streamed (exact quantiles from bounded buffers, see `topk.rs`), so memory does not grow with the
//! number of paths beyond `O(delta * paths * report times)`, and the report is identical for
//! any thread count.

#[cfg(target_arch = "x86_64")]
mod avx512;
mod binomial;
mod check;
mod dt;
mod error;
mod increments;
mod initial;
mod inputs;
mod merge;
mod noise;
mod normal;
mod part;
mod part_file;
mod paths;
mod plan;
mod regions;
mod report;
mod rng;
mod run;
mod sample;
mod shard;
mod topk;

pub use crate::workers::thread_count;
pub use binomial::{lower_bound as clopper_pearson_lower, upper_bound as clopper_pearson_upper};
pub use dt::{DtSource, DtUsed, ACCURACY as DT_ACCURACY, MAX_STEPS, RULE as DT_RULE};
pub use error::{
    Coded, InitialFault, MergeError, PartFault, PartFileError, RegionFault, RunDifference,
    RunOption, SimError, SimInvalid, SimUsage, SpanFault,
};
pub use inputs::InputMode;
pub use merge::{merge, Merger};
pub use part::{Part, PartStats, RunInfo, StepInfo};
pub use part_file::{FORMAT_VERSION, MAGIC};
pub use report::{
    Coverage, GoalCheck, HorizonReport, InitialSampling, InputsReport, NoiseKind, SafetyCheck,
    SimReport, SimStep, StateSpread, TubeReport, UnsafeHits,
};
pub use sample::{result_paths, result_substeps, sample_paths, Substeps, MAX_SAMPLE_PATHS};
pub use shard::{Shard, ShardError};

#[cfg(doc)]
use crate::model::Guarantee;
use crate::prs::Prs;
use crate::system::Model;
use increments::Increments;
use run::part;

/// The version of reachc that simulates (recorded in parts: only parts of one version merge).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// How to simulate.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Number of sample paths (at least 1, at most `2^32`).
    pub paths: u64,
    /// Random seed: the same seed gives the same report.
    pub seed: u64,
    /// Largest Euler-Maruyama step (`None`: chosen per report interval from the drift's
    /// Jacobian over the analysis' sets, `h L_k <=` [`DT_RULE`], see [`DtUsed`]).
    pub dt: Option<f64>,
    /// How inputs are drawn.
    pub inputs: InputMode,
    /// Hold time of piecewise-constant inputs (`None`: the analysis' report step).
    pub hold: Option<f64>,
    /// Confidence level of the Clopper-Pearson bounds and of the coverage check, in `(0, 1)`.
    pub confidence: f64,
    /// Worker threads (`None`: the current rayon pool). The report does not depend on it.
    pub threads: Option<usize>,
    /// A certified lower bound of the probability that no unsafe set is entered on the
    /// horizon ([`Reach::safety_probability`](crate::Reach::safety_probability)), tested
    /// against the paths (see [`SafetyCheck`]).
    pub safety_bound: Option<f64>,
    /// Per goal set of the model, a certified lower bound of the probability of its event
    /// ([`Reach::goal_probability`](crate::Reach::goal_probability)), tested against the paths
    /// (see [`GoalCheck`]); empty, or `None` for a goal: nothing tested.
    pub goal_bounds: Vec<Option<f64>>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            paths: 10_000,
            seed: 0,
            dt: None,
            inputs: InputMode::Random,
            hold: None,
            confidence: 0.999,
            threads: None,
            safety_bound: None,
            goal_bounds: Vec::new(),
        }
    }
}

/// Simulates `opts.paths` sample paths of `model` and checks them against `result` (one of its
/// analyses, computed by [`engine::run`](crate::engine::run)). `progress(done, total)` is
/// called after each batch of paths, on the calling thread. The paths run on a pool of
/// `opts.threads` threads, or on the current rayon pool.
///
/// This is [`run_part`] of all the paths ([`Shard::WHOLE`]) merged alone ([`merge`]): the
/// parts of a sharded run merge into this very report.
pub fn simulate<M: Model + ?Sized>(
    model: &M,
    result: &Prs,
    opts: &Options,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<SimReport, SimError> {
    let part = run_part(model, result, opts, Shard::WHOLE, progress)?;
    merge([(String::new(), part)]).map_err(|e| SimError::Invalid(SimInvalid::Merge(e)))
}

/// Simulates the paths of `shard` (of `opts.paths`) of `model` and returns their exact
/// statistics, with what the report needs besides them ([`Part`]; its `run.spec_hash` is
/// empty: the caller knows the spec). `progress(done, total)` counts the shard's paths.
pub fn run_part<M: Model + ?Sized>(
    model: &M,
    result: &Prs,
    opts: &Options,
    shard: Shard,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Part, SimError> {
    let info = model.info();
    match info.time().period() {
        // The loops step a map as its increments.
        Some(_) => part(&Increments(model), info, result, opts, shard, progress),
        None => part(model, info, result, opts, shard, progress),
    }
}

#[cfg(test)]
mod tests;
