//! The time-uniform stochastic tube (method.md section 8.2): one event of probability at least
//! `1 - delta` on which `|X_t - x_t|_P < rho_t` for all `t` in `[0, T]` at once.
//!
//! In the scaled coordinates of the proof of Theorem 1, `psi_t = int_0^t c_s ds` and
//! `S_t = int_0^t sigma_s^2 e^(-2 psi_s) ds` (so `Psi_t = e^(2 psi_t) S_t`), and for every fixed
//! `lambda > 0`, `M_t = e^(-lambda^2 S_t / 2) Phi_n(lambda |v~_t|)` is a non-negative
//! supermartingale with `M_0 = 1`. Ville's inequality: `P(sup_t M_t >= 1/delta) <= delta`, and
//! off that event `|X_t - x_t|_P < e^(psi_t) z(S_t) / lambda`, `z(S)` the root of
//! `ln Phi_n(z) = lambda^2 S / 2 + ln(1/delta)`.
//!
//! One `lambda` is tight at one value of `S` only, so the horizon is cut into epochs by `S`
//! (deterministic): thresholds `S^(k) = S_T 2^(k + 1 - K)`, epoch `k` the times with
//! `S_t in (S^(k-1), S^(k)]`, each with its own `lambda_k` (optimal at `S^(k)`) and
//! `delta_k = delta / K`; the union bound gives probability `delta`. At an epoch's end the radius
//! is the pointwise one at `delta_k`, in particular at the horizon.
//!
//! Rigour: `psi_t`, `S_t` are enclosed in interval arithmetic; `z` is the upper end of a bisection
//! on a certified lower bound of `ln Phi_n` ([`log_phi_lower`]), so it is never below the exact
//! root; a time whose epoch is uncertain (its `S_t` enclosure meets a threshold) gets the larger
//! of the candidate epochs' radii.

use super::radius::expm1_over;
use crate::interval::Interval;
use crate::kappa::{amgf_minimiser, log_inv_delta_upper, log_phi_lower};
use std::cell::RefCell;

/// The most epochs (the union bound's price grows with their number).
const MAX_EPOCHS: usize = 64;

/// Enclosures of `psi_t` and `S_t` at the ends of the internal steps (index 0: `t = 0`).
#[derive(Clone, Debug)]
pub(super) struct Scale {
    pub(super) psi: Vec<Interval>,
    pub(super) s: Vec<Interval>,
}

impl Scale {
    /// Along steps of lengths `h` (enclosures) with constant rates `(c, sigma)` on each:
    /// `psi_(k+1) = psi_k + c h`, `S_(k+1) = S_k + sigma^2 e^(-2 psi_k) int_0^h e^(-2 c s) ds`.
    pub(super) fn new(steps: impl Iterator<Item = (Interval, f64, f64)>) -> Scale {
        let mut scale = Scale {
            psi: vec![Interval::ZERO],
            s: vec![Interval::ZERO],
        };
        for (h, c, sigma) in steps {
            scale.push(h, c, sigma);
        }
        scale
    }

    /// The enclosures at the end of one more step (see [`Scale::new`]).
    pub(super) fn next(&self, h: Interval, c: f64, sigma: f64) -> (Interval, Interval) {
        let (p, v) = (self.psi[self.psi.len() - 1], self.s[self.s.len() - 1]);
        let sigma2 = Interval::point(sigma).sqr();
        let gain = sigma2 * (Interval::point(-2.0) * p).exp() * expm1_over(-2.0 * c, h);
        // S is non-decreasing: its lower end never falls below the previous one.
        let next = v + gain;
        (
            p + Interval::point(c) * h,
            Interval::new(next.lo().max(v.lo()), next.hi()),
        )
    }

    /// Appends one more step.
    pub(super) fn push(&mut self, h: Interval, c: f64, sigma: f64) {
        let (psi, s) = self.next(h, c, sigma);
        self.psi.push(psi);
        self.s.push(s);
    }
}

