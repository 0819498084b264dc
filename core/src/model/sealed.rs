//! The sealed model data: [`ModelInfo`] and [`Constants`] are read through accessors and made
//! only by the compiler (and the code it generates), through the hidden constructors
//! [`ModelInfo::from_parts`] and [`Constants::from_parts`]. A caller of the engines cannot
//! label numbers of its own as certified constants, and the engines take a
//! [`Model`](crate::system::Model), the system and the data generated with it, so one model's
//! constants cannot be used with another model's system.

use super::{
    Analysis, Bounds, Constants, GoalSet, InitialSet, MetricRegion, ModelInfo, Provenance, Region,
    Time, UnsafeSet,
};

/// The fields of a [`ModelInfo`], for the compiler and generated code only (not part of the
/// API: a model's data comes from its spec).
#[doc(hidden)]
#[derive(Clone, Debug, PartialEq)]
pub struct ModelParts {
    /// `model NAME`.
    pub name: String,
    /// State names (family elements as `x[3]`).
    pub states: Vec<String>,
    /// Input names.
    pub inputs: Vec<String>,
    /// Noise channel names.
    pub noises: Vec<String>,
    /// The input box, one range per input.
    pub input_box: Vec<Bounds>,
    /// The initial set.
    pub initial: InitialSet,
    /// Per state, the box where the constants were derived ([`Bounds::ENTIRE`] when unbounded).
    pub domain: Vec<Bounds>,
    /// Whether the spec gave a domain (results then hold while the state stays in it).
    pub has_domain: bool,
    /// Whether `D_x f` and `G` are constant (no state, input or time in them): then
    /// `X_t - x_t` is exactly Gaussian (method.md section 8.1) and engines size the stochastic
    /// part from its covariance.
    pub affine: bool,
    /// Whether `G` is constant (no state, input, time or table in it: additive noise). Then
    /// the noise of the linearisation along the nominal cancels the model's exactly and the
    /// first-order sets get a Gaussian part (method.md 8.10).
    pub constant_diffusion: bool,
    /// Continuous time (an SDE) or discrete time (a map stepped at a fixed period).
    pub time: Time,
    /// Unsafe sets.
    pub unsafe_sets: Vec<UnsafeSet>,
    /// Goal sets (reach-avoid and reach-and-stay questions, method.md 8.13).
    pub goals: Vec<GoalSet>,
    /// The analyses, with their certified constants.
    pub analyses: Vec<Analysis>,
}

/// The fields of [`Constants`], for the compiler and generated code only (not part of the
/// API: constants are certified by the compiler).
#[doc(hidden)]
#[derive(Clone, Debug, PartialEq)]
pub struct ConstantsParts {
    /// The metric `P`, `n x n` row-major, symmetric positive definite.
    pub metric: Vec<f64>,
    /// Where `P` comes from (given, or synthesised for which region).
    pub metric_region: MetricRegion,
    /// Contraction rate: `mu_P(D_x f) <= c` over the region, for all inputs and times (`inf`
    /// for a [`Rate::Empirical`](super::Rate::Empirical) analysis: the compiler does not bound it then).
    pub c: f64,
    /// Noise level: `P^(1/2) G G' P^(1/2) <= sigma^2 I`.
    pub sigma: f64,
    /// Input gain: `|D_u f v|_P <= rho |v|_U`, where `|v|_U = max_j |v_j| / h_j` for the input
    /// box half-widths `h_j` (so the input box is the U-ball of radius 1 around its centre).
    pub rho: f64,
    /// How each constant was bounded.
    pub provenance: Provenance,
    /// What the constants hold for.
    pub region: Region,
    /// The analysis' further metrics (`metric = auto(states = [..])`), each with its own
    /// certified constants: the PRS is the intersection of the sets of this metric and of every
    /// one here, each computed at `delta / K` (`K = 1 + also.len()`).
    pub also: Vec<Constants>,
    /// Other metrics the engine runs the analysis with as well, keeping the result whose PRS
    /// has the smallest bounding box at the horizon (a choice from deterministic quantities:
    /// every candidate's result is valid). Used where the compiler cannot predict the PRS
    /// (`metric = auto` without bounded constants over the domain).
    pub alternatives: Vec<Constants>,
}

impl ModelInfo {
    /// The model data of `parts`: for the compiler and generated code only.
    #[doc(hidden)]
    pub fn from_parts(parts: ModelParts) -> ModelInfo {
        let ModelParts {
            name,
            states,
            inputs,
            noises,
            input_box,
            initial,
            domain,
            has_domain,
            affine,
            constant_diffusion,
            time,
            unsafe_sets,
            goals,
            analyses,
        } = parts;
        ModelInfo {
            name,
            states,
            inputs,
            noises,
            input_box,
            initial,
            domain,
            has_domain,
            affine,
            constant_diffusion,
            time,
            unsafe_sets,
            goals,
            analyses,
        }
    }

