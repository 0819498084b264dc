//! The probability of safety in words and in the result's JSON (`reachc run --probability`,
//! method.md 8.9).

use super::schema::{
    GoalLimitJson, GoalMissJson, GoalProbabilityJson, LimitJson, ProbabilityJson, SearchLimitJson,
};
use super::{count, time};
use reachc_core::model::{GoalSet, UnsafeSet};
use reachc_core::probability::{GoalLimit, GoalProbability, SafetyLimit, SafetyProbability};
use reachc_core::prs::{GoalMiss, Prs, Validation};

impl ProbabilityJson {
    pub(super) fn of(prs: &Prs, p: &SafetyProbability) -> ProbabilityJson {
        let name = |set: usize| prs.unsafe_sets()[set].name.clone();
        ProbabilityJson {
            horizon: p.horizon,
            lower_bound: p.lower_bound(),
            delta: p.delta,
            not_shown_at: p.not_shown_at,
            limit: match &p.limit {
                SafetyLimit::Resolution => LimitJson::Resolution,
                SafetyLimit::Floor => LimitJson::Floor,
                SafetyLimit::Stochastic { t, set } => LimitJson::Stochastic {
                    t: *t,
                    set: name(*set),
                },
                SafetyLimit::Deterministic { t, set } => LimitJson::Deterministic {
                    t: *t,
                    set: name(*set),
                },
                SafetyLimit::Failed { delta, why } => LimitJson::Failed {
                    delta: *delta,
                    why: why.to_string(),
                },
            },
            runs: p.runs,
            proved: p.validation.not_validated.is_empty(),
            conditional_on_domain: p.validation.conditional_on_domain,
        }
    }
}

/// The certified probabilities of a run (`reachc run --probability`): of safety, and of
/// reaching each goal (method.md 8.9, 8.13).
#[derive(Clone, Copy, Debug, Default)]
pub struct Probabilities<'a> {
    /// The probability of safety, where computed.
    pub safety: Option<&'a SafetyProbability>,
    /// The probability of reaching each goal, where computed.
    pub goals: &'a [GoalProbability],
}

impl GoalProbabilityJson {
    pub(super) fn of(prs: &Prs, p: &GoalProbability) -> GoalProbabilityJson {
        GoalProbabilityJson {
            lower_bound: p.lower_bound(),
            delta: p.delta,
            t: p.t,
            not_shown_at: p.not_shown_at,
            limit: match &p.limit {
                GoalLimit::Resolution => GoalLimitJson::Search(SearchLimitJson::Resolution),
                GoalLimit::Floor => GoalLimitJson::Search(SearchLimitJson::Floor),
                GoalLimit::NotShown(miss) => GoalLimitJson::Miss(GoalMissJson::of(prs, miss)),
                GoalLimit::Failed { delta, why } => {
                    GoalLimitJson::Search(SearchLimitJson::Failed {
                        delta: *delta,
                        why: why.to_string(),
                    })
                }
            },
            runs: p.runs,
            proved: p.validation.not_validated.is_empty(),
            conditional_on_domain: p.validation.conditional_on_domain,
        }
    }
}

/// The summary's line for the probability of reaching goal `p.goal` of `goals` (`sets`: the
/// model's unsafe sets).
pub fn goal_line(
    goals: &[GoalSet],
    sets: &[UnsafeSet],
    horizon: f64,
    p: &GoalProbability,
) -> String {
    let g = &goals[p.goal];
    let w = g.window.map_or((0.0, horizon), |w| (w.lo, w.hi));
    let (lo, hi) = (time(w.0), time(w.1));
    let event = if g.stay {
        format!(
            "reach `{}` within [{lo}, {hi}] and stay until {}",
            g.name,
            time(horizon)
        )
    } else {
        format!("reach `{}` within [{lo}, {hi}]", g.name)
    };
    let event = if sets.is_empty() {
        event
    } else {
        format!("{event}, avoiding every unsafe set until then")
    };
    let s = match p.delta {
        Some(delta) => format!(
            "P({event}) >= {} for every start in the initial set and every input",
            lower_bound_text(delta)
        ),
        None => format!("P({event}): no bound"),
    };
    let limit = match &p.limit {
        GoalLimit::Resolution => format!(
            "to the bisection's resolution: not shown at delta = {:.3e}",
            p.not_shown_at.unwrap_or(f64::NAN)
        ),
        GoalLimit::Floor => "shown at the smallest delta tried".to_string(),
        GoalLimit::NotShown(miss) => {
            let at = p.not_shown_at.unwrap_or(f64::NAN);
            match miss {
                GoalMiss::NoReportTime => "no report time lies in the window".to_string(),
                GoalMiss::Unsafe { t, set } => format!(
                    "the PRS at delta = {at} meets `{}` at t = {} first",
                    sets.get(*set).map_or("?", |u| &u.name),
                    time(*t)
                ),
                GoalMiss::NotInside { t, margin } => format!(
                    "the PRS at delta = {at} is not inside the goal in the window (largest \
                     margin {margin:.3e} at t = {})",
                    time(*t)
                ),
                GoalMiss::Leaves { t } => format!(
                    "the PRS at delta = {at} is not shown to stay in the goal (the interval \
                     ending at t = {})",
                    time(*t)
                ),
            }
        }
        GoalLimit::Failed { delta, why } => {
            format!("the run at delta = {delta:.3e} failed: {why}")
        }
    };
    s + &qualifiers(p.runs, &limit, &p.validation)
}

