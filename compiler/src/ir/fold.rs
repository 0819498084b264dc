//! Constant folding without silent rounding.
//!
//! The pool folds constant sub-expressions (`2 * 3`, `1 / 3`, `sin(1)`, the coefficients of
//! like terms and of nested sums). A floating-point fold rounds, and a rounded coefficient makes
//! the IR describe a slightly different model than the one written: an interval evaluation of
//! it need not enclose the written expression. So every fold is carried out twice: in
//! round-to-nearest floating point (`approx`, what point evaluation has always used) and in
//! outward-rounded interval arithmetic (`exact`, an enclosure of the real-number value). Where
//! the enclosure is a point, the fold was exact and the result is an ordinary constant; where it
//! is not, the result becomes an [`Node::Enclosure`](super::Node::Enclosure), which interval
//! evaluation reads as `[lo, hi]`.

use reachc_core::interval::Interval;

use super::eval::Arith;
use super::node::{Func1, Func2};

/// A folded constant: its round-to-nearest value and an enclosure of its exact value.
///
/// Invariant: `exact` holds the real value of the folded expression, and `approx` lies in
/// `exact`; when `exact` is a point, `approx` is that point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Folded {
    /// The value in floating point (what point evaluation uses).
    pub(super) approx: f64,
    /// An enclosure of the exact value.
    pub(super) exact: Interval,
}

impl Folded {
    /// The exact constant `v`.
    pub(super) fn point(v: f64) -> Folded {
        Folded {
            approx: v,
            exact: Interval::point(v),
        }
    }

    /// From a floating-point value and an enclosure of the exact one; the floating-point value
    /// is moved into the enclosure (it already is, up to a libm error beyond its documented
    /// bound) and is the point itself when the enclosure is one.
    fn new(approx: f64, exact: Interval) -> Folded {
        let approx = if exact.is_point() {
            exact.lo()
        } else {
            approx.clamp(exact.lo(), exact.hi())
        };
        Folded { approx, exact }
    }

    /// Whether the fold was exact.
    pub(super) fn is_exact(self) -> bool {
        self.exact.is_point()
    }

    /// Whether the value is exactly 0.
    pub(super) fn is_zero(self) -> bool {
        self.exact == Interval::ZERO
    }

    /// Whether the value is exactly 1.
    pub(super) fn is_one(self) -> bool {
        self.exact == Interval::ONE
    }

    /// Whether both the floating-point value and the enclosure are finite (a fold is only done
    /// then; otherwise the node is kept unevaluated).
    pub(super) fn is_finite(self) -> bool {
        self.approx.is_finite() && self.exact.lo().is_finite() && self.exact.hi().is_finite()
    }

    /// `self + o`.
    pub(super) fn add(self, o: Folded) -> Folded {
        Folded::new(self.approx + o.approx, self.exact + o.exact)
    }

    /// `self * o`.
    pub(super) fn mul(self, o: Folded) -> Folded {
        Folded::new(self.approx * o.approx, self.exact * o.exact)
    }

    /// `self ^ e`, or `None` for an exponent beyond `i32`. The floating-point value uses
    /// `powf` (nearly correctly rounded, so `10^-3` gives the literal `1e-3`).
    pub(super) fn powi(self, e: i64) -> Option<Folded> {
        let n = i32::try_from(e).ok()?;
        Some(Folded::new(self.approx.powf(e as f64), self.exact.powi(n)))
    }

    /// `f(self)`: exact where the value is known exactly (`abs`, `sign`, a square root that
    /// squares back, the functions at 0 and `log(1)`), else the enclosure of the widened
    /// elementary function.
    pub(super) fn call1(self, f: Func1) -> Folded {
        let approx = <f64 as Arith>::call1(self.approx, f);
        if self.is_exact() {
            let v = self.approx;
            let exact = match f {
                Func1::Abs | Func1::Sign => true,
                Func1::Sqrt => approx.mul_add(approx, -v) == 0.0,
                Func1::Sin
                | Func1::Tan
                | Func1::Atan
                | Func1::Sinh
                | Func1::Tanh
                | Func1::DSinc
                | Func1::Cos
                | Func1::Cosh
                | Func1::Exp
                | Func1::Sinc => v == 0.0,
                Func1::Log => v == 1.0,
            };
            if exact && approx.is_finite() {
                return Folded::point(approx);
            }
        }
        Folded::new(approx, <Interval as Arith>::call1(self.exact, f))
    }

    /// `f(self, o)`.
    pub(super) fn call2(self, f: Func2, o: Folded) -> Folded {
        Folded::new(
            <f64 as Arith>::call2(self.approx, f, o.approx),
            <Interval as Arith>::call2(self.exact, f, o.exact),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_folds_stay_points_and_inexact_ones_enclose() {
        let third = Folded::point(1.0).mul(Folded::point(3.0).powi(-1).unwrap());
        assert!(!third.is_exact());
        assert_eq!(third.approx, 1.0 / 3.0);
        assert!(third.exact.lo() < 1.0 / 3.0 || third.exact.hi() > 1.0 / 3.0);
        let six = Folded::point(2.0).mul(Folded::point(3.0));
        assert!(six.is_exact());
        assert_eq!(six.approx, 6.0);
        // 0.1 + 0.2 is not 0.3 in floating point, nor exact.
        let s = Folded::point(0.1).add(Folded::point(0.2));
        assert!(!s.is_exact());
        assert_eq!(s.approx, 0.1 + 0.2);
        assert!(Folded::point(3.0).powi(2).unwrap().is_exact());
        assert!(Folded::point(3.0).powi(i64::from(i32::MAX) + 1).is_none());
        assert!(Folded::point(0.0).is_zero() && Folded::point(1.0).is_one());
    }
}
