//! Point membership in the spec's unsafe sets and domain, for counting the paths that enter an
//! unsafe set or leave the domain. Sets are closed (a point on the boundary is in the set).

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
}
