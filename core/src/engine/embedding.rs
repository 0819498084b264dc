//! The embedding system of an inclusion function (method.md, section 6), and its numerical
//! integration.
//!
//! Face pinning evaluates the inclusion function on `2n` faces of the box, each time keeping
//! only component `i`. Component `i` only reads the states `f_i` depends on
//! ([`System::jac_x_pattern`]), so states whose components do not read each other can be
//! pinned together: the states are coloured greedily so that no two states of one colour read
//! each other, and one evaluation per colour and side serves all its states. A chain (each
//! `f_i` reading its neighbours) needs 2 colours whatever its length, so a step costs a few
//! evaluations of the drift and of the non-zero Jacobian entries: time proportional to the
//! size of the expressions, not to `n^2`.

use crate::interval::Interval;
use crate::model::{Inclusion, Integrator};
use crate::system::System;

/// The embedding system on boxes `(lo, hi)`, with scratch space for its evaluations.
pub(crate) struct Embedding<'a> {
    field: Field<'a>,
    scratch: Scratch,
}

/// What the embedding evaluates: the inclusion function and the face-pinning plan.
struct Field<'a> {
    sys: &'a dyn System,
    inclusion: Inclusion,
    /// The input box of the current step.
    ubox: Vec<Interval>,
    /// The centre of the input box, as point intervals.
    uc: Vec<Interval>,
    /// `(row, column)` of the Jacobian entries `f_row` depends on.
    pattern: Vec<(usize, usize)>,
    /// Per column `j`, the indices into `pattern` of its entries (mixed inclusion).
    by_column: Vec<Vec<usize>>,
    /// States pinned together (no two read each other).
    colours: Vec<Vec<usize>>,
}

/// Buffers reused across evaluations (no allocation per step).
struct Scratch {
    bx: Vec<Interval>,
    face: Vec<Interval>,
    centre: Vec<Interval>,
    partial: Vec<Interval>,
    out: Vec<Interval>,
    jac: Vec<Interval>,
    jac_u: Vec<Interval>,
    ub: Vec<Interval>,
}

impl<'a> Embedding<'a> {
    /// The embedding of `sys` with the given inclusion (inputs: see [`Embedding::integrate`]).
    pub(crate) fn new(sys: &'a dyn System, inclusion: Inclusion) -> Self {
        let (n, p) = (sys.n(), sys.p());
        let pattern = sys.jac_x_pattern();
        let mut by_column = vec![Vec::new(); n];
        for (k, &(_, j)) in pattern.iter().enumerate() {
            by_column[j].push(k);
        }
        let colours = colour(&pattern, n);
        let zeros = |k: usize| vec![Interval::ZERO; k];
        Embedding {
            scratch: Scratch {
                bx: zeros(n),
                face: zeros(n),
                centre: zeros(n),
                partial: zeros(n),
                out: zeros(n),
                jac: zeros(pattern.len()),
                jac_u: zeros(n * p),
                ub: zeros(p),
            },
            field: Field {
                sys,
                inclusion,
                ubox: Vec::new(),
                uc: Vec::new(),
                pattern,
                by_column,
                colours,
            },
        }
    }

    /// The embedding vector field: `d = (x_lo', x_hi')` at the box `z = (x_lo, x_hi)`.
    ///
    /// Intermediate integrator stages may (numerically) invert a coordinate; the box used is
    /// then the hull of the two ends.
    fn rhs(&mut self, z: &[f64], t: f64, d: &mut [f64]) {
        let (f, s) = (&self.field, &mut self.scratch);
        let n = f.sys.n();
        let (lo, hi) = z.split_at(n);
        for (b, (&a, &c)) in s.bx.iter_mut().zip(lo.iter().zip(hi)) {
            *b = Interval::try_new(a.min(c), a.max(c)).unwrap_or(Interval::ENTIRE);
        }
        let t = Interval::point(t);
        for colour in &f.colours {
            for (side, offset) in [(lo, 0), (hi, n)] {
                s.face.copy_from_slice(&s.bx);
                for &i in colour {
                    s.face[i] = Interval::point(side[i]);
                }
                f.eval(s, t);
                for &i in colour {
                    d[offset + i] = if offset == 0 {
                        s.out[i].lo()
                    } else {
                        s.out[i].hi()
                    };
                }
            }
        }
    }

