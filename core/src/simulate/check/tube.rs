//! Membership in the time-uniform tube: every Euler-Maruyama state against the span of its
//! report interval, the shortcuts, then `Prs::span_contains`.

#[cfg(doc)]
use super::diag_quad_to_box;
use super::metric::clamp;
use super::{members, Hulls, Metric};
use crate::interval::Interval;
use crate::lanes::{Real, X8};
use crate::prs::Prs;
use crate::simulate::error::{SimInvalid, SpanFault};
use crate::simulate::paths::SMALL;

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
mod tests {
    use super::*;
    use crate::simulate::check::fixtures::{methods_and_metrics, result};
    use crate::simulate::rng::PathRng;
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
}
