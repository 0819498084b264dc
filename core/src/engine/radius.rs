//! The rigorous scalar parts of the contraction PRS: the initial radius `r1`, the
//! deterministic radius `R_t` (Proposition 2) and `Psi_t` (eq. Psi), all in [`Interval`]
//! arithmetic with the upper ends kept.

use super::linalg;
use super::problem::InitialSetError;
use crate::interval::{Interval, ELEM_ULPS};
use crate::model::{AnalysisSpec, Bounds, InitialSet, RadiusRule};
use crate::prs::RuleUsed;

/// Number of box coordinates (with non-zero width) up to which `r1` is the exact maximum over
/// the box's vertices; above it the cheaper bound `sum_ij |P_ij| h_i h_j` is used.
pub const MAX_VERTEX_COORDS: usize = 16;

/// Interval enclosure of `expm1(x) = e^x - 1`, increasing, from `f64::exp_m1` at the ends
/// widened by [`ELEM_ULPS`] ulps (the same accuracy assumption as the interval module makes for
/// `exp`: the usual libms document `expm1` within 1 ulp). Using `expm1` rather than `exp - 1`
/// keeps the relative accuracy for small `|x|` (short steps, small `|c|`).
pub(crate) fn expm1(x: Interval) -> Interval {
    let widen = |mut v: f64, up: bool| {
        for _ in 0..ELEM_ULPS {
            v = if up { v.next_up() } else { v.next_down() };
        }
        v
    };
    let mut lo = if x.lo() == f64::NEG_INFINITY {
        -1.0
    } else {
        widen(x.lo().exp_m1(), false).max(-1.0)
    };
    let mut hi = if x.hi() == f64::INFINITY {
        f64::INFINITY
    } else {
        widen(x.hi().exp_m1(), true)
    };
    // expm1 has the sign of its argument.
    if x.lo() >= 0.0 {
        lo = lo.max(0.0);
    }
    if x.hi() <= 0.0 {
        hi = hi.min(0.0);
    }
    Interval::try_new(lo, hi).unwrap_or(Interval::ENTIRE)
}

/// `expm1(a h) / a`, the integral of `e^(a s)` over `[0, h]`; `h` itself at `a = 0`.
pub(crate) fn expm1_over(a: f64, h: Interval) -> Interval {
    if a == 0.0 {
        h
    } else {
        let a = Interval::point(a);
        expm1(a * h) / a
    }
}

/// One exact step of `Psi' = 2 c Psi + sigma^2` over a step of length `h` on which `c` and
/// `sigma` are constant: `Psi(t+h) = Psi(t) e^(2ch) + sigma^2 expm1(2ch) / (2c)`, written per
/// step so piecewise-constant rates only need another `(c, sigma)` per step; `Psi(t+h)` is
/// increasing in `Psi(t)`, so an enclosure of `Psi(t)` maps to one of `Psi(t+h)`.
///
/// The affine map `Psi -> Psi decay + gain` of one step is kept so that equal consecutive steps
/// (the usual case: constant rates, uniform grid) reuse it instead of recomputing `exp` and
/// `expm1` in interval arithmetic.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PsiStep {
    key: (u64, u64, u64, u64),
    decay: Interval,
    gain: Interval,
}

impl PsiStep {
    /// The step map for rates `(c, sigma)` and step-length enclosure `h`.
    pub(crate) fn new(c: f64, sigma: f64, h: Interval) -> PsiStep {
        let sigma2 = Interval::point(sigma).sqr();
        // 2c is exact (doubling), so expm1_over(2c, h) encloses the integral of e^(2c s).
        PsiStep {
            key: Self::key(c, sigma, h),
            decay: (Interval::point(2.0 * c) * h).exp(),
            gain: sigma2 * expm1_over(2.0 * c, h),
        }
    }

    fn key(c: f64, sigma: f64, h: Interval) -> (u64, u64, u64, u64) {
        (
            c.to_bits(),
            sigma.to_bits(),
            h.lo().to_bits(),
            h.hi().to_bits(),
        )
    }