    /// Integrates the embedding system over the grid, with the inputs in `inputs[k]` on the
    /// step `[t_k, t_(k+1)]`; per grid time the box `(lo, hi)`. `Err(k)` if the box is not
    /// finite at grid index `k`.
    #[allow(clippy::type_complexity)]
    pub(crate) fn integrate(
        &mut self,
        lo: &[f64],
        hi: &[f64],
        grid: &[f64],
        inputs: &[Vec<Interval>],
        integrator: Integrator,
    ) -> Result<Vec<(Vec<f64>, Vec<f64>)>, usize> {
        let n = lo.len();
        let m = 2 * n;
        let mut z: Vec<f64> = lo.iter().chain(hi).copied().collect();
        let mut out = Vec::with_capacity(grid.len());
        out.push((lo.to_vec(), hi.to_vec()));
        let mut k1 = vec![0.0; m];
        let mut k2 = vec![0.0; m];
        let mut k3 = vec![0.0; m];
        let mut k4 = vec![0.0; m];
        let mut tmp = vec![0.0; m];
        for (idx, win) in grid.windows(2).enumerate() {
            let (t, h) = (win[0], win[1] - win[0]);
            if self.field.ubox != inputs[idx] {
                self.field.set_inputs(&inputs[idx]);
            }
            match integrator {
                Integrator::Euler => {
                    self.rhs(&z, t, &mut k1);
                    for i in 0..m {
                        z[i] += h * k1[i];
                    }
                }
                Integrator::Rk4 => {
                    self.rhs(&z, t, &mut k1);
                    for i in 0..m {
                        tmp[i] = z[i] + 0.5 * h * k1[i];
                    }
                    self.rhs(&tmp, t + 0.5 * h, &mut k2);
                    for i in 0..m {
                        tmp[i] = z[i] + 0.5 * h * k2[i];
                    }
                    self.rhs(&tmp, t + 0.5 * h, &mut k3);
                    for i in 0..m {
                        tmp[i] = z[i] + h * k3[i];
                    }
                    self.rhs(&tmp, t + h, &mut k4);
                    for i in 0..m {
                        z[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                    }
                }
            }
            if z.iter().any(|v| !v.is_finite()) {
                return Err(idx + 1);
            }
            let (l, u) = z.split_at(n);
            let (l, u): (Vec<f64>, Vec<f64>) =
                l.iter().zip(u).map(|(&a, &b)| (a.min(b), a.max(b))).unzip();
            out.push((l, u));
        }
        Ok(out)
    }
}

impl Field<'_> {
    /// The input box `ubox` from now on (and its centre).
    fn set_inputs(&mut self, ubox: &[Interval]) {
        self.ubox = ubox.to_vec();
        self.uc = ubox.iter().map(|u| Interval::point(u.mid())).collect();
    }

