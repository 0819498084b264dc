//! The typed result of an analysis: a delta-PRS at every report time, how it was computed, and
//! what of it is proved. Renderings (JSON, CSV, text) live in `reachc-runtime`'s `report`.
//!
//! A delta-PRS at time `t` is `Rbar_t (+) B_P(r_t)`: a deterministic reachable set ([`DetSet`])
//! plus the stochastic ball of radius `r_t` in the metric `P` of the analysis' constants.

use crate::engine::interval;
use crate::engine::zonotope;
use crate::engine::RunError;
use crate::interval::Interval;
use crate::model::{
    Bounds, Guarantee, Inclusion, InitialSet, Integrator, Method, MetricRegion, Provenance,
    RadiusRule, Rate, Split, TransformSource, UnsafeShape,
};
use crate::reach::InputPlan;

/// Everything an analysis computed.
///
/// Only the engine makes a result, and nothing edits it afterwards: its fields are read through
/// accessors of the same names, and [`Prs::at`], [`Prs::contains`] and [`Prs::hull`] answer
/// questions about the sets soundly (in outward-rounded arithmetic). So a verdict or a set
/// cannot be forged or changed after the fact:
///
/// ```compile_fail,E0616
/// fn forge(prs: &mut reachc_core::Prs) {
///     prs.verdict = reachc_core::prs::Verdict::Safe; // private: read with `prs.verdict()`
/// }
/// ```
///
/// ```compile_fail,E0451
/// fn forge(prs: &reachc_core::Prs) -> reachc_core::Prs {
///     reachc_core::Prs { delta: 0.5, ..prs.clone() } // no result is built outside the engine
/// }
/// ```
///
/// ```compile_fail,E0616
/// fn shrink(prs: &mut reachc_core::Prs) {
///     for st in &mut prs.steps { // private: read with `prs.steps()`
///         st.prs_radius *= 0.5;
///     }
/// }
/// ```
#[derive(Clone, Debug)]
pub struct Prs {
    /// `model NAME`.
    pub(crate) model: String,
    /// The analysis' name.
    pub(crate) analysis: String,
    /// How the deterministic sets were computed.
    pub(crate) method: Method,
    /// The inclusion function of an interval analysis (`None` for the contraction method).
    pub(crate) inclusion: Option<Inclusion>,
    /// Probability level: each PRS holds `X_t` with probability `>= 1 - delta`.
    pub(crate) delta: f64,
    /// Final time.
    pub(crate) horizon: f64,
    /// Nominal report step (the last step may be shorter).
    pub(crate) step: f64,
    /// Integrator of the nominal trajectory or of the embedding system.
    pub(crate) integrator: Integrator,
    /// What the probability level is about: all times at once, or each time separately.
    pub(crate) guarantee: Guarantee,
    /// The number of internal steps of the deterministic part (the engine chooses them; the
    /// report times are among their ends).
    pub(crate) internal_steps: usize,
    /// All state names (the order of every vector of states).
    pub(crate) states: Vec<String>,
    /// Indices of the states reports show (all when empty).
    pub(crate) outputs: Vec<usize>,
    /// Where the contraction rate came from.
    pub(crate) rate: RateUsed,
    /// The constants of Assumption 1 used.
    pub(crate) constants: ConstantsUsed,
    /// The stochastic radius rule.
    pub(crate) radius_rule: RuleUsed,
    /// `kappa(n, delta)` of the rule: `r_t = sqrt(Psi_t kappa)`.
    pub(crate) kappa: f64,
    /// Upper bound of `|x0 - x*_0|_P` over the initial set.
    pub(crate) r1: f64,
    /// Radius of the input uncertainty in the input norm (1 for the input box; 0 without
    /// inputs or with a known input plan).
    pub(crate) r2: f64,
    /// How `r1` was bounded.
    pub(crate) r1_bound: R1Bound,
    /// The coordinate transform of an interval analysis (`None` otherwise); the boxes of
    /// [`DetSet::Parallelotope`] are then in `y = T x`.
    pub(crate) transform: Option<TransformUsed>,
    /// Centre of the initial set (the nominal's start).
    pub(crate) initial_center: Vec<f64>,
    /// The nominal's input at `t = 0` (the centre of the input box, or the plan's value).
    pub(crate) input_center: Vec<f64>,
    /// The initial set the sets start from.
    pub(crate) initial: InitialSet,
    /// The input plan the sets follow (`None`: any input in the input box).
    pub(crate) input_plan: Option<InputPlan>,
    /// One record per report time.
    pub(crate) steps: Vec<Step>,
    /// Per unsafe set, its verdict over the whole horizon.
    pub(crate) unsafe_sets: Vec<UnsafeVerdict>,
    /// Per goal set of the model, what the result shows (method.md 8.13).
    pub(crate) goals: Vec<GoalVerdict>,
    /// The overall verdict.
    pub(crate) verdict: Verdict,
    /// Which parts are proved and which are not.
    pub(crate) validation: Validation,
    /// With local rates, the region of each internal step and the rates certified on it (empty
    /// otherwise).
    pub(crate) regions: Vec<RateRegion>,
    /// Further results of the same run, on the same report times, the PRS their intersection
    /// with this one: [`Prs::contains`], [`Prs::span_contains`], [`Prs::hull`], the margins and
    /// the verdicts answer for the intersection ([`Prs::delta`] is the analysis' `delta`).
    /// They are the analysis' further metrics (`metric = auto(states = [..])`, method.md
    /// section 8.6: with `K` metrics each computed at `delta / K`), and for a contraction
    /// analysis with global rates the interval method's box of each metric's run (section
    /// 8.7: same stochastic event, so at that metric's `delta`); each member's `delta` says
    /// which.
    pub(crate) also: Vec<Prs>,
    /// What this result is within an intersection: [`Role::Own`] for the analysis' result,
    /// the member's kind for those in [`Prs::also`] (set by the engine that made it).
    pub(crate) role: Role,
    /// Advice on the result (interval method: a wrapping box, a box leaving the domain).
    pub(crate) hints: Vec<Hint>,
    /// How the initial box was split (method.md 8.11): [`Split::Off`], the counts per state
    /// (a state whose range has no width is not cut: its count is 1), or automatically.
    pub(crate) split: Split,
    /// With a split, the result of each piece of the initial box, each at [`Prs::delta`]: the
    /// PRS is their union. This result's steps then hold the union's bounding box per report
    /// time ([`DetSet::Box`], `r_t = 0`), its spans' box, and per unsafe set the smallest
    /// margin of any piece; [`Prs::contains`] and [`Prs::span_contains`] answer for the union
    /// itself (in some piece's set).
    pub(crate) pieces: Vec<Prs>,
}

