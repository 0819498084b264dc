//! The driver of a simulation: a shard's paths in batches of chunks on the workers, their
//! statistics merged into a part.

use super::paths::{ChunkStats, Plan, Thresholds};
use super::plan::make_plan;
use super::{
    part_file, topk, Options, Part, PartStats, RunInfo, Shard, SimError, SimInvalid, SimUsage,
    StepInfo, VERSION,
};
#[cfg(doc)]
use super::{run_part, simulate};
use crate::interval::Interval;
use crate::model::ModelInfo;
use crate::prs::{Prs, UnsafeKind};
use crate::system::System;
use crate::workers::Workers;

/// Paths per chunk (the unit of parallel work), for a model whose candidates allow it.
const CHUNK: u64 = 256;
/// The fewest paths per chunk (the lanes of the vectorised loops).
const MIN_CHUNK: u64 = 8;
/// Most paths per batch (between two progress reports and threshold updates).
const MAX_BATCH: u64 = 1 << 16;
/// Memory budget of one batch's candidate distances, in bytes.
const BATCH_BYTES: u64 = 32 << 20;
/// Memory limit of the quantile buffers, in bytes.
pub(super) const QUANTILE_BYTES: u64 = 8 << 30;

/// [`run_part`] of `sys` with its model data `info` (for a discrete-time model, `sys` is its
/// map's [`Increments`](super::increments::Increments)).
pub(super) fn part<S: System + ?Sized>(
    sys: &S,
    info: &ModelInfo,
    result: &Prs,
    opts: &Options,
    shard: Shard,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Part, SimError> {
    let plan = make_plan(sys, info, result, opts)?;
    let steps = plan.times.len();
    let n_paths = opts.paths;
    // (`index < count` holds by construction.)
    if shard.count > n_paths {
        return Err(SimError::Usage(SimUsage::Shards {
            shard,
            paths: n_paths,
        }));
    }
    // j-th largest = ceil((1 - delta) N)-th smallest; the slack keeps delta * N = 1000 (say)
    // from rounding down to 999. N is the whole run's: every part keeps the same j.
    let j = ((result.delta * n_paths as f64 * (1.0 + 1e-12)).floor() as u64 + 1).min(n_paths);
    // One buffer per report time for the metric's distance and one per state.
    let n = sys.n();
    let buffers = steps as u64 * (1 + n as u64);
    let quantile_bytes = 16u64.saturating_mul(j).saturating_mul(buffers);
    if quantile_bytes > QUANTILE_BYTES {
        return Err(SimError::Usage(SimUsage::QuantileMemory {
            paths: n_paths,
            delta: result.delta,
            steps,
            n,
            bytes: quantile_bytes,
            max_gib: QUANTILE_BYTES >> 30,
        }));
    }
    // Batches: many chunks per batch for the threads, few enough candidates in memory. Until a
    // buffer has `j` values every path's distances are candidates (one per state and report
    // time), so a large model gets shorter chunks and a first batch within the budget (the
    // 1000-state chain: 16 paths per chunk instead of 256, its first batch of candidates 103 MB
    // instead of 414 MB). Each path has its own random stream: the chunking changes nothing in
    // the results.
    let per_path = 16 * buffers;
    let chunk = (BATCH_BYTES / per_path / MIN_CHUNK * MIN_CHUNK).clamp(MIN_CHUNK, CHUNK);
    let batch = (BATCH_BYTES / per_path)
        .clamp(chunk, MAX_BATCH)
        .div_ceil(chunk)
        * chunk;
    let workers =
        Workers::new(opts.threads).map_err(|e| SimError::Invalid(SimInvalid::Threads(e)))?;
    let j = usize::try_from(j).unwrap_or(usize::MAX);
    let (mut topk, mut state_topk) = (topk::TopK::new(steps, j), topk::TopK::new(steps * n, j));
    let sets = &plan.sets;
    let mut total = ChunkStats::new(steps, sets.unsafe_sets.len(), sets.goals.len(), n);
    let range = shard.paths(n_paths);
    let mut done = 0;
    let mine = range.end - range.start;
    while done < mine {
        // Small batches first: the thresholds are -inf until a step has `j` values, and every
        // path-step is a candidate until then; doubling keeps the number of batches
        // logarithmic.
        let end = (done + done.clamp((4 * chunk).min(batch), batch)).min(mine);
        let thresholds = Thresholds {
            metric: topk.thresholds().to_vec(),
            states: state_topk.thresholds().to_vec(),
        };
        let chunks: Vec<(u64, u64)> = (range.start + done..range.start + end)
            .step_by(chunk as usize)
            .map(|s| (s, (s + chunk).min(range.start + end)))
            .collect();
        let stats = workers.map(chunks, |(s, e)| plan.run_chunk(s..e, &thresholds));
        for c in &stats {
            total.merge(c);
            for &(k, d) in &c.candidates {
                topk.push(k as usize, d);
            }
            for &(s, d) in &c.state_candidates {
                state_topk.push(s as usize, d);
            }
        }
        topk.tighten();
        state_topk.tighten();
        done = end;
        progress(done, mine);
    }
    Ok(Part {
        run: run_info(&plan, info, result, opts, j as u64),
        shard,
        stats: PartStats::of(total),
        top: topk.into_largest(),
        state_top: state_topk.into_largest(),
    })
}

/// What every part of a run shares: the result's radii, the options, the sampling.
fn run_info<S: System + ?Sized>(
    plan: &Plan<'_, S>,
    info: &ModelInfo,
    result: &Prs,
    opts: &Options,
    j: u64,
) -> RunInfo {
    RunInfo {
        version: VERSION.to_string(),
        spec_hash: String::new(),
        model: result.model.clone(),
        analysis: result.analysis.clone(),
        states: result.states.clone(),
        method: result.method,
        delta: result.delta,
        guarantee: result.guarantee,
        step: result.step,
        paths: opts.paths,
        seed: opts.seed,
        dt_option: opts.dt,
        inputs: opts.inputs,
        hold_option: opts.hold,
        confidence: opts.confidence,
        safety_bound: opts.safety_bound,
        dt: plan.dt,
        steps_per_path: plan.steps_per_path(),
        initial_states: plan.initial.describe(),
        noise: plan.noise.describe(),
        has_inputs: !info.input_box.is_empty(),
        tube: plan.tube.is_some(),
        has_domain: info.has_domain,
        unsafe_sets: info
            .unsafe_sets
            .iter()
            .map(|u| (u.name.clone(), UnsafeKind::of(&u.shape)))
            .collect(),
        goals: info
            .goals
            .iter()
            .enumerate()
            .map(|(g, goal)| {
                let bound = opts.goal_bounds.get(g).copied().flatten();
                (goal.name.clone(), bound)
            })
            .collect(),
        quantile_rank: j,
        steps: result
            .steps
            .iter()
            .enumerate()
            .map(|(k, s)| StepInfo {
                t: s.t,
                r_t: s.r_t,
                prs_radius: s.prs_radius,
                hull: hull_half_widths(result, k),
            })
            .collect(),
        digest: part_file::checksum(
            format!(
                "{result:?} {:?} {:?} {:?} {:?}",
                info.input_box, info.domain, info.unsafe_sets, info.goals
            )
            .as_bytes(),
        ),
    }
}

/// Per state, the half-width of the PRS's bounding box at report step `k` about the nominal
/// state (`max(hi_i - x*_i, x*_i - lo_i)`, rounded up), `NaN` where there is no box.
fn hull_half_widths(result: &Prs, k: usize) -> Vec<f64> {
    let c = result.steps[k].nominal();
    match result.hull_at(k) {
        Some(hull) => hull
            .iter()
            .zip(c)
            .map(|(b, &c)| {
                let up = (Interval::point(b.hi) - Interval::point(c)).hi();
                let down = (Interval::point(c) - Interval::point(b.lo)).hi();
                up.max(down)
            })
            .collect(),
        None => vec![f64::NAN; c.len()],
    }
}
