//! A result whose numbers are not finite is no result: [`check`] finds the first report time
//! where a quantity of the PRS is NaN or infinite and says which quantity, at which time and in
//! which state, as a [`RunError::NonFinite`]. Every run of [`Reach`](crate::Reach) goes through
//! it, so no caller (the API, `reachc run`, `reachc simulate`) ever receives such a set.

use super::{Culprit, Detail, RunError, Setting};
use crate::decimal::time;
use crate::prs::{DetSet, Prs, Step};

/// The first index whose value is not finite.
fn first_bad(v: &[f64]) -> Option<usize> {
    v.iter().position(|x| !x.is_finite())
}

/// What is not finite in the deterministic set, naming the state (`None` when it is finite).
fn det_bad(det: &DetSet, states: &[String]) -> Option<String> {
    let state = |i: usize| states.get(i).map_or_else(|| format!("#{i}"), Clone::clone);
    let (kind, radius) = match det {
        DetSet::Ball { .. } => ("the deterministic ball", "radius R_t"),
        DetSet::Box { .. } => ("the deterministic box", "P-radius"),
        DetSet::Parallelotope { .. } => ("the deterministic parallelotope", "P-radius"),
        DetSet::Zonotope { .. } => ("the first-order zonotope", "P-radius"),
    };
    if let Some(i) = first_bad(det.center()) {
        return Some(format!(
            "{kind}'s centre in state `{}` is {}",
            state(i),
            det.center()[i]
        ));
    }
    if !det.radius().is_finite() {
        return Some(format!("{kind}'s {radius} is {}", det.radius()));
    }
    if let Some((lo, hi)) = det.box_hull() {
        if let Some(i) = first_bad(lo).or_else(|| first_bad(hi)) {
            return Some(format!(
                "{kind}'s hull in state `{}` is [{}, {}]",
                state(i),
                lo[i],
                hi[i]
            ));
        }
    }
    if !det.ball_added().is_finite() {
        return Some(format!("{kind}'s remainder is {}", det.ball_added()));
    }
    if let Some((lo, hi)) = det.corners() {
        if let Some(i) = first_bad(lo).or_else(|| first_bad(hi)) {
            return Some(format!(
                "{kind}'s bounds in coordinate {i} (y = T x) are [{}, {}]",
                lo[i], hi[i]
            ));
        }
    }
    None
}

/// What is not finite at this report time (`None` when everything is).
fn step_bad(st: &Step, states: &[String]) -> Option<String> {
    if !st.r_t.is_finite() {
        return Some(if st.psi.is_finite() {
            format!(
                "the stochastic radius r_t = {} (Psi_t = {:e}) overflowed",
                st.r_t, st.psi
            )
        } else {
            format!(
                "the stochastic radius r_t = {}: Psi_t overflowed (c = {}, sigma = {}: the noise \
                 grows faster than the contraction damps it; a shorter horizon or less noise may \
                 help)",
                st.r_t, st.c, st.sigma
            )
        });
    }
    if let Some(why) = det_bad(&st.det, states) {
        return Some(format!(
            "{why} (the deterministic reachable set grew without bound)"
        ));
    }
    let span = &st.span;
    if let Some(i) = first_bad(&span.lo).or_else(|| first_bad(&span.hi)) {
        let state = states.get(i).map_or_else(|| format!("#{i}"), Clone::clone);
        return Some(format!(
            "the span over the report interval in state `{state}` is [{}, {}]",
            span.lo[i], span.hi[i]
        ));
    }
    [
        ("the radius of the PRS", st.prs_radius),
        ("the span's radius over the report interval", span.radius),
        ("the pointwise radius r_pointwise", st.r_pointwise),
    ]
    .into_iter()
    .find(|(_, v)| !v.is_finite())
    .map(|(what, v)| format!("{what} is {v}"))
}

/// `Ok` when every number of the PRS at every report time is finite; otherwise a
/// [`RunError::NonFinite`] naming the first report time where one is not, the quantity and,
/// where it has one, the state; it points at the horizon.
pub(crate) fn check(prs: &Prs) -> Result<(), RunError> {
    prs.steps
        .iter()
        .find_map(|st| step_bad(st, &prs.states).map(|why| (st.t, why)))
        .map_or(Ok(()), |(t, why)| {
            // A shorter horizon stops before the first such time.
            Err(RunError::NonFinite(Detail {
                message: format!("the PRS is not finite from t = {} on: {why}", time(t)),
                culprit: Some(Culprit::Setting(Setting::Horizon)),
            }))
        })
}