/// Test support (feature `test-util`): results edited by hand, for the tests of code that reads
/// results. An edited result is not what the engine proved; nothing but tests may use this.
#[cfg(feature = "test-util")]
#[doc(hidden)]
impl Prs {
    /// This result without the members of its intersection (its own sets alone; the verdicts
    /// are left as they were).
    pub fn without_members(self) -> Prs {
        Prs {
            also: Vec::new(),
            ..self
        }
    }

    /// Its report steps, to edit.
    pub fn steps_mut(&mut self) -> &mut Vec<Step> {
        &mut self.steps
    }

    /// Its unsafe sets' verdicts, to edit.
    pub fn unsafe_sets_mut(&mut self) -> &mut Vec<UnsafeVerdict> {
        &mut self.unsafe_sets
    }

    /// Its goals' verdicts, to edit.
    pub fn goals_mut(&mut self) -> &mut Vec<GoalVerdict> {
        &mut self.goals
    }

    /// The members of its intersection, to edit.
    pub fn also_mut(&mut self) -> &mut Vec<Prs> {
        &mut self.also
    }

    /// Sets its role.
    pub fn set_role(&mut self, role: Role) {
        self.role = role;
    }
}

/// Read access to a result: its fields are set by the engine that made it, and only read
/// elsewhere (a verdict cannot be assigned, a set cannot be moved).
impl Prs {
    /// `model NAME`.
    pub fn model(&self) -> &str {
        &self.model
    }

    /// The analysis' name.
    pub fn analysis(&self) -> &str {
        &self.analysis
    }

    /// How the deterministic sets were computed.
    pub fn method(&self) -> Method {
        self.method
    }

    /// The inclusion function of an interval analysis (`None` for the contraction method).
    pub fn inclusion(&self) -> Option<Inclusion> {
        self.inclusion
    }

    /// Probability level: each PRS holds `X_t` with probability `>= 1 - delta`.
    pub fn delta(&self) -> f64 {
        self.delta
    }

    /// Final time.
    pub fn horizon(&self) -> f64 {
        self.horizon
    }

    /// Nominal report step (the last step may be shorter).
    pub fn step(&self) -> f64 {
        self.step
    }

    /// Integrator of the nominal trajectory or of the embedding system.
    pub fn integrator(&self) -> Integrator {
        self.integrator
    }

    /// What the probability level is about: all times at once, or each time separately.
    pub fn guarantee(&self) -> Guarantee {
        self.guarantee
    }

    /// The number of internal steps of the deterministic part (the engine chooses them; the
    /// report times are among their ends).
    pub fn internal_steps(&self) -> usize {
        self.internal_steps
    }

    /// All state names (the order of every vector of states).
    pub fn states(&self) -> &[String] {
        &self.states
    }

    /// Indices of the states reports show (all when empty).
    pub fn outputs(&self) -> &[usize] {
        &self.outputs
    }

    /// Where the contraction rate came from.
    pub fn rate(&self) -> &RateUsed {
        &self.rate
    }

    /// The constants of Assumption 1 used.
    pub fn constants(&self) -> &ConstantsUsed {
        &self.constants
    }

    /// The stochastic radius rule.
    pub fn radius_rule(&self) -> &RuleUsed {
        &self.radius_rule
    }

    /// `kappa(n, delta)` of the rule: `r_t = sqrt(Psi_t kappa)`.
    pub fn kappa(&self) -> f64 {
        self.kappa
    }

    /// Upper bound of `|x0 - x*_0|_P` over the initial set.
    pub fn r1(&self) -> f64 {
        self.r1
    }

    /// Radius of the input uncertainty in the input norm (1 for the input box; 0 without
    /// inputs or with a known input plan).
    pub fn r2(&self) -> f64 {
        self.r2
    }

    /// How `r1` was bounded.
    pub fn r1_bound(&self) -> &R1Bound {
        &self.r1_bound
    }

    /// The coordinate transform of an interval analysis (`None` otherwise); the boxes of
    /// [`DetSet::Parallelotope`] are then in `y = T x`.
    pub fn transform(&self) -> Option<&TransformUsed> {
        self.transform.as_ref()
    }

    /// Centre of the initial set (the nominal's start).
    pub fn initial_center(&self) -> &[f64] {
        &self.initial_center
    }

    /// The nominal's input at `t = 0` (the centre of the input box, or the plan's value).
    pub fn input_center(&self) -> &[f64] {
        &self.input_center
    }

    /// The initial set the sets start from.
    pub fn initial(&self) -> &InitialSet {
        &self.initial
    }

    /// The input plan the sets follow (`None`: any input in the input box).
    pub fn input_plan(&self) -> Option<&InputPlan> {
        self.input_plan.as_ref()
    }

    /// One record per report time.
    pub fn steps(&self) -> &[Step] {
        &self.steps
    }

    /// Per unsafe set, its verdict over the whole horizon.
    pub fn unsafe_sets(&self) -> &[UnsafeVerdict] {
        &self.unsafe_sets
    }

    /// Per goal set of the model, what the result shows (method.md 8.13).
    pub fn goals(&self) -> &[GoalVerdict] {
        &self.goals
    }

    /// Which parts are proved and which are not.
    pub fn validation(&self) -> &Validation {
        &self.validation
    }

    /// With local rates, the region of each internal step and the rates certified on it (empty
    /// otherwise).
    pub fn regions(&self) -> &[RateRegion] {
        &self.regions
    }

    /// Further results of the same run, on the same report times, the PRS their intersection
    /// with this one: [`Prs::contains`], [`Prs::span_contains`], [`Prs::hull`], the margins and
    /// the verdicts answer for the intersection ([`Prs::delta`] is the analysis' `delta`).
    /// They are the analysis' further metrics (`metric = auto(states = [..])`, method.md
    /// section 8.6: with `K` metrics each computed at `delta / K`), and for a contraction
    /// analysis with global rates the interval method's box of each metric's run (section
    /// 8.7: same stochastic event, so at that metric's `delta`); each member's `delta` says
    /// which.
    pub fn also(&self) -> &[Prs] {
        &self.also
    }

    /// What this result is within an intersection: [`Role::Own`] for the analysis' result,
    /// the member's kind for those in [`Prs::also`] (set by the engine that made it).
    pub fn role(&self) -> Role {
        self.role
    }

    /// Advice on the result (interval method: a wrapping box, a box leaving the domain).
    pub fn hints(&self) -> &[Hint] {
        &self.hints
    }

