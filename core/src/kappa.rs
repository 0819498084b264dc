//! The stochastic-radius factor `kappa(n, delta)` (method.md, section 5).
//!
//! The stochastic part of a delta-probabilistic reachable set is a ball of radius
//! `r_t = sqrt(Psi_t * kappa(n, delta))`: under Assumption 1,
//! `P(|X_t - x_t| >= r_t) <= delta`. This module computes `kappa = r^2 / Psi` for each
//! [`RadiusRule`].
//!
//! Soundness is one-sided: a `kappa` that is too large only loosens the reachable set, one that
//! is too small is a bug. Every function here therefore returns a value that is, after all
//! floating-point rounding, at least the exact value of its formula (the rounding is covered by
//! explicit error bounds and a small relative margin, [`KAPPA_MARGIN`]). Minimisations (over
//! `lambda` for `amgf`, over `eps` for `PaperOptimal`) need not be exact: every candidate gives a
//! valid bound, so an inexact minimiser only loosens the result.
//!
//! Only `std` is used.

use crate::model::RadiusRule;

/// Relative margin added to every returned `kappa` (`kappa * (1 + KAPPA_MARGIN)`).
///
/// It covers the few roundings of the final formulas (each at most `2^-53` relative) with a
/// wide safety factor; the explicitly bounded errors (the series for `ln Phi_n`, `ln delta`) are
/// accounted for separately. The result is therefore never below the exact value of the rule,
/// and at most about `1e-13` (relative) above it plus the minimiser's slack.
pub const KAPPA_MARGIN: f64 = 1e-13;

/// Unit roundoff of `f64` (`2^-53`).
const U: f64 = f64::EPSILON / 2.0;

/// Rescaling exponent of the series and the exact powers of two `2^600`, `2^-600`.
const RESCALE_EXP: i32 = 600;
const RESCALE: f64 = f64::from_bits(((1023 + RESCALE_EXP) as u64) << 52);
const INV_RESCALE: f64 = f64::from_bits(((1023 - RESCALE_EXP) as u64) << 52);

/// Relative truncation threshold of the series: once past the peak term, stop when the current
/// term is below `2^-64` of the partial sum and the geometric tail bound is below that too.
const TAIL_REL: f64 = 5.421_010_862_427_522e-20;

/// `kappa(n, delta) = r^2 / Psi` for the rule: the stochastic radius is
/// `r_t = sqrt(Psi_t * kappa)`.
///
/// Dispatches to [`kappa_amgf`], [`kappa_paper`] or [`kappa_paper_optimal`] (its `kappa`).
///
/// # Panics
///
/// If `n == 0`, `delta` is not in `(0, 1)`, or (for `Paper(eps)`) `eps` is not in `(0, 1)`.
pub fn kappa(n: usize, delta: f64, rule: RadiusRule) -> f64 {
    match rule {
        RadiusRule::Amgf => kappa_amgf(n, delta),
        RadiusRule::Paper(eps) => kappa_paper(n, delta, eps),
        RadiusRule::PaperOptimal => kappa_paper_optimal(n, delta).0,
    }
}

fn check_args(n: usize, delta: f64) {
    assert!(n >= 1, "kappa: the dimension n must be at least 1");
    assert!(
        delta > 0.0 && delta < 1.0,
        "kappa: delta must lie in (0, 1), got {delta}"
    );
}

/// `ln(1/delta)`, rounded up (an upper bound on the exact value; a larger `L` only enlarges
/// `kappa`). `ln` is assumed accurate to 2 ulp (glibc, musl and Rust's `libm` are within 1).
pub(crate) fn log_inv_delta_upper(delta: f64) -> f64 {
    let l = -delta.ln();
    l + l.abs() * (8.0 * U) + f64::MIN_POSITIVE
}

