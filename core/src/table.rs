//! Tabulated signals: piecewise-linear interpolation of sampled columns, shared by the
//! compiler's IR interpreter and generated code (which embeds each column as a `static` array).
//!
//! A signal is given by its sample times `times` (finite, strictly increasing, at least 2) and
//! its values `values` (finite, `values.len() == times.len()`). It is linearly interpolated in
//! between and held constant outside `[times[0], times[last]]`.

use crate::interval::Interval;

/// `(min, max)` of a column's values: the range of the signal over all times.
pub fn column_range(values: &[f64]) -> (f64, f64) {
    values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        })
}

/// The segment `[times[i], times[i + 1]]` holding `t`, for `times[0] < t < times[last]`.
fn segment(times: &[f64], t: f64) -> usize {
    times.partition_point(|&x| x <= t) - 1
}

/// Interpolation on segment `i` (exact at the knots).
fn interp(times: &[f64], values: &[f64], i: usize, t: f64) -> f64 {
    let (t0, t1) = (times[i], times[i + 1]);
    let (v0, v1) = (values[i], values[i + 1]);
    v0 + (v1 - v0) * ((t - t0) / (t1 - t0))
}

/// The signal at time `t` (NaN for NaN).
pub fn eval(times: &[f64], values: &[f64], t: f64) -> f64 {
    let last = times.len() - 1;
    if t.is_nan() {
        f64::NAN
    } else if t <= times[0] {
        values[0]
    } else if t >= times[last] {
        values[last]
    } else {
        interp(times, values, segment(times, t), t)
    }
}

/// Encloses the exact (real-arithmetic) interpolated value at `t`.
///
/// The computed `v0 + (v1 - v0) * ((t - t0)/(t1 - t0))` is within `6.01 eps (|v0| + |v1|)` of
/// the exact value (five relative roundings on the product, one on the sum); we widen by
/// `8 eps (|v0| + |v1|)` plus a tiny absolute term for underflow, round outward, and clamp to
/// `[min(v0, v1), max(v0, v1)]`, which holds the exact value.
fn enclose_at(times: &[f64], values: &[f64], t: f64) -> (f64, f64) {
    let last = times.len() - 1;
    if t <= times[0] {
        return (values[0], values[0]);
    }
    if t >= times[last] {
        return (values[last], values[last]);
    }
    let i = segment(times, t);
    if t == times[i] {
        return (values[i], values[i]);
    }
    let (v0, v1) = (values[i], values[i + 1]);
    let c = interp(times, values, i, t);
    let err = 8.0 * f64::EPSILON * (v0.abs() + v1.abs()) + 1e-300;
    let lo = f64::next_down(c - err).max(v0.min(v1));
    let hi = f64::next_up(c + err).min(v0.max(v1));
    (lo, hi)
}

/// `(lo, hi)` enclosing the signal over all times in `[t_lo, t_hi]`: the hull of the values at
/// both ends and at the knots in between (a piecewise-linear function attains its extremes
/// there), rounded outward. A NaN bound or `t_lo > t_hi` gives the column's range.
pub fn eval_range(times: &[f64], values: &[f64], t_lo: f64, t_hi: f64) -> (f64, f64) {
    if t_lo.is_nan() || t_hi.is_nan() || t_lo > t_hi {
        return column_range(values);
    }
    let (mut lo, mut hi) = enclose_at(times, values, t_lo);
    let (a, b) = enclose_at(times, values, t_hi);
    lo = lo.min(a);
    hi = hi.max(b);
    let start = times.partition_point(|&x| x <= t_lo);
    let end = times.partition_point(|&x| x < t_hi);
    for &v in values.get(start..end).unwrap_or(&[]) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    (lo, hi)
}

/// Encloses the signal over the time interval `t` (see [`eval_range`]).
pub fn eval_interval(times: &[f64], values: &[f64], t: Interval) -> Interval {
    let (lo, hi) = eval_range(times, values, t.lo(), t.hi());
    Interval::new(lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng::XorShift64;

    const TIMES: [f64; 5] = [0.0, 0.1, 0.3, 1.0, 2.5];
    const A: [f64; 5] = [1.0, 3.0, -1.0, 0.7, 0.7];
    const B: [f64; 5] = [0.1, 0.2, 0.3, 1e300, -1e-300];

    #[test]
    fn interpolation() {
        let f = |t| eval(&TIMES, &A, t);
        assert_eq!(f(-5.0), 1.0);
        assert_eq!(f(0.0), 1.0);
        assert_eq!(f(0.05), 2.0);
        assert_eq!(f(0.1), 3.0);
        assert!((f(0.2) - 1.0).abs() < 1e-15);
        assert_eq!(f(0.3), -1.0);
        assert_eq!(f(2.0), 0.7);
        assert_eq!(f(7.0), 0.7);
        assert!(f(f64::NAN).is_nan());
        assert_eq!(column_range(&A), (-1.0, 3.0));
    }

    #[test]
    fn ranges() {
        let r = |a, b| eval_range(&TIMES, &A, a, b);
        assert_eq!(r(-1.0, 0.0), (1.0, 1.0));
        assert_eq!(r(0.0, 0.3), (-1.0, 3.0));
        assert_eq!(r(1.0, 9.0), (0.7, 0.7));
        assert_eq!(r(f64::NEG_INFINITY, f64::INFINITY), (-1.0, 3.0));
        assert_eq!(r(f64::NAN, 1.0), (-1.0, 3.0));
        assert_eq!(r(2.0, 1.0), (-1.0, 3.0));
        let (lo, hi) = r(0.02, 0.05);
        assert!((1.39..=1.4).contains(&lo) && (2.0..2.01).contains(&hi));
        let i = eval_interval(&TIMES, &A, Interval::new(0.15, 0.25));
        assert!(i.contains(2.0) && i.contains(0.0) && i.hi() < 2.001 && i.lo() > -0.001);
    }

    /// The enclosure over `[a, b]` contains the interpolated values at points inside.
    #[test]
    fn ranges_contain_sampled_values() {
        let times = [0.0, 0.3, 0.7, 1.1];
        let values = [0.1, -2.7, 1e-3, 123.456];
        let mut rng = XorShift64(12345);
        for _ in 0..20000 {
            let s = rng.next_u64();
            let a = (s % 1_000_000) as f64 / 1_000_000.0 * 1.2 - 0.05;
            let b = a + ((s >> 20) % 1000) as f64 / 3000.0;
            let (lo, hi) = eval_range(&times, &values, a, b);
            for k in 0..=8 {
                let x = (a + (b - a) * k as f64 / 8.0).min(b);
                let v = eval(&times, &values, x);
                assert!(
                    lo <= v && v <= hi,
                    "[{a}, {b}] -> [{lo}, {hi}] misses {v} at {x}"
                );
            }
        }
    }

    #[test]
    fn extreme_values_do_not_overflow() {
        let (lo, hi) = eval_range(&TIMES, &B, 0.5, 2.0);
        assert!(lo.is_finite() && hi == 1e300 && lo <= eval(&TIMES, &B, 2.0));
        let (lo, hi) = eval_range(&TIMES, &B, 0.29, 0.31);
        assert!(lo < 0.3 && hi > 0.3);
    }
}
