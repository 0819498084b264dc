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

use crate::engine::{self, Detail, Problem, RunError, Setting};
use crate::model::Guarantee;
use crate::prs::{GoalMiss, GoalOutcome, GoalVerdict, Prs, Validation, Verdict};
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

/// A bisection in `log(delta)` over full runs, for a question each run answers yes or no.
struct Search {
    /// The smallest `delta` shown, with its result.
    best: Option<(f64, Prs)>,
    /// The largest `delta` not shown, with its result (an error counts as not shown).
    worst: Option<(f64, Result<Prs, RunError>)>,
    /// The runs made.
    runs: usize,
    /// The validation of the run at the analysis' own `delta`.
    own_validation: Validation,
}

impl Reach<'_> {
    /// The smallest `delta` in `[DELTA_FLOOR, DELTA_CEILING]` whose run is `shown`, to within
    /// [`RESOLUTION`] of a `delta` that is not: from the analysis' own `delta`, then the floor
    /// (if shown there) or the ceiling (if not, and `hopeful` of that run), then bisection.
    /// Errors: the run at the analysis' own `delta` fails.
    fn bisect(
        &self,
        shown: impl Fn(&Prs) -> bool,
        hopeful: impl Fn(&Prs) -> bool,
    ) -> Result<Search, RunError> {
        let spec = self.analysis();
        let mut runs = 0;
        let mut run = |delta: f64| {
            runs += 1;
            self.run_at(delta)
        };
        let own = run(spec.delta)?;
        let own_validation = own.validation.clone();
        let mut best: Option<(f64, Prs)> = None;
        let mut worst: Option<(f64, Result<Prs, RunError>)> = None;
        if shown(&own) {
            best = Some((spec.delta, own));
            match run(DELTA_FLOOR) {
                Ok(p) if shown(&p) => best = Some((DELTA_FLOOR, p)),
                other => worst = Some((DELTA_FLOOR, other)),
            }
        } else {
            let try_ceiling = hopeful(&own) && spec.delta < DELTA_CEILING;
            worst = Some((spec.delta, Ok(own)));
            if try_ceiling {
                match run(DELTA_CEILING) {
                    Ok(p) if shown(&p) => best = Some((DELTA_CEILING, p)),
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
                Ok(p) if shown(&p) => best = Some((mid, p)),
                other => worst = Some((mid, other)),
            }
        }
        Ok(Search {
            best,
            worst,
            runs,
            own_validation,
        })
    }

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
                Detail::from(Problem::SafetyNeedsUniform).at_setting(Setting::Guarantee),
            ));
        }
        let sets = &self.model().unsafe_sets;
        if sets.is_empty() {
            return Err(RunError::Unsupported(Problem::SafetyNeedsUnsafeSets.into()));
        }
        let search = self.bisect(
            |p| p.verdict == Verdict::Safe,
            |own| engine::deterministic_limit(sets, own).is_none(),
        )?;
        let (best, worst, runs, own_validation) = (
            search.best,
            search.worst,
            search.runs,
            search.own_validation,
        );
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

/// A certified lower bound of the probability of reaching a goal set (method.md 8.13): of
/// entering it at some time of its window, having avoided every unsafe set until then (with
/// `stay`: and of remaining in it, away from the unsafe sets, until the window ends), for
/// every start in the initial set and every input in the input box.
#[derive(Clone, Debug, PartialEq)]
pub struct GoalProbability {
    /// The goal (index into the model's goal sets).
    pub goal: usize,
    /// The smallest `delta` tried whose PRS shows the goal reached: `P >= 1 - delta`; `None`
    /// when no `delta` up to [`DELTA_CEILING`] does.
    pub delta: Option<f64>,
    /// The first report time at which the goal is shown reached at `delta`.
    pub t: Option<f64>,
    /// The largest `delta` tried whose PRS does not show it, `None` if every one tried does.
    pub not_shown_at: Option<f64>,
    /// What stops the bound from being higher.
    pub limit: GoalLimit,
    /// The runs made (each a full analysis).
    pub runs: usize,
    /// Which parts of the run at `delta` (at the analysis' own `delta` when there is no bound)
    /// are proved: the bound is proved only if they all are.
    pub validation: Validation,
}

