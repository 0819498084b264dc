//! A validated nominal trajectory for the contraction method (method.md section 8.4): the
//! engine chooses internal steps, joins RK4 nodes by cubic Hermite pieces `p`, and bounds the
//! defect `d(s) = p'(s) - f(p(s), u, s)` rigorously over every step. With the contraction rate
//! `c` (for all states and inputs of the domain), every trajectory `x` from the initial set
//! satisfies `D+ |x - p|_P <= c |x - p|_P + rho r2 + |d|_P`, so `R_t` of Proposition 2 grows by
//! the defect's integral: `p` need not be exact, only its defect bounded.
//!
//! The defect on a piece `[a, b]` of a step, centre `m`, by the mean value theorem:
//! `p(s) - p(m) in p'([a, b]) (s - m)` and `p'(s) - p'(m) in p''([a, b]) (s - m)`, and
//! `f(p(s)) - f(p(m)) in J (p(s) - p(m))` with `J` the interval Jacobian over the hull of
//! `p([a, b])`, so `d(s) in p'(m) - f(p(m), u, [a, b]) + (p''([a, b]) - J p'([a, b])) [a - m, b - m]`:
//! a small first term (the Hermite error), and a second that shrinks with the piece.

use super::hermite::{Cubic, Piece, PIECES};
use super::radius::BoxRadius;
use super::rosenbrock;
use super::{Culprit, Detail, Integrated, Problem, RunError, Setting};
use crate::interval::Interval;
use crate::system::System;

/// The most internal steps of one analysis.
pub(crate) const MAX_STEPS: usize = 2_000_000;

/// The most internal steps in one report interval.
pub(crate) const MAX_STEPS_PER_REPORT: usize = 10_000;

/// Counts a run's internal steps against [`MAX_STEPS`] and [`MAX_STEPS_PER_REPORT`], so that an
/// enclosure creeping towards a blow-up stops early with a diagnostic.
pub(crate) struct StepBudget {
    /// What is integrated.
    what: Integrated,
    total: usize,
    in_interval: usize,
    /// The most steps in all ([`MAX_STEPS`] unless [`StepBudget::at_most`] lowers it).
    limit: usize,
    /// The most steps in one report interval ([`MAX_STEPS_PER_REPORT`] unless
    /// [`StepBudget::at_most`] lowers it).
    interval_limit: usize,
}

impl StepBudget {
    pub(crate) fn new(what: Integrated) -> Self {
        StepBudget {
            what,
            total: 0,
            in_interval: 0,
            limit: MAX_STEPS,
            interval_limit: MAX_STEPS_PER_REPORT,
        }
    }

    /// The same budget with at most `limit` steps in all and `per_interval` in one report
    /// interval (never more than [`MAX_STEPS`] and [`MAX_STEPS_PER_REPORT`]).
    pub(crate) fn at_most(self, limit: usize, per_interval: usize) -> Self {
        StepBudget {
            limit: limit.min(MAX_STEPS),
            interval_limit: per_interval.min(MAX_STEPS_PER_REPORT),
            ..self
        }
    }

    /// Starts a report interval.
    pub(crate) fn next_interval(&mut self) {
        self.in_interval = 0;
    }

    /// Takes one step at `t` in the report interval `window`, or says why not.
    pub(crate) fn take(&mut self, t: f64, window: &[f64]) -> Result<(), RunError> {
        let what = self.what;
        if self.total >= self.limit {
            return Err(RunError::NonFinite(
                Detail::from(Problem::TooManySteps {
                    what,
                    limit: self.limit,
                    t,
                })
                .at_setting(Setting::Horizon),
            ));
        }
        if self.in_interval >= self.interval_limit {
            return Err(RunError::NonFinite(
                Detail::from(Problem::TooManyStepsInInterval {
                    what,
                    limit: self.interval_limit,
                    window: [window[0], window[1]],
                    t,
                })
                .at_setting(Setting::Step),
            ));
        }
        self.total += 1;
        self.in_interval += 1;
        Ok(())
    }
}

/// The shortest internal step, as a fraction of the report step: a step that must be shorter
/// to validate means the enclosure is blowing up (a finite escape time of the embedding
/// system, a nominal leaving every bound), and the run stops there with a diagnostic instead
/// of creeping towards it.
pub(crate) const MIN_STEP: f64 = 1e-6;

/// Accepted steps without ROS2 tries after a ROS2 node was refused.
const ROS2_REST: u32 = 16;

/// What the nominal has seen of the model's stiffness along the way.
#[derive(Default)]
struct Stiffness {
    /// The last accepted step ended on a ROS2 node.
    last_ros2: bool,
    /// Accepted steps to go before ROS2 is tried again after it was refused.
    rest: u32,
}

