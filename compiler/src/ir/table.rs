//! Tabulated signals: piecewise-linear functions of time.

use reachc_core::interval::Interval;
use reachc_core::table;

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
        table::column_range(&self.values[column])
    }

    /// The signal `column` at time `t` (NaN for NaN); see [`reachc_core::table::eval`].
    pub fn eval_f64(&self, column: usize, t: f64) -> f64 {
        table::eval(&self.times, &self.values[column], t)
    }

    /// `(lo, hi)` enclosing the signal `column` over all times in `[t_lo, t_hi]`, rounded
    /// outward; see [`reachc_core::table::eval_range`].
    pub fn eval_range(&self, column: usize, t_lo: f64, t_hi: f64) -> (f64, f64) {
        table::eval_range(&self.times, &self.values[column], t_lo, t_hi)
    }

    /// Encloses the signal `column` over the time interval `t` (see [`Table::eval_range`]).
    pub fn eval_interval(&self, column: usize, t: Interval) -> Interval {
        table::eval_interval(&self.times, &self.values[column], t)
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
}
