//! The general loop: one Euler-Maruyama step of a block of paths, for every model.

use super::{ChunkStats, Dim, Lanes, Plan, Step, SMALL};
use crate::simulate::check::quad_small;
use crate::simulate::regions::SetRegions;
use crate::system::System;

impl<S: System + ?Sized> Plan<'_, S> {
    /// One Euler-Maruyama step of the block's paths, then (at a report time) their records. A
    /// path draws its inputs, then its `m` normals in channel order (as
    /// [`result_paths`](super::super::result_paths) does). `DIAG`: `G` is constant and diagonal.
    ///
    /// Everything a path does in a step happens in one pass over the lanes, with its state and
    /// stream in registers. The states at the step's end are checked against `regions` (from
    /// [`sets_at`](Self::sets_at)).
    #[inline(always)]
    fn step_lanes<D: Dim, const DIAG: bool>(
        &self,
        dim: D,
        step: &Step<'_>,
        regions: &SetRegions,
        l: &mut Lanes,
        st: &mut ChunkStats,
    ) {
        let (sys, zig, metric) = (self.sys, self.zig, &self.metric);
        // With fixed sets only, `regions` are the plan's: read them from the plan, which the
        // compiler keeps in registers with the rest of it through the pass (under callgrind,
        // 1.5% fewer instructions per path-step than through the argument: as before moving
        // sets).
        let regions = if self.moving.is_none() {
            &self.sets
        } else {
            regions
        };
        let (n, p, sets) = (dim.get(), sys.p(), regions.unsafe_sets.len());
        let goals = regions.goals.len();
        let check_sets = sets > 0 || goals > 0 || regions.domain.is_some();
        let (t, h) = (step.t, step.span.h);
        // Small models: per-step vectors in local arrays, which the compiler keeps in registers
        // (heap scratch could alias the states, and would be reloaded for every lane).
        let (mut f_small, mut ds_small) = ([0.0; SMALL], [0.0; SMALL]);
        let (f, ds) = if n <= SMALL {
            ds_small[..n].copy_from_slice(&l.ds[..n]);
            (&mut f_small[..n], &ds_small[..n])
        } else {
            (&mut l.f[..n], &l.ds[..n])
        };
        let (shortcuts, upper) = (self.membership.has_shortcuts(), metric.upper());
        let lane_data =
            l.x.chunks_exact_mut(n.max(1))
                .zip(&mut l.paths)
                .take(step.lanes)
                .enumerate()
                .skip(step.first);
        for (a, (x, path)) in lane_data {
            if !path.alive {
                if let Some(rep) = step.report {
                    st.ended(rep.k);
                }
                continue;
            }
            let x = &mut x[..n];
            let u = &mut l.u[a * p.max(1)..][..p];
            let mut r = path.rng;
            if p > 0 {
                self.inputs.update(t, &mut path.hold, &mut r, u);
            }
            if DIAG {
                // Additive noise: state i gets channel i, scaled by ds[i], each normal used
                // as it is drawn.
                sys.drift(x, u, t, f);
                for i in 0..n {
                    x[i] += f[i] * h + ds[i] * zig.sample(&mut r);
                }
            } else {
                for z in &mut l.z {
                    *z = zig.sample(&mut r);
                }
                sys.drift(x, u, t, f);
                self.noise
                    .apply(sys, x, f, t, h, step.span.sqrt_h, &mut l.z, &mut l.g);
            }
            path.rng = r;
            if check_sets {
                let hit = &mut l.hit[a * sets..][..sets];
                let goal = &mut l.goal[a * goals..][..goals];
                regions.check(step.t_end, x, hit, goal, &mut path.left_domain, st);
            }
            self.check_tube(step.k, x, path, st);
            if let Some(rep) = &step.report {
                let qa = if n <= SMALL {
                    quad_small(&upper, x, rep.c)
                } else {
                    metric.quad(x, rep.c)
                };
                self.report(rep, qa, shortcuts, x, path, st);
            }
        }
    }

    /// [`step_lanes`](Self::step_lanes), compiled for the processor's extensions.
    #[inline(never)]
    pub(super) fn general<D: Dim, const DIAG: bool>(
        &self,
        dim: D,
        step: &Step<'_>,
        regions: &SetRegions,
        l: &mut Lanes,
        st: &mut ChunkStats,
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` says the processor has the extensions.
            return unsafe { self.general_avx2::<D, DIAG>(dim, step, regions, l, st) };
        }
        self.step_lanes::<D, DIAG>(dim, step, regions, l, st);
    }

    /// [`step_lanes`](Self::step_lanes) with AVX2 and BMI2 instructions.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2")]
    unsafe fn general_avx2<D: Dim, const DIAG: bool>(
        &self,
        dim: D,
        step: &Step<'_>,
        regions: &SetRegions,
        l: &mut Lanes,
        st: &mut ChunkStats,
    ) {
        self.step_lanes::<D, DIAG>(dim, step, regions, l, st);
    }
}