/// What every bound's line ends with: the runs, what limits it, and whether it is proved and
/// unconditional.
fn qualifiers(runs: usize, limit: &str, validation: &Validation) -> String {
    let mut s = format!(" ({}; {limit})", count(runs as u64, "run"));
    if !validation.not_validated.is_empty() {
        s.push_str(" [NOT proved: the runs have \"not validated\" parts]");
    }
    if validation.conditional_on_domain {
        s.push_str(" [while the state stays in the domain]");
    }
    s
}

/// `delta` rounded up to three significant digits, as `(q, e)` with `q 10^e >= delta` and
/// `q` in `[100, 1000)` (so that `1 - ` it stays a lower bound).
fn delta_up(delta: f64) -> (u64, i32) {
    let e = delta.log10().floor() as i32 - 2;
    let scale = 10f64.powi(e);
    let q = (delta / scale).ceil();
    // (The quotient is rounded: one more unit where the product fell below.)
    let q = if q * scale < delta { q + 1.0 } else { q } as u64;
    if q >= 1000 {
        (q.div_ceil(10), e + 1)
    } else {
        (q, e)
    }
}

/// `1 - delta` rounded down to three significant digits of `delta`, as an exact decimal and as
/// `1 - d`: "0.99596 (1 - 4.04e-3)"; only the latter below `1e-9`.
pub fn lower_bound_text(delta: f64) -> String {
    let (q, e) = delta_up(delta);
    let short = format!("1 - {:.2}e{}", q as f64 / 100.0, e + 2);
    if e + 2 < -9 {
        return short;
    }
    // 1 - q 10^e = (10^-e - q) 10^e exactly, with -e digits after the point.
    let digits = (-e) as u32;
    let rest = 10u64.pow(digits) - q;
    format!("0.{rest:0>width$} ({short})", width = digits as usize)
}

/// The summary's line where the probability of safety could not be computed, and why.
pub fn not_computed(why: &dyn std::fmt::Display) -> String {
    format!("probability of safety: not computed: {why}")
}

/// The summary's line where the probability of reaching `goal` could not be computed, and why.
pub fn goal_not_computed(goal: &GoalSet, why: &dyn std::fmt::Display) -> String {
    format!(
        "probability of reaching `{}`: not computed: {why}",
        goal.name
    )
}

/// The summary's line: the bound and what limits it (`sets`: the model's unsafe sets).
pub fn line(sets: &[UnsafeSet], p: &SafetyProbability) -> String {
    let name = |set: usize| &sets[set].name;
    let s = match p.delta {
        Some(delta) => format!(
            "P(safe on [0, {}]) >= {} for every start in the initial set and every input",
            p.horizon,
            lower_bound_text(delta)
        ),
        None => format!("P(safe on [0, {}]): no bound", p.horizon),
    };
    let limit = match &p.limit {
        SafetyLimit::Resolution => format!(
            "to the bisection's resolution: not shown safe at delta = {:.3e}",
            p.not_shown_at.unwrap_or(f64::NAN)
        ),
        SafetyLimit::Floor => "shown safe at the smallest delta tried".to_string(),
        SafetyLimit::Stochastic { t, set } => format!(
            "the PRS at delta = {} still meets `{}` at t = {}: the stochastic radius is too \
             large",
            p.not_shown_at.unwrap_or(f64::NAN),
            name(*set),
            time(*t)
        ),
        SafetyLimit::Deterministic { t, set } => format!(
            "the deterministic set alone is not shown to avoid `{}` at t = {}, so no delta \
             helps (a smaller initial set, a known input or a tighter method may)",
            name(*set),
            time(*t)
        ),
        SafetyLimit::Failed { delta, why } => {
            format!("the run at delta = {delta:.3e} failed: {why}")
        }
    };
    s + &qualifiers(p.runs, &limit, &p.validation)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lower_bounds_round_down() {
        assert_eq!(lower_bound_text(4.0315e-3), "0.99596 (1 - 4.04e-3)");
        assert_eq!(lower_bound_text(0.5), "0.500 (1 - 5.00e-1)");
        assert_eq!(lower_bound_text(1e-3), "0.99900 (1 - 1.00e-3)");
        assert_eq!(lower_bound_text(1e-15), "1 - 1.00e-15");
        assert_eq!(lower_bound_text(0.0999999), "0.900 (1 - 1.00e-1)");
        for d in [1e-12, 3.3e-7, 0.123456, 0.0999999, 0.5] {
            let (q, e) = delta_up(d);
            let up = q as f64 * 10f64.powi(e);
            assert!(up >= d && up <= d * 1.011, "{d} {up}");
        }
    }
}
