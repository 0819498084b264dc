//! Set geometry shared by the engines and the results: certified membership of a state in a
//! deterministic set widened by a P-ball, for every shape a result holds besides the ball
//! itself.
//!
//! - `boxes`: `[lo, hi] (+) B_P(r)`, through the box's point nearest in the metric;
//! - `parallelotope`: the coordinate transforms `y = T x` of the interval method (`Frame`: `T`
//!   with a rigorous enclosure of `T^-1`), the parallelotope `T^-1 [lo, hi]` and its P-ball;
//! - `zonotope`: the first-order sets' zonotopes, their hulls, supports, P-radii and the
//!   membership of `Z (+) B_P(r)`.
//!
//! Each test answers `true` only when the state is certainly in the set (interval arithmetic,
//! or floating point with a proven margin). The engines build and bound these sets; `prs` asks
//! them for `contains`, and the Monte Carlo check (`simulate`) builds their tests once per set.

pub(crate) mod boxes;
pub(crate) mod parallelotope;
pub(crate) mod zonotope;
