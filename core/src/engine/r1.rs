//! `r1`, the deterministic radius at `t = 0`: an upper bound of `max |x0 - x*_0|_P` over the
//! initial set `X0` (boxes, points and balls), `x*_0` its centre (method.md section 6).
//!
//! Write `x0 - x*_0 = b + y`: `b` over the box coordinates `B` (`|b_i| <= h_i`, points have
//! `h_i = 0`) and `y` over the ball coordinates `S`, with `P_BB`, `P_BS`, `P_SS` the blocks of
//! `P`.
//!
//! **One ball `y' M y <= r^2`, one box vertex `b`.** With `w = P_SB b`,
//! `f(y) = |b + y|_P^2 = b' P_BB b + 2 w'y + y' P_SS y`. For every `mu` with `mu M - P_SS > 0`
//! (then `mu > 0`, as `P_SS > 0`) and every `y` in the ball,
//!
//! ```text
//! f(y) <= f(y) + mu (r^2 - y' M y)                             (y' M y <= r^2, mu >= 0)
//!       = mu r^2 + b' P_BB b + 2 w'y - y' (mu M - P_SS) y
//!      <= mu r^2 + b' P_BB b + w' (mu M - P_SS)^-1 w  =: U_b(mu)  (the concave quadratic's max)
//! ```
//!
//! so every such `mu` gives an upper bound, and the best one is the maximum itself: a quadratic
//! maximised under one quadratic constraint has no duality gap (S-lemma, Slater's point `y = 0`
//! for `r > 0`), `max f = inf { U_b(mu) : mu > lambda_max(P_SS, M) }` (the pencil's largest
//! eigenvalue). In the eigenbasis of the pencil, `U_b(mu) = b' P_BB b + mu r^2 +
//! sum_i g_i^2 / (mu - lambda_i)`, convex in `mu`, minimal where `sum_i g_i^2 / (mu - lambda_i)^2
//! = r^2` (the trust-region secular equation), at most `|g| / r` above `lambda_max`.
//!
//! **The box part.** `|b + y|_P^2` is convex in `b`, so the maximum over the box is at a vertex:
//! `r1^2 = max_b inf_mu U_b(mu)`. For a fixed `mu`, `U_b(mu) = mu r^2 + b' Q(mu) b` with
//! `Q(mu) = P_BB + P_BS (mu M - P_SS)^-1 P_SB`, so one enclosure of `Q(mu)` bounds `U_b(mu)` at
//! every vertex at the cost of today's vertex enumeration. Each vertex keeps the smallest bound
//! over the `mu` used; the next `mu` is the minimiser, in floats, for the vertex whose bound is
//! largest; this stops when that vertex's own `mu` has been used (the bound is then the maximum,
//! up to rounding) or after [`MAX_MULTIPLIERS`]. Without a box part, `U(mu) = mu r^2` and `r1^2 =
//! r^2 lambda_max(P_SS, M)`.
//!
//! **Several balls.** `y_j' M_j y_j <= r_j^2` for every `j` implies `y' W y <= rho^2` with
//! `W = blockdiag(w_j M_j)` and `rho^2 = sum_j w_j r_j^2` for any weights `w_j > 0`: the balls'
//! product lies in one ellipsoid, to which the above applies. This is the S-procedure with one
//! multiplier `mu w_j` per ball: an upper bound, not exact in general. The weights are
//! `w_j = lambda_max(P_jj, M_j)`, which make it exact when `P` couples the balls neither with each
//! other nor with the box part (the maximum is then `max_b b' P_BB b + sum_j r_j^2 lambda_j`).
//!
//! **Many coordinates.** With more than [`MAX_VERTEX_COORDS`] box coordinates, or a box part and
//! more than [`MAX_BALL_STATES`] ball states, the parts are bounded separately,
//! `|b + y|_P <= |b|_P + |y|_P`: the box part as for a box, the balls by `rho^2 lambda_max`.
//!
//! **Rigour.** Floats only choose `mu` and the weights. `lambda_max(P_SS, W)` is bounded by a
//! `mu` for which the interval Cholesky factorisation of `mu W - P_SS` succeeds with positive
//! pivots (then every matrix in the enclosure is positive definite), and each `U_b(mu)` is
//! evaluated in interval arithmetic (`Q(mu)` by that factor and forward substitutions, the
//! vertex sums with their rounding error bounded as for a box). The result is the smaller of
//! this bound and the bound over the balls' bounding boxes, both valid, so it is never larger
//! than the latter.

use super::linalg;
use super::radius::{vertex_forms, vertex_negative, vertex_rounding, BoxRadius, MAX_VERTEX_COORDS};
use crate::interval::Interval;
use crate::model::InitialSet;
use crate::prs::{BallBound, R1Bound, R1Method};