    /// How the initial box was split (method.md 8.11): [`Split::Off`], the counts per state
    /// (a state whose range has no width is not cut: its count is 1), or automatically.
    pub fn split(&self) -> &Split {
        &self.split
    }

    /// With a split, the result of each piece of the initial box, each at [`Prs::delta`]: the
    /// PRS is their union. This result's steps then hold the union's bounding box per report
    /// time ([`DetSet::Box`], `r_t = 0`), its spans' box, and per unsafe set the smallest
    /// margin of any piece; [`Prs::contains`] and [`Prs::span_contains`] answer for the union
    /// itself (in some piece's set).
    pub fn pieces(&self) -> &[Prs] {
        &self.pieces
    }
}

/// What a result is within an intersection ([`Prs::also`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The analysis' own result (its first metric's, with several).
    Own,
    /// A further metric's result, of the same method, at `delta / K` (method.md 8.6).
    Metric,
    /// The interval method's box of a contraction run, at the same delta (method.md 8.7).
    Box,
    /// The first-order sets of the same run, at the same delta (method.md 8.8).
    FirstOrder,
    /// The linearised Gaussian sets of the same run (method.md 8.10): first-order zonotopes
    /// holding the stochastic part too, at their own share of delta.
    Linearised,
}

impl Role {
    /// The role's name in outputs: `own`, `metric`, `box`, `first_order`, `linearised`.
    pub fn name(self) -> &'static str {
        match self {
            Role::Own => "own",
            Role::Metric => "metric",
            Role::Box => "box",
            Role::FirstOrder => "first_order",
            Role::Linearised => "linearised",
        }
    }
}

/// Where the contraction rate `c_t` came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RateUsed {
    /// Local, global, or estimated from sample paths (no guarantee).
    pub rate: Rate,
    /// The largest rate used on any step (the certified `c` for a global rate).
    pub max_c: f64,
    /// The smallest rate used on any step.
    pub min_c: f64,
    /// Local rates: the time from which no region closed and the domain's global constants
    /// took over (the result is conditional on the domain then); `None`: local throughout.
    pub global_from: Option<f64>,
}

/// One internal step `[t0, t1]` of a run with local rates: the box `D_k` that holds the
/// deterministic set and the time-uniform tube over the step, and the rates certified on it.
#[derive(Clone, Debug, PartialEq)]
pub struct RateRegion {
    /// Start of the step.
    pub t0: f64,
    /// End of the step.
    pub t1: f64,
    /// Lower corner of `D_k`.
    pub lo: Vec<f64>,
    /// Upper corner of `D_k`.
    pub hi: Vec<f64>,
    /// `c_k >= mu_P(D_x f)` over `D_k`, the input box and the step's times.
    pub c: f64,
    /// `sigma_k`, the noise level over the same.
    pub sigma: f64,
    /// `rho_k`, the input gain over the same.
    pub rho: f64,
}

/// The constants of Assumption 1, as used.
#[derive(Clone, Debug, PartialEq)]
pub struct ConstantsUsed {
    /// Contraction rate.
    pub c: f64,
    /// Noise level.
    pub sigma: f64,
    /// Input gain (0 without inputs for the contraction method).
    pub rho: f64,
    /// How the compiler bounded them.
    pub provenance: Provenance,
    /// The metric `P`, `n x n` row-major.
    pub metric: Vec<f64>,
    /// Where `P` comes from.
    pub metric_region: MetricRegion,
    /// Upper bounds of `sqrt((P^-1)_ii)`: the P-ball of radius `r` around `c` lies in the box
    /// `|x_i - c_i| <= r spread_i`.
    pub spread: Vec<f64>,
}

/// The stochastic radius rule used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RuleUsed {
    /// The rule.
    pub rule: RadiusRule,
    /// `eps` of Theorem 1 (the given one, or the minimiser), for the paper rules.
    pub eps: Option<f64>,
    /// An affine system under the amgf rule: the radii come from the exact Gaussian
    /// covariance instead (method.md section 8.1).
    pub gaussian: Option<GaussianUsed>,
}

/// The exact Gaussian route of an affine system.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussianUsed {
    /// The upper bound of `chi2_n^-1(1 - delta)` of the pointwise radii
    /// `sqrt(q lambda_max(R Sigma_t R'))`.
    pub quantile: f64,
    /// Uniform guarantee: which time-uniform bound was tighter and is used.
    pub uniform: Option<UniformBound>,
}

/// The time-uniform bound of a result: both are valid, the tighter (smaller sum of radii over
/// the report times, fixed before the fact) is used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UniformBound {
    /// The AMGF tube (method.md section 8.2).
    AmgfTube,
    /// The method-of-mixtures bound for Gaussian martingales (method.md section 8.1).
    Mixture,
}

/// How `r1` was bounded (method.md section 6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct R1Bound {
    /// How the box part was bounded: the initial boxes and points, and the balls' bounding
    /// boxes too when `balls` is [`BallBound::BoundingBoxes`].
    pub boxes: R1Method,
    /// How the initial balls entered.
    pub balls: BallBound,
    /// `r1` is reported only: the interval method propagates the initial set's bounding box.
    pub reported_only: bool,
}

/// The bound over the box part of the initial set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum R1Method {
    /// The maximum over the box's vertices (exact up to rounding).
    Vertices {
        /// Non-degenerate coordinates of the box part.
        active: usize,
    },
    /// `sum_ij |P_ij| h_i h_j` (more than [`crate::engine::MAX_VERTEX_COORDS`] coordinates).
    AbsoluteSum,
}

/// How the initial balls entered `r1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BallBound {
    /// No initial ball of positive radius.
    NoBalls,
    /// Jointly with the box part's vertices: per vertex, the S-lemma bound minimised over its
    /// multiplier. Exact (up to rounding) for one ball; for several, the S-procedure with one
    /// multiplier per ball, an upper bound that need not be exact.
    Joint {
        /// Balls of positive radius.
        balls: usize,
    },
    /// Separately from the box part, `|b + y|_P <= |b|_P + |y|_P` (more than
    /// [`crate::engine::MAX_VERTEX_COORDS`] box coordinates, or a box part and more than
    /// [`crate::engine::MAX_BALL_STATES`] ball states); the balls' part as in `Joint`.
    Separate {
        /// Balls of positive radius.
        balls: usize,
    },
    /// Replaced by their bounding boxes: the balls' own bound was not smaller (or could not be
    /// certified).
    BoundingBoxes,
}