    /// Whether this map is the one for `(c, sigma, h)` (bitwise equal inputs).
    pub(crate) fn matches(&self, c: f64, sigma: f64, h: Interval) -> bool {
        self.key == Self::key(c, sigma, h)
    }

    /// `Psi(t + h)` from an enclosure of `Psi(t)`.
    pub(crate) fn apply(&self, psi: Interval) -> Interval {
        psi * self.decay + self.gain
    }
}

/// The centre of the initial set (box midpoints, ball centres) and, per state, a half-width
/// `h_i` with `|x_i - centre_i| <= h_i` for every `x` in the set (rounded up).
///
/// Ball parts `(x_S - c)' M (x_S - c) <= r^2` are replaced by their bounding box
/// `|x_i - c_i| <= r sqrt((M^-1)_ii)`: conservative (the box's corners are outside the ball),
/// but it keeps `r1` a single, simple formula. `(M^-1)_ii` is enclosed rigorously by an
/// interval Cholesky factorisation of `M`.
pub(crate) fn initial_center_and_halfwidths(
    init: &InitialSet,
    n: usize,
) -> Result<(Vec<f64>, Vec<f64>), InitialSetError> {
    if init.boxes.len() != n {
        return Err(InitialSetError::Entries {
            entries: init.boxes.len(),
            n,
        });
    }
    let mut center = vec![f64::NAN; n];
    let mut half = vec![f64::NAN; n];
    for (i, b) in init.boxes.iter().enumerate() {
        if let Some(Bounds { lo, hi }) = *b {
            let iv = Interval::try_new(lo, hi)
                .filter(|iv| iv.is_bounded())
                .ok_or(InitialSetError::UnboundedBox {
                    state: i,
                    range: Bounds { lo, hi },
                })?;
            center[i] = iv.mid();
            half[i] = iv.rad();
        }
    }
    for (bi, ball) in init.balls.iter().enumerate() {
        let k = ball.states.len();
        if ball.center.len() != k || !ball.radius.is_finite() || ball.radius < 0.0 {
            return Err(InitialSetError::MalformedBall { ball: bi });
        }
        let diag_inv: Vec<Interval> = match &ball.metric {
            None => vec![Interval::ONE; k],
            Some(m) => {
                if m.len() != k * k {
                    return Err(InitialSetError::BallMetricSize { ball: bi, k });
                }
                let l = linalg::cholesky(&linalg::to_intervals(m), k)
                    .ok_or(InitialSetError::BallMetricIndefinite { ball: bi })?;
                let inv = linalg::inverse_block(&l, k, &(0..k).collect::<Vec<_>>());
                (0..k).map(|i| inv[i * k + i]).collect()
            }
        };
        for (j, &s) in ball.states.iter().enumerate() {
            if s >= n {
                return Err(InitialSetError::BallState {
                    ball: bi,
                    state: s,
                    n,
                });
            }
            center[s] = ball.center[j];
            half[s] = (Interval::point(ball.radius) * diag_inv[j].sqrt()).hi();
        }
    }
    if let Some(i) = (0..n).find(|&i| center[i].is_nan()) {
        return Err(InitialSetError::Missing { state: i });
    }
    Ok((center, half))
}

/// Upper bounds of `max |d|_P` over boxes `|d_i| <= h_i` for one metric `P` (row-major `n x n`).
///
/// `d' P d` is convex in `d`, so its maximum over the box is attained at a vertex. With at most
/// [`MAX_VERTEX_COORDS`] coordinates of non-zero width every vertex is evaluated (in f64 with a
/// rigorous bound of the rounding error); otherwise `d' P d <= sum_ij |P_ij| h_i h_j` is used,
/// over the non-zero entries of `P` found once, so it costs `O(nnz(P))` rather than `O(n^2)`.
/// The square root is rounded up.
pub(crate) struct BoxRadius<'a> {
    p: &'a [f64],
    nonzeros: Vec<(usize, usize, f64)>,
}

