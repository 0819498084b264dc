//! PRS membership at report times: the shortcuts per shape, then `Prs::contains_at`.

use super::{lanes, members, Hulls, Metric};
use crate::lanes::X8;
use crate::prs::{DetSet, Prepared, Prs};
use crate::sets::parallelotope::ParallelotopeTest;
use crate::sets::zonotope::ZonotopeTest;

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

#[cfg(test)]
mod tests;
