//! Euler-Maruyama sample paths and their per-chunk statistics (the hot loop).
//!
//! A path is `x_{i+1} = x_i + f(x_i, u_i, t_i) h + G(x_i, t_i) sqrt(h) z_i`, `z_i` standard
//! normal, with the report interval `[t_{k-1}, t_k]` split into equal steps `h <= dt`, so every
//! report time is hit exactly. Everything a path draws comes from its own stream (see
//! [`super::rng`]); the statistics are counts, minima and candidate lists, whose merge does not
//! depend on the order, so the results are the same for any thread count.

use super::initial::InitialSampler;
use super::inputs::InputSchedule;
use super::noise::Noise;
use super::normal::Ziggurat;
use super::prs::{Membership, Metric};
use super::regions::Region;
use super::rng::PathRng;
use crate::system::System;
use std::ops::Range;

/// Everything a chunk of paths needs, shared read-only by the workers.
pub(crate) struct Plan<'a, S: ?Sized> {
    pub(crate) sys: &'a S,
    pub(crate) seed: u64,
    /// Report times `t_0 = 0 < ... < t_K`.
    pub(crate) times: Vec<f64>,
    /// Euler steps in report interval `k` (index `k - 1`).
    pub(crate) substeps: Vec<u32>,
    /// `x*_{t_k}`, flat (`n` per step).
    pub(crate) nominal: Vec<f64>,
    pub(crate) metric: Metric,
    pub(crate) membership: Membership<'a>,
    pub(crate) initial: InitialSampler,
    pub(crate) inputs: InputSchedule,
    pub(crate) noise: Noise,
    pub(crate) unsafe_sets: Vec<Region>,
    pub(crate) domain: Option<Region>,
    pub(crate) zig: &'static Ziggurat,
}

/// Statistics of a chunk of paths.
#[derive(Debug)]
pub(crate) struct ChunkStats {
    /// Per report step, paths outside the PRS.
    pub(crate) outside: Vec<u64>,
    /// `(step, squared distance)` for those above the step's threshold at the chunk's start.
    pub(crate) candidates: Vec<(u32, f64)>,
    /// Paths outside the PRS at one report step at least.
    pub(crate) outside_any: u64,
    /// Per unsafe set, paths that entered it.
    pub(crate) unsafe_hits: Vec<u64>,
    /// Per unsafe set, the earliest entry time.
    pub(crate) first_hit: Vec<f64>,
    /// Paths that left the domain.
    pub(crate) left_domain: u64,
    /// Paths whose state became non-finite.
    pub(crate) diverged: u64,
}

impl ChunkStats {
    pub(crate) fn new(steps: usize, sets: usize) -> Self {
        ChunkStats {
            outside: vec![0; steps],
            candidates: Vec::new(),
            outside_any: 0,
            unsafe_hits: vec![0; sets],
            first_hit: vec![f64::INFINITY; sets],
            left_domain: 0,
            diverged: 0,
        }
    }

    /// Adds `other` (order-independent: sums, minima, concatenation).
    pub(crate) fn merge(&mut self, other: &ChunkStats) {
        for (a, b) in self.outside.iter_mut().zip(&other.outside) {
            *a += b;
        }
        self.outside_any += other.outside_any;
        for (a, b) in self.unsafe_hits.iter_mut().zip(&other.unsafe_hits) {
            *a += b;
        }
        for (a, &b) in self.first_hit.iter_mut().zip(&other.first_hit) {
            *a = a.min(b);
        }
        self.left_domain += other.left_domain;
        self.diverged += other.diverged;
    }
}

/// Paths simulated in lockstep by one worker. Each path's Euler step is a chain of dependent
/// operations (drift, noise, update, distance); interleaving independent paths lets the
/// processor overlap their chains instead of waiting on each.
const LANES: usize = 8;

/// The number of states: a compile-time constant for small models, so that the per-state loops
/// of the hot path unroll and lose their bounds checks, or a run-time value.
trait Dim: Copy {
    fn get(self) -> usize;
}

#[derive(Clone, Copy)]
struct Fixed<const N: usize>;

impl<const N: usize> Dim for Fixed<N> {
    #[inline(always)]
    fn get(self) -> usize {
        N
    }
}

#[derive(Clone, Copy)]
struct Dynamic(usize);

impl Dim for Dynamic {
    #[inline(always)]
    fn get(self) -> usize {
        self.0
    }
}

/// The state of up to [`LANES`] paths and the worker's scratch, allocated once per chunk,
/// never per step. Per-lane vectors are flat, `n` (or `p`, or one per unsafe set) per lane.
struct Lanes {
    x: Vec<f64>,
    f: Vec<f64>,
    u: Vec<f64>,
    rng: Vec<PathRng>,
    hold: Vec<Option<u64>>,
    alive: Vec<bool>,
    outside_any: Vec<bool>,
    left_domain: Vec<bool>,
    hit: Vec<bool>,
    z: Vec<f64>,
    g: Vec<f64>,
    init: Vec<f64>,
}

