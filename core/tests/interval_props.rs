//! Property tests for `reachc_core::interval::Interval`: for random
//! intervals (infinite ends, tiny widths, points, neighbourhoods of `k*pi/2`
//! and of 0) and random points inside them, the value of the function at
//! the points lies in the interval result.
//!
//! Oracles: for `+ - * / sqrt sqr powi` the exact real result is compared
//! through error-free transformations (TwoSum / FMA residuals, double-double
//! powers) where those are exact, otherwise the round-to-nearest value is
//! used (any sound enclosure with f64 ends contains it). For the elementary
//! functions the `std` f64 value at the point is used.

use proptest::prelude::*;
use reachc_core::interval::Interval;
use std::f64::consts::{FRAC_PI_2, PI};

// ---------------------------------------------------------------------------
// Generators
// ---------------------------------------------------------------------------

fn step(mut x: f64, ulps: i32) -> f64 {
    for _ in 0..ulps.unsigned_abs() {
        x = if ulps > 0 { next_up(x) } else { next_down(x) };
    }
    x
}

fn next_up(x: f64) -> f64 {
    if x.is_nan() || x == f64::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let b = x.to_bits();
    f64::from_bits(if x > 0.0 { b + 1 } else { b - 1 })
}

fn next_down(x: f64) -> f64 {
    -next_up(-x)
}

/// Finite values of many kinds.
fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -10.0..10.0f64,
        2 => -1e3..1e3f64,
        3 => (-40i32..40, -3i32..=3).prop_map(|(k, u)| step(FRAC_PI_2 * k as f64, u)),
        1 => (-40i32..40, -1e-9..1e-9f64).prop_map(|(k, d)| FRAC_PI_2 * k as f64 + d),
        1 => -1e-300..1e-300f64,
        1 => -1e-5..1e-5f64,
        1 => prop::num::f64::NORMAL | prop::num::f64::SUBNORMAL | prop::num::f64::ZERO,
        1 => prop::sample::select(vec![
            0.0, 1.0, -1.0, 2.0, 0.5, f64::MAX, -f64::MAX, f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE, 5e-324, -5e-324, 1e300, -1e300, PI, -PI, 710.0, -745.0,
        ]),
    ]
    .prop_map(|x| x + 0.0)
}

/// Endpoints, including infinities.
fn endpoint() -> impl Strategy<Value = f64> {
    prop_oneof![
        12 => finite(),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
    ]
}

/// Intervals: arbitrary pairs, points, and tiny widths.
fn interval() -> impl Strategy<Value = Interval> {
    prop_oneof![
        4 => (endpoint(), endpoint()).prop_map(|(a, b)| Interval::new(a.min(b), a.max(b))),
        2 => finite().prop_map(Interval::point),
        2 => (finite(), 0i32..8).prop_map(|(a, u)| Interval::new(a, step(a, u))),
        1 => (finite(), 0.0..1e-3f64).prop_map(|(a, w)| Interval::new(a, a + w)),
        1 => (-1e-3..0.0f64, 0.0..1e-3f64).prop_map(|(a, b)| Interval::new(a, b)),
    ]
}

/// A selector of a point inside an interval.
#[derive(Clone, Copy, Debug)]
struct Pick {
    sel: u8,
    u: f64,
    c: f64,
}

fn pick() -> impl Strategy<Value = Pick> {
    (0u8..4, 0.0..=1.0f64, finite()).prop_map(|(sel, u, c)| Pick { sel, u, c })
}

/// A finite real point of `i`, or `None` for degenerate infinite intervals.
fn point_in(i: Interval, p: Pick) -> Option<f64> {
    let (lo, hi) = (i.lo(), i.hi());
    let clampf = |x: f64| x.max(lo).min(hi);
    let x = match p.sel {
        0 => lo,
        1 => hi,
        2 if i.is_bounded() => clampf(lo * (1.0 - p.u) + hi * p.u),
        _ => clampf(p.c),
    };
    let x = if x.is_finite() {
        x
    } else {
        clampf(x.clamp(-f64::MAX, f64::MAX))
    };
    (x.is_finite() && i.contains(x)).then_some(x + 0.0)
}

