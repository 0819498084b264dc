//! Point membership in the spec's unsafe sets and domain, for counting the paths that enter an
//! unsafe set or leave the domain. Sets are closed (a point on the boundary is in the set).

use super::prs::lanes;
use crate::lanes::X8;
use crate::model::{Bounds, UnsafeShape};

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
    pub(crate) fn unsafe_set(shape: &UnsafeShape, n: usize) -> Result<Region, String> {
        let bad = |what: &str| Err(format!("an unsafe set has {what}"));
        Ok(match shape {
            UnsafeShape::Box(ranges) => {
                if ranges.iter().any(|&(i, _)| i >= n) {
                    return bad("a state index out of range");
                }
                Region::Box(ranges.iter().map(|&(i, b)| (i, b.lo, b.hi)).collect())
            }
            UnsafeShape::Ball {
                states,
                center,
                radius,
            } => {
                if states.iter().any(|&i| i >= n) || center.len() != states.len() {
                    return bad("a bad centre or state index");
                }
                Region::Ball {
                    states: states.clone(),
                    center: center.clone(),
                    r2: radius * radius,
                }
            }
            UnsafeShape::HalfSpace { normal, offset } => {
                if normal.len() != n {
                    return bad("a normal of the wrong dimension");
                }
                Region::HalfSpace {
                    normal: normal
                        .iter()
                        .copied()
                        .enumerate()
                        .filter(|&(_, v)| v != 0.0)
                        .collect(),
                    offset: *offset,
                }
            }
        })
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
    use crate::model::Bounds;

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
