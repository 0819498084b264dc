//! Dense interval matrices and a certified positive-semidefiniteness test (interval LDL').
//!
//! Every constant of Assumption 1 is certified the same way (method.md section 3): a float
//! estimate `x` is accepted only if a matrix `Q(x)` (e.g. `2cP - A'P - PA`), computed entry by
//! entry in outward-rounded [`Interval`] arithmetic, passes [`is_psd`]. Interval LDL' succeeds only
//! if every real symmetric matrix inside the interval matrix is positive semidefinite, so the
//! accepted `x` is a bound for the exact matrices, whatever the float estimate's error was.

use reachc_core::interval::Interval;

/// A dense `rows x cols` matrix of intervals, row-major.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct IMat {
    pub rows: usize,
    pub cols: usize,
    pub data: Vec<Interval>,
}

/// Whether `x` is the point interval `[0, 0]` (then it is zero for every member of a set).
pub(crate) fn is_zero(x: Interval) -> bool {
    x.lo() == 0.0 && x.hi() == 0.0
}

impl IMat {
    /// The zero matrix.
    pub fn zeros(rows: usize, cols: usize) -> IMat {
        IMat {
            rows,
            cols,
            data: vec![Interval::ZERO; rows * cols],
        }
    }

    /// Point intervals of a row-major float matrix.
    pub fn from_f64(rows: usize, cols: usize, values: &[f64]) -> IMat {
        debug_assert_eq!(values.len(), rows * cols);
        IMat {
            rows,
            cols,
            data: values.iter().map(|&v| Interval::point(v)).collect(),
        }
    }

    /// Entry `(i, j)`.
    pub fn at(&self, i: usize, j: usize) -> Interval {
        self.data[i * self.cols + j]
    }

    /// Mutable entry `(i, j)`.
    pub fn at_mut(&mut self, i: usize, j: usize) -> &mut Interval {
        &mut self.data[i * self.cols + j]
    }

    /// The transpose.
    pub fn transpose(&self) -> IMat {
        let mut t = IMat::zeros(self.cols, self.rows);
        for i in 0..self.rows {
            for j in 0..self.cols {
                *t.at_mut(j, i) = self.at(i, j);
            }
        }
        t
    }

    /// Midpoints, row-major (for float estimates only).
    pub fn mid(&self) -> Vec<f64> {
        self.data.iter().map(|x| x.mid()).collect()
    }

    /// `self * other`, skipping exact zeros: Jacobians of large models are sparse, and a dense
    /// product of two 1000 x 1000 interval matrices would take seconds.
    pub fn mul(&self, other: &IMat) -> IMat {
        assert_eq!(self.cols, other.rows);
        let nonzero_cols: Vec<Vec<usize>> = (0..other.rows)
            .map(|k| {
                (0..other.cols)
                    .filter(|&j| !is_zero(other.at(k, j)))
                    .collect()
            })
            .collect();
        let mut out = IMat::zeros(self.rows, other.cols);
        for i in 0..self.rows {
            for (k, cols) in nonzero_cols.iter().enumerate() {
                let a = self.at(i, k);
                if is_zero(a) {
                    continue;
                }
                for &j in cols {
                    let c = out.at_mut(i, j);
                    *c += a * other.at(k, j);
                }
            }
        }
        out
    }

    /// `self + other`.
    pub fn add(&self, other: &IMat) -> IMat {
        assert_eq!((self.rows, self.cols), (other.rows, other.cols));
        IMat {
            rows: self.rows,
            cols: self.cols,
            data: self
                .data
                .iter()
                .zip(&other.data)
                .map(|(&a, &b)| a + b)
                .collect(),
        }
    }
}

/// The first column holding a possibly non-zero entry, per row of the lower triangle of the
/// union of the patterns of `mats` (all square, same size).
fn envelope(mats: &[&IMat]) -> Vec<usize> {
    let n = mats[0].rows;
    (0..n)
        .map(|i| {
            (0..i)
                .find(|&j| mats.iter().any(|m| !is_zero(m.at(i, j))))
                .unwrap_or(i)
        })
        .collect()
}

/// Envelope (skyline) storage of the lower triangle: row `i` holds columns `first[i]..=i`.
/// Fill-in of LDL' stays inside each row's envelope, so banded matrices cost `O(n b^2)` in time
/// and `O(n b)` in memory, not `O(n^3)` and `O(n^2)`.
#[derive(Clone, Debug)]
struct Skyline {
    first: Vec<usize>,
    start: Vec<usize>,
}

