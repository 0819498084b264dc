//! The elementary functions on intervals: `exp`, `ln`, the trigonometric and
//! hyperbolic functions, `atan` and `atan2`, `abs`, `sign`, `sinc`, `min` and
//! `max`, each widened by [`ELEM_ULPS`](super::ELEM_ULPS) where it calls
//! `std` and clamped to its known range (see the [module
//! documentation](super), rules 2, 3, 5 and 6).

use super::rounding::{div_ru, elem_down, elem_up, quarter_range};
use super::{Interval, FRAC_PI_2_UP, PI_UP};

/// Arguments of sin/cos/tan above this magnitude are not reduced.
const TRIG_MAX_ARG: f64 = f64::from_bits((1023 + 40) << 52);

/// A lower bound of the global minimum of `sin(x)/x` (about `-0.21723363`).
const SINC_MIN: f64 = -0.2173;
/// `sinc` is decreasing on `[0, SINC_DEC_END]` (its first minimum is at
/// about `4.4934`).
const SINC_DEC_END: f64 = 4.49;
/// An upper bound of `1 / SINC_DEC_END`, hence of `|sinc(x)|` for
/// `|x| >= SINC_DEC_END`.
const SINC_TAIL_MAX: f64 = 0.2228;

impl Interval {
    /// The exponential; widened by [`ELEM_ULPS`](super::ELEM_ULPS) ulps,
    /// clamped to `>= 0` (and `>= 1` / `<= 1` on non-negative /
    /// non-positive arguments).
    pub fn exp(self) -> Interval {
        let mut lo = if self.lo == f64::NEG_INFINITY {
            0.0
        } else {
            elem_down(self.lo.exp()).max(0.0)
        };
        let mut hi = if self.hi == f64::INFINITY {
            f64::INFINITY
        } else {
            elem_up(self.hi.exp())
        };
        if self.lo >= 0.0 {
            lo = lo.max(1.0);
        }
        if self.hi <= 0.0 {
            hi = hi.min(1.0);
        }
        Interval::from_raw(lo, hi)
    }

    /// Natural logarithm on the positive part of the interval (`-inf` as the
    /// lower bound if the interval reaches 0); `ENTIRE` if the interval has
    /// no positive point. Widened by [`ELEM_ULPS`](super::ELEM_ULPS)
    /// ulps.
    pub fn ln(self) -> Interval {
        if self.hi <= 0.0 {
            return Interval::ENTIRE;
        }
        let mut lo = if self.lo <= 0.0 {
            f64::NEG_INFINITY
        } else {
            elem_down(self.lo.ln())
        };
        let mut hi = if self.hi == f64::INFINITY {
            f64::INFINITY
        } else {
            elem_up(self.hi.ln())
        };
        if self.lo >= 1.0 {
            lo = lo.max(0.0);
        }
        if self.hi <= 1.0 {
            hi = hi.min(0.0);
        }
        Interval::from_raw(lo, hi)
    }

    /// Shared implementation of `sin`/`cos`: `shift` maps the index `n` of a
    /// critical point `n*pi/2` so that `(n + shift) mod 4 == 0` is a maximum
    /// (value 1) and `== 2` a minimum (value -1).
    fn sin_cos(self, f: fn(f64) -> f64, shift: i64) -> Interval {
        let (a, b) = (self.lo, self.hi);
        if !self.is_bounded() || self.mag() > TRIG_MAX_ARG {
            return Interval::UNIT;
        }
        let (nlo, nhi) = quarter_range(a, b);
        if nhi - nlo >= 3 {
            // Four consecutive critical points: both 1 and -1 are attained.
            return Interval::UNIT;
        }
        let (fa, fb) = (f(a), f(b));
        let mut lo = elem_down(fa.min(fb));
        let mut hi = elem_up(fa.max(fb));
        let mut n = nlo;
        while n <= nhi {
            match (n + shift).rem_euclid(4) {
                0 => hi = 1.0,
                2 => lo = -1.0,
                _ => {}
            }
            n += 1;
        }
        Interval::from_raw(lo.max(-1.0), hi.min(1.0))
    }

