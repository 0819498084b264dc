//! Advice on an interval result ([`Hint`]), read off its own numbers: a box that wraps (grows
//! far beyond the P-ball its certified contraction constants give from the same initial set),
//! or a box that leaves the spec's domain. Advisory only: plain floating point, nothing proved
//! rests on it; the report words it.

use super::Run;
use crate::model::Bounds;
use crate::prs::{Hint, Prs};

/// A box is said to wrap when its PRS's bounding box is this many times wider (in some state, at
/// some report time) than that of the contraction method's P-ball from the same constants.
pub const WRAPPING_FACTOR: f64 = 10.0;

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
