//! Moving sets held still over an interval of time (method.md 8.15): the numbers of a moving
//! unsafe or goal set are functions of `t` and tables ([`System::set_numbers`]), enclosed over
//! an interval of time; a fixed set holding every position of the set over it (to avoid) or
//! inside every position (to be inside) stands for it there, so that every check of fixed sets
//! applies unchanged.

use crate::interval::Interval;
use crate::model::{GoalSet, ModelInfo, Moving, Slot, Sweep, UnsafeSet, UnsafeShape};
use crate::System;

impl ModelInfo {
    /// Whether some unsafe or goal set moves.
    pub fn has_moving_sets(&self) -> bool {
        self.unsafe_sets.iter().any(|u| !u.moving.is_empty())
            || self.goals.iter().any(|g| !g.moving.is_empty())
    }

    /// How many numbers [`System::set_numbers`] writes for this model.
    pub fn set_numbers(&self) -> usize {
        let all = self.unsafe_sets.iter().flat_map(|u| &u.moving);
        all.chain(self.goals.iter().flat_map(|g| &g.moving))
            .map(|m| m.number + 1)
            .max()
            .unwrap_or(0)
    }
}

/// The moving numbers of `sys`'s sets over the times `t` (enclosures), or nothing for a model
/// whose sets are all fixed.
pub fn numbers<S: System + ?Sized>(sys: &S, info: &ModelInfo, t: Interval) -> Vec<Interval> {
    let mut out = vec![Interval::ZERO; info.set_numbers()];
    if !out.is_empty() {
        sys.set_numbers(t, &mut out);
    }
    out
}

/// The unsafe sets of `info` over the times the `numbers` (from [`numbers`]) were taken at,
/// each as a fixed set holding all its positions (the fixed ones as they are).
pub fn unsafe_sets(info: &ModelInfo, numbers: &[Interval]) -> Vec<UnsafeSet> {
    info.unsafe_sets
        .iter()
        .map(|u| UnsafeSet {
            name: u.name.clone(),
            shape: u.shape.swept(u.moving.iter(), numbers, Sweep::Union),
            moving: Vec::new(),
        })
        .collect()
}

/// The parts of `goal` over the times the `numbers` were taken at, each held still by `sweep`.
pub fn goal_parts(goal: &GoalSet, numbers: &[Interval], sweep: Sweep) -> Vec<UnsafeShape> {
    goal.parts
        .iter()
        .enumerate()
        .map(|(j, p)| p.swept(goal.moving.iter().filter(|m| m.part == j), numbers, sweep))
        .collect()
}

/// Whether `m` names a number that `parts` have.
pub(crate) fn fits(m: &Moving, parts: &[UnsafeShape]) -> bool {
    match (parts.get(m.part), m.slot) {
        (Some(UnsafeShape::HalfSpace { .. }), Slot::Offset) => true,
        (Some(UnsafeShape::Box(sides)), Slot::Lo(k) | Slot::Hi(k)) => k < sides.len(),
        (Some(UnsafeShape::Ball { center, .. }), Slot::Center(k)) => k < center.len(),
        (Some(UnsafeShape::Ball { .. }), Slot::Radius) => true,
        _ => false,
    }
}

impl UnsafeShape {
    /// This shape with its `moving` numbers replaced by the enclosures in `numbers`, held still
    /// by `sweep` (rounded outward for [`Sweep::Union`], inward for [`Sweep::Common`]). A
    /// common part that is empty (a box side with `lo > hi`, a negative radius) holds no point.
    pub fn swept<'m>(
        &self,
        moving: impl Iterator<Item = &'m Moving>,
        numbers: &[Interval],
        sweep: Sweep,
    ) -> UnsafeShape {
        let union = sweep == Sweep::Union;
        // The end of an enclosure that makes the set larger (union) or smaller (common), for
        // a number that grows the set when it grows (`grows`) or shrinks it.
        let pick = |v: Interval, grows: bool| if grows == union { v.hi() } else { v.lo() };
        let mut shape = self.clone();
        let mut center: Option<Vec<Interval>> = None;
        let mut radius: Option<Interval> = None;
        for m in moving {
            let v = numbers[m.number];
            match (&mut shape, m.slot) {
                (UnsafeShape::HalfSpace { offset, .. }, Slot::Offset) => *offset = pick(v, false),
                (UnsafeShape::Box(sides), Slot::Lo(k)) => sides[k].1.lo = pick(v, false),
                (UnsafeShape::Box(sides), Slot::Hi(k)) => sides[k].1.hi = pick(v, true),
                (UnsafeShape::Ball { center: c, .. }, Slot::Center(k)) => {
                    let c = center
                        .get_or_insert_with(|| c.iter().map(|&x| Interval::point(x)).collect());
                    c[k] = v;
                }
                (UnsafeShape::Ball { .. }, Slot::Radius) => radius = Some(v),
                _ => {}
            }
        }
        if let UnsafeShape::Ball {
            center: c,
            radius: r,
            ..
        } = &mut shape
        {
            let rad = radius.unwrap_or(Interval::point(*r));
            // A ball whose centre moves in a box: the balls of the box's centres lie in the
            // ball about its midpoint with the radius grown by the box's half-diagonal, and
            // hold the ball with the radius shrunk by it.
            let (mid, spread) = match &center {
                Some(cs) => {
                    let mid: Vec<f64> = cs.iter().map(|x| x.mid()).collect();
                    let spread = cs
                        .iter()
                        .zip(&mid)
                        .fold(Interval::ZERO, |acc, (x, &m)| {
                            let m = Interval::point(m);
                            let far = (Interval::point(x.hi()) - m)
                                .hi()
                                .max((m - Interval::point(x.lo())).hi());
                            acc + Interval::point(far).sqr()
                        })
                        .sqrt();
                    (mid, spread)
                }
                None => (c.clone(), Interval::ZERO),
            };
            *c = mid;
            *r = if union {
                (Interval::point(rad.hi()) + Interval::point(spread.hi())).hi()
            } else {
                (Interval::point(rad.lo()) - Interval::point(spread.hi())).lo()
            };
        }
        shape
    }
}