// ---------------------------------------------------------------------------
// Oracles
// ---------------------------------------------------------------------------

/// Checks that `r` contains the exact value `t` known as `s = RN(t)` plus the
/// sign `dir` of `t - s`.
fn contains_dir(r: Interval, s: f64, dir: f64) -> bool {
    let lo_ok = r.lo() < s || (r.lo() == s && dir >= 0.0);
    let hi_ok = r.hi() > s || (r.hi() == s && dir <= 0.0);
    lo_ok && hi_ok
}

const SAFE: f64 = 1e-270;

fn check_add(r: Interval, x: f64, y: f64) -> bool {
    let s = x + y;
    if !s.is_finite() {
        return r.contains(s);
    }
    let bb = s - x;
    let e = (x - (s - bb)) + (y - bb);
    if !e.is_finite() {
        return r.contains(s);
    }
    contains_dir(r, s, e)
}

fn check_mul(r: Interval, x: f64, y: f64) -> bool {
    let p = x * y;
    if x == 0.0 || y == 0.0 {
        return r.contains(0.0);
    }
    if !p.is_finite() || p.abs() < SAFE {
        return r.contains(p);
    }
    contains_dir(r, p, x.mul_add(y, -p))
}

fn check_div(r: Interval, x: f64, y: f64) -> bool {
    let q = x / y;
    if x == 0.0 {
        return r.contains(0.0);
    }
    if !q.is_finite() || x.abs() < SAFE || q.abs() < SAFE || y.abs() < SAFE {
        return r.contains(q);
    }
    let rem = (-q).mul_add(y, x);
    contains_dir(r, q, if y > 0.0 { rem } else { -rem })
}

fn check_sqrt(r: Interval, x: f64) -> bool {
    let q = x.sqrt();
    if x < SAFE {
        return r.contains(q);
    }
    contains_dir(r, q, (-q).mul_add(q, x))
}

/// Double-double product.
fn dd_mul((ah, al): (f64, f64), (bh, bl): (f64, f64)) -> (f64, f64) {
    let p = ah * bh;
    let e = ah.mul_add(bh, -p);
    let t = e + (ah * bl + al * bh);
    let s = p + t;
    (s, t - (s - p))
}

/// `RN(x^n)` (up to negligible double-double error) for moderate `x`, `n`.
fn powi_oracle(x: f64, n: i32) -> f64 {
    let mut acc = (1.0, 0.0);
    for _ in 0..n.unsigned_abs() {
        acc = dd_mul(acc, (x, 0.0));
    }
    if n >= 0 {
        acc.0 + acc.1
    } else {
        let (h, l) = acc;
        let q = 1.0 / h;
        let r = (-q).mul_add(h, 1.0);
        q + (r - q * l) / h
    }
}

fn well_formed(r: Interval) -> bool {
    !r.lo().is_nan() && !r.hi().is_nan() && r.lo() <= r.hi()
}

// ---------------------------------------------------------------------------
// Properties
// ---------------------------------------------------------------------------

macro_rules! unary_std {
    ($name:ident, $method:ident, $reference:expr) => {
        proptest! {
            #[test]
            fn $name(i in interval(), p in pick()) {
                let r = i.$method();
                prop_assert!(well_formed(r));
                if let Some(x) = point_in(i, p) {
                    let fx: Option<f64> = $reference(x);
                    if let Some(fx) = fx {
                        prop_assert!(r.contains(fx), "{}({}) = {} not in {}({}) = {}",
                            stringify!($method), x, fx, stringify!($method), i, r);
                    }
                }
            }
        }
    };
}

