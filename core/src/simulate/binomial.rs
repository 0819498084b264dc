//! Clopper-Pearson (exact binomial) confidence bounds for a violation probability.
//!
//! With `k` violations in `n` independent paths, the one-sided bounds at level `1 - alpha` are
//! the `p` solving `P(Bin(n, p) >= k) = alpha` (lower) and `P(Bin(n, p) <= k) = alpha` (upper).
//! Through `P(Bin(n, p) >= k) = I_p(k, n - k + 1)` (the regularised incomplete beta function)
//! both are beta quantiles, found by bisection on `I_p`.

/// `ln Gamma(x)` for `x > 0` (Lanczos, g = 7, 9 terms; relative error about 1e-15).
fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Gamma(x) Gamma(1 - x) = pi / sin(pi x).
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, &c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Continued fraction of the incomplete beta function (modified Lentz), for
/// `x < (a + 1) / (a + b + 2)` where it converges fast.
fn beta_cf(a: f64, b: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < TINY {
        d = TINY;
    }
    d = 1.0 / d;
    let mut h = d;
    // Convergence takes O(sqrt(max(a, b))) terms: a few thousand for 10^7 paths.
    for m in 1..200_000 {
        let m = f64::from(m);
        let m2 = 2.0 * m;
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        if d.abs() < TINY {
            d = TINY;
        }
        c = 1.0 + aa / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        h *= d * c;
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        if d.abs() < TINY {
            d = TINY;
        }
        c = 1.0 + aa / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

/// The regularised incomplete beta function `I_x(a, b)`, `a, b > 0`.
fn inc_beta(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (-x).ln_1p();
    if x < (a + 1.0) / (a + b + 2.0) {
        ln_front.exp() * beta_cf(a, b, x) / a
    } else {
        1.0 - ln_front.exp() * beta_cf(b, a, 1.0 - x) / b
    }
}

/// The `p` in `[0, 1]` with `I_p(a, b) = target` (increasing in `p`), by bisection.
fn inc_beta_inverse(a: f64, b: f64, target: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    // 1100 halvings reach the smallest subnormals; stop when the bracket stops shrinking.
    for _ in 0..1100 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if inc_beta(a, b, mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// One-sided lower Clopper-Pearson bound at level `1 - alpha` for `k` events in `n` trials.
pub fn lower_bound(k: u64, n: u64, alpha: f64) -> f64 {
    assert!(k <= n && n > 0, "lower_bound: k = {k}, n = {n}");
    if k == 0 {
        return 0.0;
    }
    if k == n {
        return alpha.powf(1.0 / n as f64);
    }
    // P(Bin(n, p) >= k) = I_p(k, n - k + 1) = alpha.
    inc_beta_inverse(k as f64, (n - k + 1) as f64, alpha)
}

/// One-sided upper Clopper-Pearson bound at level `1 - alpha` for `k` events in `n` trials.
pub fn upper_bound(k: u64, n: u64, alpha: f64) -> f64 {
    assert!(k <= n && n > 0, "upper_bound: k = {k}, n = {n}");
    if k == n {
        return 1.0;
    }
    if k == 0 {
        // (1 - p)^n = alpha.
        return -(alpha.ln() / n as f64).exp_m1();
    }
    // P(Bin(n, p) <= k) = 1 - I_p(k + 1, n - k) = alpha.
    inc_beta_inverse((k + 1) as f64, (n - k) as f64, 1.0 - alpha)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `P(Bin(n, p) >= k)` by direct summation of the probabilities (log space).
    fn tail_at_least(k: u64, n: u64, p: f64) -> f64 {
        let ln_choose = |i: u64| {
            ln_gamma(n as f64 + 1.0) - ln_gamma(i as f64 + 1.0) - ln_gamma((n - i) as f64 + 1.0)
        };
        (k..=n)
            .map(|i| (ln_choose(i) + i as f64 * p.ln() + (n - i) as f64 * (-p).ln_1p()).exp())
            .sum()
    }

    #[test]
    fn ln_gamma_matches_factorials() {
        let mut f = 1.0f64;
        for k in 1..30u32 {
            f *= f64::from(k);
            let lg = ln_gamma(f64::from(k) + 1.0);
            assert!((lg - f.ln()).abs() < 1e-12 * f.ln().max(1.0), "{k}");
        }
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-14);
    }

    #[test]
    fn bounds_solve_their_defining_equations() {
        let alpha = 1e-3;
        for &(k, n) in &[
            (1u64, 100u64),
            (5, 1000),
            (37, 1000),
            (500, 1000),
            (999, 1000),
        ] {
            let lo = lower_bound(k, n, alpha);
            let hi = upper_bound(k, n, alpha);
            let phat = k as f64 / n as f64;
            assert!(lo < phat && phat < hi, "k = {k}: {lo} {hi}");
            // P(Bin(n, lo) >= k) = alpha and P(Bin(n, hi) <= k) = alpha.
            let at_lo = tail_at_least(k, n, lo);
            let at_hi = 1.0 - tail_at_least(k + 1, n, hi);
            assert!((at_lo - alpha).abs() < 1e-9, "k = {k}: {at_lo}");
            assert!((at_hi - alpha).abs() < 1e-9, "k = {k}: {at_hi}");
        }
    }

    #[test]
    fn edge_cases_have_closed_forms() {
        // k = 0: upper = 1 - alpha^(1/n) ("rule of three" ~ 6.9 / n at alpha = 1e-3).
        let u = upper_bound(0, 100_000, 1e-3);
        assert!((u - (1.0 - 1e-3f64.powf(1e-5))).abs() < 1e-15);
        assert_eq!(lower_bound(0, 10, 0.05), 0.0);
        assert_eq!(upper_bound(10, 10, 0.05), 1.0);
        assert!((lower_bound(10, 10, 0.05) - 0.05f64.powf(0.1)).abs() < 1e-15);
    }

    #[test]
    fn large_counts_agree_with_the_normal_approximation() {
        // 10^7 trials, 10^5 events: the bounds are phat -+ z sqrt(phat (1 - phat) / n) to
        // within a few percent of the half-width (z = 3.09 for alpha = 1e-3).
        let (k, n) = (100_000u64, 10_000_000u64);
        let phat = 1e-2;
        let half = 3.090_232 * (phat * (1.0 - phat) / n as f64).sqrt();
        let lo = lower_bound(k, n, 1e-3);
        let hi = upper_bound(k, n, 1e-3);
        assert!((phat - lo - half).abs() < 0.05 * half, "{lo}");
        assert!((hi - phat - half).abs() < 0.05 * half, "{hi}");
    }
}