/// A coordinate transform `y = T x`, as used.
#[derive(Clone, Debug, PartialEq)]
pub struct TransformUsed {
    /// `T`, `n x n` row-major.
    pub matrix: Vec<f64>,
    /// `T^-1` computed in floating point, `n x n` row-major (`x = T^-1 y`).
    pub inverse: Vec<f64>,
    /// A rigorous bound of `|(T^-1)_ij - inverse_ij|` over all entries (0 when exact).
    pub inverse_error: f64,
    /// Written in the spec or chosen by the compiler.
    pub source: TransformSource,
}

/// Advice on a result, read off its own numbers (advisory: plain floating point, no guarantee
/// rests on it).
#[derive(Clone, Debug, PartialEq)]
pub enum Hint {
    /// The box wraps: at time `t` the PRS's bounding box in `state` is more than
    /// [`WRAPPING_FACTOR`](crate::engine::WRAPPING_FACTOR) times wider than that of the P-ball
    /// the result's own constants give from the initial set (`R_t = e^(ct) r1 + rho r2
    /// (e^(ct) - 1) / c` plus the same `r_t`, the contraction method's set), the largest such
    /// ratio over the report times and states.
    Wrapping {
        /// The report time.
        t: f64,
        /// The state (index into [`Prs::states`]).
        state: usize,
        /// Half-width of the PRS's bounding box in `state` (the box's hull plus `r_t`).
        half_width: f64,
        /// Half-width of the P-ball's bounding box in `state`.
        ball_half_width: f64,
        /// The contraction rate `c` of the result's constants.
        c: f64,
    },
    /// The deterministic box leaves the spec's domain (first report time and state).
    LeavesDomain {
        /// The report time.
        t: f64,
        /// The state (index into [`Prs::states`]).
        state: usize,
        /// The box's hull in `state`.
        range: Bounds,
        /// The domain in `state`.
        domain: Bounds,
    },
    /// From report time `t` on, the first-order sets' (method.md 8.8) second-order remainder
    /// exceeds their linear part: the initial set (or the input box) is too wide for one
    /// linearisation over the horizon; smaller pieces shrink the remainder quadratically.
    FirstOrderLoose {
        /// The report time.
        t: f64,
        /// The remainder's P-radius.
        remainder: f64,
        /// The P-radius of the linear part (the zonotope around the nominal).
        linear: f64,
    },
    /// The first-order sets (method.md 8.8) were wanted but could not be bounded on some
    /// internal step (the a-priori remainder did not hold its own bound).
    FirstOrderUnbounded,
    /// The analysis' own sets (its ball or box) could not be bounded: the PRS is the linearised
    /// Gaussian set alone at the full delta (method.md 8.12).
    LinearisedAlone {
        /// What stopped the analysis' own run.
        failed: RunError,
    },
}

/// The sets at one report time.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// Time.
    pub t: f64,
    /// The deterministic reachable set `Rbar_t`.
    pub det: DetSet,
    /// Stochastic radius `r_t` (in `|.|_P`) of the analysis' guarantee: the time-uniform
    /// tube's radius at `t` (uniform), or the radius for time `t` alone (pointwise).
    pub r_t: f64,
    /// The pointwise radius at `t` (what `r_t` would be for this time alone: the price of
    /// uniformity is `r_t / r_pointwise`).
    pub r_pointwise: f64,
    /// The stochastic radius of the report interval ending here (method.md 8.14): the largest
    /// over the interval for a uniform guarantee, `r_t` for a pointwise one (0 at `t = 0`, and
    /// in a split's union, whose pieces hold theirs).
    pub r_span: f64,
    /// `Psi_t` (upper bound).
    pub psi: f64,
    /// Contraction rate on the step ending here.
    pub c: f64,
    /// Noise level on the step ending here.
    pub sigma: f64,
    /// Radius of a P-ball around [`DetSet::center`] containing the PRS: the PRS itself for
    /// [`DetSet::Ball`] (`R_t + r_t`), coarser than the PRS for boxes.
    pub prs_radius: f64,
    /// The PRS over the whole report interval ending at `t` (after the previous report time;
    /// at `t = 0`, the PRS at 0): the sets of every time in between lie in it.
    pub span: Span,
    /// Safety margin per unsafe set over [`Step::span`] (the order of [`Prs::unsafe_sets`];
    /// `> 0` means shown safe at every time of the interval).
    pub margins: Vec<f64>,
}

/// The set `{x : lo <= x <= hi} (+) B_P(radius)` holding the PRS of every time of an interval.
#[derive(Clone, Debug, PartialEq)]
pub struct Span {
    /// Lower corner of the box.
    pub lo: Vec<f64>,
    /// Upper corner of the box.
    pub hi: Vec<f64>,
    /// The radius of the P-ball added to it.
    pub radius: f64,
}

/// A deterministic reachable set.
#[derive(Clone, Debug, PartialEq)]
pub enum DetSet {
    /// `{x : |x - center|_P <= radius}` (contraction method; `radius` is `R_t`).
    Ball {
        /// The nominal state.
        center: Vec<f64>,
        /// `R_t` (upper bound).
        radius: f64,
    },
    /// `{x : lo <= x <= hi}` (interval method), inside the P-ball `(center, radius)`.
    Box {
        /// Lower corner.
        lo: Vec<f64>,
        /// Upper corner.
        hi: Vec<f64>,
        /// Centre of the box.
        center: Vec<f64>,
        /// Upper bound of the box's P-radius around `center`.
        radius: f64,
    },
    /// `{x : lo <= T x <= hi}` (interval method with the transform `T` of
    /// [`Prs::transform`]), with its interval hull `[hull_lo, hull_hi]` in `x`, inside the
    /// P-ball `(center, radius)` of the hull.
    Parallelotope {
        /// Lower corner of the box in `y = T x`.
        lo: Vec<f64>,
        /// Upper corner of the box in `y`.
        hi: Vec<f64>,
        /// Lower corner of the interval hull in `x`.
        hull_lo: Vec<f64>,
        /// Upper corner of the interval hull in `x`.
        hull_hi: Vec<f64>,
        /// Centre of the hull.
        center: Vec<f64>,
        /// Upper bound of the hull's P-radius around `center`.
        radius: f64,
    },
    /// `{center + sum_j xi_j g_j : |xi_j| <= 1} (+) B_P(remainder)` (first-order sets,
    /// method.md 8.8): the image of the initial box under the flow's linearisation along the
    /// nominal (a zonotope with the generators `g_j`), plus a P-ball bounding the error of the
    /// linearisation; with the zonotope's interval hull `[hull_lo, hull_hi]` (without the
    /// ball), all inside the P-ball `(center, radius)`.
    Zonotope {
        /// The centre (the nominal state).
        center: Vec<f64>,
        /// The generators, generator-major: `g_j` is `generators[j n..(j + 1) n]`.
        generators: Vec<f64>,
        /// The P-radius of the ball added to the zonotope (upper bound).
        remainder: f64,
        /// Lower corner of the zonotope's interval hull.
        hull_lo: Vec<f64>,
        /// Upper corner of the zonotope's interval hull.
        hull_hi: Vec<f64>,
        /// Upper bound of the whole set's P-radius around `center`.
        radius: f64,
    },
}