    /// Sine. Critical points `pi/2 + k*pi` are located conservatively;
    /// unbounded or very wide intervals give `[-1, 1]`.
    pub fn sin(self) -> Interval {
        self.sin_cos(f64::sin, -1)
    }

    /// Cosine. Critical points `k*pi` are located conservatively; unbounded
    /// or very wide intervals give `[-1, 1]`.
    pub fn cos(self) -> Interval {
        self.sin_cos(f64::cos, 0)
    }

    /// Tangent; `ENTIRE` if the interval may contain a pole `pi/2 + k*pi`
    /// (or is unbounded or of magnitude above `2^40`).
    pub fn tan(self) -> Interval {
        let (a, b) = (self.lo, self.hi);
        if !self.is_bounded() || self.mag() > TRIG_MAX_ARG {
            return Interval::ENTIRE;
        }
        let (nlo, nhi) = quarter_range(a, b);
        if nhi > nlo || (nhi == nlo && nlo.rem_euclid(2) == 1) {
            return Interval::ENTIRE;
        }
        Interval::from_raw(elem_down(a.tan()), elem_up(b.tan()))
    }

    /// Arctangent, within `[-pi/2, pi/2]` (outward).
    pub fn atan(self) -> Interval {
        let mut lo = elem_down(self.lo.atan()).max(-FRAC_PI_2_UP);
        let mut hi = elem_up(self.hi.atan()).min(FRAC_PI_2_UP);
        if self.lo >= 0.0 {
            lo = lo.max(0.0);
        }
        if self.hi <= 0.0 {
            hi = hi.min(0.0);
        }
        Interval::from_raw(lo, hi)
    }

    /// Hyperbolic sine (monotone; sign-preserving).
    pub fn sinh(self) -> Interval {
        let mut lo = elem_down(self.lo.sinh());
        let mut hi = elem_up(self.hi.sinh());
        if self.lo >= 0.0 {
            lo = lo.max(0.0);
        }
        if self.hi <= 0.0 {
            hi = hi.min(0.0);
        }
        Interval::from_raw(lo, hi)
    }

    /// Hyperbolic cosine (even, minimum 1 at 0).
    pub fn cosh(self) -> Interval {
        if self.mag() == 0.0 {
            return Interval::ONE;
        }
        let hi = elem_up(self.mag().cosh());
        let lo = if self.contains_zero() {
            1.0
        } else {
            elem_down(self.mig().cosh()).max(1.0)
        };
        Interval::from_raw(lo, hi)
    }

    /// Hyperbolic tangent, within `[-1, 1]`.
    pub fn tanh(self) -> Interval {
        let mut lo = elem_down(self.lo.tanh()).max(-1.0);
        let mut hi = elem_up(self.hi.tanh()).min(1.0);
        if self.lo >= 0.0 {
            lo = lo.max(0.0);
        }
        if self.hi <= 0.0 {
            hi = hi.min(0.0);
        }
        Interval::from_raw(lo, hi)
    }

