//! A path's states against the unsafe sets, the goals and the domain.

use super::stats::ChunkStats;
#[cfg(target_arch = "x86_64")]
use super::Path;
#[cfg(target_arch = "x86_64")]
use crate::lanes::X8;
#[cfg(target_arch = "x86_64")]
use crate::simulate::check::lanes;
use crate::simulate::regions::{GoalEvent, SetRegions};

/// One path's progress on one goal.
#[derive(Clone, Copy, Debug)]
pub(super) struct GoalPath {
    /// Reach: the event has happened.
    reached: bool,
    /// Stay: the start of the path's current run of steps in the goal (NaN: not in it).
    since: f64,
}

impl GoalPath {
    pub(super) const START: GoalPath = GoalPath {
        reached: false,
        since: f64::NAN,
    };

    /// Whether the path's event has happened, at the horizon (`clean`: it entered no unsafe
    /// set; `alive`: its state stayed finite, else it stays nowhere).
    pub(super) fn happened(self, event: &GoalEvent, clean: bool, alive: bool) -> bool {
        match event.stay {
            false => self.reached,
            true => alive && clean && self.since <= event.window.1,
        }
    }
}

impl SetRegions {
    /// Unsafe-set entries, goal progress and domain exits of a path at time `t`.
    #[inline(always)]
    pub(super) fn check(
        &self,
        t: f64,
        x: &[f64],
        hit: &mut [bool],
        goal: &mut [GoalPath],
        left_domain: &mut bool,
        st: &mut ChunkStats,
    ) {
        for (j, set) in self.unsafe_sets.iter().enumerate() {
            if !hit[j] && set.contains(x) {
                hit[j] = true;
                st.unsafe_hits[j] += 1;
                st.first_hit[j] = st.first_hit[j].min(t);
            }
        }
        if !goal.is_empty() {
            let clean = !hit.contains(&true);
            for (event, path) in self.goals.iter().zip(goal) {
                let inside = event.parts.iter().all(|r| r.contains(x));
                if event.stay {
                    path.since = match inside {
                        true if path.since.is_nan() => t,
                        true => path.since,
                        false => f64::NAN,
                    };
                } else if inside && clean && event.window.0 <= t && t <= event.window.1 {
                    path.reached = true;
                }
            }
        }
        if let Some(d) = &self.domain {
            if !*left_domain && !d.contains(x) {
                *left_domain = true;
            }
        }
    }

    /// [`check`](Self::check) of the `live` lanes of eight states `x` (lane `l`: path
    /// `paths[l]`, its hits `hit[l * sets..]` with `sets` at least 1), the regions decided in
    /// lanes: the same hits and exits as lane by lane.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(super) fn check_x8(
        &self,
        t: f64,
        x: &[X8],
        live: u8,
        hit: &mut [bool],
        paths: &mut [Path],
        st: &mut ChunkStats,
    ) {
        let sets = self.unsafe_sets.len().max(1);
        for (j, set) in self.unsafe_sets.iter().enumerate() {
            let fresh = live & lanes(|l| !hit[l * sets + j]);
            if fresh == 0 {
                continue;
            }
            let mut new = fresh & set.contains_x8(x);
            while new != 0 {
                let l = new.trailing_zeros() as usize;
                new &= new - 1;
                hit[l * sets + j] = true;
                st.unsafe_hits[j] += 1;
                st.first_hit[j] = st.first_hit[j].min(t);
            }
        }
        if let Some(d) = &self.domain {
            let mut out = live & lanes(|l| !paths[l].left_domain) & !d.contains_x8(x);
            while out != 0 {
                let l = out.trailing_zeros() as usize;
                out &= out - 1;
                paths[l].left_domain = true;
            }
        }
    }
}
