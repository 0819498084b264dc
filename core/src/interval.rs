//! Sound, outward-rounded interval arithmetic on `f64`.
//!
//! An [`Interval`] `[lo, hi]` denotes the set of real numbers `x` with
//! `lo <= x <= hi`. `lo` may be `-inf` and `hi` may be `+inf` (half-lines and
//! the whole real line, [`Interval::ENTIRE`]). Endpoints are never NaN and
//! `lo <= hi` always holds; there is no empty interval (operations that could
//! produce one, such as [`Interval::intersect`], return an `Option`).
//!
//! # Soundness contract
//!
//! For every operation `F` implemented here and every real `x` (resp. reals
//! `x`, `y`) in the input interval(s) at which the real function `f` is
//! defined, the exact real value `f(x)` lies in `F(X)`. Results are allowed to
//! be wider than the exact range (overestimation), never narrower. The rules
//! used to guarantee this are:
//!
//! 1. **Basic operations** (`+`, `-`, `*`, `/`, [`Interval::sqrt`], and the
//!    multiplications inside [`Interval::sqr`] and [`Interval::powi`]) compute
//!    the IEEE-754 round-to-nearest result `r` of each endpoint formula. The
//!    exact result lies within half an ulp of `r`, so moving `r` one ulp outward
//!    (`next_down` for a lower bound, `next_up` for an upper bound) always
//!    gives a valid bound. The one-ulp move is skipped only where it is
//!    *provably* unnecessary:
//!    * the result is exact by construction (negation, multiplication by zero,
//!      `abs`, `min`/`max`, results that are exact infinities of infinite
//!      operands);
//!    * an error-free transformation shows the rounding error has the harmless
//!      sign (or is zero): `TwoSum` for `+`/`-`, and the fused multiply-add
//!      residuals `a*b - r`, `a - r*b`, `x - r*r` for `*`, `/`, `sqrt`. These
//!      are used only in exponent ranges where the residual is known to be
//!      exactly representable (no underflow, no overflow); elsewhere the bound
//!      is moved one ulp unconditionally.
//!
//!    On overflow of a finite computation the lower bound becomes `f64::MAX`
//!    (resp. the upper bound `-f64::MAX`), the other bound stays infinite.
//! 2. **Elementary functions** delegated to `std` (`exp`, `ln`, `sin`, `cos`,
//!    `tan`, `atan`, `atan2`, `sinh`, `cosh`, `tanh`) are not correctly rounded.
//!    Their results are widened outward by [`ELEM_ULPS`]` = 4` steps of
//!    `next_down`/`next_up`. Four steps cover any libm error of at most 2 ulps
//!    even when the exact value lies in the neighbouring binade (where ulps are
//!    half as large); the usual libms (glibc, musl, macOS) document at most
//!    1–2 ulps for these functions. Results are then clamped to the
//!    mathematically known range (`sin`, `cos`, `tanh` in `[-1, 1]`,
//!    `exp >= 0`, `cosh >= 1`, `atan` in `[-pi/2, pi/2]` and `atan2` in
//!    `[-pi, pi]`, both with the f64 constant rounded outward), and to known
//!    signs (e.g. `exp(x) >= 1` for `x >= 0`, `ln(x) <= 0` for `x <= 1`).
//! 3. **Periodic functions** (`sin`, `cos`, `tan`) are evaluated at the
//!    endpoints and the interval is searched for the critical points
//!    `k*pi/2`. The index range is computed from `x / (pi/2)` with a relative
//!    safety margin of `2^-48` (the reduction error is below `2^-51`), so a
//!    critical point that *may* lie inside is always included. Unbounded
//!    arguments or arguments with magnitude above `2^40` give `[-1, 1]`
//!    (`ENTIRE` for `tan`); `tan` returns `ENTIRE` whenever a pole may lie
//!    inside.
//! 4. **Division** by an interval containing zero gives `ENTIRE`, except when
//!    zero is an endpoint of the divisor and the sign of the quotient is
//!    known: then the proper half-line is returned. Endpoint products use
//!    `0 * inf = 0` (so `ENTIRE * [0, 0] = [0, 0]`).
//! 5. **Domains.** `sqrt` and `ln` are evaluated on the part of the argument
//!    inside their domain (`x >= 0`, resp. `x > 0`); if that part is empty
//!    the result is `ENTIRE`. [`Interval::pow`] returns `ENTIRE` whenever the
//!    base may be negative, or may be zero while the exponent may be `<= 0`.
//!    `atan2` returns `[-pi, pi]` (outward) when the argument box may meet the
//!    branch cut (`x <= 0`, `y` straddling 0) or the origin.
//! 6. **No NaN escapes.** Any NaN produced internally turns the result into
//!    `ENTIRE`.
//!
//! Degenerate intervals `[+inf, +inf]` and `[-inf, -inf]` (e.g. from
//! [`Interval::point`]`(f64::INFINITY)`) contain no real number; they are
//! accepted and propagated without NaN, but carry no soundness meaning.