/// Up to this many ball states (all balls together), the balls are bounded jointly with the box
/// part's vertices (their pencil's eigenvectors are estimated, `O(k^3)`); beyond it, and a box
/// part, separately (triangle inequality).
pub const MAX_BALL_STATES: usize = 64;

/// Multipliers `mu` tried at most (each one enclosure of `Q(mu)` and one pass over the vertices).
const MAX_MULTIPLIERS: usize = 8;

/// `r1` over `init` for the metric `p` (`n x n` row-major, `n = half.len()`), and how it was
/// bounded. `half` are the half-widths of `init`'s bounding box around its centre
/// ([`super::radius::initial_center_and_halfwidths`]).
pub(crate) fn bound(p: &[f64], init: &InitialSet, half: &[f64]) -> (f64, R1Bound) {
    let n = half.len();
    let boxes = BoxRadius::new(p, n);
    let vertex_or_sum = |active: usize| {
        if active <= MAX_VERTEX_COORDS {
            R1Method::Vertices { active }
        } else {
            R1Method::AbsoluteSum
        }
    };
    let as_boxes = |balls| {
        let active = half.iter().filter(|&&h| h > 0.0).count();
        (
            boxes.bound(half),
            R1Bound {
                boxes: vertex_or_sum(active),
                balls,
                reported_only: false,
            },
        )
    };
    if init.balls.iter().all(|b| b.radius == 0.0) {
        return as_boxes(BallBound::NoBalls);
    }
    let Some(balls) = Balls::new(p, n, init) else {
        return as_boxes(BallBound::BoundingBoxes);
    };
    let mut box_half = half.to_vec();
    for &i in &balls.states {
        box_half[i] = 0.0;
    }
    let active: Vec<usize> = (0..n).filter(|&i| box_half[i] > 0.0).collect();
    let joint = active.is_empty()
        || (active.len() <= MAX_VERTEX_COORDS && balls.states.len() <= MAX_BALL_STATES);
    let found = if joint {
        Joint::new(p, n, &balls, &active, half).bound()
    } else {
        Some(balls.separate(boxes.bound(&box_half)))
    };
    let today = as_boxes(BallBound::BoundingBoxes);
    match found {
        Some(r) if r < today.0 => (
            r,
            R1Bound {
                boxes: vertex_or_sum(active.len()),
                balls: if joint {
                    BallBound::Joint { balls: balls.count }
                } else {
                    BallBound::Separate { balls: balls.count }
                },
                reported_only: false,
            },
        ),
        _ => today,
    }
}

/// The block of `p` (`n x n`) over `rows x cols`, row-major.
fn block(p: &[f64], n: usize, rows: &[usize], cols: &[usize]) -> Vec<f64> {
    rows.iter()
        .flat_map(|&i| cols.iter().map(move |&j| p[i * n + j]))
        .collect()
}

/// The balls of positive radius as one ellipsoid `y' W y <= rho^2` over their states `S`, with
/// the certified largest eigenvalue of the pencil `(P_SS, W)`.
struct Balls {
    /// The states `S`, ball after ball.
    states: Vec<usize>,
    /// `P_SS` (`k x k`, `k = |S|`).
    p_ss: Vec<f64>,
    /// `W = blockdiag(w_j M_j)`.
    w: Vec<Interval>,
    /// `rho^2 = sum_j w_j r_j^2`.
    rho2: Interval,
    /// Balls of positive radius.
    count: usize,
    /// The pencil in floats (up to [`MAX_BALL_STATES`] states).
    pencil: Option<Pencil>,
    /// An upper bound of `lambda_max(P_SS, W)`, with `lambda W - P_SS` certified positive
    /// definite.
    lambda: f64,
}

