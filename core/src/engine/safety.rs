//! Sound safety checks of a P-ball `B_P(x*, R)` against the spec's unsafe sets.
//!
//! "Sound" means one-sided: a check may fail to show safety for a ball that is safe, never the
//! reverse. Everything depending on `P^-1` is enclosed rigorously (interval Cholesky, see
//! [`super::linalg`]); the margins are rounded down. The nominal centre `x*` is taken as exact
//! (it is the numerically integrated nominal, which the report marks as not validated).

use super::linalg;
use crate::interval::Interval;
use crate::system::{UnsafeSet, UnsafeShape};

/// A precomputed check for one unsafe set (the `P^-1` quantities do not depend on time).
#[derive(Clone, Debug)]
pub(crate) enum Check {
    /// `{a . x >= b}`: `max_{B_P(x*, R)} a.x = a.x* + R sqrt(a' P^-1 a)`.
    HalfSpace {
        normal: Vec<f64>,
        offset: f64,
        /// Upper bound of `sqrt(a' P^-1 a)`.
        dual_norm: f64,
        /// Enclosure of the Euclidean norm `|a|`.
        norm: Interval,
    },
    /// Box over some coordinates: the P-ball lies in `x*_i +- R sqrt((P^-1)_ii)`.
    Box {
        /// `(state, (lo, hi), upper bound of sqrt((P^-1)_ii))`.
        coords: Vec<(usize, (f64, f64), f64)>,
    },
    /// Euclidean ball over states `S`: the projection of the P-ball onto `S` lies in the
    /// Euclidean ball of radius `R sqrt(lambda_max((P^-1)_SS))` around `x*_S`.
    Ball {
        states: Vec<usize>,
        center: Vec<f64>,
        radius: f64,
        /// Upper bound of `sqrt(lambda_max((P^-1)_SS))`.
        spread: f64,
    },
}

impl Check {
    /// The kind, for the report.
    pub(crate) fn kind(&self) -> &'static str {
        match self {
            Check::HalfSpace { .. } => "half_space",
            Check::Box { .. } => "box",
            Check::Ball { .. } => "ball",
        }
    }

    /// Precomputes the checks of every unsafe set (see [`Check::new`]).
    pub(crate) fn all(
        sets: &[UnsafeSet],
        n: usize,
        l: &[Interval],
        p_inv_diag: &[Interval],
    ) -> Result<Vec<Check>, String> {
        sets.iter()
            .map(|s| Check::new(s, n, l, p_inv_diag))
            .collect()
    }

    /// Precomputes the check; `l` is the interval Cholesky factor of `P`, `p_inv_diag` an
    /// enclosure of the diagonal of `P^-1`.
    pub(crate) fn new(
        set: &UnsafeSet,
        n: usize,
        l: &[Interval],
        p_inv_diag: &[Interval],
    ) -> Result<Check, String> {
        let bad = |what: &str| format!("unsafe set `{}`: {what}", set.name);
        match &set.shape {
            UnsafeShape::HalfSpace { normal, offset } => {
                if normal.len() != n {
                    return Err(bad(&format!(
                        "normal has {} entries, n = {n}",
                        normal.len()
                    )));
                }
                let q = linalg::inv_quad_form(l, n, normal);
                let norm = normal
                    .iter()
                    .fold(Interval::ZERO, |acc, &a| acc + Interval::point(a).sqr())
                    .sqrt();
                Ok(Check::HalfSpace {
                    normal: normal.clone(),
                    offset: *offset,
                    dual_norm: q.sqrt().hi(),
                    norm,
                })
            }
            UnsafeShape::Box(coords) => {
                let mut out = Vec::with_capacity(coords.len());
                for &(i, range) in coords {
                    if i >= n {
                        return Err(bad(&format!("refers to state {i}, n = {n}")));
                    }
                    out.push((i, range, p_inv_diag[i].sqrt().hi()));
                }
                Ok(Check::Box { coords: out })
            }
            UnsafeShape::Ball {
                states,
                center,
                radius,
            } => {
                let k = states.len();
                if center.len() != k || states.iter().any(|&s| s >= n) {
                    return Err(bad("states and centre do not match the model"));
                }
                let sub = linalg::inverse_block(l, n, states);
                let lam = linalg::lambda_max_upper(&sub, k);
                Ok(Check::Ball {
                    states: states.clone(),
                    center: center.clone(),
                    radius: *radius,
                    spread: Interval::point(lam.max(0.0)).sqrt().hi(),
                })
            }
        }
    }

    /// A lower bound of the safety margin of `B_P(x, r)`; the ball is shown safe iff the margin
    /// is `> 0`. Units: Euclidean distance for half-spaces and balls; for boxes the largest
    /// per-coordinate gap between the ball's bounding box and the unsafe box (when `<= 0` the
    /// bounding boxes overlap in every constrained coordinate).
    pub(crate) fn margin(&self, x: &[f64], r: f64) -> f64 {
        let r = Interval::point(r);
        match self {
            Check::HalfSpace {
                normal,
                offset,
                dual_norm,
                norm,
            } => {
                if norm.hi() == 0.0 {
                    // {0 >= b}: empty (safe everywhere) if b > 0, else the whole space.
                    return if *offset > 0.0 {
                        f64::INFINITY
                    } else {
                        f64::NEG_INFINITY
                    };
                }
                let ax = normal.iter().zip(x).fold(Interval::ZERO, |acc, (&a, &xi)| {
                    acc + Interval::point(a) * Interval::point(xi)
                });
                let reach = ax + r * Interval::point(*dual_norm);
                ((Interval::point(*offset) - reach) / *norm).lo()
            }
            Check::Box { coords } => coords
                .iter()
                .map(|&(i, (lo, hi), w)| {
                    let half = r * Interval::point(w);
                    let xi = Interval::point(x[i]);
                    // Gap below the unsafe box, and gap above it.
                    let below = if lo == f64::NEG_INFINITY {
                        f64::NEG_INFINITY
                    } else {
                        (Interval::point(lo) - (xi + half)).lo()
                    };
                    let above = if hi == f64::INFINITY {
                        f64::NEG_INFINITY
                    } else {
                        ((xi - half) - Interval::point(hi)).lo()
                    };
                    below.max(above)
                })
                .fold(f64::NEG_INFINITY, f64::max),
            Check::Ball {
                states,
                center,
                radius,
                spread,
            } => {
                let dist = states
                    .iter()
                    .zip(center)
                    .fold(Interval::ZERO, |acc, (&s, &c)| {
                        acc + (Interval::point(x[s]) - Interval::point(c)).sqr()
                    })
                    .sqrt();
                (dist - r * Interval::point(*spread) - Interval::point(*radius)).lo()
            }
        }
    }
}