use std::fmt;
use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

/// Number of ulps by which results of `std` elementary functions are widened
/// outward (see the module documentation, rule 2).
pub const ELEM_ULPS: u32 = 4;

/// `2^-900`: below this magnitude the FMA residual used to decide the rounding
/// direction may be inexact (underflow), so we widen unconditionally.
const RESIDUAL_SAFE_MIN: f64 = f64::from_bits((1023 - 900) << 52);

/// Arguments of sin/cos/tan above this magnitude are not reduced.
const TRIG_MAX_ARG: f64 = f64::from_bits((1023 + 40) << 52);

/// Relative safety margin of the `x / (pi/2)` reduction.
const REDUCTION_MARGIN: f64 = f64::from_bits((1023 - 48) << 52);

/// Smallest f64 strictly above pi/2.
const FRAC_PI_2_UP: f64 = f64::from_bits(std::f64::consts::FRAC_PI_2.to_bits() + 1);
/// Smallest f64 strictly above pi.
const PI_UP: f64 = f64::from_bits(std::f64::consts::PI.to_bits() + 1);

/// A lower bound of the global minimum of `sin(x)/x` (about `-0.21723363`).
const SINC_MIN: f64 = -0.2173;
/// `sinc` is decreasing on `[0, SINC_DEC_END]` (its first minimum is at
/// about `4.4934`).
const SINC_DEC_END: f64 = 4.49;
/// An upper bound of `1 / SINC_DEC_END`, hence of `|sinc(x)|` for
/// `|x| >= SINC_DEC_END`.
const SINC_TAIL_MAX: f64 = 0.2228;

// ---------------------------------------------------------------------------
// Rounding primitives
// ---------------------------------------------------------------------------

/// `n` steps of `next_up`.
#[inline]
fn up_n(mut x: f64, n: u32) -> f64 {
    for _ in 0..n {
        x = f64::next_up(x);
    }
    x
}

/// `n` steps of `next_down`.
#[inline]
fn down_n(mut x: f64, n: u32) -> f64 {
    for _ in 0..n {
        x = f64::next_down(x);
    }
    x
}

/// Lower bound of a libm result.
#[inline]
fn elem_down(x: f64) -> f64 {
    down_n(x, ELEM_ULPS)
}

/// Upper bound of a libm result.
#[inline]
fn elem_up(x: f64) -> f64 {
    up_n(x, ELEM_ULPS)
}

/// Lower bound for a finite operation whose nearest result overflowed.
#[inline]
fn overflow_down(r: f64) -> f64 {
    if r > 0.0 {
        f64::MAX
    } else {
        r
    }
}

