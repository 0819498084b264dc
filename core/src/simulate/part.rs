//! The result of one shard of a simulation ([`Part`]): exact, mergeable statistics of its paths,
//! and everything the report needs besides them ([`RunInfo`]), so that parts merge into the
//! report without the system (see `merge.rs`; the file format is in `part_file.rs`).

use super::dt::DtUsed;
use super::error::PartFault;
use super::inputs::InputMode;
use super::paths::ChunkStats;
use super::report::{InitialSampling, NoiseKind};
use super::shard::Shard;
use crate::model::{Guarantee, Method};
use crate::prs::UnsafeKind;

/// One shard's paths: what the run was, and the exact statistics of the shard's paths.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// What every part of the run shares (checked when merging).
    pub run: RunInfo,
    /// Which shard of the paths.
    pub shard: Shard,
    /// The counts of the shard's paths.
    pub stats: PartStats,
    /// Per report time, the largest `min(quantile_rank, paths of the shard)` squared distances
    /// `|X_t - x*_t|_P^2` of the shard's paths, largest first (the `j` largest of the union of
    /// all parts hold the quantile and the maximum of the whole run).
    pub top: Vec<Vec<f64>>,
    /// The same for each state's deviation `|X_t,i - x*_t,i|`: entry `k n + i` for report time
    /// `k` and state `i`.
    pub state_top: Vec<Vec<f64>>,
}

/// What a simulation was: the analysis' result as the report shows it, the options, and the
/// sampling. Equal in every part of one run.
#[derive(Clone, Debug, PartialEq)]
pub struct RunInfo {
    /// The version of reachc (of `reachc-core`) that simulated the paths.
    pub version: String,
    /// An identifier of the spec (reachc writes the SHA-256 of its source; empty when unknown).
    pub spec_hash: String,
    /// `model NAME`.
    pub model: String,
    /// The analysis.
    pub analysis: String,
    /// The state names, in order.
    pub states: Vec<String>,
    /// Its method.
    pub method: Method,
    /// Its probability level (the one simulated, with `--delta`).
    pub delta: f64,
    /// Its guarantee.
    pub guarantee: Guarantee,
    /// The analysis' report step (the default hold time).
    pub step: f64,
    /// Paths of the whole run (all shards).
    pub paths: u64,
    /// Random seed.
    pub seed: u64,
    /// The `dt` option (`None`: the rule's steps).
    pub dt_option: Option<f64>,
    /// How inputs were drawn.
    pub inputs: InputMode,
    /// The hold-time option (`None`: the analysis' step).
    pub hold_option: Option<f64>,
    /// Confidence level of the bounds and the check.
    pub confidence: f64,
    /// A certified lower bound of the probability of safety to test (`--probability`).
    pub safety_bound: Option<f64>,
    /// The Euler-Maruyama steps used and how they compare with the rule.
    pub dt: DtUsed,
    /// Euler-Maruyama steps per path.
    pub steps_per_path: u64,
    /// How initial states were drawn.
    pub initial_states: InitialSampling,
    /// How the noise was applied.
    pub noise: NoiseKind,
    /// The model has inputs.
    pub has_inputs: bool,
    /// The paths were checked against a time-uniform tube (a uniform result).
    pub tube: bool,
    /// The model has a domain (exits are counted).
    pub has_domain: bool,
    /// The unsafe sets, in order: name and kind.
    pub unsafe_sets: Vec<(String, UnsafeKind)>,
    /// The goal sets' names, each with the certified lower bound of its probability to test.
    pub goals: Vec<(String, Option<f64>)>,
    /// `j = floor(delta N (1 + 1e-12)) + 1` (at most `N`), from the whole run's `N`.
    pub quantile_rank: u64,
    /// Per report time, what the analysis computed there.
    pub steps: Vec<StepInfo>,
    /// A digest of everything else the paths were checked against and drawn from: the whole
    /// result (sets, spans, metric) and the model's input box, domain and unsafe sets (FNV-1a
    /// of their `Debug` text, whose floats round-trip).
    pub digest: u64,
}

/// The analysis' radii at one report time.
#[derive(Clone, Debug, PartialEq)]
pub struct StepInfo {
    /// Time.
    pub t: f64,
    /// Stochastic radius `r_t`.
    pub r_t: f64,
    /// PRS radius.
    pub prs_radius: f64,
    /// Per state, the half-width of the PRS's bounding box about the nominal state (`NaN`
    /// where the result has none).
    pub hull: Vec<f64>,
}