impl<'a> BoxRadius<'a> {
    /// `p` is `n x n` row-major.
    pub(crate) fn new(p: &'a [f64], n: usize) -> Self {
        let nonzeros = p
            .iter()
            .enumerate()
            .filter(|&(_, &v)| v != 0.0)
            .map(|(idx, &v)| (idx / n, idx % n, v))
            .collect();
        BoxRadius { p, nonzeros }
    }

    /// Upper bound of `max |d|_P` over `|d_i| <= half_i` (see [`BoxRadius`]).
    pub(crate) fn bound(&self, half: &[f64]) -> f64 {
        let (p, n) = (self.p, half.len());
        let active: Vec<usize> = (0..n).filter(|&i| half[i] > 0.0).collect();
        if active.is_empty() {
            return 0.0;
        }
        let k = active.len();
        if k > MAX_VERTEX_COORDS {
            let sum = self
                .nonzeros
                .iter()
                .fold(Interval::ZERO, |acc, &(i, j, v)| {
                    acc + Interval::point(v.abs())
                        * Interval::point(half[i])
                        * Interval::point(half[j])
                });
            return Interval::point(sum.hi().max(0.0)).sqrt().hi();
        }
        // q_ab = P_ij h_i h_j over the active coordinates in f64, and whether q is diagonal.
        let mut q = vec![0.0; k * k];
        let mut diagonal = true;
        for (a, &i) in active.iter().enumerate() {
            for (b, &j) in active.iter().enumerate() {
                let v = p[i * n + j] * half[i] * half[j];
                q[a * k + b] = v;
                diagonal &= a == b || v == 0.0;
            }
        }
        let max_sq = if diagonal {
            // Every vertex gives sum_a q_aa.
            active.iter().fold(Interval::ZERO, |acc, &i| {
                acc + Interval::point(p[i * n + i])
                    * Interval::point(half[i])
                    * Interval::point(half[i])
            })
        } else {
            let mut max_sq = f64::NEG_INFINITY;
            vertex_forms(&q, k, |_, v| max_sq = max_sq.max(v));
            Interval::point(max_sq) + vertex_rounding(&q, k)
        };
        Interval::point(max_sq.hi().max(0.0)).sqrt().hi()
    }
}

/// Whether coordinate `a` of vertex number `vertex` of [`vertex_forms`] has the sign `-1`.
pub(crate) fn vertex_negative(vertex: usize, a: usize) -> bool {
    a > 0 && (vertex >> (a - 1)) & 1 == 1
}

/// `s' q s` in f64 for the sign vectors `s` of a box's vertices (`q` is `k x k` row-major,
/// `k >= 1`), passed to `f` with the vertex's number. Vertices `s` and `-s` give the same value,
/// so `s_0 = +1` and the other `2^(k-1)` sign patterns are enumerated: `s_a = -1` where
/// [`vertex_negative`]. Each value is within [`vertex_rounding`] of the exact form of the `q`
/// given, and of the exact `q` itself when every `q_ab` is an f64 product of at most three exact
/// factors (`P_ij h_i h_j`).
pub(crate) fn vertex_forms(q: &[f64], k: usize, mut f: impl FnMut(usize, f64)) {
    debug_assert!((1..=MAX_VERTEX_COORDS).contains(&k) && q.len() == k * k);
    for vertex in 0..1usize << (k - 1) {
        let sign = |a: usize| {
            if vertex_negative(vertex, a) {
                -1.0
            } else {
                1.0
            }
        };
        let s: f64 = (0..k)
            .map(|a| sign(a) * (0..k).map(|b| sign(b) * q[a * k + b]).sum::<f64>())
            .sum();
        f(vertex, s);
    }
}

/// A bound of the rounding error of each value of [`vertex_forms`]: a sum of `k^2` terms
/// `+-q_ab`, each within `2u |q_ab|` of its exact value; the products' and the sums' errors stay
/// below `(k^2 + 2) u sum |q_ab|`, within this margin with a factor 2 (rounded up).
pub(crate) fn vertex_rounding(q: &[f64], k: usize) -> Interval {
    let abs_sum = q
        .iter()
        .fold(Interval::ZERO, |acc, v| acc + Interval::point(v.abs()));
    abs_sum * Interval::point((k * k + 2) as f64 * f64::EPSILON)
}