impl Skyline {
    fn new(first: Vec<usize>) -> Skyline {
        let mut start = Vec::with_capacity(first.len() + 1);
        let mut offset = 0;
        for (i, &f) in first.iter().enumerate() {
            start.push(offset);
            offset += i + 1 - f;
        }
        start.push(offset);
        Skyline { first, start }
    }

    fn index(&self, i: usize, j: usize) -> usize {
        self.start[i] + j - self.first[i]
    }

    fn gather(&self, m: &IMat) -> Vec<Interval> {
        let mut out = Vec::with_capacity(*self.start.last().unwrap());
        for (i, &f) in self.first.iter().enumerate() {
            out.extend((f..=i).map(|j| m.at(i, j)));
        }
        out
    }

    /// Whether every real symmetric matrix in the interval matrix `q` (in this storage) is PSD
    /// (PD if `strict`); `q` is overwritten by the factorisation.
    ///
    /// Row-oriented interval LDL' storing `W = L D` (not `L`): the updates are
    /// `q_ij - sum_k w_ik w_jk / d_k` and `d_i = q_ii - sum_k w_ik^2 / d_k`, in which every
    /// computed interval appears once. The form `l_ik^2 d_k` (with `l = w / d`) uses `d_k`
    /// twice, and on long near-singular chains that dependency makes the widths grow
    /// geometrically (the 1000-state chain lost 7% of its bound that way).
    fn ldl_psd(&self, q: &mut [Interval], strict: bool) -> bool {
        let n = self.first.len();
        // `1 / d_k`, or `None` for an accepted exactly-zero pivot.
        let mut inv_d: Vec<Option<Interval>> = vec![None; n];
        for i in 0..n {
            let fi = self.first[i];
            for j in fi..i {
                let fj = self.first[j];
                let mut w = q[self.index(i, j)];
                for k in fi.max(fj)..j {
                    if let Some(r) = inv_d[k] {
                        w -= q[self.index(i, k)] * q[self.index(j, k)] * r;
                    }
                }
                if inv_d[j].is_none() && !is_zero(w) {
                    // Zero pivot `j` with a non-zero entry below it: indefinite (or unknown).
                    return false;
                }
                q[self.index(i, j)] = w;
            }
            let mut d = q[self.index(i, i)];
            for k in fi..i {
                if let Some(r) = inv_d[k] {
                    d -= q[self.index(i, k)].sqr() * r;
                }
            }
            if d.lo() > 0.0 {
                inv_d[i] = Some(d.recip());
            } else if strict || !is_zero(d) {
                return false;
            }
        }
        true
    }
}

/// Whether every real symmetric matrix in the (square) interval matrix `q` is positive
/// semidefinite, or positive definite if `strict`. Only the lower triangle is read.
///
/// Interval LDL': each pivot must have a positive lower bound. An exactly zero pivot `[0, 0]`
/// is accepted (when not `strict`) only if the rest of its column is exactly zero as well: the
/// matrix is then PSD iff the trailing block is, for every member. This is what lets an exact
/// bound such as `c = -0.4` for `A = -0.4 I`, `P = I` pass (its `Q` is the zero matrix); any
/// pivot straddling zero fails, and the caller increases the constant.
pub(crate) fn is_psd(q: &IMat, strict: bool) -> bool {
    assert_eq!(q.rows, q.cols);
    if q.rows == 0 {
        return true;
    }
    let sky = Skyline::new(envelope(&[q]));
    let mut data = sky.gather(q);
    sky.ldl_psd(&mut data, strict)
}

/// The family `a X - S` (float `a`), prepared once for repeated PSD tests: `2cP - (A'P + PA)`
/// for `c`, `s2 I - G'PG` for `sigma^2`.
#[derive(Clone, Debug)]
pub(crate) struct Pencil {
    sky: Skyline,
    x: Vec<Interval>,
    s: Vec<Interval>,
}

impl Pencil {
    /// For square `s` and `x` of the same size.
    pub fn new(s: &IMat, x: &IMat) -> Pencil {
        assert_eq!((s.rows, s.cols), (x.rows, x.cols));
        let sky = Skyline::new(if s.rows == 0 {
            Vec::new()
        } else {
            envelope(&[s, x])
        });
        Pencil {
            x: sky.gather(x),
            s: sky.gather(s),
            sky,
        }
    }

