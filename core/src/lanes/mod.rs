//! [`X8`]: eight `f64` lanes, the arithmetic of [`System::drift_x8`](crate::System::drift_x8).
//!
//! Generated code evaluates the drift of eight sample paths at once with the same expression
//! text as its scalar `drift`, over `X8` instead of `f64` (constants and the time stay `f64`).
//! Every operation acts lane by lane with the same IEEE operation or the same library function
//! as the scalar code, so lane `i` of the result is bit for bit what `drift` gives for path
//! `i`; the element-wise loops compile to vector instructions.

mod sin;

use std::ops::{Add, Div, Mul, Neg, Sub};

/// Eight `f64` lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct X8(pub [f64; 8]);

impl X8 {
    /// Every lane `v`.
    #[inline(always)]
    pub fn splat(v: f64) -> X8 {
        X8([v; 8])
    }

    /// `f` of every lane.
    #[inline(always)]
    pub fn map(self, f: impl Fn(f64) -> f64) -> X8 {
        X8(self.0.map(f))
    }

    /// `f` of every pair of lanes.
    #[inline(always)]
    pub fn zip(self, other: X8, f: impl Fn(f64, f64) -> f64) -> X8 {
        X8(std::array::from_fn(|i| f(self.0[i], other.0[i])))
    }
}

/// The arithmetic `f64` and [`X8`] share, for code written once for one path and for eight
/// (the same IEEE operations in the same order per lane).
pub trait Real:
    Copy + From<f64> + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self>
{
    /// The absolute value (per lane).
    fn abs(self) -> Self;
    /// `v` moved into `[lo, hi]` by `clamp` (per lane).
    fn clamp_with(self, clamp: impl Fn(f64) -> f64) -> Self;
}

impl Real for f64 {
    #[inline(always)]
    fn abs(self) -> f64 {
        f64::abs(self)
    }
    #[inline(always)]
    fn clamp_with(self, clamp: impl Fn(f64) -> f64) -> f64 {
        clamp(self)
    }
}

impl Real for X8 {
    #[inline(always)]
    fn abs(self) -> X8 {
        X8::abs(self)
    }
    #[inline(always)]
    fn clamp_with(self, clamp: impl Fn(f64) -> f64) -> X8 {
        self.map(clamp)
    }
}

impl From<f64> for X8 {
    #[inline(always)]
    fn from(v: f64) -> X8 {
        X8::splat(v)
    }
}

/// The element-wise binary operators, with `f64` on either side.
macro_rules! binary {
    ($($tr:ident $m:ident $op:tt),*) => {$(
        impl $tr for X8 {
            type Output = X8;
            #[inline(always)]
            fn $m(self, o: X8) -> X8 {
                self.zip(o, |a, b| a $op b)
            }
        }
        impl $tr<f64> for X8 {
            type Output = X8;
            #[inline(always)]
            fn $m(self, o: f64) -> X8 {
                self.map(|a| a $op o)
            }
        }
        impl $tr<X8> for f64 {
            type Output = X8;
            #[inline(always)]
            fn $m(self, o: X8) -> X8 {
                o.map(|b| self $op b)
            }
        }
    )*};
}

binary!(Add add +, Sub sub -, Mul mul *, Div div /);

impl Neg for X8 {
    type Output = X8;
    #[inline(always)]
    fn neg(self) -> X8 {
        self.map(|a| -a)
    }
}

/// Methods named as `f64`'s, lane by lane.
macro_rules! unary {
    ($($m:ident),*) => {
        impl X8 {$(
            #[doc = concat!("`f64::", stringify!($m), "` of every lane.")]
            #[inline(always)]
            pub fn $m(self) -> X8 {
                self.map(f64::$m)
            }
        )*}
    };
}

unary!(cos, tan, exp, ln, sqrt, abs, atan, sinh, cosh, tanh);

impl X8 {
    /// `f64::powi` of every lane.
    #[inline(always)]
    pub fn powi(self, k: i32) -> X8 {
        self.map(|a| a.powi(k))
    }

    /// [`crate::func::pow`] of every lane.
    #[inline(always)]
    pub fn powf(self, y: impl Into<X8>) -> X8 {
        self.zip(y.into(), crate::func::pow)
    }

    /// `f64::atan2` of every lane (`self` is `y`).
    #[inline(always)]
    pub fn atan2(self, x: impl Into<X8>) -> X8 {
        self.zip(x.into(), f64::atan2)
    }

    /// `f64::min` of every lane.
    #[inline(always)]
    pub fn min(a: impl Into<X8>, b: impl Into<X8>) -> X8 {
        a.into().zip(b.into(), f64::min)
    }

    /// `f64::max` of every lane.
    #[inline(always)]
    pub fn max(a: impl Into<X8>, b: impl Into<X8>) -> X8 {
        a.into().zip(b.into(), f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_compute_what_scalars_do() {
        let a = X8(std::array::from_fn(|i| i as f64 * 0.7 - 2.1));
        let b = X8(std::array::from_fn(|i| 1.3 - i as f64 * 0.45));
        let e = (2.0 * a - b / 3.0 + a * b).sin() / (1.5 + b.powi(2)) - X8::max(a, 0.25);
        for i in 0..8 {
            let (x, y) = (a.0[i], b.0[i]);
            let s = (2.0 * x - y / 3.0 + x * y).sin() / (1.5 + y.powi(2)) - f64::max(x, 0.25);
            assert_eq!(e.0[i].to_bits(), s.to_bits(), "lane {i}");
        }
        assert_eq!(X8::splat(2.0).atan2(-1.0).0[3], 2.0f64.atan2(-1.0));
        assert_eq!((-a).0[1], -a.0[1]);
    }
}
