//! What a path's state records: the tube, membership at report times, quantile candidates.

use super::{ChunkStats, Path, Plan, Report};
#[cfg(target_arch = "x86_64")]
use crate::lanes::X8;
#[cfg(target_arch = "x86_64")]
use crate::simulate::check::lanes;
#[cfg(doc)]
use crate::simulate::check::Membership;
use crate::system::System;

impl<S: System + ?Sized> Plan<'_, S> {
    /// The record of `path`'s state `x` at the report step `rep`, given `(q, a) =
    /// metric.quad(x, x*_k)`, unless a shortcut finds it quiet (inside the PRS and not a
    /// quantile candidate). `shortcuts` is [`Membership::has_shortcuts`].
    #[inline(always)]
    pub(super) fn report(
        &self,
        rep: &Report<'_>,
        (q, a): (f64, f64),
        shortcuts: bool,
        x: &[f64],
        path: &mut Path,
        st: &mut ChunkStats,
    ) {
        let metric = &self.metric;
        // Most states are inside the PRS by a shortcut and not quantile candidates.
        let quiet = match rep.quiet {
            Some(b) => q < b,
            None => {
                shortcuts
                    && q < rep.thr
                    && self.membership.inside_by_shortcut(metric, rep.k, x, q, a)
            }
        };
        if !quiet {
            self.record(rep.k, x, (q, a), rep.thr, st, path);
        }
        st.record_states(rep.k, x, rep.c, rep.states);
    }

    /// [`report`](Self::report)'s "quiet" answer for eight states in lanes (`(q, a)` their
    /// distances): bit `l` set when lane `l` needs no record, the same answer as for that
    /// state alone.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(super) fn quiet_x8(&self, rep: &Report<'_>, shortcuts: bool, x: &[X8], q: X8, a: X8) -> u8 {
        match rep.quiet {
            Some(b) => lanes(|l| q.0[l] < b),
            None if shortcuts => {
                let near = lanes(|l| q.0[l] < rep.thr);
                if near == 0 {
                    return 0;
                }
                near & self
                    .membership
                    .inside_by_shortcut_x8(&self.metric, rep.k, x, q, a)
            }
            None => 0,
        }
    }

    /// Checks `path`'s state `x` in report interval `k` against the tube, if there is one and
    /// the path has not left it yet.
    #[inline(always)]
    pub(super) fn check_tube(&self, k: usize, x: &[f64], path: &mut Path, st: &mut ChunkStats) {
        if let Some(tube) = &self.tube {
            if !path.left_tube && !tube.inside_by_shortcut(&self.metric, k, x) {
                self.tube_slow(k, x, path, st);
            }
        }
    }

    /// [`check_tube`](Self::check_tube) for a state the shortcut did not find inside.
    #[cold]
    #[inline(never)]
    pub(super) fn tube_slow(&self, k: usize, x: &[f64], path: &mut Path, st: &mut ChunkStats) {
        if let Some(tube) = &self.tube {
            if !tube.inside_slow(&self.metric, k, x) {
                path.leave_tube(k, st);
            }
        }
    }

    /// Records `path`'s state `x` at report step `k` (its membership and, above the candidate
    /// threshold `thr`, its squared distance), given `(q, a) = metric.quad(x, x*_k)`; the path
    /// ends if the state is not finite.
    #[inline(never)]
    pub(super) fn record(
        &self,
        k: usize,
        x: &[f64],
        (q, a): (f64, f64),
        thr: f64,
        st: &mut ChunkStats,
        path: &mut Path,
    ) {
        let n = x.len();
        let c = &self.nominal[k * n..(k + 1) * n];
        // P is positive definite: a non-finite coordinate makes q non-finite.
        let finite = q.is_finite();
        let (q, inside) = if finite {
            // Rounding can make q slightly negative only with off-diagonal terms.
            let q = if a == q { q } else { q.max(0.0) };
            (q, self.membership.inside(&self.metric, k, x, c, q, a))
        } else {
            (f64::INFINITY, false)
        };
        if !inside {
            st.outside[k] += 1;
            path.outside_any = true;
            // The tube at a report time is that time's PRS.
            if self.tube.is_some() {
                path.leave_tube(k, st);
            }
        }
        if q > thr {
            st.candidates.push((k as u32, q));
        }
        path.alive = finite;
    }
}
