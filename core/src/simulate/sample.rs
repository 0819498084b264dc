//! A few recorded sample paths, for plots: the Euler-Maruyama paths of [`simulate`](super::simulate)
//! (same random streams, same initial states, inputs and noise, same steps), with the state
//! kept at every report time ([`result_paths`]; [`sample_paths`] without a result) or after
//! every Euler-Maruyama step ([`result_substeps`]) instead of being reduced to statistics.

use super::increments::Increments;
use super::initial::InitialSampler;
use super::inputs::InputSchedule;
use super::noise::Noise;
use super::normal::Ziggurat;
use super::rng::{PathRng, DRAWS_PER_PATH, MAX_PATHS};
use super::{dt, Options, SimError, SimInvalid, SimUsage};
use crate::model::ModelInfo;
use crate::prs::Prs;
use crate::system::System;

/// Most paths the functions of this module record: they are all kept in memory.
pub const MAX_SAMPLE_PATHS: u64 = 100_000;

/// Most state coordinates [`result_substeps`] records in all (1 GiB).
const MAX_SUBSTEP_VALUES: u64 = 1 << 27;

/// Sample paths recorded after every Euler-Maruyama step (see [`result_substeps`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Substeps {
    /// Per report interval `(t_{k-1}, t_k]` (index `k - 1`), its number of Euler-Maruyama
    /// steps, as [`simulate`](super::simulate) splits it.
    pub per_interval: Vec<u32>,
    /// Per path, the initial state and then the state after each Euler-Maruyama step, flat
    /// (`n` values each): `1 + sum(per_interval)` states; the last state of interval `k` is
    /// the state at `t_k`.
    pub paths: Vec<Vec<f64>>,
}

/// Simulates `opts.paths` sample paths of `sys` over the report times `times` (increasing,
/// starting at 0) and returns, per path, its states at those times, flat: the state at
/// `times[k]` is `path[k * n..(k + 1) * n]`. A path whose state became non-finite keeps the
/// non-finite values.
///
/// The paths of [`simulate`](super::simulate)'s random streams (`opts.seed`, `opts.inputs`,
/// `opts.hold`), with equal Euler-Maruyama steps of at most `opts.dt` (default: the largest
/// interval between report times; `hold` defaults to it too) and the constant diffusion
/// evaluated at `center` (`None`: path 0's initial state). Without a result there is no rule
/// for the step: [`result_paths`] gives the paths `simulate` checks. `opts.confidence` and
/// `opts.threads` are not used: the paths run on the calling thread.
pub fn sample_paths<S: System + ?Sized>(
    sys: &S,
    info: &ModelInfo,
    times: &[f64],
    center: Option<&[f64]>,
    opts: &Options,
) -> Result<Vec<Vec<f64>>, SimError> {
    check_times(times)?;
    let step = times.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
    let dt = opts.dt.unwrap_or(step);
    if times.len() > 1 && !(dt > 0.0 && dt.is_finite()) {
        return Err(SimError::Usage(SimUsage::Dt(dt)));
    }
    // (A discrete-time model takes one step per step of its map.)
    let dt = info.time().period().unwrap_or(dt);
    let substeps = times
        .windows(2)
        .map(|w| ((w[1] - w[0]) / dt * (1.0 - 1e-12)).ceil().max(1.0))
        .map(|s| if s <= 1e9 { s as u32 } else { u32::MAX })
        .collect();
    let what = Recording {
        times,
        center,
        opts,
        substeps,
        every_step: false,
    };
    record(sys, info, what).map(|s| s.paths)
}

/// Path `p` of [`simulate`](super::simulate) of `result` with the same options, recorded at
/// the result's report times (flat, as [`sample_paths`]): the same random streams, the same
/// Euler-Maruyama steps (the rule [`DT_RULE`](super::DT_RULE), or `opts.dt`), the constant diffusion
/// at the result's `initial_center`.
pub fn result_paths<S: System + ?Sized>(
    sys: &S,
    info: &ModelInfo,
    result: &Prs,
    opts: &Options,
) -> Result<Vec<Vec<f64>>, SimError> {
    of_result(sys, info, result, opts, false).map(|s| s.paths)
}

