//! The statistics of a chunk of paths, and the thresholds that filter their candidates.

use std::cmp::Ordering;

/// Statistics of a chunk of paths.
#[derive(Debug, PartialEq)]
pub(crate) struct ChunkStats {
    /// Per report step, paths outside the PRS.
    pub(crate) outside: Vec<u64>,
    /// `(step, squared distance)` for those above the step's threshold at the chunk's start.
    pub(crate) candidates: Vec<(u32, f64)>,
    /// `(k n + i, |x_i - x*_i|)` at report step `k` for those above state `i`'s threshold at
    /// the chunk's start (non-finite deviations as `inf`).
    pub(crate) state_candidates: Vec<(u32, f64)>,
    /// The number of states.
    states: usize,
    /// Paths outside the PRS at one report step at least.
    pub(crate) outside_any: u64,
    /// Paths that left the time-uniform tube at one Euler step at least (0 without a tube).
    pub(crate) outside_tube: u64,
    /// Per report step `k`, the paths that left the tube for the first time in the report
    /// interval ending there (`k = 0`: at the start).
    pub(crate) left_tube: Vec<u64>,
    /// Per unsafe set, paths that entered it.
    pub(crate) unsafe_hits: Vec<u64>,
    /// Per unsafe set, the earliest entry time.
    pub(crate) first_hit: Vec<f64>,
    /// Paths that entered some unsafe set.
    pub(crate) unsafe_any: u64,
    /// Per goal set, paths whose event happened.
    pub(crate) goal_reached: Vec<u64>,
    /// Paths that left the domain.
    pub(crate) left_domain: u64,
    /// Paths whose state became non-finite.
    pub(crate) diverged: u64,
}

impl ChunkStats {
    pub(crate) fn new(steps: usize, sets: usize, goals: usize, states: usize) -> Self {
        ChunkStats {
            outside: vec![0; steps],
            candidates: Vec::new(),
            state_candidates: Vec::new(),
            states,
            outside_any: 0,
            outside_tube: 0,
            left_tube: vec![0; steps],
            unsafe_hits: vec![0; sets],
            first_hit: vec![f64::INFINITY; sets],
            unsafe_any: 0,
            goal_reached: vec![0; goals],
            left_domain: 0,
            diverged: 0,
        }
    }

    /// A path whose state became non-finite at an earlier report step, at report step `k`:
    /// it stays outside every PRS, above every quantile.
    pub(super) fn ended(&mut self, k: usize) {
        self.outside[k] += 1;
        self.candidates.push((k as u32, f64::INFINITY));
        let n = self.states;
        self.state_candidates
            .extend((k * n..(k + 1) * n).map(|s| (s as u32, f64::INFINITY)));
    }

    /// The per-state candidates of a state `x` at report step `k` (centre `c`, thresholds
    /// `thr`, one per state).
    #[inline(always)]
    pub(super) fn record_states(&mut self, k: usize, x: &[f64], c: &[f64], thr: &[f64]) {
        let first = k * self.states;
        for (i, ((&x, &c), &thr)) in x.iter().zip(c).zip(thr).enumerate() {
            let d = (x - c).abs();
            // Not `d > thr`: a NaN deviation (a non-finite state) is above every quantile.
            if let Some(Ordering::Greater) | None = d.partial_cmp(&thr) {
                let d = if d.is_nan() { f64::INFINITY } else { d };
                self.state_candidates.push(((first + i) as u32, d));
            }
        }
    }

    /// The statistics with their candidates in one order (the loops record them in different
    /// orders).
    #[cfg(test)]
    pub(crate) fn sorted(mut self) -> Self {
        for c in [&mut self.candidates, &mut self.state_candidates] {
            c.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        }
        self
    }

    /// Adds `other` (order-independent: sums, minima, concatenation).
    pub(crate) fn merge(&mut self, other: &ChunkStats) {
        for (a, b) in self.outside.iter_mut().zip(&other.outside) {
            *a += b;
        }
        self.outside_any += other.outside_any;
        self.outside_tube += other.outside_tube;
        for (a, b) in self.left_tube.iter_mut().zip(&other.left_tube) {
            *a += b;
        }
        for (a, b) in self.unsafe_hits.iter_mut().zip(&other.unsafe_hits) {
            *a += b;
        }
        for (a, &b) in self.first_hit.iter_mut().zip(&other.first_hit) {
            *a = a.min(b);
        }
        self.unsafe_any += other.unsafe_any;
        for (a, b) in self.goal_reached.iter_mut().zip(&other.goal_reached) {
            *a += b;
        }
        self.left_domain += other.left_domain;
        self.diverged += other.diverged;
    }
}

/// The quantile candidates' thresholds of a batch of paths (the buffers' `j`-th largest
/// values at its start, `-inf` before a buffer has `j`): at report step `k`, a squared
/// distance is a candidate above `metric[k]`, state `i`'s deviation above `states[k n + i]`.
pub(crate) struct Thresholds {
    pub(crate) metric: Vec<f64>,
    pub(crate) states: Vec<f64>,
}

impl Thresholds {
    /// `v` for every step and state.
    #[cfg(test)]
    pub(crate) fn uniform(steps: usize, n: usize, v: f64) -> Self {
        Thresholds {
            metric: vec![v; steps],
            states: vec![v; steps * n],
        }
    }

    /// The thresholds of report step `k` for the states (`n` of them).
    pub(super) fn states_at(&self, k: usize, n: usize) -> &[f64] {
        &self.states[k * n..][..n]
    }
}