/// Theorem 1 of the paper: `kappa = eps1 n + eps2 ln(1/delta)` with
/// `eps1 = 2 ln(1 + 2/eps) / (1 - eps)^2` and `eps2 = 2 / (1 - eps)^2`, for `eps` in `(0, 1)`.
///
/// The general formula is used for every `n`, including `n = 1` (where the paper allows the
/// Hoeffding constants `eps1 = 2 ln 2`, `eps2 = 2`): the reference values
/// (`kappa_paper_eps_1_16` in `core/tests/data/kappa.jsonl`) use the general formula at `n = 1`,
/// and for `n = 1` the `amgf` rule is anyway never above the Hoeffding value
/// `2 ln 2 + 2 ln(1/delta)` (since `cosh z >= e^z / 2`).
///
/// The result is rounded up by [`KAPPA_MARGIN`] (relative), which covers the roundings of the
/// formula.
///
/// # Panics
///
/// If `n == 0`, `delta` is not in `(0, 1)` or `eps` is not in `(0, 1)`.
pub fn kappa_paper(n: usize, delta: f64, eps: f64) -> f64 {
    check_args(n, delta);
    assert!(
        eps > 0.0 && eps < 1.0,
        "kappa_paper: eps must lie in (0, 1), got {eps}"
    );
    paper_formula(n as f64, log_inv_delta_upper(delta), eps) * (1.0 + KAPPA_MARGIN)
}

/// `2 (n ln(1 + 2/eps) + l) / (1 - eps)^2`, unmargined.
fn paper_formula(n: f64, l: f64, eps: f64) -> f64 {
    let one_minus = 1.0 - eps;
    2.0 * (n * (2.0 / eps).ln_1p() + l) / (one_minus * one_minus)
}

/// Theorem 1 with `eps` minimising [`kappa_paper`] over `(0, 1)`; returns `(kappa, eps)`.
///
/// `g(eps) = 2 (n ln(1 + 2/eps) + ln(1/delta)) / (1 - eps)^2` tends to infinity at both ends of
/// `(0, 1)`. A coarse grid locates the minimum and a golden-section search refines it. Every
/// `eps` gives a valid radius, so the minimisation only needs to be good; the returned `kappa`
/// is exactly `kappa_paper(n, delta, eps)` for the returned `eps` (hence sound), and is never
/// above `kappa_paper(n, delta, eps)` at the grid points (in particular `eps = 1/16`).
///
/// # Panics
///
/// If `n == 0` or `delta` is not in `(0, 1)`.
pub fn kappa_paper_optimal(n: usize, delta: f64) -> (f64, f64) {
    check_args(n, delta);
    let nf = n as f64;
    let l = log_inv_delta_upper(delta);
    let g = |eps: f64| paper_formula(nf, l, eps);
    // Coarse grid on (0, 1); it contains 1/16 = 4/64.
    const GRID: usize = 64;
    let (mut best_v, mut best_i) = (f64::INFINITY, 1);
    for i in 1..GRID {
        let v = g(i as f64 / GRID as f64);
        if v < best_v {
            best_v = v;
            best_i = i;
        }
    }
    let mut best = (best_v, best_i as f64 / GRID as f64);
    let lo = if best_i == 1 {
        1e-9
    } else {
        (best_i - 1) as f64 / GRID as f64
    };
    let hi = (best_i + 1) as f64 / GRID as f64;
    let (e, v) = golden_min(g, lo, hi, 1e-12, 200);
    if v < best.0 {
        best = (v, e);
    }
    let eps = best.1;
    (kappa_paper(n, delta, eps), eps)
}

/// Golden-section search for the minimum of a unimodal `f` on `[a, b]`; returns the best
/// `(x, f(x))` seen.
fn golden_min<F: Fn(f64) -> f64>(
    f: F,
    mut a: f64,
    mut b: f64,
    rel_tol: f64,
    max_iter: usize,
) -> (f64, f64) {
    const INV_PHI: f64 = 0.618_033_988_749_894_9;
    let mut c = b - INV_PHI * (b - a);
    let mut d = a + INV_PHI * (b - a);
    let mut fc = f(c);
    let mut fd = f(d);
    for _ in 0..max_iter {
        if (b - a) <= rel_tol * b.abs().max(a.abs()) {
            break;
        }
        if fc <= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - INV_PHI * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + INV_PHI * (b - a);
            fd = f(d);
        }
    }
    if fc <= fd {
        (c, fc)
    } else {
        (d, fd)
    }
}

