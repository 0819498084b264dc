//! Point membership in the spec's unsafe sets, goal sets and domain, for counting the paths that
//! enter an unsafe set, reach a goal or leave the domain. Sets are closed (a point on the
//! boundary is in the set).

use super::error::RegionFault;
use super::prs::lanes;
use crate::interval::Interval;
use crate::lanes::X8;
use crate::model::{Bounds, ModelInfo, Sweep, UnsafeShape};
use crate::sweep;

/// The regions every path's state is checked against after every Euler-Maruyama step.
#[derive(Clone, Debug)]
pub(crate) struct SetRegions {
    /// The unsafe sets.
    pub(crate) unsafe_sets: Vec<Region>,
    /// The goal sets' events to count (method.md 8.13).
    pub(crate) goals: Vec<GoalEvent>,
    /// The domain, if the spec has one.
    pub(crate) domain: Option<Region>,
}

/// A goal set's event, as the paths are checked against it at every Euler-Maruyama step: in
/// the goal at a step in the window with no unsafe set entered at a step before (reach), or
/// in it from a step no later than the window's end to the horizon with no unsafe set entered
/// at any step (stay).
#[derive(Clone, Debug)]
pub(crate) struct GoalEvent {
    /// The goal is the intersection of these.
    pub(crate) parts: Vec<Region>,
    /// The window `[t1, t2]`.
    pub(crate) window: (f64, f64),
    /// Reach and stay until the horizon.
    pub(crate) stay: bool,
}

impl SetRegions {
    /// The regions of `info`'s sets over `n` states as the model gives them (a moving set: at
    /// `t = 0`), goal windows defaulting to `[0, horizon]`; `Err` for malformed data.
    pub(crate) fn new(info: &ModelInfo, n: usize, horizon: f64) -> Result<Self, RegionFault> {
        let unsafe_sets = info
            .unsafe_sets
            .iter()
            .map(|u| Region::unsafe_set(&u.shape, n))
            .collect::<Result<Vec<_>, _>>()?;
        let goals = info
            .goals
            .iter()
            .map(|g| {
                let parts = g
                    .parts
                    .iter()
                    .map(|p| Region::unsafe_set(p, n))
                    .collect::<Result<Vec<_>, _>>()?;
                let w = g.window.unwrap_or(Bounds::new(0.0, horizon));
                Ok(GoalEvent {
                    parts,
                    window: (w.lo, w.hi),
                    stay: g.stay,
                })
            })
            .collect::<Result<Vec<_>, RegionFault>>()?;
        Ok(SetRegions {
            unsafe_sets,
            goals,
            domain: info.has_domain.then(|| Region::domain(&info.domain)),
        })
    }

    /// Moves the regions of `info`'s moving sets (method.md 8.15; `self` from
    /// [`new`](Self::new) of `info`) to where the `numbers` ([`sweep::numbers`]) put them: an
    /// unsafe set held still by [`Sweep::Union`], a goal's parts by [`Sweep::Common`]. At a
    /// point time that is the set itself up to rounding, outward for the unsafe sets and
    /// inward for the goals: hits can only grow and reaches only shrink. The fixed sets'
    /// regions stay as they are.
    pub(crate) fn place(&mut self, info: &ModelInfo, numbers: &[Interval]) {
        let unsafe_sets = self.unsafe_sets.iter_mut().zip(&info.unsafe_sets);
        for (region, u) in unsafe_sets.filter(|(_, u)| !u.moving.is_empty()) {
            *region = Region::of(&u.shape.swept(u.moving.iter(), numbers, Sweep::Union));
        }
        let goals = self.goals.iter_mut().zip(&info.goals);
        for (event, g) in goals.filter(|(_, g)| !g.moving.is_empty()) {
            let parts = sweep::goal_parts(g, numbers, Sweep::Common);
            for (region, part) in event.parts.iter_mut().zip(&parts) {
                *region = Region::of(part);
            }
        }
    }
}

/// A region of the state space.
#[derive(Clone, Debug)]
pub(crate) enum Region {
    /// `lo <= x_i <= hi` for the listed states (ends may be infinite).
    Box(Vec<(usize, f64, f64)>),
    /// `sum (x_i - c_i)^2 <= r^2` over the listed states.
    Ball {
        states: Vec<usize>,
        center: Vec<f64>,
        r2: f64,
    },
    /// `normal . x >= offset` (only the non-zero coefficients kept).
    HalfSpace {
        normal: Vec<(usize, f64)>,
        offset: f64,
    },
}

impl Region {
    /// The region of an unsafe set over `n` states; `Err` for malformed data.
    pub(crate) fn unsafe_set(shape: &UnsafeShape, n: usize) -> Result<Region, RegionFault> {
        let bad = Err;
        match shape {
            UnsafeShape::Box(ranges) if ranges.iter().any(|&(i, _)| i >= n) => {
                bad(RegionFault::State)
            }
            UnsafeShape::Ball { states, center, .. }
                if states.iter().any(|&i| i >= n) || center.len() != states.len() =>
            {
                bad(RegionFault::Ball)
            }
            UnsafeShape::HalfSpace { normal, .. } if normal.len() != n => bad(RegionFault::Normal),
            _ => Ok(Region::of(shape)),
        }
    }

