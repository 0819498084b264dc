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

mod additive;
mod general;
#[cfg(target_arch = "x86_64")]
mod lanes_x8;
mod record;
mod sets;
mod stats;
#[cfg(test)]
mod tests;

pub(crate) use stats::{ChunkStats, Thresholds};

use super::check::{Membership, Metric, Tube};
use super::dt::DtUsed;
use super::initial::InitialSampler;
use super::inputs::InputSchedule;
use super::noise::Noise;
use super::normal::Ziggurat;
use super::regions::SetRegions;
use super::rng::PathRng;
use crate::interval::Interval;
use crate::model::ModelInfo;
use crate::sweep;
use crate::system::System;
use sets::GoalPath;
use std::ops::Range;

/// The Euler steps between two report times `t0 < t1`: `steps` equal steps of length `dt`,
/// each `x += h f + sqrt(h) G z` (`h = dt`; `h = 1` for the steps of a map, [`Span::map`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Span {
    pub(crate) t0: f64,
    pub(crate) t1: f64,
    pub(crate) steps: u32,
    /// The time a step takes.
    pub(crate) dt: f64,
    /// The drift's factor in the update.
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
            dt: h,
            h,
            sqrt_h: h.sqrt(),
        }
    }

    /// `[t0, t1]` in `steps` steps of a discrete-time model's map, simulated as its increments
    /// ([`Increments`](super::increments::Increments)): `h = sqrt(h) = 1`.
    pub(crate) fn map(t0: f64, t1: f64, steps: u32) -> Self {
        Span {
            t0,
            t1,
            steps,
            dt: (t1 - t0) / f64::from(steps),
            h: 1.0,
            sqrt_h: 1.0,
        }
    }

    /// The start and end of Euler step `i` (the last one ends at `t1` exactly).
    #[inline(always)]
    pub(crate) fn step_times(&self, i: u32) -> (f64, f64) {
        let t = self.t0 + f64::from(i) * self.dt;
        (
            t,
            if i + 1 == self.steps {
                self.t1
            } else {
                t + self.dt
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
}
