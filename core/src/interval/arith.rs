//! Interval arithmetic: `+`, `-`, `*`, `/` (also with `f64` operands and as
//! assignments), the square, integer and real powers, the reciprocal and the
//! square root, each rounded outward (see the [module documentation](super),
//! rules 1, 4 and 5).

use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

use super::rounding::{
    add_rd, add_ru, div_rd, div_ru, mul_rd, mul_ru, pow_rd, pow_ru, sqrt_rd, sqrt_ru, sub_rd,
    sub_ru,
};
use super::Interval;

impl Interval {
    /// The square `{x^2}`; tighter than `self * self` when `self` contains 0
    /// (e.g. `sqr([-2, 1]) = [0, 4]`).
    pub fn sqr(self) -> Interval {
        let big = self.mag();
        let hi = mul_ru(big, big);
        if self.contains_zero() {
            Interval::from_raw(0.0, hi)
        } else {
            let small = self.mig();
            Interval::from_raw(mul_rd(small, small).max(0.0), hi)
        }
    }

    /// Integer power `x^n`.
    ///
    /// `n = 0` gives `[1, 1]` (also for intervals containing 0). Even powers
    /// are non-negative, odd powers monotone. Negative powers are computed as
    /// `1 / x^|n|`; if `self` contains 0 this gives `ENTIRE` for odd `n` and
    /// the half-line `[1/mag^|n|, +inf]` for even `n`.
    pub fn powi(self, n: i32) -> Interval {
        if n == 0 {
            return Interval::ONE;
        }
        if n == 1 {
            return self;
        }
        let k = n.unsigned_abs();
        let pos = if k.is_multiple_of(2) {
            let hi = pow_ru(self.mag(), k);
            if self.contains_zero() {
                Interval::from_raw(0.0, hi)
            } else {
                Interval::from_raw(pow_rd(self.mig(), k), hi)
            }
        } else {
            let lo = if self.lo < 0.0 {
                -pow_ru(-self.lo, k)
            } else {
                pow_rd(self.lo, k)
            };
            let hi = if self.hi < 0.0 {
                -pow_rd(-self.hi, k)
            } else {
                pow_ru(self.hi, k)
            };
            Interval::from_raw(lo, hi)
        };
        if n < 0 {
            pos.recip()
        } else {
            pos
        }
    }

    /// Real power `x^y = exp(y * ln x)`.
    ///
    /// Defined for `x > 0`, and for `x = 0` with `y > 0` (`0^y = 0`). If the
    /// base may be negative, or may be 0 while the exponent may be `<= 0`,
    /// the result is `ENTIRE` (sound: the expression is undefined there).
    /// Integer exponents of negative bases are served by
    /// [`Interval::powi`].
    pub fn pow(self, y: Interval) -> Interval {
        if self.lo < 0.0 {
            return Interval::ENTIRE;
        }
        if self.lo == 0.0 {
            if y.lo <= 0.0 {
                return Interval::ENTIRE;
            }
            if self.hi == 0.0 {
                return Interval::ZERO;
            }
            // x^y is increasing in x for y > 0 and tends to 0 as x -> 0.
            let top = Interval::point(self.hi).pow_pos(y).hi;
            return Interval::from_raw(0.0, top);
        }
        self.pow_pos(y)
    }

    /// `exp(y * ln x)` for `x.lo > 0`.
    fn pow_pos(self, y: Interval) -> Interval {
        (y * self.ln()).exp()
    }

    /// The reciprocal `1 / x` (see division for intervals containing 0).
    pub fn recip(self) -> Interval {
        Interval::ONE / self
    }

    /// Square root on the non-negative part of the interval; `ENTIRE` if the
    /// interval is entirely negative.
    pub fn sqrt(self) -> Interval {
        if self.hi < 0.0 {
            return Interval::ENTIRE;
        }
        Interval::from_raw(sqrt_rd(self.lo.max(0.0)), sqrt_ru(self.hi))
    }
}

impl Neg for Interval {
    type Output = Interval;
    /// `[-hi, -lo]` (exact).
    #[inline]
    fn neg(self) -> Interval {
        Interval::from_raw(-self.hi, -self.lo)
    }
}

