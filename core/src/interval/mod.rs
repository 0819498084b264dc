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
//!
//! # Layout
//!
//! This file holds the type: its constants, constructors, accessors, set
//! operations, conversions and formatting. The arithmetic (operators,
//! powers, square root) is in `arith.rs`, the elementary functions in
//! `elementary.rs`, and the directed-rounding primitives both are built on
//! in `rounding.rs`.

use std::fmt;

mod arith;
mod elementary;
mod rounding;
#[cfg(test)]
mod tests;

use rounding::sub_ru;

/// Number of ulps by which results of `std` elementary functions are widened
/// outward (see the module documentation, rule 2).
pub const ELEM_ULPS: u32 = 4;

/// Smallest f64 strictly above pi/2.
const FRAC_PI_2_UP: f64 = f64::from_bits(std::f64::consts::FRAC_PI_2.to_bits() + 1);
/// Smallest f64 strictly above pi.
const PI_UP: f64 = f64::from_bits(std::f64::consts::PI.to_bits() + 1);

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
