//! Monte Carlo validation of a delta-PRS: Euler-Maruyama sample paths of the SDE, checked
//! against the sets an analysis computed.
//!
//! For every report time `t_k` of an [`Prs`] the simulation counts the paths whose
//! state `X_{t_k}` lies outside the PRS (decided by [`Prs::contains_at`](crate::prs::Prs::contains_at))
//! and computes the empirical `(1 - delta)` quantile of `|X_{t_k} - x*_{t_k}|_P` (the P-norm of
//! the analysis' metric around the result's centre `steps[k].nominal()`), to be read against the
//! PRS radius and `r_t`. The coverage check fails when some time's violation probability is,
//! with confidence, above `delta` (Clopper-Pearson lower bound, Bonferroni over the report
//! times). A PRS holds `X_t` with probability `1 - delta` at each time `t`; it says nothing
//! about whole paths, so the horizon-wide count is reported but not checked.
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
mod initial;
mod inputs;
mod noise;
mod normal;
mod paths;
mod prs;
mod regions;
mod report;
mod rng;
mod sample;
mod topk;
mod workers;

pub use binomial::{lower_bound as clopper_pearson_lower, upper_bound as clopper_pearson_upper};
pub use inputs::InputMode;
pub use report::{
    Coverage, HorizonReport, InitialSampling, InputsReport, NoiseKind, SimReport, SimStep,
    UnsafeHits,
};
pub use sample::{sample_paths, MAX_SAMPLE_PATHS};
pub use workers::thread_count;

use crate::model::ModelInfo;
use crate::prs::{Prs, UnsafeKind};
use crate::system::System;
use paths::{ChunkStats, Plan, Span};
use std::collections::BTreeMap;
use std::fmt;

/// Paths per chunk (the unit of parallel work).
const CHUNK: u64 = 256;
/// Most paths per batch (between two progress reports and threshold updates).
const MAX_BATCH: u64 = 1 << 16;
/// Memory budget of one batch's candidate distances, in bytes.
const BATCH_BYTES: u64 = 32 << 20;
/// Memory limit of the quantile buffers, in bytes.
const QUANTILE_BYTES: u64 = 8 << 30;

/// How to simulate.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Number of sample paths (at least 1, at most `2^32`).
    pub paths: u64,
    /// Random seed: the same seed gives the same report.
    pub seed: u64,
    /// Largest Euler-Maruyama step (`None`: the analysis' report step).
    pub dt: Option<f64>,
    /// How inputs are drawn.
    pub inputs: InputMode,
    /// Hold time of piecewise-constant inputs (`None`: the analysis' report step).
    pub hold: Option<f64>,
    /// Confidence level of the Clopper-Pearson bounds and of the coverage check, in `(0, 1)`.
    pub confidence: f64,
    /// Worker threads (`None`: the current rayon pool). The report does not depend on it.
    pub threads: Option<usize>,
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
        }
    }
}

