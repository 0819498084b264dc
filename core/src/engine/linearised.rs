//! The linearised Gaussian part of the first-order sets (method.md 8.10): with additive noise
//! (`G` constant), the state is compared with `p + M xi + Z`, `Z` the Gaussian solution of the
//! linearisation along the nominal, and the difference `W` is bounded path by path.
//!
//! On an internal step `[t_k, t_(k+1)]` of the first-order sets (8.8) the nominal `p`, the
//! matrix curve `M' = A_k M` and the box `V = [M] Xi` are given. `Z` solves
//! `dZ = A_k Z dt + G dW`, `Z_0 = 0`, so `Z_t ~ N(0, Sigma_t)` with
//! `Sigma_(k+1) = E Sigma_k E' + int_0^h e^(A s) G G' e^(A' s) ds` (enclosed). Since `G` is
//! constant the noise cancels in `W = X - p - M xi - Z`:
//!
//! ```text
//! W' = A_k W + (Jbar - A_k)(M xi + Z + W) + (f(X, u) - f(X, u*)) - d,
//! ```
//!
//! `Jbar` the mean of `D_x f` on the segment from `p` to `X`. On the event that `Z` stays in the
//! per-step boxes of the reflection bound (probability `1 - delta`: one epoch per internal step
//! and coordinate),
//! the forcing is bounded per coordinate on a box holding `X`, and `W` is propagated by the
//! linear flow itself (a zonotope), not by a contraction rate: a remainder in a fast direction is
//! damped as fast as the flow damps it.

use super::assemble::{spread, Piece};
use super::first_order::exp_enclosure;
use super::gaussian::{add, congruence, step_flow};
use super::linalg::product_point;
use super::{Inputs, Run};
use crate::chi2::chi2_quantile_upper;
use crate::interval::Interval;
use crate::model::Guarantee;
use crate::prs::{DetSet, Span};
use crate::sets::zonotope;

/// Attempts per step to find an a-priori box for `W` that holds its own bound.
const MAX_TRIES: usize = 12;

/// `W`'s zonotope keeps at most this many generators per state; beyond, the smallest are
/// replaced by their bounding box.
const ORDER: usize = 4;

/// The P-ball added to each set, relative to its radius (see [`Tracker::set_at`]).
const SLACK: f64 = 1e-6;

/// What one internal step of the first-order sets hands over (method.md 8.8's quantities).
pub(super) struct StepData<'s> {
    /// The point matrix `A_k`, row-major.
    pub(super) a: &'s [f64],
    /// `exp(A_k h)`, enclosed.
    pub(super) exp_h: &'s [Interval],
    /// `exp(A_k tau)` for every `tau` in `[0, h]`, enclosed.
    pub(super) exp_over: &'s [Interval],
    /// The step's length and its time range.
    pub(super) span: Interval,
    pub(super) times: Interval,
    /// The nominal's hull over the step.
    pub(super) hull: &'s [Interval],
    /// `V = [M] Xi` over the step.
    pub(super) v: &'s [Interval],
    /// The nominal input on the step.
    pub(super) u: &'s [f64],
    /// `|d|_P` over the step (the nominal's defect).
    pub(super) defect: f64,
    /// Per coordinate, a bound of the node's jump `(E M_k - M_(k+1)) xi`.
    pub(super) jump: &'s [f64],
    /// The nominal at the step's end.
    pub(super) x1: &'s [f64],
    /// `M_(k+1)` (floating point, row-major).
    pub(super) m_next: &'s [f64],
    /// The initial box's half-widths.
    pub(super) half: &'s [f64],
    /// Whether the step ends at a report time.
    pub(super) report: bool,
}

/// The linearised Gaussian sets along the steps of one run.
pub(super) struct Tracker<'r> {
    run: &'r Run<'r>,
    n: usize,
    /// `G G'`, enclosed.
    noise: Vec<Interval>,
    /// `Sigma` at the current node.
    sigma: Vec<Interval>,
    /// `q` with `P(|N(0, 1)| > sqrt(q)) <= delta / (2 n K)`: by the reflection principle, each
    /// coordinate's martingale leaves `sqrt(q)` standard deviations on an epoch with
    /// probability at most `delta / (n K)`.
    quantile: Interval,
    /// `W`'s zonotope (centre 0): its generators.
    gens: Vec<Vec<f64>>,
    /// Per coordinate, `sqrt((P^-1)_ii)` rounded up (P-norm bounds to coordinates).
    w: Vec<f64>,
    /// Per coordinate, the growth of `W`'s hull over the previous step (the next guess).
    grew: Vec<f64>,
    /// The internal steps (epochs) the bound was laid out for.
    epochs: usize,
    /// Per state, whether it is pinned: a point start that neither noise, nor an input, nor
    /// another state's spread reaches (see [`pinned`]).
    pinned: Vec<bool>,
}

