//! The typed result of an analysis: a delta-PRS at every report time, how it was computed, and
//! what of it is proved. Renderings (JSON, CSV, text) live in `reachc-runtime`'s `report`.
//!
//! A delta-PRS at time `t` is `Rbar_t (+) B_P(r_t)`: a deterministic reachable set ([`DetSet`])
//! plus the stochastic ball of radius `r_t` in the metric `P` of the analysis' constants.

mod how;
mod membership;
mod sets;
mod validation;
mod verdicts;

pub use how::{
    BallBound, ConstantsUsed, GaussianUsed, Hint, R1Bound, R1Method, RateRegion, RateUsed, Role,
    RuleUsed, TransformUsed, UniformBound,
};
pub(crate) use membership::Prepared;
pub use sets::{DetSet, Span, Step};
pub use validation::{Proved, Unproved, Validation};
pub use verdicts::{GoalMiss, GoalOutcome, GoalVerdict, UnsafeKind, UnsafeVerdict, Verdict};

use crate::model::{Guarantee, Inclusion, InitialSet, Integrator, Method, Split, UnsafeShape};
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
    /// The sampling period of a discrete-time model (method.md 8.16): its sets are at the steps
    /// `t_k = k period`, the map enclosed exactly; `None` for continuous time.
    pub(crate) period: Option<f64>,
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

    /// The sampling period of a discrete-time model (its sets are at the steps `k period`, and
    /// a report interval's span holds the sets of its steps); `None` for continuous time.
    pub fn period(&self) -> Option<f64> {
        self.period
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
    pub fn swept_unsafe(&self, j: usize, k: usize) -> Option<&UnsafeShape> {
        self.unsafe_sets.get(j).and_then(|v| v.swept.get(k))
    }

    /// The overall verdict.
    pub fn verdict(&self) -> Verdict {
        self.verdict
    }
}
