//! Eight paths of a small model through every span in AVX-512 lanes.

#[cfg(doc)]
use super::Lanes;
use super::{ChunkStats, Dim, Group, Plan, Report, Thresholds, SMALL};
use crate::lanes::X8;
use crate::simulate::check::quad_small;
use crate::system::System;

impl<S: System + ?Sized> Plan<'_, S> {
    /// [`step_lanes`](Self::step_lanes) for eight paths (`group`) of a model with at most
    /// [`SMALL`] states, inputs and channels and no goal or moving set, through every span: the
    /// inputs, the normals, the drift and a state-dependent diffusion (by
    /// [`System::drift_x8`] and [`System::diffusion_x8`]), the update and the unsafe sets and
    /// domain in the lanes of AVX-512 registers, with the same draws and IEEE operations per
    /// lane as `step_lanes`, so the same states and hits; each state then goes through the same
    /// scalar tube check and record as there. `quiet` is [`Lanes::quiet`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq")]
    pub(super) fn lanes_x8<D: Dim>(
        &self,
        dim: D,
        Group { x, paths, hit }: Group<'_>,
        quiet: Option<&[f64]>,
        thresholds: &Thresholds,
        st: &mut ChunkStats,
    ) {
        let (n, m, p) = (dim.get(), self.sys.m(), self.sys.p());
        let check_sets = !self.sets.unsafe_sets.is_empty() || self.sets.domain.is_some();
        // The paths' inputs and their hold interval, the same for all eight (see
        // `InputSchedule::update_x8`).
        let (mut u, mut hold) = ([X8::splat(0.0); SMALL], None);
        let mut live = 0u8;
        for (a, path) in paths.iter().enumerate() {
            live |= u8::from(path.alive) << a;
        }
        let (shortcuts, upper) = (self.membership.has_shortcuts(), self.metric.upper());
        let mut group =
            super::super::avx512::Group8::new(n, x, std::array::from_fn(|a| paths[a].rng));
        let (mut f, mut z) = ([X8::splat(0.0); SMALL], [X8::splat(0.0); SMALL]);
        let mut g = [X8::splat(0.0); SMALL * SMALL];
        for (k, span) in (1..).zip(&self.spans) {
            for i in 0..span.steps {
                let (t, t_end) = span.step_times(i);
                // A path draws its inputs (when they change), then its m normals in channel
                // order (the drift draws nothing).
                if p > 0 {
                    self.inputs
                        .update_x8(t, &mut hold, || group.bits(), &mut u[..p]);
                }
                for zj in &mut z[..m] {
                    *zj = group.normal(self.zig, live);
                }
                let mut xs = group.states();
                self.sys.drift_x8(&xs[..n], &u[..p], t, &mut f[..n]);
                self.noise.apply_x8(
                    self.sys,
                    &mut xs[..n],
                    &f[..n],
                    t,
                    span.h,
                    span.sqrt_h,
                    &mut z[..m],
                    &mut g[..n * m],
                );
                group.set_states(&xs);
                if check_sets {
                    self.sets.check_x8(t_end, &xs[..n], live, hit, paths, st);
                }
                let report = (i + 1 == span.steps).then(|| Report {
                    k,
                    c: &self.nominal[k * n..][..n],
                    thr: thresholds.metric[k],
                    states: thresholds.states_at(k, n),
                    quiet: quiet.map(|q| q[k]),
                });
                // The tube's shortcut and the distances in the lanes; the rest per lane.
                let inside = match &self.tube {
                    Some(tube) => tube.inside_by_shortcut_x8(&self.metric, k, &xs[..n]),
                    None => 0xff,
                };
                // The lanes with something to do: at a report time, the ended paths and those
                // not settled by the shortcuts of the tube and of `report`; between report
                // times, the live paths the tube's shortcut did not settle.
                let (q, qa, quiet) = match &report {
                    Some(rep) => {
                        let (q, qa) = quad_small(&upper, &xs[..n], rep.c);
                        (q, qa, self.quiet_x8(rep, shortcuts, &xs[..n], q, qa))
                    }
                    None => (X8::splat(0.0), X8::splat(0.0), 0xff),
                };
                let mut busy = if report.is_some() {
                    !live | !(inside & quiet)
                } else {
                    live & !inside
                };
                if let Some(rep) = &report {
                    let mut each = live;
                    while each != 0 {
                        let a = each.trailing_zeros() as usize;
                        each &= each - 1;
                        let xa: [f64; SMALL] = std::array::from_fn(|j| xs[j].0[a]);
                        st.record_states(k, &xa[..n], rep.c, rep.states);
                    }
                }
                // Lane by lane in order, as the scalar loops go path by path.
                while busy != 0 {
                    let a = busy.trailing_zeros() as usize;
                    busy &= busy - 1;
                    let path = &mut paths[a];
                    if !path.alive {
                        st.ended(k);
                        continue;
                    }
                    let xa: [f64; SMALL] = std::array::from_fn(|j| xs[j].0[a]);
                    if inside >> a & 1 == 0 && !path.left_tube {
                        self.tube_slow(k, &xa[..n], path, st);
                    }
                    if let Some(rep) = &report {
                        if quiet >> a & 1 == 0 {
                            self.record(k, &xa[..n], (q.0[a], qa.0[a]), rep.thr, st, path);
                        }
                        if !path.alive {
                            live &= !(1 << a);
                        }
                    }
                }
            }
        }
    }
}