    /// The region of a shape that [`unsafe_set`](Self::unsafe_set) accepts (as a moving set's
    /// shape stays wherever it moves). A ball of negative radius (a goal's part held still
    /// inside all its positions, which have none in common) holds no point.
    fn of(shape: &UnsafeShape) -> Region {
        match shape {
            UnsafeShape::Box(ranges) => {
                Region::Box(ranges.iter().map(|&(i, b)| (i, b.lo, b.hi)).collect())
            }
            UnsafeShape::Ball {
                states,
                center,
                radius,
            } => Region::Ball {
                states: states.clone(),
                center: center.clone(),
                r2: if *radius < 0.0 {
                    f64::NEG_INFINITY
                } else {
                    radius * radius
                },
            },
            UnsafeShape::HalfSpace { normal, offset } => Region::HalfSpace {
                normal: normal
                    .iter()
                    .copied()
                    .enumerate()
                    .filter(|&(_, v)| v != 0.0)
                    .collect(),
                offset: *offset,
            },
        }
    }

    /// The domain box (states with an unbounded range are not constrained).
    pub(crate) fn domain(domain: &[Bounds]) -> Region {
        Region::Box(
            domain
                .iter()
                .enumerate()
                .filter(|(_, r)| r.lo.is_finite() || r.hi.is_finite())
                .map(|(i, r)| (i, r.lo, r.hi))
                .collect(),
        )
    }

    /// Whether `x` is in the region.
    #[inline(always)] // called for every path and Euler step of models with sets
    pub(crate) fn contains(&self, x: &[f64]) -> bool {
        match self {
            Region::Box(r) => r.iter().all(|&(i, lo, hi)| lo <= x[i] && x[i] <= hi),
            Region::Ball { states, center, r2 } => {
                let d2: f64 = states
                    .iter()
                    .zip(center)
                    .map(|(&i, c)| (x[i] - c) * (x[i] - c))
                    .sum();
                d2 <= *r2
            }
            Region::HalfSpace { normal, offset } => {
                normal.iter().map(|&(i, a)| a * x[i]).sum::<f64>() >= *offset
            }
        }
    }