impl Balls {
    /// `None` if a ball is malformed (the initial set's checks report it) or a pencil could not
    /// be certified.
    fn new(p: &[f64], n: usize, init: &InitialSet) -> Option<Balls> {
        // Each ball: its states and M as intervals. Balls of radius 0 pin their states (h = 0).
        let mut parts = Vec::new();
        for ball in init.balls.iter().filter(|b| b.radius > 0.0) {
            let k = ball.states.len();
            if ball.states.iter().any(|&s| s >= n) || !ball.radius.is_finite() {
                return None;
            }
            let m: Vec<Interval> = match &ball.metric {
                Some(m) if m.len() == k * k => linalg::to_intervals(m),
                Some(_) => return None,
                None => (0..k * k)
                    .map(|i| Interval::point(if i % (k + 1) == 0 { 1.0 } else { 0.0 }))
                    .collect(),
            };
            parts.push((ball, m));
        }
        let count = parts.len();
        let states: Vec<usize> = parts.iter().flat_map(|(b, _)| b.states.clone()).collect();
        let k = states.len();
        let (mut w, mut rho2) = (vec![Interval::ZERO; k * k], Interval::ZERO);
        let mut offset = 0;
        for (ball, m) in &parts {
            let kj = ball.states.len();
            // One ball: W = M exactly. Several: w_j = lambda_max(P_jj, M_j) (any w_j > 0 is
            // valid; these make uncoupled balls exact).
            let weight = if count == 1 {
                1.0
            } else {
                let est = estimate(&block(p, n, &ball.states, &ball.states), m, kj);
                if est.is_finite() && est > 0.0 {
                    est
                } else {
                    1.0
                }
            };
            let weight = Interval::point(weight);
            for a in 0..kj {
                for b in 0..kj {
                    w[(offset + a) * k + offset + b] = weight * m[a * kj + b];
                }
            }
            rho2 += weight * Interval::point(ball.radius).sqr();
            offset += kj;
        }
        let p_ss = block(p, n, &states, &states);
        let pencil = (k <= MAX_BALL_STATES)
            .then(|| Pencil::new(&p_ss, &w, k))
            .flatten();
        let est = match &pencil {
            Some(pencil) => pencil.lambda_max(),
            None => diagonal_estimate(&p_ss, &w, k),
        };
        let lambda = certified_lambda_max(&p_ss, &w, k, est)?;
        Some(Balls {
            states,
            p_ss,
            w,
            rho2,
            count,
            pencil,
            lambda,
        })
    }

    /// `mu W - P_SS` in interval arithmetic.
    fn shifted(&self, mu: f64) -> Vec<Interval> {
        shifted(&self.p_ss, &self.w, mu)
    }

    /// `|b|_P + |y|_P` with the box part's radius `box_radius` (rounded up) and `|y|_P^2 <=
    /// lambda rho^2`.
    fn separate(&self, box_radius: f64) -> f64 {
        let balls = (Interval::point(self.lambda) * self.rho2).sqrt();
        (Interval::point(box_radius) + balls).hi()
    }
}

/// `mu W - P_SS` (`k x k`) in interval arithmetic.
fn shifted(p_ss: &[f64], w: &[Interval], mu: f64) -> Vec<Interval> {
    let mu = Interval::point(mu);
    w.iter()
        .zip(p_ss)
        .map(|(&w, &p)| mu * w - Interval::point(p))
        .collect()
}