impl Add for Interval {
    type Output = Interval;
    /// `[lo1 + lo2, hi1 + hi2]`, rounded outward.
    #[inline]
    fn add(self, rhs: Interval) -> Interval {
        Interval::from_raw(add_rd(self.lo, rhs.lo), add_ru(self.hi, rhs.hi))
    }
}

impl Sub for Interval {
    type Output = Interval;
    /// `[lo1 - hi2, hi1 - lo2]`, rounded outward.
    #[inline]
    fn sub(self, rhs: Interval) -> Interval {
        Interval::from_raw(sub_rd(self.lo, rhs.hi), sub_ru(self.hi, rhs.lo))
    }
}

impl Mul for Interval {
    type Output = Interval;
    /// Min/max of the endpoint products, rounded outward, with `0 * inf = 0`.
    /// The signs of the operands say which two products are the min and the max
    /// (four only when both straddle 0): each rounded product costs an exact
    /// residual, so this is the hot spot of every inclusion function.
    #[inline]
    fn mul(self, rhs: Interval) -> Interval {
        let (a, b, c, d) = (self.lo, self.hi, rhs.lo, rhs.hi);
        let ((l1, l2), (h1, h2)) = if a >= 0.0 {
            if c >= 0.0 {
                ((a, c), (b, d))
            } else if d <= 0.0 {
                ((b, c), (a, d))
            } else {
                ((b, c), (b, d))
            }
        } else if b <= 0.0 {
            if c >= 0.0 {
                ((a, d), (b, c))
            } else if d <= 0.0 {
                ((b, d), (a, c))
            } else {
                ((a, d), (a, c))
            }
        } else if c >= 0.0 {
            ((a, d), (b, d))
        } else if d <= 0.0 {
            ((b, c), (a, c))
        } else {
            let lo = mul_rd(a, d).min(mul_rd(b, c));
            let hi = mul_ru(a, c).max(mul_ru(b, d));
            return Interval::from_raw(lo, hi);
        };
        Interval::from_raw(mul_rd(l1, l2), mul_ru(h1, h2))
    }
}

impl Div for Interval {
    type Output = Interval;
    /// Quotient, rounded outward. A divisor containing 0 gives `ENTIRE`,
    /// except: `[0, 0] / y = [0, 0]` for `y != [0, 0]`, and a divisor with 0
    /// as one endpoint gives a half-line when the numerator does not
    /// straddle 0.
    fn div(self, rhs: Interval) -> Interval {
        let (a, b, c, d) = (self.lo, self.hi, rhs.lo, rhs.hi);
        if c > 0.0 || d < 0.0 {
            let (lo, hi) = if c > 0.0 {
                if a >= 0.0 {
                    (div_rd(a, d), div_ru(b, c))
                } else if b <= 0.0 {
                    (div_rd(a, c), div_ru(b, d))
                } else {
                    (div_rd(a, c), div_ru(b, c))
                }
            } else if a >= 0.0 {
                (div_rd(b, d), div_ru(a, c))
            } else if b <= 0.0 {
                (div_rd(b, c), div_ru(a, d))
            } else {
                (div_rd(b, d), div_ru(a, d))
            };
            return Interval::from_raw(lo, hi);
        }
        // The divisor contains 0.
        if c == 0.0 && d == 0.0 {
            return Interval::ENTIRE;
        }
        if a == 0.0 && b == 0.0 {
            return Interval::ZERO;
        }
        if c == 0.0 {
            // divisor in (0, d]
            if a >= 0.0 {
                return Interval::from_raw(div_rd(a, d), f64::INFINITY);
            }
            if b <= 0.0 {
                return Interval::from_raw(f64::NEG_INFINITY, div_ru(b, d));
            }
        } else if d == 0.0 {
            // divisor in [c, 0)
            if a >= 0.0 {
                return Interval::from_raw(f64::NEG_INFINITY, div_ru(a, c));
            }
            if b <= 0.0 {
                return Interval::from_raw(div_rd(b, c), f64::INFINITY);
            }
        }
        Interval::ENTIRE
    }
}

