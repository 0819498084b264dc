//! Per-step contraction rates `c_k` of [`Rate::Empirical`](crate::model::Rate::Empirical)
//! analyses: `c_k` is the rate on the report step `(t_(k-1), t_k]`, and `R_t` and `Psi_t`
//! follow their per-step recursions with it (Proposition 2 and eq. Psi with piecewise-constant
//! rates).

use super::{Detail, Problem, Run, RunError, Setting};
use crate::model::ModelInfo;
use crate::simulate::{self, InputMode};

/// Seed of the empirical estimate's sample paths: fixed (the result is reproducible) and not
/// `reachc simulate`'s default 0, so a coverage check runs on paths the estimate never saw.
pub(crate) const EMPIRICAL_SEED: u64 = 0x6361_6c69_6272_6174;

/// Estimated per-step rates from `paths` sample paths of the SDE (the spec's initial set,
/// random piecewise-constant inputs, seed [`EMPIRICAL_SEED`]): `c_k` is the largest one-sided
/// Lipschitz quotient
/// `(X - x*)' P (f(X, u_c, t) - f(x*, u_c, t)) / |X - x*|_P^2` over the sampled states `X` at
/// `t_(k-1)` and `t_k`, with `x*` the nominal and `u_c` the input box's centre: the quantity the
/// proof of Theorem 1 bounds by `c` along the pair `(X_t, x*_t)`. An estimate, not a bound.
pub(crate) fn empirical(
    run: &Run,
    metric: &[f64],
    grid: &[f64],
    traj: &[Vec<f64>],
    inputs: &[Vec<f64>],
    paths: u64,
) -> Result<Vec<f64>, RunError> {
    let sys = run.sys;
    let n = sys.n();
    let opts = simulate::Options {
        paths,
        seed: EMPIRICAL_SEED,
        inputs: InputMode::Random,
        ..simulate::Options::default()
    };
    // The paths start in the run's initial set.
    let info = ModelInfo {
        initial: run.initial.clone(),
        ..run.info.clone()
    };
    let sampled = simulate::sample_paths(sys, &info, grid, Some(&traj[0]), &opts).map_err(|e| {
        RunError::Invalid(
            Detail::from(Problem::EmpiricalSampling(Box::new(e))).at_setting(Setting::Rate),
        )
    })?;
    // Per report time, the pooled quotient over the paths.
    let mut at = vec![f64::NEG_INFINITY; grid.len()];
    let (mut fx, mut fn_) = (vec![0.0; n], vec![0.0; n]);
    let mut d = vec![0.0; n];
    for (k, ((&t, nominal), u_center)) in grid.iter().zip(traj).zip(inputs).enumerate() {
        sys.drift(nominal, u_center, t, &mut fn_);
        let (mut sum_num, mut sum_den) = (0.0, 0.0);
        for path in &sampled {
            let x = &path[k * n..(k + 1) * n];
            if x.iter().any(|v| !v.is_finite()) {
                return Err(RunError::NonFinite(
                    Detail::from(Problem::EmpiricalPathNotFinite(t)).at_setting(Setting::Rate),
                ));
            }
            sys.drift(x, u_center, t, &mut fx);
            for i in 0..n {
                d[i] = x[i] - nominal[i];
            }
            let (mut num, mut den) = (0.0, 0.0);
            for i in 0..n {
                for j in 0..n {
                    num += d[i] * metric[i * n + j] * (fx[j] - fn_[j]);
                    den += d[i] * metric[i * n + j] * d[j];
                }
            }
            sum_num += num;
            sum_den += den;
        }
        if sum_den > 0.0 {
            at[k] = sum_num / sum_den;
        }
    }
    // The rate on a step covers both of its ends; a time where every sample sat on the nominal
    // (the point initial state at t = 0) takes its neighbour's.
    let mut rates: Vec<f64> = (0..grid.len())
        .map(|k| at[k].max(if k > 0 { at[k - 1] } else { at[k] }))
        .collect();
    if rates.len() > 1 && rates[0] == f64::NEG_INFINITY {
        rates[0] = rates[1];
    }
    if let Some(k) = rates.iter().position(|c| !c.is_finite()) {
        return Err(RunError::NonFinite(
            Detail::from(Problem::EmpiricalRateNotFinite(grid[k])).at_setting(Setting::Rate),
        ));
    }
    Ok(rates)
}