    /// Absolute value (exact).
    pub fn abs(self) -> Interval {
        if self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            -self
        } else {
            Interval::from_raw(0.0, (-self.lo).max(self.hi))
        }
    }

    /// Sign function (`-1`, `0`, `1`): `[sign(lo), sign(hi)]`, a subset of
    /// `[-1, 1]` (exact, since sign is non-decreasing).
    pub fn sign(self) -> Interval {
        fn sgn(x: f64) -> f64 {
            if x > 0.0 {
                1.0
            } else if x < 0.0 {
                -1.0
            } else {
                0.0
            }
        }
        Interval::from_raw(sgn(self.lo), sgn(self.hi))
    }

    /// `sinc(x) = sin(x)/x` with `sinc(0) = 1`; always within
    /// `[-0.2173, 1]`. Uses monotonicity on `[0, 4.49]` (where `sinc` is
    /// decreasing in `|x|`) and the bound `|sinc(x)| <= 1/|x|` beyond.
    pub fn sinc(self) -> Interval {
        fn at(x: f64) -> Interval {
            // x > 0, finite or not
            let p = Interval::point(x);
            p.sin() / p
        }
        let small = self.mig();
        let big = self.mag();
        if big <= SINC_DEC_END {
            let hi = if small == 0.0 {
                1.0
            } else {
                at(small).hi.min(1.0)
            };
            let lo = if big == 0.0 {
                1.0
            } else {
                at(big).lo.max(SINC_MIN)
            };
            return Interval::from_raw(lo, hi);
        }
        if small <= SINC_DEC_END {
            let hi = if small == 0.0 {
                1.0
            } else {
                at(small).hi.clamp(SINC_TAIL_MAX, 1.0)
            };
            return Interval::from_raw(SINC_MIN, hi);
        }
        // |x| > 4.49 everywhere: 0 is not in self.
        let bound = div_ru(1.0, small);
        let envelope = Interval::from_raw((-bound).max(SINC_MIN), bound.min(1.0));
        let q = self.sin() / self;
        q.intersect(envelope).unwrap_or(envelope)
    }

    /// Two-argument arctangent `atan2(self, x)` (`self` is `y`), the angle
    /// of the point `(x, y)` in `(-pi, pi]`.
    ///
    /// Uses monotonicity in each argument on the half-planes `y >= 0`,
    /// `y < 0` and `x > 0`. If the box may meet the branch cut (`x <= 0`
    /// with `y` straddling 0), the result is `[-pi, pi]` rounded outward.
    pub fn atan2(self, x: Interval) -> Interval {
        let y = self;
        if y.lo >= 0.0 {
            return atan2_upper(y, x);
        }
        if y.hi < 0.0 || (y.hi == 0.0 && x.lo >= 0.0) {
            return -atan2_upper(-y, x);
        }
        if x.lo > 0.0 {
            // Right half-plane, y.lo < 0 < y.hi: increasing in y; for y < 0
            // increasing in x, for y > 0 decreasing in x.
            let lo = elem_down(y.lo.atan2(x.lo)).max(-FRAC_PI_2_UP);
            let hi = elem_up(y.hi.atan2(x.lo)).min(FRAC_PI_2_UP);
            return Interval::from_raw(lo, hi);
        }
        Interval::from_raw(-PI_UP, PI_UP)
    }

    /// Endpoint-wise minimum `{min(x, y)}`.
    pub fn min(self, other: Interval) -> Interval {
        Interval::from_raw(self.lo.min(other.lo), self.hi.min(other.hi))
    }

    /// Endpoint-wise maximum `{max(x, y)}`.
    pub fn max(self, other: Interval) -> Interval {
        Interval::from_raw(self.lo.max(other.lo), self.hi.max(other.hi))
    }
}

/// `atan2(y, x)` for `y.lo >= 0` (closed upper half-plane). There atan2 is
/// non-increasing in `x`, and in `y` increasing for `x > 0`, decreasing for
/// `x < 0`.
fn atan2_upper(y: Interval, x: Interval) -> Interval {
    let (ylo, yhi) = (y.lo + 0.0, y.hi + 0.0);
    let lo_v = if x.hi >= 0.0 {
        ylo.atan2(x.hi + 0.0)
    } else {
        yhi.atan2(x.hi)
    };
    let hi_v = if x.lo >= 0.0 {
        yhi.atan2(x.lo + 0.0)
    } else {
        ylo.atan2(x.lo)
    };
    Interval::from_raw(elem_down(lo_v).max(0.0), elem_up(hi_v).min(PI_UP))
}

#[cfg(test)]
mod tests {
    use super::super::rounding::down_n;
    use super::super::tests::iv;
    use super::super::ELEM_ULPS;
    use super::*;
    use std::f64::consts::{E, FRAC_PI_2, PI};

