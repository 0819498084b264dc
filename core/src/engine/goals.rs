//! Goal sets (method.md 8.13): reach-avoid and reach-and-stay verdicts read off a finished
//! result. A time-uniform PRS holds the whole path on one event of probability at least
//! `1 - delta`; on it, a PRS inside the goal at a report time puts the state there, and spans
//! missing every unsafe set (the margins of `safety.rs`) keep it away from them in continuous
//! time. So the verdicts need no further run and no further share of delta.

use crate::interval::Interval;
use crate::model::{Bounds, GoalSet, Guarantee, Sweep, UnsafeShape};
use crate::prs::{GoalMiss, GoalOutcome, GoalVerdict, Prs};
use crate::sweep;

/// What `prs` (time-uniform, or [`GoalOutcome::NeedsUniform`]) shows about each goal;
/// `numbers` encloses the model's moving set numbers over an interval of time
/// ([`crate::sweep::numbers`]).
pub(crate) fn assess(
    goals: &[GoalSet],
    prs: &Prs,
    numbers: &dyn Fn(Interval) -> Vec<Interval>,
) -> Vec<GoalVerdict> {
    goals.iter().map(|g| assess_one(g, prs, numbers)).collect()
}

fn assess_one(
    goal: &GoalSet,
    prs: &Prs,
    numbers: &dyn Fn(Interval) -> Vec<Interval>,
) -> GoalVerdict {
    let window = goal.window.unwrap_or(Bounds::new(0.0, prs.horizon));
    let at = |k: usize| Interval::point(prs.steps[k].t);
    let over = |k: usize| Interval::new(prs.steps[k.saturating_sub(1)].t, prs.steps[k].t);
    // A moving goal is held still inside all its positions over the times asked about
    // (method.md 8.15); its parts at the report times serve both the margins and the report.
    let parts_over = |t: Interval| sweep::goal_parts(goal, &numbers(t), Sweep::Common);
    let swept: Vec<Vec<UnsafeShape>> = match goal.moving.is_empty() {
        true => Vec::new(),
        false => (0..prs.steps.len()).map(|k| parts_over(at(k))).collect(),
    };
    let parts_at = |k: usize| swept.get(k).map_or(&goal.parts[..], |p| &p[..]);
    let inside = |b: Option<Vec<Bounds>>, parts: &[UnsafeShape]| {
        b.map_or(f64::NEG_INFINITY, |b| margin(parts, &b))
    };
    // Reaching alone (no stay, no unsafe set to avoid on the way) asks about one time: the
    // pointwise radius at that time serves, whatever the guarantee (method.md 8.13).
    let at_one_time = !goal.stay && prs.unsafe_sets.is_empty();
    let margins: Vec<f64> = (0..prs.steps.len())
        .map(|k| match at_one_time {
            true => inside(prs.pointwise_hull_at(k), parts_at(k)),
            false => inside(prs.hull_at(k), parts_at(k)),
        })
        .collect();
    let outcome = if prs.guarantee != Guarantee::Uniform && !at_one_time {
        GoalOutcome::NeedsUniform
    } else {
        outcome(goal, prs, window, &margins, |k| {
            match goal.moving.is_empty() {
                true => inside(prs.span_hull_at(k), &goal.parts),
                false => inside(prs.span_hull_at(k), &parts_over(over(k))),
            }
        })
    };
    GoalVerdict {
        name: goal.name.clone(),
        window,
        stay: goal.stay,
        margins,
        swept,
        outcome,
    }
}

/// The first report time in the window at which the goal is shown reached (see
/// [`GoalOutcome::Reached`]), or why there is none; `span_margin(k)` is the containment margin
/// of the tube over the report interval ending at step `k`.
fn outcome(
    goal: &GoalSet,
    prs: &Prs,
    window: Bounds,
    margins: &[f64],
    span_margin: impl Fn(usize) -> f64,
) -> GoalOutcome {
    let steps = &prs.steps;
    let in_window: Vec<usize> = (0..steps.len())
        .filter(|&k| window.lo <= steps[k].t && steps[k].t <= window.hi)
        .collect();
    let Some(&last_in) = in_window.last() else {
        return GoalOutcome::NotShown(GoalMiss::NoReportTime);
    };
    // The first unsafe set met by the tube up to step `k` (NaN never counts as clear).
    let first_unsafe = |k: usize| {
        (0..=k).find_map(|j| {
            let set = steps[j].margins.iter().position(|&m| !positive(m))?;
            Some(GoalMiss::Unsafe { t: steps[j].t, set })
        })
    };
    // With stay: every report interval to the horizon.
    let end = steps.len() - 1;
    if goal.stay {
        if let Some(miss) = first_unsafe(end) {
            return GoalOutcome::NotShown(miss);
        }
    }
    let mut left = None;
    for &k in &in_window {
        let m = margins[k];
        if !positive(m) {
            continue;
        }
        if !goal.stay {
            return match first_unsafe(k) {
                Some(miss) => GoalOutcome::NotShown(miss),
                None => GoalOutcome::Reached {
                    t: steps[k].t,
                    margin: m,
                },
            };
        }
        let spans: Vec<f64> = (k + 1..=end).map(&span_margin).collect();
        match spans.iter().position(|&s| !positive(s)) {
            Some(j) => {
                left = Some(GoalMiss::Leaves {
                    t: steps[k + 1 + j].t,
                })
            }
            None => {
                return GoalOutcome::Reached {
                    t: steps[k].t,
                    margin: spans.into_iter().fold(m, f64::min),
                }
            }
        }
    }
    GoalOutcome::NotShown(left.unwrap_or_else(|| {
        let best = in_window
            .iter()
            .copied()
            .max_by(|&a, &b| margins[a].total_cmp(&margins[b]))
            .unwrap_or(last_in);
        GoalMiss::NotInside {
            t: steps[best].t,
            margin: margins[best],
        }
    }))
}