/// Why a simulation could not run.
#[derive(Clone, Debug, PartialEq)]
pub enum SimError {
    /// Bad options (a usage error).
    Usage(String),
    /// The model or result cannot be simulated (inconsistent data, unbounded initial set...).
    Invalid(String),
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::Usage(m) | SimError::Invalid(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for SimError {}

/// Simulates `opts.paths` sample paths of `sys` and checks them against `result` (an analysis
/// of `info` computed by [`engine::run`](crate::engine::run)). `progress(done, total)` is called
/// after each batch of paths, on the calling thread. The paths run on a pool of
/// `opts.threads` threads, or on the current rayon pool.
pub fn simulate<S: System + Sync + ?Sized>(
    sys: &S,
    info: &ModelInfo,
    result: &Prs,
    opts: &Options,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<SimReport, SimError> {
    let plan = make_plan(sys, info, result, opts)?;
    let steps = plan.times.len();
    let n_paths = opts.paths;
    // j-th largest = ceil((1 - delta) N)-th smallest; the slack keeps delta * N = 1000 (say)
    // from rounding down to 999.
    let j = ((result.delta * n_paths as f64 * (1.0 + 1e-12)).floor() as u64 + 1).min(n_paths);
    let quantile_bytes = 16 * j * steps as u64;
    if quantile_bytes > QUANTILE_BYTES {
        return Err(SimError::Usage(format!(
            "exact quantiles of {n_paths} paths at delta = {} over {steps} report times need \
             {:.1} GiB (more than {} GiB): use fewer paths",
            result.delta,
            quantile_bytes as f64 / f64::from(1u32 << 30),
            QUANTILE_BYTES >> 30
        )));
    }
    // Batches: many chunks per batch for the threads, few enough candidates in memory.
    let batch = (BATCH_BYTES / (16 * steps as u64))
        .clamp(4 * CHUNK, MAX_BATCH)
        .div_ceil(CHUNK)
        * CHUNK;
    let workers = workers::Workers::new(opts.threads)?;
    let mut topk = topk::TopK::new(steps, usize::try_from(j).unwrap_or(usize::MAX));
    let mut total = ChunkStats::new(steps, plan.unsafe_sets.len());
    let mut done = 0;
    while done < n_paths {
        // Small batches first: the thresholds are -inf until a step has `j` values, and every
        // path-step is a candidate until then; doubling keeps the number of batches
        // logarithmic.
        let end = (done + done.clamp(4 * CHUNK, batch)).min(n_paths);
        let thresholds = topk.thresholds().to_vec();
        let chunks: Vec<(u64, u64)> = (done..end)
            .step_by(CHUNK as usize)
            .map(|s| (s, (s + CHUNK).min(end)))
            .collect();
        let stats = workers.map(chunks, |(s, e)| plan.run_chunk(s..e, &thresholds));
        for c in &stats {
            total.merge(c);
            for &(k, d) in &c.candidates {
                topk.push(k as usize, d);
            }
        }
        topk.tighten();
        done = end;
        progress(done, n_paths);
    }
    Ok(report(&plan, info, result, opts, j, &total, &mut topk))
}

/// Checks the options and data and prepares what the workers share.
fn make_plan<'a, S: System + ?Sized>(
    sys: &'a S,
    info: &ModelInfo,
    result: &'a Prs,
    opts: &Options,
) -> Result<Plan<'a, S>, SimError> {
    let usage = |m: String| Err(SimError::Usage(m));
    if opts.paths == 0 || opts.paths > rng::MAX_PATHS {
        return usage(format!(
            "the number of paths must be between 1 and {}, not {}",
            rng::MAX_PATHS,
            opts.paths
        ));
    }
    let dt = opts.dt.unwrap_or(result.step);
    if !(dt > 0.0 && dt.is_finite()) {
        return usage(format!("dt = {dt} must be positive and finite"));
    }
    let hold = opts.hold.unwrap_or(result.step);
    if !(hold > 0.0 && hold.is_finite()) {
        return usage(format!("the hold time {hold} must be positive and finite"));
    }
    if !(opts.confidence > 0.0 && opts.confidence < 1.0) {
        return usage(format!(
            "the confidence {} must lie in (0, 1)",
            opts.confidence
        ));
    }
    let invalid = |m: String| Err(SimError::Invalid(m));
    let (n, p, m) = (sys.n(), sys.p(), sys.m());
    if result.states.len() != n || result.steps.is_empty() {
        return invalid(format!(
            "the result has {} states and {} steps; the system has {n} states",
            result.states.len(),
            result.steps.len()
        ));
    }
    if result.constants.metric.len() != n * n {
        return invalid("the result's metric is not n x n".into());
    }
    if result.input_plan.is_some() {
        return invalid("sets under an input plan cannot be simulated (the paths draw inputs from the input box)".into());
    }
    if info.input_box.len() != p {
        return invalid(format!(
            "the input box has {} ranges, the system has {p} inputs",
            info.input_box.len()
        ));
    }
    if let Some(b) = info
        .input_box
        .iter()
        .find(|r| !(r.lo.is_finite() && r.hi.is_finite() && r.lo <= r.hi))
    {
        return invalid(format!("the input box [{}, {}] is not bounded", b.lo, b.hi));
    }
    let times: Vec<f64> = result.steps.iter().map(|s| s.t).collect();
    let mut spans = Vec::with_capacity(times.len().saturating_sub(1));
    for w in times.windows(2) {
        // The slack keeps a step of exactly dt (up to rounding) from being split in two.
        let s = ((w[1] - w[0]) / dt * (1.0 - 1e-12)).ceil().max(1.0);
        if s.is_nan() || s > 1e9 {
            return usage(format!("dt = {dt} gives too many Euler steps"));
        }
        spans.push(Span::new(w[0], w[1], s as u32));
    }
    let per_path: u64 = spans.iter().map(|s| u64::from(s.steps)).sum();
    // Draws per Euler step: m normals (about 1% need a second draw), p inputs at most.
    if per_path.saturating_mul(2 * (m + p + 1) as u64) >= rng::DRAWS_PER_PATH {
        return usage(format!(
            "{per_path} Euler steps of {m} noise channels are too many random numbers per path"
        ));
    }
    let nominal: Vec<f64> = result
        .steps
        .iter()
        .flat_map(|s| s.nominal().iter().copied())
        .collect();
    if nominal.len() != n * times.len() {
        return invalid("a nominal state has the wrong dimension".into());
    }
    let metric = prs::Metric::new(&result.constants.metric, n);
    let unsafe_sets = info
        .unsafe_sets
        .iter()
        .map(|u| regions::Region::unsafe_set(&u.shape, n))
        .collect::<Result<Vec<_>, _>>()
        .map_err(SimError::Invalid)?;
    Ok(Plan {
        sys,
        seed: opts.seed,
        spans,
        nominal,
        membership: prs::Membership::new(result, &metric),
        metric,
        // The paths start where the sets start.
        initial: initial::InitialSampler::new(&result.initial, n).map_err(SimError::Invalid)?,
        inputs: inputs::InputSchedule::new(&info.input_box, opts.inputs, hold),
        noise: noise::Noise::new(sys, *times.last().unwrap_or(&0.0), &result.initial_center),
        unsafe_sets,
        domain: info
            .has_domain
            .then(|| regions::Region::domain(&info.domain)),
        zig: normal::Ziggurat::get(),
        avx2: has_avx2(),
        #[cfg(target_arch = "x86_64")]
        avx512: avx512::available(),
        #[cfg(not(target_arch = "x86_64"))]
        avx512: false,
        times,
    })
}

/// Quantiles, Clopper-Pearson bounds and the verdict from the merged statistics.
fn report<S: System + ?Sized>(
    plan: &Plan<'_, S>,
    info: &ModelInfo,
    result: &Prs,
    opts: &Options,
    j: u64,
    total: &ChunkStats,
    topk: &mut topk::TopK,
) -> SimReport {
    let n_paths = opts.paths;
    let frac = |k: u64| k as f64 / n_paths as f64;
    let alpha = 1.0 - opts.confidence;
    let alpha_step = alpha / plan.times.len() as f64;
    // Many steps share a count (often 0): compute each bound once.
    let mut upper_cache = BTreeMap::new();
    let mut upper = |k: u64| {
        *upper_cache
            .entry(k)
            .or_insert_with(|| binomial::upper_bound(k, n_paths, alpha))
    };
    let steps: Vec<SimStep> = result
        .steps
        .iter()
        .enumerate()
        .map(|(k, st)| {
            // The buffers hold squared distances (sqrt is monotone: same order statistics).
            let (q2, max2) = topk.result(k).unwrap_or((f64::NAN, f64::NAN));
            let (quantile, max) = (q2.sqrt(), max2.sqrt());
            let outside = total.outside[k];
            SimStep {
                t: st.t,
                r_t: st.r_t,
                prs_radius: st.prs_radius,
                quantile,
                max,
                outside,
                fraction: frac(outside),
                cp_upper: upper(outside),
            }
        })
        .collect();
    // The lower bound grows with the count: the step with the most violations decides, and the
    // failing steps are those above the smallest failing count.
    let worst_step = (0..steps.len())
        .max_by(|&a, &b| steps[a].outside.cmp(&steps[b].outside).then(b.cmp(&a)))
        .unwrap_or(0);
    let (worst_t, worst_outside) = (steps[worst_step].t, steps[worst_step].outside);
    let worst_cp_lower = binomial::lower_bound(worst_outside, n_paths, alpha_step);
    let mut lower_cache = BTreeMap::new();
    let failing_steps = steps
        .iter()
        .filter(|s| {
            *lower_cache.entry(s.outside).or_insert_with(|| {
                binomial::lower_bound(s.outside, n_paths, alpha_step) > result.delta
            })
        })
        .count();
    let hold = (!info.input_box.is_empty() && opts.inputs != InputMode::Centre)
        .then(|| opts.hold.unwrap_or(result.step));
    let dt = plan.spans.iter().map(|s| s.h).fold(0.0, f64::max);
    SimReport {
        model: result.model.clone(),
        analysis: result.analysis.clone(),
        method: result.method,
        delta: result.delta,
        paths: n_paths,
        seed: opts.seed,
        dt,
        steps_per_path: plan.steps_per_path(),
        initial_states: plan.initial.describe(),
        inputs: InputsReport {
            mode: opts.inputs,
            hold,
            any: !info.input_box.is_empty(),
            hold_shown: hold.unwrap_or(result.step),
        },
        noise: plan.noise.describe(),
        quantile_rank: j,
        steps,
        confidence: opts.confidence,
        horizon: HorizonReport {
            outside_any: total.outside_any,
            fraction: frac(total.outside_any),
            cp_upper: binomial::upper_bound(total.outside_any, n_paths, alpha),
        },
        unsafe_sets: info
            .unsafe_sets
            .iter()
            .enumerate()
            .map(|(i, u)| UnsafeHits {
                name: u.name.clone(),
                kind: UnsafeKind::of(&u.shape),
                hits: total.unsafe_hits[i],
                fraction: frac(total.unsafe_hits[i]),
                first_hit_t: Some(total.first_hit[i]).filter(|t| t.is_finite()),
            })
            .collect(),
        left_domain: info.has_domain.then_some(total.left_domain),
        diverged: total.diverged,
        verdict: Coverage {
            passed: failing_steps == 0,
            alpha,
            alpha_per_step: alpha_step,
            failing_steps,
            worst_step,
            worst_t,
            worst_outside,
            worst_cp_lower,
        },
    }
}

/// Whether the processor has AVX2, BMI1 and BMI2 (see `Plan::avx2`).
fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        has!("avx2") && has!("bmi1") && has!("bmi2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine;
    use crate::interval::Interval;
    use crate::model::*;

    /// `dx = (-x + b u) dt + 0.3 dW` per state, two states and one input (unused if `b = 0`).
    struct Sys {
        b: f64,
    }

    impl System for Sys {
        fn n(&self) -> usize {
            2
        }
        fn p(&self) -> usize {
            usize::from(self.b != 0.0)
        }
        fn m(&self) -> usize {
            2
        }
        fn drift(&self, x: &[f64], u: &[f64], _t: f64, out: &mut [f64]) {
            for i in 0..2 {
                out[i] = -x[i] + u.first().map_or(0.0, |u| self.b * u);
            }
        }
        fn drift_interval(&self, x: &[Interval], u: &[Interval], _t: Interval, o: &mut [Interval]) {
            for i in 0..2 {
                o[i] = -x[i]
                    + u.first()
                        .map_or(Interval::ZERO, |&u| Interval::point(self.b) * u);
            }
        }
        fn jac_x(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
            out.copy_from_slice(&[-1.0, 0.0, 0.0, -1.0]);
        }
        fn jac_x_interval(
            &self,
            _x: &[Interval],
            _u: &[Interval],
            _t: Interval,
            o: &mut [Interval],
        ) {
            for (o, v) in o.iter_mut().zip([-1.0, 0.0, 0.0, -1.0]) {
                *o = Interval::point(v);
            }
        }
        fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
            out.fill(self.b);
        }
        fn jac_u_interval(
            &self,
            _x: &[Interval],
            _u: &[Interval],
            _t: Interval,
            o: &mut [Interval],
        ) {
            o.fill(Interval::point(self.b));
        }
        fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
            out.copy_from_slice(&[0.3, 0.0, 0.0, 0.3]);
        }
        fn diffusion_interval(&self, _x: &[Interval], _t: Interval, o: &mut [Interval]) {
            for (o, v) in o.iter_mut().zip([0.3, 0.0, 0.0, 0.3]) {
                *o = Interval::point(v);
            }
        }
    }

    /// With `b != 0`: an input in `[-0.5, 0.5]` and an unsafe half-space `x1 >= 0.4`.
    fn info(b: f64) -> ModelInfo {
        let inputs = b != 0.0;
        let mut info = ModelInfo {
            name: "m".into(),
            states: vec!["x1".into(), "x2".into()],
            inputs: if inputs { vec!["u".into()] } else { vec![] },
            noises: vec!["w1".into(), "w2".into()],
            input_box: if inputs {
                vec![Bounds::new(-0.5, 0.5)]
            } else {
                vec![]
            },
            initial: InitialSet {
                boxes: vec![Some(Bounds::new(0.1, 0.3)), Some(Bounds::new(-0.1, 0.1))],
                balls: vec![],
            },
            domain: vec![Bounds::ENTIRE; 2],
            has_domain: false,
            unsafe_sets: if inputs {
                vec![UnsafeSet {
                    name: "far".into(),
                    shape: UnsafeShape::HalfSpace {
                        normal: vec![1.0, 0.0],
                        offset: 0.4,
                    },
                }]
            } else {
                vec![]
            },
            analyses: vec![],
        };
        // |(b u, b u)| <= sqrt(2) |b| / 2 over the input box.
        let constants = Constants::given(&info, vec![1.0, 0.0, 0.0, 1.0], -1.0, 0.3, b.abs());
        info.analyses.push(Analysis {
            spec: AnalysisSpec {
                name: "a".into(),
                delta: 0.05,
                horizon: 0.5,
                step: 0.01,
                ..AnalysisSpec::default()
            },
            constants: Ok(constants),
        });
        info
    }

    /// The loops compiled for AVX2 and BMI2 and the eight-lane AVX-512 loop (when the
    /// processor has them) and the baseline loops give the same statistics, in the fast loop
    /// for additive noise (`b = 0`) and in the general one (an input, an unsafe set, Euler
    /// steps finer than the report step); with every state recorded (no threshold) and with
    /// the quiet bounds (only candidates and states near the PRS boundary recorded). 300 paths:
    /// blocks of 64 and a last one of 44, whose last 4 paths are not a group of eight.
    #[test]
    fn the_extensions_do_not_change_the_paths() {
        let sorted = |mut s: ChunkStats| {
            // The eight-lane loop records a group's steps in turn, the others a step's paths.
            s.candidates
                .sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
            s
        };
        for (b, threshold) in [
            (0.0, f64::NEG_INFINITY),
            (0.0, 0.05),
            (1.0, f64::NEG_INFINITY),
        ] {
            let (sys, info) = (Sys { b }, info(b));
            let r = engine::run(&sys, &info, &info.analyses[0]).unwrap();
            let opts = Options {
                dt: Some(0.004),
                ..Options::default()
            };
            let mut plan = make_plan(&sys, &info, &r, &opts).unwrap();
            let thresholds = vec![threshold; plan.times.len()];
            let detected = sorted(plan.run_chunk(0..300, &thresholds));
            plan.avx512 = false;
            let avx2 = sorted(plan.run_chunk(0..300, &thresholds));
            plan.avx2 = false;
            let baseline = sorted(plan.run_chunk(0..300, &thresholds));
            assert_eq!(detected, baseline, "b = {b}, threshold {threshold}");
            assert_eq!(avx2, baseline, "b = {b}, threshold {threshold}");
            let records = baseline.candidates.len();
            if threshold < 0.0 {
                assert_eq!(records, 300 * plan.times.len());
            } else {
                assert!(
                    records > 0 && records < 300 * plan.times.len() / 2,
                    "{records}"
                );
            }
        }
    }
}