impl Step {
    /// The nominal state `x*_t` (all states); for the interval method the centre of the set's
    /// hull.
    pub fn nominal(&self) -> &[f64] {
        self.det.center()
    }
}

/// A membership test of [`Prs::own_contains_at`] built once for many states (the Monte Carlo
/// check).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Prepared<'a> {
    /// The test of a result's parallelotopes (its metric and transform).
    Parallelotope(&'a interval::ParallelotopeTest),
    /// The test of one step's zonotope (with the result's metric).
    Zonotope(&'a zonotope::ZonotopeTest),
}

/// `hull` cut by the box `other`, both holding the same set (an intersection's members): an
/// empty cut cannot happen for sets holding the same nominal state, but stays a valid
/// (degenerate) box.
fn cut(hull: &mut [Bounds], other: &[Bounds]) {
    for (b, o) in hull.iter_mut().zip(other) {
        let lo = b.lo.max(o.lo);
        *b = Bounds::new(lo, b.hi.min(o.hi).max(lo));
    }
}

/// Whether `|x - c|_P <= r` certainly (interval arithmetic), `p` n x n row-major (both
/// off-diagonal entries, so a slightly asymmetric `P` is used as given).
pub(crate) fn within(p: &[f64], x: &[f64], c: &[f64], r: f64) -> bool {
    let n = x.len();
    let d: Vec<Interval> = x
        .iter()
        .zip(c)
        .map(|(&a, &b)| Interval::point(a) - Interval::point(b))
        .collect();
    let mut q = Interval::ZERO;
    for i in 0..n {
        q += p[i * n + i] * d[i].sqr();
        for j in i + 1..n {
            q += Interval::point(p[i * n + j]) * d[i] * d[j]
                + Interval::point(p[j * n + i]) * d[j] * d[i];
        }
    }
    q.hi() <= Interval::point(r).sqr().lo()
}

impl DetSet {
    /// The name of the set's shape in result files: `"p_ball"`, `"box"`, `"parallelotope"` or
    /// `"zonotope"`.
    pub fn shape(&self) -> &'static str {
        match self {
            DetSet::Ball { .. } => "p_ball",
            DetSet::Box { .. } => "box",
            DetSet::Parallelotope { .. } => "parallelotope",
            DetSet::Zonotope { .. } => "zonotope",
        }
    }

    /// The centre of the set (of its hull for a parallelotope).
    pub fn center(&self) -> &[f64] {
        match self {
            DetSet::Ball { center, .. }
            | DetSet::Box { center, .. }
            | DetSet::Parallelotope { center, .. }
            | DetSet::Zonotope { center, .. } => center,
        }
    }

    /// The radius of a P-ball around [`DetSet::center`] containing the set (`R_t` for a ball).
    pub fn radius(&self) -> f64 {
        match self {
            DetSet::Ball { radius, .. }
            | DetSet::Box { radius, .. }
            | DetSet::Parallelotope { radius, .. }
            | DetSet::Zonotope { radius, .. } => *radius,
        }
    }

    /// The box of an interval method's set, `(lo, hi)`: in `x` for [`DetSet::Box`], in
    /// `y = T x` for [`DetSet::Parallelotope`]; `None` for a ball or a zonotope.
    pub fn corners(&self) -> Option<(&[f64], &[f64])> {
        match self {
            DetSet::Ball { .. } | DetSet::Zonotope { .. } => None,
            DetSet::Box { lo, hi, .. } | DetSet::Parallelotope { lo, hi, .. } => Some((lo, hi)),
        }
    }

    /// An interval hull in `x` of the set without its [`DetSet::ball_added`]: `None` for a
    /// ball (its hull needs `P^-1`, see [`Prs::hull`]).
    pub fn box_hull(&self) -> Option<(&[f64], &[f64])> {
        match self {
            DetSet::Ball { .. } => None,
            DetSet::Box { lo, hi, .. } => Some((lo, hi)),
            DetSet::Parallelotope {
                hull_lo, hull_hi, ..
            }
            | DetSet::Zonotope {
                hull_lo, hull_hi, ..
            } => Some((hull_lo, hull_hi)),
        }
    }

    /// The P-radius of the ball added to the set's [`DetSet::box_hull`] part: a zonotope's
    /// remainder, 0 for boxes and parallelotopes (and for a ball, which has no such part).
    pub fn ball_added(&self) -> f64 {
        match self {
            DetSet::Zonotope { remainder, .. } => *remainder,
            _ => 0.0,
        }
    }

    /// The generators of a zonotope, `g_j` one per item; empty for the other shapes.
    pub fn generators(&self) -> Vec<&[f64]> {
        match self {
            DetSet::Zonotope {
                center, generators, ..
            } if !center.is_empty() => generators.chunks(center.len()).collect(),
            _ => Vec::new(),
        }
    }
}

/// The kind of an unsafe set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnsafeKind {
    /// `{x : a.x >= b}`; margins are Euclidean distances.
    HalfSpace,
    /// A box; margins are the largest per-coordinate gap between the PRS's bounding box and it.
    Box,
    /// A Euclidean ball; margins are Euclidean distances.
    Ball,
}

impl UnsafeKind {
    /// The kind of an unsafe set's shape.
    pub fn of(shape: &UnsafeShape) -> UnsafeKind {
        match shape {
            UnsafeShape::HalfSpace { .. } => UnsafeKind::HalfSpace,
            UnsafeShape::Box(_) => UnsafeKind::Box,
            UnsafeShape::Ball { .. } => UnsafeKind::Ball,
        }
    }
}

/// One unsafe set's verdict over the horizon.
#[derive(Clone, Debug, PartialEq)]
pub struct UnsafeVerdict {
    /// Its name.
    pub name: String,
    /// Its kind (what the margins measure).
    pub kind: UnsafeKind,
    /// Shown safe at every report time.
    pub safe: bool,
    /// Smallest margin over the report times.
    pub min_margin: f64,
    /// Time of the smallest margin.
    pub min_margin_t: f64,
    /// First report time at which safety was not shown.
    pub first_not_safe_t: Option<f64>,
    /// A moving set (method.md 8.15): per report time, the fixed set that held all its
    /// positions over the report interval ending there (the time itself at `t = 0`), which the
    /// margins were computed against. Empty for a fixed set.
    pub swept: Vec<crate::model::UnsafeShape>,
}