/// A certified lower bound on `ln Phi_n(z)`, where
/// `Phi_n(z) = E_{l ~ S^(n-1)} e^(z l_1) = sum_k t_k`, `t_k = (z^2/4)^k Gamma(n/2) / (k! Gamma(n/2 + k))`
/// (`cosh z` for `n = 1`, `sinh(z)/z` for `n = 3`).
///
/// The terms are generated by the ratio recurrence `t_0 = 1`,
/// `t_{k+1} = t_k * (z^2/4) / ((k+1)(n/2+k))` (no gamma function), summed in linear scale with
/// exact power-of-two rescaling, and the sum is truncated after the peak term once the remaining
/// terms are negligible. Truncation drops only positive terms, so it can only lower the value.
/// Rounding is bounded explicitly: each ratio carries at most 3 roundings and each product one
/// more, so term `k` has relative error at most `4k u` (`u = 2^-53`); the sequential sum of `K`
/// positive terms adds at most `K u`; `ln` adds at most 2 ulp (assumed of the platform `ln`;
/// glibc, musl and Rust's `libm` are within 1); the bound `(5K + 2) u` (with a safety factor 2)
/// plus `8 u |ln S| + 4 u |ln Phi|` is subtracted from the computed logarithm. Powers of two
/// used for rescaling are exact.
///
/// Accuracy: below the true value by about `1e-15 * max(1, ln Phi)` plus `1e-15 K`; the number
/// of terms `K` is about the peak index (where `(k+1)(n/2+k) ~ z^2/4`) plus a tail of a few
/// dozen to a few hundred terms.
///
/// The cost is about `K` multiply-adds and one `ln`.
///
/// # Panics
///
/// If `n == 0` or `z` is not in `[0, 1e60]` (beyond which intermediate products could overflow).
pub fn log_phi_lower(n: usize, z: f64) -> f64 {
    assert!(n >= 1, "log_phi_lower: n must be at least 1");
    assert!(
        (0.0..=1e60).contains(&z),
        "log_phi_lower: z must lie in [0, 1e60], got {z}"
    );
    if z == 0.0 {
        return 0.0;
    }
    if z > SERIES_MAX_Z {
        return log_phi_lower_large(n, z);
    }
    let a = z * z * 0.25;
    let half_n = n as f64 * 0.5;
    let mut t = 1.0f64;
    let mut s = 1.0f64;
    let mut rescales: u32 = 0;
    let mut k: u64 = 0;
    loop {
        let kf = k as f64;
        let q = a / ((kf + 1.0) * (half_n + kf));
        t *= q;
        s += t;
        k += 1;
        if s > RESCALE {
            s *= INV_RESCALE;
            t *= INV_RESCALE;
            rescales += 1;
        }
        // Past the peak (q < 1, and the ratios decrease with k), the tail after t is at most
        // t q / (1 - q). Stop when that is negligible relative to the sum (dropping it is sound).
        if q < 0.5 && t < s * TAIL_REL {
            break;
        }
        if t == 0.0 {
            break;
        }
    }
    let terms = (k + 1) as f64;
    let scale_part = f64::from(rescales) * f64::from(RESCALE_EXP) * std::f64::consts::LN_2;
    let log_s = s.ln();
    let value = log_s + scale_part;
    // Relative error of s: at most gamma_{5K}; |ln(1 + theta)| <= 1.01 |theta| for tiny theta.
    // ln and the scale constant: 2 ulp each; the final sum and subtraction: 2 more roundings.
    let err = 1.01 * (5.0 * terms + 2.0) * U * 2.0
        + 8.0 * U * log_s.abs()
        + 4.0 * U * scale_part
        + 4.0 * U * value.abs();
    value - err
}

/// Above this `z` the series of [`log_phi_lower`] would need more than about `z` terms: a
/// single term bounds it instead ([`log_phi_lower_large`]).
const SERIES_MAX_Z: f64 = 1e4;

/// A lower bound on `ln Phi_n(z)` by one term of its series, `t_k` with `k` near the peak
/// `z / 2`, its gamma functions bounded by Binet's form of Stirling's formula
/// (`ln Gamma(x) = (x - 1/2) ln x - x + ln(2 pi) / 2 + mu(x)`, `0 < mu(x) < 1 / (12 x)` for every
/// `x > 0`). Below the true value by about `ln z` (against `ln Phi_n(z) ~ z`) plus a rounding
/// margin of `1e-12` of the terms' magnitudes, which only matters for radii that are vacuous
/// anyway.
fn log_phi_lower_large(n: usize, z: f64) -> f64 {
    let k = (0.5 * z).floor().max(1.0);
    let half_n = n as f64 * 0.5;
    let half_ln_2pi = 0.5 * (2.0 * std::f64::consts::PI).ln();
    let stirling = |x: f64| (x - 0.5) * x.ln() - x + half_ln_2pi;
    // ln t_k = k ln(z^2 / 4) + ln Gamma(n/2) - ln Gamma(k + 1) - ln Gamma(n/2 + k).
    let terms = [
        2.0 * k * (0.5 * z).ln(),
        stirling(half_n),
        -(stirling(k + 1.0) + 1.0 / (12.0 * (k + 1.0))),
        -(stirling(half_n + k) + 1.0 / (12.0 * (half_n + k))),
    ];
    let value: f64 = terms.iter().sum();
    let scale: f64 = terms.iter().map(|t| t.abs()).sum();
    value - 1e-12 * scale - f64::MIN_POSITIVE
}

