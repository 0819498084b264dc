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

use super::defect::{StepBudget, MAX_STEPS, MAX_STEPS_PER_REPORT, MIN_STEP};
use super::hermite::{Cubic, Piece, PIECES};
use super::nominal::rk4_step;
use super::{Detail, Integrated, Problem, RunError, Setting};
use crate::interval::Interval;
use crate::model::{Inclusion, Integrator};
use crate::system::System;

/// How much work the embedding's validated steps may take.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Budget {
    /// The most steps in all.
    pub(crate) steps: usize,
    /// The most steps in one report interval.
    pub(crate) per_interval: usize,
    /// The shortest step accuracy alone may ask for, as a fraction of the report step (shorter
    /// steps are taken only where a longer one does not validate).
    pub(crate) floor: f64,
}

impl Budget {
    /// An analysis' own boxes: up to [`MAX_STEPS`] and [`MAX_STEPS_PER_REPORT`], accuracy down
    /// to `2^-12` of the report step.
    pub(crate) const FULL: Budget = Budget {
        steps: MAX_STEPS,
        per_interval: MAX_STEPS_PER_REPORT,
        floor: 1.0 / 4096.0,
    };

    /// A helper's boxes over `reports` report intervals: `per_report` steps per interval on
    /// average and 4 times that in any one, accuracy down to `1 / floor_steps` of the report
    /// step.
    pub(crate) fn helper(reports: usize, per_report: usize, floor_steps: usize) -> Budget {
        Budget {
            steps: per_report * reports.max(1),
            per_interval: 4 * per_report,
            floor: 1.0 / floor_steps.max(1) as f64,
        }
    }
}

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
        let mut z: Vec<f64> = lo.iter().chain(hi).copied().collect();
        let mut out = Vec::with_capacity(grid.len());
        let (mut prev_lo, mut prev_hi) = (lo.to_vec(), hi.to_vec());
        let mut slope = vec![0.0; 2 * n];
        for (idx, win) in grid.windows(2).enumerate() {
            let (t, h) = (win[0], win[1] - win[0]);
            if self.field.ubox != inputs[idx] {
                self.field.set_inputs(&inputs[idx]);
            }
            match integrator {
                Integrator::Euler => {
                    self.rhs(&z, t, &mut slope);
                    for (zi, di) in z.iter_mut().zip(&slope) {
                        *zi += h * di;
                    }
                }
                Integrator::Rk4 | Integrator::Validated => {
                    z = rk4_step(&mut |z, t, d| self.rhs(z, t, d), &z, t, h).0;
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
    /// `k`: each step's end box and its hull over the step hold every trajectory from the box,
    /// at the end and over the whole step. Steps are chosen so that what validation adds to a
    /// box stays near `accuracy` times its width per unit time, within `budget`. The last step
    /// of each report interval ends exactly on the report time.
    pub(crate) fn validated(
        &mut self,
        lo: &[f64],
        hi: &[f64],
        grid: &[f64],
        inputs: &[Vec<Interval>],
        accuracy: f64,
        budget: Budget,
    ) -> Result<Vec<BoxStep>, RunError> {
        let mut out = Vec::new();
        let (mut lo, mut hi) = (lo.to_vec(), hi.to_vec());
        let mut t = 0.0;
        let mut h = grid.get(1).copied().unwrap_or(0.0);
        let mut steps =
            StepBudget::new(Integrated::Embedding).at_most(budget.steps, budget.per_interval);
        for (k, w) in grid.windows(2).enumerate() {
            if self.field.ubox != inputs[k] {
                self.field.set_inputs(&inputs[k]);
            }
            let end = w[1];
            steps.next_interval();
            while t < end {
                steps.take(t, w)?;
                let report = w[1] - w[0];
                let (step, next) = self.validated_step(
                    &lo,
                    &hi,
                    t,
                    h.min(report),
                    w,
                    k,
                    (accuracy, budget.floor),
                )?;
                h = next.min(report);
                (lo, hi) = (step.lo.clone(), step.hi.clone());
                t = step.t1;
                out.push(step);
            }
        }
        Ok(out)
    }

    /// One validated step from the box `[lo, hi]` at `t` in report interval `interval`
    /// (`window`), of length at most `h`: shortened until it validates and what it adds to the
    /// box is within `accuracy` (the latter only down to `floor` times the report step: a step
    /// that validates is sound, only looser; the former down to [`MIN_STEP`] of it). Returns
    /// the step and the length to try next.
    #[allow(clippy::too_many_arguments)]
    fn validated_step(
        &mut self,
        lo: &[f64],
        hi: &[f64],
        t: f64,
        mut h: f64,
        window: &[f64],
        interval: usize,
        (accuracy, floor): (f64, f64),
    ) -> Result<(BoxStep, f64), RunError> {
        let end = window[1];
        let min_h = MIN_STEP * (end - window[0]);
        let floor = (end - window[0]) * floor;
        h = h.max(min_h);
        let wmax = lo.iter().zip(hi).fold(0.0f64, |m, (a, b)| m.max(b - a));
        // Per coordinate, what a step may add per unit time (a floor for boxes of no width).
        let allowed: Vec<f64> = lo
            .iter()
            .zip(hi)
            .map(|(a, b)| {
                let scale = (b - a)
                    .max(1e-3 * wmax)
                    .max(1e-9 * (1.0 + a.abs().max(b.abs())));
                accuracy * scale
            })
            .collect();
        loop {
            let t1 = if t + h >= end * (1.0 - 1e-15) || end - (t + h) < min_h {
                end
            } else {
                t + h
            };
            let used = t1 - t;
            let mut shrink = 0.5;
            if let Some(step) = self.try_validated(lo, hi, t, t1) {
                // What validation added, relative to what is allowed (<= 1 to accept).
                let ratio = (0..lo.len())
                    .map(|i| {
                        let added = (step.end_lo[i] - step.lo[i]).max(step.hi[i] - step.end_hi[i]);
                        added / (allowed[i] * used)
                    })
                    .fold(0.0f64, f64::max);
                // It grows about like the square of the step: aim at 0.8 of the allowance.
                let next = 0.9 / ratio.sqrt();
                if ratio <= 1.0 || used.min(h) <= floor {
                    // (`h`, the length asked for: a step asked at the floor may land on the
                    // report time a little beyond it.)
                    // Accuracy shortens steps down to the floor only: a step the accuracy
                    // target cannot meet there is kept, and so is the floor for the next one
                    // (else the steps decay geometrically towards `min_h`; a zero-width
                    // coordinate driven by `t` keeps the ratio above 1 at every length).
                    let next_h = (used * next.min(2.0)).max(floor);
                    return Ok((step.into_box(t1, interval), next_h));
                }
                // Not below the floor for accuracy alone.
                shrink = next.clamp(0.1, 0.5).max(floor / used);
            }
            h = shrink * used;
            if h < min_h {
                return Err(RunError::NonFinite(
                    Detail::from(Problem::EmbeddingStepTooSmall {
                        t,
                        min_step: min_h,
                        width: wmax,
                    })
                    .at_setting(Setting::Inclusion),
                ));
            }
        }
    }

    /// A validated step on `[t, t1]`. The embedding's RK4 step, joined by the cubic
    /// `q = (q_lo, q_hi)` ([`Cubic`]), is a box moving with time; no trajectory leaves a moving
    /// box whose lower faces move no faster than `inf f_i` over them and upper faces no
    /// slower than `sup f_i` (differential inequalities on the faces). `q` satisfies this up to
    /// a deficit, bounded on each piece of the step by the mean value theorem around the
    /// piece's midpoint `m`: for `x` on the lower face `i` at `s`,
    /// `f_i(x, s) - q_lo_i'(s) >= inf f_i(face(m), [piece]) - q_lo_i'(m)
    ///     + (J_i([hull]) x'([piece]) - q_lo_i''([piece])) (s - m)`,
    /// with `x'` the rates of the face's coordinates (the hull of `q_lo_j'` and `q_hi_j'`,
    /// `q_lo_i'` for the pinned one). Widening the faces by `e(s)`, linear from 0 with
    /// `e' >= deficit + M e` (`M` the Metzler bound of the Jacobian: how much widening the box
    /// lowers the faces' bounds), absorbs the deficit. `None` if a value is not finite or the
    /// step is too long for the widening.
    fn try_validated(&mut self, lo: &[f64], hi: &[f64], t: f64, t1: f64) -> Option<Validated> {
        let n = lo.len();
        let z0: Vec<f64> = lo.iter().chain(hi).copied().collect();
        let (z1, f0) = rk4_step(&mut |z, s, d| self.rhs(z, s, d), &z0, t, t1 - t);
        let mut f1 = vec![0.0; 2 * n];
        self.rhs(&z1, t1, &mut f1);
        if z1.iter().chain(&f0).chain(&f1).any(|v| !v.is_finite()) {
            return None;
        }
        let cubic = Cubic::new(t, t1, &z0, &z1, &f0, &f1);
        let (mut dlo, mut dhi) = (vec![0.0; n], vec![0.0; n]);
        // Per coordinate: the deficits of the lower (i) and upper (n + i) faces.
        let mut deficit = vec![0.0f64; 2 * n];
        let (mut over_lo, mut over_hi) = (lo.to_vec(), hi.to_vec());
        let mut hull = vec![Interval::ZERO; n];
        let mut rate = vec![Interval::ZERO; n];
        let mut slope = vec![Interval::ZERO; 2 * n];
        let mut piece = Piece::new(2 * n);
        for k in 0..PIECES {
            cubic.piece(k, &mut piece);
            let (mid, over) = (&piece.mid, &piece.over);
            let s = &mut self.scratch;
            for j in 0..n {
                s.pin_lo[j] = mid.p[j];
                s.pin_hi[j] = mid.p[n + j];
                s.bx[j] = mid.p[j].hull(mid.p[n + j]);
                hull[j] = over.p[j].hull(over.p[n + j]);
                rate[j] = over.dp[j].hull(over.dp[n + j]);
                over_lo[j] = over_lo[j].min(hull[j].lo());
                over_hi[j] = over_hi[j].max(hull[j].hi());
            }
            self.faces(piece.times, &mut dlo, &mut dhi);
            let f = &self.field;
            let jac = &mut self.scratch.jac;
            f.sys
                .jac_x_sparse_interval(&hull, &f.ubox, piece.times, jac);
            for i in 0..n {
                slope[i] = -over.d2p[i];
                slope[n + i] = -over.d2p[n + i];
            }
            for (&(i, j), &jij) in f.pattern.iter().zip(jac.iter()) {
                if i == j {
                    slope[i] += jij * over.dp[i];
                    slope[n + i] += jij * over.dp[n + i];
                } else {
                    let v = jij * rate[j];
                    slope[i] += v;
                    slope[n + i] += v;
                }
            }
            for i in 0..n {
                // f_i - q_lo_i' on the lower face, q_hi_i' - f_i on the upper: >= 0 wanted.
                let low = Interval::point(dlo[i]) - mid.dp[i] + slope[i] * piece.offset;
                let up = mid.dp[n + i] - Interval::point(dhi[i]) - slope[n + i] * piece.offset;
                if !(low.lo().is_finite() && up.lo().is_finite()) {
                    return None;
                }
                deficit[i] = deficit[i].max(-low.lo());
                deficit[n + i] = deficit[n + i].max(-up.lo());
            }
        }
        let widen = self.widening(&deficit, &over_lo, &over_hi, t, t1)?;
        let end = cubic.end();
        let out = |a: Interval, e: f64, up: bool| {
            let e = Interval::point(e);
            if up {
                (a + e).hi()
            } else {
                (a - e).lo()
            }
        };
        Some(Validated {
            lo: (0..n).map(|i| out(end[i], widen[i], false)).collect(),
            hi: (0..n)
                .map(|i| out(end[n + i], widen[n + i], true))
                .collect(),
            end_lo: (0..n).map(|i| end[i].lo()).collect(),
            end_hi: (0..n).map(|i| end[n + i].hi()).collect(),
            over_lo: (0..n)
                .map(|i| out(Interval::point(over_lo[i]), widen[i], false))
                .collect(),
            over_hi: (0..n)
                .map(|i| out(Interval::point(over_hi[i]), widen[n + i], true))
                .collect(),
        })
    }

    /// The widening `e(t1)` of each face (lower `i`, upper `n + i`) that absorbs the deficits
    /// on `[t, t1]`: with `e_i(s) = (deficit_i + nu E) (s - t)` and `E >= max e(t1)`,
    /// `e_i' >= deficit_i + sum_j M_ij e_j`, where `nu` bounds the rows of the Metzler matrix
    /// `M` (`max(J_ii, 0)`, `|J_ij|` off the diagonal) over the widened hull of the step. `None`
    /// when the step is too long for that (`nu (t1 - t) > 1/2`).
    fn widening(
        &mut self,
        deficit: &[f64],
        over_lo: &[f64],
        over_hi: &[f64],
        t: f64,
        t1: f64,
    ) -> Option<Vec<f64>> {
        let n = over_lo.len();
        let dmax = deficit.iter().fold(0.0f64, |m, &d| m.max(d));
        if dmax == 0.0 {
            return Some(vec![0.0; 2 * n]);
        }
        let h = Interval::point(t1) - Interval::point(t);
        let times = Interval::point(t).hull(Interval::point(t1));
        let mut guess = (Interval::point(4.0 * dmax) * h).hi();
        for _ in 0..4 {
            let (f, s) = (&self.field, &mut self.scratch);
            let g = Interval::new(-guess, guess);
            for j in 0..n {
                s.bx[j] = Interval::new(over_lo[j], over_hi[j]) + g;
            }
            f.sys
                .jac_x_sparse_interval(&s.bx, &f.ubox, times, &mut s.jac);
            let mut rows = vec![Interval::ZERO; n];
            for (&(i, j), &jij) in f.pattern.iter().zip(&s.jac) {
                rows[i] += if i == j {
                    Interval::point(jij.hi().max(0.0))
                } else {
                    Interval::point(jij.mag())
                };
            }
            let nu = rows.iter().fold(Interval::ZERO, |m, r| m.max(*r));
            let nu_h = nu * h;
            // (NaN fails too.)
            if nu_h.hi().partial_cmp(&0.5) != Some(std::cmp::Ordering::Less) {
                return None;
            }
            // E = dmax h / (1 - nu h) solves E = (dmax + nu E) h.
            let e_max = (Interval::point(dmax) * h / (Interval::ONE - nu_h)).hi();
            if e_max <= guess {
                let grow = Interval::point(nu.hi()) * Interval::point(e_max);
                return Some(
                    deficit
                        .iter()
                        .map(|&d| ((Interval::point(d) + grow) * h).hi())
                        .collect(),
                );
            }
            guess = 2.0 * e_max;
        }
        None
    }
}

/// A validated step before it is placed on the grid.
struct Validated {
    /// The box at the end.
    lo: Vec<f64>,
    hi: Vec<f64>,
    /// The RK4 step's end (what the box would be without validation).
    end_lo: Vec<f64>,
    end_hi: Vec<f64>,
    /// A box holding the boxes of the whole step.
    over_lo: Vec<f64>,
    over_hi: Vec<f64>,
}

impl Validated {
    fn into_box(self, t1: f64, interval: usize) -> BoxStep {
        BoxStep {
            t1,
            interval,
            lo: self.lo,
            hi: self.hi,
            over_lo: self.over_lo,
            over_hi: self.over_hi,
        }
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