/// The overall verdict. A PRS touching an unsafe set does not prove a violation, hence "not
/// shown safe" rather than "unsafe".
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// Every PRS is disjoint from every unsafe set.
    Safe,
    /// The spec has no unsafe sets.
    NoUnsafeSets,
    /// The first report time and set for which safety was not shown.
    NotShownSafe {
        /// Time.
        t: f64,
        /// Step index.
        step: usize,
        /// Index of the unsafe set in [`Prs::unsafe_sets`].
        set: usize,
    },
}

/// What a result shows about one goal set of the model (method.md 8.13).
#[derive(Clone, Debug, PartialEq)]
pub struct GoalVerdict {
    /// The goal's name.
    pub name: String,
    /// The times at which entering counts: the goal's window, or `[0, T]`.
    pub window: Bounds,
    /// Reach and stay (the state must remain in the goal until the horizon).
    pub stay: bool,
    /// Per report time, how far the PRS lies inside the goal: the smallest Euclidean gap
    /// between its bounding box and the goal's boundary (for a half-space or a ball part), or
    /// per coordinate (for a box part), rounded down; not positive where it is not shown
    /// inside. For reaching alone in a model without unsafe sets, the box is the pointwise one
    /// ([`Prs::pointwise_hull_at`]).
    pub margins: Vec<f64>,
    /// A moving goal (method.md 8.15): per report time, its parts held still inside all their
    /// positions at that time (the margins' goal). Empty for a fixed goal.
    pub swept: Vec<Vec<crate::model::UnsafeShape>>,
    /// What is shown.
    pub outcome: GoalOutcome,
}

/// The outcome of a [`GoalVerdict`].
#[derive(Clone, Debug, PartialEq)]
pub enum GoalOutcome {
    /// With probability at least `1 - delta`, for every start and input: the state is in the
    /// goal at report time `t` (in the window), having avoided every unsafe set on `[0, t]`;
    /// with `stay`, it also remains in the goal, and away from the unsafe sets, until the
    /// horizon.
    Reached {
        /// The first report time at which this is shown.
        t: f64,
        /// The smallest containment margin involved (at `t`, and with `stay` over the report
        /// intervals to the horizon).
        margin: f64,
    },
    /// Not shown (this does not prove that the goal is missed).
    NotShown(GoalMiss),
    /// A pointwise result bounds each time separately, not the path: no verdict (except for
    /// reaching alone without unsafe sets, a question about one time).
    NeedsUniform,
}

/// Why a goal is not shown reached.
#[derive(Clone, Debug, PartialEq)]
pub enum GoalMiss {
    /// No report time lies in the window.
    NoReportTime,
    /// The tube may meet unsafe set `set` (index into [`Prs::unsafe_sets`]) over the report
    /// interval ending at `t`, before the goal is shown reached (with `stay`: before the
    /// horizon).
    Unsafe {
        /// Report time.
        t: f64,
        /// Unsafe set index.
        set: usize,
    },
    /// At no report time in the window is the PRS shown inside the goal: the largest margin,
    /// and when.
    NotInside {
        /// Report time of the largest margin.
        t: f64,
        /// That margin (not positive).
        margin: f64,
    },
    /// The PRS is inside the goal at some report time in the window, but (the last such
    /// time tried) the tube over the report interval ending at `t` is not shown inside.
    Leaves {
        /// Report time.
        t: f64,
    },
}

impl GoalVerdict {
    /// Whether the goal is shown reached.
    pub fn reached(&self) -> bool {
        matches!(self.outcome, GoalOutcome::Reached { .. })
    }
}

/// Which parts of the result are proved.
#[derive(Clone, Debug, PartialEq)]
pub struct Validation {
    /// Proved parts (outward-rounded, or certified by the compiler).
    pub rigorous: Vec<Proved>,
    /// Parts that are not validated.
    pub not_validated: Vec<Unproved>,
    /// The result holds only while the state stays in the spec's domain.
    pub conditional_on_domain: bool,
}

/// A proved part of a result.
#[derive(Clone, Debug, PartialEq)]
pub enum Proved {
    /// The constants certified by the compiler: which of `c`, `sigma`, `rho` the engine used.
    Constants {
        /// `c` (certified rate).
        c: bool,
        /// `rho` (contraction method).
        rho: bool,
        /// How the compiler bounded them.
        provenance: Provenance,
    },
    /// The inclusion function of the drift on each face (interval method).
    Inclusion(Inclusion),
    /// `kappa`, rounded up.
    Kappa,
    /// `Psi_t`, exact per-step integration in interval arithmetic.
    Psi,
    /// `r1`, `R_t`, `r_t` and the PRS radius (contraction method).
    Radii,
    /// `r_t` (interval method).
    StochasticRadius,
    /// The safety margins given the deterministic set (`P^-1` enclosed by interval Cholesky).
    Margins {
        /// Given the nominal (contraction) or the box (interval).
        given: Method,
    },
    /// The transformed system, the initial box in `y = T x` and the map back to `x`. The
    /// transformed drift `T f(T^-1 y)` is built by the compiler with the exact `T^-1` and
    /// coefficients folded without rounding (enclosures where a fold is inexact), so its
    /// interval forms enclose it as the model's enclose `f`.
    TransformMaps {
        /// The bound of `T^-1`'s entries around the floating-point inverse.
        inverse_error: f64,
    },
    /// The nominal trajectory enclosed on validated steps: a defect bound of a piecewise
    /// cubic, propagated with the contraction rate into `R_t` (contraction method).
    ValidatedNominal {
        /// The number of internal steps.
        steps: usize,
    },
    /// The embedding system enclosed on validated steps (the comparison principle on each
    /// step's hull; interval method).
    ValidatedEmbedding {
        /// The number of internal steps.
        steps: usize,
    },
    /// Local rates: `c`, `sigma`, `rho` certified per internal step on a region holding the
    /// tube over that step (interval Jacobian, verified eigenvalue bounds); no domain needed.
    LocalRates {
        /// The number of regions (internal steps).
        regions: usize,
        /// Where the metric was synthesised.
        metric: MetricRegion,
    },
    /// The time-uniform tube: Ville's inequality on `epochs` epochs at `delta / epochs` each.
    UniformTube {
        /// The number of epochs.
        epochs: usize,
    },
    /// The stochastic part of an affine system from its exact Gaussian covariance (enclosed in
    /// interval arithmetic), with a rigorous chi-square quantile.
    ExactGaussian,
    /// The time-uniform Gaussian mixture bound on `epochs` epochs at `delta / epochs` each.
    GaussianMixture {
        /// The number of epochs.
        epochs: usize,
    },
    /// The linearised Gaussian sets (method.md 8.10): the linearisation's covariance along the
    /// nominal (enclosed), the reflection principle per coordinate on `epochs` epochs (one per
    /// internal step), and the linearisation's error bounded path by path on that event.
    LinearisedGaussian {
        /// The number of epochs.
        epochs: usize,
    },
}