    /// [`contains`](Self::contains) of eight states in lanes (state `i` of lane `l` in
    /// `x[i]`): bit `l` set when lane `l`'s state is in the region. The same operations per
    /// lane, so the same answers (the sums here start from `+0` where `contains`'s may start
    /// from `-0`: they can differ in the sign of a zero only, which no comparison sees).
    #[inline(always)]
    pub(crate) fn contains_x8(&self, x: &[X8]) -> u8 {
        match self {
            Region::Box(r) => {
                let mut mask = 0xff;
                for &(i, lo, hi) in r {
                    mask &= lanes(|l| lo <= x[i].0[l] && x[i].0[l] <= hi);
                }
                mask
            }
            Region::Ball { states, center, r2 } => {
                let mut d2 = X8::splat(0.0);
                for (&i, &c) in states.iter().zip(center) {
                    d2 = d2 + (x[i] - c) * (x[i] - c);
                }
                lanes(|l| d2.0[l] <= *r2)
            }
            Region::HalfSpace { normal, offset } => {
                let mut s = X8::splat(0.0);
                for &(i, a) in normal {
                    s = s + X8::splat(a) * x[i];
                }
                lanes(|l| s.0[l] >= *offset)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{GoalSet, Moving, Slot, UnsafeSet};
    use crate::test_support::models::model;

    #[test]
    fn shapes() {
        let b = Region::unsafe_set(&UnsafeShape::Box(vec![(1, Bounds::new(0.0, 1.0))]), 2).unwrap();
        assert!(b.contains(&[9.0, 1.0]) && !b.contains(&[0.0, 1.5]));
        let ball = Region::unsafe_set(
            &UnsafeShape::Ball {
                states: vec![0, 1],
                center: vec![1.0, 1.0],
                radius: 0.5,
            },
            2,
        )
        .unwrap();
        assert!(ball.contains(&[1.3, 1.4]) && !ball.contains(&[1.4, 1.4]));
        let h = Region::unsafe_set(
            &UnsafeShape::HalfSpace {
                normal: vec![1.0, -1.0],
                offset: 1.0,
            },
            2,
        )
        .unwrap();
        assert!(h.contains(&[1.0, 0.0]) && !h.contains(&[1.0, 0.5]));
        let d = Region::domain(&[
            Bounds::new(-1.0, 1.0),
            Bounds::new(f64::NEG_INFINITY, f64::INFINITY),
        ]);
        assert!(d.contains(&[0.5, 1e300]) && !d.contains(&[1.5, 0.0]));
        assert!(
            Region::unsafe_set(&UnsafeShape::Box(vec![(2, Bounds::new(0.0, 1.0))]), 2).is_err()
        );
    }

    /// Moving sets placed at a time are the sets there, rounded outward (unsafe) or inward
    /// (goals) within the numbers' enclosures: a half-space's offset, a ball's centre and
    /// radius, a box's side; a goal's ball of negative radius holds no point; fixed sets stay.
    #[test]
    fn moving_sets_are_placed() {
        let moving = |part, slot, number| Moving { part, slot, number };
        let fixed = UnsafeShape::Box(vec![(1, Bounds::new(5.0, 6.0))]);
        let ball = |radius| UnsafeShape::Ball {
            states: vec![0, 1],
            center: vec![0.0, 0.0],
            radius,
        };
        let info = ModelInfo {
            unsafe_sets: vec![
                UnsafeSet {
                    name: "half".into(),
                    shape: UnsafeShape::HalfSpace {
                        normal: vec![1.0, 0.0],
                        offset: 0.0,
                    },
                    moving: vec![moving(0, Slot::Offset, 0)],
                },
                UnsafeSet {
                    name: "ball".into(),
                    shape: ball(1.0),
                    moving: vec![moving(0, Slot::Center(0), 1), moving(0, Slot::Radius, 2)],
                },
                UnsafeSet {
                    name: "fixed".into(),
                    shape: fixed.clone(),
                    moving: vec![],
                },
            ],
            goals: vec![GoalSet {
                name: "goal".into(),
                parts: vec![
                    UnsafeShape::Box(vec![(0, Bounds::new(0.0, 1.0))]),
                    ball(1.0),
                ],
                moving: vec![moving(0, Slot::Hi(0), 3), moving(1, Slot::Radius, 4)],
                window: None,
                stay: false,
            }],
            ..model("m", &["x", "y"], &[], &[(0.0, 0.0); 2])
        };
        let mut sets = SetRegions::new(&info, 2, 1.0).unwrap();
        let numbers = [
            Interval::new(1.0, 1.25),
            Interval::point(3.0),
            Interval::point(0.5),
            Interval::new(2.0, 2.5),
            Interval::point(-1.0),
        ];
        sets.place(&info, &numbers);
        let [half, ball, kept] = &sets.unsafe_sets[..] else {
            panic!("three unsafe sets")
        };
        assert!(half.contains(&[1.0, 0.0]) && !half.contains(&[0.99, 0.0]));
        assert!(ball.contains(&[3.5, 0.0]) && !ball.contains(&[2.49, 0.0]));
        assert!(!ball.contains(&[0.0, 0.0]));
        assert_eq!(format!("{kept:?}"), format!("{:?}", Region::of(&fixed)));
        let [top, empty] = &sets.goals[0].parts[..] else {
            panic!("two parts")
        };
        assert!(top.contains(&[2.0, 0.0]) && !top.contains(&[2.01, 0.0]));
        assert!(!empty.contains(&[0.0, 0.0]));
        assert_eq!(empty.contains_x8(&[X8::splat(0.0); 2]), 0);
    }

    #[test]
    fn lanes_answer_as_one_state_does() {
        let regions = [
            Region::unsafe_set(&UnsafeShape::Box(vec![(1, Bounds::new(0.0, 1.0))]), 2).unwrap(),
            Region::unsafe_set(
                &UnsafeShape::Ball {
                    states: vec![0, 1],
                    center: vec![0.5, 0.25],
                    radius: 0.5,
                },
                2,
            )
            .unwrap(),
            Region::unsafe_set(
                &UnsafeShape::HalfSpace {
                    normal: vec![1.0, -0.5],
                    offset: 0.125,
                },
                2,
            )
            .unwrap(),
            Region::domain(&[Bounds::new(-1.0, 1.0), Bounds::new(f64::NEG_INFINITY, 0.75)]),
        ];
        // States on a grid that puts some on every boundary (the ball's and the half-space's
        // included: 0.5 + 0.5 = 1, 0.5 * 0.25 + 0.125...), and non-finite ones.
        let mut states: Vec<[f64; 2]> = (0..8 * 40)
            .map(|k| [f64::from(k % 17) / 8.0 - 1.0, f64::from(k / 17) / 8.0 - 1.0])
            .collect();
        states[3] = [f64::NAN, 0.5];
        states[12] = [0.5, f64::INFINITY];
        let mut seen = [0u32; 4];
        for chunk in states.chunks_exact(8) {
            let x: Vec<X8> = (0..2)
                .map(|i| X8(std::array::from_fn(|l| chunk[l][i])))
                .collect();
            for (r, region) in regions.iter().enumerate() {
                let mask = region.contains_x8(&x);
                for (l, s) in chunk.iter().enumerate() {
                    assert_eq!(mask >> l & 1 == 1, region.contains(s), "{region:?} {s:?}");
                    seen[r] += u32::from(region.contains(s));
                }
            }
        }
        assert!(seen.iter().all(|&c| c > 10 && c < 300), "{seen:?}");
    }
}