/// [`result_paths`] with the state kept after every Euler-Maruyama step: what
/// [`simulate`](super::simulate) checks against the tube of a time-uniform result, to be
/// checked again independently (or plotted between report times). At most
/// [`MAX_SAMPLE_PATHS`] paths and `2^27` recorded values in all.
pub fn result_substeps<S: System + ?Sized>(
    sys: &S,
    info: &ModelInfo,
    result: &Prs,
    opts: &Options,
) -> Result<Substeps, SimError> {
    of_result(sys, info, result, opts, true)
}

/// The paths of `simulate(result)`, at its report times or after every step (`every_step`).
fn of_result<S: System + ?Sized>(
    sys: &S,
    info: &ModelInfo,
    result: &Prs,
    opts: &Options,
    every_step: bool,
) -> Result<Substeps, SimError> {
    let times: Vec<f64> = result.steps.iter().map(|s| s.t).collect();
    check_times(&times)?;
    let (substeps, _) = dt::choose(sys, info, result, &times, opts.dt)
        .map_err(|dt| SimError::Usage(SimUsage::DtSteps(dt)))?;
    let center = Some(&result.initial_center[..]);
    let what = Recording {
        times: &times,
        center,
        opts,
        substeps,
        every_step,
    };
    record(sys, info, what)
}

/// Report times start at 0 and increase.
fn check_times(times: &[f64]) -> Result<(), SimError> {
    if times.first() != Some(&0.0)
        || times
            .windows(2)
            .any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
    {
        return Err(SimError::Invalid(SimInvalid::Times));
    }
    Ok(())
}

/// What to record: the paths over `times`, report interval `k` split into `substeps[k]` equal
/// steps, with the states of every step (`every_step`) or of the report times, the constant
/// diffusion evaluated at `center`.
struct Recording<'a> {
    times: &'a [f64],
    center: Option<&'a [f64]>,
    opts: &'a Options,
    substeps: Vec<u32>,
    every_step: bool,
}

/// The paths of `what` (Euler-Maruyama steps; a discrete-time model's map stepped as its
/// increments with `h = 1`).
fn record<S: System + ?Sized>(
    sys: &S,
    info: &ModelInfo,
    what: Recording,
) -> Result<Substeps, SimError> {
    match info.time().period() {
        Some(_) => record_in(&Increments(sys), info, what, true),
        None => record_in(sys, info, what, false),
    }
}