/// The counts of a set of paths (sums over shards, and a minimum).
#[derive(Clone, Debug, PartialEq)]
pub struct PartStats {
    /// Per report time, paths outside the PRS.
    pub outside: Vec<u64>,
    /// Paths outside the PRS at one report time at least.
    pub outside_any: u64,
    /// Paths that left the time-uniform tube (0 without a tube).
    pub outside_tube: u64,
    /// Per report time `k`, paths that left the tube first in the interval ending there.
    pub left_tube: Vec<u64>,
    /// Per unsafe set, paths that entered it.
    pub unsafe_hits: Vec<u64>,
    /// Per unsafe set, the earliest entry (`inf`: none).
    pub first_hit: Vec<f64>,
    /// Paths that entered some unsafe set.
    pub unsafe_any: u64,
    /// Per goal set, paths whose event happened.
    pub goal_reached: Vec<u64>,
    /// Paths that left the domain.
    pub left_domain: u64,
    /// Paths whose state became non-finite.
    pub diverged: u64,
}

impl PartStats {
    /// The counts of `c` (its candidates go to the quantile buffers).
    pub(crate) fn of(c: ChunkStats) -> PartStats {
        PartStats {
            outside: c.outside,
            outside_any: c.outside_any,
            outside_tube: c.outside_tube,
            left_tube: c.left_tube,
            unsafe_hits: c.unsafe_hits,
            first_hit: c.first_hit,
            unsafe_any: c.unsafe_any,
            goal_reached: c.goal_reached,
            left_domain: c.left_domain,
            diverged: c.diverged,
        }
    }

    /// Adds `other`'s counts (sums; the earlier first hit).
    pub(crate) fn add(&mut self, other: &PartStats) {
        let sum = |a: &mut Vec<u64>, b: &[u64]| a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
        sum(&mut self.outside, &other.outside);
        sum(&mut self.left_tube, &other.left_tube);
        sum(&mut self.unsafe_hits, &other.unsafe_hits);
        sum(&mut self.goal_reached, &other.goal_reached);
        for (a, &b) in self.first_hit.iter_mut().zip(&other.first_hit) {
            *a = a.min(b);
        }
        self.outside_any += other.outside_any;
        self.outside_tube += other.outside_tube;
        self.unsafe_any += other.unsafe_any;
        self.left_domain += other.left_domain;
        self.diverged += other.diverged;
    }
}

impl Part {
    /// Why this part is not well formed (vectors of the wrong length, counts above its paths,
    /// quantile buffers out of order), or `None`. Merging checks every part with it, so a part
    /// read from a file or built by hand never makes the report panic or lie.
    pub fn malformed(&self) -> Option<PartFault> {
        let (run, st) = (&self.run, &self.stats);
        if run.paths == 0 || self.shard.count == 0 || self.shard.index >= self.shard.count {
            return Some(PartFault::Shard {
                shard: self.shard,
                paths: run.paths,
            });
        }
        if !(run.confidence > 0.0 && run.confidence < 1.0 && run.delta > 0.0) {
            return Some(PartFault::Range {
                confidence: run.confidence,
                delta: run.delta,
            });
        }
        let n = self.shard.paths(run.paths);
        let mine = n.end - n.start;
        let steps = run.steps.len();
        let sets = run.unsafe_sets.len();
        let n = run.states.len();
        if steps == 0
            || st.outside.len() != steps
            || st.left_tube.len() != steps
            || self.top.len() != steps
            || self.state_top.len() != steps * n
            || run.steps.iter().any(|s| s.hull.len() != n)
            || st.unsafe_hits.len() != sets
            || st.first_hit.len() != sets
            || st.goal_reached.len() != run.goals.len()
        {
            return Some(PartFault::Statistics);
        }
        if run.quantile_rank == 0 || run.quantile_rank > run.paths {
            return Some(PartFault::Rank {
                rank: run.quantile_rank,
                paths: run.paths,
            });
        }
        let counts = st
            .outside
            .iter()
            .chain(&st.unsafe_hits)
            .chain(&st.goal_reached);
        let totals = [
            st.outside_any,
            st.outside_tube,
            st.unsafe_any,
            st.left_domain,
            st.diverged,
        ];
        if counts.chain(&totals).any(|&c| c > mine)
            || st.left_tube.iter().sum::<u64>() != st.outside_tube
        {
            return Some(PartFault::Counts { paths: mine });
        }
        let kept = run.quantile_rank.min(mine);
        let buffers = self.top.iter().enumerate().map(|(k, top)| (k, None, top));
        let per_state = self
            .state_top
            .iter()
            .enumerate()
            .map(|(s, top)| (s / n, Some(s % n), top));
        for (k, state, top) in buffers.chain(per_state) {
            if top.len() as u64 != kept {
                return Some(PartFault::Distances {
                    count: top.len(),
                    state,
                    step: k,
                    kept,
                });
            }
            if top.iter().any(|d| d.is_nan() || *d < 0.0) || top.windows(2).any(|w| w[0] < w[1]) {
                return Some(PartFault::Unsorted { state, step: k });
            }
        }
        None
    }
}