/// An upper bound of `lambda_max(P_SS, W)`: the smallest `mu` found for which `mu W - P_SS` is
/// certifiably positive definite (interval Cholesky), searched upward from the estimate `est` by
/// growing relative margins, then refined by bisection. `None` if no margin up to a factor of
/// about `10^7` above `est` certifies.
fn certified_lambda_max(p_ss: &[f64], w: &[Interval], k: usize, est: f64) -> Option<f64> {
    if !(est.is_finite() && est > 0.0) {
        return None;
    }
    let positive = |mu: f64| linalg::cholesky(&shifted(p_ss, w, mu), k).is_some();
    let mut below = None;
    let mut above = None;
    let mut margin = f64::EPSILON / 16.0;
    for _ in 0..28 {
        let mu = est * (1.0 + margin);
        if positive(mu) {
            above = Some(mu);
            break;
        }
        below = Some(mu);
        margin *= 8.0;
    }
    let mut hi = above?;
    if let Some(mut lo) = below {
        for _ in 0..40 {
            if hi - lo <= 1e-12 * hi {
                break;
            }
            let mid = 0.5 * (lo + hi);
            if positive(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
    }
    Some(hi)
}

/// A float estimate of `lambda_max(P_SS, W)`: by [`Pencil`] up to [`MAX_BALL_STATES`] states,
/// else [`diagonal_estimate`].
fn estimate(p_ss: &[f64], w: &[Interval], k: usize) -> f64 {
    match (k <= MAX_BALL_STATES).then(|| Pencil::new(p_ss, w, k)) {
        Some(Some(pencil)) => pencil.lambda_max(),
        _ => diagonal_estimate(p_ss, w, k),
    }
}

/// `max_i P_ii / W_ii`, the Rayleigh quotients at the unit vectors: at most `lambda_max(P_SS, W)`
/// (a cheap starting point for [`certified_lambda_max`] with many ball states).
fn diagonal_estimate(p_ss: &[f64], w: &[Interval], k: usize) -> f64 {
    (0..k)
        .map(|i| p_ss[i * k + i] / w[i * k + i].mid())
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The pencil `(P_SS, W)` in floats, to choose multipliers: `C = G P_SS G' = V diag(lambda) V'`
/// with `G ~ L^-1`, `W = L L'` (estimates only; nothing rigorous depends on their accuracy).
struct Pencil {
    /// `G`, `k x k` row-major.
    g: Vec<f64>,
    /// The eigenvalues of `C`.
    lambda: Vec<f64>,
    /// Its eigenvectors, column `i` for `lambda_i`.
    v: Vec<f64>,
    k: usize,
}

impl Pencil {
    fn new(p_ss: &[f64], w: &[Interval], k: usize) -> Option<Pencil> {
        let l = linalg::cholesky(w, k)?;
        // Column j of L^-1, as f64.
        let mut g = vec![0.0; k * k];
        for j in 0..k {
            let mut e = vec![Interval::ZERO; k];
            e[j] = Interval::ONE;
            for (i, x) in linalg::forward_solve(&l, k, &e).iter().enumerate() {
                g[i * k + j] = x.mid();
            }
        }
        let gp = mul(&g, p_ss, k, k, k);
        let mut c = vec![0.0; k * k];
        for i in 0..k {
            for j in 0..k {
                c[i * k + j] = (0..k).map(|m| gp[i * k + m] * g[j * k + m]).sum();
            }
        }
        let (lambda, v) = linalg::jacobi_eigen(&c, k);
        lambda
            .iter()
            .all(|x| x.is_finite())
            .then_some(Pencil { g, lambda, v, k })
    }

    fn lambda_max(&self) -> f64 {
        self.lambda.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
    }

    /// `V' G x` for the `k x c` matrix `x`: the eigenbasis coordinates of `L^-1 x`.
    fn project(&self, x: &[f64], c: usize) -> Vec<f64> {
        let k = self.k;
        let gx = mul(&self.g, x, k, k, c);
        let mut out = vec![0.0; k * c];
        for i in 0..k {
            for j in 0..c {
                out[i * c + j] = (0..k).map(|m| self.v[m * k + i] * gx[m * c + j]).sum();
            }
        }
        out
    }
}

/// `a b` for f64 matrices `r x k` and `k x c`, row-major.
fn mul(a: &[f64], b: &[f64], r: usize, k: usize, c: usize) -> Vec<f64> {
    let mut out = vec![0.0; r * c];
    for i in 0..r {
        for m in 0..k {
            let aim = a[i * k + m];
            for j in 0..c {
                out[i * c + j] += aim * b[m * c + j];
            }
        }
    }
    out
}

/// `min over mu > max lambda of rho2 mu + sum_i g_i^2 / (mu - lambda_i)` and its minimiser, in
/// floats: the root of the increasing derivative `rho2 - sum_i g_i^2 / (mu - lambda_i)^2` by
/// bisection on `(0, |g| / sqrt(rho2)]` above `max lambda` (it is non-negative at the upper end);
/// `mu` tends to `max lambda` where `g` has no component along the top eigenvector.
fn secular_min(lambda: &[f64], g: &[f64], rho2: f64) -> (f64, f64) {
    let top = lambda.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b));
    // mu - lambda_i as (top - lambda_i) + t: no cancellation for tiny t.
    let terms = |t: f64, power: i32| -> f64 {
        lambda
            .iter()
            .zip(g)
            .map(|(l, gi)| gi * gi / ((top - l) + t).powi(power))
            .sum()
    };
    let norm = g.iter().map(|x| x * x).sum::<f64>().sqrt();
    let (mut lo, mut hi) = (0.0, norm / rho2.sqrt());
    if hi > 0.0 {
        for _ in 0..200 {
            let t = 0.5 * (lo + hi);
            if t <= lo || t >= hi {
                break;
            }
            if rho2 < terms(t, 2) {
                lo = t;
            } else {
                hi = t;
            }
        }
    }
    let value = rho2 * (top + hi) + if hi > 0.0 { terms(hi, 1) } else { 0.0 };
    (value, top + hi)
}

/// One ellipsoid jointly with the box part's vertices (see the module documentation).
struct Joint<'a> {
    p: &'a [f64],
    n: usize,
    balls: &'a Balls,
    /// The box part's coordinates of non-zero width.
    active: &'a [usize],
    /// Their half-widths.
    h: Vec<f64>,
}

impl<'a> Joint<'a> {
    fn new(p: &'a [f64], n: usize, balls: &'a Balls, active: &'a [usize], half: &[f64]) -> Self {
        Joint {
            p,
            n,
            balls,
            active,
            h: active.iter().map(|&i| half[i]).collect(),
        }
    }

