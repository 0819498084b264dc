//! Special functions shared by the compiler's IR interpreter and generated code, so both
//! evaluate `sinc`, its derivative, `sign` and `pow` with one implementation.
//!
//! The interval versions of `sinc` and `sign` are [`Interval::sinc`] and [`Interval::sign`];
//! the derivative of `sinc` has no `Interval` method and is [`dsinc_interval`].

use crate::interval::Interval;

/// `sin(x)/x`, 1 at 0.
pub fn sinc(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        x.sin() / x
    }
}

/// `sinc'(x) = (x cos x - sin x)/x^2`, 0 at 0. A Taylor series near 0, where the quotient
/// cancels catastrophically.
pub fn dsinc(x: f64) -> f64 {
    if x.abs() < 0.1 {
        // -x/3 + x^3/30 - x^5/840 + x^7/45360 - x^9/3991680; next term < 1e-19 relative.
        let x2 = x * x;
        x * (-1.0 / 3.0
            + x2 * (1.0 / 30.0 + x2 * (-1.0 / 840.0 + x2 * (1.0 / 45360.0 - x2 / 3991680.0))))
    } else {
        (x * x.cos() - x.sin()) / (x * x)
    }
}

/// `x^y` by the C library's `pow`, out of line: where the caller's base or exponent is a
/// literal, LLVM rewrites `f64::powf` (`pow(2, y)` as `exp2(y)`, which differs from `pow` in
/// the last bit), and does so in some functions and not others. Generated code and the
/// interpreter both call this function, so they agree bit for bit.
#[inline(never)]
pub fn pow(x: f64, y: f64) -> f64 {
    x.powf(y)
}

/// -1, 0 or 1 (NaN stays NaN); unlike `f64::signum`, `sign(0) = 0`.
pub fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        x * 0.0 // 0 for +-0, NaN for NaN
    }
}

/// `max |sinc'|` over R is 0.436181817... (at x ~ 2.0816), rounded up.
pub const DSINC_MAX: f64 = 0.4362;
/// `sinc' <= 0` on `[0, 4.4934...]` (the first positive zero, where `tan x = x`), rounded down.
const DSINC_NEG_END: f64 = 4.49;

/// Encloses `sinc'` over `x`. Envelope: `|sinc'(x)| <= min(|x|/3, 0.4362, 1/|x| + 1/x^2)` (from
/// `|sin x - x cos x| <= |x|^3/3`, whose derivative is `x sin x`, and `<= 1 + |x|`), signed
/// on `[-4.49, 4.49]` (`sinc'` is odd, `<= 0` on `[0, 4.49]`); away from 0 intersected with the
/// interval evaluation of `(x cos x - sin x)/x^2`.
pub fn dsinc_interval(x: Interval) -> Interval {
    let (mig, mag) = (x.mig(), x.mag());
    let mut b = DSINC_MAX.min(f64::next_up(mag / 3.0));
    if mig > 0.0 {
        let r = f64::next_up(1.0 / mig);
        b = b.min(f64::next_up(r + f64::next_up(r * r)));
    }
    let (mut lo, mut hi) = (-b, b);
    if x.lo() >= 0.0 && x.hi() <= DSINC_NEG_END {
        hi = 0.0;
    }
    if x.hi() <= 0.0 && x.lo() >= -DSINC_NEG_END {
        lo = 0.0;
    }
    let envelope = Interval::new(lo, hi);
    if x.contains_zero() {
        return envelope;
    }
    let q = (x * x.cos() - x.sin()) / x.sqr();
    q.intersect(envelope).unwrap_or(envelope)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng::Rng;

    #[test]
    fn point_values() {
        assert_eq!(sinc(0.0), 1.0);
        assert_eq!(sinc(2.0), 2f64.sin() / 2.0);
        assert_eq!(sign(0.0), 0.0);
        assert_eq!(sign(-0.0), 0.0);
        assert_eq!(sign(-3.0), -1.0);
        assert_eq!(sign(1e-300), 1.0);
        assert!(sign(f64::NAN).is_nan());
        assert_eq!(dsinc(0.0), 0.0);
        // the series and the quotient agree where they meet
        let q = |x: f64| (x * x.cos() - x.sin()) / (x * x);
        assert!((dsinc(0.0999) - q(0.0999)).abs() < 1e-14);
        assert!((dsinc(-0.05) - q(-0.05)).abs() < 1e-12);
        assert_eq!(dsinc(0.5), q(0.5));
    }

    #[test]
    fn dsinc_enclosure() {
        let mut rng = Rng(99);
        for _ in 0..2000 {
            let c = rng.range(-12.0, 12.0);
            let r = rng.range(0.0, 3.0) * rng.uniform();
            let x = Interval::new(c - r, c + r);
            let enc = dsinc_interval(x);
            for k in 0..=20 {
                let v = c - r + 2.0 * r * (k as f64) / 20.0;
                assert!(
                    enc.contains(dsinc(v)),
                    "{v} in {x}: {} not in {enc}",
                    dsinc(v)
                );
            }
        }
        assert!(dsinc_interval(Interval::ENTIRE).contains(0.43));
        assert!(dsinc_interval(Interval::new(-1e-3, 1e-3)).hi() < 4e-4);
        assert_eq!(dsinc_interval(Interval::ZERO), Interval::ZERO);
    }
}
