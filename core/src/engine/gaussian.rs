//! Exact Gaussian radii for affine SDEs (method.md section 8.1).
//!
//! When `D_x f = A` and `G` are constant ([`ModelInfo::affine`](crate::model::ModelInfo::affine)),
//! the deviation `e_t = X_t - x_t` from the deterministic trajectory with the same initial state
//! and input is `N(0, Sigma_t)`, `Sigma_t = int_0^t e^(A s) W e^(A' s) ds`, `W = G G'`, whatever
//! the initial state and the input. With `P = R'R`:
//!
//! * pointwise: `{v : v' Sigma_t^-1 v <= q}`, `q` an upper bound of `chi2_n^-1(1 - delta)`,
//!   holds `e_t` with probability `1 - delta` and lies in the P-ball of radius
//!   `sqrt(q lambda_max(R Sigma_t R'))`: exact when `Sigma_t` is a multiple of `P^-1`, never
//!   above the AMGF radius (which must hold for this Gaussian too). `Sigma_t` grows in the
//!   Loewner order, so a report interval's largest radius is its end's.
//! * time-uniform (method of mixtures): `e_t = Phi_t M_t`, `Phi_t = e^(A t)`, with `M_t` a
//!   continuous Gaussian martingale of quadratic variation `Q_t`. For a fixed `H > 0`, mixing
//!   `exp(l' M_t - l' Q_t l / 2)` over `l ~ N(0, H^-1)` gives the non-negative martingale
//!   `det(I + H^-1 Q_t)^(-1/2) exp(M_t' (Q_t + H)^-1 M_t / 2)`, so by Ville's inequality
//!   `M_t' (Q_t + H)^-1 M_t < 2 ln(1/delta_j) + ln det(I + H^-1 Q_t)` for all `t` at once, except
//!   with probability `delta_j`. Epoch `j` (report times up to `t_e`) takes `H = eta Q_(t_e)`:
//!   for `t <= t_e`, `Q_t <= Q_(t_e)` bounds the log-determinant by `n ln(1 + 1/eta)`, and
//!   `e_t` lies in the ellipsoid of shape `beta_j (Sigma_t + eta B_t)` with
//!   `B_t = e^(-A (t_e - t)) Sigma_(t_e) e^(-A' (t_e - t))`. The epochs (laid out from
//!   `lambda_max(R Sigma R')` doubling, like the AMGF tube's) share `delta` by the union bound.
//!
//! Rigour: `e^(A h)` and `int_0^h e^(A s) W e^(A' s) ds` are Taylor series with a bounded
//! remainder in interval arithmetic over enclosures of `A` and `W` (the system's interval
//! Jacobian and diffusion), over sub-steps short enough for the series and joined by doubling;
//! `lambda_max` is verified by interval Cholesky ([`linalg::lambda_max`]); `q` comes from
//! [`chi2_quantile_upper`]. Everything about epochs and `eta` is fixed before the fact from
//! deterministic quantities, so any choice is valid.

use super::linalg::{self, lambda_max, product};
use super::Run;
use crate::chi2::chi2_quantile_upper;
use crate::interval::Interval;
use crate::kappa::log_inv_delta_upper;

/// Above this many states the covariance is not propagated (`n^3` interval products per step).
pub(crate) const MAX_STATES: usize = 64;

/// The most epochs of the mixture tube (as for the AMGF tube).
const MAX_EPOCHS: usize = 64;

/// The most pieces a report step is cut into to enclose `e^(-A theta)` over it (the mixture
/// tube's bound between report times); beyond, the mixture tube is not offered.
const MAX_PIECES: usize = 64;

/// Taylor terms are added until the remainder is below this (relative to the leading term).
const REMAINDER: f64 = 1e-20;

/// An `n x n` interval matrix, row-major.
type Mat = Vec<Interval>;

/// The radii of the Gaussian route at the report times after 0.
pub(super) struct GaussianRadii {
    /// Upper bound of `chi2_n^-1(1 - delta)`.
    pub(super) quantile: f64,
    /// Pointwise radius at each report time.
    pub(super) pointwise: Vec<f64>,
    /// The mixture tube: per report time `(radius at it, largest radius over the report
    /// interval ending there)`, with its number of epochs; `None` when `Sigma` is singular.
    pub(super) uniform: Option<(Vec<(f64, f64)>, usize)>,
}

/// The affine system's constant matrices: enclosures of `A = D_x f` and `W = G G'`, and the
/// metric's factor `R` (`P = R'R`).
struct Linear {
    n: usize,
    a: Mat,
    w: Mat,
    r: Mat,
}