/// `kappa(n, delta)` of the analysis' radius rule, and the rule as used (with the minimising
/// `eps` for `paper(optimal)`).
pub(crate) fn stochastic_factor(n: usize, spec: &AnalysisSpec) -> (f64, RuleUsed) {
    let kappa = crate::kappa::kappa(n, spec.delta, spec.radius);
    let eps = match spec.radius {
        RadiusRule::Amgf => None,
        RadiusRule::Paper(eps) => Some(eps),
        RadiusRule::PaperOptimal => Some(crate::kappa::kappa_paper_optimal(n, spec.delta).1),
    };
    (
        kappa,
        RuleUsed {
            rule: spec.radius,
            eps,
            gaussian: None,
        },
    )
}

/// `Psi_t` and `r_t = sqrt(Psi_t kappa)` along the report grid: exact per-step Psi, reusing the
/// step map while the rates and the step length repeat; upper ends kept.
pub(crate) struct Stochastic {
    kappa: Interval,
    psi: Interval,
    map: Option<PsiStep>,
}

impl Stochastic {
    /// Starts at `Psi_0 = 0`.
    pub(crate) fn new(kappa: f64) -> Stochastic {
        Stochastic {
            kappa: Interval::point(kappa),
            psi: Interval::ZERO,
            map: None,
        }
    }

    /// Advances `Psi` over `[prev, t]` with the rates `(c, sigma)` of that step (nothing at the
    /// first report time, `prev = None`); returns upper bounds of `(Psi_t, r_t)`.
    pub(crate) fn advance(&mut self, prev: Option<f64>, t: f64, c: f64, sigma: f64) -> (f64, f64) {
        if let Some(prev) = prev {
            let h = Interval::point(t) - Interval::point(prev);
            let map = match self.map {
                Some(m) if m.matches(c, sigma, h) => m,
                _ => PsiStep::new(c, sigma, h),
            };
            self.psi = map.apply(self.psi);
            self.map = Some(map);
        }
        let psi = self.psi.hi();
        (psi, (Interval::point(psi) * self.kappa).sqrt().hi())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn psi_steps_match_closed_form() {
        let (c, sigma) = (-0.4, 2f64.sqrt());
        let mut psi = Interval::ZERO;
        let h = 0.01;
        for k in 1..=400 {
            psi = PsiStep::new(c, sigma, Interval::point(h)).apply(psi);
            let t = k as f64 * h;
            let exact = sigma * sigma * (2.0 * c * t).exp_m1() / (2.0 * c);
            assert!(psi.lo() <= exact * (1.0 + 1e-15) && exact * (1.0 - 1e-15) <= psi.hi());
            assert!((psi.hi() - exact).abs() <= 1e-12 * exact);
        }
    }

    #[test]
    fn psi_at_zero_rate_is_linear() {
        let psi = PsiStep::new(0.0, 3.0, Interval::point(0.5)).apply(Interval::ZERO);
        assert!(psi.contains(4.5));
    }

    #[test]
    fn r1_vertices_vs_sum_bound() {
        // P = [[2, 1], [1, 2]], h = (1, 1): vertex max at (1, 1): 6.
        let r = BoxRadius::new(&[2.0, 1.0, 1.0, 2.0], 2).bound(&[1.0, 1.0]);
        assert!(r >= 6f64.sqrt() && r <= 6f64.sqrt() * (1.0 + 1e-14));
        // Negative coupling: max at (1, -1): 2 + 2 + 2 = 6 as well.
        let r = BoxRadius::new(&[2.0, -1.0, -1.0, 2.0], 2).bound(&[1.0, 1.0]);
        assert!(r >= 6f64.sqrt() && r <= 6f64.sqrt() * (1.0 + 1e-14));
    }

    #[test]
    fn expm1_encloses() {
        for x in [-3.0, -1e-9, 0.0, 1e-12, 0.7] {
            let e = expm1(Interval::point(x));
            assert!(e.contains(x.exp_m1()));
            assert!(e.width() <= 1e-14 * x.exp_m1().abs().max(1e-300) + 1e-300);
        }
    }
}
