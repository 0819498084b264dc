//! The probability of safety (method.md section 8.9): a certified lower bound of the
//! probability that the state avoids every unsafe set on the whole horizon, for every start in
//! the initial set and every input in the input box.
//!
//! A time-uniform PRS at `delta` holds the whole path with probability at least `1 - delta`;
//! when it avoids every unsafe set (margins over every report interval, so in continuous time),
//! `P(safe on [0, T]) >= 1 - delta`. Each `delta` tried is a full sound run (local rates are
//! certified on the tube of that `delta`), chosen by a bisection that does not look at any
//! random outcome, so the bound of every run shown safe holds, and the smallest such `delta`
//! is reported.

use crate::engine::{self, Detail, RunError, Setting};
use crate::model::Guarantee;
use crate::prs::{Prs, Validation, Verdict};
use crate::reach::Reach;

/// The smallest `delta` tried: below it the bound is reported as `1 - 1e-15`.
pub const DELTA_FLOOR: f64 = 1e-15;

/// The largest `delta` tried: a PRS not shown safe at it gives no bound.
pub const DELTA_CEILING: f64 = 0.5;

/// The bisection stops when the smallest `delta` shown safe is within this factor of the
/// largest not shown safe.
pub const RESOLUTION: f64 = 1.02;

/// A certified lower bound of `P(X_t avoids every unsafe set for all t in [0, T])`.
#[derive(Clone, Debug, PartialEq)]
pub struct SafetyProbability {
    /// The horizon `T`.
    pub horizon: f64,
    /// The smallest `delta` tried whose PRS avoids every unsafe set: `P >= 1 - delta`.
    /// `None` when no `delta` up to [`DELTA_CEILING`] was shown safe.
    pub delta: Option<f64>,
    /// The largest `delta` tried whose PRS was not shown safe (the bound cannot be raised past
    /// `1 - not_shown_at` by this analysis), `None` if every one tried was shown safe.
    pub not_shown_at: Option<f64>,
    /// What stops the bound from being higher.
    pub limit: SafetyLimit,
    /// The runs made (each a full analysis).
    pub runs: usize,
    /// Which parts of the run at `delta` (at the analysis' own `delta` when there is no bound)
    /// are proved: the bound is proved only if they all are.
    pub validation: Validation,
}

impl SafetyProbability {
    /// The lower bound `1 - delta` rounded down to a double (`None` without a bound).
    pub fn lower_bound(&self) -> Option<f64> {
        self.delta.map(|d| (1.0 - d).next_down())
    }
}

/// What limits a [`SafetyProbability`].
#[derive(Clone, Debug, PartialEq)]
pub enum SafetyLimit {
    /// The bisection's resolution: `delta` is within [`RESOLUTION`] of a `delta` not shown
    /// safe. A larger probability needs tighter sets (the stochastic radius grows like
    /// `sqrt(log(1 / delta))`).
    Resolution,
    /// Shown safe at [`DELTA_FLOOR`], the smallest `delta` tried.
    Floor,
    /// Not shown safe even at [`DELTA_CEILING`]: the tube at that `delta` first meets unsafe
    /// set `set` (index into the model's unsafe sets) at report time `t`.
    Stochastic {
        /// Report time.
        t: f64,
        /// Unsafe set index.
        set: usize,
    },
    /// The deterministic set alone (no noise) is not shown to avoid unsafe set `set` at report
    /// time `t`: no `delta` helps (a smaller initial set, a known input or a tighter method
    /// may).
    Deterministic {
        /// Report time.
        t: f64,
        /// Unsafe set index.
        set: usize,
    },
    /// A run failed at `delta`, the smallest `delta` tried after the last one shown safe:
    /// treated as not shown safe.
    Failed {
        /// The `delta` whose run failed.
        delta: f64,
        /// Why it failed.
        why: RunError,
    },
}

