//! Hard-coded checks of known cases and of the private rounding primitives.

use super::*;
use std::f64::consts::{E, FRAC_PI_2, PI};

fn iv(lo: f64, hi: f64) -> Interval {
    Interval::new(lo, hi)
}

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
