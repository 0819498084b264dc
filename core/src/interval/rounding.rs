//! Directed-rounding primitives on `f64`: outward ulp steps, the basic
//! operations rounded down or up (error-free transformations where they are
//! exact, one ulp otherwise), integer powers, and the `k*pi/2` range search
//! of the periodic functions (see the [module documentation](super), rules 1
//! to 3).

use super::ELEM_ULPS;

/// `2^-900`: below this magnitude the FMA residual used to decide the rounding
/// direction may be inexact (underflow), so we widen unconditionally.
const RESIDUAL_SAFE_MIN: f64 = f64::from_bits((1023 - 900) << 52);

/// Relative safety margin of the `x / (pi/2)` reduction.
const REDUCTION_MARGIN: f64 = f64::from_bits((1023 - 48) << 52);

/// `n` steps of `next_up`.
#[inline]
pub(super) fn up_n(mut x: f64, n: u32) -> f64 {
    for _ in 0..n {
        x = f64::next_up(x);
    }
    x
}

/// `n` steps of `next_down`.
#[inline]
pub(super) fn down_n(mut x: f64, n: u32) -> f64 {
    for _ in 0..n {
        x = f64::next_down(x);
    }
    x
}

/// Lower bound of a libm result.
#[inline]
pub(super) fn elem_down(x: f64) -> f64 {
    down_n(x, ELEM_ULPS)
}

/// Upper bound of a libm result.
#[inline]
pub(super) fn elem_up(x: f64) -> f64 {
    up_n(x, ELEM_ULPS)
}

/// Lower bound for a finite operation whose nearest result overflowed.
#[inline]
pub(super) fn overflow_down(r: f64) -> f64 {
    if r > 0.0 {
        f64::MAX
    } else {
        r
    }
}

/// Lower bound of `a + b`.
#[inline]
pub(super) fn add_rd(a: f64, b: f64) -> f64 {
    let s = a + b;
    if s.is_nan() {
        return s;
    }
    if s.is_infinite() {
        if a.is_infinite() || b.is_infinite() {
            return s;
        }
        return overflow_down(s);
    }
    // TwoSum (Knuth): e = (a + b) - s exactly, barring spurious overflow,
    // which shows up as a non-finite e.
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    if e < 0.0 || !e.is_finite() {
        f64::next_down(s)
    } else {
        s
    }
}

/// Upper bound of `a + b`.
#[inline]
pub(super) fn add_ru(a: f64, b: f64) -> f64 {
    -add_rd(-a, -b)
}

/// Lower bound of `a - b`.
#[inline]
pub(super) fn sub_rd(a: f64, b: f64) -> f64 {
    add_rd(a, -b)
}

/// Upper bound of `a - b`.
#[inline]
pub(super) fn sub_ru(a: f64, b: f64) -> f64 {
    add_ru(a, -b)
}

/// Lower bound of `a * b`, with `0 * inf = 0`.
#[inline]
pub(super) fn mul_rd(a: f64, b: f64) -> f64 {
    if a == 0.0 || b == 0.0 {
        return 0.0;
    }
    let p = a * b;
    if p.is_nan() {
        return p;
    }
    if p.is_infinite() {
        if a.is_infinite() || b.is_infinite() {
            return p;
        }
        return overflow_down(p);
    }
    if p.abs() >= RESIDUAL_SAFE_MIN {
        // Exact residual a*b - p (representable since no underflow).
        let e = a.mul_add(b, -p);
        if e < 0.0 {
            f64::next_down(p)
        } else {
            p
        }
    } else {
        f64::next_down(p)
    }
}

/// Upper bound of `a * b`, with `0 * inf = 0`.
#[inline]
pub(super) fn mul_ru(a: f64, b: f64) -> f64 {
    -mul_rd(-a, b)
}

/// Lower bound of `a / b` (`b != 0`); `finite / inf` gives the limit 0.
pub(super) fn div_rd(a: f64, b: f64) -> f64 {
    let q = a / b;
    if q.is_nan() {
        return q;
    }
    if a == 0.0 {
        return 0.0;
    }
    if q.is_infinite() {
        if a.is_infinite() || b == 0.0 {
            return q;
        }
        return overflow_down(q);
    }
    if b.is_infinite() {
        return q;
    }
    if a.abs() >= RESIDUAL_SAFE_MIN && b.abs() >= f64::MIN_POSITIVE && q.abs() >= f64::MIN_POSITIVE
    {
        // Exact remainder r = a - q*b; the exact quotient is q + r/b.
        let r = (-q).mul_add(b, a);
        let dir = if b > 0.0 { r } else { -r };
        if dir < 0.0 {
            f64::next_down(q)
        } else {
            q
        }
    } else {
        f64::next_down(q)
    }
}