/// A part of a result that is not proved.
#[derive(Clone, Debug, PartialEq)]
pub enum Unproved {
    /// The contraction rate is an estimate from sample paths.
    EmpiricalRate {
        /// Number of sample paths.
        paths: u64,
    },
    /// The nominal trajectory is integrated numerically and taken as exact.
    Nominal {
        /// The integrator.
        integrator: Integrator,
        /// Its step.
        step: f64,
    },
    /// The embedding system is integrated numerically (no remainder bound).
    Embedding {
        /// The integrator.
        integrator: Integrator,
        /// Its step.
        step: f64,
    },
}

impl Prs {
    /// This result as a member of an intersection, of kind `role`.
    pub(crate) fn with_role(mut self, role: Role) -> Prs {
        self.role = role;
        self
    }

    /// The dimension `n`.
    pub fn n(&self) -> usize {
        self.states.len()
    }

    /// Where the result held unsafe set `j` still over the report interval ending at step `k`
    /// (method.md 8.15); `None` for a fixed set, which is its own shape.
    pub fn swept_unsafe(&self, j: usize, k: usize) -> Option<&crate::model::UnsafeShape> {
        self.unsafe_sets.get(j).and_then(|v| v.swept.get(k))
    }

    /// The index of the report time `t` (within `1e-9` relative to the horizon, so grid times
    /// such as `0.3` written as literals are found); `None` between report times (the sets are
    /// only computed at report times).
    pub fn step_index(&self, t: f64) -> Option<usize> {
        let tol = 1e-9 * self.horizon.abs().max(1.0);
        let k = self.steps.partition_point(|s| s.t < t - tol);
        self.steps
            .get(k)
            .filter(|s| (s.t - t).abs() <= tol)
            .map(|_| k)
    }

    /// The sets at report time `t` (see [`Prs::step_index`]).
    pub fn at(&self, t: f64) -> Option<&Step> {
        self.step_index(t).map(|k| &self.steps[k])
    }

    /// The overall verdict.
    pub fn verdict(&self) -> Verdict {
        self.verdict
    }

    /// Whether `x` lies in [`Step::span`] of report step `k`, the PRS of every time of the
    /// report interval ending there: `true` only if certainly (see [`Prs::contains`]).
    pub fn span_contains(&self, k: usize, x: &[f64]) -> bool {
        if !self.pieces.is_empty() {
            return self.pieces.iter().any(|p| p.span_contains(k, x));
        }
        self.own_span_contains(k, x) && self.also.iter().all(|m| m.own_span_contains(k, x))
    }

    /// A bounding box of this result's own span at report step `k` ([`Step::span`]: its box
    /// widened by its P-ball, rounded outward; the members of an intersection cut it further):
    /// `None` if [`ConstantsUsed::spread`] is missing or the span has the wrong length. Panics
    /// if `k` is out of range.
    pub(crate) fn own_span_hull_at(&self, k: usize) -> Option<Vec<Bounds>> {
        let span = &self.steps[k].span;
        let w = &self.constants.spread;
        let n = self.n();
        if w.len() != n || span.lo.len() != n || span.hi.len() != n {
            return None;
        }
        // (A span without a ball adds nothing, even where a spread is infinite.)
        let d = |i: usize| match span.radius {
            0.0 => Interval::ZERO,
            r => Interval::point(r) * Interval::point(w[i]),
        };
        Some(
            (0..n)
                .map(|i| {
                    Bounds::new(
                        (Interval::point(span.lo[i]) - d(i)).lo(),
                        (Interval::point(span.hi[i]) + d(i)).hi(),
                    )
                })
                .collect(),
        )
    }

    /// A rigorous bounding box of the PRS over every time of the report interval ending at
    /// step `k` (step 0: at `t = 0`): this result's own span box widened by its P-ball, cut by
    /// its members' (an intersection holds the state in each); a split result's is the union's
    /// (the box of its pieces' spans). `None` if [`ConstantsUsed::spread`] is missing. Panics
    /// if `k` is out of range.
    pub fn span_hull_at(&self, k: usize) -> Option<Vec<Bounds>> {
        let mut hull = self.own_span_hull_at(k)?;
        for m in &self.also {
            cut(&mut hull, &m.own_span_hull_at(k)?);
        }
        Some(hull)
    }

    /// [`Prs::span_contains`] for this result's own metric.
    pub(crate) fn own_span_contains(&self, k: usize, x: &[f64]) -> bool {
        let span = &self.steps[k].span;
        assert_eq!(
            x.len(),
            self.n(),
            "span_contains: x has the wrong dimension"
        );
        interval::box_contains(
            &self.constants.metric,
            self.n(),
            x,
            &span.lo,
            &span.hi,
            span.radius,
        )
    }

    /// Whether `x` lies in the PRS at report time `t`: `Some(true)` only if certainly
    /// (decided in interval arithmetic; a point within rounding of the boundary counts as
    /// outside), `None` if `t` is not a report time. Panics if `x` has the wrong length.
    pub fn contains(&self, x: &[f64], t: f64) -> Option<bool> {
        self.step_index(t).map(|k| self.contains_at(k, x))
    }

    /// Whether `x` lies in the PRS at report step `k` (see [`Prs::contains`]). Panics if `k` is
    /// out of range or `x` has the wrong length.
    pub fn contains_at(&self, k: usize, x: &[f64]) -> bool {
        if !self.pieces.is_empty() {
            return self.pieces.iter().any(|p| p.contains_at(k, x));
        }
        self.own_contains_at(k, x) && self.also.iter().all(|m| m.own_contains_at(k, x))
    }

    /// [`Prs::contains_at`] for this result's own metric.
    pub(crate) fn own_contains_at(&self, k: usize, x: &[f64]) -> bool {
        self.own_contains_at_with(k, x, None)
    }