    /// The fields, for the compiler (which writes them into generated code) only.
    #[doc(hidden)]
    pub fn into_parts(self) -> ModelParts {
        let ModelInfo {
            name,
            states,
            inputs,
            noises,
            input_box,
            initial,
            domain,
            has_domain,
            affine,
            constant_diffusion,
            time,
            unsafe_sets,
            goals,
            analyses,
        } = self;
        ModelParts {
            name,
            states,
            inputs,
            noises,
            input_box,
            initial,
            domain,
            has_domain,
            affine,
            constant_diffusion,
            time,
            unsafe_sets,
            goals,
            analyses,
        }
    }

    /// `model NAME`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// State names (family elements as `x[3]`).
    pub fn states(&self) -> &[String] {
        &self.states
    }

    /// Input names.
    pub fn inputs(&self) -> &[String] {
        &self.inputs
    }

    /// Noise channel names.
    pub fn noises(&self) -> &[String] {
        &self.noises
    }

    /// The input box, one range per input.
    pub fn input_box(&self) -> &[Bounds] {
        &self.input_box
    }

    /// The initial set.
    pub fn initial(&self) -> &InitialSet {
        &self.initial
    }

    /// Per state, the box where the constants were derived ([`Bounds::ENTIRE`] when unbounded).
    pub fn domain(&self) -> &[Bounds] {
        &self.domain
    }

    /// Whether the spec gave a domain (results then hold while the state stays in it).
    pub fn has_domain(&self) -> bool {
        self.has_domain
    }

    /// Whether `D_x f` and `G` are constant (no state, input or time in them): then
    /// `X_t - x_t` is exactly Gaussian (method.md section 8.1) and engines size the stochastic
    /// part from its covariance.
    pub fn affine(&self) -> bool {
        self.affine
    }

    /// Continuous time (an SDE) or discrete time (a map stepped at a fixed period).
    pub fn time(&self) -> Time {
        self.time
    }

    /// Whether `G` is constant (no state, input, time or table in it: additive noise). Then
    /// the noise of the linearisation along the nominal cancels the model's exactly and the
    /// first-order sets get a Gaussian part (method.md 8.10).
    pub fn constant_diffusion(&self) -> bool {
        self.constant_diffusion
    }

    /// Unsafe sets.
    pub fn unsafe_sets(&self) -> &[UnsafeSet] {
        &self.unsafe_sets
    }

    /// Goal sets (reach-avoid and reach-and-stay questions, method.md 8.13).
    pub fn goals(&self) -> &[GoalSet] {
        &self.goals
    }

    /// The analyses, with their certified constants.
    pub fn analyses(&self) -> &[Analysis] {
        &self.analyses
    }
}

/// Test support (feature `test-util`): model data edited by hand, for tests of what the engines do
/// with unusual data. Nothing but tests may use this.
#[cfg(feature = "test-util")]
#[doc(hidden)]
impl ModelInfo {
    /// `name`, to edit.
    pub fn name_mut(&mut self) -> &mut String {
        &mut self.name
    }

    /// `states`, to edit.
    pub fn states_mut(&mut self) -> &mut Vec<String> {
        &mut self.states
    }

    /// `inputs`, to edit.
    pub fn inputs_mut(&mut self) -> &mut Vec<String> {
        &mut self.inputs
    }

    /// `noises`, to edit.
    pub fn noises_mut(&mut self) -> &mut Vec<String> {
        &mut self.noises
    }

    /// `input_box`, to edit.
    pub fn input_box_mut(&mut self) -> &mut Vec<Bounds> {
        &mut self.input_box
    }

    /// `initial`, to edit.
    pub fn initial_mut(&mut self) -> &mut InitialSet {
        &mut self.initial
    }

    /// `domain`, to edit.
    pub fn domain_mut(&mut self) -> &mut Vec<Bounds> {
        &mut self.domain
    }

    /// `has_domain`, to edit.
    pub fn has_domain_mut(&mut self) -> &mut bool {
        &mut self.has_domain
    }

    /// `affine`, to edit.
    pub fn affine_mut(&mut self) -> &mut bool {
        &mut self.affine
    }

    /// `constant_diffusion`, to edit.
    pub fn constant_diffusion_mut(&mut self) -> &mut bool {
        &mut self.constant_diffusion
    }