    #[test]
    fn sqrt_exp_ln() {
        assert_eq!(iv(4.0, 9.0).sqrt(), iv(2.0, 3.0));
        assert_eq!(iv(-4.0, 9.0).sqrt(), iv(0.0, 3.0));
        assert_eq!(iv(-4.0, -1.0).sqrt(), Interval::ENTIRE);
        let s = Interval::point(2.0).sqrt();
        assert!(s.contains(2f64.sqrt()) && !s.is_point());
        // exp
        let e = Interval::point(1e3).exp();
        assert_eq!(e.hi(), f64::INFINITY);
        assert_eq!(e.lo(), down_n(f64::MAX, ELEM_ULPS - 1));
        assert_eq!(Interval::ZERO.exp(), Interval::ONE);
        let e1 = Interval::ONE.exp();
        assert!(e1.lo() <= E && e1.hi() > E); // real e is above the f64 E
        assert_eq!(Interval::ENTIRE.exp(), iv(0.0, f64::INFINITY));
        assert_eq!(Interval::point(-1e3).exp().lo(), 0.0);
        // ln
        assert_eq!(Interval::ONE.ln(), Interval::ZERO);
        assert_eq!(iv(0.0, 1.0).ln(), iv(f64::NEG_INFINITY, 0.0));
        assert_eq!(iv(-1.0, 0.0).ln(), Interval::ENTIRE);
        let l2 = Interval::point(2.0).ln();
        assert!(l2.contains(std::f64::consts::LN_2));
        assert_eq!(iv(1.0, f64::INFINITY).ln(), iv(0.0, f64::INFINITY));
    }

    #[test]
    fn sin_cos_known() {
        let s = iv(0.0, PI).sin();
        assert!(s.contains(1.0) && s.hi() == 1.0);
        assert!(s.lo() <= 0.0);
        assert_eq!(Interval::ENTIRE.cos(), iv(-1.0, 1.0));
        assert_eq!(Interval::ENTIRE.sin(), iv(-1.0, 1.0));
        assert_eq!(iv(0.0, 7.0).sin(), iv(-1.0, 1.0));
        assert_eq!(iv(1e20, 1e20).sin(), iv(-1.0, 1.0));
        // monotone piece
        let s = iv(0.1, 0.2).sin();
        assert!(s.lo() <= 0.1f64.sin() && s.hi() >= 0.2f64.sin() && s.hi() < 0.2);
        // cos around 0 and pi
        assert_eq!(iv(-0.1, 0.1).cos().hi(), 1.0);
        assert_eq!(iv(3.0, 3.2).cos().lo(), -1.0);
        // sin(pi_f64) is a tiny positive number (real pi is above PI)
        let sp = Interval::point(PI).sin();
        assert!(sp.contains(1.2246467991473532e-16));
        // near the extremum: the point FRAC_PI_2 is a hair below pi/2, the
        // extremum is included conservatively.
        assert_eq!(Interval::point(FRAC_PI_2).sin().hi(), 1.0);
        // a point clearly away from extrema is tight
        let c = Interval::point(1.0).cos();
        assert!(c.contains(1f64.cos()) && c.width() < 1e-14);
    }

    #[test]
    fn tan_known() {
        assert_eq!(iv(1.0, 2.0).tan(), Interval::ENTIRE);
        assert!(Interval::PI.tan().contains(0.0));
        assert_eq!(Interval::FRAC_PI_2.tan(), Interval::ENTIRE);
        let t = iv(-1.0, 1.0).tan();
        assert!(t.lo() <= (-1f64).tan() && t.hi() >= 1f64.tan());
        // [2, 4] lies strictly between the poles pi/2 and 3pi/2
        let t = iv(2.0, 4.0).tan();
        assert!(t.is_bounded() && t.contains(2f64.tan()) && t.contains(4f64.tan()));
        assert!(t.contains(0.0));
        assert_eq!(Interval::ENTIRE.tan(), Interval::ENTIRE);
    }