    /// The rigorous bound (`r1` itself, rounded up); `None` if no multiplier certified, or with
    /// a box part and no float pencil (too many ball states).
    fn bound(&self) -> Option<f64> {
        let balls = self.balls;
        if self.active.is_empty() {
            // r1^2 = rho^2 lambda_max.
            return Some((Interval::point(balls.lambda) * balls.rho2).sqrt().hi());
        }
        let pencil = balls.pencil.as_ref()?;
        let kb = self.active.len();
        let vertices = 1usize << (kb - 1);
        // Floats: each vertex's minimiser of U_b and (an estimate of) its value.
        let mut box_part = vec![0.0; vertices];
        vertex_forms(&self.box_form(), kb, |v, x| box_part[v] = x);
        let z = pencil.project(&block(self.p, self.n, &balls.states, self.active), kb);
        let rho2 = balls.rho2.mid();
        let mut g = vec![0.0; pencil.k];
        let (estimate, mus): (Vec<f64>, Vec<f64>) = box_part
            .iter()
            .enumerate()
            .map(|(v, &bpb)| {
                for (i, gi) in g.iter_mut().enumerate() {
                    *gi = (0..kb)
                        .map(|a| {
                            let x = self.h[a] * z[i * kb + a];
                            if vertex_negative(v, a) {
                                -x
                            } else {
                                x
                            }
                        })
                        .sum();
                }
                let (value, mu) = secular_min(&pencil.lambda, &g, rho2);
                (bpb + value, mu)
            })
            .unzip();
        // Rigorous: the smallest bound per vertex over the multipliers used.
        let mut best = vec![f64::INFINITY; vertices];
        let mut used = vec![false; vertices];
        let mut worst = argmax(&estimate);
        for _ in 0..MAX_MULTIPLIERS {
            if used[worst] {
                break;
            }
            used[worst] = true;
            if let Some(bounds) = self.bounds_at(mus[worst].max(balls.lambda)) {
                for (b, x) in best.iter_mut().zip(bounds) {
                    *b = b.min(x);
                }
            }
            worst = argmax(&best);
        }
        let max_sq = best[argmax(&best)];
        max_sq
            .is_finite()
            .then(|| Interval::point(max_sq.max(0.0)).sqrt().hi())
    }

    /// `P_BB h_a h_b` over the active box coordinates, in f64.
    fn box_form(&self) -> Vec<f64> {
        let kb = self.active.len();
        let mut q = block(self.p, self.n, self.active, self.active);
        for a in 0..kb {
            for b in 0..kb {
                q[a * kb + b] *= self.h[a] * self.h[b];
            }
        }
        q
    }

    /// Upper bounds of `U_b(mu)` at every vertex, trying `mu` and slightly larger values (the
    /// interval Cholesky factorisation may not certify `mu` just above `lambda_max`).
    fn bounds_at(&self, mu: f64) -> Option<Vec<f64>> {
        [0.0, 2f64.powi(-40), 2f64.powi(-30), 2f64.powi(-20)]
            .iter()
            .find_map(|bump| self.bounds_exactly_at(mu * (1.0 + bump)))
    }

    /// Upper bounds of `U_b(mu) = mu rho^2 + b' Q(mu) b` at every vertex `b`, with `Q(mu) = P_BB +
    /// X'X`, `X = L^-1 P_SB` and `mu W - P_SS = L L'` in interval arithmetic; `None` if the
    /// factorisation does not certify `mu W - P_SS > 0`.
    fn bounds_exactly_at(&self, mu: f64) -> Option<Vec<f64>> {
        let (balls, kb, n) = (self.balls, self.active.len(), self.n);
        let k = balls.states.len();
        let l = linalg::cholesky(&balls.shifted(mu), k)?;
        let x: Vec<Vec<Interval>> = self
            .active
            .iter()
            .map(|&j| {
                let col: Vec<Interval> = balls
                    .states
                    .iter()
                    .map(|&i| Interval::point(self.p[i * n + j]))
                    .collect();
                linalg::forward_solve(&l, k, &col)
            })
            .collect();
        // q_ab = mid(Q_ab) h_a h_b in f64; the radii of Q's entries are added to every vertex.
        let mut q = vec![0.0; kb * kb];
        let mut spread = Interval::ZERO;
        for a in 0..kb {
            for b in 0..kb {
                let xx = x[a]
                    .iter()
                    .zip(&x[b])
                    .fold(Interval::ZERO, |acc, (&u, &v)| {
                        acc + if a == b { u.sqr() } else { u * v }
                    });
                let entry = Interval::point(self.p[self.active[a] * n + self.active[b]]) + xx;
                let (ha, hb) = (self.h[a], self.h[b]);
                q[a * kb + b] = entry.mid() * ha * hb;
                spread += Interval::point(entry.rad()) * Interval::point(ha) * Interval::point(hb);
            }
        }
        let base = Interval::point(mu) * balls.rho2 + spread + vertex_rounding(&q, kb);
        let mut out = vec![0.0; 1 << (kb - 1)];
        vertex_forms(&q, kb, |v, form| {
            out[v] = (Interval::point(form) + base).hi();
        });
        Some(out)
    }
}

