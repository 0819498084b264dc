//! Euler-Maruyama sample paths and their per-chunk statistics (the hot loop).
//!
//! A path is `x_{i+1} = x_i + f(x_i, u_i, t_i) h + G(x_i, t_i) sqrt(h) z_i`, `z_i` standard
//! normal, with the report interval `[t_{k-1}, t_k]` split into equal steps `h <= dt`, so every
//! report time is hit exactly. Everything a path draws comes from its own stream (see
//! [`super::rng`]); the statistics are counts, minima and candidate lists, whose merge does not
//! depend on the order, so the results are the same for any thread count.
//!
//! Four loops run the steps: `additive_lanes` for the common case (constant diagonal noise,
//! no inputs, no unsafe sets or domain, a small model with a non-negative diagonal metric),
//! with every per-step constant in a register; `additive_x8`, the same eight paths at a time
//! in AVX-512 lanes where the processor has them; `lanes_x8`, eight paths in lanes for the
//! other models of at most 4 states, inputs and noise channels and no goal or moving set (the
//! inputs, normals, drift, diffusion, update, unsafe sets, domain and the PRS shortcuts in
//! lanes, the rest of the checks and records in the scalar code); and `step_lanes` for
//! everything else. All compute the same operations in the same order as
//! [`result_paths`](super::result_paths), so the paths are the same whichever loop runs them.
//!
//! Moving unsafe and goal sets (method.md 8.15) are checked in `step_lanes` only: after each
//! Euler step of a block, against the sets where they are at the step's end, placed once for
//! all the block's paths ([`SetRegions::place`]).
//!
//! For a time-uniform result every loop also checks each path's state after every Euler step
//! of report interval `k` against the tube over that interval ([`Tube`], the span `k` of the
//! result; the initial state against span 0), until the path has left it once: the shortcut
//! ([`Tube::inside_by_shortcut`], in the lanes the same comparison per lane) answers almost
//! every state, and the others go to [`Tube::inside_slow`], a function of the state alone, so
//! the loops agree on every decision. A state at a report time outside that time's PRS has
//! left the tube too (the tube there is that PRS).

use super::dt::DtUsed;
use super::initial::InitialSampler;
use super::inputs::InputSchedule;
use super::noise::Noise;
use super::normal::Ziggurat;
use super::prs::{diag_quad, diag_quad_to_box, lanes, quad_small, Membership, Metric, Tube};
use super::regions::{GoalEvent, SetRegions};
use super::rng::PathRng;
use crate::interval::Interval;
use crate::lanes::X8;
use crate::model::ModelInfo;
use crate::sweep;
use crate::system::System;
use std::cmp::Ordering;
use std::ops::Range;

/// The Euler steps between two report times `t0 < t1`: `steps` equal steps of size `h`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Span {
    pub(crate) t0: f64,
    pub(crate) t1: f64,
    pub(crate) steps: u32,
    pub(crate) h: f64,
    /// `sqrt(h)`, once per span rather than per step.
    pub(crate) sqrt_h: f64,
}

impl Span {
    /// `[t0, t1]` in `steps` steps.
    pub(crate) fn new(t0: f64, t1: f64, steps: u32) -> Self {
        let h = (t1 - t0) / f64::from(steps);
        Span {
            t0,
            t1,
            steps,
            h,
            sqrt_h: h.sqrt(),
        }
    }

    /// The start and end of Euler step `i` (the last one ends at `t1` exactly).
    #[inline(always)]
    pub(crate) fn step_times(&self, i: u32) -> (f64, f64) {
        let t = self.t0 + f64::from(i) * self.h;
        (
            t,
            if i + 1 == self.steps {
                self.t1
            } else {
                t + self.h
            },
        )
    }
}

/// Everything a chunk of paths needs, shared read-only by the workers.
pub(crate) struct Plan<'a, S: ?Sized> {
    pub(crate) sys: &'a S,
    pub(crate) seed: u64,
    /// Report times `t_0 = 0 < ... < t_K`.
    pub(crate) times: Vec<f64>,
    /// The Euler steps of report interval `k` (index `k - 1`).
    pub(crate) spans: Vec<Span>,
    /// How the steps were chosen.
    pub(crate) dt: DtUsed,
    /// `x*_{t_k}`, flat (`n` per step).
    pub(crate) nominal: Vec<f64>,
    pub(crate) metric: Metric,
    pub(crate) membership: Membership<'a>,
    /// The time-uniform tube of a uniform result (`None`: pointwise, nothing to check between
    /// report times).
    pub(crate) tube: Option<Tube<'a>>,
    pub(crate) initial: InitialSampler,
    pub(crate) inputs: InputSchedule,
    pub(crate) noise: Noise,
    /// The unsafe sets, goal events and domain (a moving set: at `t = 0`, as the model gives
    /// it).
    pub(crate) sets: SetRegions,
    /// The model, if some of its sets move (method.md 8.15): then the paths are checked, after
    /// each Euler-Maruyama step of a block, against a worker's copy of `sets` with the moving
    /// ones placed where they are at the step's end ([`SetRegions::place`]). `None`: every set
    /// is fixed, and `sets` serve at every step.
    pub(crate) moving: Option<&'a ModelInfo>,
    pub(crate) zig: &'static Ziggurat,
    /// The processor has AVX2, BMI1 and BMI2: the hot loops run in copies compiled for them
    /// (three-operand arithmetic, `mulx`: 11% fewer instructions on the linear example). The
    /// copies do the same IEEE operations in the same order (Rust never fuses a multiply and an
    /// add), so the results do not depend on it.
    pub(crate) avx2: bool,
    /// The processor has AVX-512 (F and DQ): `additive_lanes`' paths run eight at a time in
    /// vector lanes ([`super::avx512`]), which draw the same numbers and do the same IEEE
    /// operations per lane, so the results do not depend on it either.
    pub(crate) avx512: bool,
}