    /// The inclusion function on the box `s.face` at time `t`, into `s.out`.
    fn eval(&self, s: &mut Scratch, t: Interval) {
        let p = self.uc.len();
        if self.inclusion == Inclusion::Natural {
            self.sys.drift_interval(&s.face, &self.ubox, t, &mut s.out);
            return;
        }
        // The enclosure of f at the centre (xc, uc) of the box x U.
        for (c, x) in s.centre.iter_mut().zip(&s.face) {
            *c = Interval::point(x.mid());
        }
        self.sys.drift_interval(&s.centre, &self.uc, t, &mut s.out);
        match self.inclusion {
            Inclusion::Natural => {}
            Inclusion::Jacobian => {
                // Mean value theorem on the segment from (xc, uc) to (x, u), inside the convex
                // box x U: f(x, u) in f(xc, uc) + Jx([x], U)(x - xc) + Ju([x], U)(u - uc).
                self.sys
                    .jac_x_sparse_interval(&s.face, &self.ubox, t, &mut s.jac);
                for (&(i, j), &jij) in self.pattern.iter().zip(&s.jac) {
                    let dj = s.face[j] - s.centre[j];
                    // A pinned coordinate contributes exactly 0 (also avoids 0 * inf).
                    if dj != Interval::ZERO {
                        s.out[i] += jij * dj;
                    }
                }
                if p > 0 {
                    self.sys
                        .jac_u_interval(&s.face, &self.ubox, t, &mut s.jac_u);
                    add_input_columns(&mut s.out, &s.jac_u, &self.ubox, &self.uc, 0..p);
                }
            }
            Inclusion::Mixed => {
                // One coordinate at a time (immrax's mjacif): f(x, u) - f(xc, uc) telescopes
                // over the states (inputs at uc), then the inputs (states in their box); term j
                // is in column j of the Jacobian over the box whose coordinates before j are
                // boxes, j its box, and after j their centres. Tighter than one Jacobian over
                // the whole box, at the cost of one Jacobian evaluation per coordinate.
                s.partial.copy_from_slice(&s.centre);
                for j in 0..s.face.len() {
                    s.partial[j] = s.face[j];
                    let dj = s.face[j] - s.centre[j];
                    if dj == Interval::ZERO {
                        continue;
                    }
                    self.sys
                        .jac_x_sparse_interval(&s.partial, &self.uc, t, &mut s.jac);
                    for &k in &self.by_column[j] {
                        s.out[self.pattern[k].0] += s.jac[k] * dj;
                    }
                }
                s.ub.copy_from_slice(&self.uc);
                for j in 0..p {
                    s.ub[j] = self.ubox[j];
                    if self.ubox[j] != self.uc[j] {
                        self.sys.jac_u_interval(&s.face, &s.ub, t, &mut s.jac_u);
                        add_input_columns(&mut s.out, &s.jac_u, &self.ubox, &self.uc, j..j + 1);
                    }
                }
            }
        }
    }
}

/// Groups the states so that no two in a group read each other (greedy colouring of the
/// dependency graph of `pattern`): the states of a group can be pinned in one evaluation.
fn colour(pattern: &[(usize, usize)], n: usize) -> Vec<Vec<usize>> {
    let mut reads = vec![Vec::new(); n];
    for &(i, j) in pattern {
        if i != j {
            reads[i].push(j);
            reads[j].push(i);
        }
    }
    // Each state takes the smallest colour not used by a state it reads or is read by.
    let mut colour_of = vec![usize::MAX; n];
    let mut colours: Vec<Vec<usize>> = Vec::new();
    for i in 0..n {
        let taken: Vec<usize> = reads[i].iter().map(|&j| colour_of[j]).collect();
        let c = (0..).find(|c| !taken.contains(c)).unwrap_or(0);
        colour_of[i] = c;
        if c == colours.len() {
            colours.push(Vec::new());
        }
        colours[c].push(i);
    }
    colours
}

/// `out[k] += Ju[k][j] (U_j - uc_j)` for the input columns `j` in `cols` of the `n x p`
/// matrix `ju`.
fn add_input_columns(
    out: &mut [Interval],
    ju: &[Interval],
    ubox: &[Interval],
    uc: &[Interval],
    cols: std::ops::Range<usize>,
) {
    let p = ubox.len();
    for j in cols {
        let d = ubox[j] - uc[j];
        // A point input contributes exactly 0; skipping it also avoids 0 * inf.
        if d == Interval::ZERO {
            continue;
        }
        for (k, o) in out.iter_mut().enumerate() {
            *o += ju[k * p + j] * d;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::colour;

    #[test]
    fn colouring() {
        // A chain (tridiagonal dependencies) needs 2 colours at any length.
        for n in [3usize, 10, 1000] {
            let pattern: Vec<(usize, usize)> = (0..n)
                .flat_map(|i| (i.saturating_sub(1)..(i + 2).min(n)).map(move |j| (i, j)))
                .collect();
            let c = colour(&pattern, n);
            assert_eq!(c.len(), 2, "n = {n}");
            for group in &c {
                for &(i, j) in &pattern {
                    assert!(i == j || !(group.contains(&i) && group.contains(&j)));
                }
            }
        }
        // Dense dependencies: one state per colour; none: one colour.
        let dense: Vec<(usize, usize)> = (0..4).flat_map(|i| (0..4).map(move |j| (i, j))).collect();
        assert_eq!(colour(&dense, 4).len(), 4);
        assert_eq!(colour(&[(0, 0), (1, 1)], 2), vec![vec![0, 1]]);
    }
}