    #[test]
    fn atan_atan2() {
        let a = Interval::ENTIRE.atan();
        assert!(a.lo() <= -FRAC_PI_2 && a.hi() >= FRAC_PI_2);
        assert!(a.hi() <= FRAC_PI_2_UP);
        assert_eq!(Interval::ZERO.atan(), Interval::ZERO);
        // across the branch cut
        let c = iv(-1.0, 1.0).atan2(iv(-2.0, -1.0));
        assert!(c.lo() <= -PI && c.hi() >= PI);
        assert_eq!(c, iv(-PI_UP, PI_UP));
        // y = 0 exactly on the negative x axis: pi only
        let d = Interval::ZERO.atan2(iv(-2.0, -1.0));
        assert!(d.contains(PI) && d.hi() == PI_UP && d.lo() > 3.0);
        // right half-plane straddling y = 0
        let r = iv(-1.0, 1.0).atan2(iv(1.0, 2.0));
        assert!(r.lo() <= -FRAC_PI_2 / 2.0 && r.hi() >= FRAC_PI_2 / 2.0);
        assert!(r.hi() < 0.8);
        // quadrants
        let q2 = iv(1.0, 2.0).atan2(iv(-2.0, -1.0));
        assert!(q2.contains(2f64.atan2(-1.0)) && q2.contains(1f64.atan2(-2.0)));
        let q3 = iv(-2.0, -1.0).atan2(iv(-2.0, -1.0));
        assert!(q3.contains((-2f64).atan2(-1.0)) && q3.contains((-1f64).atan2(-2.0)));
        assert!(q3.hi() < -1.5);
        // origin
        assert_eq!(Interval::ENTIRE.atan2(Interval::ENTIRE), iv(-PI_UP, PI_UP));
    }

    #[test]
    fn hyperbolic() {
        assert_eq!(Interval::ZERO.sinh(), Interval::ZERO);
        assert_eq!(Interval::ZERO.cosh(), Interval::ONE);
        assert_eq!(Interval::ZERO.tanh(), Interval::ZERO);
        assert_eq!(Interval::ENTIRE.tanh(), iv(-1.0, 1.0));
        assert_eq!(Interval::ENTIRE.sinh(), Interval::ENTIRE);
        assert_eq!(Interval::ENTIRE.cosh(), iv(1.0, f64::INFINITY));
        assert!(iv(-2.0, 1.0).cosh().contains(2f64.cosh()));
        assert_eq!(iv(-2.0, 1.0).cosh().lo(), 1.0);
    }

    #[test]
    fn abs_sign_min_max() {
        assert_eq!(iv(-3.0, 2.0).abs(), iv(0.0, 3.0));
        assert_eq!(iv(-3.0, -2.0).abs(), iv(2.0, 3.0));
        assert_eq!(iv(2.0, 3.0).abs(), iv(2.0, 3.0));
        assert_eq!(iv(2.0, 3.0).sign(), Interval::ONE);
        assert_eq!(iv(-3.0, -2.0).sign(), -Interval::ONE);
        assert_eq!(Interval::ZERO.sign(), Interval::ZERO);
        assert_eq!(iv(0.0, 3.0).sign(), iv(0.0, 1.0));
        assert_eq!(iv(-3.0, 0.0).sign(), iv(-1.0, 0.0));
        assert_eq!(Interval::ENTIRE.sign(), iv(-1.0, 1.0));
        assert_eq!(iv(0.0, 5.0).min(iv(1.0, 2.0)), iv(0.0, 2.0));
        assert_eq!(iv(0.0, 5.0).max(iv(1.0, 2.0)), iv(1.0, 5.0));
    }

    #[test]
    fn sinc_known() {
        assert_eq!(Interval::ZERO.sinc(), Interval::ONE);
        let g = Interval::ENTIRE.sinc();
        assert_eq!(g, iv(SINC_MIN, 1.0));
        let near = iv(-1e-8, 1e-8).sinc();
        assert_eq!(near.hi(), 1.0);
        assert!(near.lo() > 0.999_999);
        let s = iv(1.0, 2.0).sinc();
        assert!(s.contains(1f64.sin()) && s.contains(2f64.sin() / 2.0));
        assert!(s.lo() > 0.45 && s.hi() < 0.85);
        // the global minimum near 4.4934
        let m = iv(4.0, 5.0).sinc();
        assert!(m.lo() <= -0.217_233 && m.lo() >= SINC_MIN);
        let far = iv(100.0, 200.0).sinc();
        assert!(far.subset_of(iv(-0.0101, 0.0101)));
        let tail = iv(-1e300, -10.0).sinc();
        assert!(tail.subset_of(iv(-0.1001, 0.1001)));
    }
}