/// One path's progress on one goal.
#[derive(Clone, Copy, Debug)]
struct GoalPath {
    /// Reach: the event has happened.
    reached: bool,
    /// Stay: the start of the path's current run of steps in the goal (NaN: not in it).
    since: f64,
}

impl GoalPath {
    const START: GoalPath = GoalPath {
        reached: false,
        since: f64::NAN,
    };

    /// Whether the path's event has happened, at the horizon (`clean`: it entered no unsafe
    /// set; `alive`: its state stayed finite, else it stays nowhere).
    fn happened(self, event: &GoalEvent, clean: bool, alive: bool) -> bool {
        match event.stay {
            false => self.reached,
            true => alive && clean && self.since <= event.window.1,
        }
    }
}

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
    fn ended(&mut self, k: usize) {
        self.outside[k] += 1;
        self.candidates.push((k as u32, f64::INFINITY));
        let n = self.states;
        self.state_candidates
            .extend((k * n..(k + 1) * n).map(|s| (s as u32, f64::INFINITY)));
    }

    /// The per-state candidates of a state `x` at report step `k` (centre `c`, thresholds
    /// `thr`, one per state).
    #[inline(always)]
    fn record_states(&mut self, k: usize, x: &[f64], c: &[f64], thr: &[f64]) {
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

/// Paths simulated in lockstep by one worker: each Euler step runs over a block of this many
/// paths, one after the other. A path's step is a chain of dependent operations (normals,
/// drift, update, distance) but consecutive paths' chains are independent, so the processor
/// overlaps them; per-step work (span constants, dispatch, bounds) is paid once per block.
/// 64 paths of up to 4 states stay in L1 (counted on the linear example: the per-block work
/// is 9 instructions per path-step with 16 lanes, under 3 with 64; 128 save 2% more).
const LANES: usize = 64;

/// Models with at most this many states keep per-step vectors on the stack.
pub(crate) const SMALL: usize = 4;

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

/// One path's stream and flags.
#[derive(Clone, Copy, Debug)]
struct Path {
    rng: PathRng,
    /// Its input's hold interval.
    hold: Option<u64>,
    /// Its state is finite.
    alive: bool,
    outside_any: bool,
    /// It has left the time-uniform tube (then it is not checked against it again).
    left_tube: bool,
    left_domain: bool,
}

impl Path {
    /// The path leaves the tube in report interval `k` (counted once).
    #[inline(always)]
    fn leave_tube(&mut self, k: usize, st: &mut ChunkStats) {
        if !self.left_tube {
            self.left_tube = true;
            st.left_tube[k] += 1;
        }
    }
}

/// The state of [`LANES`] paths and the worker's scratch, allocated once per chunk, never per
/// step. Per-lane vectors are flat: `max(n, 1)` (or `max(p, 1)`, or one per unsafe set) per
/// lane.
struct Lanes {
    x: Vec<f64>,
    u: Vec<f64>,
    hit: Vec<bool>,
    /// One per goal per lane.
    goal: Vec<GoalPath>,
    paths: [Path; LANES],
    /// Scratch of the general loop: the drift of models larger than [`SMALL`], one path's
    /// normals and `G` (noise that is not constant and diagonal).
    f: Vec<f64>,
    z: Vec<f64>,
    g: Vec<f64>,
    /// With a constant diagonal `G`: `G_ii sqrt(h)` for the current span.
    ds: Vec<f64>,
    /// With [`Membership::inside_below`]: per report step, the squared distances below which a
    /// state needs no record (inside the PRS and not a quantile candidate).
    quiet: Option<Vec<f64>>,
    init: Vec<f64>,
}

/// Eight paths of a block, for the vector lanes: their states (`n` per path), flags and
/// unsafe-set hits (as in [`Lanes`]).
#[cfg(target_arch = "x86_64")]
struct Group<'a> {
    x: &'a mut [f64],
    paths: &'a mut [Path],
    hit: &'a mut [bool],
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
    fn states_at(&self, k: usize, n: usize) -> &[f64] {
        &self.states[k * n..][..n]
    }
}