/// Radii of the Gaussian route at the report times `times` (after 0, increasing), or `None`
/// when the system is too large or its matrices cannot be enclosed.
pub(super) fn radii(run: &Run, times: &[f64]) -> Option<GaussianRadii> {
    let lin = Linear::of(run)?;
    let n = lin.n;
    let quantile = chi2_quantile_upper(n, run.spec.delta);
    // Sigma at every report time and the steps' lengths (the flow is reused while the step
    // repeats).
    let mut sigma = Vec::with_capacity(times.len());
    let mut steps = Vec::with_capacity(times.len());
    let mut cur = vec![Interval::ZERO; n * n];
    let mut t0 = 0.0;
    let mut cache: Option<(Interval, Mat, Mat)> = None;
    for &t in times {
        let h = Interval::point(t) - Interval::point(t0);
        let (phi, q) = match &cache {
            Some((ch, phi, q)) if *ch == h => (phi.clone(), q.clone()),
            _ => {
                let (phi, q) = lin.flow(1.0, h);
                cache = Some((h, phi.clone(), q.clone()));
                (phi, q)
            }
        };
        cur = add(&congruence(&phi, &cur, n), &q);
        sigma.push(cur.clone());
        steps.push(h);
        t0 = t;
    }
    let lam: Vec<f64> = sigma.iter().map(|s| lin.lambda(s)).collect();
    if lam.iter().any(|l| !l.is_finite()) {
        return None;
    }
    let q = Interval::point(quantile);
    let pointwise = lam
        .iter()
        .map(|&l| (q * Interval::point(l.max(0.0))).sqrt().hi())
        .collect();
    let uniform = lin.mixture(run, times, &sigma, &steps, &lam);
    Some(GaussianRadii {
        quantile,
        pointwise,
        uniform,
    })
}

impl Linear {
    fn of(run: &Run) -> Option<Linear> {
        let (sys, n) = (run.sys, run.setup.n);
        if !run.info.affine || n > MAX_STATES {
            return None;
        }
        let m = sys.m();
        let x: Vec<Interval> = vec![Interval::ENTIRE; n];
        let t = Interval::new(0.0, run.spec.horizon);
        let inputs = super::input_intervals(run.info);
        let mut a = vec![Interval::ZERO; n * n];
        sys.jac_x_interval(&x, &inputs, t, &mut a);
        let mut g = vec![Interval::ZERO; n * m];
        sys.diffusion_interval(&x, t, &mut g);
        if a.iter().chain(&g).any(|v| !v.is_bounded()) {
            return None;
        }
        let mut w = vec![Interval::ZERO; n * n];
        for i in 0..n {
            for j in 0..n {
                let mut s = Interval::ZERO;
                for k in 0..m {
                    s += g[i * m + k] * g[j * m + k];
                }
                w[i * n + j] = s;
            }
        }
        let chol = linalg::cholesky(&linalg::to_intervals(&run.setup.consts.metric), n)?;
        let r = transpose(&chol, n);
        Some(Linear { n, a, w, r })
    }

    /// An upper bound of `lambda_max(R S R')` over the symmetric matrices in `s`.
    fn lambda(&self, s: &Mat) -> f64 {
        let n = self.n;
        let rs = product(
            &product(&self.r, s, n, n, n),
            &transpose(&self.r, n),
            n,
            n,
            n,
        );
        lambda_max(&linalg::symmetric_part(&rs, n), n)
    }

    /// `(||A||_inf + ||A||_1)`, an upper bound (the growth of `X -> A X + X A'`).
    fn norm(&self) -> f64 {
        let n = self.n;
        let (mut rows, mut cols) = (0.0f64, 0.0f64);
        for i in 0..n {
            let (mut r, mut c) = (Interval::ZERO, Interval::ZERO);
            for j in 0..n {
                r += Interval::point(self.a[i * n + j].mag());
                c += Interval::point(self.a[j * n + i].mag());
            }
            rows = rows.max(r.hi());
            cols = cols.max(c.hi());
        }
        (Interval::point(rows) + Interval::point(cols)).hi()
    }

    /// Enclosures of `e^(s A h)` and `int_0^h e^(s A u) W e^(s A' u) du` (`s = +-1`) for every
    /// `h` in the point-like enclosure `h`: sub-steps `h / 2^k` short enough for the series,
    /// joined by `Phi_2h = Phi_h^2`, `Q_2h = Phi_h Q_h Phi_h' + Q_h`.
    fn flow(&self, s: f64, h: Interval) -> (Mat, Mat) {
        let norm = self.norm();
        let mut k = 0;
        let mut sub = h;
        while k < 1100 && (Interval::point(norm) * sub).hi() > 0.5 {
            sub *= Interval::point(0.5);
            k += 1;
        }
        let (mut phi, mut q) = self.taylor(s, sub, norm);
        for _ in 0..k {
            q = add(&congruence(&phi, &q, self.n), &q);
            phi = product(&phi, &phi, self.n, self.n, self.n);
        }
        (phi, q)
    }

