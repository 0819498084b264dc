//! The noise increment `G(x, t) dW` of an Euler-Maruyama step, using what the interval
//! enclosure of `G` proves about its structure.
//!
//! `System::diffusion_interval` over all states (`[-inf, inf]^n`) and `t` in `[0, horizon]`
//! encloses every value `G` can take. An entry whose enclosure is `[0, 0]` is identically zero
//! and skipped; when every entry's enclosure is a point (up to a few ulps), `G` is constant
//! (additive noise) and evaluated once instead of at every step. Both facts are proven by the
//! enclosure, not guessed from samples, so the simulated increments are those of the model.

use super::report::NoiseKind;
use crate::interval::Interval;
use crate::lanes::X8;
use crate::system::System;

/// The structure of `G` and how to apply it.
#[derive(Clone, Debug)]
pub(crate) struct Noise {
    m: usize,
    /// The entries not identically zero, by rows (compressed sparse rows): row `i` is
    /// `row[i]..row[i + 1]` of `cols` and `vals` (`vals` used only when constant).
    row: Vec<usize>,
    cols: Vec<usize>,
    vals: Vec<f64>,
    /// Constant `G`.
    constant: bool,
    /// Constant and diagonal (`m == n`, only `(i, i)` entries): its diagonal.
    diagonal: Option<Vec<f64>>,
}

impl Noise {
    /// Analyses `G` of `sys` for times in `[0, horizon]`; `x_ref` is any state (where a
    /// constant `G` is evaluated).
    pub(crate) fn new<S: System + ?Sized>(sys: &S, horizon: f64, x_ref: &[f64]) -> Self {
        let (n, m) = (sys.n(), sys.m());
        let mut enclosure = vec![Interval::ZERO; n * m];
        sys.diffusion_interval(
            &vec![Interval::ENTIRE; n],
            Interval::new(0.0, horizon),
            &mut enclosure,
        );
        let mut values = vec![0.0; n * m];
        sys.diffusion(x_ref, 0.0, &mut values);
        let constant = enclosure.iter().all(|e| {
            e.is_bounded() && e.width() <= 4.0 * f64::EPSILON * e.lo().abs().max(e.hi().abs())
        });
        let (mut row, mut cols, mut vals) = (vec![0], Vec::new(), Vec::new());
        for i in 0..n {
            for j in 0..m {
                let (e, v) = (enclosure[i * m + j], values[i * m + j]);
                let zero = e.lo() == 0.0 && e.hi() == 0.0;
                // Constant: the value itself says whether the entry is zero.
                if !(zero || constant && v == 0.0) {
                    cols.push(j);
                    vals.push(v);
                }
            }
            row.push(cols.len());
        }
        let diagonal =
            (constant && m == n && (0..n).all(|i| (row[i]..row[i + 1]).all(|k| cols[k] == i)))
                .then(|| {
                    (0..n)
                        .map(|i| {
                            if row[i + 1] > row[i] {
                                vals[row[i]]
                            } else {
                                0.0
                            }
                        })
                        .collect()
                });
        Noise {
            m,
            row,
            cols,
            vals,
            constant,
            diagonal,
        }
    }

    /// For the report.
    pub(crate) fn describe(&self) -> NoiseKind {
        match (self.constant, &self.diagonal) {
            (true, Some(_)) => NoiseKind::AdditiveDiagonal,
            (true, None) => NoiseKind::Additive {
                entries: self.cols.len(),
            },
            (false, _) => NoiseKind::StateDependent {
                entries: self.cols.len(),
            },
        }
    }

    /// Whether `G` is evaluated at every step (then [`apply`](Self::apply) needs `g` of n x m).
    pub(crate) fn needs_matrix(&self) -> bool {
        !self.constant
    }

    /// The diagonal of a constant diagonal `G` (then `m == n` and state `i` gets channel `i`).
    pub(crate) fn diagonal(&self) -> Option<&[f64]> {
        self.diagonal.as_deref()
    }

    /// [`apply`](Self::apply) on eight paths in lanes (`x`, `f`: state `i` of path `l` in
    /// lane `l` of entry `i`; `z`: the `m` channels' normals, likewise; `g`: scratch of `n * m`
    /// when [`needs_matrix`](Self::needs_matrix), filled by [`System::diffusion_x8`]): the same
    /// IEEE operations in the same order per lane, so the same states to the bit.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)] // as `apply`
    pub(crate) fn apply_x8<S: System + ?Sized>(
        &self,
        sys: &S,
        x: &mut [X8],
        f: &[X8],
        t: f64,
        h: f64,
        sqrt_h: f64,
        z: &mut [X8],
        g: &mut [X8],
    ) {
        if let Some(d) = &self.diagonal {
            for i in 0..x.len() {
                x[i] = x[i] + (f[i] * h + d[i] * sqrt_h * z[i]);
            }
            return;
        }
        for zj in z.iter_mut().take(self.m) {
            *zj = *zj * sqrt_h;
        }
        if !self.constant {
            sys.diffusion_x8(x, t, g);
        }
        for i in 0..x.len() {
            let mut dx = f[i] * h;
            for k in self.row[i]..self.row[i + 1] {
                let j = self.cols[k];
                let gij = if self.constant {
                    X8::splat(self.vals[k])
                } else {
                    g[i * self.m + j]
                };
                dx = dx + gij * z[j];
            }
            x[i] = x[i] + dx;
        }
    }

    /// The Euler-Maruyama update `x += f h + G(x, t) sqrt(h) z` given the drift `f` at `x` and
    /// `m` standard normal draws `z` (in channel order). `z` is overwritten (scaled by
    /// `sqrt_h = sqrt(h)`); `g` is scratch of `n * m` when [`needs_matrix`](Self::needs_matrix).
    ///
    /// Every loop reads `f` and writes `x` one element at a time, fused row by row: the drift
    /// was just stored element by element, and a vector load of those fresh stores would stall
    /// on store forwarding (measured: a quarter of the step time for n = 2).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)] // all scratch and state of the hot loop, no allocation
    pub(crate) fn apply<S: System + ?Sized>(
        &self,
        sys: &S,
        x: &mut [f64],
        f: &[f64],
        t: f64,
        h: f64,
        sqrt_h: f64,
        z: &mut [f64],
        g: &mut [f64],
    ) {
        if let Some(d) = &self.diagonal {
            let (d, f, z) = (&d[..x.len()], &f[..x.len()], &z[..x.len()]);
            for i in 0..x.len() {
                x[i] += f[i] * h + d[i] * sqrt_h * z[i];
            }
            return;
        }
        for zj in z.iter_mut().take(self.m) {
            *zj *= sqrt_h;
        }
        if !self.constant {
            sys.diffusion(x, t, g);
        }
        for i in 0..x.len() {
            let mut dx = f[i] * h;
            for k in self.row[i]..self.row[i + 1] {
                let j = self.cols[k];
                let gij = if self.constant {
                    self.vals[k]
                } else {
                    g[i * self.m + j]
                };
                dx += gij * z[j];
            }
            x[i] += dx;
        }
    }
}
