//! The loops for additive diagonal noise: one block's step with every constant in a register,
//! and eight paths through every span in AVX-512 lanes.

#[cfg(doc)]
use super::Lanes;
#[cfg(target_arch = "x86_64")]
use super::Thresholds;
use super::{ChunkStats, Dim, Path, Plan, Step, SMALL};
#[cfg(target_arch = "x86_64")]
use crate::lanes::X8;
use crate::simulate::check::{diag_quad, diag_quad_to_box};
use crate::system::System;

impl<S: System + ?Sized> Plan<'_, S> {
    /// [`step_lanes`](Self::step_lanes) for additive diagonal noise, no inputs, no unsafe sets
    /// or domain, at most [`SMALL`] states, a non-negative diagonal metric and (at a report
    /// time) a bound from [`Lanes::quiet`]: the hot loop of most linear and many nonlinear
    /// models, with every constant in a register. `scales` is `G_ii sqrt(h)`; `paths` are the
    /// block's; `REPORT`: the step ends at a report time; `TUBE`: check the tube (a uniform
    /// result).
    #[inline(always)]
    fn additive_lanes<D: Dim, const REPORT: bool, const TUBE: bool>(
        &self,
        dim: D,
        step: &Step<'_>,
        scales: &[f64],
        x: &mut [f64],
        paths: &mut [Path],
        st: &mut ChunkStats,
    ) {
        let (sys, zig) = (self.sys, self.zig);
        let n = dim.get();
        let (t, h) = (step.t, step.span.h);
        let (mut f, mut ds, mut w, mut c) =
            ([0.0; SMALL], [0.0; SMALL], [0.0; SMALL], [0.0; SMALL]);
        let (f, ds, w, c) = (&mut f[..n], &mut ds[..n], &mut w[..n], &mut c[..n]);
        ds.copy_from_slice(&scales[..n]);
        // The caller's condition includes a non-negative diagonal metric.
        if let Some(diag) = self.metric.nonneg_diagonal() {
            w.copy_from_slice(&diag[..n]);
        }
        let (k, quiet, thr, thr_states) = match step.report {
            Some(rep) if REPORT => {
                c.copy_from_slice(&rep.c[..n]);
                (
                    rep.k,
                    rep.quiet.unwrap_or(f64::NEG_INFINITY),
                    rep.thr,
                    rep.states,
                )
            }
            _ => (0, f64::NEG_INFINITY, f64::NEG_INFINITY, &[][..]),
        };
        // The tube over this report interval: its box and "clearly inside" bound.
        let (mut lo, mut hi, mut q_in) = ([0.0; SMALL], [0.0; SMALL], f64::INFINITY);
        let (lo, hi) = (&mut lo[..n], &mut hi[..n]);
        if let (true, Some(tube)) = (TUBE, &self.tube) {
            let (l, u, q) = tube.diag_bounds(step.k);
            lo.copy_from_slice(l);
            hi.copy_from_slice(u);
            q_in = q;
        }
        for (x, path) in x.chunks_exact_mut(n).zip(paths) {
            if !path.alive {
                if REPORT {
                    st.ended(k);
                }
                continue;
            }
            let mut r = path.rng;
            sys.drift(x, &[], t, f);
            for i in 0..n {
                x[i] += f[i] * h + ds[i] * zig.sample(&mut r);
            }
            path.rng = r;
            // `Tube::inside_by_shortcut` for this metric, with the constants in registers.
            if TUBE && !path.left_tube {
                // Not `q < q_in` (NaN included).
                let q = diag_quad_to_box(w, x, lo, hi);
                if q.partial_cmp(&q_in) != Some(std::cmp::Ordering::Less) {
                    self.tube_slow(step.k, x, path, st);
                }
            }
            if REPORT {
                // Most states are inside the PRS and not quantile candidates.
                let q = diag_quad(w, x, c);
                let quiet = q < quiet;
                if !quiet {
                    self.record(k, x, (q, q), thr, st, path);
                }
                st.record_states(k, x, c, thr_states);
            }
        }
    }

    /// [`additive_lanes`](Self::additive_lanes) for eight paths (`paths`, states `x`) through
    /// every span, in the lanes of AVX-512 registers ([`super::super::avx512`]): the same draws and
    /// the same IEEE operations in the same order per lane (the drift by
    /// [`System::drift_x8`]), so the same paths and records; the tube's shortcut is the same
    /// comparison per lane, and the lanes it does not answer go to the same scalar test.
    /// `quiet` is [`Lanes::quiet`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq")]
    pub(super) fn additive_x8<D: Dim>(
        &self,
        dim: D,
        x: &mut [f64],
        paths: &mut [Path],
        quiet: &[f64],
        thresholds: &Thresholds,
        st: &mut ChunkStats,
    ) {
        let n = dim.get();
        let (Some(g), Some(w)) = (self.noise.diagonal(), self.metric.nonneg_diagonal()) else {
            unreachable!("the caller checks additive diagonal noise and metric");
        };
        let mut live = 0u8;
        for (a, path) in paths.iter().enumerate() {
            live |= u8::from(path.alive) << a;
        }
        // Lanes still to check against the tube (none without one); an ended path has left it
        // (its state was not finite at some step), and is not stepped by the other loops.
        let mut pending = 0u8;
        if self.tube.is_some() {
            for (a, path) in paths.iter().enumerate() {
                pending |= u8::from(path.alive && !path.left_tube) << a;
            }
        }
        let mut group =
            super::super::avx512::Group8::new(n, x, std::array::from_fn(|a| paths[a].rng));
        let mut f = [X8::splat(0.0); SMALL];
        for (k, span) in (1..).zip(&self.spans) {
            let h = span.h;
            let ds = std::array::from_fn(|i| if i < n { g[i] * span.sqrt_h } else { 0.0 });
            let (lo, hi, q_in) = match &self.tube {
                Some(tube) => tube.diag_bounds(k),
                None => (&[][..], &[][..], f64::INFINITY),
            };
            for step in 0..span.steps {
                let t = span.t0 + f64::from(step) * span.dt;
                self.sys.drift_x8(&group.states()[..n], &[], t, &mut f[..n]);
                group.step(n, &f, h, &ds, self.zig, live);
                if pending != 0 {
                    let mut out = group.outside_box(n, w, lo, hi, q_in) & pending;
                    while out != 0 {
                        let a = out.trailing_zeros() as usize;
                        out &= out - 1;
                        self.tube_slow(k, &group.lane(a)[..n], &mut paths[a], st);
                        if paths[a].left_tube {
                            pending &= !(1 << a);
                        }
                    }
                }
            }
            // Lanes to record: ended paths, and states not below the quiet bound (or NaN).
            let c = &self.nominal[k * n..][..n];
            let (q, loud) = group.quad(n, w, c, quiet[k]);
            let thr_states = thresholds.states_at(k, n);
            let mut each = live;
            while each != 0 {
                let a = each.trailing_zeros() as usize;
                each &= each - 1;
                st.record_states(k, &group.lane(a)[..n], c, thr_states);
            }
            let mut loud = loud | !live;
            while loud != 0 {
                let a = loud.trailing_zeros() as usize;
                loud &= loud - 1;
                let path = &mut paths[a];
                if !path.alive {
                    st.ended(k);
                    continue;
                }
                let (xa, qa) = (group.lane(a), (q.0[a], q.0[a]));
                self.record(k, &xa[..n], qa, thresholds.metric[k], st, path);
                if !path.alive {
                    live &= !(1 << a);
                }
                if path.left_tube {
                    pending &= !(1 << a);
                }
            }
        }
    }

    /// [`additive_lanes`](Self::additive_lanes), compiled for the processor's extensions.
    #[inline(never)]
    pub(super) fn additive<D: Dim, const REPORT: bool, const TUBE: bool>(
        &self,
        dim: D,
        step: &Step<'_>,
        scales: &[f64],
        x: &mut [f64],
        paths: &mut [Path],
        st: &mut ChunkStats,
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` says the processor has the extensions.
            return unsafe {
                self.additive_avx2::<D, REPORT, TUBE>(dim, step, scales, x, paths, st)
            };
        }
        self.additive_lanes::<D, REPORT, TUBE>(dim, step, scales, x, paths, st);
    }

    /// [`additive_lanes`](Self::additive_lanes) with AVX2 and BMI2 instructions.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2")]
    unsafe fn additive_avx2<D: Dim, const REPORT: bool, const TUBE: bool>(
        &self,
        dim: D,
        step: &Step<'_>,
        scales: &[f64],
        x: &mut [f64],
        paths: &mut [Path],
        st: &mut ChunkStats,
    ) {
        self.additive_lanes::<D, REPORT, TUBE>(dim, step, scales, x, paths, st);
    }
}
