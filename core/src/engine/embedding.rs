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

use super::defect::MAX_STEPS;
use super::RunError;
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
    /// The box the faces are taken of.
    bx: Vec<Interval>,
    /// Per state, where it is pinned on its lower and upper face.
    pin_lo: Vec<Interval>,
    pin_hi: Vec<Interval>,
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
                pin_lo: zeros(n),
                pin_hi: zeros(n),
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
        let s = &mut self.scratch;
        let n = self.field.sys.n();
        let (lo, hi) = z.split_at(n);
        for i in 0..n {
            s.bx[i] =
                Interval::try_new(lo[i].min(hi[i]), lo[i].max(hi[i])).unwrap_or(Interval::ENTIRE);
            s.pin_lo[i] = Interval::point(lo[i]);
            s.pin_hi[i] = Interval::point(hi[i]);
        }
        let (dlo, dhi) = d.split_at_mut(n);
        self.faces(Interval::point(t), dlo, dhi);
    }

    /// Bounds of the embedding field on faces: for each state `i`, `dlo[i]` is a lower bound
    /// of `f_i` over the box `scratch.bx` with `x_i` in `scratch.pin_lo[i]`, and `dhi[i]` an
    /// upper bound with `x_i` in `scratch.pin_hi[i]`, for inputs in the current box and times in
    /// `t`. A colour's states are pinned in one evaluation (none reads another).
    fn faces(&mut self, t: Interval, dlo: &mut [f64], dhi: &mut [f64]) {
        let (f, s) = (&self.field, &mut self.scratch);
        for colour in &f.colours {
            for low in [true, false] {
                s.face.copy_from_slice(&s.bx);
                for &i in colour {
                    s.face[i] = if low { s.pin_lo[i] } else { s.pin_hi[i] };
                }
                f.eval(s, t);
                for &i in colour {
                    if low {
                        dlo[i] = s.out[i].lo();
                    } else {
                        dhi[i] = s.out[i].hi();
                    }
                }
            }
        }
    }

    /// Integrates the embedding system over the grid with one step of the (unvalidated)
    /// integrator per report step, with the inputs in `inputs[k]` on `[t_k, t_(k+1)]`; the box
    /// at each report time after 0 (the hull of both ends stands for the step's sets, not
    /// validated). `Err(k)` if the box is not finite at grid index `k`.
    pub(crate) fn integrate(
        &mut self,
        lo: &[f64],
        hi: &[f64],
        grid: &[f64],
        inputs: &[Vec<Interval>],
        integrator: Integrator,
    ) -> Result<Vec<BoxStep>, usize> {
        let n = lo.len();
        let m = 2 * n;
        let mut z: Vec<f64> = lo.iter().chain(hi).copied().collect();
        let mut out = Vec::with_capacity(grid.len());
        let (mut prev_lo, mut prev_hi) = (lo.to_vec(), hi.to_vec());
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
                Integrator::Rk4 | Integrator::Validated => {
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
            out.push(BoxStep {
                t1: win[1],
                interval: idx,
                over_lo: l.iter().zip(&prev_lo).map(|(a, b)| a.min(*b)).collect(),
                over_hi: u.iter().zip(&prev_hi).map(|(a, b)| a.max(*b)).collect(),
                lo: l.clone(),
                hi: u.clone(),
            });
            (prev_lo, prev_hi) = (l, u);
        }
        Ok(out)
    }

    /// The embedding system on validated steps (method.md section 8.4) from the box
    /// `[lo, hi]` at `t = 0` over the report grid, inputs in `inputs[k]` on report interval
    /// `k`: each step's end box and the hull of its boxes hold every trajectory from the box
    /// at the end and over the whole step. The last step of each report interval ends exactly
    /// on the report time.
    pub(crate) fn validated(
        &mut self,
        lo: &[f64],
        hi: &[f64],
        grid: &[f64],
        inputs: &[Vec<Interval>],
    ) -> Result<Vec<BoxStep>, RunError> {
        let mut out = Vec::new();
        let (mut lo, mut hi) = (lo.to_vec(), hi.to_vec());
        let mut t = 0.0;
        let mut h = grid.get(1).copied().unwrap_or(0.0);
        for (k, w) in grid.windows(2).enumerate() {
            if self.field.ubox != inputs[k] {
                self.field.set_inputs(&inputs[k]);
            }
            let end = w[1];
            while t < end {
                if out.len() >= MAX_STEPS {
                    return Err(RunError::NonFinite(format!(
                        "the embedding system needs more than {MAX_STEPS} validated steps before \
                         t = {t} (a coordinate transform or a shorter horizon may help)"
                    )));
                }
                let (step, used) = self.validated_step(&lo, &hi, t, h.min(w[1] - w[0]), end, k)?;
                h = (2.0 * used).min(w[1] - w[0]);
                (lo, hi) = (step.lo.clone(), step.hi.clone());
                t = step.t1;
                out.push(step);
            }
        }
        Ok(out)
    }

    /// One validated step from the box `[lo, hi]` at `t`, of length at most `h` (halved until
    /// it validates); returns it with the length used.
    fn validated_step(
        &mut self,
        lo: &[f64],
        hi: &[f64],
        t: f64,
        mut h: f64,
        end: f64,
        interval: usize,
    ) -> Result<(BoxStep, f64), RunError> {
        let min_h = 1e-12 * end.abs().max(1.0);
        loop {
            let t1 = if t + h >= end * (1.0 - 1e-15) || end - (t + h) < min_h {
                end
            } else {
                t + h
            };
            if let Some((nlo, nhi)) = self.try_validated(lo, hi, t, t1) {
                let over_lo = lo.iter().zip(&nlo).map(|(a, b)| a.min(*b)).collect();
                let over_hi = hi.iter().zip(&nhi).map(|(a, b)| a.max(*b)).collect();
                let step = BoxStep {
                    t1,
                    interval,
                    lo: nlo,
                    hi: nhi,
                    over_lo,
                    over_hi,
                };
                return Ok((step, t1 - t));
            }
            h = 0.5 * (t1 - t);
            if h < min_h {
                return Err(RunError::NonFinite(format!(
                    "the embedding system cannot be validated at t = {t}: the step shrank below \
                     {min_h:e} (the box grows without bound: try the other inclusion, a \
                     coordinate transform or a domain)"
                )));
            }
        }
    }

    /// The comparison principle on `[t, t1]`: with `lo(s)`, `hi(s)` linear from `[lo, hi]` and
    /// every face bound taken over a box `B` holding both ends and with the pinned coordinate
    /// over the interval its end sweeps, `lo_i' <= inf f_i` on the lower faces (and `hi`
    /// likewise) for all `s` at once, so no trajectory leaves `[lo(s), hi(s)]`. Guess, check,
    /// widen; `None` when the guesses do not close (a shorter step may).
    fn try_validated(
        &mut self,
        lo: &[f64],
        hi: &[f64],
        t: f64,
        t1: f64,
    ) -> Option<(Vec<f64>, Vec<f64>)> {
        let n = lo.len();
        let h = Interval::point(t1) - Interval::point(t);
        let times = Interval::point(t).hull(Interval::point(t1));
        let (mut dlo, mut dhi) = (vec![0.0; n], vec![0.0; n]);
        // First guess: the slopes on the box itself.
        for i in 0..n {
            self.scratch.bx[i] = Interval::try_new(lo[i], hi[i])?;
            self.scratch.pin_lo[i] = Interval::point(lo[i]);
            self.scratch.pin_hi[i] = Interval::point(hi[i]);
        }
        self.faces(times, &mut dlo, &mut dhi);
        let (mut nlo, mut nhi) = (vec![0.0; n], vec![0.0; n]);
        for _ in 0..6 {
            // Widen the pins to the swept intervals of the current guess (with some slack), the
            // box to hold them.
            for i in 0..n {
                let end_lo = (Interval::point(lo[i]) + h * Interval::point(dlo[i])).lo();
                let end_hi = (Interval::point(hi[i]) + h * Interval::point(dhi[i])).hi();
                if !(end_lo.is_finite() && end_hi.is_finite()) {
                    return None;
                }
                let slack = |a: f64, b: f64| 0.25 * (a - b).abs() + 1e-15 * (1.0 + a.abs());
                let pin_lo = Interval::try_new(
                    lo[i].min(end_lo) - slack(lo[i], end_lo),
                    lo[i].max(end_lo) + slack(lo[i], end_lo),
                )?;
                let pin_hi = Interval::try_new(
                    hi[i].min(end_hi) - slack(hi[i], end_hi),
                    hi[i].max(end_hi) + slack(hi[i], end_hi),
                )?;
                let s = &mut self.scratch;
                s.pin_lo[i] = s.pin_lo[i].hull(pin_lo);
                s.pin_hi[i] = s.pin_hi[i].hull(pin_hi);
                s.bx[i] = s.bx[i].hull(s.pin_lo[i]).hull(s.pin_hi[i]);
            }
            self.faces(times, &mut dlo, &mut dhi);
            // The new ends, and the check: each end inside its pin, both boxes inside bx.
            let mut closed = true;
            for i in 0..n {
                nlo[i] = (Interval::point(lo[i]) + h * Interval::point(dlo[i])).lo();
                nhi[i] = (Interval::point(hi[i]) + h * Interval::point(dhi[i])).hi();
                let s = &self.scratch;
                closed &= s.pin_lo[i].contains(nlo[i])
                    && s.pin_hi[i].contains(nhi[i])
                    && s.bx[i].contains(nlo[i].min(lo[i]))
                    && s.bx[i].contains(nhi[i].max(hi[i]));
            }
            if closed {
                // A sound embedding keeps lo <= hi; rounding aside, order the ends.
                let (l, u) = nlo
                    .iter()
                    .zip(&nhi)
                    .map(|(&a, &b)| (a.min(b), a.max(b)))
                    .unzip();
                return Some((l, u));
            }
        }
        None
    }
}

/// One step of the embedding system (in `y = T x` with a transform).
#[derive(Clone, Debug)]
pub(crate) struct BoxStep {
    /// Its end.
    pub(crate) t1: f64,
    /// The report interval it belongs to (`[t_k, t_(k+1)]`).
    pub(crate) interval: usize,
    /// The box at `t1`.
    pub(crate) lo: Vec<f64>,
    pub(crate) hi: Vec<f64>,
    /// A box holding the boxes of every time of the step.
    pub(crate) over_lo: Vec<f64>,
    pub(crate) over_hi: Vec<f64>,
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
