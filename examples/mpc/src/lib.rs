//! A model-predictive controller on the stochastic cart of `cart.sde` (compiled by `build.rs`):
//! every control period it measures the cart, asks [`Reach`] for the stochastic radii of the
//! next second from that state ([`Reach::from_box`]), tightens its constraints by them
//! ([`Reach::tighten`], method.md 8.14), and picks the input whose noise-free plan meets the
//! tightened constraints and comes closest to the wall. The noisy plant then runs one period
//! under that input ([`Plant`]).
//!
//! The guarantee is per plan: if the nominal under a plan meets the tightened constraints over
//! the plan's report intervals, the stochastic cart under the same plan meets the original ones
//! over the whole second with probability at least `1 - delta` (the analysis is uniform in
//! time). The planner checks the nominal on a grid of [`H`] within each interval.

mod cart {
    reachc_runtime::include_sde!("cart");
}

pub use cart::*;

use rand::rngs::SmallRng;
use rand::{RngExt, SeedableRng};
use reachc_runtime::engine::{Constraint, RunError, TightStep, TightenError};
use reachc_runtime::model::{Bounds, UnsafeShape};
use reachc_runtime::{Reach, System};
use std::fmt;
use std::time::{Duration, Instant};

/// The planner's integration step for the nominal (s).
pub const H: f64 = 0.01;
/// The control period: the plan's first report interval (s).
pub const PERIOD: f64 = 0.1;
/// The state constraint on the speed: `|v| <= SPEED`.
pub const SPEED: f64 = 1.0;

/// A planning failure.
#[derive(Debug)]
pub enum PlanError {
    /// The reachability run from the measured state failed.
    Reach(RunError),
    /// The constraints could not be tightened.
    Tighten(TightenError),
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlanError::Reach(e) => write!(f, "reachability from the measured state: {e}"),
            PlanError::Tighten(e) => write!(f, "tightening: {e}"),
        }
    }
}

impl std::error::Error for PlanError {}

/// One plan: the input held over the next period, and what choosing it showed.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The force applied over the next period.
    pub force: f64,
    /// Whether the chosen nominal meets every tightened constraint over the plan's horizon (when
    /// no candidate does, the one that violates them least is applied).
    pub feasible: bool,
    /// The wall as the nominal must avoid it at the end of the horizon: `p < wall`.
    pub wall: f64,
    /// The time the reachability run and the tightening took together.
    pub reach_time: Duration,
}

/// The receding-horizon controller: constant forces from a grid of candidates, each checked
/// on its noise-free plan against the constraints tightened from the current state.
pub struct Planner<'a> {
    reach: Reach<'a>,
    candidates: Vec<f64>,
}

impl<'a> Planner<'a> {
    /// A planner on the analysis `plan` of the cart, with `count` candidate forces evenly
    /// spread over the input box `[-1, 1]`.
    pub fn new(sys: &'a Cart, count: usize) -> Self {
        let reach = Reach::new(sys, analysis::PLAN).expect("the spec has the analysis `plan`");
        let candidates = (0..count)
            .map(|i| -1.0 + 2.0 * i as f64 / (count - 1) as f64)
            .collect();
        Planner { reach, candidates }
    }

    /// The constraints tightened for plans from the measured state `x` (one step per report
    /// interval of the plan): the speed box and the model's wall.
    pub fn tightened(&self, x: [f64; 2]) -> Result<Vec<TightStep>, PlanError> {
        let start = [Bounds::new(x[0], x[0]), Bounds::new(x[1], x[1])];
        let prs = self.reach.from_box(&start).map_err(PlanError::Reach)?;
        let speed = Constraint::Box(vec![(1, Bounds::new(-SPEED, SPEED))]);
        let t = self
            .reach
            .tighten(&prs, &[speed])
            .map_err(PlanError::Tighten)?;
        Ok(t.steps)
    }

    /// The plan from the measured state `x`: the feasible candidate that ends closest to the
    /// wall (the least violating one if none is feasible).
    pub fn plan(&self, sys: &Cart, x: [f64; 2]) -> Result<Plan, PlanError> {
        let clock = Instant::now();
        let steps = self.tightened(x)?;
        let reach_time = clock.elapsed();
        let wall = match &steps.last().map(|s| &s.unsafe_sets[0].shape) {
            Some(UnsafeShape::HalfSpace { offset, .. }) => *offset,
            _ => f64::NAN,
        };
        let best = self
            .candidates
            .iter()
            .map(|&force| {
                let (violation, end) = violation(sys, x, force, &steps);
                (force, violation, end)
            })
            .min_by(|a, b| {
                // Feasible first, then closest to the wall; else the smallest violation.
                let key = |c: &(f64, f64, f64)| (c.1 > 0.0, if c.1 > 0.0 { c.1 } else { -c.2 });
                key(a)
                    .partial_cmp(&key(b))
                    .unwrap_or(std::cmp::Ordering::Equal)
            })
            .expect("at least one candidate");
        Ok(Plan {
            force: best.0,
            feasible: best.1 <= 0.0,
            wall,
            reach_time,
        })
    }
}