impl<'r> Tracker<'r> {
    /// A tracker for `run` over `epochs` internal steps at probability level `delta`, or `None`
    /// when the model's noise is not constant or the run's guarantee is not time-uniform.
    pub(super) fn new(
        run: &'r Run<'r>,
        epochs: usize,
        delta: f64,
        half: &[f64],
    ) -> Option<Tracker<'r>> {
        let n = run.setup.n;
        if !run.info.constant_diffusion || run.spec.guarantee != Guarantee::Uniform || epochs == 0 {
            return None;
        }
        let m = run.sys.m();
        let mut g = vec![Interval::ZERO; n * m];
        run.sys.diffusion_interval(
            &vec![Interval::ENTIRE; n],
            Interval::new(0.0, run.spec.horizon),
            &mut g,
        );
        if g.iter().any(|v| !v.is_bounded()) {
            return None;
        }
        let pinned = pinned(run, &g, half);
        let noise: Vec<Interval> = (0..n * n)
            .map(|k| {
                let (i, j) = (k / n, k % n);
                (0..m).fold(Interval::ZERO, |s, l| s + g[i * m + l] * g[j * m + l])
            })
            .collect();
        // One epoch per internal step and one event per coordinate, each at delta / (n K)
        // (union bound), of which the reflection principle spends half on each side.
        let share = (delta / (2 * n * epochs) as f64).next_down();
        // (A delta so small that its share underflows: no member, rather than no quantile.)
        if share <= 0.0 {
            return None;
        }
        let quantile = Interval::point(chi2_quantile_upper(1, share));
        Some(Tracker {
            run,
            n,
            noise,
            sigma: vec![Interval::ZERO; n * n],
            quantile,
            gens: Vec::new(),
            w: spread(run),
            grew: vec![0.0; n],
            epochs,
            pinned,
        })
    }

    /// The number of epochs of the Gaussian bound (one per internal step).
    pub(super) fn epochs(&self) -> usize {
        self.epochs
    }

    /// Advances over one internal step: the piece of the linearised Gaussian set, or `None`
    /// when the step cannot be bounded (the run then goes without this set).
    pub(super) fn step(&mut self, d: &StepData, rates: (f64, f64)) -> Option<Piece> {
        let n = self.n;
        let point = Interval::point;
        // Sigma at the step's end.
        let (_, gamma) = step_flow(d.a, &self.noise, n, d.span);
        self.sigma = add(&congruence(&d.exp_h.to_vec(), &self.sigma, n), &gamma);
        // Z over the step: Z_t = e^(-A (t_(k+1) - t)) N_t with |N_(t, j)| <= z_end[j] for every
        // t of the step (the reflection principle per coordinate, method.md 8.10).
        let z_end: Vec<f64> = (0..n)
            .map(|i| {
                (self.quantile * point(self.sigma[i * n + i].hi().max(0.0)))
                    .sqrt()
                    .hi()
            })
            .collect();
        let neg: Vec<f64> = d.a.iter().map(|v| -v).collect();
        let back = exp_enclosure(&neg, n, Interval::new(0.0, d.span.hi()))?;
        let z_over = abs_times(&back, &z_end);
        if z_over.iter().chain(&z_end).any(|z| !z.is_finite()) {
            return None;
        }
        // W over the step, on an a-priori box that must hold it.
        let gi = self.gens_matrix();
        let m = self.gens.len();
        let fg = product_point(d.exp_over, &gi, n, n, m);
        let base: Vec<f64> = (0..n)
            .map(|i| {
                (0..m)
                    .fold(Interval::ZERO, |s, j| s + point(fg[i * m + j].mag()))
                    .hi()
            })
            .collect();
        let ui: Vec<Interval> = d.u.iter().map(|&x| point(x)).collect();
        let mut cap: Vec<f64> = base
            .iter()
            .zip(&self.grew)
            .map(|(b, g)| 1.25 * (b + g) + f64::MIN_POSITIVE)
            .collect();
        let mut jac = vec![Interval::ZERO; n * n];
        let mut accepted = None;
        for _ in 0..MAX_TRIES {
            // X - p lies in dev = V + Z + W; the region holds p + dev.
            let dev: Vec<Interval> = (0..n)
                .map(|i| {
                    d.v[i] + Interval::new(-z_over[i], z_over[i]) + Interval::new(-cap[i], cap[i])
                })
                .collect();
            let region: Vec<Interval> = (0..n).map(|i| d.hull[i] + dev[i]).collect();
            sliced_jacobian(self.run.sys, d.hull, &dev, &ui, d.times, &mut jac);
            let du = input_change(self.run, d, &region);
            let beta: Vec<f64> = (0..n)
                .map(|i| {
                    let lin = (0..n).fold(du[i], |acc, j| {
                        acc + (jac[i * n + j] - point(d.a[i * n + j])) * dev[j]
                    });
                    (point(lin.mag()) + point(d.defect) * point(self.w[i])).hi()
                })
                .collect();
            if beta.iter().any(|b| !b.is_finite()) {
                return None;
            }
            // int_0^h e^(A (h - s)) b(s) ds, and over the step: h [e^(A [0, h])] [-beta, beta].
            let forced: Vec<f64> = abs_times(d.exp_over, &beta)
                .into_iter()
                .map(|v| (point(v) * point(d.span.hi())).hi())
                .collect();
            let over: Vec<f64> = (0..n)
                .map(|i| (point(base[i]) + point(forced[i])).hi())
                .collect();
            if over.iter().zip(&cap).all(|(o, c)| o < c) {
                accepted = Some((over, forced));
                break;
            }
            for (c, o) in cap.iter_mut().zip(&over) {
                *c = (2.0 * *c).max(1.25 * o);
            }
        }
        let (over, forced) = accepted?;
        // W at the step's end: E W_k (the midpoint's generators, the rest in a box), the
        // forcing, the node's jump.
        let eg = product_point(d.exp_h, &gi, n, n, m);
        let mut boxed: Vec<f64> = (0..n)
            .map(|i| {
                (0..m)
                    .fold(point(forced[i]) + point(d.jump[i]), |s, j| {
                        let e = eg[i * m + j];
                        s + point((point(e.hi()) - point(e.mid())).hi())
                            .max(point((point(e.mid()) - point(e.lo())).hi()))
                    })
                    .hi()
            })
            .collect();
        let mut gens: Vec<Vec<f64>> = (0..m)
            .map(|j| (0..n).map(|i| eg[i * m + j].mid()).collect())
            .collect();
        reduce(&mut gens, &mut boxed, n);
        push_box(&mut gens, &boxed);
        let before: Vec<f64> = self.hull_of_w();
        self.gens = gens;
        let after = self.hull_of_w();
        self.grew = after
            .iter()
            .zip(&before)
            .map(|(a, b)| (a - b).max(0.0))
            .collect();
        if after.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let mut boxes: Vec<Interval> = (0..n)
            .map(|i| {
                let r = point(z_over[i]) + point(over[i]);
                d.hull[i] + d.v[i] + Interval::new(-r.hi(), r.hi())
            })
            .collect();
        self.widen_pinned(&mut boxes);
        let over_span = Span {
            lo: boxes.iter().map(|b| b.lo()).collect(),
            hi: boxes.iter().map(|b| b.hi()).collect(),
            radius: 0.0,
        };
        let end = d.report.then(|| self.set_at(d, &z_end));
        Some(Piece {
            t1: d.times.hi(),
            rates,
            over: over_span,
            end,
        })
    }

    /// The set at a report time: `p + M Xi` (the generators in interval arithmetic, their
    /// rounding in a box), `W`'s zonotope and `Z`'s box, as one zonotope.
    fn set_at(&self, d: &StepData, z: &[f64]) -> DetSet {
        let n = self.n;
        let point = Interval::point;
        let mut boxed = z.to_vec();
        let mut flat = Vec::with_capacity(n * (n + self.gens.len() + 1));
        for j in 0..n {
            for (i, b) in boxed.iter_mut().enumerate() {
                let g = point(d.m_next[i * n + j]) * point(d.half[j]);
                flat.push(g.mid());
                let r = (point(g.hi()) - point(g.mid()))
                    .max(point(g.mid()) - point(g.lo()))
                    .hi();
                *b = (point(*b) + point(r)).hi();
            }
        }
        for g in &self.gens {
            flat.extend_from_slice(g);
        }
        for (i, &b) in boxed.iter().enumerate() {
            if b > 0.0 {
                flat.extend((0..n).map(|k| if k == i { b } else { 0.0 }));
            }
        }
        let metric = &self.run.setup.consts.metric;
        for (i, wide) in self.pinned_widths(&flat) {
            flat.extend((0..n).map(|k| if k == i { wide } else { 0.0 }));
        }
        let (hull_lo, hull_hi) = zonotope::hull(d.x1, &flat);
        let radius = zonotope::p_radius(metric, n, &flat);
        // A ball of a millionth of the set's radius around it: the set only grows, and a
        // state inside gets certified by the membership test (which needs a positive slack).
        let remainder = (point(radius) * point(SLACK)).hi();
        DetSet::Zonotope {
            center: d.x1.to_vec(),
            generators: flat,
            remainder,
            hull_lo,
            hull_hi,
            radius: (point(radius) + point(remainder)).hi(),
        }
    }

    /// Per pinned state `i` (see [`pinned`]), the half-width the set claims there: the extent
    /// `R sqrt((P^-1)_ii)` of the P-ball of radius `R` around the centre holding the zonotope
    /// with generators `flat` (the set only grows).
    fn pinned_widths(&self, flat: &[f64]) -> Vec<(usize, f64)> {
        if !self.pinned.contains(&true) {
            return Vec::new();
        }
        let around = zonotope::p_radius(&self.run.setup.consts.metric, self.n, flat);
        (0..self.n)
            .filter(|&i| self.pinned[i])
            .map(|i| {
                (
                    i,
                    (Interval::point(around) * Interval::point(self.w[i])).hi(),
                )
            })
            .collect()
    }

    /// Widens the pinned states of the box `boxes` as [`Tracker::pinned_widths`] does a set.
    fn widen_pinned(&self, boxes: &mut [Interval]) {
        let n = self.n;
        let flat: Vec<f64> = (0..n)
            .flat_map(|j| {
                let r = boxes[j].rad();
                (0..n).map(move |i| if i == j { r } else { 0.0 })
            })
            .collect();
        for (i, wide) in self.pinned_widths(&flat) {
            boxes[i] += Interval::new(-wide, wide);
        }
    }

    /// `W`'s generators as an `n x m` matrix (row-major).
    fn gens_matrix(&self) -> Vec<f64> {
        let m = self.gens.len();
        (0..self.n * m).map(|k| self.gens[k % m][k / m]).collect()
    }

    /// Per coordinate, the half-width of `W`'s hull (rounded up).
    fn hull_of_w(&self) -> Vec<f64> {
        (0..self.n)
            .map(|i| {
                self.gens
                    .iter()
                    .fold(Interval::ZERO, |s, g| s + Interval::point(g[i].abs()))
                    .hi()
            })
            .collect()
    }
}