/// Lower bound of `a + b`.
#[inline]
fn add_rd(a: f64, b: f64) -> f64 {
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
fn add_ru(a: f64, b: f64) -> f64 {
    -add_rd(-a, -b)
}

/// Lower bound of `a - b`.
#[inline]
fn sub_rd(a: f64, b: f64) -> f64 {
    add_rd(a, -b)
}

/// Upper bound of `a - b`.
#[inline]
fn sub_ru(a: f64, b: f64) -> f64 {
    add_ru(a, -b)
}

/// Lower bound of `a * b`, with `0 * inf = 0`.
#[inline]
fn mul_rd(a: f64, b: f64) -> f64 {
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
fn mul_ru(a: f64, b: f64) -> f64 {
    -mul_rd(-a, b)
}

/// Lower bound of `a / b` (`b != 0`); `finite / inf` gives the limit 0.
fn div_rd(a: f64, b: f64) -> f64 {
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
fn div_ru(a: f64, b: f64) -> f64 {
    -div_rd(-a, b)
}

/// Lower bound of `sqrt(x)`, `x >= 0`.
fn sqrt_rd(x: f64) -> f64 {
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
fn sqrt_ru(x: f64) -> f64 {
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
fn pow_rd(x: f64, mut n: u32) -> f64 {
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
fn pow_ru(x: f64, mut n: u32) -> f64 {
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
fn quarter_range(a: f64, b: f64) -> (i64, i64) {
    let half_pi = std::f64::consts::FRAC_PI_2;
    let ta = a / half_pi;
    let tb = b / half_pi;
    let lower = f64::next_down(ta - ta.abs() * REDUCTION_MARGIN);
    let upper = f64::next_up(tb + tb.abs() * REDUCTION_MARGIN);
    (lower.ceil() as i64, upper.floor() as i64)
}

// ---------------------------------------------------------------------------
// The interval type
// ---------------------------------------------------------------------------

/// A closed real interval `[lo, hi]` with outward-rounded `f64` endpoints.
///
/// Invariants: `lo <= hi`, neither endpoint is NaN; `lo` may be `-inf` and
/// `hi` may be `+inf`. See the [module documentation](self) for the soundness
/// contract.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    lo: f64,
    hi: f64,
}

impl Interval {
    /// The whole real line `[-inf, +inf]`.
    pub const ENTIRE: Interval = Interval {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };
    /// The point interval `[0, 0]`.
    pub const ZERO: Interval = Interval { lo: 0.0, hi: 0.0 };
    /// The point interval `[1, 1]`.
    pub const ONE: Interval = Interval { lo: 1.0, hi: 1.0 };
    /// `[-1, 1]`, the range of `sin` and `cos`.
    const UNIT: Interval = Interval { lo: -1.0, hi: 1.0 };
    /// A tight enclosure of pi: `[PI, f64::next_up(PI)]` (the f64 constant `PI`
    /// is below the real pi).
    pub const PI: Interval = Interval {
        lo: std::f64::consts::PI,
        hi: PI_UP,
    };
    /// A tight enclosure of pi/2.
    pub const FRAC_PI_2: Interval = Interval {
        lo: std::f64::consts::FRAC_PI_2,
        hi: FRAC_PI_2_UP,
    };
    /// A tight enclosure of 2*pi.
    pub const TAU: Interval = Interval {
        lo: std::f64::consts::TAU,
        hi: f64::from_bits(std::f64::consts::TAU.to_bits() + 1),
    };
    /// A tight enclosure of Euler's number e.
    pub const E: Interval = Interval {
        lo: std::f64::consts::E,
        hi: f64::from_bits(std::f64::consts::E.to_bits() + 1),
    };

    /// Internal constructor for computed results: NaN endpoints (or a
    /// violated order) turn the result into [`Interval::ENTIRE`]; negative
    /// zeros are normalised to `+0`.
    #[inline]
    fn from_raw(lo: f64, hi: f64) -> Interval {
        if lo.is_nan() || hi.is_nan() || lo > hi {
            return Interval::ENTIRE;
        }
        Interval {
            lo: lo + 0.0,
            hi: hi + 0.0,
        }
    }

    /// Creates the interval `[lo, hi]`.
    ///
    /// `lo` may be `-inf` and `hi` may be `+inf`.
    ///
    /// # Panics
    ///
    /// Panics if `lo` or `hi` is NaN or if `lo > hi`: constructing such an
    /// interval is a programming error. Use [`Interval::try_new`] for
    /// untrusted input.
    pub fn new(lo: f64, hi: f64) -> Interval {
        match Interval::try_new(lo, hi) {
            Some(i) => i,
            None => panic!("Interval::new: invalid bounds [{lo}, {hi}]"),
        }
    }

    /// Creates `[lo, hi]`, or returns `None` if an endpoint is NaN or
    /// `lo > hi`.
    pub fn try_new(lo: f64, hi: f64) -> Option<Interval> {
        if lo.is_nan() || hi.is_nan() || lo > hi {
            None
        } else {
            Some(Interval::from_raw(lo, hi))
        }
    }

    /// The point interval `[x, x]`. NaN gives [`Interval::ENTIRE`]; an
    /// infinite `x` gives the degenerate interval `[x, x]`.
    #[inline]
    pub fn point(x: f64) -> Interval {
        Interval::from_raw(x, x)
    }

    /// The lower endpoint.
    #[inline]
    pub fn lo(self) -> f64 {
        self.lo
    }

    /// The upper endpoint.
    #[inline]
    pub fn hi(self) -> f64 {
        self.hi
    }

    /// A point of the interval close to its midpoint: `0` for `ENTIRE`,
    /// `-f64::MAX` / `f64::MAX` for half-lines, the endpoint for point
    /// intervals. The result always lies in the interval.
    #[inline]
    pub fn mid(self) -> f64 {
        let (a, b) = (self.lo, self.hi);
        if a == b {
            return a;
        }
        match (a.is_finite(), b.is_finite()) {
            (false, false) => 0.0,
            (false, true) => -f64::MAX,
            (true, false) => f64::MAX,
            (true, true) => {
                let s = a + b;
                let m = if s.is_finite() {
                    s * 0.5
                } else {
                    a * 0.5 + b * 0.5
                };
                m.max(a).min(b) + 0.0
            }
        }
    }

    /// An upper bound of the width `hi - lo` (rounded up; `+inf` if
    /// unbounded, `0` for point intervals).
    pub fn width(self) -> f64 {
        if self.lo == self.hi {
            0.0
        } else {
            sub_ru(self.hi, self.lo)
        }
    }

    /// An upper bound `r` of half the width such that
    /// `[mid() - r, mid() + r]` (computed exactly) contains the interval.
    pub fn rad(self) -> f64 {
        if self.lo == self.hi {
            return 0.0;
        }
        let m = self.mid();
        sub_ru(m, self.lo).max(sub_ru(self.hi, m))
    }

    /// The magnitude `max |x|` over the interval.
    pub fn mag(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// The mignitude `min |x|` over the interval (`0` if it contains 0).
    pub fn mig(self) -> f64 {
        if self.contains_zero() {
            0.0
        } else {
            self.lo.abs().min(self.hi.abs())
        }
    }

    /// Whether `lo <= x <= hi` (false for NaN).
    pub fn contains(self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// Whether the interval contains 0.
    pub fn contains_zero(self) -> bool {
        self.lo <= 0.0 && 0.0 <= self.hi
    }

    /// Whether `self` is a subset of `other`.
    pub fn subset_of(self, other: Interval) -> bool {
        other.lo <= self.lo && self.hi <= other.hi
    }

    /// Whether both endpoints are finite.
    pub fn is_bounded(self) -> bool {
        self.lo.is_finite() && self.hi.is_finite()
    }

    /// Whether `lo == hi`.
    pub fn is_point(self) -> bool {
        self.lo == self.hi
    }

    /// The smallest interval containing both `self` and `other`.
    pub fn hull(self, other: Interval) -> Interval {
        Interval {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }

    /// The intersection, or `None` if it is empty.
    pub fn intersect(self, other: Interval) -> Option<Interval> {
        let lo = self.lo.max(other.lo);
        let hi = self.hi.min(other.hi);
        if lo <= hi {
            Some(Interval { lo, hi })
        } else {
            None
        }
    }

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

    /// The exponential; widened by [`ELEM_ULPS`] ulps, clamped to `>= 0`
    /// (and `>= 1` / `<= 1` on non-negative / non-positive arguments).
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
    /// no positive point. Widened by [`ELEM_ULPS`] ulps.
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

impl Default for Interval {
    /// `[0, 0]`.
    fn default() -> Self {
        Interval::ZERO
    }
}

impl From<f64> for Interval {
    /// Same as [`Interval::point`].
    fn from(x: f64) -> Self {
        Interval::point(x)
    }
}

impl fmt::Display for Interval {
    /// Formats as `[lo, hi]`, e.g. `[-0.1, 0.2]` (shortest round-trip
    /// representation of each endpoint).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}, {}]", self.lo, self.hi)
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
mod tests;