    /// Whether `a X - S` is PSD for every `S` in the interval matrix `S` (see [`is_psd`]).
    pub fn psd_at(&self, a: f64) -> bool {
        let a = Interval::point(a);
        let mut q: Vec<Interval> = self
            .x
            .iter()
            .zip(&self.s)
            .map(|(&x, &s)| if is_zero(x) { -s } else { a * x - s })
            .collect();
        self.sky.ldl_psd(&mut q, false)
    }
}

/// The smallest float `x` (up to about two ulps of `scale`) such that `pass(x)`, searching
/// upward from the float estimate `guess`; `None` if nothing up to `guess + 1e30 * scale` passes.
///
/// `pass` must be (essentially) monotone: if `x` passes then larger values pass. The result
/// always passed, so it is as sound as the test itself; `guess` only affects the cost. Steps grow
/// geometrically from about one ulp of `scale`, then bisection tightens: an estimate that is off
/// by rounding costs a few tests, a crude lower bound (e.g. a Rayleigh quotient) about 60.
pub(crate) fn certify_min(
    guess: f64,
    scale: f64,
    mut pass: impl FnMut(f64) -> bool,
) -> Option<f64> {
    if !guess.is_finite() {
        return None;
    }
    if pass(guess) {
        return Some(guess);
    }
    let scale = scale.max(guess.abs()).max(1e-300);
    let unit = scale * f64::EPSILON;
    let mut lo = guess;
    let mut step = unit * 4.0;
    let mut hi = loop {
        let x = guess + step;
        if !x.is_finite() || step > scale * 1e30 {
            return None;
        }
        if pass(x) {
            break x;
        }
        lo = x;
        step *= 4.0;
    };
    for _ in 0..200 {
        if hi - lo <= unit * 2.0 {
            break;
        }
        let mid = lo + (hi - lo) / 2.0;
        if mid <= lo || mid >= hi {
            break;
        }
        if pass(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// An upper bound of `sqrt(x)` (outward-rounded).
pub(crate) fn sqrt_up(x: f64) -> f64 {
    Interval::point(x.max(0.0)).sqrt().hi()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(rows: usize, v: &[f64]) -> IMat {
        IMat::from_f64(rows, v.len() / rows, v)
    }

    #[test]
    fn psd_basic() {
        assert!(is_psd(&m(2, &[2.0, 1.0, 1.0, 2.0]), true));
        assert!(!is_psd(&m(2, &[1.0, 2.0, 2.0, 1.0]), false));
        // Singular PSD with an exactly computed zero pivot: accepted, but not as definite.
        assert!(is_psd(&m(2, &[1.0, 1.0, 1.0, 1.0]), false));
        assert!(!is_psd(&m(2, &[1.0, 1.0, 1.0, 1.0]), true));
        // Singular PSD whose zero pivot is not exact (1/3 rounds): rejected (conservative).
        assert!(!is_psd(&m(2, &[3.0, 1.0, 1.0, 1.0 / 3.0]), false));
        // Exact zeros are PSD, not PD.
        assert!(is_psd(&IMat::zeros(3, 3), false));
        assert!(!is_psd(&IMat::zeros(3, 3), true));
        // Zero pivot with a non-zero column: indefinite.
        assert!(!is_psd(&m(2, &[0.0, 1.0, 1.0, 1.0]), false));
        // Zero block then a positive block.
        assert!(is_psd(&m(2, &[0.0, 0.0, 0.0, 1.0]), false));
    }

    #[test]
    fn psd_interval_entries() {
        let mut q = m(2, &[2.0, 0.0, 0.0, 2.0]);
        *q.at_mut(1, 0) = Interval::new(-1.0, 1.0);
        *q.at_mut(0, 1) = Interval::new(-1.0, 1.0);
        assert!(is_psd(&q, true));
        *q.at_mut(1, 0) = Interval::new(-2.5, 1.0);
        assert!(!is_psd(&q, false));
    }

    #[test]
    fn certify_min_finds_threshold() {
        let t = 0.3;
        let x = certify_min(0.0, 1.0, |x| x >= t).unwrap();
        assert!(x >= t && x - t < 1e-15);
        assert_eq!(certify_min(0.5, 1.0, |x| x >= t), Some(0.5));
    }
}
