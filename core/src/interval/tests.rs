//! Hard-coded checks of the type itself (constructors, accessors, formatting,
//! constants) and of degenerate intervals through every operation; the
//! arithmetic, the elementary functions and the rounding primitives are tested
//! beside them.

use super::*;
use std::f64::consts::{E, FRAC_PI_2, PI};

pub(super) fn iv(lo: f64, hi: f64) -> Interval {
    Interval::new(lo, hi)
}

#[test]
fn constructors() {
    assert_eq!(Interval::try_new(2.0, 1.0), None);
    assert_eq!(Interval::try_new(f64::NAN, 1.0), None);
    assert_eq!(Interval::point(f64::NAN), Interval::ENTIRE);
    let p = Interval::point(f64::INFINITY);
    assert_eq!((p.lo(), p.hi()), (f64::INFINITY, f64::INFINITY));
    assert_eq!(
        Interval::new(f64::NEG_INFINITY, f64::INFINITY),
        Interval::ENTIRE
    );
    // negative zero is normalised
    assert!(iv(-0.0, 0.0).lo().is_sign_positive());
    assert_eq!(Interval::default(), Interval::ZERO);
    assert_eq!(Interval::from(2.5), Interval::point(2.5));
}

#[test]
#[should_panic]
fn new_panics_on_reversed() {
    let _ = Interval::new(1.0, 0.0);
}

#[test]
#[should_panic]
fn new_panics_on_nan() {
    let _ = Interval::new(f64::NAN, 0.0);
}

#[test]
fn accessors() {
    let x = iv(-1.0, 3.0);
    assert_eq!(x.mid(), 1.0);
    assert_eq!(x.width(), 4.0);
    assert_eq!(x.rad(), 2.0);
    assert_eq!(x.mag(), 3.0);
    assert_eq!(x.mig(), 0.0);
    assert_eq!(iv(-5.0, -2.0).mig(), 2.0);
    assert!(x.contains(0.0) && x.contains(3.0) && !x.contains(3.5));
    assert!(!x.contains(f64::NAN));
    assert!(x.contains_zero());
    assert!(iv(0.0, 1.0).subset_of(x) && !x.subset_of(iv(0.0, 1.0)));
    assert!(x.is_bounded() && !Interval::ENTIRE.is_bounded());
    assert!(Interval::point(2.0).is_point() && !x.is_point());
    assert_eq!(Interval::ENTIRE.mid(), 0.0);
    assert_eq!(iv(1.0, f64::INFINITY).mid(), f64::MAX);
    assert_eq!(iv(f64::NEG_INFINITY, 1.0).mid(), -f64::MAX);
    assert_eq!(iv(-f64::MAX, f64::MAX).mid(), 0.0);
    assert_eq!(iv(f64::MAX, f64::MAX).mid(), f64::MAX);
    assert_eq!(Interval::ENTIRE.width(), f64::INFINITY);
    assert_eq!(iv(-f64::MAX, f64::MAX).width(), f64::INFINITY);
    // width rounded up
    let w = iv(0.1, 0.7).width();
    assert!(w >= 0.6 && w - (0.7 - 0.1) >= 0.0);
    // rad encloses
    let y = iv(0.1, 0.3);
    let (m, r) = (y.mid(), y.rad());
    assert!(m - r <= 0.1 && m + r >= 0.3);
    assert_eq!(x.hull(iv(5.0, 6.0)), iv(-1.0, 6.0));
    assert_eq!(x.intersect(iv(2.0, 6.0)), Some(iv(2.0, 3.0)));
    assert_eq!(x.intersect(iv(4.0, 6.0)), None);
    assert_eq!(x.intersect(iv(3.0, 6.0)), Some(iv(3.0, 3.0)));
}

#[test]
fn display() {
    assert_eq!(iv(-0.1, 0.2).to_string(), "[-0.1, 0.2]");
    assert_eq!(Interval::ENTIRE.to_string(), "[-inf, inf]");
    assert_eq!(iv(1.0, 2.5).to_string(), "[1, 2.5]");
}

#[test]
fn no_nan_escapes_degenerate() {
    let pinf = Interval::point(f64::INFINITY);
    let ninf = Interval::point(f64::NEG_INFINITY);
    let all = [
        pinf + ninf,
        pinf - pinf,
        pinf * Interval::ZERO,
        pinf / pinf,
        Interval::ENTIRE / Interval::ENTIRE,
        pinf.sin(),
        pinf.exp(),
        pinf.ln(),
        ninf.sqrt(),
        pinf.pow(Interval::ZERO),
        ninf.atan2(pinf),
        pinf.sinc(),
        pinf.tan(),
        pinf.powi(-3),
    ];
    for r in all {
        assert!(
            !r.lo().is_nan() && !r.hi().is_nan() && r.lo() <= r.hi(),
            "{r}"
        );
    }
}

#[test]
fn constants_enclose() {
    assert!(Interval::PI.contains(PI) && Interval::PI.hi() > PI);
    assert!(Interval::TAU.contains(std::f64::consts::TAU));
    assert!(Interval::E.contains(E));
    assert!(Interval::FRAC_PI_2.contains(FRAC_PI_2));
}