impl GoalProbability {
    /// The lower bound `1 - delta` rounded down to a double (`None` without a bound).
    pub fn lower_bound(&self) -> Option<f64> {
        self.delta.map(|d| (1.0 - d).next_down())
    }
}

/// What limits a [`GoalProbability`].
#[derive(Clone, Debug, PartialEq)]
pub enum GoalLimit {
    /// The bisection's resolution (see [`SafetyLimit::Resolution`]).
    Resolution,
    /// Shown at [`DELTA_FLOOR`], the smallest `delta` tried.
    Floor,
    /// Not shown even at the largest `delta` tried (at most [`DELTA_CEILING`]), for this
    /// reason.
    NotShown(GoalMiss),
    /// A run failed at `delta`, the smallest `delta` tried after the last one shown: treated
    /// as not shown.
    Failed {
        /// The `delta` whose run failed.
        delta: f64,
        /// Why it failed.
        why: RunError,
    },
}

impl Reach<'_> {
    /// A certified lower bound of the probability of reaching goal `goal` (an index into the
    /// model's goal sets) as [`GoalProbability`] says, by the same bisection over `delta` as
    /// [`Reach::safety_probability`]: each `delta` a full sound run, the smallest whose
    /// time-uniform PRS shows the goal reached kept.
    ///
    /// Errors: a pointwise guarantee (except for reaching alone, without unsafe sets: a question
    /// about one time), no goal `goal`, or a run at the analysis' own `delta` that fails.
    pub fn goal_probability(&self, goal: usize) -> Result<GoalProbability, RunError> {
        // Reaching alone, with no unsafe set to avoid, is a question about one time.
        let one_time = self
            .model()
            .goals
            .get(goal)
            .is_some_and(|g| !g.stay && self.model().unsafe_sets.is_empty());
        if self.analysis().guarantee != Guarantee::Uniform && !one_time {
            return Err(RunError::Unsupported(
                Detail::from(Problem::GoalNeedsUniform).at_setting(Setting::Guarantee),
            ));
        }
        if goal >= self.model().goals.len() {
            return Err(RunError::Invalid(
                Problem::NoGoal {
                    goal,
                    goals: self.model().goals.len(),
                }
                .into(),
            ));
        }
        let reached = |p: &Prs| p.goals.get(goal).is_some_and(GoalVerdict::reached);
        let search = self.bisect(reached, |_| true)?;
        let limit = match (&search.best, &search.worst) {
            (_, Some((delta, Err(e)))) => GoalLimit::Failed {
                delta: *delta,
                why: e.clone(),
            },
            (Some(_), None) => GoalLimit::Floor,
            (Some(_), Some(_)) => GoalLimit::Resolution,
            (None, Some((_, Ok(p)))) => match p.goals.get(goal).map(|g| &g.outcome) {
                Some(GoalOutcome::NotShown(miss)) => GoalLimit::NotShown(miss.clone()),
                // (Not reached: a result in `worst` does not show the goal reached.)
                _ => GoalLimit::Resolution,
            },
            (None, None) => unreachable!("the run at the analysis' delta is kept"),
        };
        let t = search.best.as_ref().and_then(|(_, p)| {
            p.goals.get(goal).and_then(|g| match g.outcome {
                GoalOutcome::Reached { t, .. } => Some(t),
                _ => None,
            })
        });
        Ok(GoalProbability {
            goal,
            delta: search.best.as_ref().map(|(d, _)| *d),
            t,
            not_shown_at: search.worst.as_ref().map(|(d, _)| *d),
            limit,
            runs: search.runs,
            validation: match &search.best {
                Some((_, p)) => p.validation.clone(),
                None => search.own_validation,
            },
        })
    }
}