/// Upper bound of `a / b` (`b != 0`).
#[inline]
pub(super) fn div_ru(a: f64, b: f64) -> f64 {
    -div_rd(-a, b)
}

/// Lower bound of `sqrt(x)`, `x >= 0`.
pub(super) fn sqrt_rd(x: f64) -> f64 {
    if x == 0.0 || x == f64::INFINITY {
        return x.sqrt() + 0.0;
    }
    let q = x.sqrt();
    if x >= RESIDUAL_SAFE_MIN {
        let r = (-q).mul_add(q, x);
        if r < 0.0 {
            f64::next_down(q)
        } else {
            q
        }
    } else {
        f64::next_down(q).max(0.0)
    }
}

/// Upper bound of `sqrt(x)`, `x >= 0`.
pub(super) fn sqrt_ru(x: f64) -> f64 {
    if x == 0.0 || x == f64::INFINITY {
        return x.sqrt() + 0.0;
    }
    let q = x.sqrt();
    if x >= RESIDUAL_SAFE_MIN {
        let r = (-q).mul_add(q, x);
        if r > 0.0 {
            f64::next_up(q)
        } else {
            q
        }
    } else {
        f64::next_up(q)
    }
}

/// Lower bound of `x^n` for `x >= 0` (binary powering, every step rounded
/// down and clamped at 0, which keeps all factors non-negative).
pub(super) fn pow_rd(x: f64, mut n: u32) -> f64 {
    let mut base = x;
    let mut acc = 1.0;
    while n > 0 {
        if n & 1 == 1 {
            acc = mul_rd(acc, base).max(0.0);
        }
        n >>= 1;
        if n > 0 {
            base = mul_rd(base, base).max(0.0);
        }
    }
    acc
}

/// Upper bound of `x^n` for `x >= 0`.
pub(super) fn pow_ru(x: f64, mut n: u32) -> f64 {
    let mut base = x;
    let mut acc = 1.0;
    while n > 0 {
        if n & 1 == 1 {
            acc = mul_ru(acc, base);
        }
        n >>= 1;
        if n > 0 {
            base = mul_ru(base, base);
        }
    }
    acc
}

/// Range `[nlo, nhi]` of integers `n` such that `n * pi/2` may lie in
/// `[a, b]` (finite, `|a|, |b| <= TRIG_MAX_ARG`). Conservative: every `n`
/// with `n * pi/2` in `[a, b]` is in the range. Empty when `nlo > nhi`.
pub(super) fn quarter_range(a: f64, b: f64) -> (i64, i64) {
    let half_pi = std::f64::consts::FRAC_PI_2;
    let ta = a / half_pi;
    let tb = b / half_pi;
    let lower = f64::next_down(ta - ta.abs() * REDUCTION_MARGIN);
    let upper = f64::next_up(tb + tb.abs() * REDUCTION_MARGIN);
    (lower.ceil() as i64, upper.floor() as i64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directed_primitives_basic() {
        // exact cases stay exact
        assert_eq!(add_rd(1.0, 2.0), 3.0);
        assert_eq!(add_ru(1.0, 2.0), 3.0);
        assert_eq!(mul_rd(3.0, 0.5), 1.5);
        assert_eq!(mul_ru(3.0, 0.5), 1.5);
        assert_eq!(div_rd(1.0, 4.0), 0.25);
        assert_eq!(div_ru(1.0, 4.0), 0.25);
        assert_eq!(sqrt_rd(4.0), 2.0);
        assert_eq!(sqrt_ru(4.0), 2.0);
        // inexact cases bracket the value with adjacent floats
        let (l, h) = (div_rd(1.0, 3.0), div_ru(1.0, 3.0));
        assert!(l < h && f64::next_up(l) == h);
        assert!(l * 3.0 <= 1.0);
        let (l, h) = (sqrt_rd(2.0), sqrt_ru(2.0));
        assert!(f64::next_up(l) == h && l * l < 2.0 && h * h > 2.0);
        // overflow
        assert_eq!(add_rd(f64::MAX, f64::MAX), f64::MAX);
        assert_eq!(add_ru(f64::MAX, f64::MAX), f64::INFINITY);
        assert_eq!(mul_rd(-f64::MAX, 2.0), f64::NEG_INFINITY);
        assert_eq!(mul_ru(-f64::MAX, 2.0), -f64::MAX);
        // underflow: product of two tiny numbers is bracketed around 0
        let t = 1e-200;
        assert!(mul_rd(t, t) < 0.0 || mul_rd(t, t) == 0.0);
        assert!(mul_ru(t, t) > 0.0);
        // 0 * inf = 0
        assert_eq!(mul_rd(0.0, f64::INFINITY), 0.0);
        assert_eq!(mul_ru(f64::NEG_INFINITY, 0.0), 0.0);
    }
}