impl<S: System + ?Sized> Plan<'_, S> {
    /// Euler steps per path.
    pub(crate) fn steps_per_path(&self) -> u64 {
        self.substeps.iter().map(|&s| u64::from(s)).sum()
    }

    /// Simulates the paths `range`; `thresholds[k]` filters the candidates of step `k`.
    pub(crate) fn run_chunk(&self, range: Range<u64>, thresholds: &[f64]) -> ChunkStats {
        match self.sys.n() {
            1 => self.run_chunk_in(Fixed::<1>, range, thresholds),
            2 => self.run_chunk_in(Fixed::<2>, range, thresholds),
            3 => self.run_chunk_in(Fixed::<3>, range, thresholds),
            4 => self.run_chunk_in(Fixed::<4>, range, thresholds),
            n => self.run_chunk_in(Dynamic(n), range, thresholds),
        }
    }

    /// [`run_chunk`](Self::run_chunk) with `dim.get() == sys.n()`.
    fn run_chunk_in<D: Dim>(&self, dim: D, range: Range<u64>, thresholds: &[f64]) -> ChunkStats {
        let (n, p, m) = (dim.get(), self.sys.p(), self.sys.m());
        let sets = self.unsafe_sets.len();
        let mut st = ChunkStats::new(self.times.len(), sets);
        let mut l = Lanes {
            x: vec![0.0; LANES * n],
            f: vec![0.0; LANES * n],
            u: vec![0.0; LANES * p],
            rng: vec![PathRng::new(0, 0); LANES],
            hold: vec![None; LANES],
            alive: vec![true; LANES],
            outside_any: vec![false; LANES],
            left_domain: vec![false; LANES],
            hit: vec![false; LANES * sets],
            z: vec![0.0; m],
            g: vec![0.0; if self.noise.needs_matrix() { n * m } else { 0 }],
            init: vec![0.0; self.initial.scratch_len()],
        };
        let mut first = range.start;
        while first < range.end {
            let lanes = (range.end - first).min(LANES as u64) as usize;
            self.run_lanes(dim, first, lanes, thresholds, &mut l, &mut st);
            first += lanes as u64;
        }
        st
    }

    /// Paths `first .. first + lanes` in lockstep; their records go into `st`.
    fn run_lanes<D: Dim>(
        &self,
        dim: D,
        first: u64,
        lanes: usize,
        thresholds: &[f64],
        l: &mut Lanes,
        st: &mut ChunkStats,
    ) {
        let sys = self.sys;
        let (n, p) = (dim.get(), sys.p());
        let sets = self.unsafe_sets.len();
        let check_sets = sets > 0 || self.domain.is_some();
        for a in 0..lanes {
            l.rng[a] = PathRng::new(self.seed, first + a as u64);
            l.hold[a] = None;
            l.outside_any[a] = false;
            l.left_domain[a] = false;
            let x = &mut l.x[a * n..(a + 1) * n];
            self.initial.sample(&mut l.rng[a], self.zig, x, &mut l.init);
            l.alive[a] = self.record(0, x, thresholds, st, &mut l.outside_any[a]);
        }
        l.hit.fill(false);
        if check_sets {
            for a in 0..lanes {
                let (x, hit) = (
                    &l.x[a * n..(a + 1) * n],
                    &mut l.hit[a * sets..(a + 1) * sets],
                );
                self.check_sets(0.0, x, hit, st, &mut l.left_domain[a]);
            }
        }
        for k in 1..self.times.len() {
            let (t0, t1) = (self.times[k - 1], self.times[k]);
            let nsub = self.substeps[k - 1];
            let h = (t1 - t0) / f64::from(nsub);
            for i in 0..nsub {
                let t = t0 + f64::from(i) * h;
                let t_end = if i + 1 == nsub { t1 } else { t + h };
                for a in 0..lanes {
                    if !l.alive[a] {
                        continue;
                    }
                    let rng = &mut l.rng[a];
                    let u = &mut l.u[a * p..(a + 1) * p];
                    let (x, f) = (&mut l.x[a * n..(a + 1) * n], &mut l.f[a * n..(a + 1) * n]);
                    if p > 0 {
                        self.inputs.update(t, &mut l.hold[a], rng, u);
                    }
                    sys.drift(x, u, t, f);
                    self.noise
                        .step(sys, x, f, t, h, self.zig, rng, &mut l.z, &mut l.g);
                    if check_sets {
                        let hit = &mut l.hit[a * sets..(a + 1) * sets];
                        self.check_sets(t_end, x, hit, st, &mut l.left_domain[a]);
                    }
                }
            }
            for a in 0..lanes {
                if l.alive[a] {
                    let x = &l.x[a * n..(a + 1) * n];
                    l.alive[a] = self.record(k, x, thresholds, st, &mut l.outside_any[a]);
                } else {
                    // A non-finite state stays outside every PRS.
                    st.outside[k] += 1;
                    st.candidates.push((k as u32, f64::INFINITY));
                }
            }
        }
        for a in 0..lanes {
            st.outside_any += u64::from(l.outside_any[a]);
            st.left_domain += u64::from(l.left_domain[a]);
            st.diverged += u64::from(!l.alive[a]);
        }
    }

    /// Records the state at report step `k` (its squared distance and membership); `false` if
    /// it is not finite.
    #[inline(always)]
    fn record(
        &self,
        k: usize,
        x: &[f64],
        thresholds: &[f64],
        st: &mut ChunkStats,
        outside_any: &mut bool,
    ) -> bool {
        let n = x.len();
        let c = &self.nominal[k * n..(k + 1) * n];
        let (q, a) = self.metric.quad(x, c);
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
            *outside_any = true;
        }
        if q > thresholds[k] {
            st.candidates.push((k as u32, q));
        }
        finite
    }

    /// Unsafe-set entries and domain exits at time `t`.
    #[inline]
    fn check_sets(
        &self,
        t: f64,
        x: &[f64],
        hit: &mut [bool],
        st: &mut ChunkStats,
        left_domain: &mut bool,
    ) {
        for (j, set) in self.unsafe_sets.iter().enumerate() {
            if !hit[j] && set.contains(x) {
                hit[j] = true;
                st.unsafe_hits[j] += 1;
                st.first_hit[j] = st.first_hit[j].min(t);
            }
        }
        if let Some(d) = &self.domain {
            if !*left_domain && !d.contains(x) {
                *left_domain = true;
            }
        }
    }
}
