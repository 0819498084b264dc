//! Distances `|x - x*_t|_P` and PRS membership of sample states.
//!
//! Membership is decided by [`Prs::contains_at`] (the engine's own, conservative test). It
//! allocates and works in interval arithmetic, too slow for every path and step, so two
//! shortcuts answer the clear cases first, each only where it provably agrees with `contains`:
//!
//! * outside: `|x - x*_t|_P` clearly above the PRS radius. For the shapes whose PRS lies in the
//!   P-ball `B_P(x*_t, prs_radius)` (`"p_ball"`, and `"box"`, `"parallelotope"` and
//!   `"zonotope"` with `x*_t` the centre of the box, of the parallelotope's hull or of the
//!   zonotope), a point outside that ball is outside the PRS;
//! * inside: for `"p_ball"`, `|x - x*_t|_P` clearly below the radius; for `"box"`, `x` in the
//!   box (a subset of the PRS `box (+) B_P(r_t)`); for `"parallelotope"`, `T x` clearly in the
//!   box `[lo, hi]` of `y = T x` (where `contains` also answers at once); for `"zonotope"`,
//!   the bound of `x`'s P-distance to the zonotope by the inverse of a basis of its generators
//!   (`ZonotopeTest::excess`, `O(n^2)` with a per-step inverse, the first thing `contains`
//!   asks) at most `remainder + r_t`; for all three, also `|x - c|_P` clearly below the
//!   radius of the P-ball around the centre `c` that the PRS holds (`r_t` when a box or a
//!   parallelotope certainly holds `c`, `remainder + r_t` for a zonotope; `contains` asks that
//!   ball too).
//!
//! The shortcuts are also computed for eight states at once in vector lanes
//! ([`Membership::inside_by_shortcut_x8`]), with the same operations per lane.
//!
//! "Clearly" means by more than a bound on the rounding errors of both computations:
//! `|q_computed - q| <= gamma * sum |w_ij d_i d_j|` with `gamma` a generous multiple of the unit
//! roundoff times the number of terms, and likewise for `T x`. Points in those bands, and every
//! point for other shapes, go to `contains`.
//!
//! The time-uniform tube ([`Tube`]) is checked against the spans of the result
//! ([`Step::span`](crate::prs::Step::span): `{lo <= y <= hi} (+) B_P(radius)`, decided by
//! [`Prs::span_contains`]) at every Euler-Maruyama step, so it has shortcuts of its own:
//!
//! * inside: the box point nearest `x` coordinate by coordinate, `y = clamp(x, lo, hi)`, is a
//!   point of the box, so `|x - y|_P` clearly below `radius` proves `x` in the span (for a
//!   non-negative diagonal `P`, `y` is the nearest point of the box in `|.|_P`, and this is
//!   the exact distance to the box);
//! * outside: for a non-negative diagonal `P`, `|x - y|_P` clearly above `radius`; for other
//!   metrics, `|x - c|_P` clearly above `radius + b`, with `c` the box's centre and `b` an
//!   upper bound of the box's P-radius around `c` (the span lies in the ball `B_P(c, radius +
//!   b)`).
//!
//! The PRS of an intersection (several metrics' sets, `Prs::also`) is decided set by set,
//! each with its own metric's shortcuts, and so is its tube.
//!
//! A non-finite state is outside, a state in the box inside (the span at `t = 0` of an interval
//! analysis has radius 0); everything else goes to `span_contains`. Every shortcut is
//! sound on its own (an "inside" is proved by a point of the box), so a state is never counted
//! inside the tube when it is not.

mod membership;
mod metric;
mod tube;

#[cfg(test)]
pub(super) mod fixtures;

pub(crate) use membership::Membership;
pub(crate) use metric::{diag_quad, diag_quad_to_box, quad_small, Metric};
pub(crate) use tube::Tube;

use super::error::SimInvalid;
use crate::model::Bounds;
use crate::prs::Prs;

/// A result's bounding boxes, `[lo, hi]` per state, step after step (`n` per step): a state
/// outside step `k`'s box is outside the result's set at `k` (a quick test before the exact
/// one).
#[derive(Clone, Debug)]
pub(crate) struct Hulls {
    n: usize,
    bounds: Vec<(f64, f64)>,
}

impl Hulls {
    /// Per step of `result`, the box `hull` gives (no bound where it gives none).
    fn of(result: &Prs, hull: impl Fn(usize) -> Option<Vec<Bounds>>) -> Hulls {
        let n = result.n();
        let bounds = (0..result.steps.len())
            .flat_map(|k| {
                hull(k).map_or_else(
                    || vec![(f64::NEG_INFINITY, f64::INFINITY); n],
                    |b| b.iter().map(|x| (x.lo, x.hi)).collect(),
                )
            })
            .collect();
        Hulls { n, bounds }
    }

    /// Whether `x` may lie in the set of step `k` (`false`: certainly not).
    fn may_hold(&self, k: usize, x: &[f64]) -> bool {
        let b = &self.bounds[k * self.n..(k + 1) * self.n];
        x.iter().zip(b).all(|(v, (lo, hi))| lo <= v && v <= hi)
    }
}

/// The members of `result`'s intersection (`result.also`), each with its metric and what
/// `make` builds of it and that metric.
fn members<'a, T>(
    result: &'a Prs,
    make: impl Fn(&'a Prs, &Metric) -> Result<T, SimInvalid>,
) -> Result<Vec<(Metric, T)>, SimInvalid> {
    let n = result.states.len();
    result
        .also
        .iter()
        .map(|m| {
            let metric = Metric::new(&m.constants.metric, n);
            let part = make(m, &metric)?;
            Ok((metric, part))
        })
        .collect()
}

/// The mask of the lanes `l` for which `f(l)` holds (bit `l`).
#[inline(always)]
pub(crate) fn lanes(f: impl Fn(usize) -> bool) -> u8 {
    let mut mask = 0;
    for l in 0..8 {
        mask |= u8::from(f(l)) << l;
    }
    mask
}
