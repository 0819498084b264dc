//! The questions a result answers about its sets, soundly (outward-rounded arithmetic): the
//! report step of a time, whether a state is in the PRS (or in the span over a report
//! interval), and the PRS's bounding box; for an intersection and for a union of pieces.

use super::{DetSet, Prs, Step};
use crate::interval::Interval;
use crate::model::Bounds;
use crate::sets::{boxes, parallelotope, zonotope};

impl Prs {
    /// The index of the report time `t` (within `1e-9` relative to the horizon, so grid times
    /// such as `0.3` written as literals are found); `None` between report times (the sets are
    /// only computed at report times).
    pub fn step_index(&self, t: f64) -> Option<usize> {
        let tol = 1e-9 * self.horizon.abs().max(1.0);
        let k = self.steps.partition_point(|s| s.t < t - tol);
        self.steps
            .get(k)
            .filter(|s| (s.t - t).abs() <= tol)
            .map(|_| k)
    }

    /// The sets at report time `t` (see [`Prs::step_index`](super::Prs::step_index)).
    pub fn at(&self, t: f64) -> Option<&Step> {
        self.step_index(t).map(|k| &self.steps[k])
    }

    /// Whether `x` lies in [`Step::span`] of report step `k`, the PRS of every time of the
    /// report interval ending there: `true` only if certainly (see [`Prs::contains`](super::Prs::contains)).
    pub fn span_contains(&self, k: usize, x: &[f64]) -> bool {
        if !self.pieces.is_empty() {
            return self.pieces.iter().any(|p| p.span_contains(k, x));
        }
        self.own_span_contains(k, x) && self.also.iter().all(|m| m.own_span_contains(k, x))
    }

    /// A bounding box of this result's own span at report step `k` ([`Step::span`]: its box
    /// widened by its P-ball, rounded outward; the members of an intersection cut it further):
    /// `None` if [`ConstantsUsed::spread`](super::ConstantsUsed::spread) is missing or the span has the wrong length. Panics
    /// if `k` is out of range.
    pub(crate) fn own_span_hull_at(&self, k: usize) -> Option<Vec<Bounds>> {
        let span = &self.steps[k].span;
        let w = &self.constants.spread;
        let n = self.n();
        if w.len() != n || span.lo.len() != n || span.hi.len() != n {
            return None;
        }
        // (A span without a ball adds nothing, even where a spread is infinite.)
        let d = |i: usize| match span.radius {
            0.0 => Interval::ZERO,
            r => Interval::point(r) * Interval::point(w[i]),
        };
        Some(
            (0..n)
                .map(|i| {
                    Bounds::new(
                        (Interval::point(span.lo[i]) - d(i)).lo(),
                        (Interval::point(span.hi[i]) + d(i)).hi(),
                    )
                })
                .collect(),
        )
    }

    /// A rigorous bounding box of the PRS over every time of the report interval ending at
    /// step `k` (step 0: at `t = 0`): this result's own span box widened by its P-ball, cut by
    /// its members' (an intersection holds the state in each); a split result's is the union's
    /// (the box of its pieces' spans). `None` if [`ConstantsUsed::spread`](super::ConstantsUsed::spread) is missing. Panics
    /// if `k` is out of range.
    pub fn span_hull_at(&self, k: usize) -> Option<Vec<Bounds>> {
        let mut hull = self.own_span_hull_at(k)?;
        for m in &self.also {
            cut(&mut hull, &m.own_span_hull_at(k)?);
        }
        Some(hull)
    }

    /// [`Prs::span_contains`](super::Prs::span_contains) for this result's own metric.
    pub(crate) fn own_span_contains(&self, k: usize, x: &[f64]) -> bool {
        let span = &self.steps[k].span;
        assert_eq!(
            x.len(),
            self.n(),
            "span_contains: x has the wrong dimension"
        );
        boxes::box_contains(
            &self.constants.metric,
            self.n(),
            x,
            &span.lo,
            &span.hi,
            span.radius,
        )
    }

    /// Whether `x` lies in the PRS at report time `t`: `Some(true)` only if certainly
    /// (decided in interval arithmetic; a point within rounding of the boundary counts as
    /// outside), `None` if `t` is not a report time. Panics if `x` has the wrong length.
    pub fn contains(&self, x: &[f64], t: f64) -> Option<bool> {
        self.step_index(t).map(|k| self.contains_at(k, x))
    }

    /// Whether `x` lies in the PRS at report step `k` (see [`Prs::contains`](super::Prs::contains)). Panics if `k` is
    /// out of range or `x` has the wrong length.
    pub fn contains_at(&self, k: usize, x: &[f64]) -> bool {
        if !self.pieces.is_empty() {
            return self.pieces.iter().any(|p| p.contains_at(k, x));
        }
        self.own_contains_at(k, x) && self.also.iter().all(|m| m.own_contains_at(k, x))
    }

