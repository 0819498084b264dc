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

use super::error::{SimInvalid, SpanFault};
use super::paths::SMALL;
use crate::interval::Interval;
use crate::lanes::{Real, X8};
use crate::model::Bounds;
use crate::prs::{DetSet, Prepared, Prs};
use crate::sets::parallelotope::ParallelotopeTest;
use crate::sets::zonotope::ZonotopeTest;

/// The quadratic form `d' P d` as a list of terms.
#[derive(Clone, Debug)]
pub(crate) struct Metric {
    /// `(i, j, w)` with `w = P_ii` on the diagonal and `w = P_ij + P_ji` for `i < j` (both
    /// off-diagonal entries, as `contains` uses them); zero terms dropped.
    terms: Vec<(usize, usize, f64)>,
    /// Bound factor of the rounding error of [`quad`](Self::quad), relative to its `abs_sum`.
    gamma: f64,
    /// `P` is diagonal with non-negative entries: every term is non-negative, so the error
    /// bound is relative to `q` itself and the tests reduce to comparisons with per-step
    /// constants.
    nonneg: bool,
    /// `|P_ij|`, `n x n` row-major (for bounds of a box's P-radius).
    abs: Vec<f64>,
    /// That diagonal (when `nonneg`), one entry per state.
    diag: Vec<f64>,
}

impl Metric {
    /// The metric `P`, `n x n` row-major.
    pub(crate) fn new(p: &[f64], n: usize) -> Self {
        let at = |i: usize, j: usize| p[i * n + j];
        let mut terms = Vec::new();
        for i in 0..n {
            if at(i, i) != 0.0 {
                terms.push((i, i, at(i, i)));
            }
            for j in i + 1..n {
                let w = at(i, j) + at(j, i);
                if w != 0.0 {
                    terms.push((i, j, w));
                }
            }
        }
        // Each term: a rounded difference per factor, two products, the doubled weight; then a
        // sum of `terms.len()` values. A factor 4 over the textbook bound covers `contains`'s
        // own (outward-rounded) evaluation.
        let gamma = 4.0 * (terms.len() as f64 + 8.0) * f64::EPSILON;
        let nonneg = terms.iter().all(|&(i, j, w)| i == j && w >= 0.0);
        let diag = (0..n).map(|i| at(i, i)).collect();
        Metric {
            terms,
            gamma,
            nonneg,
            diag,
            abs: p.iter().map(|v| v.abs()).collect(),
        }
    }

    /// The diagonal `w` of `P` when `P` is diagonal and non-negative: then
    /// [`quad`](Self::quad) returns `(q, q)` with `q = diag_quad(w, x, c)`, which callers may
    /// compute themselves, to the same bits.
    pub(crate) fn nonneg_diagonal(&self) -> Option<&[f64]> {
        self.nonneg.then_some(&self.diag[..])
    }

    /// The terms as a dense upper triangle for models with at most [`SMALL`] states: `w[i *
    /// SMALL + j]` for `i <= j`, zero for the dropped terms (see [`quad_small`]).
    pub(crate) fn upper(&self) -> [f64; SMALL * SMALL] {
        let mut w = [0.0; SMALL * SMALL];
        for &(i, j, v) in &self.terms {
            if i < SMALL && j < SMALL {
                w[i * SMALL + j] = v;
            }
        }
        w
    }

    /// `(q, a)`: `q = (x - c)' P (x - c)` and `a = sum |w_ij d_i d_j|` (for the error bound).
    #[inline(always)]
    pub(crate) fn quad(&self, x: &[f64], c: &[f64]) -> (f64, f64) {
        if self.nonneg {
            let q = diag_quad(&self.diag, x, c);
            return (q, q);
        }
        let (mut q, mut a) = (0.0, 0.0);
        for &(i, j, w) in &self.terms {
            let t = w * (x[i] - c[i]) * (x[j] - c[j]);
            q += t;
            a += t.abs();
        }
        (q, a)
    }

    /// [`quad`](Self::quad) of the difference `d(i)` (`d(i) = x_i - c_i` gives `quad(x, c)`),
    /// the terms in the same order.
    /// Generic over [`Real`]: one path's `f64` or eight paths' lanes, the same operations.
    #[inline(always)]
    fn quad_by<T: Real>(&self, d: impl Fn(usize) -> T) -> (T, T) {
        if self.nonneg {
            let q = (0..self.diag.len())
                .map(|i| {
                    let d = d(i);
                    T::from(self.diag[i]) * d * d
                })
                .reduce(|q, t| q + t)
                .unwrap_or(T::from(0.0));
            return (q, q);
        }
        let (mut q, mut a) = (T::from(0.0), T::from(0.0));
        for &(i, j, w) in &self.terms {
            let t = T::from(w) * d(i) * d(j);
            q = q + t;
            a = a + t.abs();
        }
        (q, a)
    }
}

/// `x` moved into `[lo, hi]` (`lo` below, `hi` above, NaN kept: then the difference to `x`
/// is NaN and no shortcut holds). The scalar form of the eight-lane clamp in
/// [`super::avx512`], to the bit.
#[inline(always)]
pub(crate) fn clamp(x: f64, lo: f64, hi: f64) -> f64 {
    if x < lo {
        lo
    } else if x > hi {
        hi
    } else {
        x
    }
}

/// `sum_i w_i (x_i - y_i)^2` with `y = clamp(x, lo, hi)`, in [`diag_quad`]'s order: the squared
/// P-distance of `x` to the box `[lo, hi]` for a non-negative diagonal metric `w` (the clamp is
/// the nearest point), as [`Tube`] and the eight-lane loop compute it.
#[inline(always)]
pub(crate) fn diag_quad_to_box(w: &[f64], x: &[f64], lo: &[f64], hi: &[f64]) -> f64 {
    let n = x.len();
    let (w, lo, hi) = (&w[..n], &lo[..n], &hi[..n]);
    (0..n)
        .map(|i| {
            let d = x[i] - clamp(x[i], lo[i], hi[i]);
            w[i] * d * d
        })
        .reduce(|q, t| q + t)
        .unwrap_or(0.0)
}

/// `sum_i w_i (x_i - c_i)^2` over the states of `x` in order, starting from the first term:
/// [`Metric::quad`] with a non-negative diagonal metric `w` (by state rather than by term, so
/// that a constant dimension unrolls the loop).
#[inline(always)]
pub(crate) fn diag_quad(w: &[f64], x: &[f64], c: &[f64]) -> f64 {
    let (w, c) = (&w[..x.len()], &c[..x.len()]);
    (0..x.len())
        .map(|i| {
            let d = x[i] - c[i];
            w[i] * d * d
        })
        .reduce(|q, t| q + t)
        .unwrap_or(0.0)
}

/// [`Metric::quad`] for at most [`SMALL`] states (`x.len()`), with `w` from [`Metric::upper`]:
/// the same terms in the same order, plus the zero ones, which add `+-0` to finite sums (and
/// cannot make a non-finite sum finite), so `(q, a)` is `quad`'s to the bit when finite and
/// non-finite when it is. Fixed-size weights let a small model's loops unroll. Generic over
/// [`Real`]: one path's `f64` or eight paths' lanes, the same operations.
#[inline(always)]
pub(crate) fn quad_small<T: Real>(w: &[f64; SMALL * SMALL], x: &[T], c: &[f64]) -> (T, T) {
    let n = x.len().min(SMALL);
    let (x, c) = (&x[..n], &c[..n]);
    let (mut q, mut a) = (T::from(0.0), T::from(0.0));
    for i in 0..n {
        let di = x[i] - T::from(c[i]);
        for j in i..n {
            let t = T::from(w[i * SMALL + j]) * di * (x[j] - T::from(c[j]));
            q = q + t;
            a = a + t.abs();
        }
    }
    (q, a)
}

/// The PRS shapes the shortcuts know.
#[derive(Clone, Debug)]
enum Shape {
    PBall,
    /// Per report step, the box's corners (flat, n per step).
    Box {
        lo: Vec<f64>,
        hi: Vec<f64>,
    },
    /// `{x : lo <= T x <= hi}`: `T` (n x n, row-major) and, per report step, the corners of the
    /// box in `y = T x` (flat, n per step).
    Parallelotope {
        t: Vec<f64>,
        lo: Vec<f64>,
        hi: Vec<f64>,
        /// The exact test (`Prs::contains_at`'s), built once.
        exact: Box<ParallelotopeTest>,
    },
    /// `Z_k (+) B_P(remainder + r_t)`: per report step, the test of the zonotope
    /// (`Prs::contains_at`'s, built once; `None` for a box among them, at `t = 0`) and the
    /// radius added to it.
    Zonotope {
        tests: Vec<Option<ZonotopeTest>>,
        radius: Vec<f64>,
    },
    /// Anything else: always ask `contains`.
    Other,
}

