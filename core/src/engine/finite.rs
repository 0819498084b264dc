//! A result whose numbers are not finite is no result: [`check`] finds the first report time
//! where a quantity of the PRS is NaN or infinite and says which quantity, at which time and in
//! which state, as a [`RunError::NonFinite`]. Every run of [`Reach`](crate::Reach) goes through
//! it, so no caller (the API, `reachc run`, `reachc simulate`) ever receives such a set.

use super::{Detail, NonFiniteQuantity, Problem, RunError, SetKind, SetPart, Setting};
use crate::prs::{DetSet, Prs, Step};

/// The first index whose value is not finite.
fn first_bad(v: &[f64]) -> Option<usize> {
    v.iter().position(|x| !x.is_finite())
}

/// What is not finite in the deterministic set, naming the state (`None` when it is finite).
fn det_bad(det: &DetSet, states: &[String]) -> Option<NonFiniteQuantity> {
    let state = |i: usize| states.get(i).map_or_else(|| format!("#{i}"), Clone::clone);
    let set = match det {
        DetSet::Ball { .. } => SetKind::Ball,
        DetSet::Box { .. } => SetKind::Box,
        DetSet::Parallelotope { .. } => SetKind::Parallelotope,
        DetSet::Zonotope { .. } => SetKind::Zonotope,
    };
    let bad = |part| Some(NonFiniteQuantity::Deterministic { set, part });
    if let Some(i) = first_bad(det.center()) {
        return bad(SetPart::Centre {
            state: state(i),
            value: det.center()[i],
        });
    }
    if !det.radius().is_finite() {
        return bad(SetPart::Radius(det.radius()));
    }
    if let Some((lo, hi)) = det.box_hull() {
        if let Some(i) = first_bad(lo).or_else(|| first_bad(hi)) {
            return bad(SetPart::Hull {
                state: state(i),
                lo: lo[i],
                hi: hi[i],
            });
        }
    }
    if !det.ball_added().is_finite() {
        return bad(SetPart::Remainder(det.ball_added()));
    }
    if let Some((lo, hi)) = det.corners() {
        if let Some(i) = first_bad(lo).or_else(|| first_bad(hi)) {
            return bad(SetPart::Corners {
                coordinate: i,
                lo: lo[i],
                hi: hi[i],
            });
        }
    }
    None
}

/// What is not finite at this report time (`None` when everything is).
fn step_bad(st: &Step, states: &[String]) -> Option<NonFiniteQuantity> {
    if !st.r_t.is_finite() {
        return Some(if st.psi.is_finite() {
            NonFiniteQuantity::Radius {
                r_t: st.r_t,
                psi: st.psi,
            }
        } else {
            NonFiniteQuantity::Psi {
                r_t: st.r_t,
                c: st.c,
                sigma: st.sigma,
            }
        });
    }
    if let Some(why) = det_bad(&st.det, states) {
        return Some(why);
    }
    let span = &st.span;
    if let Some(i) = first_bad(&span.lo).or_else(|| first_bad(&span.hi)) {
        let state = states.get(i).map_or_else(|| format!("#{i}"), Clone::clone);
        return Some(NonFiniteQuantity::Span {
            state,
            lo: span.lo[i],
            hi: span.hi[i],
        });
    }
    [
        (NonFiniteQuantity::PrsRadius as fn(f64) -> _, st.prs_radius),
        (NonFiniteQuantity::SpanRadius, span.radius),
        (NonFiniteQuantity::PointwiseRadius, st.r_pointwise),
    ]
    .into_iter()
    .find(|(_, v)| !v.is_finite())
    .map(|(what, v)| what(v))
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
            Err(RunError::NonFinite(
                Detail::from(Problem::NotFinite { t, what: why }).at_setting(Setting::Horizon),
            ))
        })
}