/// Which integrator gives a step's end node (the cubic and its defect bound are the same).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Nodes {
    Rk4,
    /// The linearly implicit step of `rosenbrock.rs`, for stiff models.
    Ros2,
}

/// One validated step `[t0, t1]` of the nominal.
pub(super) struct NominalStep {
    /// Its end.
    pub(super) t1: f64,
    /// The nominal at `t1` (the RK4 or ROS2 node).
    pub(super) x1: Vec<f64>,
    /// Whether that node came from ROS2.
    pub(super) ros2: bool,
    /// An upper bound of `|d(s)|_P` over the step.
    pub(super) defect: f64,
    /// The interval hull of `p([t0, t1])`.
    pub(super) lo: Vec<f64>,
    pub(super) hi: Vec<f64>,
}

/// The validated nominal over the report grid: internal steps chosen so that the defect stays
/// below `tolerance` (in the P-norm, per unit time), landing on every report time.
pub(super) struct Nominal<'a> {
    sys: &'a dyn System,
    /// `(row, column)` of the Jacobian entries the drift depends on.
    pattern: Vec<(usize, usize)>,
    metric: BoxRadius<'a>,
    tolerance: f64,
    /// The box where the constants hold (the nominal must stay in it).
    domain: Option<&'a [crate::model::Bounds]>,
}

impl<'a> Nominal<'a> {
    /// The nominal of `sys` in the metric `p` (`n x n`), with defects up to `tolerance` per unit
    /// time, kept inside `domain` when given.
    pub(super) fn new(
        sys: &'a dyn System,
        p: &'a [f64],
        tolerance: f64,
        domain: Option<&'a [crate::model::Bounds]>,
    ) -> Self {
        Nominal {
            sys,
            pattern: sys.jac_x_pattern(),
            metric: BoxRadius::new(p, sys.n()),
            tolerance,
            domain,
        }
    }

    /// The validated steps from `x0` at `t = 0` over `grid` (report times), the input
    /// `inputs[k]` held on `[t_k, t_(k+1)]`. The last step of each report interval ends
    /// exactly on the report time. Errors name the time and what to change.
    pub(super) fn steps(
        &self,
        x0: &[f64],
        grid: &[f64],
        inputs: &[Vec<f64>],
    ) -> Result<Vec<(NominalStep, usize)>, RunError> {
        let mut out = Vec::new();
        let mut x = x0.to_vec();
        let mut t = 0.0;
        let mut h = grid.get(1).copied().unwrap_or(0.0);
        let mut budget = StepBudget::new(Integrated::Nominal);
        let mut stiff = Stiffness::default();
        for (k, w) in grid.windows(2).enumerate() {
            let end = w[1];
            budget.next_interval();
            while t < end {
                budget.take(t, w)?;
                let (step, used) = self.step(&x, &inputs[k], t, h.min(end - t), w, &mut stiff)?;
                // Land exactly on the report time when the step reaches it.
                h = (2.0 * used).min(w[1] - w[0]);
                x = step.x1.clone();
                t = step.t1;
                out.push((step, k));
            }
        }
        Ok(out)
    }

