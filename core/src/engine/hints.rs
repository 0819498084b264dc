//! Advice on a result ([`Hint`]), read off its own numbers: an interval result's box that wraps
//! (grows far beyond the P-ball its certified contraction constants give from the same initial
//! set) or leaves the spec's domain, and first-order sets that do not help (their remainder
//! outgrows their linear part, or cannot be bounded). Advisory only: plain floating point,
//! nothing proved rests on it; the report words it.

use super::{first_order, Run};
use crate::model::Bounds;
use crate::prs::{Hint, Prs, Role};

/// A box is said to wrap when its PRS's bounding box is this many times wider (in some state, at
/// some report time) than that of the contraction method's P-ball from the same constants.
pub const WRAPPING_FACTOR: f64 = 10.0;

/// A first-order remainder is worth a hint only when it is at least this part of its set's
/// whole P-radius (the zonotope's, the remainder and `r_t`).
const RELEVANT: f64 = 0.1;

/// The hints of an interval result `prs` of `run`.
pub(super) fn interval(run: &Run, prs: &Prs) -> Vec<Hint> {
    let mut hints = Vec::new();
    hints.extend(wrapping(prs, run.input_radius()));
    if run.info.has_domain {
        hints.extend(leaves_domain(prs, &run.info.domain));
    }
    hints
}

/// The report time and state where the PRS's bounding box (of the intersection with its
/// members, [`Prs::hull_at`]) exceeds the P-ball's the most, if by more than
/// [`WRAPPING_FACTOR`]. The P-ball has the contraction method's radius
/// `R_t = e^(ct) r1 + rho r2 (e^(ct) - 1) / c` plus the result's own `r_t` (both sets carry the
/// same stochastic part), so only the deterministic parts' growth can tell them apart.
fn wrapping(prs: &Prs, r2: f64) -> Option<Hint> {
    let k = &prs.constants;
    let forcing = k.rho * r2;
    // No finite constants (local rates without a global bound): nothing to compare with.
    if !(k.c.is_finite() && forcing.is_finite() && prs.r1.is_finite()) {
        return None;
    }
    let ball = |t: f64| {
        let ct = k.c * t;
        let growth = if ct == 0.0 { t } else { ct.exp_m1() / k.c };
        prs.r1 * ct.exp() + forcing * growth
    };
    let mut worst: Option<(f64, Hint)> = None;
    for (step, st) in prs.steps.iter().enumerate().skip(1) {
        if st.det.box_hull().is_none() {
            continue;
        }
        let Some(hull) = prs.hull_at(step) else {
            continue;
        };
        let radius = ball(st.t) + st.r_t;
        for (i, (b, &w)) in hull.iter().zip(&k.spread).enumerate() {
            let half_width = 0.5 * (b.hi - b.lo);
            let ball_half_width = radius * w;
            // A point initial set without noise has no ball to compare with (a zero or NaN
            // width gives no finite ratio).
            let ratio = half_width / ball_half_width;
            if ratio.is_finite()
                && ratio > WRAPPING_FACTOR
                && worst.as_ref().is_none_or(|(r, _)| ratio > *r)
            {
                let hint = Hint::Wrapping {
                    t: st.t,
                    state: i,
                    half_width,
                    ball_half_width,
                    c: k.c,
                };
                worst = Some((ratio, hint));
            }
        }
    }
    worst.map(|(_, hint)| hint)
}

/// The first report time (and its first state) where the deterministic box's hull leaves the
/// domain.
fn leaves_domain(prs: &Prs, domain: &[Bounds]) -> Option<Hint> {
    prs.steps.iter().find_map(|st| {
        let (lo, hi) = st.det.box_hull()?;
        (0..lo.len()).find_map(|i| {
            let d = domain[i];
            (lo[i] < d.lo || hi[i] > d.hi).then(|| Hint::LeavesDomain {
                t: st.t,
                state: i,
                range: Bounds::new(lo[i], hi[i]),
                domain: d,
            })
        })
    })
}

/// The hint on the first-order sets of `run` (method.md 8.8): `offered` are the members the run
/// computed, `None` when a step could not be bounded ([`Hint::FirstOrderUnbounded`]); else the
/// first report time where their remainder exceeds their linear part and is at least
/// [`RELEVANT`] of their whole P-radius ([`Hint::FirstOrderLoose`]), whether or not they still
/// cut the result there. A point start (no linear part) gives no hint: splitting has nothing to
/// split; nor does a remainder that the stochastic radius dwarfs (a contracting flow shrinks
/// both parts below it).
pub(super) fn first_order(run: &Run, offered: Option<&[Prs]>) -> Option<Hint> {
    if !first_order::wanted(run) {
        return None;
    }
    let Some(members) = offered else {
        return Some(Hint::FirstOrderUnbounded);
    };
    let first = members.iter().find(|m| m.role == Role::FirstOrder)?;
    first.steps.iter().find_map(|st| {
        let (linear, remainder) = first_order::linear_and_remainder(&st.det)?;
        let matters = remainder > RELEVANT * (linear + remainder + st.r_t);
        (linear > 0.0 && remainder > linear && matters).then_some(Hint::FirstOrderLoose {
            t: st.t,
            remainder,
            linear,
        })
    })
}
