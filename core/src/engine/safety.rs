//! Sound safety checks of a PRS `Rbar_t (+) B_P(r_t)` against the spec's unsafe sets, for every
//! shape of deterministic set: a P-ball `B_P(x*, R)` (the PRS is then `B_P(x*, R + r_t)`), a
//! box, a parallelotope, or a zonotope plus a P-ball.
//!
//! "Sound" means one-sided: a check may fail to show safety for a set that is safe, never the
//! reverse. Everything depending on `P^-1` is enclosed rigorously (interval Cholesky, see
//! [`super::linalg`]); the margins are rounded down. The deterministic set is taken as given
//! (the report marks how it was computed).

use super::linalg;
use super::problem::{UnsafeSetError, UnsafeSetFault};
use crate::interval::Interval;
use crate::model::{UnsafeSet, UnsafeShape};
use crate::prs::{DetSet, Span, UnsafeKind};
use crate::sets::parallelotope::Frame;
use crate::sets::zonotope;

/// What the margins of box-shaped sets need besides the set.
pub(crate) struct Context<'a> {
    /// Upper bounds of `sqrt((P^-1)_ii)`: `B_P(r)` lies in the box `|d_i| <= r w_i`.
    pub(crate) w: &'a [f64],
    /// The transform of parallelotope sets.
    pub(crate) frame: Option<&'a Frame>,
}

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
    /// The kind of the unsafe set.
    pub(crate) fn kind(&self) -> UnsafeKind {
        match self {
            Check::HalfSpace { .. } => UnsafeKind::HalfSpace,
            Check::Box { .. } => UnsafeKind::Box,
            Check::Ball { .. } => UnsafeKind::Ball,
        }
    }

    /// A lower bound of the safety margin of the PRS `set (+) B_P(r_t)`; the PRS is shown safe
    /// iff the margin is `> 0`. Units: Euclidean distance for half-spaces and balls; for boxes
    /// the largest per-coordinate gap between the PRS's bounding box and the unsafe box (when
    /// `<= 0` the bounding boxes overlap in every constrained coordinate).
    pub(crate) fn margin(&self, set: &DetSet, r_t: f64, context: &Context) -> f64 {
        match set {
            // B_P(x, R) (+) B_P(r_t) = {x} (+) B_P(R + r_t): a box of width zero.
            DetSet::Ball { center, radius } => {
                let prs = (Interval::point(*radius) + Interval::point(r_t)).hi();
                box_margin(self, center, center, prs, context.w, None)
            }
            DetSet::Box { lo, hi, .. } => box_margin(self, lo, hi, r_t, context.w, None),
            DetSet::Parallelotope {
                lo,
                hi,
                hull_lo,
                hull_hi,
                ..
            } => {
                // A half-space has an exact support function on the parallelotope.
                let support = match (self, context.frame) {
                    (Check::HalfSpace { normal, .. }, Some(f)) => Some(f.support(normal, lo, hi)),
                    _ => None,
                };
                box_margin(self, hull_lo, hull_hi, r_t, context.w, support)
            }
            // Z (+) B_P(remainder) (+) B_P(r_t): the zonotope's hull and support function, the
            // two balls as one.
            DetSet::Zonotope {
                center,
                generators,
                remainder,
                hull_lo,
                hull_hi,
                ..
            } => {
                let support = match self {
                    Check::HalfSpace { normal, .. } => {
                        Some(zonotope::support(center, generators, normal))
                    }
                    _ => None,
                };
                let r = (Interval::point(*remainder) + Interval::point(r_t)).hi();
                box_margin(self, hull_lo, hull_hi, r, context.w, support)
            }
        }
    }

    /// A lower bound of the safety margin of the span `{lo <= x <= hi} (+) B_P(radius)` (see
    /// [`Check::margin`]).
    pub(crate) fn margin_of_span(&self, span: &Span, context: &Context) -> f64 {
        box_margin(self, &span.lo, &span.hi, span.radius, context.w, None)
    }

    /// This check for the same set at another place: the numbers of `shape` (the set's own
    /// shape with other offsets, sides, centre or radius, as [`crate::sweep`] holds a moving
    /// set still) in place of its own; the `P^-1` quantities do not depend on them.
    pub(crate) fn moved(&self, shape: &UnsafeShape) -> Check {
        let mut c = self.clone();
        match (&mut c, shape) {
            (Check::HalfSpace { offset, .. }, UnsafeShape::HalfSpace { offset: o, .. }) => {
                *offset = *o;
            }
            (Check::Box { coords }, UnsafeShape::Box(sides)) => {
                for ((_, range, _), (_, b)) in coords.iter_mut().zip(sides) {
                    *range = (b.lo, b.hi);
                }
            }
            (
                Check::Ball { center, radius, .. },
                UnsafeShape::Ball {
                    center: c,
                    radius: r,
                    ..
                },
            ) => {
                center.clone_from(c);
                *radius = *r;
            }
            _ => {}
        }
        c
    }

    /// Precomputes the checks of every unsafe set (see [`Check::new`]).
    pub(crate) fn all(
        sets: &[UnsafeSet],
        n: usize,
        l: &[Interval],
        p_inv_diag: &[Interval],
    ) -> Result<Vec<Check>, UnsafeSetError> {
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
    ) -> Result<Check, UnsafeSetError> {
        let bad = |fault: UnsafeSetFault| UnsafeSetError {
            set: set.name.clone(),
            fault,
        };
        match &set.shape {
            UnsafeShape::HalfSpace { normal, offset } => {
                if normal.len() != n {
                    return Err(bad(UnsafeSetFault::NormalLength {
                        entries: normal.len(),
                        n,
                    }));
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
                        return Err(bad(UnsafeSetFault::State { state: i, n }));
                    }
                    out.push((i, (range.lo, range.hi), p_inv_diag[i].sqrt().hi()));
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
                    return Err(bad(UnsafeSetFault::Ball));
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
}

/// Lower bound of the distance from `c` to the box `[lo, hi]` over `states`.
fn dist_to_box(states: &[usize], center: &[f64], lo: &[f64], hi: &[f64]) -> f64 {
    states
        .iter()
        .zip(center)
        .fold(Interval::ZERO, |acc, (&s, &c)| {
            let c = Interval::point(c);
            let gap = (Interval::point(lo[s]) - c)
                .lo()
                .max((c - Interval::point(hi[s])).lo())
                .max(0.0);
            acc + Interval::point(gap).sqr()
        })
        .sqrt()
        .lo()
}

/// A lower bound of the safety margin of the PRS `[lo, hi] (+) B_P(r)` (same units as
/// [`Check::margin`]; `> 0` means shown safe).
///
/// `B_P(r)` lies in the box `|d_i| <= r w_i` (`w_i >= sqrt((P^-1)_ii)`), so the PRS lies in the
/// inflated box `[lo - r w, hi + r w]`. Half-spaces use the exact support function
/// `max_box a.x + r sqrt(a' P^-1 a)` (and the inflated box, whichever bound is smaller); boxes
/// the per-coordinate gaps to the inflated box; balls the larger of two lower bounds of the
/// distance, `dist(c, inflated box)` and `dist(c, box) - r spread`.
///
/// `support`, for a half-space, is another upper bound of `max a.x` over the deterministic set
/// (exact for a parallelotope whose hull is `[lo, hi]`); the smaller bound is used.
fn box_margin(
    check: &Check,
    lo: &[f64],
    hi: &[f64],
    r: f64,
    w: &[f64],
    support: Option<f64>,
) -> f64 {
    let r = Interval::point(r);
    let inf_lo = |i: usize| (Interval::point(lo[i]) - r * Interval::point(w[i])).lo();
    let inf_hi = |i: usize| (Interval::point(hi[i]) + r * Interval::point(w[i])).hi();
    match check {
        Check::HalfSpace {
            normal,
            offset,
            dual_norm,
            norm,
        } => {
            if norm.hi() == 0.0 {
                return if *offset > 0.0 {
                    f64::INFINITY
                } else {
                    f64::NEG_INFINITY
                };
            }
            let mut over_box = Interval::ZERO;
            let mut over_inflated = Interval::ZERO;
            for (i, &a) in normal.iter().enumerate() {
                if a == 0.0 {
                    continue;
                }
                let ai = Interval::point(a);
                let (b, ib) = if a > 0.0 {
                    (hi[i], inf_hi(i))
                } else {
                    (lo[i], inf_lo(i))
                };
                over_box += ai * Interval::point(b);
                over_inflated += ai * Interval::point(ib);
            }
            let over_set = support.map_or(over_box, |s| Interval::point(s.min(over_box.hi())));
            let exact = over_set + r * Interval::point(*dual_norm);
            let reach = exact.hi().min(over_inflated.hi());
            ((Interval::point(*offset) - Interval::point(reach)) / *norm).lo()
        }
        Check::Box { coords } => coords
            .iter()
            .map(|&(i, (ulo, uhi), wi)| {
                let half = r * Interval::point(wi);
                let below = if ulo == f64::NEG_INFINITY {
                    f64::NEG_INFINITY
                } else {
                    (Interval::point(ulo) - (Interval::point(hi[i]) + half)).lo()
                };
                let above = if uhi == f64::INFINITY {
                    f64::NEG_INFINITY
                } else {
                    ((Interval::point(lo[i]) - half) - Interval::point(uhi)).lo()
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
            let (ilo, ihi): (Vec<f64>, Vec<f64>) =
                (0..lo.len()).map(|i| (inf_lo(i), inf_hi(i))).unzip();
            let rad = Interval::point(*radius);
            let m1 = (Interval::point(dist_to_box(states, center, &ilo, &ihi)) - rad).lo();
            let m2 = (Interval::point(dist_to_box(states, center, lo, hi))
                - r * Interval::point(*spread)
                - rad)
                .lo();
            m1.max(m2)
        }
    }
}

/// The first report step and unsafe set at which the deterministic sets of `prs` alone (its
/// own and its members', each without its stochastic radius) are not shown to avoid the set:
/// where no `delta` can make the PRS safe. `None` when they avoid every set at every report
/// time (or a metric cannot be factorised, which leaves nothing to say).
///
/// Each member's margin is computed in its own metric; the intersection's margin is the largest
/// (as for the PRS); a union's limit is its pieces' earliest. Parallelotopes are checked through their hulls (no frame): one-sided like
/// every margin here, so "not shown" rather than "touches".
pub(crate) fn deterministic_limit(
    sets: &[UnsafeSet],
    prs: &crate::prs::Prs,
) -> Option<(usize, usize)> {
    // A union (method.md 8.11): its deterministic sets are the pieces' (its own steps' boxes
    // hold the stochastic part too), so the earliest of the pieces' limits.
    if !prs.pieces.is_empty() {
        return prs
            .pieces
            .iter()
            .filter_map(|p| deterministic_limit(sets, p))
            .min();
    }
    let n = prs.n();
    let members: Vec<&crate::prs::Prs> = std::iter::once(prs).chain(&prs.also).collect();
    let mut checks = Vec::with_capacity(members.len());
    for m in &members {
        let l = linalg::cholesky(&linalg::to_intervals(&m.constants.metric), n)?;
        let diag = linalg::inverse_diagonal(&l, n);
        let w: Vec<f64> = diag.iter().map(|d| d.sqrt().hi()).collect();
        checks.push((Check::all(sets, n, &l, &diag).ok()?, w));
    }
    (0..prs.steps.len()).find_map(|k| {
        (0..sets.len()).find_map(|j| {
            let margin = members
                .iter()
                .zip(&checks)
                .map(|(m, (c, w))| {
                    let context = Context { w, frame: None };
                    // A moving set is checked where the result held it still (8.15).
                    match prs.swept_unsafe(j, k) {
                        Some(shape) => c[j].moved(shape).margin(&m.steps[k].det, 0.0, &context),
                        None => c[j].margin(&m.steps[k].det, 0.0, &context),
                    }
                })
                .fold(f64::NEG_INFINITY, f64::max);
            (margin.is_nan() || margin <= 0.0).then_some((k, j))
        })
    })
}