macro_rules! scalar_ops {
    ($($tr:ident $m:ident $atr:ident $am:ident),*) => {$(
        impl $tr<f64> for Interval {
            type Output = Interval;
            /// Same as the operation with `Interval::point(rhs)`.
            #[inline]
            fn $m(self, rhs: f64) -> Interval {
                $tr::$m(self, Interval::point(rhs))
            }
        }
        impl $tr<Interval> for f64 {
            type Output = Interval;
            /// Same as the operation with `Interval::point(self)`.
            #[inline]
            fn $m(self, rhs: Interval) -> Interval {
                $tr::$m(Interval::point(self), rhs)
            }
        }
        impl $atr for Interval {
            /// `*self = *self op rhs`.
            #[inline]
            fn $am(&mut self, rhs: Interval) {
                *self = $tr::$m(*self, rhs);
            }
        }
        impl $atr<f64> for Interval {
            /// `*self = *self op Interval::point(rhs)`.
            #[inline]
            fn $am(&mut self, rhs: f64) {
                *self = $tr::$m(*self, Interval::point(rhs));
            }
        }
    )*};
}

scalar_ops!(
    Add add AddAssign add_assign,
    Sub sub SubAssign sub_assign,
    Mul mul MulAssign mul_assign,
    Div div DivAssign div_assign
);

#[cfg(test)]
mod tests {
    use super::super::tests::iv;
    use super::*;

    #[test]
    fn addition_rounds_outward() {
        let s = Interval::point(0.1) + Interval::point(0.2);
        let naive = 0.1 + 0.2; // 0.30000000000000004
        assert_ne!(s, Interval::point(naive));
        assert!(!s.is_point());
        assert!(s.contains(naive));
        // The exact sum of the doubles 0.1 and 0.2 lies below `naive`.
        assert!(s.lo() < naive && s.lo() <= 0.3);
        // Real 0.3 (not representable) is above the f64 0.3 = s.lo().
        assert_eq!(s.lo(), 0.3);
        // exact sums are not widened
        assert_eq!(iv(1.0, 2.0) + iv(3.0, 4.0), iv(4.0, 6.0));
        assert_eq!(iv(1.0, 2.0) - iv(3.0, 4.0), iv(-3.0, -1.0));
        // with scalars
        assert_eq!(iv(1.0, 2.0) + 1.0, iv(2.0, 3.0));
        assert_eq!(1.0 - iv(1.0, 2.0), iv(-1.0, 0.0));
        let mut a = iv(1.0, 2.0);
        a += 1.0;
        a *= iv(2.0, 2.0);
        a -= 1.0;
        a /= 2.0;
        assert_eq!(a, iv(1.5, 2.5));
    }

    #[test]
    fn multiplication_rounds_outward() {
        let p = Interval::point(0.1) * Interval::point(3.0);
        assert!(!p.is_point());
        assert!(p.contains(0.1 * 3.0));
        let q = Interval::point(1.0) / Interval::point(3.0);
        assert!(q.lo() < 1.0 / 3.0 || q.hi() > 1.0 / 3.0);
        assert!(q.contains(1.0 / 3.0) && !q.is_point());
        assert_eq!(iv(-2.0, 3.0) * iv(-1.0, 4.0), iv(-8.0, 12.0));
    }

    #[test]
    fn zero_times_infinity() {
        assert_eq!(Interval::ENTIRE * Interval::ZERO, Interval::ZERO);
        assert_eq!(Interval::ZERO * Interval::ENTIRE, Interval::ZERO);
        assert_eq!(
            iv(0.0, 1.0) * iv(1.0, f64::INFINITY),
            iv(0.0, f64::INFINITY)
        );
        assert_eq!(Interval::ENTIRE * Interval::ENTIRE, Interval::ENTIRE);
    }