/// The index of the largest entry (the first of equal ones).
fn argmax(x: &[f64]) -> usize {
    (0..x.len()).fold(0, |best, i| if x[i] > x[best] { i } else { best })
}

#[cfg(test)]
mod tests {
    use super::super::radius::initial_center_and_halfwidths;
    use super::*;
    use crate::model::{Ball, Bounds};
    use crate::test_support::rng::Rng;

    /// `r1` and how, with the bounding-box bound of the same set.
    fn r1_and_boxes(p: &[f64], init: &InitialSet) -> (f64, R1Bound, f64) {
        let n = init.boxes.len();
        let (_, half) = initial_center_and_halfwidths(init, n).unwrap();
        let (r1, how) = bound(p, init, &half);
        (r1, how, BoxRadius::new(p, n).bound(&half))
    }

    fn quad(p: &[f64], d: &[f64]) -> f64 {
        let n = d.len();
        (0..n)
            .map(|i| d[i] * (0..n).map(|j| p[i * n + j] * d[j]).sum::<f64>())
            .sum()
    }

    /// A point `y` on the boundary of `{y' M y <= r^2}` in direction `u` (`M = L L'`, `y = r
    /// L^-T u / |u|`), in floats.
    fn on_boundary(m: &[f64], k: usize, r: f64, u: &[f64]) -> Vec<f64> {
        let l = linalg::cholesky(&linalg::to_intervals(m), k).unwrap();
        let norm = u.iter().map(|x| x * x).sum::<f64>().sqrt();
        let mut y = vec![0.0; k];
        for i in (0..k).rev() {
            let s: f64 = (i + 1..k).map(|j| l[j * k + i].mid() * y[j]).sum();
            y[i] = (r * u[i] / norm - s) / l[i * k + i].mid();
        }
        y
    }

    /// `max |d|_P` over a box part's vertices (`sign` patterns of `h` on `box_states`) and
    /// `angles` points of an ellipse's boundary over `ball_states`.
    fn sampled(
        p: &[f64],
        n: usize,
        (box_states, h): (&[usize], &[f64]),
        (ball_states, m, r): ([usize; 2], &[f64], f64),
        angles: usize,
    ) -> f64 {
        let mut best = 0.0f64;
        let mut d = vec![0.0; n];
        for vertex in 0..1usize << box_states.len() {
            for (a, &i) in box_states.iter().enumerate() {
                d[i] = if (vertex >> a) & 1 == 1 { -h[a] } else { h[a] };
            }
            for t in 0..angles {
                let phi = std::f64::consts::TAU * t as f64 / angles as f64;
                let y = on_boundary(m, 2, r, &[phi.cos(), phi.sin()]);
                d[ball_states[0]] = y[0];
                d[ball_states[1]] = y[1];
                best = best.max(quad(p, &d));
            }
        }
        best.sqrt()
    }

    #[test]
    fn one_ball_is_the_ellipse_maximum() {
        let p = [35.68, 2.21, 2.21, 1.27];
        let m = [3.0, -1.2, -1.2, 0.8];
        let r = 0.7;
        let init = InitialSet {
            boxes: vec![None, None],
            balls: vec![Ball {
                states: vec![0, 1],
                center: vec![0.3, -0.1],
                radius: r,
                metric: Some(m.to_vec()),
            }],
        };
        let (r1, how, boxes) = r1_and_boxes(&p, &init);
        assert_eq!(how.balls, BallBound::Joint { balls: 1 });
        assert_eq!(how.boxes, R1Method::Vertices { active: 0 });
        let sampled = sampled(&p, 2, (&[], &[]), ([0, 1], &m, r), 400_000);

        assert!(
            sampled <= r1 && r1 <= sampled * (1.0 + 1e-9),
            "r1 {r1}, sampled {sampled}"
        );
        assert!(r1 < boxes, "r1 {r1}, bounding box {boxes}");
    }

