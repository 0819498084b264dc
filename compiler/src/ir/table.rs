//! Tabulated signals: piecewise-linear functions of time.

use reachc_runtime::interval::Interval;

/// A table of signals sampled at increasing times, linearly interpolated in between and held
/// constant outside `[times[0], times[last]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// The table's name in the spec.
    pub name: String,
    /// Column names, without the time column.
    pub columns: Vec<String>,
    /// Sample times: finite, strictly increasing, at least 2.
    pub times: Vec<f64>,
    /// `values[column][row]`, finite.
    pub values: Vec<Vec<f64>>,
}

impl Table {
    /// The index of the column called `name`.
    pub fn column_index(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// `(min, max)` of a column's values: the range of the signal over all times.
    pub fn column_range(&self, column: usize) -> (f64, f64) {
        self.values[column]
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            })
    }

    /// The segment `[times[i], times[i + 1]]` holding `t`, for `times[0] < t < times[last]`.
    fn segment(&self, t: f64) -> usize {
        self.times.partition_point(|&x| x <= t) - 1
    }

    /// Interpolation on segment `i` (exact at the knots).
    fn interp(&self, column: usize, i: usize, t: f64) -> f64 {
        let (t0, t1) = (self.times[i], self.times[i + 1]);
        let (v0, v1) = (self.values[column][i], self.values[column][i + 1]);
        v0 + (v1 - v0) * ((t - t0) / (t1 - t0))
    }

    /// The signal `column` at time `t` (NaN for NaN).
    pub fn eval_f64(&self, column: usize, t: f64) -> f64 {
        let vs = &self.values[column];
        let last = self.times.len() - 1;
        if t.is_nan() {
            f64::NAN
        } else if t <= self.times[0] {
            vs[0]
        } else if t >= self.times[last] {
            vs[last]
        } else {
            self.interp(column, self.segment(t), t)
        }
    }

    /// Encloses the exact (real-arithmetic) interpolated value at `t`.
    ///
    /// The computed `v0 + (v1 - v0) * ((t - t0)/(t1 - t0))` is within
    /// `6.01 eps (|v0| + |v1|)` of the exact value (five relative roundings on the product, one
    /// on the sum); we widen by `8 eps (|v0| + |v1|)` plus a tiny absolute term for underflow,
    /// round outward, and clamp to `[min(v0, v1), max(v0, v1)]`, which holds the exact value.
    fn enclose_at(&self, column: usize, t: f64) -> (f64, f64) {
        let last = self.times.len() - 1;
        let vs = &self.values[column];
        if t <= self.times[0] {
            return (vs[0], vs[0]);
        }
        if t >= self.times[last] {
            return (vs[last], vs[last]);
        }
        let i = self.segment(t);
        if t == self.times[i] {
            return (vs[i], vs[i]);
        }
        let (v0, v1) = (vs[i], vs[i + 1]);
        let c = self.interp(column, i, t);
        let err = 8.0 * f64::EPSILON * (v0.abs() + v1.abs()) + 1e-300;
        let lo = f64::next_down(c - err).max(v0.min(v1));
        let hi = f64::next_up(c + err).min(v0.max(v1));
        (lo, hi)
    }

    /// `(lo, hi)` enclosing the signal `column` over all times in `[t_lo, t_hi]`: the hull of the
    /// values at both ends and at the knots in between (a piecewise-linear function attains its
    /// extremes there), rounded outward. A NaN bound or `t_lo > t_hi` gives the column's range.
    pub fn eval_range(&self, column: usize, t_lo: f64, t_hi: f64) -> (f64, f64) {
        if t_lo.is_nan() || t_hi.is_nan() || t_lo > t_hi {
            return self.column_range(column);
        }
        let (mut lo, mut hi) = self.enclose_at(column, t_lo);
        let (a, b) = self.enclose_at(column, t_hi);
        lo = lo.min(a);
        hi = hi.max(b);
        let start = self.times.partition_point(|&x| x <= t_lo);
        let end = self.times.partition_point(|&x| x < t_hi);
        for &v in self.values[column].get(start..end).unwrap_or(&[]) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        (lo, hi)
    }

    /// Encloses the signal `column` over the time interval `t` (see [`Table::eval_range`]).
    pub fn eval_interval(&self, column: usize, t: Interval) -> Interval {
        let (lo, hi) = self.eval_range(column, t.lo(), t.hi());
        Interval::new(lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tab() -> Table {
        Table {
            name: "wind".into(),
            columns: vec!["a".into(), "b".into()],
            times: vec![0.0, 0.1, 0.3, 1.0, 2.5],
            values: vec![
                vec![1.0, 3.0, -1.0, 0.7, 0.7],
                vec![0.1, 0.2, 0.3, 1e300, -1e-300],
            ],
        }
    }

    #[test]
    fn interpolation() {
        let t = tab();
        assert_eq!(t.eval_f64(0, -5.0), 1.0);
        assert_eq!(t.eval_f64(0, 0.0), 1.0);
        assert_eq!(t.eval_f64(0, 0.05), 2.0);
        assert_eq!(t.eval_f64(0, 0.1), 3.0);
        assert!((t.eval_f64(0, 0.2) - 1.0).abs() < 1e-15);
        assert_eq!(t.eval_f64(0, 0.3), -1.0);
        assert_eq!(t.eval_f64(0, 2.0), 0.7);
        assert_eq!(t.eval_f64(0, 7.0), 0.7);
        assert!(t.eval_f64(0, f64::NAN).is_nan());
        assert_eq!(t.column_range(0), (-1.0, 3.0));
        assert_eq!(t.column_index("b"), Some(1));
        assert_eq!(t.column_index("c"), None);
    }

    #[test]
    fn ranges() {
        let t = tab();
        assert_eq!(t.eval_range(0, -1.0, 0.0), (1.0, 1.0));
        assert_eq!(t.eval_range(0, 0.0, 0.3), (-1.0, 3.0));
        assert_eq!(t.eval_range(0, 1.0, 9.0), (0.7, 0.7));
        assert_eq!(
            t.eval_range(0, f64::NEG_INFINITY, f64::INFINITY),
            (-1.0, 3.0)
        );
        let (lo, hi) = t.eval_range(0, 0.02, 0.05);
        assert!((1.39..=1.4).contains(&lo) && (2.0..2.01).contains(&hi));
        let i = t.eval_interval(0, Interval::new(0.15, 0.25));
        assert!(i.contains(2.0) && i.contains(0.0) && i.hi() < 2.001 && i.lo() > -0.001);
    }

    /// The enclosure over `[a, b]` contains the interpolated values at points inside.
    #[test]
    fn ranges_contain_sampled_values() {
        let t = Table {
            name: "s".into(),
            columns: vec!["a".into()],
            times: vec![0.0, 0.3, 0.7, 1.1],
            values: vec![vec![0.1, -2.7, 1e-3, 123.456]],
        };
        let mut s: u64 = 12345;
        for _ in 0..20000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let a = (s % 1_000_000) as f64 / 1_000_000.0 * 1.2 - 0.05;
            let b = a + ((s >> 20) % 1000) as f64 / 3000.0;
            let (lo, hi) = t.eval_range(0, a, b);
            for k in 0..=8 {
                let x = (a + (b - a) * k as f64 / 8.0).min(b);
                let v = t.eval_f64(0, x);
                assert!(
                    lo <= v && v <= hi,
                    "[{a}, {b}] -> [{lo}, {hi}] misses {v} at {x}"
                );
            }
        }
    }

    #[test]
    fn extreme_values_do_not_overflow() {
        let t = tab();
        let (lo, hi) = t.eval_range(1, 0.5, 2.0);
        assert!(lo.is_finite() && hi == 1e300 && lo <= t.eval_f64(1, 2.0));
        let (lo, hi) = t.eval_range(1, 0.29, 0.31);
        assert!(lo < 0.3 && hi > 0.3);
    }
}
