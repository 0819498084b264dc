//! The options and data checked, and the plan the workers share.

#[cfg(target_arch = "x86_64")]
use super::avx512;
use super::paths::{Plan, Span};
use super::{
    check, dt, initial, inputs, noise, normal, regions, rng, Options, SimError, SimInvalid,
    SimUsage,
};
use crate::model::{Guarantee, ModelInfo};
use crate::prs::Prs;
use crate::system::System;

/// Checks the options and data and prepares what the workers share.
pub(super) fn make_plan<'a, S: System + ?Sized>(
    sys: &'a S,
    info: &'a ModelInfo,
    result: &'a Prs,
    opts: &Options,
) -> Result<Plan<'a, S>, SimError> {
    let usage = |m: SimUsage| Err(SimError::Usage(m));
    if opts.paths == 0 || opts.paths > rng::MAX_PATHS {
        return usage(SimUsage::Paths {
            paths: opts.paths,
            max: rng::MAX_PATHS,
        });
    }
    if let Some(dt) = opts.dt.filter(|dt| !(*dt > 0.0 && dt.is_finite())) {
        return usage(SimUsage::Dt(dt));
    }
    let map = info.time().period().is_some();
    if let (true, Some(dt)) = (map, opts.dt) {
        return usage(SimUsage::DtDiscrete(dt));
    }
    let hold = opts.hold.unwrap_or(result.step);
    if !(hold > 0.0 && hold.is_finite()) {
        return usage(SimUsage::Hold(hold));
    }
    let bounds = opts
        .safety_bound
        .iter()
        .chain(opts.goal_bounds.iter().flatten());
    if let Some(b) = bounds.copied().find(|b| !(0.0..=1.0).contains(b)) {
        return usage(SimUsage::ProbabilityBound(b));
    }
    if !opts.goal_bounds.is_empty() && opts.goal_bounds.len() != info.goals.len() {
        return usage(SimUsage::GoalBounds {
            bounds: opts.goal_bounds.len(),
            goals: info.goals.len(),
        });
    }
    if !(opts.confidence > 0.0 && opts.confidence < 1.0) {
        return usage(SimUsage::Confidence(opts.confidence));
    }
    let invalid = |m: SimInvalid| Err(SimError::Invalid(m));
    let (n, p, m) = (sys.n(), sys.p(), sys.m());
    if result.states.len() != n || result.steps.is_empty() {
        return invalid(SimInvalid::ResultSize {
            states: result.states.len(),
            steps: result.steps.len(),
            n,
        });
    }
    if result.constants.metric.len() != n * n {
        return invalid(SimInvalid::MetricSize);
    }
    if result.input_plan.is_some() {
        return invalid(SimInvalid::InputPlan);
    }
    if info.input_box.len() != p {
        return invalid(SimInvalid::InputRanges {
            ranges: info.input_box.len(),
            p,
        });
    }
    if let Some(b) = info
        .input_box
        .iter()
        .find(|r| !(r.lo.is_finite() && r.hi.is_finite() && r.lo <= r.hi))
    {
        return invalid(SimInvalid::UnboundedInput(*b));
    }
    let times: Vec<f64> = result.steps.iter().map(|s| s.t).collect();
    let (steps, dt) = dt::choose(sys, info, result, &times, opts.dt)
        .map_err(|dt| SimError::Usage(SimUsage::DtSteps(dt)))?;
    let spans: Vec<Span> = times
        .windows(2)
        .zip(steps)
        .map(|(w, s)| match map {
            true => Span::map(w[0], w[1], s),
            false => Span::new(w[0], w[1], s),
        })
        .collect();
    let per_path: u64 = spans.iter().map(|s| u64::from(s.steps)).sum();
    // Draws per Euler step: m normals (about 1% need a second draw), p inputs at most.
    if per_path.saturating_mul(2 * (m + p + 1) as u64) >= rng::DRAWS_PER_PATH {
        return usage(SimUsage::TooManyDraws {
            steps: per_path,
            channels: m,
        });
    }
    let nominal: Vec<f64> = result
        .steps
        .iter()
        .flat_map(|s| s.nominal().iter().copied())
        .collect();
    if nominal.len() != n * times.len() {
        return invalid(SimInvalid::NominalSize);
    }
    let metric = check::Metric::new(&result.constants.metric, n);
    let sets = regions::SetRegions::new(info, n, result.horizon)
        .map_err(|e| SimError::Invalid(SimInvalid::UnsafeSet(e)))?;
    let tube = match result.guarantee {
        Guarantee::Uniform => Some(check::Tube::new(result, &metric).map_err(SimError::Invalid)?),
        Guarantee::Pointwise => None,
    };
    Ok(Plan {
        sys,
        seed: opts.seed,
        spans,
        dt,
        nominal,
        membership: check::Membership::new(result, &metric),
        tube,
        metric,
        // The paths start where the sets start.
        initial: initial::InitialSampler::new(&result.initial, n)
            .map_err(|e| SimError::Invalid(SimInvalid::Initial(e)))?,
        inputs: inputs::InputSchedule::new(&info.input_box, opts.inputs, hold),
        noise: noise::Noise::new(sys, *times.last().unwrap_or(&0.0), &result.initial_center),
        sets,
        moving: info.has_moving_sets().then_some(info),
        zig: normal::Ziggurat::get(),
        avx2: has_avx2(),
        #[cfg(target_arch = "x86_64")]
        avx512: avx512::available(),
        #[cfg(not(target_arch = "x86_64"))]
        avx512: false,
        times,
    })
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