    /// [`Prs::contains_at`](super::Prs::contains_at) for this result's own metric.
    pub(crate) fn own_contains_at(&self, k: usize, x: &[f64]) -> bool {
        self.own_contains_at_with(k, x, None)
    }

    /// [`Prs::own_contains_at`](super::Prs::own_contains_at), with the exact test of step `k`'s set built once by the
    /// caller (`test`: of this result's parallelotopes, for its metric and transform, or of
    /// step `k`'s zonotope, for its metric): the same answers.
    pub(crate) fn own_contains_at_with(
        &self,
        k: usize,
        x: &[f64],
        test: Option<Prepared<'_>>,
    ) -> bool {
        let st = &self.steps[k];
        let n = self.n();
        assert_eq!(x.len(), n, "contains: x has the wrong dimension");
        let p = &self.constants.metric;
        // The set also holds B_P(c, r) when the deterministic set holds its centre c (a point
        // certain where the search for the nearest point of the set may stop short; the Monte
        // Carlo check decides most states by that ball alone).
        let near_centre = || {
            self.centre_radius(k)
                .is_some_and(|r| within(p, x, st.det.center(), r))
        };
        match &st.det {
            DetSet::Ball { center, .. } => within(p, x, center, st.prs_radius),
            DetSet::Box { lo, hi, .. } => {
                boxes::box_contains(p, n, x, lo, hi, st.r_t) || near_centre()
            }
            DetSet::Parallelotope { lo, hi, .. } => match &self.transform {
                Some(tr) => {
                    let near = match test {
                        Some(Prepared::Parallelotope(test)) => test.contains(x, lo, hi, st.r_t),
                        _ => parallelotope::parallelotope_contains(p, tr, x, lo, hi, st.r_t),
                    };
                    near || near_centre()
                }
                None => false,
            },
            DetSet::Zonotope {
                center, generators, ..
            } => {
                let r = self.zonotope_radius(k);
                let near = match test {
                    Some(Prepared::Zonotope(test)) => test.contains(x, r),
                    _ => zonotope::contains(p, x, center, generators, r),
                };
                near || near_centre()
            }
        }
    }

    /// The P-radius added to the zonotope of report step `k` in its PRS, `remainder + r_t`
    /// (rounded down: membership tests ask for points within it).
    pub(crate) fn zonotope_radius(&self, k: usize) -> f64 {
        let st = &self.steps[k];
        (Interval::point(st.r_t) + Interval::point(st.det.ball_added())).lo()
    }

    /// The radius of a P-ball around the centre of report step `k`'s deterministic set
    /// ([`DetSet::center`]) that this result's own PRS certainly holds: the PRS radius of a
    /// ball, `r_t` for a box or a parallelotope holding its centre, the zonotope's
    /// `remainder + r_t` (rounded down); `None` when the set is not certain to hold its centre.
    pub(crate) fn centre_radius(&self, k: usize) -> Option<f64> {
        let st = &self.steps[k];
        match &st.det {
            DetSet::Ball { .. } => Some(st.prs_radius),
            DetSet::Zonotope { .. } => Some(self.zonotope_radius(k)),
            DetSet::Box { lo, hi, center, .. } => center
                .iter()
                .zip(lo.iter().zip(hi))
                .all(|(c, (l, h))| l <= c && c <= h)
                .then_some(st.r_t),
            DetSet::Parallelotope { lo, hi, center, .. } => self
                .transform
                .as_ref()
                .is_some_and(|tr| {
                    let t: Vec<Vec<f64>> =
                        tr.matrix.chunks(self.n()).map(<[f64]>::to_vec).collect();
                    parallelotope::inside(&t, center, lo, hi)
                })
                .then_some(st.r_t),
        }
    }

    /// A rigorous bounding box of the PRS at report time `t` (`None` between report times;
    /// see [`Prs::hull_at`](super::Prs::hull_at)).
    pub fn hull(&self, t: f64) -> Option<Vec<Bounds>> {
        self.step_index(t).and_then(|k| self.hull_at(k))
    }

    /// A rigorous bounding box of the PRS at report step `k`: the deterministic set's hull
    /// inflated by `r_t sqrt((P^-1)_ii)` (a zonotope's by `(remainder + r_t) sqrt((P^-1)_ii)`;
    /// for a ball, the ball `B_P(x*, R_t + r_t)`'s own hull), rounded outward; `None` if
    /// [`ConstantsUsed::spread`](super::ConstantsUsed::spread) is missing (a result built by hand). Panics if `k` is out of
    /// range.
    pub fn hull_at(&self, k: usize) -> Option<Vec<Bounds>> {
        let mut hull = self.own_hull_at(k)?;
        for m in &self.also {
            cut(&mut hull, &m.own_hull_at(k)?);
        }
        Some(hull)
    }