    #[test]
    fn division_cases() {
        assert_eq!(iv(1.0, 2.0) / iv(-1.0, 1.0), Interval::ENTIRE);
        assert_eq!(iv(1.0, 2.0) / Interval::ZERO, Interval::ENTIRE);
        assert_eq!(Interval::ZERO / iv(-1.0, 1.0), Interval::ZERO);
        assert_eq!(iv(1.0, 2.0) / iv(0.0, 2.0), iv(0.5, f64::INFINITY));
        assert_eq!(iv(-2.0, -1.0) / iv(0.0, 2.0), iv(f64::NEG_INFINITY, -0.5));
        assert_eq!(iv(1.0, 2.0) / iv(-2.0, 0.0), iv(f64::NEG_INFINITY, -0.5));
        assert_eq!(iv(-2.0, -1.0) / iv(-2.0, 0.0), iv(0.5, f64::INFINITY));
        assert_eq!(iv(-1.0, 2.0) / iv(0.0, 2.0), Interval::ENTIRE);
        assert_eq!(iv(1.0, 2.0) / iv(2.0, 4.0), iv(0.25, 1.0));
        assert_eq!(iv(-1.0, 2.0) / iv(-4.0, -2.0), iv(-1.0, 0.5));
        assert_eq!(iv(1.0, 2.0) / iv(1.0, f64::INFINITY), iv(0.0, 2.0));
        assert_eq!(iv(2.0, 4.0).recip(), iv(0.25, 0.5));
        assert_eq!(iv(0.0, 4.0).recip(), iv(0.25, f64::INFINITY));
        assert_eq!(iv(-1.0, 4.0).recip(), Interval::ENTIRE);
    }

    #[test]
    fn sqr_and_powi() {
        let s = iv(-2.0, 1.0).sqr();
        assert_eq!(s.lo(), 0.0);
        assert!(s.hi() >= 4.0 && s.hi() <= 4.0 + 1e-15);
        assert_eq!(iv(2.0, 3.0).sqr(), iv(4.0, 9.0));
        assert_eq!(iv(-3.0, -2.0).sqr(), iv(4.0, 9.0));
        let c = iv(-2.0, 1.0).powi(3);
        assert!(c.lo() <= -8.0 && c.lo() >= -8.0 - 1e-14);
        assert!(c.hi() >= 1.0 && c.hi() <= 1.0 + 1e-15);
        assert_eq!(iv(-2.0, 1.0).powi(2), iv(0.0, 4.0));
        assert_eq!(iv(-2.0, 1.0).powi(4), iv(0.0, 16.0));
        assert_eq!(Interval::ENTIRE.powi(0), Interval::ONE);
        assert_eq!(iv(-2.0, 1.0).powi(1), iv(-2.0, 1.0));
        assert_eq!(iv(2.0, 4.0).powi(-1), iv(0.25, 0.5));
        assert_eq!(iv(-2.0, 1.0).powi(-1), Interval::ENTIRE);
        assert_eq!(iv(-2.0, 1.0).powi(-3), Interval::ENTIRE);
        assert_eq!(iv(-2.0, 1.0).powi(-2), iv(0.25, f64::INFINITY));
        assert_eq!(iv(0.0, 2.0).powi(-1), iv(0.5, f64::INFINITY));
        let big = iv(10.0, 10.0).powi(400);
        assert_eq!(big.hi(), f64::INFINITY);
        assert_eq!(big.lo(), f64::MAX);
        let p = Interval::point(1.1).powi(7);
        assert!(p.contains(1.1f64.powi(7)) && !p.is_point());
        assert!(Interval::ENTIRE.powi(i32::MIN).lo() >= 0.0);
        assert_eq!(iv(f64::NEG_INFINITY, -1.0).powi(3).lo(), f64::NEG_INFINITY);
    }

    #[test]
    fn pow_real() {
        assert_eq!(iv(-1.0, 2.0).pow(iv(2.0, 2.0)), Interval::ENTIRE);
        assert_eq!(iv(0.0, 2.0).pow(iv(0.0, 1.0)), Interval::ENTIRE);
        let r = iv(0.0, 2.0).pow(iv(1.0, 2.0));
        assert_eq!(r.lo(), 0.0);
        assert!(r.hi() >= 4.0 && r.hi() < 4.0001);
        assert_eq!(Interval::ZERO.pow(iv(0.5, 1.0)), Interval::ZERO);
        let s = iv(4.0, 9.0).pow(Interval::point(0.5));
        assert!(s.lo() <= 2.0 && s.lo() > 1.9999 && s.hi() >= 3.0 && s.hi() < 3.0001);
        assert!(iv(2.0, 2.0).pow(iv(10.0, 10.0)).contains(1024.0));
        assert_eq!(iv(2.0, 3.0).pow(Interval::ZERO), Interval::ONE);
    }
}