/// Per row `i`, `sum_j |m_ij| v_j` rounded up (`m` square, row-major; `v >= 0`): the bound of
/// `M x` over `|x_j| <= v_j` for every matrix in the enclosure `m`.
fn abs_times(m: &[Interval], v: &[f64]) -> Vec<f64> {
    let n = v.len();
    (0..n)
        .map(|i| {
            (0..n)
                .fold(Interval::ZERO, |acc, j| {
                    acc + Interval::point(m[i * n + j].mag()) * Interval::point(v[j])
                })
                .hi()
        })
        .collect()
}

/// Per state, whether it is pinned to the validated nominal: it starts at a point and no
/// noise channel, input or initial spread reaches it through the drift's dependencies (`f_i`
/// depends on `x_j` where `(i, j)` is in [`System::jac_x_pattern`]). The set is exact there up
/// to the nominal's defect (1e-6 and below), far finer than an Euler-Maruyama path of any
/// practical step follows the state (its error is `O(dt)`), so a Monte Carlo check could not
/// tell a correct set from a wrong one: the member leaves those states to the other sets
/// (method.md 8.10).
///
/// [`System::jac_x_pattern`]: crate::system::System::jac_x_pattern
fn pinned(run: &Run, g: &[Interval], half: &[f64]) -> Vec<bool> {
    let n = run.setup.n;
    let (m, p) = (run.sys.m(), run.sys.p());
    let zero = |v: &Interval| v.lo() == 0.0 && v.hi() == 0.0;
    let mut ju = vec![Interval::ZERO; n * p];
    if p > 0 {
        run.sys.jac_u_interval(
            &vec![Interval::ENTIRE; n],
            &super::input_intervals(run.info),
            Interval::new(0.0, run.spec.horizon),
            &mut ju,
        );
    }
    let mut reached: Vec<bool> = (0..n)
        .map(|i| {
            half[i] > 0.0
                || (0..m).any(|l| !zero(&g[i * m + l]))
                || (0..p).any(|l| !zero(&ju[i * p + l]))
        })
        .collect();
    let pattern = run.sys.jac_x_pattern();
    loop {
        let mut grew = false;
        for &(i, j) in &pattern {
            if reached[j] && !reached[i] {
                reached[i] = true;
                grew = true;
            }
        }
        if !grew {
            return reached.iter().map(|r| !r).collect();
        }
    }
}