    /// An enclosure of `e^(s A theta)` for every `theta` in `[0, h]`, or `None` when that takes
    /// more than [`MAX_PIECES`] pieces (a stiff `A` against the report step).
    fn flow_over(&self, s: f64, h: Interval) -> Option<Mat> {
        let norm = self.norm();
        let pieces = ((Interval::point(norm) * h).hi() / 0.5).ceil().max(1.0);
        if pieces > MAX_PIECES as f64 {
            return None;
        }
        let pieces = pieces as usize;
        let sub = Interval::new(0.0, (h / Interval::point(pieces as f64)).hi());
        let (over, _) = self.taylor(s, sub, norm);
        let (step, _) = self.flow(s, h / Interval::point(pieces as f64));
        // e^(sA theta) = e^(sA j h') e^(sA [0, h']) for theta in [j h', (j+1) h'].
        let mut start = identity(self.n);
        let mut hull = over.clone();
        for _ in 1..pieces {
            start = product(&start, &step, self.n, self.n, self.n);
            let part = product(&start, &over, self.n, self.n, self.n);
            hull = hull.iter().zip(&part).map(|(a, b)| a.hull(*b)).collect();
        }
        Some(hull)
    }

    /// Taylor enclosures for `(norm h) <= 1/2` (`norm` from [`Linear::norm`]): the partial sums
    /// of `sum_k (s A h)^k / k!` and `sum_k h^(k+1) / (k+1)! L^k(W)`, `L(X) = s(A X + X A')`,
    /// plus their remainders added to every entry (entries are bounded by the inf-norm).
    fn taylor(&self, s: f64, h: Interval, norm: f64) -> (Mat, Mat) {
        let n = self.n;
        let sa: Mat = self.a.iter().map(|&v| v * Interval::point(s)).collect();
        let nu = (Interval::point(norm) * Interval::point(h.hi().max(0.0))).hi();
        let w_norm = inf_norm(&self.w, n);
        let mut phi = identity(n);
        let mut term = identity(n);
        let mut x = self.w.clone();
        let mut coef = h;
        let mut q: Mat = x.iter().map(|&v| v * coef).collect();
        let mut k = 1usize;
        // Remainder factors nu^(k+1) / (k+1)! for Phi and h nu^(k+1) / (k+2)! for Q.
        let mut tail = Interval::point(nu);
        loop {
            let kk = Interval::point(k as f64);
            // `h / k` once per term: a product per entry, not a product and a quotient.
            let scale = h / kk;
            term = product(&term, &sa, n, n, n)
                .into_iter()
                .map(|v| v * scale)
                .collect();
            phi = add(&phi, &term);
            let ax = product(&sa, &x, n, n, n);
            x = add(&ax, &transpose(&ax, n));
            coef = coef * h / (kk + Interval::ONE);
            q = add(&q, &x.iter().map(|&v| v * coef).collect::<Mat>());
            tail = tail * Interval::point(nu) / (kk + Interval::ONE);
            if tail.hi() <= REMAINDER || k >= 60 {
                break;
            }
            k += 1;
        }
        // Geometric tails: sum_(j > k) nu^j / j! <= nu^(k+1) / (k+1)! / (1 - nu / (k+2)).
        let kk = Interval::point(k as f64);
        let ratio = Interval::ONE - Interval::point(nu) / (kk + Interval::point(2.0));
        let rem_phi = (tail / ratio).hi();
        let rem_q = (Interval::point(h.hi().max(0.0)) * Interval::point(w_norm) * tail
            / (kk + Interval::point(2.0))
            / ratio)
            .hi();
        let widen =
            |m: Mat, r: f64| -> Mat { m.into_iter().map(|v| v + Interval::new(-r, r)).collect() };
        (widen(phi, rem_phi), widen(q, rem_q))
    }

