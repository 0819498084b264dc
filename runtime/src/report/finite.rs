//! A result whose sets are not finite is no result: [`not_finite`] says where and why, so that
//! `run` and `simulate` report it as an error of the analysis instead of writing `null`/`inf`.

use reachc_core::prs::{DetSet, Step};
use reachc_core::Prs;

use super::time;

fn all(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Whether the deterministic set at this step is finite.
fn det_finite(det: &DetSet) -> bool {
    all(det.center())
        && det.radius().is_finite()
        && det.corners().is_none_or(|(lo, hi)| all(lo) && all(hi))
        && det.box_hull().is_none_or(|(lo, hi)| all(lo) && all(hi))
}

/// Whether every number describing the PRS at this step is finite.
fn step_finite(st: &Step) -> bool {
    det_finite(&st.det)
        && st.r_t.is_finite()
        && st.prs_radius.is_finite()
        && all(&st.span.lo)
        && all(&st.span.hi)
        && st.span.radius.is_finite()
}

/// Why the PRS at `st` is not finite, as far as the numbers tell.
fn why(st: &Step) -> String {
    let det = match st.det {
        DetSet::Ball { .. } => "the deterministic set's radius R_t",
        DetSet::Box { .. } | DetSet::Parallelotope { .. } => "the deterministic box",
    };
    if !st.r_t.is_finite() && !st.psi.is_finite() {
        format!(
            "r_t = {}: Psi_t overflowed (c = {}, sigma = {}: the noise grows faster than the \
             contraction damps it; a shorter horizon or less noise may help)",
            st.r_t, st.c, st.sigma
        )
    } else if !st.r_t.is_finite() {
        format!(
            "r_t = {} (Psi_t = {:e}): the stochastic radius overflowed",
            st.r_t, st.psi
        )
    } else if !det_finite(&st.det) {
        format!("{det} is not finite (the deterministic reachable set grew without bound)")
    } else {
        "its bounds are not finite".to_string()
    }
}

/// `None` when the PRS is finite at every report time; otherwise a sentence naming the first
/// report time where it is not, and why if the numbers tell.
pub fn not_finite(prs: &Prs) -> Option<String> {
    let st = prs.steps.iter().find(|st| !step_finite(st))?;
    Some(format!(
        "the PRS is not finite from t = {} on ({}); no result is written",
        time(st.t),
        why(st)
    ))
}