/// `f(X, u) - f(X, u*)` over `region`, per coordinate: `[D_u f](region, U) (U - u*)` under
/// the input box (the mean value theorem on the convex box), zero under a known input.
fn input_change(run: &Run, d: &StepData, region: &[Interval]) -> Vec<Interval> {
    let n = region.len();
    let p = run.sys.p();
    if !matches!(run.inputs, Inputs::Box) || p == 0 {
        return vec![Interval::ZERO; n];
    }
    let u = super::input_intervals(run.info);
    let mut ju = vec![Interval::ZERO; n * p];
    run.sys.jac_u_interval(region, &u, d.times, &mut ju);
    (0..n)
        .map(|i| {
            (0..p).fold(Interval::ZERO, |s, l| {
                s + ju[i * p + l] * (u[l] - Interval::point(d.u[l]))
            })
        })
        .collect()
}

/// Keeps the `(ORDER - 1) n` largest generators (by their 1-norm) and adds the others'
/// magnitudes to `boxed` (their zonotope lies in that box).
fn reduce(gens: &mut Vec<Vec<f64>>, boxed: &mut [f64], n: usize) {
    let keep = (ORDER - 1) * n;
    if gens.len() <= keep {
        return;
    }
    gens.sort_by(|a, b| {
        let size = |g: &Vec<f64>| g.iter().map(|v| v.abs()).sum::<f64>();
        size(b).total_cmp(&size(a))
    });
    for g in gens.drain(keep..) {
        for (b, v) in boxed.iter_mut().zip(&g) {
            *b = (Interval::point(*b) + Interval::point(v.abs())).hi();
        }
    }
}