/// The nominal from `x` under the constant `force`, by RK4 steps of [`H`], against the tightened
/// `steps`: the largest violation of a constraint or of the inflated wall (0 when it meets
/// them all) and the position at the end of the horizon.
pub fn violation(sys: &Cart, x: [f64; 2], force: f64, steps: &[TightStep]) -> (f64, f64) {
    let mut x = x;
    let mut t = 0.0;
    let mut worst = 0.0f64;
    let mut check = |x: &[f64; 2], step: &TightStep| {
        for c in &step.constraints {
            if let Constraint::Box(coords) = c {
                for (i, b) in coords {
                    worst = worst.max(b.lo - x[*i]).max(x[*i] - b.hi);
                }
            }
        }
        for u in &step.unsafe_sets {
            if let UnsafeShape::HalfSpace { normal, offset } = &u.shape {
                let dot: f64 = normal.iter().zip(x).map(|(a, b)| a * b).sum();
                worst = worst.max(dot - offset);
            }
        }
    };
    check(&x, &steps[0]);
    for step in &steps[1..] {
        while t < step.t - 1e-9 {
            rk4(sys, &mut x, t, force);
            t += H;
            check(&x, step);
        }
    }
    (worst, x[0])
}

/// One RK4 step of [`H`] of the noise-free cart under a constant `force`.
fn rk4(sys: &Cart, x: &mut [f64; 2], t: f64, force: f64) {
    let f = |x: &[f64; 2], t: f64| {
        let mut out = [0.0; 2];
        sys.drift(x, &[force], t, &mut out);
        out
    };
    let along = |x: &[f64; 2], k: &[f64; 2], s: f64| [x[0] + s * k[0], x[1] + s * k[1]];
    let k1 = f(x, t);
    let k2 = f(&along(x, &k1, 0.5 * H), t + 0.5 * H);
    let k3 = f(&along(x, &k2, 0.5 * H), t + 0.5 * H);
    let k4 = f(&along(x, &k3, H), t + H);
    for i in 0..2 {
        x[i] += H / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

/// The noisy cart: Euler-Maruyama steps of `dt`, seeded.
pub struct Plant {
    /// The state `(p, v)`.
    pub x: [f64; 2],
    rng: SmallRng,
    dt: f64,
}

impl Plant {
    /// A cart at `x`; `seed` fixes its noise, `dt` its Euler-Maruyama step.
    pub fn new(x: [f64; 2], seed: u64, dt: f64) -> Self {
        Plant {
            x,
            rng: SmallRng::seed_from_u64(seed),
            dt,
        }
    }

    /// Runs the cart for `duration` under a constant `force`; returns whether it touched the
    /// wall (`p >= 0.8`) or broke the speed limit at any step.
    pub fn run(&mut self, sys: &Cart, force: f64, duration: f64) -> bool {
        let (mut f, mut g) = ([0.0; 2], [0.0; 2]);
        let mut broke = false;
        let steps = (duration / self.dt).round() as usize;
        for k in 0..steps {
            let t = k as f64 * self.dt;
            sys.drift(&self.x, &[force], t, &mut f);
            sys.diffusion(&self.x, t, &mut g);
            let dw = self.normal() * self.dt.sqrt();
            for i in 0..2 {
                self.x[i] += f[i] * self.dt + g[i] * dw;
            }
            broke |= self.x[0] >= 0.8 || self.x[1].abs() > SPEED;
        }
        broke
    }

    /// A standard normal (Box-Muller).
    fn normal(&mut self) -> f64 {
        let u: f64 = 1.0 - self.rng.random::<f64>();
        let v: f64 = self.rng.random();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// What a closed-loop run measured.
#[derive(Clone, Debug, Default)]
pub struct Summary {
    /// Control periods run.
    pub periods: usize,
    /// Periods in which the plant touched the wall or broke the speed limit.
    pub violations: usize,
    /// Periods in which no candidate met the tightened constraints.
    pub infeasible: usize,
    /// The time of each reachability call with its tightening.
    pub reach_times: Vec<Duration>,
    /// The plant's position after each period.
    pub positions: Vec<f64>,
    /// The tightened wall at the end of each plan.
    pub walls: Vec<f64>,
}

/// `periods` control periods of the closed loop from rest, the plant's noise seeded by `seed`.
pub fn closed_loop(sys: &Cart, periods: usize, seed: u64) -> Result<Summary, PlanError> {
    let planner = Planner::new(sys, 21);
    let mut plant = Plant::new([0.0, 0.0], seed, 1e-3);
    let mut s = Summary::default();
    for _ in 0..periods {
        let plan = planner.plan(sys, plant.x)?;
        s.infeasible += usize::from(!plan.feasible);
        s.reach_times.push(plan.reach_time);
        s.walls.push(plan.wall);
        s.violations += usize::from(plant.run(sys, plan.force, PERIOD));
        s.positions.push(plant.x[0]);
        s.periods += 1;
    }
    Ok(s)
}