    /// `unsafe_sets`, to edit.
    pub fn unsafe_sets_mut(&mut self) -> &mut Vec<UnsafeSet> {
        &mut self.unsafe_sets
    }

    /// `goals`, to edit.
    pub fn goals_mut(&mut self) -> &mut Vec<GoalSet> {
        &mut self.goals
    }

    /// `analyses`, to edit.
    pub fn analyses_mut(&mut self) -> &mut Vec<Analysis> {
        &mut self.analyses
    }
}

impl Constants {
    /// The constants of `parts`: for the compiler and generated code only.
    #[doc(hidden)]
    pub fn from_parts(parts: ConstantsParts) -> Constants {
        let ConstantsParts {
            metric,
            metric_region,
            c,
            sigma,
            rho,
            provenance,
            region,
            also,
            alternatives,
        } = parts;
        Constants {
            metric,
            metric_region,
            c,
            sigma,
            rho,
            provenance,
            region,
            also,
            alternatives,
        }
    }

    /// The fields, for the compiler (which writes them into generated code) only.
    #[doc(hidden)]
    pub fn into_parts(self) -> ConstantsParts {
        let Constants {
            metric,
            metric_region,
            c,
            sigma,
            rho,
            provenance,
            region,
            also,
            alternatives,
        } = self;
        ConstantsParts {
            metric,
            metric_region,
            c,
            sigma,
            rho,
            provenance,
            region,
            also,
            alternatives,
        }
    }

    /// The metric `P`, `n x n` row-major, symmetric positive definite.
    pub fn metric(&self) -> &[f64] {
        &self.metric
    }

    /// Where `P` comes from (given, or synthesised for which region).
    pub fn metric_region(&self) -> MetricRegion {
        self.metric_region
    }

    /// Contraction rate: `mu_P(D_x f) <= c` over the region, for all inputs and times (`inf`
    /// for a [`Rate::Empirical`](super::Rate::Empirical) analysis: the compiler does not bound it then).
    pub fn c(&self) -> f64 {
        self.c
    }

    /// Noise level: `P^(1/2) G G' P^(1/2) <= sigma^2 I`.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// Input gain: `|D_u f v|_P <= rho |v|_U`, where `|v|_U = max_j |v_j| / h_j` for the input
    /// box half-widths `h_j` (so the input box is the U-ball of radius 1 around its centre).
    pub fn rho(&self) -> f64 {
        self.rho
    }

    /// How each constant was bounded.
    pub fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    /// What the constants hold for.
    pub fn region(&self) -> &Region {
        &self.region
    }

    /// The analysis' further metrics (`metric = auto(states = [..])`), each with its own
    /// certified constants: the PRS is the intersection of the sets of this metric and of every
    /// one here, each computed at `delta / K` (`K = 1 + also.len()`).
    pub fn also(&self) -> &[Constants] {
        &self.also
    }

    /// Other metrics the engine runs the analysis with as well, keeping the result whose PRS
    /// has the smallest bounding box at the horizon (a choice from deterministic quantities:
    /// every candidate's result is valid). Used where the compiler cannot predict the PRS
    /// (`metric = auto` without bounded constants over the domain).
    pub fn alternatives(&self) -> &[Constants] {
        &self.alternatives
    }
}

/// Test support (feature `test-util`): constants edited by hand, for tests of what the engines do
/// with unusual data. Nothing but tests may use this.
#[cfg(feature = "test-util")]
#[doc(hidden)]
impl Constants {
    /// `metric`, to edit.
    pub fn metric_mut(&mut self) -> &mut Vec<f64> {
        &mut self.metric
    }

    /// `metric_region`, to edit.
    pub fn metric_region_mut(&mut self) -> &mut MetricRegion {
        &mut self.metric_region
    }

    /// `c`, to edit.
    pub fn c_mut(&mut self) -> &mut f64 {
        &mut self.c
    }

    /// `sigma`, to edit.
    pub fn sigma_mut(&mut self) -> &mut f64 {
        &mut self.sigma
    }

    /// `rho`, to edit.
    pub fn rho_mut(&mut self) -> &mut f64 {
        &mut self.rho
    }

    /// `provenance`, to edit.
    pub fn provenance_mut(&mut self) -> &mut Provenance {
        &mut self.provenance
    }

    /// `region`, to edit.
    pub fn region_mut(&mut self) -> &mut Region {
        &mut self.region
    }

    /// `also`, to edit.
    pub fn also_mut(&mut self) -> &mut Vec<Constants> {
        &mut self.also
    }

    /// `alternatives`, to edit.
    pub fn alternatives_mut(&mut self) -> &mut Vec<Constants> {
        &mut self.alternatives
    }
}