/// Appends the box `[-boxed, boxed]` as axis generators (the non-zero ones).
fn push_box(gens: &mut Vec<Vec<f64>>, boxed: &[f64]) {
    let n = boxed.len();
    for (i, &b) in boxed.iter().enumerate() {
        if b > 0.0 {
            gens.push((0..n).map(|k| if k == i { b } else { 0.0 }).collect());
        }
    }
}

/// How many slices of the segment from the nominal to the state the mean-value Jacobian is
/// averaged over (method.md 8.8, "The mean value over slices").
pub(super) const SLICES: usize = 8;

/// An enclosure of `Jbar = int_0^1 D_x f(p + th dev, u, t) dth` for `p` in the box `hull`, `dev`
/// in the box `dev` symmetric about 0 and `t` in `times`: the mean of the interval Jacobians
/// over the boxes `hull + ((i + 1) / SLICES) dev`, `i < SLICES` (each slice's mean lies in its
/// box's enclosure, a convex set; for a Jacobian affine in the state the excess over
/// `D_x f(p)` is `(SLICES + 1) / (2 SLICES)` of the unsliced one's).
pub(super) fn sliced_jacobian(
    sys: &dyn crate::system::System,
    hull: &[Interval],
    dev: &[Interval],
    u: &[Interval],
    times: Interval,
    out: &mut [Interval],
) {
    let n = hull.len();
    let (mut part, mut region) = (vec![Interval::ZERO; n * n], vec![Interval::ZERO; n]);
    out.iter_mut().for_each(|v| *v = Interval::ZERO);
    for i in 0..SLICES {
        let th = Interval::point((i + 1) as f64) / Interval::point(SLICES as f64);
        for (r, (h, d)) in region.iter_mut().zip(hull.iter().zip(dev)) {
            *r = *h + th * *d;
        }
        sys.jac_x_interval(&region, u, times, &mut part);
        for (o, p) in out.iter_mut().zip(&part) {
            *o += *p;
        }
    }
    let m = Interval::point(SLICES as f64);
    out.iter_mut().for_each(|v| *v /= m);
}

#[cfg(test)]
mod tests {
    use super::{sliced_jacobian, SLICES};
    use crate::interval::Interval;
    use crate::system::System;

    /// Van der Pol, `x' = y`, `y' = (1 - x^2) y - x`: a Jacobian that is not affine in the state.
    struct Vdp;