/// [`record`] with the system the loop steps (`map`: a discrete-time model's increments).
fn record_in<S: System + ?Sized>(
    sys: &S,
    info: &ModelInfo,
    what: Recording,
    map: bool,
) -> Result<Substeps, SimError> {
    let Recording {
        times,
        center,
        opts,
        substeps,
        every_step,
    } = what;
    let usage = |m: SimUsage| Err(SimError::Usage(m));
    let (n, p, m) = (sys.n(), sys.p(), sys.m());
    if opts.paths > MAX_SAMPLE_PATHS.min(MAX_PATHS) {
        return usage(SimUsage::RecordedPaths {
            paths: opts.paths,
            max: MAX_SAMPLE_PATHS,
        });
    }
    let step = times.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
    let hold = opts.hold.unwrap_or(step);
    if times.len() > 1 && !(hold > 0.0 && hold.is_finite()) {
        return usage(SimUsage::Hold(hold));
    }
    if info.input_box.len() != p
        || info
            .input_box
            .iter()
            .any(|r| !(r.lo.is_finite() && r.hi.is_finite() && r.lo <= r.hi))
    {
        return Err(SimError::Invalid(SimInvalid::InputBox));
    }
    let per_path: u64 = substeps.iter().map(|&s| u64::from(s)).sum();
    if per_path.saturating_mul(2 * (m + p + 1) as u64) >= DRAWS_PER_PATH {
        return usage(SimUsage::TooManyRecordedSteps(per_path));
    }
    let kept = if every_step {
        per_path + 1
    } else {
        times.len() as u64
    };
    if every_step && kept.saturating_mul(n as u64).saturating_mul(opts.paths) > MAX_SUBSTEP_VALUES {
        return usage(SimUsage::TooManyValues {
            paths: opts.paths,
            kept,
            n,
        });
    }
    let initial = InitialSampler::new(&info.initial, n)
        .map_err(|e| SimError::Invalid(SimInvalid::Initial(e)))?;
    let inputs = InputSchedule::new(&info.input_box, opts.inputs, hold);
    let zig = Ziggurat::get();
    let (mut x, mut f, mut u) = (vec![0.0; n], vec![0.0; n], vec![0.0; p]);
    let mut scratch = vec![0.0; initial.scratch_len()];
    let mut noise = None;
    let (mut z, mut g) = (vec![0.0; m], Vec::new());
    let mut paths = Vec::with_capacity(usize::try_from(opts.paths).unwrap_or(0));
    for path in 0..opts.paths {
        let mut rng = PathRng::new(opts.seed, path);
        initial.sample(&mut rng, zig, &mut x, &mut scratch);
        let noise = noise.get_or_insert_with(|| {
            let nz = Noise::new(sys, *times.last().unwrap_or(&0.0), center.unwrap_or(&x));
            if nz.needs_matrix() {
                g = vec![0.0; n * m];
            }
            nz
        });
        let mut record = Vec::with_capacity(kept as usize * n);
        record.extend_from_slice(&x);
        let mut interval = None;
        for (k, &nsub) in substeps.iter().enumerate() {
            let (t0, t1) = (times[k], times[k + 1]);
            let dt = (t1 - t0) / f64::from(nsub);
            let (h, sqrt_h) = if map { (1.0, 1.0) } else { (dt, dt.sqrt()) };
            for i in 0..nsub {
                let t = t0 + f64::from(i) * dt;
                // The draws in `simulate`'s order: inputs, then the normals in channel order.
                if p > 0 {
                    inputs.update(t, &mut interval, &mut rng, &mut u);
                }
                for zj in &mut z {
                    *zj = zig.sample(&mut rng);
                }
                sys.drift(&x, &u, t, &mut f);
                noise.apply(sys, &mut x, &f, t, h, sqrt_h, &mut z, &mut g);
                if every_step {
                    record.extend_from_slice(&x);
                }
            }
            if !every_step {
                record.extend_from_slice(&x);
            }
        }
        paths.push(record);
    }
    Ok(Substeps {
        per_interval: substeps,
        paths,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ModelInfo;
    use crate::test_support::models::model;
    use crate::test_support::systems::Linear;

    /// `dx = -x dt + 0.5 dW`; input-free.
    const OU: Linear = Linear {
        n: 1,
        a: -1.0,
        b: 0.0,
        s: 0.5,
    };

    /// [`OU`] with x(0) uniform in [1, 2].
    fn info() -> ModelInfo {
        model("ou", &["x"], &["w"], &[(1.0, 2.0)])
    }

    #[test]
    fn paths_start_in_the_initial_set_and_have_the_ou_statistics() {
        let times: Vec<f64> = (0..=10).map(|k| 0.1 * f64::from(k)).collect();
        let opts = Options {
            paths: 4000,
            dt: Some(0.01),
            ..Options::default()
        };
        let paths = sample_paths(&OU, &info(), &times, None, &opts).unwrap();
        assert_eq!(paths.len(), 4000);
        assert!(paths.iter().all(|p| p.len() == 11));
        assert!(paths.iter().all(|p| (1.0..=2.0).contains(&p[0])));
        // X_1 = e^-1 X_0 + N(0, 0.25 (1 - e^-2) / 2): mean 1.5 e^-1 ~ 0.552, variance
        // e^-2 / 12 + 0.108 ~ 0.1194 (Euler with h = 0.01 is within 1% of both).
        let end: Vec<f64> = paths.iter().map(|p| p[10]).collect();
        let mean = end.iter().sum::<f64>() / 4000.0;
        let var = end.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 3999.0;
        assert!((mean - 0.552).abs() < 0.02, "{mean}");
        assert!((var - 0.1194).abs() < 0.012, "{var}");
    }

    #[test]
    fn the_same_seed_gives_the_same_paths_and_bad_times_are_refused() {
        let times = [0.0, 0.5, 1.0];
        let opts = Options {
            paths: 3,
            seed: 9,
            ..Options::default()
        };
        let a = sample_paths(&OU, &info(), &times, Some(&[1.5]), &opts).unwrap();
        let b = sample_paths(&OU, &info(), &times, None, &opts).unwrap();
        assert_eq!(a, b);
        assert_ne!(a[0], a[1]);
        assert!(sample_paths(&OU, &info(), &[0.5, 1.0], None, &opts).is_err());
        assert!(sample_paths(&OU, &info(), &[0.0, 1.0, 1.0], None, &opts).is_err());
    }
}