    /// One accepted step from `(x, t)` in the report interval `window`: tries `h`, halving it
    /// until the defect is below the tolerance; returns the step and the length used. The nodes
    /// come from RK4, or where RK4 is unstable at the length tried (`|J| h` above
    /// [`rosenbrock::RK4_LIMIT`], a stiff model) from ROS2 as well: first if the previous step
    /// used it, else after RK4 failed, and not for [`ROS2_REST`] steps after ROS2 failed (a
    /// fast mode that oscillates, which ROS2 damps instead of following).
    fn step(
        &self,
        x: &[f64],
        u: &[f64],
        t: f64,
        mut h: f64,
        window: &[f64],
        stiff: &mut Stiffness,
    ) -> Result<(NominalStep, f64), RunError> {
        let end = window[1];
        let min_h = MIN_STEP * (end - window[0]);
        // `|J(x)|_inf`, evaluated only where an RK4 step failed or ROS2 is to go first (off the
        // path of a model that is not stiff); 0 above `rosenbrock::MAX_STATES` (never ROS2).
        let mut norm = None;
        let mut stiff_at = |h: f64| {
            let norm = *norm.get_or_insert_with(|| {
                if x.len() <= rosenbrock::MAX_STATES {
                    rosenbrock::jacobian_norm(self.sys, x, u, t)
                } else {
                    0.0
                }
            });
            norm * h > rosenbrock::RK4_LIMIT
        };
        loop {
            // The last step of an interval ends exactly on its report time.
            let t1 = if t + h >= end * (1.0 - 1e-15) || end - (t + h) < min_h {
                end
            } else {
                t + h
            };
            let h_used = t1 - t;
            let ros2_first = stiff.last_ros2 && stiff_at(h_used);
            let order = if ros2_first {
                [Nodes::Ros2, Nodes::Rk4]
            } else {
                [Nodes::Rk4, Nodes::Ros2]
            };
            for by in order {
                // ROS2 after a failed RK4 only where RK4 is unstable, and not while resting.
                if by == Nodes::Ros2 && !ros2_first && (stiff.rest > 0 || !stiff_at(h_used)) {
                    continue;
                }
                if let Some(step) = self.try_step(x, u, t, t1, by)? {
                    if step.defect <= self.tolerance {
                        stiff.last_ros2 = by == Nodes::Ros2;
                        stiff.rest = stiff.rest.saturating_sub(1);
                        return Ok((step, h_used));
                    }
                }
                if by == Nodes::Ros2 {
                    stiff.last_ros2 = false;
                    stiff.rest = ROS2_REST;
                }
            }
            h = 0.5 * h_used;
            if h < min_h {
                return Err(RunError::NonFinite(
                    Detail::from(Problem::NominalStepTooSmall { t, min_step: min_h })
                        .at_setting(Setting::Horizon),
                ));
            }
        }
    }

    /// A step `[t, t1]` with its end node from `by`, and its defect bound; `None` if a value is
    /// not finite (a smaller step may help); an error if the nominal leaves the domain.
    fn try_step(
        &self,
        x: &[f64],
        u: &[f64],
        t: f64,
        t1: f64,
        by: Nodes,
    ) -> Result<Option<NominalStep>, RunError> {
        let sys = self.sys;
        let n = x.len();
        let h = t1 - t;
        let mut f0 = vec![0.0; n];
        sys.drift(x, u, t, &mut f0);
        let x1 = match by {
            Nodes::Rk4 => super::nominal::rk4(sys, x, u, t, h),
            Nodes::Ros2 => match rosenbrock::ros2(sys, x, u, t, h) {
                Some(x1) => x1,
                None => return Ok(None),
            },
        };
        let mut f1 = vec![0.0; n];
        sys.drift(&x1, u, t1, &mut f1);
        if x1.iter().chain(&f0).chain(&f1).any(|v| !v.is_finite()) {
            return Ok(None);
        }
        let ui: Vec<Interval> = u.iter().map(|&a| Interval::point(a)).collect();
        let cubic = Cubic::new(t, t1, x, &x1, &f0, &f1);
        let (mut lo, mut hi) = (x.to_vec(), x.to_vec());
        let mut defect_half = vec![0.0f64; n];
        let mut jac = vec![Interval::ZERO; self.pattern.len()];
        let mut f_mid = vec![Interval::ZERO; n];
        let mut slope = vec![Interval::ZERO; n];
        let mut piece = Piece::new(n);
        for k in 0..PIECES {
            cubic.piece(k, &mut piece);
            for i in 0..n {
                lo[i] = lo[i].min(piece.over.p[i].lo());
                hi[i] = hi[i].max(piece.over.p[i].hi());
            }
            sys.drift_interval(&piece.mid.p, &ui, piece.times, &mut f_mid);
            sys.jac_x_sparse_interval(&piece.over.p, &ui, piece.times, &mut jac);
            // p'' - J p' over the piece, J on the drift's dependency pattern.
            slope.copy_from_slice(&piece.over.d2p);
            for (&(i, j), &jij) in self.pattern.iter().zip(&jac) {
                slope[i] -= jij * piece.over.dp[j];
            }
            for i in 0..n {
                let d = piece.mid.dp[i] - f_mid[i] + slope[i] * piece.offset;
                if !(d.lo().is_finite() && d.hi().is_finite()) {
                    return Ok(None);
                }
                defect_half[i] = defect_half[i].max(d.mag());
            }
        }
        if let Some(domain) = self.domain {
            if let Some(i) = (0..n).find(|&i| lo[i] < domain[i].lo || hi[i] > domain[i].hi) {
                return Err(RunError::Invalid(
                    Detail::from(Problem::LeavesDomain { state: i, t }).at(Culprit::State(i)),
                ));
            }
        }
        Ok(Some(NominalStep {
            t1,
            defect: self.metric.bound(&defect_half),
            x1,
            ros2: by == Nodes::Ros2,
            lo,
            hi,
        }))
    }
}