    /// The mixture tube (see the module documentation), or `None` when `Sigma` is singular at
    /// the first report time (then `H` would not be positive definite) or `A` is too stiff for
    /// the report step ([`MAX_PIECES`]).
    fn mixture(
        &self,
        run: &Run,
        times: &[f64],
        sigma: &[Mat],
        steps: &[Interval],
        lam: &[f64],
    ) -> Option<(Vec<(f64, f64)>, usize)> {
        let n = self.n;
        let (first, last) = (*lam.first()?, *lam.last()?);
        linalg::cholesky(&sigma[0], n)?;
        if first <= 0.0 {
            return None;
        }
        let k = ((last / first).max(1.0).log2().ceil() as usize + 1).clamp(1, MAX_EPOCHS);
        // Epoch ends: the first report time whose lambda reaches each threshold.
        let mut ends: Vec<usize> = (0..k)
            .map(|j| {
                let threshold = last * 2f64.powi(j as i32 + 1 - k as i32);
                lam.iter()
                    .position(|&l| l >= threshold)
                    .unwrap_or(times.len() - 1)
            })
            .collect();
        ends.dedup();
        if ends.last() != Some(&(times.len() - 1)) {
            ends.push(times.len() - 1);
        }
        let epochs = ends.len();
        let delta_j = (run.spec.delta / epochs as f64).next_down();
        let log_inv = log_inv_delta_upper(delta_j);
        let eta = best_eta(n, log_inv);
        let beta = (Interval::point(2.0) * Interval::point(log_inv)
            + Interval::point(n as f64) * (Interval::ONE + Interval::point(eta).recip()).ln())
        .hi();
        let (beta, eta) = (Interval::point(beta), Interval::point(eta));
        let mut out = vec![(0.0, 0.0); times.len()];
        let mut start = 0;
        for &end in &ends {
            // B at the epoch's end is Sigma there; backwards with e^(-A h).
            let mut b = sigma[end].clone();
            for idx in (start..=end).rev() {
                let h = &steps[idx];
                let at = add(&sigma[idx], &scale(&b, eta));
                let r_end = (beta * Interval::point(self.lambda(&at))).sqrt().hi();
                // Over (t_(idx-1), t_idx]: Sigma at most its end's, B_t = e^(-A th) B e^(-A' th).
                let back_over = self.flow_over(-1.0, *h)?;
                let b_over = self.lambda(&congruence(&back_over, &b, n));
                let over = (beta
                    * (Interval::point(lam[idx]) + eta * Interval::point(b_over.max(0.0))))
                .sqrt()
                .hi();
                out[idx] = (r_end, over.max(r_end));
                if idx > start {
                    let (back, _) = self.flow(-1.0, *h);
                    b = congruence(&back, &b, n);
                }
            }
            start = end + 1;
        }
        out.iter()
            .all(|(a, b)| a.is_finite() && b.is_finite())
            .then_some((out, epochs))
    }
}

/// Enclosures of `e^(A h)` and `int_0^h e^(A s) W e^(A' s) ds` for a point matrix `A` (row-major)
/// and the interval matrix `w` (the linearisation's step of method.md 8.10; the metric is not
/// used).
pub(super) fn step_flow(
    a: &[f64],
    w: &[Interval],
    n: usize,
    h: Interval,
) -> (Vec<Interval>, Vec<Interval>) {
    let lin = Linear {
        n,
        a: a.iter().map(|&v| Interval::point(v)).collect(),
        w: w.to_vec(),
        r: Vec::new(),
    };
    lin.flow(1.0, h)
}

/// `eta` minimising `(1 + eta)(2 L + n ln(1 + 1/eta))`, the squared radius factor at an epoch's
/// end (golden section on `ln eta`; any `eta > 0` is valid).
pub(super) fn best_eta(n: usize, log_inv: f64) -> f64 {
    let f = |u: f64| {
        let eta = u.exp();
        (1.0 + eta) * (2.0 * log_inv + n as f64 * (1.0 / eta).ln_1p())
    };
    let (mut a, mut b) = (-12.0f64, 6.0f64);
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..100 {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if f(c) < f(d) {
            b = d;
        } else {
            a = c;
        }
    }
    (0.5 * (a + b)).exp()
}

/// `M X M'`.
pub(super) fn congruence(m: &Mat, x: &Mat, n: usize) -> Mat {
    product(&product(m, x, n, n, n), &transpose(m, n), n, n, n)
}

pub(super) fn add(a: &Mat, b: &Mat) -> Mat {
    a.iter().zip(b).map(|(x, y)| *x + *y).collect()
}

fn scale(a: &Mat, s: Interval) -> Mat {
    a.iter().map(|&x| x * s).collect()
}

fn transpose(a: &Mat, n: usize) -> Mat {
    (0..n * n).map(|k| a[(k % n) * n + k / n]).collect()
}

fn identity(n: usize) -> Mat {
    (0..n * n)
        .map(|k| {
            if k % n == k / n {
                Interval::ONE
            } else {
                Interval::ZERO
            }
        })
        .collect()
}

/// An upper bound of the largest row sum of magnitudes.
fn inf_norm(a: &Mat, n: usize) -> f64 {
    (0..n)
        .map(|i| {
            (0..n)
                .fold(Interval::ZERO, |s, j| {
                    s + Interval::point(a[i * n + j].mag())
                })
                .hi()
        })
        .fold(0.0, f64::max)
}