impl Reach<'_> {
    /// A certified lower bound of the probability of safety on `[0, T]` for every start in the
    /// spec's initial set and every input in its input box (method.md 8.9): the smallest
    /// `delta` in `[1e-15, 0.5]` whose PRS avoids every unsafe set, found by bisection in
    /// `log(delta)` from the analysis' own `delta` to within a factor [`RESOLUTION`].
    ///
    /// Errors: a pointwise guarantee (it bounds each time separately, not the path), a model
    /// without unsafe sets, or a run at the analysis' own `delta` that fails.
    pub fn safety_probability(&self) -> Result<SafetyProbability, RunError> {
        let spec = self.analysis();
        if spec.guarantee != Guarantee::Uniform {
            return Err(RunError::Unsupported(
                Detail::from(
                    "a probability of safety over the horizon needs `guarantee = uniform` (a \
                     pointwise PRS bounds each time separately, not the path)",
                )
                .at_setting(Setting::Guarantee),
            ));
        }
        let sets = &self.model().unsafe_sets;
        if sets.is_empty() {
            return Err(RunError::Unsupported(Detail::from(
                "a probability of safety needs unsafe sets (the model has none)",
            )));
        }
        let mut runs = 0;
        let mut run = |delta: f64| {
            runs += 1;
            self.run_at(delta)
        };
        let own = run(spec.delta)?;
        let own_validation = own.validation.clone();
        let safe = |p: &Prs| p.verdict == Verdict::Safe;
        // (delta, its result) of the smallest delta shown safe, and the largest not shown safe
        // with its result (an error counts as not shown safe).
        let mut best: Option<(f64, Prs)> = None;
        let mut worst: Option<(f64, Result<Prs, RunError>)> = None;
        if safe(&own) {
            best = Some((spec.delta, own));
            let at_floor = run(DELTA_FLOOR);
            match at_floor {
                Ok(p) if safe(&p) => best = Some((DELTA_FLOOR, p)),
                other => worst = Some((DELTA_FLOOR, other)),
            }
        } else {
            let limit = engine::deterministic_limit(sets, &own);
            worst = Some((spec.delta, Ok(own)));
            if limit.is_none() && spec.delta < DELTA_CEILING {
                match run(DELTA_CEILING) {
                    Ok(p) if safe(&p) => best = Some((DELTA_CEILING, p)),
                    other => worst = Some((DELTA_CEILING, other)),
                }
            }
        }
        while let (Some((hi, _)), Some((lo, _))) = (&best, &worst) {
            if *hi <= *lo * RESOLUTION {
                break;
            }
            let mid = (0.5 * (hi.ln() + lo.ln())).exp();
            match run(mid) {
                Ok(p) if safe(&p) => best = Some((mid, p)),
                other => worst = Some((mid, other)),
            }
        }
        let limit = match (&best, &worst) {
            (_, Some((delta, Err(e)))) => SafetyLimit::Failed {
                delta: *delta,
                why: e.clone(),
            },
            (Some(_), None) => SafetyLimit::Floor,
            (Some(_), Some(_)) => SafetyLimit::Resolution,
            (None, Some((_, Ok(p)))) => match engine::deterministic_limit(sets, p) {
                Some((k, set)) => SafetyLimit::Deterministic {
                    t: p.steps[k].t,
                    set,
                },
                None => match p.verdict {
                    Verdict::NotShownSafe { t, set, .. } => SafetyLimit::Stochastic { t, set },
                    // (Not reached: a result in `worst` is not safe.)
                    _ => SafetyLimit::Resolution,
                },
            },
            (None, None) => unreachable!("the run at the analysis' delta is kept"),
        };
        let validation = match &best {
            Some((_, p)) => p.validation.clone(),
            None => own_validation,
        };
        Ok(SafetyProbability {
            horizon: spec.horizon,
            delta: best.as_ref().map(|(d, _)| *d),
            not_shown_at: worst.as_ref().map(|(d, _)| *d),
            limit,
            runs,
            validation,
        })
    }
}