unary_std!(prop_exp, exp, |x: f64| Some(x.exp()));
unary_std!(prop_ln, ln, |x: f64| (x > 0.0).then(|| x.ln()));
unary_std!(prop_sin, sin, |x: f64| Some(x.sin()));
unary_std!(prop_cos, cos, |x: f64| Some(x.cos()));
unary_std!(prop_tan, tan, |x: f64| Some(x.tan()));
unary_std!(prop_atan, atan, |x: f64| Some(x.atan()));
unary_std!(prop_sinh, sinh, |x: f64| Some(x.sinh()));
unary_std!(prop_cosh, cosh, |x: f64| Some(x.cosh()));
unary_std!(prop_tanh, tanh, |x: f64| Some(x.tanh()));
unary_std!(prop_abs, abs, |x: f64| Some(x.abs()));
unary_std!(prop_sign, sign, |x: f64| Some(if x == 0.0 {
    0.0
} else {
    x.signum()
}));
unary_std!(prop_sinc, sinc, |x: f64| Some(if x == 0.0 {
    1.0
} else {
    x.sin() / x
}));
unary_std!(prop_recip, recip, |x: f64| (x != 0.0).then(|| 1.0 / x));

proptest! {
    #[test]
    fn prop_add_sub(a in interval(), b in interval(), p in pick(), q in pick()) {
        let s = a + b;
        let d = a - b;
        prop_assert!(well_formed(s) && well_formed(d));
        if let (Some(x), Some(y)) = (point_in(a, p), point_in(b, q)) {
            prop_assert!(check_add(s, x, y), "{x} + {y} not in {a} + {b} = {s}");
            prop_assert!(check_add(d, x, -y), "{x} - {y} not in {a} - {b} = {d}");
            prop_assert!(check_add(a + y, x, y));
            prop_assert!(check_add(x - b, x, -y));
        }
    }

    #[test]
    fn prop_mul(a in interval(), b in interval(), p in pick(), q in pick()) {
        let m = a * b;
        prop_assert!(well_formed(m));
        if let (Some(x), Some(y)) = (point_in(a, p), point_in(b, q)) {
            prop_assert!(check_mul(m, x, y), "{x} * {y} not in {a} * {b} = {m}");
            prop_assert!(check_mul(a * y, x, y));
        }
    }

    #[test]
    fn prop_div(a in interval(), b in interval(), p in pick(), q in pick()) {
        let d = a / b;
        prop_assert!(well_formed(d));
        if let (Some(x), Some(y)) = (point_in(a, p), point_in(b, q)) {
            if y != 0.0 {
                prop_assert!(check_div(d, x, y), "{x} / {y} not in {a} / {b} = {d}");
                prop_assert!(check_div(x / b, x, y));
            }
        }
    }

    #[test]
    fn prop_point_arith_is_tight(x in finite(), y in finite()) {
        // Point arithmetic is within one ulp of the nearest result.
        let (px, py) = (Interval::point(x), Interval::point(y));
        for (r, n) in [(px + py, x + y), (px * py, x * y), (px / py, x / y)] {
            if n.is_finite() && n != 0.0 && y != 0.0 {
                prop_assert!(r.lo() >= next_down(n) && r.hi() <= next_up(n), "{r} vs {n}");
            }
        }
    }

    #[test]
    fn prop_sqrt(i in interval(), p in pick()) {
        let r = i.sqrt();
        prop_assert!(well_formed(r));
        if let Some(x) = point_in(i, p) {
            if x >= 0.0 {
                prop_assert!(check_sqrt(r, x), "sqrt({x}) not in sqrt({i}) = {r}");
            }
        }
    }

    #[test]
    fn prop_sqr(i in interval(), p in pick()) {
        let r = i.sqr();
        prop_assert!(well_formed(r) && r.lo() >= 0.0);
        if let Some(x) = point_in(i, p) {
            prop_assert!(check_mul(r, x, x), "{x}^2 not in sqr({i}) = {r}");
        }
    }

    #[test]
    fn prop_powi(lo in -50.0..50.0f64, w in prop_oneof![Just(0.0), 0.0..1e-6f64, 0.0..20.0f64],
                 n in -12i32..=12, u in 0.0..=1.0f64) {
        let i = Interval::new(lo, lo + w);
        let r = i.powi(n);
        prop_assert!(well_formed(r));
        let x = (lo + u * w).min(i.hi());
        if x != 0.0 && x.abs() > 1e-5 {
            let v = powi_oracle(x, n);
            prop_assert!(r.contains(v), "{x}^{n} = {v} not in {i}^{n} = {r}");
        }
        if x == 0.0 && n > 0 {
            prop_assert!(r.contains(0.0));
        }
        if n % 2 == 0 {
            prop_assert!(r.lo() >= 0.0);
        }
    }

    #[test]
    fn prop_powi_wild(i in interval(), n in -40i32..=40, p in pick()) {
        let r = i.powi(n);
        prop_assert!(well_formed(r));
        if let Some(x) = point_in(i, p) {
            // The rounded-to-nearest repeated product is not an exact oracle;
            // only check values far from under/overflow where it is within a
            // few ulps, against a widened result.
            let v = x.powi(n);
            if v.is_finite() && v.abs() > 1e-200 && v.abs() < 1e200 && x != 0.0 {
                let rel = 64.0 * f64::EPSILON * v.abs();
                prop_assert!(r.lo() - rel <= v && v <= r.hi() + rel, "{x}^{n}={v} vs {r}");
            }
        }
    }

    #[test]
    fn prop_pow(i in interval(), j in interval(), p in pick(), q in pick()) {
        let r = i.pow(j);
        prop_assert!(well_formed(r));
        if let (Some(x), Some(y)) = (point_in(i, p), point_in(j, q)) {
            if x > 0.0 || (x == 0.0 && y > 0.0) {
                let v = x.powf(y);
                prop_assert!(r.contains(v), "{x}^{y} = {v} not in {i}^{j} = {r}");
            }
        }
    }

    #[test]
    fn prop_atan2(a in interval(), b in interval(), p in pick(), q in pick()) {
        let r = a.atan2(b);
        prop_assert!(well_formed(r));
        prop_assert!(r.lo() >= -3.1415926535897936 && r.hi() <= 3.1415926535897936);
        if let (Some(y), Some(x)) = (point_in(a, p), point_in(b, q)) {
            if !(x == 0.0 && y == 0.0) {
                let v = y.atan2(x);
                prop_assert!(r.contains(v), "atan2({y}, {x}) = {v} not in atan2({a}, {b}) = {r}");
            }
        }
    }

    #[test]
    fn prop_min_max_hull(a in interval(), b in interval(), p in pick(), q in pick()) {
        let (mn, mx, h) = (a.min(b), a.max(b), a.hull(b));
        prop_assert!(well_formed(mn) && well_formed(mx) && well_formed(h));
        prop_assert!(a.subset_of(h) && b.subset_of(h));
        if let (Some(x), Some(y)) = (point_in(a, p), point_in(b, q)) {
            prop_assert!(mn.contains(x.min(y)) && mx.contains(x.max(y)));
            if let Some(k) = a.intersect(b) {
                prop_assert!(k.subset_of(a) && k.subset_of(b));
            } else {
                prop_assert!(x != y);
            }
        }
    }

    #[test]
    fn prop_accessors(i in interval(), p in pick()) {
        let m = i.mid();
        prop_assert!(i.contains(m) || (i.is_point() && i.lo().is_infinite()));
        prop_assert!(i.width() >= 0.0 && i.rad() >= 0.0);
        prop_assert!(i.mig() <= i.mag());
        if let Some(x) = point_in(i, p) {
            prop_assert!(i.mig() <= x.abs() && x.abs() <= i.mag());
            // |x - mid| <= rad, checked exactly via directed bounds
            let d = Interval::point(x) - Interval::point(m);
            prop_assert!(d.abs().lo() <= i.rad());
            let w = Interval::point(i.hi()) - Interval::point(i.lo());
            prop_assert!(w.lo() <= i.width());
        }
    }

    #[test]
    fn prop_scalar_ops_match(i in interval(), c in finite()) {
        let pc = Interval::point(c);
        prop_assert_eq!(i + c, i + pc);
        prop_assert_eq!(i - c, i - pc);
        prop_assert_eq!(i * c, i * pc);
        prop_assert_eq!(i / c, i / pc);
        prop_assert_eq!(c + i, pc + i);
        prop_assert_eq!(c / i, pc / i);
        prop_assert_eq!(-(-i), i);
    }
}