    /// A box part (two coordinates and a point) coupled with a ball over two states listed out
    /// of order: the maximum over vertices times the ellipse, to 1e-9.
    #[test]
    fn box_times_ball_is_the_joint_maximum() {
        let n = 5;
        #[rustfmt::skip]
        let p = [
            4.0, 1.2, -0.7, 0.9, 1.5,
            1.2, 3.0, 0.4, -0.8, 1.1,
            -0.7, 0.4, 2.0, 0.3, -0.2,
            0.9, -0.8, 0.3, 2.5, 0.6,
            1.5, 1.1, -0.2, 0.6, 3.5,
        ];
        let m = [2.0, 0.9, 0.9, 1.0];
        let r = 0.5;
        let init = InitialSet {
            boxes: vec![
                Some(Bounds::new(-0.2, 0.3)),
                None,
                Some(Bounds::new(1.0, 1.0)),
                Some(Bounds::new(0.4, 0.6)),
                None,
            ],
            balls: vec![Ball {
                states: vec![4, 1],
                center: vec![0.0, 2.0],
                radius: r,
                metric: Some(m.to_vec()),
            }],
        };
        let (r1, how, boxes) = r1_and_boxes(&p, &init);
        assert_eq!(how.balls, BallBound::Joint { balls: 1 });
        assert_eq!(how.boxes, R1Method::Vertices { active: 2 });
        let (_, half) = initial_center_and_halfwidths(&init, n).unwrap();
        let sampled = sampled(
            &p,
            n,
            (&[0, 3], &[half[0], half[3]]),
            ([4, 1], &m, r),
            400_000,
        );

        assert!(
            sampled <= r1 && r1 <= sampled * (1.0 + 1e-9),
            "r1 {r1}, sampled {sampled}"
        );
        assert!(r1 < boxes, "r1 {r1}, bounding box {boxes}");
    }

    /// Two balls that `P` couples with nothing else: the S-procedure's weights make the bound
    /// `sqrt(sum_j r_j^2 lambda_j)`, the exact maximum.
    #[test]
    fn uncoupled_balls_are_exact() {
        // States 0, 1: ball A; 2: a box (uncoupled); 3, 4: ball B.
        let n = 5;
        let mut p = vec![0.0; n * n];
        for (i, j, v) in [
            (0, 0, 2.0),
            (0, 1, 0.5),
            (1, 1, 1.0),
            (2, 2, 3.0),
            (3, 3, 5.0),
            (3, 4, -1.0),
            (4, 4, 0.7),
        ] {
            p[i * n + j] = v;
            p[j * n + i] = v;
        }
        let (ma, mb) = ([1.0, 0.2, 0.2, 2.0], [0.5, 0.0, 0.0, 4.0]);
        let ball = |states: Vec<usize>, m: &[f64], radius: f64| Ball {
            states,
            center: vec![0.0, 0.0],
            radius,
            metric: Some(m.to_vec()),
        };
        let init = InitialSet {
            boxes: vec![None, None, Some(Bounds::new(-0.1, 0.1)), None, None],
            balls: vec![ball(vec![0, 1], &ma, 0.3), ball(vec![3, 4], &mb, 1.5)],
        };
        // lambda_max of M^-1 P for 2 x 2 blocks, by the trace and determinant.
        let lambda = |pb: [f64; 4], m: &[f64]| {
            let det_m = m[0] * m[3] - m[1] * m[2];
            let inv = [m[3] / det_m, -m[1] / det_m, -m[2] / det_m, m[0] / det_m];
            let a = [
                inv[0] * pb[0] + inv[1] * pb[2],
                inv[0] * pb[1] + inv[1] * pb[3],
                inv[2] * pb[0] + inv[3] * pb[2],
                inv[2] * pb[1] + inv[3] * pb[3],
            ];
            let (tr, det) = (a[0] + a[3], a[0] * a[3] - a[1] * a[2]);
            0.5 * (tr + (tr * tr - 4.0 * det).sqrt())
        };
        let exact = (3.0 * 0.01
            + 0.09 * lambda([2.0, 0.5, 0.5, 1.0], &ma)
            + 2.25 * lambda([5.0, -1.0, -1.0, 0.7], &mb))
        .sqrt();
        let (r1, how, _) = r1_and_boxes(&p, &init);
        assert_eq!(how.balls, BallBound::Joint { balls: 2 });
        assert!(
            exact <= r1 && r1 <= exact * (1.0 + 1e-9),
            "r1 {r1}, exact {exact}"
        );
    }