/// A margin that shows what it measures (NaN never does).
fn positive(m: f64) -> bool {
    m > 0.0
}

/// How far the box `b` lies inside the goal of `parts`: the smallest of its parts' margins
/// (see [`part_margin`]), rounded down.
pub(crate) fn margin(parts: &[UnsafeShape], b: &[Bounds]) -> f64 {
    parts
        .iter()
        .map(|p| part_margin(p, b))
        .fold(f64::INFINITY, f64::min)
}

/// How far the box `b` lies inside the region `shape`, rounded down: for a box, the smallest
/// gap per constrained coordinate between `b` and the region's faces; for a ball, the radius
/// less the largest distance from its centre to `b`; for a half-space `a . x >= o`, the
/// smallest `(a . x - o) / |a|` over `b`. Not positive where `b` is not certainly inside;
/// `-inf` where `b` is unbounded in a direction that matters.
pub(crate) fn part_margin(shape: &UnsafeShape, b: &[Bounds]) -> f64 {
    let x = |i: usize| Interval::new(b[i].lo, b[i].hi);
    let p = Interval::point;
    match shape {
        UnsafeShape::Box(sides) => sides
            .iter()
            .map(|&(i, side)| {
                let below = (x(i) - p(side.lo)).lo();
                let above = (p(side.hi) - x(i)).lo();
                below.min(above)
            })
            .fold(f64::INFINITY, f64::min),
        UnsafeShape::Ball {
            states,
            center,
            radius,
        } => {
            // The farthest point of the box from the centre, coordinate by coordinate.
            let far = states
                .iter()
                .zip(center)
                .map(|(&i, &c)| (x(i) - p(c)).abs().sqr())
                .fold(Interval::ZERO, |a, d| a + d);
            (p(*radius) - far.sqrt()).lo()
        }
        UnsafeShape::HalfSpace { normal, offset } => {
            let dot = normal
                .iter()
                .enumerate()
                .filter(|(_, a)| **a != 0.0)
                .fold(Interval::ZERO, |s, (i, &a)| s + p(a) * x(i));
            let norm = normal
                .iter()
                .fold(Interval::ZERO, |s, &a| s + p(a).sqr())
                .sqrt();
            ((dot - p(*offset)) / norm).lo()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b(v: &[(f64, f64)]) -> Vec<Bounds> {
        v.iter().map(|&(l, h)| Bounds::new(l, h)).collect()
    }

    /// Margins against hand-computed values, each a lower bound within a few ulps.
    #[test]
    fn part_margins() {
        let bx = b(&[(0.2, 0.4), (-1.0, 1.0)]);
        let close = |a: f64, e: f64| a <= e + 1e-15 && a >= e - 1e-12;
        let goal_box = UnsafeShape::Box(vec![(0, Bounds::new(0.0, 1.0))]);
        assert!(close(part_margin(&goal_box, &bx), 0.2));
        let outside = UnsafeShape::Box(vec![(0, Bounds::new(0.3, 1.0))]);
        assert!(close(part_margin(&outside, &bx), -0.1));
        // The farthest corner of [0.2, 0.4] x [-1, 1] from (0.3, 0) is at distance sqrt(1.01).
        let ball = UnsafeShape::Ball {
            states: vec![0, 1],
            center: vec![0.3, 0.0],
            radius: 2.0,
        };
        assert!(close(part_margin(&ball, &bx), 2.0 - 1.01f64.sqrt()));
        // x + y >= -2: the smallest x + y is -0.8, (-0.8 + 2) / sqrt(2).
        let half = UnsafeShape::HalfSpace {
            normal: vec![1.0, 1.0],
            offset: -2.0,
        };
        assert!(close(part_margin(&half, &bx), 1.2 / 2f64.sqrt()));
        let unbounded = b(&[(0.2, 0.4), (f64::NEG_INFINITY, 1.0)]);
        assert_eq!(part_margin(&half, &unbounded), f64::NEG_INFINITY);
        // An intersection: the smaller margin.
        assert!(close(margin(&[goal_box, half], &bx), 0.2));
    }
}