/// The averaged-MGF rule (method.md section 5, the default):
/// `kappa(n, delta) = inf { s > 0 : inf_lambda [lambda^2/2 - ln Phi_n(lambda sqrt(s))] <= ln delta }`.
///
/// Computation. Substitute `z = lambda sqrt(s)`: the condition holds for `s` iff some `z > 0`
/// has `z^2 / (2 s) <= ln Phi_n(z) - L` with `L = ln(1/delta)`, i.e.
/// `s >= h(z) = z^2 / (2 (ln Phi_n(z) - L))` (for `ln Phi_n(z) > L`). Hence
/// `kappa = inf_z h(z)`, a one-dimensional minimisation with no outer bisection; `h` is
/// unimodal (it tends to infinity at the root of `ln Phi_n = L` and at infinity, and
/// `2 (ln Phi_n - L) - z (ln Phi_n)'` increases because `ln Phi_n` is convex with decreasing
/// second derivative). A geometric scan brackets the minimum and a golden-section search
/// refines it.
///
/// Soundness. For the returned `s` and the `z` found, `lambda = z / sqrt(s)` satisfies the
/// condition: `h` is evaluated with a certified lower bound of `ln Phi_n` ([`log_phi_lower`]),
/// an upper bound of `L`, and the result is rounded up by [`KAPPA_MARGIN`] (relative) which
/// covers the three roundings of `h`. Any `z` yields a valid `s`, so an inexact minimisation
/// only loosens the result (the search stops at relative width `1e-10` in `z`, where the
/// loss in `h` is about `1e-20` relative). The result is never below the Gaussian floor (the
/// chi-square quantile), which any valid rule must respect.
///
/// # Panics
///
/// If `n == 0` or `delta` is not in `(0, 1)`.
pub fn kappa_amgf(n: usize, delta: f64) -> f64 {
    amgf_minimiser(n, delta).0
}

/// [`kappa_amgf`] and the `z = lambda sqrt(s)` attaining it: `(kappa, z)`. The time-uniform
/// tube (`engine/uniform.rs`) tunes each epoch's `lambda` with it.
///
/// # Panics
///
/// If `n == 0` or `delta` is not in `(0, 1)`.
pub fn amgf_minimiser(n: usize, delta: f64) -> (f64, f64) {
    check_args(n, delta);
    let l = log_inv_delta_upper(delta);
    let h = |z: f64| -> f64 {
        let d = log_phi_lower(n, z) - l;
        if d > 0.0 {
            z * z / (2.0 * d)
        } else {
            f64::INFINITY
        }
    };
    // ln Phi_n(z) < z for z > 0 (as |l_1| <= 1), so h(L) is infinite and the minimiser lies
    // beyond L: scan z = L, 1.25 L, ... until h increases again; then the minimum lies in
    // [z_prev, z_next] (h(z_prev) >= h(z) <= h(z_next)).
    const STEP: f64 = 1.25;
    let mut z_prev = l;
    let mut z = l * STEP;
    let mut h_cur = h(z);
    loop {
        let z_next = z * STEP;
        let h_next = h(z_next);
        if h_cur.is_finite() && h_next >= h_cur {
            let (zm, v) = golden_min(h, z_prev, z_next, 1e-10, 300);
            let (z, v) = if v <= h_cur { (zm, v) } else { (z, h_cur) };
            return (v * (1.0 + KAPPA_MARGIN), z);
        }
        assert!(
            z_next < 1e59,
            "kappa_amgf: no minimum found (n = {n}, delta = {delta})"
        );
        z_prev = z;
        z = z_next;
        h_cur = h_next;
    }
}