    impl System for Vdp {
        fn n(&self) -> usize {
            2
        }
        fn p(&self) -> usize {
            0
        }
        fn m(&self) -> usize {
            0
        }
        fn drift(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
            out[0] = x[1];
            out[1] = (1.0 - x[0] * x[0]) * x[1] - x[0];
        }
        fn drift_interval(
            &self,
            x: &[Interval],
            _: &[Interval],
            _: Interval,
            out: &mut [Interval],
        ) {
            out[0] = x[1];
            out[1] = (Interval::ONE - x[0].sqr()) * x[1] - x[0];
        }
        fn jac_x(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
            out.copy_from_slice(&[0.0, 1.0, -2.0 * x[0] * x[1] - 1.0, 1.0 - x[0] * x[0]]);
        }
        fn jac_x_interval(
            &self,
            x: &[Interval],
            _: &[Interval],
            _: Interval,
            out: &mut [Interval],
        ) {
            out[0] = Interval::ZERO;
            out[1] = Interval::ONE;
            out[2] = Interval::point(-2.0) * x[0] * x[1] - Interval::ONE;
            out[3] = Interval::ONE - x[0].sqr();
        }
        fn jac_u(&self, _: &[f64], _: &[f64], _: f64, _: &mut [f64]) {}
        fn jac_u_interval(&self, _: &[Interval], _: &[Interval], _: Interval, _: &mut [Interval]) {}
        fn diffusion(&self, _: &[f64], _: f64, _: &mut [f64]) {}
        fn diffusion_interval(&self, _: &[Interval], _: Interval, _: &mut [Interval]) {}
    }

    /// The exact mean-value Jacobian `int_0^1 D_x f(p + th d) dth` of [`Vdp`] (polynomial).
    fn mean_value(p: [f64; 2], d: [f64; 2]) -> [f64; 4] {
        let ([x, y], [a, b]) = (p, d);
        // int (x + th a)(y + th b) = xy + (xb + ya) / 2 + ab / 3; int (x + th a)^2 likewise.
        let xy = x * y + (x * b + y * a) / 2.0 + a * b / 3.0;
        let xx = x * x + x * a + a * a / 3.0;
        [0.0, 1.0, -2.0 * xy - 1.0, 1.0 - xx]
    }

    #[test]
    fn sliced_jacobian_holds_the_mean_value_jacobians_and_is_narrower() {
        let hull = [Interval::new(-1.3, -1.2), Interval::new(-2.1, -2.0)];
        let dev = [Interval::new(-0.4, 0.4), Interval::new(-0.3, 0.3)];
        let t = Interval::ZERO;
        let mut sliced = vec![Interval::ZERO; 4];
        sliced_jacobian(&Vdp, &hull, &dev, &[], t, &mut sliced);
        // Every mean-value Jacobian of a start in the hull and a deviation in `dev` is inside
        // (a grid over both boxes, corners included).
        let grid = |b: Interval, k: usize| b.lo() + (b.hi() - b.lo()) * k as f64 / 8.0;
        for (i, j, k, l) in (0..=8).flat_map(|i| {
            (0..=8).flat_map(move |j| (0..=8).flat_map(move |k| (0..=8).map(move |l| (i, j, k, l))))
        }) {
            let p = [grid(hull[0], i), grid(hull[1], j)];
            let d = [grid(dev[0], k), grid(dev[1], l)];
            for (e, v) in sliced.iter().zip(mean_value(p, d)) {
                assert!(
                    e.lo() <= v && v <= e.hi(),
                    "{v} outside {e:?} at {p:?} + {d:?}"
                );
            }
        }
        // The unsliced enclosure over hull + dev is wider: its excess over the hull's own
        // Jacobian is about 2 SLICES / (SLICES + 1) times the sliced one's.
        let region: Vec<Interval> = (0..2).map(|i| hull[i] + dev[i]).collect();
        let (mut whole, mut own) = (vec![Interval::ZERO; 4], vec![Interval::ZERO; 4]);
        Vdp.jac_x_interval(&region, &[], t, &mut whole);
        Vdp.jac_x_interval(&hull, &[], t, &mut own);
        for e in 2..4 {
            let excess = |b: Interval| b.width() - own[e].width();
            let ratio = excess(sliced[e]) / excess(whole[e]);
            let affine = (SLICES + 1) as f64 / (2 * SLICES) as f64;
            assert!(ratio < affine + 0.05, "entry {e}: excess ratio {ratio}");
        }
    }
}