/// The smallest scale the epochs are laid out for. Noise that is zero has an outward-rounded
/// bound of a subnormal (`sigma = 5e-324`), whose `S` would make `lambda = z / sqrt(S kappa)`
/// overflow and the radius infinite; epochs laid out for a larger `S` hold all the same (any
/// thresholds covering the horizon's `S` do), and give a radius of about `sqrt(S_FLOOR)`.
const S_FLOOR: f64 = 1e-200;

/// Slots of [`recent_root`]'s cache.
const ROOT_SLOTS: usize = 64;

thread_local! {
    /// Roots recently found on this thread, `(n, target's bits, root)` in a slot chosen by the
    /// key (`n = 0`: empty).
    static ROOTS: RefCell<[(usize, u64, f64); ROOT_SLOTS]> =
        const { RefCell::new([(0, 0, 0.0); ROOT_SLOTS]) };
}

/// The root for `(n, target)` found by `search`, or the one it found before on this thread.
/// A report time's root is asked for by its radius, by the radius over the step before it and
/// by the local rates' region around it; the search is a pure function of `(n, target)`, so
/// the cache changes no result.
fn recent_root(n: usize, target: f64, search: impl FnOnce() -> f64) -> f64 {
    let bits = target.to_bits();
    let slot = ((bits ^ (bits >> 29) ^ n as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 58)
        as usize
        % ROOT_SLOTS;
    if let Some(z) =
        ROOTS.with_borrow(|r| (r[slot].0 == n && r[slot].1 == bits).then_some(r[slot].2))
    {
        return z;
    }
    let z = search();
    ROOTS.with_borrow_mut(|r| r[slot] = (n, bits, z));
    z
}

/// One epoch of the tube.
#[derive(Clone, Copy, Debug)]
struct Epoch {
    /// Its threshold `S^(k)` (the epoch holds the times with `S_t <= S^(k)` after the previous
    /// epoch).
    s_end: f64,
    /// Its `lambda`.
    lambda: f64,
    /// An upper bound of `ln(1 / delta_k)`.
    log_inv_delta: f64,
}

/// The epochs of a run, fixed before the fact from its deterministic `S_t`.
#[derive(Clone, Debug)]
pub(super) struct Tube {
    n: usize,
    epochs: Vec<Epoch>,
}

impl Tube {
    /// The tube for dimension `n`, probability `delta`, from the scale of the first report time
    /// after 0 (`s_first`, the first epoch's threshold at most) to the horizon's (`s_last`).
    pub(super) fn new(n: usize, delta: f64, s_first: f64, s_last: f64) -> Tube {
        if s_last <= 0.0 {
            return Tube {
                n,
                epochs: Vec::new(),
            };
        }
        let (s_first, s_last) = (s_first.max(S_FLOOR), s_last.max(S_FLOOR));
        let ratio = (s_last / s_first.max(f64::MIN_POSITIVE)).max(1.0);
        // An infinite scale (a run that diverges) saturates the cast: add without overflow.
        let k = (ratio.log2().ceil() as usize)
            .saturating_add(1)
            .clamp(1, MAX_EPOCHS);
        // A little below delta / K, so that the K shares sum to at most delta.
        let delta_k = (delta / k as f64).next_down();
        let (kappa, z) = amgf_minimiser(n, delta_k);
        let log_inv_delta = log_inv_delta_upper(delta_k);
        let epochs = (0..k)
            .map(|e| {
                let s_end = s_last * 2f64.powi(e as i32 + 1 - k as i32);
                Epoch {
                    s_end,
                    // Optimal at the threshold: there the radius is the pointwise one at
                    // delta_k (any lambda > 0 is valid).
                    lambda: z / (s_end * kappa).sqrt(),
                    log_inv_delta,
                }
            })
            .collect();
        Tube { n, epochs }
    }

    /// The tube for a run whose scale is `scale`, its first report time at step index
    /// `first` (index into `scale`).
    pub(super) fn for_scale(n: usize, delta: f64, scale: &Scale, first: usize) -> Tube {
        let s_last = scale.s.last().map_or(0.0, |s| s.hi());
        let s_first = scale.s.get(first).map_or(s_last, |s| s.lo());
        Tube::new(n, delta, s_first, s_last)
    }

    /// The horizon's `S` the epochs were laid out for.
    pub(super) fn s_last(&self) -> f64 {
        self.epochs.last().map_or(0.0, |e| e.s_end)
    }

    /// The number of epochs (the union bound's `K`).
    pub(super) fn epochs(&self) -> usize {
        self.epochs.len()
    }

    /// An upper bound of the tube's radius over the times whose `psi` lies in `psi` and whose
    /// `S` lies in `s` (a time, or a step: the enclosures of both ends' hulls).
    pub(super) fn radius(&self, psi: Interval, s: Interval) -> f64 {
        if s.hi() <= 0.0 || self.epochs.is_empty() {
            return 0.0;
        }
        let grow = Interval::point(psi.hi()).exp();
        let mut radius = 0.0f64;
        let mut s_prev = f64::NEG_INFINITY;
        for e in &self.epochs {
            // The times of this epoch within the range: S in (s_prev, s_end] and in s.
            if s.hi() > s_prev && s.lo() <= e.s_end {
                let s_top = s.hi().min(e.s_end);
                let z = self.root(e, s_top);
                let r = grow * Interval::point(z) / Interval::point(e.lambda);
                radius = radius.max(r.hi());
            }
            s_prev = e.s_end;
        }
        // Beyond the last threshold (rounding of S at the horizon): the last epoch's formula.
        if let Some(last) = self.epochs.last().filter(|e| s.hi() > e.s_end) {
            let z = self.root(last, s.hi());
            radius = radius.max((grow * Interval::point(z) / Interval::point(last.lambda)).hi());
        }
        radius
    }

    /// An upper bound of the root `z` of `ln Phi_n(z) = lambda^2 S / 2 + ln(1/delta_k)`
    /// (increasing in `S`): a bracket `[lo, hi]` whose upper end the certified lower bound of
    /// `ln Phi_n` already lifts above the target, narrowed by regula falsi (Illinois) to a
    /// relative width of `1e-12`.
    fn root(&self, e: &Epoch, s: f64) -> f64 {
        let lambda = Interval::point(e.lambda);
        let target = (lambda.sqr() * Interval::point(s) * Interval::point(0.5)
            + Interval::point(e.log_inv_delta))
        .hi();
        // A vacuous radius (an exploding S): no finite bound is worth computing.
        if target.is_nan() || target > 1e50 {
            return f64::INFINITY;
        }
        recent_root(self.n, target, || self.search(target))
    }

    /// The root's upper bound for `target` (see [`Tube::root`]).
    fn search(&self, target: f64) -> f64 {
        // Increasing in z; >= 0 at an upper bound of the root.
        let gap = |z: f64| log_phi_lower(self.n, z) - target;
        // ln Phi_n(0) = 0 < target, and ln Phi_n(z) <= z: the root is at least the target.
        let (mut lo, mut g_lo) = (0.0, -target);
        let mut hi = target.max(1.0);
        let mut g_hi = gap(hi);
        while g_hi < 0.0 {
            (lo, g_lo) = (hi, g_hi);
            hi *= 2.0;
            g_hi = gap(hi);
        }
        let mut last = 0i8;
        for _ in 0..200 {
            if hi - lo <= 1e-12 * hi {
                break;
            }
            let mut z = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
            if !(z > lo && z < hi) {
                z = 0.5 * (lo + hi);
            }
            let g = gap(z);
            if g >= 0.0 {
                (hi, g_hi) = (z, g);
                // The same end twice: halve the other's weight (Illinois).
                if last == 1 {
                    g_lo *= 0.5;
                }
                last = 1;
            } else {
                (lo, g_lo) = (z, g);
                if last == -1 {
                    g_hi *= 0.5;
                }
                last = -1;
            }
        }
        hi
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kappa::kappa_amgf;

    /// Found by the fuzz campaign (tests/fuzz/findings/run-panic.sde): `horizon = 100000` on an
    /// unstable model, whose scale overflows to infinity.
    #[test]
    fn an_infinite_scale_gets_the_most_epochs_without_overflow() {
        let tube = Tube::new(2, 1e-3, 1e-2, f64::INFINITY);
        assert_eq!(tube.epochs.len(), MAX_EPOCHS);
    }

    /// Zero noise bounded outward (a subnormal sigma, so a subnormal `S`): a finite radius of
    /// about `sqrt(S_FLOOR)` (it was infinite, and the local rates of noise-free specs could
    /// not close), still above the pointwise radius of the real `S`.
    #[test]
    fn a_subnormal_scale_gets_a_tiny_finite_radius() {
        let s = 5e-324 * 0.01;
        let tube = Tube::new(1, 1e-3, s, 1e-323);
        for s in [0.0f64, 5e-324, 1e-323] {
            let r = tube.radius(Interval::ZERO, Interval::new(0.0, s.max(5e-324)));
            assert!(r > 0.0 && r < 1e-98, "S = {s:e}: {r:e}");
        }
    }

    /// At each epoch's threshold the tube's radius is the pointwise one at delta / K; between
    /// thresholds it is larger than the pointwise one at delta, by a bounded factor.
    #[test]
    fn the_tube_meets_the_pointwise_radius_at_the_thresholds() {
        let (n, delta) = (2, 1e-3);
        let tube = Tube::new(n, delta, 1e-4, 1.0);
        let k = tube.epochs();
        assert_eq!(k, 15);
        let kappa_k = kappa_amgf(n, (delta / k as f64).next_down());
        for e in &tube.epochs {
            let r = tube.radius(Interval::ZERO, Interval::point(e.s_end));
            let pointwise = (e.s_end * kappa_k).sqrt();
            assert!(r >= pointwise * (1.0 - 1e-9), "{r} vs {pointwise}");
            assert!(r <= pointwise * (1.0 + 1e-6), "{r} vs {pointwise}");
        }
        // The price of uniformity at the horizon: sqrt(kappa(delta / K) / kappa(delta)).
        let at_end = tube.radius(Interval::ZERO, Interval::point(1.0));
        let price = at_end / kappa_amgf(n, delta).sqrt();
        assert!(price > 1.0 && price < 1.2, "{price}");
        // Inside an epoch, at most a bounded factor above the pointwise radius at delta.
        for i in 0..200 {
            let s = 1e-4 * 10f64.powf(4.0 * f64::from(i) / 200.0);
            let r = tube.radius(Interval::ZERO, Interval::point(s));
            let pointwise = (s * kappa_amgf(n, delta)).sqrt();
            assert!(
                r >= pointwise && r < 1.6 * pointwise,
                "S = {s}: {r} vs {pointwise}"
            );
        }
        // The radius scales with e^psi.
        let r0 = tube.radius(Interval::ZERO, Interval::point(0.5));
        let r1 = tube.radius(Interval::point(-1.0), Interval::point(0.5));
        assert!((r1 / r0 - (-1.0f64).exp()).abs() < 1e-12);
    }

    /// `Scale` against the closed forms for constant rates: `psi = c t`,
    /// `S = sigma^2 (1 - e^(-2 c t)) / (2 c)`, and `Psi = e^(2 psi) S`.
    #[test]
    fn scale_matches_closed_forms() {
        let (c, sigma, h) = (-0.5, 0.3, 0.01);
        let scale = Scale::new((0..400).map(|_| (Interval::point(h), c, sigma)));
        for k in [1usize, 100, 400] {
            let t = k as f64 * h;
            let s = sigma * sigma * (-(-2.0 * c * t).exp_m1()) / (2.0 * c);
            assert!(scale.s[k].contains(s), "{:?} vs {s}", scale.s[k]);
            assert!(scale.s[k].width() <= 1e-12 * s);
            assert!(scale.psi[k].contains(c * t));
        }
    }

    /// No noise: no radius.
    #[test]
    fn no_noise_no_tube() {
        let tube = Tube::new(3, 0.01, 0.0, 0.0);
        assert_eq!(tube.radius(Interval::point(2.0), Interval::ZERO), 0.0);
    }
}