/// What a step ending at a report time records, besides the step itself.
#[derive(Clone, Copy)]
struct Report<'c> {
    /// The report step.
    k: usize,
    /// Its centre `x*_k`.
    c: &'c [f64],
    /// Its candidate threshold.
    thr: f64,
    /// Its per-state candidate thresholds.
    states: &'c [f64],
    /// Its bound from [`Lanes::quiet`], if any.
    quiet: Option<f64>,
}

/// One Euler step of a block of paths.
struct Step<'a> {
    /// Its start and end times.
    t: f64,
    t_end: f64,
    /// Its report interval `(t_{k-1}, t_k]`.
    k: usize,
    span: &'a Span,
    /// At a report time: what to record.
    report: Option<Report<'a>>,
    /// The block's number of paths.
    lanes: usize,
    /// The first path the scalar loops step (those before ran in vector lanes).
    first: usize,
}

impl<S: System + ?Sized> Plan<'_, S> {
    /// Euler steps per path.
    pub(crate) fn steps_per_path(&self) -> u64 {
        self.spans.iter().map(|s| u64::from(s.steps)).sum()
    }

    /// Simulates the paths `range`; `thresholds` filter the candidates.
    pub(crate) fn run_chunk(&self, range: Range<u64>, thresholds: &Thresholds) -> ChunkStats {
        match self.sys.n() {
            1 => self.run_chunk_in(Fixed::<1>, range, thresholds),
            2 => self.run_chunk_in(Fixed::<2>, range, thresholds),
            3 => self.run_chunk_in(Fixed::<3>, range, thresholds),
            4 => self.run_chunk_in(Fixed::<4>, range, thresholds),
            n => self.run_chunk_in(Dynamic(n), range, thresholds),
        }
    }

    /// [`run_chunk`](Self::run_chunk) with `dim.get() == sys.n()`.
    fn run_chunk_in<D: Dim>(
        &self,
        dim: D,
        range: Range<u64>,
        thresholds: &Thresholds,
    ) -> ChunkStats {
        // Lanes are `max(n, 1)` and `max(p, 1)` wide so that chunking by them never panics.
        let (n, p, m) = (dim.get().max(1), self.sys.p().max(1), self.sys.m());
        let sets = self.sets.unsafe_sets.len();
        let mut st = ChunkStats::new(self.times.len(), sets, self.sets.goals.len(), dim.get());
        let quiet = (0..self.times.len())
            .map(|k| Some(thresholds.metric[k].min(self.membership.inside_below(k)?)))
            .collect();
        let path = Path {
            rng: PathRng::new(0, 0),
            hold: None,
            alive: false,
            outside_any: false,
            left_tube: false,
            left_domain: false,
        };
        let mut l = Lanes {
            x: vec![0.0; LANES * n],
            u: vec![0.0; LANES * p],
            hit: vec![false; LANES * sets.max(1)],
            goal: vec![GoalPath::START; LANES * self.sets.goals.len()],
            paths: [path; LANES],
            f: vec![0.0; n],
            z: vec![0.0; m],
            g: vec![0.0; if self.noise.needs_matrix() { n * m } else { 0 }],
            ds: vec![0.0; n],
            quiet,
            init: vec![0.0; self.initial.scratch_len()],
        };
        // The worker's copy of the regions, for moving sets.
        let mut placed = self.moving.map(|_| self.sets.clone());
        let mut first = range.start;
        while first < range.end {
            let lanes = (range.end - first).min(LANES as u64) as usize;
            self.run_lanes(dim, first, lanes, thresholds, &mut l, &mut placed, &mut st);
            first += lanes as u64;
        }
        st
    }

    /// The regions to check the states against at time `t`: the plan's when every set is
    /// fixed; else `placed` (a worker's copy of them, see [`Plan::moving`]) with the moving
    /// sets placed where they are at `t`.
    fn sets_at<'s>(&'s self, t: f64, placed: &'s mut Option<SetRegions>) -> &'s SetRegions {
        match (self.moving, placed) {
            (Some(info), Some(placed)) => {
                placed.place(info, &sweep::numbers(self.sys, info, Interval::point(t)));
                placed
            }
            _ => &self.sets,
        }
    }

    /// Paths `first .. first + lanes` in lockstep; their records go into `st`. `placed` is the
    /// worker's copy of the regions for moving sets (`None` for fixed ones), placed at every
    /// step's end, once for all the block's paths.
    #[allow(clippy::too_many_arguments)] // the block, its scratch and the chunk's records
    fn run_lanes<D: Dim>(
        &self,
        dim: D,
        first: u64,
        lanes: usize,
        thresholds: &Thresholds,
        l: &mut Lanes,
        placed: &mut Option<SetRegions>,
        st: &mut ChunkStats,
    ) {
        let (n, nn) = (dim.get(), dim.get().max(1));
        let (sets, goals) = (self.sets.unsafe_sets.len().max(1), self.sets.goals.len());
        l.hit.fill(false);
        l.goal.fill(GoalPath::START);
        let at_start = self.sets_at(0.0, placed);
        for (a, path) in l.paths.iter_mut().enumerate().take(lanes) {
            path.rng = PathRng::new(self.seed, first + a as u64);
            path.hold = None;
            path.outside_any = false;
            path.left_tube = false;
            path.left_domain = false;
            let x = &mut l.x[a * nn..][..n];
            self.initial.sample(&mut path.rng, self.zig, x, &mut l.init);
            let qa = self.metric.quad(x, &self.nominal[..n]);
            self.record(0, x, qa, thresholds.metric[0], st, path);
            st.record_states(0, x, &self.nominal[..n], thresholds.states_at(0, n));
            self.check_tube(0, x, path, st);
            let hit = &mut l.hit[a * sets..][..sets];
            let goal = &mut l.goal[a * goals..][..goals];
            at_start.check(0.0, x, hit, goal, &mut path.left_domain, st);
        }
        // The common case, in a loop of its own (`additive_lanes`): no sets, so none moving.
        let additive = n <= SMALL
            && self.sys.p() == 0
            && self.sets.unsafe_sets.is_empty()
            && self.sets.goals.is_empty()
            && self.sets.domain.is_none()
            && self.noise.diagonal().is_some()
            && self.metric.nonneg_diagonal().is_some();
        // With a quiet bound at every report step every step runs `additive_lanes`: then
        // groups of eight paths run in vector lanes, the rest below.
        let mut start = 0;
        #[cfg(target_arch = "x86_64")]
        if let (true, true, Some(quiet)) = (additive, self.avx512, &l.quiet) {
            start = lanes / 8 * 8;
            let groups =
                l.x.chunks_exact_mut(8 * nn)
                    .zip(l.paths.chunks_exact_mut(8));
            for (x, paths) in groups.take(lanes / 8) {
                // SAFETY: `avx512` says the processor has the extensions.
                unsafe { self.additive_x8(dim, x, paths, quiet, thresholds, st) };
            }
        }
        // Other small models: eight paths at a time in `lanes_x8` (fixed unsafe sets only).
        #[cfg(target_arch = "x86_64")]
        if start == 0
            && self.avx512
            && self.lanes_take(n)
            && self.sets.goals.is_empty()
            && self.moving.is_none()
        {
            start = lanes / 8 * 8;
            let groups =
                l.x.chunks_exact_mut(8 * nn)
                    .zip(l.paths.chunks_exact_mut(8))
                    .zip(l.hit.chunks_exact_mut(8 * sets));
            for ((x, paths), hit) in groups.take(lanes / 8) {
                let group = Group { x, paths, hit };
                // SAFETY: `avx512` says the processor has the extensions.
                unsafe { self.lanes_x8(dim, group, l.quiet.as_deref(), thresholds, st) };
            }
        }
        // The paths the lanes did not take, if any.
        let spans = if start < lanes { &self.spans[..] } else { &[] };
        for (k, span) in (1..).zip(spans) {
            if let Some(d) = self.noise.diagonal() {
                for (ds, d) in l.ds.iter_mut().zip(d) {
                    *ds = d * span.sqrt_h;
                }
            }
            for i in 0..span.steps {
                let (t, t_end) = span.step_times(i);
                let report = (i + 1 == span.steps).then(|| Report {
                    k,
                    c: &self.nominal[k * n..][..n],
                    thr: thresholds.metric[k],
                    states: thresholds.states_at(k, n),
                    quiet: l.quiet.as_ref().map(|q| q[k]),
                });
                let step = Step {
                    t,
                    t_end,
                    k,
                    span,
                    report,
                    lanes,
                    first: start,
                };
                let (x, paths) = (&mut l.x[start * nn..], &mut l.paths[start..lanes]);
                let tube = self.tube.is_some();
                if additive && report.is_none() {
                    if tube {
                        self.additive::<D, false, true>(dim, &step, &l.ds, x, paths, st);
                    } else {
                        self.additive::<D, false, false>(dim, &step, &l.ds, x, paths, st);
                    }
                } else if additive && report.is_some_and(|r| r.quiet.is_some()) {
                    if tube {
                        self.additive::<D, true, true>(dim, &step, &l.ds, x, paths, st);
                    } else {
                        self.additive::<D, true, false>(dim, &step, &l.ds, x, paths, st);
                    }
                } else {
                    let sets = self.sets_at(t_end, placed);
                    if self.noise.diagonal().is_some() {
                        self.general::<D, true>(dim, &step, sets, l, st);
                    } else {
                        self.general::<D, false>(dim, &step, sets, l, st);
                    }
                }
            }
        }
        if !self.sets.unsafe_sets.is_empty() {
            let entered = l.hit.chunks_exact(sets).take(lanes);
            st.unsafe_any += entered.filter(|h| h.contains(&true)).count() as u64;
        }
        for (a, path) in l.paths[..lanes].iter().enumerate() {
            st.outside_any += u64::from(path.outside_any);
            st.outside_tube += u64::from(path.left_tube);
            st.left_domain += u64::from(path.left_domain);
            st.diverged += u64::from(!path.alive);
            let clean = !l.hit[a * sets..][..sets].contains(&true);
            let events = self.sets.goals.iter().zip(&l.goal[a * goals..][..goals]);
            for (n, (event, p)) in st.goal_reached.iter_mut().zip(events) {
                *n += u64::from(p.happened(event, clean, path.alive));
            }
        }
    }

    /// Whether [`lanes_x8`](Self::lanes_x8) takes a model with `n` states: at most [`SMALL`]
    /// states, inputs and channels.
    fn lanes_take(&self, n: usize) -> bool {
        n <= SMALL && self.sys.m() <= SMALL && self.sys.p() <= SMALL
    }

    /// One Euler-Maruyama step of the block's paths, then (at a report time) their records. A
    /// path draws its inputs, then its `m` normals in channel order (as
    /// [`result_paths`](super::result_paths) does). `DIAG`: `G` is constant and diagonal.
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

    /// The record of `path`'s state `x` at the report step `rep`, given `(q, a) =
    /// metric.quad(x, x*_k)`, unless a shortcut finds it quiet (inside the PRS and not a
    /// quantile candidate). `shortcuts` is [`Membership::has_shortcuts`].
    #[inline(always)]
    fn report(
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
    fn quiet_x8(&self, rep: &Report<'_>, shortcuts: bool, x: &[X8], q: X8, a: X8) -> u8 {
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
    /// every span, in the lanes of AVX-512 registers ([`super::avx512`]): the same draws and
    /// the same IEEE operations in the same order per lane (the drift by
    /// [`System::drift_x8`]), so the same paths and records; the tube's shortcut is the same
    /// comparison per lane, and the lanes it does not answer go to the same scalar test.
    /// `quiet` is [`Lanes::quiet`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq")]
    fn additive_x8<D: Dim>(
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
        let mut group = super::avx512::Group8::new(n, x, std::array::from_fn(|a| paths[a].rng));
        let mut f = [X8::splat(0.0); SMALL];
        for (k, span) in (1..).zip(&self.spans) {
            let h = span.h;
            let ds = std::array::from_fn(|i| if i < n { g[i] * span.sqrt_h } else { 0.0 });
            let (lo, hi, q_in) = match &self.tube {
                Some(tube) => tube.diag_bounds(k),
                None => (&[][..], &[][..], f64::INFINITY),
            };
            for step in 0..span.steps {
                let t = span.t0 + f64::from(step) * h;
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

    /// [`step_lanes`](Self::step_lanes) for eight paths (`group`) of a model with at most
    /// [`SMALL`] states, inputs and channels and no goal or moving set, through every span: the
    /// inputs, the normals, the drift and a state-dependent diffusion (by
    /// [`System::drift_x8`] and [`System::diffusion_x8`]), the update and the unsafe sets and
    /// domain in the lanes of AVX-512 registers, with the same draws and IEEE operations per
    /// lane as `step_lanes`, so the same states and hits; each state then goes through the same
    /// scalar tube check and record as there. `quiet` is [`Lanes::quiet`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq")]
    fn lanes_x8<D: Dim>(
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
        let mut group = super::avx512::Group8::new(n, x, std::array::from_fn(|a| paths[a].rng));
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

    /// [`step_lanes`](Self::step_lanes), compiled for the processor's extensions.
    #[inline(never)]
    fn general<D: Dim, const DIAG: bool>(
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

    /// [`additive_lanes`](Self::additive_lanes), compiled for the processor's extensions.
    #[inline(never)]
    fn additive<D: Dim, const REPORT: bool, const TUBE: bool>(
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

    /// Checks `path`'s state `x` in report interval `k` against the tube, if there is one and
    /// the path has not left it yet.
    #[inline(always)]
    fn check_tube(&self, k: usize, x: &[f64], path: &mut Path, st: &mut ChunkStats) {
        if let Some(tube) = &self.tube {
            if !path.left_tube && !tube.inside_by_shortcut(&self.metric, k, x) {
                self.tube_slow(k, x, path, st);
            }
        }
    }

    /// [`check_tube`](Self::check_tube) for a state the shortcut did not find inside.
    #[cold]
    #[inline(never)]
    fn tube_slow(&self, k: usize, x: &[f64], path: &mut Path, st: &mut ChunkStats) {
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
    fn record(
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

impl SetRegions {
    /// Unsafe-set entries, goal progress and domain exits of a path at time `t`.
    #[inline(always)]
    fn check(
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
    fn check_x8(
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

#[cfg(test)]
mod tests {
    use super::super::{make_plan, InputMode, Options};
    use super::*;
    use crate::engine;
    use crate::interval::Interval;
    use crate::model::*;
    use crate::test_support::models::{pendulum_model, PENDULUM_METRIC};
    use crate::test_support::systems::Pendulum;

    /// The pendulum of specs/pendulum.sde: one noise channel on the second state (constant
    /// `G` that is not diagonal), a drift with `sin`.
    const PENDULUM: Pendulum = Pendulum::PAPER;

    /// The pendulum's model; its analysis `method` with the paper's (full) metric.
    fn pendulum(method: Method) -> ModelInfo {
        let mut info = pendulum_model();
        let constants = Constants::given(&info, PENDULUM_METRIC.to_vec(), -0.5, 0.12, 0.0);
        info.analyses.push(Analysis {
            spec: AnalysisSpec {
                name: "a".into(),
                method,
                delta: 1e-3,
                horizon: 1.0,
                step: 0.02,
                ..AnalysisSpec::default()
            },
            constants: Ok(constants),
        });
        info
    }

    /// The portable part of `lanes_x8`, on any processor: eight paths stepped with the lane
    /// kernels (`InputSchedule::update_x8`, `System::drift_x8`, `Noise::apply_x8`,
    /// `SetRegions::check_x8`), each lane drawing its normals from its own stream as the
    /// AVX-512 lanes do (that they draw the same numbers is `avx512`'s test), against the same
    /// paths stepped one by one as `step_lanes` does: the same states to the bit after every
    /// step, and the same unsafe-set hits, first hit times and domain exits. The pendulum
    /// (constant `G` that is not diagonal), with state-dependent noise, and forced by an input
    /// in each input mode, with unsafe sets and a domain the paths enter and leave. What only
    /// runs on AVX-512 (the registers' streams and loads) is
    /// [`lanes_do_not_change_the_paths`].
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn lane_kernels_step_as_the_scalar_loop() {
        use crate::test_support::rng::Rng;
        let info = pendulum(Method::Interval);
        let r = engine::run_paired(&PENDULUM, &info, &info.analyses[0]).unwrap();
        let regions = with_regions(&info, true);
        let forced = with_input(&regions);
        let modes = [InputMode::Random, InputMode::Corners, InputMode::Centre];
        let systems = [
            (&PENDULUM as &dyn System, &regions, InputMode::Random),
            (&MULTIPLICATIVE, &regions, InputMode::Random),
        ]
        .into_iter()
        .chain(modes.map(|mode| (&FORCED as &dyn System, &forced, mode)));
        let mut start = Rng(0x1a4e5);
        let (mut hits, mut exits) = (0, 0);
        for (sys, info, mode) in systems {
            let opts = Options {
                inputs: mode,
                hold: Some(0.05),
                ..Options::default()
            };
            let plan = make_plan(sys, info, &r, &opts).unwrap();
            let (n, m, p, sets) = (sys.n(), sys.m(), sys.p(), plan.sets.unsafe_sets.len());
            let case = format!("{p} inputs ({mode:?}), G(x): {}", plan.noise.needs_matrix());
            // Four corners of the initial box (two heading out of the domain) and four inside.
            let a = std::f64::consts::PI / 10.0;
            let x: Vec<[f64; 2]> = [[a, 0.2], [-a, -0.2], [a, -0.2], [-a, 0.2]]
                .into_iter()
                .chain((0..4).map(|_| [start.range(-a, a), start.range(-0.2, 0.2)]))
                .collect();
            // The lanes' and the scalar loop's states, inputs, normals, drift, G, paths, hits.
            let mut xl: [X8; SMALL] = std::array::from_fn(|i| {
                X8(std::array::from_fn(|l| if i < n { x[l][i] } else { 0.0 }))
            });
            let (mut ul, mut zl) = ([X8::splat(0.0); SMALL], [X8::splat(0.0); SMALL]);
            let (mut fl, mut gl) = ([X8::splat(0.0); SMALL], [X8::splat(0.0); SMALL * SMALL]);
            let mut hold = None;
            let path = |l: usize| Path {
                rng: PathRng::new(17, l as u64),
                hold: None,
                alive: true,
                outside_any: false,
                left_tube: false,
                left_domain: false,
            };
            let mut lanes: Vec<Path> = (0..8).map(path).collect();
            let mut scalar = lanes.clone();
            let (mut hit_l, mut hit_s) = (vec![false; 8 * sets], vec![false; 8 * sets]);
            let stats = || ChunkStats::new(plan.times.len(), sets, 0, n);
            let (mut st_l, mut st_s) = (stats(), stats());
            let mut xs = x.clone();
            // Each path holds its own inputs between draws.
            let mut us = [[0.0; SMALL]; 8];
            let (mut z, mut f, mut g) = ([0.0; SMALL], [0.0; 2], [0.0; 2]);
            for span in &plan.spans {
                for i in 0..span.steps {
                    let (t, t_end) = span.step_times(i);
                    if p > 0 {
                        let next = || std::array::from_fn(|l| lanes[l].rng.next_u64());
                        plan.inputs.update_x8(t, &mut hold, next, &mut ul[..p]);
                    }
                    for zj in &mut zl[..m] {
                        *zj = X8(std::array::from_fn(|l| plan.zig.sample(&mut lanes[l].rng)));
                    }
                    sys.drift_x8(&xl[..n], &ul[..p], t, &mut fl[..n]);
                    let (h, sqrt_h) = (span.h, span.sqrt_h);
                    let (xn, fnn) = (&mut xl[..n], &fl[..n]);
                    plan.noise
                        .apply_x8(sys, xn, fnn, t, h, sqrt_h, &mut zl[..m], &mut gl[..n * m]);
                    plan.sets
                        .check_x8(t_end, &xl[..n], 0xff, &mut hit_l, &mut lanes, &mut st_l);
                    for (l, (x, path)) in xs.iter_mut().zip(&mut scalar).enumerate() {
                        let u = &mut us[l];
                        if p > 0 {
                            plan.inputs
                                .update(t, &mut path.hold, &mut path.rng, &mut u[..p]);
                        }
                        for zj in &mut z[..m] {
                            *zj = plan.zig.sample(&mut path.rng);
                        }
                        sys.drift(x, &u[..p], t, &mut f);
                        plan.noise
                            .apply(sys, x, &f, t, h, sqrt_h, &mut z[..m], &mut g);
                        let hit = &mut hit_s[l * sets..][..sets];
                        plan.sets
                            .check(t_end, x, hit, &mut [], &mut path.left_domain, &mut st_s);
                        for (j, xj) in x.iter().enumerate() {
                            let lane = xl[j].0[l];
                            assert_eq!(lane.to_bits(), xj.to_bits(), "{case}, t = {t}, lane {l}");
                        }
                    }
                }
            }
            assert_eq!(hit_l, hit_s, "{case}");
            assert_eq!(st_l, st_s, "{case}");
            let flags = |paths: &[Path]| paths.iter().map(|p| p.left_domain).collect::<Vec<_>>();
            assert_eq!(flags(&lanes), flags(&scalar), "{case}");
            for (a, b) in lanes.iter().zip(&scalar) {
                assert_eq!(
                    a.rng.state(),
                    b.rng.state(),
                    "{case}: the streams moved alike"
                );
            }
            hits += hit_s.iter().filter(|&&h| h).count();
            exits += flags(&scalar).iter().filter(|&&e| e).count();
        }
        // Not vacuous: the paths enter unsafe sets and leave the domain.
        assert!(hits > 10, "{hits}");
        assert!(exits > 0, "{exits}");
    }

    /// Eight paths in lanes (`lanes_x8`; of 203 paths, the last three in the scalar loops)
    /// against the scalar loops, path by path: a constant `G` that is not diagonal, a full
    /// metric, the contraction method's intersection with its interval box (time-uniform: the
    /// tube at every step; and pointwise) and the interval method's box, with and without
    /// quantile candidates, and with sets narrowed so that paths leave them (then also with
    /// unsafe sets and a domain, checked after every step); the pendulum, the pendulum with
    /// state-dependent noise, and a forced pendulum in each input mode. The records, counts,
    /// tube exits, unsafe-set hits with their first times, and domain exits are the same.
    ///
    /// The lanes need AVX-512 (F and DQ). Where the processor that built the tests has none,
    /// the test is ignored (`cargo test` lists it as such: a skip that shows, not a pass), and
    /// [`lane_kernels_step_as_the_scalar_loop`] still checks the portable kernels; the build
    /// script decides (`reachc_avx512`). `REACHC_REQUIRE_AVX512=1` at build time runs it
    /// regardless, so that a machine meant to test the lanes fails without them.
    #[cfg(target_arch = "x86_64")]
    #[cfg_attr(
        not(reachc_avx512),
        ignore = "no AVX-512 (F and DQ) on the machine that built the tests: the lanes cannot run"
    )]
    #[test]
    fn lanes_do_not_change_the_paths() {
        super::super::avx512::require();
        // The lanes record a group's steps in turn, the scalar loops a step's paths.
        let sorted = ChunkStats::sorted;
        let (mut outside, mut hits, mut late) = (0, 0, 0.0_f64);
        for method in [Method::Contraction, Method::Interval] {
            for guarantee in [Guarantee::Uniform, Guarantee::Pointwise] {
                let info = pendulum(method);
                let mut r = engine::run_paired(&PENDULUM, &info, &info.analyses[0]).unwrap();
                r.guarantee = guarantee;
                if method == Method::Contraction {
                    assert!(!r.also.is_empty(), "an intersection");
                }
                for narrow in [false, true] {
                    if narrow {
                        // Radii and spans at a third: some paths leave the sets.
                        for st in &mut r.steps {
                            st.prs_radius /= 3.0;
                            st.span.radius /= 3.0;
                        }
                    }
                    // With unsafe sets and a domain (checked after every step), and without;
                    // the pendulum, with state-dependent noise, and forced by an input in each
                    // of the input modes.
                    let regions = with_regions(&info, narrow);
                    let forced = with_input(&regions);
                    let modes = [InputMode::Random, InputMode::Corners, InputMode::Centre];
                    let systems = [
                        (&PENDULUM as &dyn System, &regions, InputMode::Random, true),
                        (&MULTIPLICATIVE, &regions, InputMode::Random, false),
                    ]
                    .into_iter()
                    .chain(modes.map(|mode| (&FORCED as &dyn System, &forced, mode, true)));
                    for ((sys, info, mode, constant), threshold) in
                        systems.flat_map(|s| [(s, f64::NEG_INFINITY), (s, 0.5)])
                    {
                        let opts = Options {
                            inputs: mode,
                            hold: Some(0.05),
                            ..Options::default()
                        };
                        let mut plan = make_plan(sys, info, &r, &opts).unwrap();
                        assert!(plan.lanes_take(2) && plan.noise.diagonal().is_none());
                        assert_eq!(plan.noise.needs_matrix(), !constant);
                        let thresholds =
                            Thresholds::uniform(plan.times.len(), plan.sys.n(), threshold);
                        plan.avx512 = true;
                        let lanes = sorted(plan.run_chunk(0..203, &thresholds));
                        plan.avx512 = false;
                        let scalar = sorted(plan.run_chunk(0..203, &thresholds));
                        let case = format!(
                            "{method:?} {guarantee:?} narrow {narrow} {threshold} inputs {} \
                             {mode:?}",
                            sys.p()
                        );
                        assert_eq!(lanes, scalar, "{case}");
                        outside += scalar.outside_any + scalar.outside_tube;
                        hits += scalar.unsafe_hits.iter().sum::<u64>() + scalar.left_domain;
                        if let Some(&t) = scalar.first_hit.get(1).filter(|t| t.is_finite()) {
                            late = late.max(t);
                        }
                    }
                }
            }
        }
        // Not vacuous: the narrowed sets are left, the unsafe sets hit, the domain left.
        assert!(outside > 100, "{outside}");
        assert!(hits > 100, "{hits}");
        assert!(late > 0.0, "the ball is first entered after the start");
    }

    /// [`Pendulum`], `forced` by an input `u` on the second state (`omega' = ... + u`), or with
    /// `multiplicative` noise (`G = [0, 0.1 + 0.05 sin theta]'`).
    struct Variant {
        forced: bool,
        multiplicative: bool,
    }

    const FORCED: Variant = Variant {
        forced: true,
        multiplicative: false,
    };
    const MULTIPLICATIVE: Variant = Variant {
        forced: false,
        multiplicative: true,
    };

    impl System for Variant {
        fn n(&self) -> usize {
            2
        }
        fn p(&self) -> usize {
            usize::from(self.forced)
        }
        fn m(&self) -> usize {
            1
        }
        fn drift(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
            PENDULUM.drift(x, u, t, out);
            if self.forced {
                out[1] += u[0];
            }
        }
        fn drift_interval(&self, x: &[Interval], u: &[Interval], t: Interval, o: &mut [Interval]) {
            PENDULUM.drift_interval(x, u, t, o);
            if self.forced {
                o[1] += u[0];
            }
        }
        fn jac_x(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
            PENDULUM.jac_x(x, u, t, out);
        }
        fn jac_x_interval(&self, x: &[Interval], u: &[Interval], t: Interval, o: &mut [Interval]) {
            PENDULUM.jac_x_interval(x, u, t, o);
        }
        fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
            if self.forced {
                out.copy_from_slice(&[0.0, 1.0]);
            }
        }
        fn jac_u_interval(&self, _: &[Interval], _: &[Interval], _: Interval, o: &mut [Interval]) {
            if self.forced {
                o.copy_from_slice(&[Interval::ZERO, Interval::ONE]);
            }
        }
        fn diffusion(&self, x: &[f64], t: f64, out: &mut [f64]) {
            if self.multiplicative {
                out.copy_from_slice(&[0.0, 0.1 + 0.05 * x[0].sin()]);
            } else {
                PENDULUM.diffusion(x, t, out);
            }
        }
        fn diffusion_interval(&self, x: &[Interval], t: Interval, o: &mut [Interval]) {
            if self.multiplicative {
                let p = Interval::point;
                o.copy_from_slice(&[Interval::ZERO, p(0.1) + p(0.05) * x[0].sin()]);
            } else {
                PENDULUM.diffusion_interval(x, t, o);
            }
        }
    }

    /// `info` for [`FORCED`]: its input in `[-0.5, 1]`.
    fn with_input(info: &ModelInfo) -> ModelInfo {
        let mut info = info.clone();
        info.inputs = vec!["u".into()];
        info.input_box = vec![Bounds::new(-0.5, 1.0)];
        info
    }

    /// `info` with three unsafe sets (a box, a ball and a half-space, which pendulum paths
    /// enter, the ball only after the start) and a domain that some leave, if `add`.
    fn with_regions(info: &ModelInfo, add: bool) -> ModelInfo {
        let mut info = info.clone();
        if add {
            let set = |name: &str, shape| UnsafeSet {
                name: name.into(),
                shape,
                moving: Vec::new(),
            };
            info.unsafe_sets = vec![
                set("box", UnsafeShape::Box(vec![(1, Bounds::new(0.12, 1.0))])),
                set(
                    "ball",
                    UnsafeShape::Ball {
                        states: vec![0, 1],
                        center: vec![0.15, -0.0765],
                        radius: 0.01,
                    },
                ),
                set(
                    "half",
                    UnsafeShape::HalfSpace {
                        normal: vec![1.0, 0.5],
                        offset: 0.3,
                    },
                ),
            ];
            info.domain = vec![Bounds::new(-0.315, 0.315), Bounds::ENTIRE];
            info.has_domain = true;
        }
        info
    }
}