impl Shape {
    /// The shape of every step of `result`'s own set (the sets of one result all have one
    /// shape; the members of an intersection, `result.also`, have shapes of their own).
    fn of(result: &Prs) -> Shape {
        let n = result.states.len();
        let all = |f: fn(&DetSet) -> bool| result.steps.iter().all(|s| f(&s.det));
        // The contraction method's set at t = 0 may be the initial box inside its P-ball: the
        // ball's shortcuts then hold for "outside" only (see `Membership::ball`).
        let ball_after_start = result
            .steps
            .iter()
            .skip(1)
            .all(|s| matches!(s.det, DetSet::Ball { .. }))
            && matches!(
                result.steps.first().map(|s| &s.det),
                Some(DetSet::Ball { .. } | DetSet::Box { .. })
            );
        if ball_after_start {
            return Shape::PBall;
        }
        // Zonotopes, and boxes among them (the initial box at t = 0).
        let zonotope = |d: &DetSet| match d {
            DetSet::Zonotope { center, .. } => center.len() == n,
            _ => false,
        };
        if result.steps.iter().any(|s| zonotope(&s.det))
            && all(|d| matches!(d, DetSet::Zonotope { .. } | DetSet::Box { .. }))
        {
            let p = &result.constants.metric;
            return Shape::Zonotope {
                tests: result
                    .steps
                    .iter()
                    .map(|s| match &s.det {
                        DetSet::Zonotope {
                            center, generators, ..
                        } if center.len() == n => Some(ZonotopeTest::new(p, center, generators)),
                        _ => None,
                    })
                    .collect(),
                radius: (0..result.steps.len())
                    .map(|k| result.zonotope_radius(k))
                    .collect(),
            };
        }
        // Every step's box, flat (`n` per step).
        let (mut lo, mut hi) = (Vec::new(), Vec::new());
        for st in &result.steps {
            match st.det.corners() {
                Some((l, h)) if l.len() == n && h.len() == n => {
                    lo.extend_from_slice(l);
                    hi.extend_from_slice(h);
                }
                _ => return Shape::Other,
            }
        }
        if all(|d| matches!(d, DetSet::Box { .. })) {
            return Shape::Box { lo, hi };
        }
        match &result.transform {
            Some(tr) if n > 0 && tr.matrix.len() == n * n => Shape::Parallelotope {
                t: tr.matrix.clone(),
                lo,
                hi,
                exact: Box::new(ParallelotopeTest::new(&result.constants.metric, tr, n)),
            },
            _ => Shape::Other,
        }
    }
}