    /// A rigorous bounding box of a set holding `X_t` at report step `k` with probability at
    /// least `1 - delta` at that time alone (not for all times at once): [`Prs::hull_at`](super::Prs::hull_at) with
    /// the pointwise radius `r_pointwise` in place of `r_t` in this result's own set (never
    /// larger; its members keep their sets, which hold at every time); for a split result, the
    /// hull of its pieces'. `None` as for [`Prs::hull_at`](super::Prs::hull_at).
    pub fn pointwise_hull_at(&self, k: usize) -> Option<Vec<Bounds>> {
        if let Some((first, rest)) = self.pieces.split_first() {
            let mut hull = first.pointwise_hull_at(k)?;
            for p in rest {
                for (b, o) in hull.iter_mut().zip(p.pointwise_hull_at(k)?) {
                    *b = Bounds::new(b.lo.min(o.lo), b.hi.max(o.hi));
                }
            }
            return Some(hull);
        }
        let mut hull = self.own_hull_with(k, Some(self.steps[k].r_pointwise))?;
        for m in &self.also {
            cut(&mut hull, &m.own_hull_at(k)?);
        }
        Some(hull)
    }

    /// [`Prs::hull_at`](super::Prs::hull_at) for this result's own metric.
    pub(crate) fn own_hull_at(&self, k: usize) -> Option<Vec<Bounds>> {
        self.own_hull_with(k, None)
    }

    /// [`Prs::own_hull_at`](super::Prs::own_hull_at) with the stochastic radius `r` in place of `r_t` (`None`: `r_t`).
    fn own_hull_with(&self, k: usize, r: Option<f64>) -> Option<Vec<Bounds>> {
        let st = &self.steps[k];
        let n = self.n();
        let w = &self.constants.spread;
        if w.len() != n {
            return None;
        }
        let spread = |r: f64, i: usize| Interval::point(r) * Interval::point(w[i]);
        let (r_t, prs_radius) = match r {
            None => (st.r_t, st.prs_radius),
            Some(r) => (
                r,
                (Interval::point(st.det.radius()) + Interval::point(r)).hi(),
            ),
        };
        Some(match st.det.box_hull() {
            None => {
                let c = st.det.center();
                (0..n)
                    .map(|i| {
                        let d = spread(prs_radius, i);
                        let c = Interval::point(c[i]);
                        Bounds::new((c - d).lo(), (c + d).hi())
                    })
                    .collect()
            }
            Some((lo, hi)) => (0..n)
                .map(|i| {
                    let r = Interval::point(r_t) + Interval::point(st.det.ball_added());
                    let d = spread(r.hi(), i);
                    Bounds::new(
                        (Interval::point(lo[i]) - d).lo(),
                        (Interval::point(hi[i]) + d).hi(),
                    )
                })
                .collect(),
        })
    }
}

/// A membership test of [`Prs::own_contains_at`](super::Prs::own_contains_at) built once for many states (the Monte Carlo
/// check).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Prepared<'a> {
    /// The test of a result's parallelotopes (its metric and transform).
    Parallelotope(&'a parallelotope::ParallelotopeTest),
    /// The test of one step's zonotope (with the result's metric).
    Zonotope(&'a zonotope::ZonotopeTest),
}

/// `hull` cut by the box `other`, both holding the same set (an intersection's members): an
/// empty cut cannot happen for sets holding the same nominal state, but stays a valid
/// (degenerate) box.
fn cut(hull: &mut [Bounds], other: &[Bounds]) {
    for (b, o) in hull.iter_mut().zip(other) {
        let lo = b.lo.max(o.lo);
        *b = Bounds::new(lo, b.hi.min(o.hi).max(lo));
    }
}

/// Whether `|x - c|_P <= r` certainly (interval arithmetic), `p` n x n row-major (both
/// off-diagonal entries, so a slightly asymmetric `P` is used as given).
pub(crate) fn within(p: &[f64], x: &[f64], c: &[f64], r: f64) -> bool {
    let n = x.len();
    let d: Vec<Interval> = x
        .iter()
        .zip(c)
        .map(|(&a, &b)| Interval::point(a) - Interval::point(b))
        .collect();
    let mut q = Interval::ZERO;
    for i in 0..n {
        q += p[i * n + i] * d[i].sqr();
        for j in i + 1..n {
            q += Interval::point(p[i * n + j]) * d[i] * d[j]
                + Interval::point(p[j * n + i]) * d[j] * d[i];
        }
    }
    q.hi() <= Interval::point(r).sqr().lo()
}