    /// [`Prs::own_contains_at`], with the exact test of step `k`'s set built once by the
    /// caller (`test`: of this result's parallelotopes, for its metric and transform, or of
    /// step `k`'s zonotope, for its metric): the same answers.
    pub(crate) fn own_contains_at_with(
        &self,
        k: usize,
        x: &[f64],
        test: Option<Prepared<'_>>,
    ) -> bool {
        let st = &self.steps[k];
        let n = self.n();
        assert_eq!(x.len(), n, "contains: x has the wrong dimension");
        let p = &self.constants.metric;
        // The set also holds B_P(c, r) when the deterministic set holds its centre c (a point
        // certain where the search for the nearest point of the set may stop short; the Monte
        // Carlo check decides most states by that ball alone).
        let near_centre = || {
            self.centre_radius(k)
                .is_some_and(|r| within(p, x, st.det.center(), r))
        };
        match &st.det {
            DetSet::Ball { center, .. } => within(p, x, center, st.prs_radius),
            DetSet::Box { lo, hi, .. } => {
                interval::box_contains(p, n, x, lo, hi, st.r_t) || near_centre()
            }
            DetSet::Parallelotope { lo, hi, .. } => match &self.transform {
                Some(tr) => {
                    let near = match test {
                        Some(Prepared::Parallelotope(test)) => test.contains(x, lo, hi, st.r_t),
                        _ => interval::parallelotope_contains(p, tr, x, lo, hi, st.r_t),
                    };
                    near || near_centre()
                }
                None => false,
            },
            DetSet::Zonotope {
                center, generators, ..
            } => {
                let r = self.zonotope_radius(k);
                let near = match test {
                    Some(Prepared::Zonotope(test)) => test.contains(x, r),
                    _ => zonotope::contains(p, x, center, generators, r),
                };
                near || near_centre()
            }
        }
    }

    /// The P-radius added to the zonotope of report step `k` in its PRS, `remainder + r_t`
    /// (rounded down: membership tests ask for points within it).
    pub(crate) fn zonotope_radius(&self, k: usize) -> f64 {
        let st = &self.steps[k];
        (Interval::point(st.r_t) + Interval::point(st.det.ball_added())).lo()
    }

    /// The radius of a P-ball around the centre of report step `k`'s deterministic set
    /// ([`DetSet::center`]) that this result's own PRS certainly holds: the PRS radius of a
    /// ball, `r_t` for a box or a parallelotope holding its centre, the zonotope's
    /// `remainder + r_t` (rounded down); `None` when the set is not certain to hold its centre.
    pub(crate) fn centre_radius(&self, k: usize) -> Option<f64> {
        let st = &self.steps[k];
        match &st.det {
            DetSet::Ball { .. } => Some(st.prs_radius),
            DetSet::Zonotope { .. } => Some(self.zonotope_radius(k)),
            DetSet::Box { lo, hi, center, .. } => center
                .iter()
                .zip(lo.iter().zip(hi))
                .all(|(c, (l, h))| l <= c && c <= h)
                .then_some(st.r_t),
            DetSet::Parallelotope { lo, hi, center, .. } => self
                .transform
                .as_ref()
                .is_some_and(|tr| {
                    let t: Vec<Vec<f64>> =
                        tr.matrix.chunks(self.n()).map(<[f64]>::to_vec).collect();
                    crate::engine::transform::inside(&t, center, lo, hi)
                })
                .then_some(st.r_t),
        }
    }

    /// A rigorous bounding box of the PRS at report time `t` (`None` between report times;
    /// see [`Prs::hull_at`]).
    pub fn hull(&self, t: f64) -> Option<Vec<Bounds>> {
        self.step_index(t).and_then(|k| self.hull_at(k))
    }

    /// A rigorous bounding box of the PRS at report step `k`: the deterministic set's hull
    /// inflated by `r_t sqrt((P^-1)_ii)` (a zonotope's by `(remainder + r_t) sqrt((P^-1)_ii)`;
    /// for a ball, the ball `B_P(x*, R_t + r_t)`'s own hull), rounded outward; `None` if
    /// [`ConstantsUsed::spread`] is missing (a result built by hand). Panics if `k` is out of
    /// range.
    pub fn hull_at(&self, k: usize) -> Option<Vec<Bounds>> {
        let mut hull = self.own_hull_at(k)?;
        for m in &self.also {
            cut(&mut hull, &m.own_hull_at(k)?);
        }
        Some(hull)
    }

    /// A rigorous bounding box of a set holding `X_t` at report step `k` with probability at
    /// least `1 - delta` at that time alone (not for all times at once): [`Prs::hull_at`] with
    /// the pointwise radius `r_pointwise` in place of `r_t` in this result's own set (never
    /// larger; its members keep their sets, which hold at every time); for a split result, the
    /// hull of its pieces'. `None` as for [`Prs::hull_at`].
    pub fn pointwise_hull_at(&self, k: usize) -> Option<Vec<Bounds>> {
        if let Some((first, rest)) = self.pieces.split_first() {
            let mut hull = first.pointwise_hull_at(k)?;
            for p in rest {
                for (b, o) in hull.iter_mut().zip(p.pointwise_hull_at(k)?) {
                    *b = Bounds::new(b.lo.min(o.lo), b.hi.max(o.hi));
                }
            }
            return Some(hull);
        }
        let mut hull = self.own_hull_with(k, Some(self.steps[k].r_pointwise))?;
        for m in &self.also {
            cut(&mut hull, &m.own_hull_at(k)?);
        }
        Some(hull)
    }

    /// [`Prs::hull_at`] for this result's own metric.
    pub(crate) fn own_hull_at(&self, k: usize) -> Option<Vec<Bounds>> {
        self.own_hull_with(k, None)
    }

    /// [`Prs::own_hull_at`] with the stochastic radius `r` in place of `r_t` (`None`: `r_t`).
    fn own_hull_with(&self, k: usize, r: Option<f64>) -> Option<Vec<Bounds>> {
        let st = &self.steps[k];
        let n = self.n();
        let w = &self.constants.spread;
        if w.len() != n {
            return None;
        }
        let spread = |r: f64, i: usize| Interval::point(r) * Interval::point(w[i]);
        let (r_t, prs_radius) = match r {
            None => (st.r_t, st.prs_radius),
            Some(r) => (
                r,
                (Interval::point(st.det.radius()) + Interval::point(r)).hi(),
            ),
        };
        Some(match st.det.box_hull() {
            None => {
                let c = st.det.center();
                (0..n)
                    .map(|i| {
                        let d = spread(prs_radius, i);
                        let c = Interval::point(c[i]);
                        Bounds::new((c - d).lo(), (c + d).hi())
                    })
                    .collect()
            }
            Some((lo, hi)) => (0..n)
                .map(|i| {
                    let r = Interval::point(r_t) + Interval::point(st.det.ball_added());
                    let d = spread(r.hi(), i);
                    Bounds::new(
                        (Interval::point(lo[i]) - d).lo(),
                        (Interval::point(hi[i]) + d).hi(),
                    )
                })
                .collect(),
        })
    }
}