/// Decides PRS membership at each report step of `result`: in its own set and in those of
/// the members of an intersection (`result.also`, each with its own metric), every set with
/// its own shortcuts.
#[derive(Clone, Debug)]
pub(crate) struct Membership<'a> {
    own: OneSet<'a>,
    /// The members, with their metrics.
    also: Vec<(Metric, OneSet<'a>)>,
    /// A split result's pieces (method.md 8.11), in the result's metric, each with its
    /// bounding boxes per step: the PRS is their union, inside its own bounding box (`own`).
    pieces: Vec<(Hulls, Membership<'a>)>,
}

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

impl<'a> Membership<'a> {
    /// For `result` (its steps), with `metric` built from its metric.
    pub(crate) fn new(result: &'a Prs, metric: &Metric) -> Self {
        let also = members(result, |m, metric| Ok(OneSet::new(m, metric)))
            .expect("building a member's set never fails");
        Membership {
            own: OneSet::new(result, metric),
            also,
            // (The pieces share the analysis' metric.)
            pieces: result
                .pieces
                .iter()
                .map(|p| (Hulls::of(p, |k| p.hull_at(k)), Membership::new(p, metric)))
                .collect(),
        }
    }

    /// `Some(b)`: a squared distance `q < b` (from [`Metric::quad`]) means `x` is in the PRS of
    /// step `k`, found with one comparison (what [`inside`](Self::inside) answers). `None` when
    /// no such bound holds (an intersection, a union, shapes other than the P-ball, metrics with
    /// off-diagonal or negative terms: see [`inside_by_shortcut`](Self::inside_by_shortcut)).
    pub(crate) fn inside_below(&self, k: usize) -> Option<f64> {
        if self.also.is_empty() && self.pieces.is_empty() {
            self.own.inside_below(k)
        } else {
            None
        }
    }

    /// Whether [`inside_by_shortcut`](Self::inside_by_shortcut) can ever answer `true` (never
    /// for a union: its own set is the pieces' bounding box).
    pub(crate) fn has_shortcuts(&self) -> bool {
        self.pieces.is_empty()
            && self.own.has_shortcuts()
            && self.also.iter().all(|(_, s)| s.has_shortcuts())
    }

    /// Whether `x` is, by the shortcuts alone, in the PRS of step `k` (then
    /// [`inside`](Self::inside) is `true`; `false` says nothing). Arguments as for `inside`.
    #[inline(always)]
    pub(crate) fn inside_by_shortcut(
        &self,
        metric: &Metric,
        k: usize,
        x: &[f64],
        q: f64,
        a: f64,
    ) -> bool {
        if !self.pieces.is_empty() || !self.own.inside_by_shortcut(metric, k, x, q, a) {
            return false;
        }
        // A loop rather than `all`, which might not be inlined into the hot loops.
        for (m, s) in &self.also {
            if !s.inside_by_shortcut_with(m, k, x, || m.quad(x, s.centre(k))) {
                return false;
            }
        }
        true
    }

    /// [`inside_by_shortcut`](Self::inside_by_shortcut) of eight states in lanes (state `i` of
    /// path `l` in lane `l` of `x[i]`, `(q, a)` the lanes' `metric.quad`): bit `l` set when
    /// lane `l` is inside by the shortcuts, the same answer as for that state alone.
    #[inline(always)]
    pub(crate) fn inside_by_shortcut_x8(
        &self,
        metric: &Metric,
        k: usize,
        x: &[X8],
        q: X8,
        a: X8,
    ) -> u8 {
        if !self.pieces.is_empty() {
            return 0;
        }
        let mut mask = self.own.inside_by_shortcut_x8(metric, k, x, || (q, a));
        for (m, s) in &self.also {
            if mask == 0 {
                break;
            }
            let c = s.centre(k);
            mask &= s.inside_by_shortcut_x8(m, k, x, || m.quad_by(|i| x[i] - X8::from(c[i])));
        }
        mask
    }

    /// Whether the finite state `x` is in the PRS of step `k`, given the centre `c = x*_k` and
    /// `(q, a) = metric.quad(x, c)`: in every member's set (`Prs::contains_at`'s answer, each
    /// set decided by its shortcuts where they hold).
    #[inline]
    pub(crate) fn inside(
        &self,
        metric: &Metric,
        k: usize,
        x: &[f64],
        c: &[f64],
        q: f64,
        a: f64,
    ) -> bool {
        let at = |m: &Metric, c: &[f64]| {
            let (q, a) = m.quad(x, c);
            // As `record` does for the own metric: rounding can make `q` slightly negative
            // only with off-diagonal terms.
            (if a == q { q } else { q.max(0.0) }, a)
        };
        self.own.inside(metric, k, x, c, q, a)
            && self.also.iter().all(|(m, s)| {
                let c = s.centre(k);
                let (q, a) = at(m, c);
                s.inside(m, k, x, c, q, a)
            })
            && (self.pieces.is_empty()
                || self.pieces.iter().any(|(hulls, p)| {
                    hulls.may_hold(k, x) && {
                        let c = p.own.centre(k);
                        let (q, a) = at(metric, c);
                        p.inside(metric, k, x, c, q, a)
                    }
                }))
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

/// Decides membership in one metric's set at each report step (a result's own set, or one
/// member of an intersection).
#[derive(Clone, Debug)]
struct OneSet<'a> {
    result: &'a Prs,
    shape: Shape,
    /// Squared PRS radius per step.
    r2: Vec<f64>,
    /// With a non-negative diagonal metric: `q` above `q_out[k]` is clearly outside the P-ball,
    /// below `q_in[k]` clearly inside (the error bound solved for `q` once per step).
    q_out: Vec<f64>,
    q_in: Vec<f64>,
    nonneg: bool,
    n: usize,
    /// Per step, whether the set is the whole P-ball of the PRS radius (for [`Shape::PBall`]:
    /// else, the initial box at `t = 0`, only "clearly outside" is decided by the ball).
    ball: Vec<bool>,
    /// Per step, whether the PRS of a box, a parallelotope or a zonotope certainly holds a
    /// P-ball around the set's centre ([`Prs::centre_radius`]: `r_t` when a box or a
    /// parallelotope holds its centre, `remainder + r_t` for a zonotope); that ball's squared
    /// radius and, with a non-negative diagonal metric, its "clearly inside" bound.
    holds: Vec<bool>,
    rt2: Vec<f64>,
    rt_in: Vec<f64>,
}

impl<'a> OneSet<'a> {
    /// For `result`'s own set, with `metric` built from its metric.
    fn new(result: &'a Prs, metric: &Metric) -> Self {
        let n = result.states.len();
        let shape = Shape::of(result);
        let r2: Vec<f64> = result
            .steps
            .iter()
            .map(|s| s.prs_radius * s.prs_radius)
            .collect();
        // q (1 - gamma) > r2 (1 + 8 eps) and q (1 + gamma) < r2 (1 - 8 eps), with 16 eps for
        // the roundings of these two formulas.
        let eps16 = 16.0 * f64::EPSILON;
        let q_out = r2
            .iter()
            .map(|r| r * (1.0 + eps16) / (1.0 - metric.gamma))
            .collect();
        let q_in = r2
            .iter()
            .map(|r| r * (1.0 - eps16) / (1.0 + metric.gamma))
            .collect();
        let ball = result
            .steps
            .iter()
            .map(|s| matches!(s.det, DetSet::Ball { .. }))
            .collect();
        let centre: Vec<Option<f64>> = (0..result.steps.len())
            .map(|k| match shape {
                Shape::Box { .. } | Shape::Parallelotope { .. } | Shape::Zonotope { .. } => {
                    result.centre_radius(k)
                }
                Shape::PBall | Shape::Other => None,
            })
            .collect();
        let holds = centre.iter().map(Option::is_some).collect();
        let rt2: Vec<f64> = centre.iter().map(|r| r.map_or(0.0, |r| r * r)).collect();
        let rt_in = rt2
            .iter()
            .map(|r| r * (1.0 - eps16) / (1.0 + metric.gamma))
            .collect();
        OneSet {
            result,
            shape,
            r2,
            q_out,
            q_in,
            nonneg: metric.nonneg,
            n,
            ball,
            holds,
            rt2,
            rt_in,
        }
    }

    /// `Some(b)`: a squared distance `q < b` (from [`Metric::quad`]) means `x` is in the PRS of
    /// step `k`, found with one comparison (what [`inside`](Self::inside) answers). `None` when
    /// no such bound holds (shapes other than the P-ball, metrics with off-diagonal or negative
    /// terms: see [`inside_by_shortcut`](Self::inside_by_shortcut)).
    fn inside_below(&self, k: usize) -> Option<f64> {
        match self.shape {
            Shape::PBall if self.nonneg && self.ball[k] => Some(self.q_in[k]),
            Shape::PBall if self.nonneg => Some(f64::NEG_INFINITY),
            _ => None,
        }
    }

    /// The centre `x*_k` of step `k`, around which [`Metric::quad`] measures for this set.
    fn centre(&self, k: usize) -> &'a [f64] {
        self.result.steps[k].nominal()
    }

    /// Whether [`inside_by_shortcut`](Self::inside_by_shortcut) can ever answer `true`.
    fn has_shortcuts(&self) -> bool {
        !matches!(self.shape, Shape::Other)
    }

    /// `(clearly outside, clearly inside)` the P-ball of step `k` (see the module's notes).
    #[inline(always)]
    fn clearly(&self, metric: &Metric, k: usize, q: f64, a: f64) -> (bool, bool) {
        let (out, inside) = if self.nonneg {
            (q > self.q_out[k], q < self.q_in[k])
        } else {
            let (r2, err) = (
                self.r2[k],
                metric.gamma * a + 8.0 * f64::EPSILON * self.r2[k],
            );
            (q - err > r2, q + err < r2)
        };
        // Inside the P-ball is inside the set only where the set is that ball.
        let ball = !matches!(self.shape, Shape::PBall) || self.ball[k];
        (out, inside && ball)
    }

    /// Whether `x` is, by one of the shortcuts alone, in the PRS of step `k` (then
    /// [`inside`](Self::inside) is `true`; `false` says nothing). Arguments as for `inside`.
    #[inline(always)]
    fn inside_by_shortcut(&self, metric: &Metric, k: usize, x: &[f64], q: f64, a: f64) -> bool {
        self.inside_by_shortcut_with(metric, k, x, || (q, a))
    }

    /// [`inside_by_shortcut`](Self::inside_by_shortcut) with `(q, a)` computed only if the
    /// shape needs it: a box or a parallelotope is in the PRS, so a state in it is inside
    /// whatever its distance to `x*_k` (for [`Membership`]'s members, which would compute the
    /// distance in their own metric for nothing).
    #[inline(always)]
    fn inside_by_shortcut_with(
        &self,
        metric: &Metric,
        k: usize,
        x: &[f64],
        quad: impl FnOnce() -> (f64, f64),
    ) -> bool {
        match &self.shape {
            Shape::PBall => {
                let (q, a) = quad();
                self.clearly(metric, k, q, a).1
            }
            Shape::Box { lo, hi } => {
                self.in_box(lo, hi, k, x) || self.near_centre_by(metric, k, quad)
            }
            Shape::Parallelotope { t, lo, hi, .. } => {
                self.in_parallelotope(t, lo, hi, k, x) || self.near_centre_by(metric, k, quad)
            }
            Shape::Zonotope { tests, radius } => {
                tests[k].as_ref().is_some_and(|t| t.excess(x) <= radius[k])
                    || self.near_centre_by(metric, k, quad)
            }
            Shape::Other => false,
        }
    }

    /// [`inside_by_shortcut_with`](Self::inside_by_shortcut_with) of eight states in lanes:
    /// bit `l` set when lane `l` is inside by the shortcut, the same answer as for that state
    /// alone (the same operations per lane).
    #[inline(always)]
    fn inside_by_shortcut_x8(
        &self,
        metric: &Metric,
        k: usize,
        x: &[X8],
        quad: impl FnOnce() -> (X8, X8),
    ) -> u8 {
        match &self.shape {
            Shape::PBall => {
                let (q, a) = quad();
                let mut mask = 0;
                for l in 0..8 {
                    mask |= u8::from(self.clearly(metric, k, q.0[l], a.0[l]).1) << l;
                }
                mask
            }
            Shape::Box { lo, hi } => {
                let (lo, hi) = (&lo[k * self.n..][..self.n], &hi[k * self.n..][..self.n]);
                let mut mask = 0xff;
                for ((v, &l), &h) in x.iter().zip(lo).zip(hi) {
                    mask &= lanes(|a| l <= v.0[a] && v.0[a] <= h);
                }
                mask | self.near_centre_x8(metric, k, mask, quad)
            }
            Shape::Parallelotope { t, lo, hi, .. } => {
                let n = self.n;
                let (lo, hi, x) = (&lo[k * n..][..n], &hi[k * n..][..n], &x[..n]);
                let rel = 16.0 * (n as f64 + 2.0) * f64::EPSILON;
                // `in_parallelotope`'s operations, lane by lane.
                let mut mask = 0xff;
                for ((row, &a), &b) in t.chunks_exact(n).zip(lo).zip(hi) {
                    let (mut y, mut s) = (X8::splat(0.0), X8::splat(0.0));
                    for (&tij, &xj) in row.iter().zip(x) {
                        let p = tij * xj;
                        y = y + p;
                        s = s + p.abs();
                    }
                    let margin = rel * s + f64::MIN_POSITIVE;
                    let (below, above) = (y - margin, y + margin);
                    mask &= lanes(|l| a <= below.0[l] && above.0[l] <= b);
                }
                mask | self.near_centre_x8(metric, k, mask, quad)
            }
            Shape::Zonotope { tests, radius } => {
                // `excess`'s operations, lane by lane.
                let mask = tests[k].as_ref().map_or(0, |t| {
                    let (e, r) = (t.excess(&x[..self.n]), radius[k]);
                    lanes(|l| e.0[l] <= r)
                });
                mask | self.near_centre_x8(metric, k, mask, quad)
            }
            Shape::Other => 0,
        }
    }

    /// Whether `(q, a)` (from [`Metric::quad`] around the centre of step `k`) clearly puts
    /// the state in the P-ball around the centre `c` that the PRS holds (see
    /// [`OneSet::holds`]; `Prs::contains_at` asks the same ball).
    #[inline(always)]
    fn near_centre(&self, metric: &Metric, k: usize, q: f64, a: f64) -> bool {
        self.holds[k]
            && if self.nonneg {
                q < self.rt_in[k]
            } else {
                q + (metric.gamma * a + 8.0 * f64::EPSILON * self.rt2[k]) < self.rt2[k]
            }
    }

    /// [`near_centre`](Self::near_centre), with `(q, a)` computed only if the set holds its
    /// centre.
    #[inline(always)]
    fn near_centre_by(&self, metric: &Metric, k: usize, quad: impl FnOnce() -> (f64, f64)) -> bool {
        self.holds[k] && {
            let (q, a) = quad();
            self.near_centre(metric, k, q, a)
        }
    }

    /// [`near_centre`](Self::near_centre) of eight states in lanes, for the lanes not already
    /// in `mask` (`(q, a)` computed only if one is left).
    #[inline(always)]
    fn near_centre_x8(
        &self,
        metric: &Metric,
        k: usize,
        mask: u8,
        quad: impl FnOnce() -> (X8, X8),
    ) -> u8 {
        if mask == 0xff || !self.holds[k] {
            return 0;
        }
        let (q, a) = quad();
        let mut near = 0;
        for l in 0..8 {
            near |= u8::from(self.near_centre(metric, k, q.0[l], a.0[l])) << l;
        }
        near
    }

    /// `T x` clearly in the box `[lo, hi]` of step `k`: then the outward-rounded `T x` that
    /// `contains` computes is in it too. Both that enclosure and the rounded sum here lie
    /// within `(5 n + 1) eps s` of the exact `T x` (`s = sum_j |t_ij x_j|`; one ulp per
    /// operation), so a margin of `16 (n + 2) eps s` covers both and the rounding of the
    /// comparison itself; the smallest normal number covers the subnormal steps of sums near 0.
    #[inline(always)]
    fn in_parallelotope(&self, t: &[f64], lo: &[f64], hi: &[f64], k: usize, x: &[f64]) -> bool {
        let n = self.n;
        let (lo, hi, x) = (&lo[k * n..][..n], &hi[k * n..][..n], &x[..n]);
        let rel = 16.0 * (n as f64 + 2.0) * f64::EPSILON;
        // Loops rather than `all`, which might not be inlined into the hot loops.
        for ((row, &a), &b) in t.chunks_exact(n).zip(lo).zip(hi) {
            let (mut y, mut s) = (0.0, 0.0);
            for (tij, xj) in row.iter().zip(x) {
                let p = tij * xj;
                y += p;
                s += p.abs();
            }
            let margin = rel * s + f64::MIN_POSITIVE;
            if !(a <= y - margin && y + margin <= b) {
                return false;
            }
        }
        true
    }

    /// `x` in the box `[lo, hi]` of step `k`.
    #[inline(always)]
    fn in_box(&self, lo: &[f64], hi: &[f64], k: usize, x: &[f64]) -> bool {
        let (lo, hi) = (&lo[k * self.n..][..self.n], &hi[k * self.n..][..self.n]);
        // A loop rather than `all`, which might not be inlined into the hot loops.
        for ((v, l), h) in x.iter().zip(lo).zip(hi) {
            if !(l <= v && v <= h) {
                return false;
            }
        }
        true
    }

    /// Whether `x` is in the PRS of step `k`, given the centre `c = x*_k` and
    /// `(q, a) = metric.quad(x, c)`.
    #[inline]
    fn inside(&self, metric: &Metric, k: usize, x: &[f64], c: &[f64], q: f64, a: f64) -> bool {
        let (clearly_out, clearly_in) = self.clearly(metric, k, q, a);
        match &self.shape {
            Shape::PBall => {
                if clearly_out {
                    return false;
                }
                // x = x*_t exactly (a point initial set at t = 0, where the radius may be 0):
                // `contains` finds |x - x*_t|_P = 0 exactly.
                if clearly_in || (q == 0.0 && x == c) {
                    return true;
                }
            }
            Shape::Box { lo, hi } => {
                if clearly_out {
                    return false;
                }
                if self.in_box(lo, hi, k, x) || self.near_centre(metric, k, q, a) {
                    return true;
                }
            }
            Shape::Parallelotope { t, lo, hi, exact } => {
                if clearly_out {
                    return false;
                }
                if self.in_parallelotope(t, lo, hi, k, x) {
                    return true;
                }
                if self.near_centre(metric, k, q, a) {
                    return true;
                }
                return self.result.own_contains_at_with(
                    k,
                    x,
                    Some(Prepared::Parallelotope(exact)),
                );
            }
            Shape::Zonotope { tests, .. } => {
                if clearly_out {
                    return false;
                }
                // The zonotope's own test starts with the shortcut's bound.
                if self.near_centre(metric, k, q, a) {
                    return true;
                }
                let test = tests[k].as_ref().map(Prepared::Zonotope);
                return self.result.own_contains_at_with(k, x, test);
            }
            Shape::Other => {}
        }
        self.result.own_contains_at(k, x)
    }
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

/// Decides membership in the spans of a time-uniform result (see the module's notes): the
/// state of every Euler-Maruyama step of report interval `k` against [`Step::span`] `k`
/// (`k = 0`: the initial state against the PRS at 0).
///
/// [`Step::span`]: crate::prs::Step::span
#[derive(Clone, Debug)]
pub(crate) struct Tube<'a> {
    own: OneSpan<'a>,
    /// The spans of the members of an intersection (`result.also`), with their metrics: a
    /// state is in the tube when it is in every member's span.
    also: Vec<(Metric, OneSpan<'a>)>,
    /// A split result's pieces' tubes (method.md 8.11), in the result's metric, each with the
    /// bounding boxes of its spans: a state is in the union's tube when it is in some piece's
    /// (and in `own`, their bounding box).
    pieces: Vec<(Hulls, Tube<'a>)>,
}

impl<'a> Tube<'a> {
    /// The tube of `result`'s spans, with `metric` built from its metric; `Err` when a span is
    /// malformed (a corner of the wrong length, NaN, `lo > hi`, a negative or NaN radius).
    pub(crate) fn new(result: &'a Prs, metric: &Metric) -> Result<Tube<'a>, SimInvalid> {
        let also = members(result, OneSpan::new)?;
        Ok(Tube {
            own: OneSpan::new(result, metric)?,
            also,
            pieces: result
                .pieces
                .iter()
                .map(|p| {
                    Ok((
                        Hulls::of(p, |k| p.own_span_hull_at(k)),
                        Tube::new(p, metric)?,
                    ))
                })
                .collect::<Result<_, SimInvalid>>()?,
        })
    }

    /// The box and the "clearly inside" bound of step `k` for the caller's own
    /// [`diag_quad_to_box`] (non-negative diagonal metrics): `(lo, hi, q_in)`. With the members
    /// of an intersection the own span's distance proves nothing alone: `q_in` is `-inf`, and
    /// every state goes to [`inside_slow`](Self::inside_slow).
    #[inline(always)]
    pub(crate) fn diag_bounds(&self, k: usize) -> (&[f64], &[f64], f64) {
        let (lo, hi, q_in) = self.own.diag_bounds(k);
        let q_in = if self.also.is_empty() && self.pieces.is_empty() {
            q_in
        } else {
            f64::NEG_INFINITY
        };
        (lo, hi, q_in)
    }

    /// Whether `x` is, by the "inside" shortcuts alone, in the span of step `k` of every member
    /// (then [`inside`](Self::inside) is `true`; `false` says nothing). Alone and with a
    /// non-negative diagonal metric, the same as `diag_quad_to_box(w, x, lo, hi) < q_in` with
    /// [`diag_bounds`](Self::diag_bounds).
    #[inline(always)]
    pub(crate) fn inside_by_shortcut(&self, metric: &Metric, k: usize, x: &[f64]) -> bool {
        self.pieces.is_empty()
            && self.own.inside_by_shortcut(metric, k, x)
            && self.also.iter().all(|(m, s)| s.inside_by_shortcut(m, k, x))
    }

    /// Whether `x` lies in the span of step `k`: the shortcuts, then [`Prs::span_contains`];
    /// `true` only if certainly.
    #[cfg(test)]
    pub(crate) fn inside(&self, metric: &Metric, k: usize, x: &[f64]) -> bool {
        self.inside_by_shortcut(metric, k, x) || self.inside_slow(metric, k, x)
    }

    /// [`inside_by_shortcut`](Self::inside_by_shortcut) of eight states in lanes (state `i` of
    /// path `l` in lane `l` of `x[i]`): bit `l` set when lane `l` is inside by the shortcuts,
    /// the same answer as for that state alone.
    #[inline(always)]
    pub(crate) fn inside_by_shortcut_x8(&self, metric: &Metric, k: usize, x: &[X8]) -> u8 {
        if !self.pieces.is_empty() {
            return 0;
        }
        let mut mask = self.own.inside_by_shortcut_x8(metric, k, x);
        for (m, s) in &self.also {
            mask &= s.inside_by_shortcut_x8(m, k, x);
        }
        mask
    }

    /// [`inside`](Self::inside) for a state the shortcut did not find inside (the same answer
    /// then): [`Prs::span_contains`]'s, member by member, each decided by its own shortcuts
    /// where they hold.
    #[cold]
    #[inline(never)]
    pub(crate) fn inside_slow(&self, metric: &Metric, k: usize, x: &[f64]) -> bool {
        if !x.iter().all(|v| v.is_finite()) {
            return false;
        }
        self.own.decide(metric, k, x)
            && self.also.iter().all(|(m, s)| s.decide(m, k, x))
            && (self.pieces.is_empty()
                || self
                    .pieces
                    .iter()
                    .any(|(hulls, p)| hulls.may_hold(k, x) && p.inside_slow(metric, k, x)))
    }
}

/// The spans of one metric's set (a result's own, or one member of an intersection).
#[derive(Clone, Debug)]
struct OneSpan<'a> {
    result: &'a Prs,
    n: usize,
    /// Per report step, the span's box, flat (`n` per step).
    lo: Vec<f64>,
    hi: Vec<f64>,
    /// Per step, the squared radius of the span's ball.
    r2: Vec<f64>,
    /// With a non-negative diagonal metric: a squared distance to the box
    /// ([`diag_quad_to_box`]) below `q_in[k]` is clearly inside, above `q_out[k]` clearly
    /// outside.
    q_in: Vec<f64>,
    q_out: Vec<f64>,
    /// Other metrics: per step, the centre of the box (flat) and an upper bound of the squared
    /// radius of a P-ball around it holding the span (`inf` when there is none).
    centre: Vec<f64>,
    outer2: Vec<f64>,
    nonneg: bool,
}

impl<'a> OneSpan<'a> {
    /// The spans of `result`'s own set, with `metric` built from its metric; `Err` as for
    /// [`Tube::new`].
    fn new(result: &'a Prs, metric: &Metric) -> Result<OneSpan<'a>, SimInvalid> {
        let n = result.states.len();
        let steps = result.steps.len();
        let mut tube = OneSpan {
            result,
            n,
            lo: Vec::with_capacity(n * steps),
            hi: Vec::with_capacity(n * steps),
            r2: Vec::with_capacity(steps),
            q_in: Vec::with_capacity(steps),
            q_out: Vec::with_capacity(steps),
            centre: Vec::with_capacity(n * steps),
            outer2: Vec::with_capacity(steps),
            nonneg: metric.nonneg,
        };
        let eps16 = 16.0 * f64::EPSILON;
        for (k, st) in result.steps.iter().enumerate() {
            let s = &st.span;
            let bad = |fault| Err(SimInvalid::Span { step: k, fault });
            if s.lo.len() != n || s.hi.len() != n {
                return bad(SpanFault::Dimension);
            }
            if s.lo
                .iter()
                .zip(&s.hi)
                .any(|(l, h)| l.is_nan() || h.is_nan() || l > h)
            {
                return bad(SpanFault::Corners);
            }
            if s.radius.is_nan() || s.radius < 0.0 {
                return bad(SpanFault::Radius(s.radius));
            }
            tube.lo.extend_from_slice(&s.lo);
            tube.hi.extend_from_slice(&s.hi);
            // As in `Membership::new`: the error bound solved for q once per step.
            let r2 = s.radius * s.radius;
            tube.r2.push(r2);
            tube.q_in.push(r2 * (1.0 - eps16) / (1.0 + metric.gamma));
            tube.q_out.push(r2 * (1.0 + eps16) / (1.0 - metric.gamma));
            // A ball around the box's centre holding the span: radius + b, with
            // b^2 <= sum_ij |P_ij| h_i h_j and h_i >= |y_i - c_i| over the box, all rounded up.
            let centre: Vec<f64> =
                s.lo.iter()
                    .zip(&s.hi)
                    .map(|(l, h)| l + (h - l) / 2.0)
                    .collect();
            let half: Vec<Interval> = (0..n)
                .map(|i| {
                    let c = Interval::point(centre[i]);
                    let up = (Interval::point(s.hi[i]) - c).hi();
                    let down = (c - Interval::point(s.lo[i])).hi();
                    Interval::point(up.max(down))
                })
                .collect();
            let mut b2 = Interval::ZERO;
            for i in 0..n {
                for j in 0..n {
                    b2 += Interval::point(metric.abs[i * n + j]) * half[i] * half[j];
                }
            }
            let outer = Interval::point(s.radius) + b2.sqrt();
            let outer2 = outer.sqr().hi();
            let finite = centre.iter().all(|c| c.is_finite()) && outer2.is_finite();
            tube.outer2
                .push(if finite { outer2 } else { f64::INFINITY });
            tube.centre
                .extend(centre.iter().map(|&c| if finite { c } else { 0.0 }));
        }
        Ok(tube)
    }

    /// The box and the "clearly inside" bound of step `k`: `(lo, hi, q_in)`.
    #[inline(always)]
    fn diag_bounds(&self, k: usize) -> (&[f64], &[f64], f64) {
        let n = self.n;
        (&self.lo[k * n..][..n], &self.hi[k * n..][..n], self.q_in[k])
    }

    /// `(q, a)` of [`Metric::quad`] for `x` and its clamp into the box of step `k` (one path,
    /// or eight in lanes).
    #[inline(always)]
    fn quad_to_box<T: Real>(&self, metric: &Metric, k: usize, x: &[T]) -> (T, T) {
        let (lo, hi, _) = self.diag_bounds(k);
        let d = |i: usize| x[i] - x[i].clamp_with(|v| clamp(v, lo[i], hi[i]));
        if x.len() <= SMALL {
            // Each difference once (the terms use each several times; the same bits).
            // A loop rather than `array::from_fn`, whose closure is not inlined here.
            let mut ds = [T::from(0.0); SMALL];
            for (i, di) in ds.iter_mut().enumerate().take(x.len()) {
                *di = d(i);
            }
            metric.quad_by(|i| ds[i])
        } else {
            metric.quad_by(d)
        }
    }

    /// Whether `x` is, by the "inside" shortcut alone, in the span of step `k` (`false` says
    /// nothing).
    #[inline(always)]
    fn inside_by_shortcut(&self, metric: &Metric, k: usize, x: &[f64]) -> bool {
        self.in_box(k, x, |x| x) || {
            let (q, a) = self.quad_to_box(metric, k, x);
            self.close(metric, k, q, a)
        }
    }

    /// [`inside_by_shortcut`](Self::inside_by_shortcut) of eight states in lanes (state `i` of
    /// lane `l` in lane `l` of `x[i]`): bit `l` set when lane `l` is inside, the same answer
    /// as for that state alone.
    #[inline(always)]
    fn inside_by_shortcut_x8(&self, metric: &Metric, k: usize, x: &[X8]) -> u8 {
        let (q, a) = self.quad_to_box(metric, k, x);
        // A loop rather than a closure or iterator adapters, which might not be inlined into
        // the vector loop (and would then work on the lanes one by one).
        let mut mask = 0;
        for l in 0..8 {
            let inside = self.in_box(k, x, |x| x.0[l]) || self.close(metric, k, q.0[l], a.0[l]);
            mask |= u8::from(inside) << l;
        }
        mask
    }

    /// Whether the state `(at(x[i]))_i` is in the box of step `k` (which the span holds): most
    /// states of an interval box's span, and the states at t = 0 of an interval analysis, whose
    /// span there is the initial box with radius 0.
    #[inline(always)]
    fn in_box<T: Copy>(&self, k: usize, x: &[T], at: impl Fn(T) -> f64) -> bool {
        let (lo, hi, _) = self.diag_bounds(k);
        for i in 0..self.n {
            if !(lo[i] <= at(x[i]) && at(x[i]) <= hi[i]) {
                return false;
            }
        }
        true
    }

    /// Whether `(q, a)` of [`quad_to_box`](Self::quad_to_box) clearly puts the state in the
    /// span of step `k`.
    #[inline(always)]
    fn close(&self, metric: &Metric, k: usize, q: f64, a: f64) -> bool {
        if self.nonneg {
            q < self.q_in[k]
        } else {
            q + (metric.gamma * a + 8.0 * f64::EPSILON * self.r2[k]) < self.r2[k]
        }
    }

    /// Whether the finite state `x` lies in the span of step `k` ([`Prs::own_span_contains`]'s
    /// answer): the shortcuts, then that test.
    fn decide(&self, metric: &Metric, k: usize, x: &[f64]) -> bool {
        if self.inside_by_shortcut(metric, k, x) {
            return true;
        }
        let clearly_out = if self.nonneg {
            self.quad_to_box(metric, k, x).0 > self.q_out[k]
        } else {
            let c = &self.centre[k * self.n..][..self.n];
            let (q, a) = metric.quad(x, c);
            let o2 = self.outer2[k];
            q - (metric.gamma * a + 8.0 * f64::EPSILON * o2) > o2
        };
        !clearly_out && self.result.own_span_contains(k, x)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::engine;
    use crate::interval::Interval;
    use crate::model::*;
    use crate::prs::TransformUsed;
    use crate::sets::zonotope;
    use crate::simulate::rng::PathRng;
    use crate::system::System;
    use crate::test_support::models::model;
    use crate::test_support::rng::box_muller;
    use crate::test_support::sets::zonotope_in_box;

    /// `dx = A x dt + 0.2 dW` with a non-symmetric stable `A`.
    struct Sys;

    const A: [f64; 4] = [-1.0, 0.5, -0.3, -0.8];

    impl System for Sys {
        fn n(&self) -> usize {
            2
        }
        fn p(&self) -> usize {
            0
        }
        fn m(&self) -> usize {
            2
        }
        fn drift(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
            out[0] = A[0] * x[0] + A[1] * x[1];
            out[1] = A[2] * x[0] + A[3] * x[1];
        }
        fn drift_interval(
            &self,
            x: &[Interval],
            _u: &[Interval],
            _t: Interval,
            o: &mut [Interval],
        ) {
            let p = Interval::point;
            o[0] = p(A[0]) * x[0] + p(A[1]) * x[1];
            o[1] = p(A[2]) * x[0] + p(A[3]) * x[1];
        }
        fn jac_x(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
            out.copy_from_slice(&A);
        }
        fn jac_x_interval(
            &self,
            _x: &[Interval],
            _u: &[Interval],
            _t: Interval,
            o: &mut [Interval],
        ) {
            for (o, a) in o.iter_mut().zip(A) {
                *o = Interval::point(a);
            }
        }
        fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, _out: &mut [f64]) {}
        fn jac_u_interval(
            &self,
            _x: &[Interval],
            _u: &[Interval],
            _t: Interval,
            _o: &mut [Interval],
        ) {
        }
        fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
            out.copy_from_slice(&[0.2, 0.0, 0.0, 0.2]);
        }
        fn diffusion_interval(&self, _x: &[Interval], _t: Interval, o: &mut [Interval]) {
            for (o, g) in o.iter_mut().zip([0.2, 0.0, 0.0, 0.2]) {
                *o = Interval::point(g);
            }
        }
    }

    /// The result of `method` with `metric`; `members`: with the members of its intersection
    /// (a contraction run's interval box, method.md 8.7), else its own set alone.
    fn result(method: Method, metric: Vec<f64>, members: bool) -> Prs {
        let info = model("m", &["x", "y"], &["w1", "w2"], &[(0.9, 1.1), (-0.1, 0.2)]);
        let analysis = Analysis {
            spec: AnalysisSpec {
                name: "a".into(),
                method,
                delta: 0.01,
                horizon: 1.0,
                step: 0.1,
                ..AnalysisSpec::default()
            },
            // Valid for P = I and for the skewed P below (generous c, sigma).
            constants: Ok(Constants::given(&info, metric, -0.2, 0.5, 0.0)),
        };
        let mut r = engine::run_paired(&Sys, &info, &analysis).unwrap();
        if members {
            assert!(!r.also.is_empty(), "{method:?}: an intersection");
        } else {
            r.also.clear();
        }
        r
    }

    /// The interval method's box result turned into a parallelotope `{x : lo <= T x <= hi}`
    /// inside each box (the pendulum's `T`), so that the box's enclosing P-ball still holds it.
    fn parallelotope(metric: Vec<f64>) -> Prs {
        let mut r = result(Method::Interval, metric, false);
        let t = [[1.0, 0.2], [1.0, 0.0]];
        r.transform = Some(TransformUsed {
            matrix: t.concat(),
            inverse: vec![0.0, 1.0, 5.0, -5.0],
            inverse_error: 1e-15,
            source: TransformSource::Given,
        });
        for st in &mut r.steps {
            let DetSet::Box {
                lo,
                hi,
                center,
                radius,
            } = st.det.clone()
            else {
                panic!("a box")
            };
            // T^-1 = [[0, 1], [5, -5]] maps a y-box of half-width e into x within 10 e.
            let e = (0..2).map(|i| hi[i] - lo[i]).fold(f64::INFINITY, f64::min) / 40.0;
            let y: Vec<f64> = t
                .iter()
                .map(|row| row[0] * center[0] + row[1] * center[1])
                .collect();
            st.det = DetSet::Parallelotope {
                lo: y.iter().map(|v| v - e).collect(),
                hi: y.iter().map(|v| v + e).collect(),
                hull_lo: lo,
                hull_hi: hi,
                center,
                radius,
            };
        }
        r
    }

    /// Generators of [`zonotope`] in units of the box's half-widths: two (a basis), three (a
    /// basis among them) and one (a flat zonotope: no basis).
    pub(in crate::simulate) const SQUARE: &[[f64; 2]] = &[[0.6, 0.3], [-0.3, 0.6]];
    const THREE: &[[f64; 2]] = &[[0.5, 0.2], [-0.2, 0.5], [0.2, -0.25]];
    const FLAT: &[[f64; 2]] = &[[0.7, 0.5]];

    /// The interval method's box result with each box replaced by a zonotope around its centre
    /// (generators `gens` in units of the box's half-widths, so inside the box) plus a
    /// remainder of `remainder r_t`, with the radii that hold it.
    fn zonotope(metric: Vec<f64>, gens: &[[f64; 2]], remainder: f64) -> Prs {
        boxes_to_zonotopes(result(Method::Interval, metric, false), gens, remainder)
    }

    /// [`zonotope`] of any box result `r` in two states.
    pub(in crate::simulate) fn boxes_to_zonotopes(
        mut r: Prs,
        gens: &[[f64; 2]],
        remainder: f64,
    ) -> Prs {
        let p = r.constants.metric.clone();
        for st in &mut r.steps {
            let (lo, hi) = st.det.box_hull().expect("a box");
            let (center, generators) = zonotope_in_box(lo, hi, gens);
            let (hull_lo, hull_hi) = zonotope::hull(&center, &generators);
            let remainder = remainder * st.r_t;
            let up = |a: f64, b: f64| (Interval::point(a) + Interval::point(b)).hi();
            let radius = up(zonotope::p_radius(&p, 2, &generators), remainder);
            st.prs_radius = up(radius, st.r_t);
            st.det = DetSet::Zonotope {
                center,
                generators,
                remainder,
                hull_lo,
                hull_hi,
                radius,
            };
        }
        r
    }

    /// Zonotope results for `metric`: [`zonotope`] with each set of generators (the three
    /// generators' also with the initial box at `t = 0`), and the contraction method's ball cut
    /// by a zonotope member (an intersection).
    fn zonotopes(metric: &[f64]) -> Vec<(&'static str, Prs)> {
        let mut cut = result(Method::Contraction, metric.to_vec(), false);
        cut.also.push(zonotope(metric.to_vec(), SQUARE, 0.3));
        let mut boxed = zonotope(metric.to_vec(), THREE, 0.5);
        boxed.steps[0] = result(Method::Interval, metric.to_vec(), false).steps[0].clone();
        vec![
            ("square", zonotope(metric.to_vec(), SQUARE, 0.5)),
            ("box at t = 0", boxed),
            ("three", zonotope(metric.to_vec(), THREE, 0.2)),
            ("flat", zonotope(metric.to_vec(), FLAT, 1.0)),
            ("member", cut),
        ]
    }

    /// The lanes' shortcut (`inside_by_shortcut_x8`) against the scalar one, state by state:
    /// eight states at a time from `xs`, distances around `c`.
    fn lanes_agree(mem: &Membership<'_>, m: &Metric, k: usize, c: &[f64], xs: &[[f64; 2]]) {
        for chunk in xs.chunks_exact(8) {
            let x8: Vec<X8> = (0..2)
                .map(|i| X8(std::array::from_fn(|l| chunk[l][i])))
                .collect();
            let (q, a) = quad_small(&m.upper(), &x8, c);
            let mask = mem.inside_by_shortcut_x8(m, k, &x8, q, a);
            for (l, x) in chunk.iter().enumerate() {
                let (q, a) = m.quad(x, c);
                let one = mem.inside_by_shortcut(m, k, x, q, a);
                assert_eq!(mask >> l & 1 == 1, one, "k = {k}, lane {l}, x = {x:?}");
            }
        }
    }

    /// States in and around the P-ball of radius `1.5 r_t` about the centre of each step, for
    /// boxes and parallelotopes: the ball of radius `r_t` decides many of those outside the
    /// deterministic set (`near_centre`), and every shortcut, in lanes or alone, agrees with
    /// `Prs::contains_at`.
    #[test]
    fn the_ball_around_the_centre_decides_states_outside_the_set() {
        let mut rng = PathRng::new(8, 0);
        let mut by_ball = 0;
        for metric in [vec![1.0, 0.0, 0.0, 1.0], vec![2.0, 0.7, 0.7, 1.0]] {
            for r in [
                parallelotope(metric.clone()),
                result(Method::Interval, metric.clone(), false),
            ] {
                let m = Metric::new(&r.constants.metric, 2);
                let mem = Membership::new(&r, &m);
                for (k, st) in r.steps.iter().enumerate() {
                    let c = st.nominal();
                    let mut xs = Vec::new();
                    for _ in 0..400 {
                        let dir = [rng.uniform() - 0.5, rng.uniform() - 0.5];
                        let (q1, _) = m.quad(&[c[0] + dir[0], c[1] + dir[1]], c);
                        let scale = 1.5 * rng.uniform() * st.r_t / q1.sqrt();
                        let x = [c[0] + scale * dir[0], c[1] + scale * dir[1]];
                        let (q, a) = m.quad(&x, c);
                        let exact = r.contains_at(k, &x);
                        assert_eq!(mem.inside(&m, k, &x, c, q, a), exact, "k = {k}");
                        if mem.inside_by_shortcut(&m, k, &x, q, a) {
                            assert!(exact, "k = {k}: shortcut");
                            let (lo, hi) = st.det.corners().expect("corners");
                            let y = match &r.transform {
                                Some(_) => [x[0] + 0.2 * x[1], x[0]],
                                None => x,
                            };
                            if (0..2).any(|i| y[i] < lo[i] || y[i] > hi[i]) {
                                by_ball += 1;
                            }
                        }
                        xs.push(x);
                    }
                    lanes_agree(&mem, &m, k, c, &xs);
                }
            }
        }
        // Not vacuous.
        assert!(by_ball > 1000, "{by_ball}");
    }

    /// Points near the faces of the parallelotopes, just inside and just outside: the
    /// shortcut's "inside" always agrees with `Prs::contains_at`.
    #[test]
    fn the_parallelotope_shortcut_agrees_with_contains() {
        let mut rng = PathRng::new(6, 0);
        let mut shortcut = 0;
        for metric in [vec![1.0, 0.0, 0.0, 1.0], vec![2.0, 0.7, 0.7, 1.0]] {
            let r = parallelotope(metric);
            let m = Metric::new(&r.constants.metric, 2);
            let mem = Membership::new(&r, &m);
            assert!(mem.has_shortcuts());
            for (k, st) in r.steps.iter().enumerate() {
                let DetSet::Parallelotope { lo, hi, .. } = &st.det else {
                    panic!("a parallelotope")
                };
                let mut xs = Vec::new();
                for i in 0..400 {
                    // y uniform in the box, then one coordinate moved to a face, off by a few
                    // ulps to a relative 1e-6 either way.
                    let mut y: Vec<f64> = (0..2)
                        .map(|j| lo[j] + (hi[j] - lo[j]) * rng.uniform())
                        .collect();
                    let j = i % 2;
                    let face = if rng.uniform() < 0.5 { lo[j] } else { hi[j] };
                    let off = (rng.uniform() - 0.5) * [1e-15, 1e-12, 1e-6, 0.0][i / 2 % 4];
                    y[j] = face * (1.0 + off);
                    let x = [y[1], 5.0 * (y[0] - y[1])];
                    xs.push(x);
                    let (q, a) = m.quad(&x, st.nominal());
                    let exact = r.contains_at(k, &x);
                    assert_eq!(mem.inside(&m, k, &x, st.nominal(), q, a), exact, "k = {k}");
                    if mem.inside_by_shortcut(&m, k, &x, q, a) {
                        assert!(exact, "k = {k}: shortcut");
                        shortcut += 1;
                    }
                }
                lanes_agree(&mem, &m, k, st.nominal(), &xs);
            }
        }
        // Not vacuous: points off the faces by 1e-6 are decided by the shortcut.
        assert!(shortcut > 500, "{shortcut}");
    }

    /// Points around every span (a random point of its box moved in a random direction by a
    /// P-distance from far inside to far outside the span's radius, many within rounding of
    /// the boundary, and points moved off a face of the box): the tube's decision is
    /// `Prs::span_contains`'s, its shortcut never calls a point inside that `span_contains`
    /// does not, and it decides most points. Non-finite points are outside.
    #[test]
    fn the_tube_agrees_with_span_contains() {
        let mut rng = PathRng::new(7, 0);
        for (method, metric, members) in methods_and_metrics() {
            let r = result(method, metric, members);
            let m = Metric::new(&r.constants.metric, 2);
            let tube = Tube::new(&r, &m).unwrap();
            let (mut shortcut, mut inside, mut points) = (0, 0, 0);
            for (k, st) in r.steps.iter().enumerate() {
                let span = &st.span;
                assert!(span.radius > 0.0 || k == 0);
                for i in 0..400 {
                    let y: Vec<f64> = (0..2)
                        .map(|j| span.lo[j] + (span.hi[j] - span.lo[j]) * rng.uniform())
                        .collect();
                    let dir = [rng.uniform() - 0.5, rng.uniform() - 0.5];
                    let (q1, _) = m.quad(&dir, &[0.0, 0.0]);
                    let s = match i % 4 {
                        0 => 1.0 + (rng.uniform() - 0.5) * 1e-12,
                        1 => 1.0 + (rng.uniform() - 0.5) * 1e-6,
                        2 => rng.uniform() * 2.0,
                        _ => 0.9 + rng.uniform() * 0.2,
                    };
                    let scale = s * span.radius / q1.sqrt();
                    let mut x = [y[0] + scale * dir[0], y[1] + scale * dir[1]];
                    if i % 8 == 7 {
                        // Straight off a face, at about the radius.
                        let j = i / 8 % 2;
                        x = [y[0], y[1]];
                        x[j] = span.hi[j] + s * span.radius / m.diag[j].sqrt();
                    }
                    let exact = r.span_contains(k, &x);
                    assert_eq!(tube.inside(&m, k, &x), exact, "{method:?} k = {k} s = {s}");
                    if tube.inside_by_shortcut(&m, k, &x) {
                        assert!(exact, "{method:?} k = {k} s = {s}: shortcut");
                        shortcut += 1;
                    }
                    inside += u64::from(exact);
                    points += 1;
                }
                for x in [
                    [f64::NAN, 0.0],
                    [f64::INFINITY, 0.0],
                    [0.0, f64::NEG_INFINITY],
                ] {
                    assert!(!tube.inside(&m, k, &x));
                }
            }
            // Not vacuous: points on both sides, and most of those inside found by the
            // shortcut (the rest are within 1e-6 of the boundary, or, for the skewed metric,
            // where the box point nearest in |.|_P is not the clamp).
            eprintln!("{method:?}: {shortcut} by the shortcut, {inside} inside, {points} points");
            assert!(
                inside > points / 4 && inside < points * 9 / 10,
                "{inside} of {points}"
            );
            assert!(shortcut > inside / 2, "{method:?}: {shortcut} of {inside}");
        }
    }

    /// Both methods, each with the identity and a skewed metric; the contraction method's
    /// set alone and as the intersection with its interval box (`true`).
    fn methods_and_metrics() -> [(Method, Vec<f64>, bool); 6] {
        let (identity, skewed) = (vec![1.0, 0.0, 0.0, 1.0], vec![2.0, 0.7, 0.7, 1.0]);
        [
            (Method::Contraction, identity.clone(), false),
            (Method::Contraction, skewed.clone(), false),
            (Method::Contraction, identity.clone(), true),
            (Method::Contraction, skewed.clone(), true),
            (Method::Interval, identity, false),
            (Method::Interval, skewed, false),
        ]
    }

    /// Points at relative P-distances from far inside to far outside, many within rounding of
    /// the boundary: the shortcuts never disagree with `Prs::contains_at`, for every shape
    /// (the zonotopes of [`zonotopes`] too).
    #[test]
    fn shortcuts_agree_with_contains() {
        let mut rng = PathRng::new(5, 0);
        let zonotopes = [vec![1.0, 0.0, 0.0, 1.0], vec![2.0, 0.7, 0.7, 1.0]]
            .iter()
            .flat_map(|metric| zonotopes(metric))
            .map(|(name, r)| (format!("zonotope {name}"), r))
            .collect::<Vec<_>>();
        let cases = methods_and_metrics()
            .into_iter()
            .map(|(method, metric, members)| {
                (format!("{method:?}"), result(method, metric, members))
            })
            .chain(zonotopes);
        for (case, r) in cases {
            let m = Metric::new(&r.constants.metric, 2);
            let mem = Membership::new(&r, &m);
            for (k, st) in r.steps.iter().enumerate() {
                let c = st.nominal();
                let mut xs = Vec::new();
                for i in 0..400 {
                    // A random direction, scaled to a P-distance s * prs_radius.
                    let dir = [rng.uniform() - 0.5, rng.uniform() - 0.5];
                    let (q1, _) = m.quad(&[c[0] + dir[0], c[1] + dir[1]], c);
                    let s = match i % 4 {
                        0 => 1.0 + (rng.uniform() - 0.5) * 1e-12,
                        1 => 1.0 + (rng.uniform() - 0.5) * 1e-6,
                        2 => rng.uniform() * 2.0,
                        _ => 0.9 + rng.uniform() * 0.2,
                    };
                    let scale = s * st.prs_radius / q1.sqrt();
                    let x = [c[0] + scale * dir[0], c[1] + scale * dir[1]];
                    xs.push(x);
                    let (q, a) = m.quad(&x, c);
                    assert_eq!((q, a), quad_small(&m.upper(), &x, c));
                    let fast = mem.inside(&m, k, &x, c, q, a);
                    let exact = r.contains_at(k, &x);
                    assert_eq!(fast, exact, "{case} k = {k} s = {s}");
                    if mem.inside_by_shortcut(&m, k, &x, q, a)
                        || mem.inside_below(k).is_some_and(|b| q < b)
                    {
                        assert!(exact, "{case} k = {k} s = {s}: shortcut");
                    }
                }
                lanes_agree(&mem, &m, k, c, &xs);
            }
        }
    }

    /// Points `c + G xi + w` around every zonotope of [`zonotopes`]: `xi` in the cube with one
    /// coordinate at a face, off by a few ulps to a relative 1e-6 either way or well beyond,
    /// and `w` of P-norm from 0 to 1.5 times `remainder + r_t`. Every decision (alone, in
    /// lanes, by the shortcut) agrees with `Prs::contains_at`; the shortcut decides most of the
    /// states inside, and `contains_at` finds the states built inside (by a relative 1e-9 of
    /// the radius) inside (at `t = 0`, where the radius is 0, those of the basis'
    /// parallelotope; the flat zonotope has no basis, and its shortcut is the ball around the
    /// centre alone).
    #[test]
    fn the_zonotope_shortcut_agrees_with_contains() {
        let mut rng = PathRng::new(9, 0);
        for metric in [vec![1.0, 0.0, 0.0, 1.0], vec![2.0, 0.7, 0.7, 1.0]] {
            for (name, r) in zonotopes(&metric) {
                let m = Metric::new(&r.constants.metric, 2);
                let mem = Membership::new(&r, &m);
                assert!(mem.has_shortcuts(), "{name}");
                let z = r.also.first().unwrap_or(&r);
                let zm = Metric::new(&z.constants.metric, 2);
                let (mut built_in, mut found_in, mut by_shortcut, mut inside) = (0, 0, 0, 0);
                for (k, st) in z.steps.iter().enumerate() {
                    let DetSet::Zonotope {
                        center,
                        generators,
                        remainder,
                        ..
                    } = &st.det
                    else {
                        // The initial box (shortcuts_agree_with_contains checks it).
                        continue;
                    };
                    let radius = remainder + st.r_t;
                    let gens: Vec<&[f64]> = generators.chunks(2).collect();
                    let c = r.steps[k].nominal();
                    let mut xs = Vec::new();
                    for i in 0..400 {
                        let mut xi: Vec<f64> =
                            gens.iter().map(|_| 2.0 * rng.uniform() - 1.0).collect();
                        let j = i % gens.len();
                        let face = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
                        let off = [1e-15, 1e-12, 1e-6, 0.3, 0.0][i / 2 % 5];
                        xi[j] = face * (1.0 + (rng.uniform() - 0.5) * off);
                        if i % 7 == 0 {
                            // Inside: away from the faces.
                            xi[j] = (rng.uniform() - 0.5) * 1.8;
                        }
                        let dir = [rng.uniform() - 0.5, rng.uniform() - 0.5];
                        let (q1, _) = zm.quad(&dir, &[0.0, 0.0]);
                        let s = 1.5 * rng.uniform();
                        let w = s * radius / q1.sqrt();
                        let x: Vec<f64> = (0..2)
                            .map(|d| {
                                center[d]
                                    + gens.iter().zip(&xi).map(|(g, v)| g[d] * v).sum::<f64>()
                                    + w * dir[d]
                            })
                            .collect();
                        let x = [x[0], x[1]];
                        xs.push(x);
                        let (q, a) = m.quad(&x, c);
                        let exact = r.contains_at(k, &x);
                        assert_eq!(mem.inside(&m, k, &x, c, q, a), exact, "{name} k = {k}");
                        if mem.inside_by_shortcut(&m, k, &x, q, a) {
                            assert!(exact, "{name} k = {k}: shortcut");
                            by_shortcut += 1;
                        }
                        inside += u64::from(exact);
                        let cube = xi.iter().all(|v| v.abs() <= 1.0 - 1e-9);
                        // With radius 0 (t = 0) only the basis' parallelotope is certain: a
                        // point of the zonotope outside it has no certified neighbour.
                        let certain = radius > 0.0 || gens.len() == 2;
                        if cube && s < 1.0 - 1e-9 && r.also.is_empty() && certain {
                            built_in += 1;
                            found_in += u64::from(exact);
                        }
                    }
                    lanes_agree(&mem, &m, k, c, &xs);
                }
                eprintln!(
                    "{name}: {by_shortcut} by the shortcut, {inside} inside; {found_in} of \
                     {built_in} built inside found"
                );
                assert!(
                    by_shortcut > inside / 2,
                    "{name}: {by_shortcut} of {inside}"
                );
                if name != "member" {
                    assert_eq!(found_in, built_in, "{name}");
                    assert!(built_in > 500, "{name}: {built_in}");
                }
            }
        }
    }
    /// A hand-made result in `n` states with a zonotope of `n` random generators (entries up
    /// to 0.15) at each of `steps` report times, a random metric `A' A + I / 2`, `r_t = 0.05`
    /// and a remainder of 0.01; and `count` states `c + G xi + w` at random report steps, `xi`
    /// uniform in the cube and `w` Gaussian scaled to a P-norm of about 0.8 of
    /// `remainder + r_t` (inside the PRS, most in the shell around the zonotope that its
    /// shortcut does not decide).
    fn high_dimensional(n: usize, steps: usize, count: usize) -> (Prs, Vec<(usize, Vec<f64>)>) {
        let mut rng = PathRng::new(n as u64, 0);
        let normal = |rng: &mut PathRng| {
            let u = rng.uniform_open0();
            box_muller(u, rng.uniform())
        };
        let mut r = result(Method::Interval, vec![1.0, 0.0, 0.0, 1.0], false);
        let a: Vec<f64> = (0..n * n).map(|_| rng.uniform() - 0.5).collect();
        let p: Vec<f64> = (0..n * n)
            .map(|v| {
                let (i, j) = (v / n, v % n);
                let aa: f64 = (0..n).map(|l| a[l * n + i] * a[l * n + j]).sum();
                aa + if i == j { 0.5 } else { 0.0 }
            })
            .collect();
        r.states = (0..n).map(|i| format!("x{i}")).collect();
        r.constants.metric = p.clone();
        let template = r.steps[1].clone();
        r.steps = (0..steps)
            .map(|k| {
                let center: Vec<f64> = (0..n).map(|_| rng.uniform()).collect();
                let generators: Vec<f64> =
                    (0..n * n).map(|_| 0.3 * (rng.uniform() - 0.5)).collect();
                let (hull_lo, hull_hi) = zonotope::hull(&center, &generators);
                let (r_t, remainder) = (0.05, 0.01);
                let up = |a: f64, b: f64| (Interval::point(a) + Interval::point(b)).hi();
                let radius = up(zonotope::p_radius(&p, n, &generators), remainder);
                let mut st = template.clone();
                st.t = k as f64;
                st.r_t = r_t;
                st.prs_radius = up(radius, r_t);
                st.span.lo.clone_from(&hull_lo);
                st.span.hi.clone_from(&hull_hi);
                st.det = DetSet::Zonotope {
                    center,
                    generators,
                    remainder,
                    hull_lo,
                    hull_hi,
                    radius,
                };
                st
            })
            .collect();
        let m = Metric::new(&p, n);
        let states = (0..count)
            .map(|i| {
                let k = i % steps;
                let st = &r.steps[k];
                let gens: Vec<&[f64]> = st.det.generators();
                let xi: Vec<f64> = (0..n).map(|_| 2.0 * rng.uniform() - 1.0).collect();
                let w: Vec<f64> = (0..n).map(|_| normal(&mut rng)).collect();
                let (qw, _) = m.quad(&w, &vec![0.0; n]);
                let s = 0.8 * (st.det.ball_added() + st.r_t) / qw.sqrt();
                let x = (0..n)
                    .map(|d| {
                        let gx: f64 = gens.iter().zip(&xi).map(|(g, v)| g[d] * v).sum();
                        st.det.center()[d] + gx + s * w[d]
                    })
                    .collect();
                (k, x)
            })
            .collect();
        (r, states)
    }

    /// States `x` of [`high_dimensional`] against their step's PRS: `(inside, by the
    /// shortcut)` counts, each decision asserted equal to `Prs::contains_at`'s.
    fn decide(r: &Prs, states: &[(usize, Vec<f64>)]) -> (usize, usize) {
        let m = Metric::new(&r.constants.metric, r.n());
        let mem = Membership::new(r, &m);
        let (mut inside, mut by_shortcut) = (0, 0);
        for (k, x) in states {
            let c = r.steps[*k].nominal();
            let (q, a) = m.quad(x, c);
            let shortcut = mem.inside_by_shortcut(&m, *k, x, q, a);
            let decided = shortcut || mem.inside(&m, *k, x, c, q, a);
            assert_eq!(decided, r.contains_at(*k, x), "k = {k}, x = {x:?}");
            inside += usize::from(decided);
            by_shortcut += usize::from(shortcut);
        }
        (inside, by_shortcut)
    }

    /// Zonotopes of 2, 6 and 12 states: every state built inside the PRS (by a fifth of the
    /// ball's radius) is found inside, by the same decisions as `Prs::contains_at`'s.
    #[test]
    fn high_dimensional_zonotopes_hold_their_states() {
        for n in [2, 6, 12] {
            let (r, states) = high_dimensional(n, 20, 1000);
            let (inside, by_shortcut) = decide(&r, &states);
            assert_eq!(inside, states.len(), "n = {n}");
            assert!(by_shortcut > states.len() / 4, "n = {n}: {by_shortcut}");
        }
    }
}