    /// Random sets of boxes, points and up to two balls, random metrics: `r1` is never above
    /// the bounding-box bound and never below a sampled point's `|x0 - x*_0|_P`.
    #[test]
    fn never_above_the_bounding_box_bound_and_sound() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let spd = |rng: &mut Rng, k: usize| {
            let a: Vec<f64> = (0..k * k).map(|_| rng.range(-1.0, 1.0)).collect();
            let mut s = vec![0.0; k * k];
            for i in 0..k {
                for j in 0..k {
                    s[i * k + j] = (0..k).map(|m| a[i * k + m] * a[j * k + m]).sum::<f64>()
                        + if i == j { 0.05 } else { 0.0 };
                }
            }
            s
        };
        let mut tighter = 0;
        for case in 0..400 {
            let n = 1 + case % 6;
            let p = spd(&mut rng, n);
            // Each state: 0 box, 1 point, 2 ball A, 3 ball B.
            let kinds: Vec<usize> = (0..n).map(|_| (rng.range(0.0, 4.0)) as usize).collect();
            let mut init = InitialSet {
                boxes: vec![None; n],
                balls: Vec::new(),
            };
            for (i, &kind) in kinds.iter().enumerate() {
                if kind < 2 {
                    let lo = rng.range(-1.0, 1.0);
                    let w = if kind == 1 { 0.0 } else { rng.range(0.0, 0.5) };
                    init.boxes[i] = Some(Bounds::new(lo, lo + w));
                }
            }
            for ball in [2, 3] {
                let states: Vec<usize> = (0..n).filter(|&i| kinds[i] == ball).collect();
                let k = states.len();
                if k > 0 {
                    let metric = (rng.range(0.0, 1.0) < 0.7).then(|| spd(&mut rng, k));
                    init.balls.push(Ball {
                        states,
                        center: (0..k).map(|_| rng.range(-1.0, 1.0)).collect(),
                        radius: rng.range(0.0, 0.6),
                        metric,
                    });
                }
            }
            let (r1, _, boxes) = r1_and_boxes(&p, &init);
            assert!(r1 <= boxes, "case {case}: r1 {r1} > bounding box {boxes}");
            tighter += usize::from(r1 < boxes * (1.0 - 1e-6));
            let (_, half) = initial_center_and_halfwidths(&init, n).unwrap();
            for _ in 0..200 {
                let mut d = vec![0.0; n];
                for i in (0..n).filter(|&i| kinds[i] < 2) {
                    d[i] = half[i] * [-1.0, 1.0, rng.range(-1.0, 1.0)][case % 3];
                }
                for ball in &init.balls {
                    let k = ball.states.len();
                    let u: Vec<f64> = (0..k).map(|_| rng.range(-1.0, 1.0)).collect();
                    let identity: Vec<f64> = (0..k * k)
                        .map(|i| if i % (k + 1) == 0 { 1.0 } else { 0.0 })
                        .collect();
                    let m = ball.metric.as_deref().unwrap_or(&identity);
                    for (&s, y) in ball.states.iter().zip(on_boundary(m, k, ball.radius, &u)) {
                        d[s] = y;
                    }
                }
                let x = quad(&p, &d).sqrt();
                assert!(
                    x <= r1 * (1.0 + 1e-12),
                    "case {case}: |d|_P = {x} > r1 {r1}"
                );
            }
        }
        assert!(tighter > 100, "{tighter}");
    }

    /// Many coordinates: a ball over 100 states alone is exact (identity metrics: `r1 = r`);
    /// with a box part, or with more than MAX_VERTEX_COORDS box coordinates, the parts are
    /// bounded separately, still below the bounding boxes.
    #[test]
    fn many_coordinates_stay_cheap_and_tight() {
        let identity = |n: usize| {
            (0..n * n)
                .map(|i| if i % (n + 1) == 0 { 1.0 } else { 0.0 })
                .collect::<Vec<f64>>()
        };
        let ball = |states: Vec<usize>| Ball {
            center: vec![0.0; states.len()],
            states,
            radius: 0.1,
            metric: None,
        };
        let init = InitialSet {
            boxes: vec![None; 100],
            balls: vec![ball((0..100).collect())],
        };
        let (r1, how, boxes) = r1_and_boxes(&identity(100), &init);
        assert_eq!(how.balls, BallBound::Joint { balls: 1 });
        assert!((0.1..=0.1 * (1.0 + 1e-9)).contains(&r1), "{r1}");
        assert!(boxes >= 0.99, "{boxes}");

        let mut init = InitialSet {
            boxes: vec![Some(Bounds::new(-0.1, 0.1)); 100],
            balls: vec![ball((20..100).collect())],
        };
        init.boxes[20..].fill(None);
        let (r1, how, boxes) = r1_and_boxes(&identity(100), &init);
        assert_eq!(how.balls, BallBound::Separate { balls: 1 });
        assert_eq!(how.boxes, R1Method::AbsoluteSum);
        let exact = (20.0 * 0.01f64).sqrt() + 0.1;
        assert!(r1 >= exact && r1 <= exact * (1.0 + 1e-9), "{r1}");
        assert!(r1 < boxes, "{r1} {boxes}");
    }
}
