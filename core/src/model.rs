//! The data model of a spec: its sets, inputs and analyses, and the constants the compiler
//! certified for each analysis. The compiler lowers a spec straight into these types; generated
//! code builds them through the hidden constructors of the sealed ones (`sealed.rs`); the
//! engines read them.
//!
//! Matrices are flat row-major vectors: entry `(i, j)` of an `r x c` matrix is `[i * c + j]`.

use crate::interval::Interval;

mod sealed;

pub use sealed::{ConstantsParts, ModelParts};

/// A closed interval `[lo, hi]` of reals given by its ends (`-inf` and `inf` allowed), as plain
/// data (no rounding: see [`Interval`] for arithmetic).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

impl Bounds {
    /// All of R.
    pub const ENTIRE: Bounds = Bounds {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// `[lo, hi]` (not checked: see [`Interval::try_new`](crate::Interval::try_new)).
    pub const fn new(lo: f64, hi: f64) -> Bounds {
        Bounds { lo, hi }
    }
}

/// Everything about a model that is not code: names, sets and analyses, with the constants the
/// compiler certified for each analysis.
///
/// Sealed: read through accessors of the fields' names, made only by the compiler and the code
/// it generates ([`ModelInfo::from_parts`], hidden), and reached by callers through
/// [`Model::info`](crate::system::Model::info) of the system it was generated with. A caller
/// cannot build one, or edit one to claim another domain or other analyses:
///
/// ```compile_fail,E0451
/// # use reachc_core::model::{InitialSet, ModelInfo};
/// let info = ModelInfo { name: "forged".into(), states: vec![], inputs: vec![], noises: vec![],
///     input_box: vec![], initial: InitialSet::default(), domain: vec![], has_domain: false,
///     affine: true, constant_diffusion: true, unsafe_sets: vec![], goals: vec![], analyses: vec![] };
/// ```
///
/// ```compile_fail,E0616
/// # fn edit(mut info: reachc_core::ModelInfo) {
/// info.affine = true;
/// # }
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ModelInfo {
    /// `model NAME`.
    pub(crate) name: String,
    /// State names (family elements as `x[3]`).
    pub(crate) states: Vec<String>,
    /// Input names.
    pub(crate) inputs: Vec<String>,
    /// Noise channel names.
    pub(crate) noises: Vec<String>,
    /// The input box, one range per input.
    pub(crate) input_box: Vec<Bounds>,
    /// The initial set.
    pub(crate) initial: InitialSet,
    /// Per state, the box where the constants were derived ([`Bounds::ENTIRE`] when unbounded).
    pub(crate) domain: Vec<Bounds>,
    /// Whether the spec gave a domain (results then hold while the state stays in it).
    pub(crate) has_domain: bool,
    /// Whether `D_x f` and `G` are constant (no state, input or time in them): then
    /// `X_t - x_t` is exactly Gaussian (method.md section 8.1) and engines size the stochastic
    /// part from its covariance.
    pub(crate) affine: bool,
    /// Whether `G` is constant (no state, input, time or table in it: additive noise). Then
    /// the noise of the linearisation along the nominal cancels the model's exactly and the
    /// first-order sets get a Gaussian part (method.md 8.10).
    pub(crate) constant_diffusion: bool,
    /// Continuous time (an SDE) or discrete time (a map stepped at a fixed period).
    pub(crate) time: Time,
    /// Unsafe sets.
    pub(crate) unsafe_sets: Vec<UnsafeSet>,
    /// Goal sets (reach-avoid and reach-and-stay questions, method.md 8.13).
    pub(crate) goals: Vec<GoalSet>,
    /// The analyses, with their certified constants.
    pub(crate) analyses: Vec<Analysis>,
}

impl ModelInfo {
    /// The analysis named `name`.
    pub fn analysis(&self, name: &str) -> Option<&Analysis> {
        self.analyses.iter().find(|a| a.spec.name == name)
    }

    /// The model's domain and input box over times `[0, horizon]`: the region constants for
    /// this model must cover.
    pub fn region(&self, horizon: f64) -> Region {
        Region {
            domain: self.domain.clone(),
            input_box: self.input_box.clone(),
            time: Bounds::new(0.0, horizon),
        }
    }
}

/// The initial set: per-state boxes (points are degenerate boxes) times balls over groups of
/// states.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct InitialSet {
    /// Per state: its box, or `None` if the state belongs to a ball.
    pub boxes: Vec<Option<Bounds>>,
    /// Balls `{x_S : (x_S - c)' M (x_S - c) <= r^2}`.
    pub balls: Vec<Ball>,
}

impl InitialSet {
    /// The box `x0` (one range per state, no balls).
    pub fn from_box(x0: &[Bounds]) -> InitialSet {
        InitialSet {
            boxes: x0.iter().map(|&b| Some(b)).collect(),
            balls: Vec::new(),
        }
    }

    /// A box holding the set (balls by their bounding boxes, rounded outward), or why not
    /// (inconsistent data).
    pub fn bounding_box(&self) -> Result<Vec<Bounds>, crate::engine::InitialSetError> {
        let (center, half) =
            crate::engine::radius::initial_center_and_halfwidths(self, self.boxes.len())?;
        Ok(self
            .boxes
            .iter()
            .zip(center.iter().zip(&half))
            .map(|(b, (&c, &h))| {
                b.unwrap_or_else(|| {
                    let (c, h) = (Interval::point(c), Interval::point(h));
                    Bounds::new((c - h).lo(), (c + h).hi())
                })
            })
            .collect())
    }
}

/// A ball `{x_S : (x_S - center)' M (x_S - center) <= radius^2}` over the states `S`.
#[derive(Clone, Debug, PartialEq)]
pub struct Ball {
    /// State indices `S`.
    pub states: Vec<usize>,
    /// Centre, one entry per state in `states`.
    pub center: Vec<f64>,
    /// Radius (`>= 0`).
    pub radius: f64,
    /// Metric `M`, `k x k` row-major (`k = states.len()`); the identity when `None`.
    pub metric: Option<Vec<f64>>,
}

/// A named unsafe set.
#[derive(Clone, Debug, PartialEq)]
pub struct UnsafeSet {
    /// Its name.
    pub name: String,
    /// Its shape (a moving set: at `t = 0`).
    pub shape: UnsafeShape,
    /// The numbers of the shape that move with time (method.md 8.15; empty: a fixed set).
    pub moving: Vec<Moving>,
}

/// A number of a set's shape given by a function of time and tables (a moving set, method.md
/// 8.15): entry `number` of [`System::set_numbers`](crate::System::set_numbers).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Moving {
    /// The part of a goal it belongs to (0 for an unsafe set).
    pub part: usize,
    /// Which number of that part's shape.
    pub slot: Slot,
    /// The entry of `System::set_numbers` that gives it.
    pub number: usize,
}

/// A number of an [`UnsafeShape`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// A half-space's offset.
    Offset,
    /// The lower end of a box's side `k` (its place in the box's list).
    Lo(usize),
    /// The upper end of a box's side `k`.
    Hi(usize),
    /// Entry `k` of a ball's centre.
    Center(usize),
    /// A ball's radius.
    Radius,
}

/// How a moving set is held still over an interval of time (method.md 8.15).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sweep {
    /// A fixed set holding the set at every time of the interval (for sets to avoid).
    Union,
    /// A fixed set inside the set at every time of the interval (for sets to be inside).
    Common,
}

/// A named goal set (method.md 8.13): the state should enter it at some time in `window`
/// (and, with `stay`, remain in it until the horizon), avoiding every unsafe set until then.
#[derive(Clone, Debug, PartialEq)]
pub struct GoalSet {
    /// Its name.
    pub name: String,
    /// The goal is the intersection of these regions (each read as the set it describes, as
    /// for an unsafe set of that shape; a moving part: at `t = 0`).
    pub parts: Vec<UnsafeShape>,
    /// The numbers of the parts that move with time (method.md 8.15; empty: a fixed goal).
    pub moving: Vec<Moving>,
    /// The times at which entering counts, `[t1, t2]`; `None`: an analysis' whole horizon.
    pub window: Option<Bounds>,
    /// Reach and stay: once entered, the state must remain in the goal until the horizon.
    pub stay: bool,
}

/// Shapes of unsafe sets (and of the parts of goal sets).
#[derive(Clone, Debug, PartialEq)]
pub enum UnsafeShape {
    /// A box over some states (the others unconstrained): `(state, bounds)` pairs.
    Box(Vec<(usize, Bounds)>),
    /// A Euclidean ball over some states.
    Ball {
        /// State indices.
        states: Vec<usize>,
        /// Centre.
        center: Vec<f64>,
        /// Radius.
        radius: f64,
    },
    /// `{x : normal . x >= offset}` (`normal` has one entry per state).
    HalfSpace {
        /// One entry per state.
        normal: Vec<f64>,
        /// Offset.
        offset: f64,
    },
}

/// How the deterministic reachable set is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Proposition 2: a P-ball around the nominal trajectory.
    Contraction,
    /// Proposition 3: an embedding system on boxes.
    Interval,
}

impl Method {
    /// Its name in specs and reports.
    pub fn name(self) -> &'static str {
        match self {
            Method::Contraction => "contraction",
            Method::Interval => "interval",
        }
    }
}

/// The stochastic radius rule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RadiusRule {
    /// The averaged-MGF bound (default).
    Amgf,
    /// Theorem 1 with a given eps in (0, 1).
    Paper(f64),
    /// Theorem 1 with eps minimising the radius.
    PaperOptimal,
}

impl RadiusRule {
    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            RadiusRule::Amgf => "amgf",
            RadiusRule::Paper(_) => "paper",
            RadiusRule::PaperOptimal => "paper_optimal",
        }
    }
}

/// The inclusion function of the drift used by the interval method's embedding system.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Inclusion {
    /// Natural inclusion: `System::drift_interval` on the (pinned) box and the input box.
    Natural,
    /// Jacobian-based (mean-value) inclusion around the centre `(xc, uc)` of the pinned box and
    /// the input box: `f(xc, uc) + J_x([x], U) ([x] - xc) + J_u([x], U) (U - uc)`.
    #[default]
    Jacobian,
    /// Mixed Jacobian (one column at a time, as immrax's `mjacif`).
    Mixed,
}

impl Inclusion {
    /// Its name in specs and reports.
    pub fn name(self) -> &'static str {
        match self {
            Inclusion::Natural => "natural",
            Inclusion::Jacobian => "jacobian",
            Inclusion::Mixed => "mixed",
        }
    }
}

/// How the deterministic part is integrated in time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Integrator {
    /// Validated steps chosen by the engine (the default): each internal step yields a
    /// rigorous enclosure over the whole step, so the sets hold in continuous time.
    #[default]
    Validated,
    /// Classical Runge-Kutta of order 4, one step per report step, taken as exact (not
    /// validated; labelled so).
    Rk4,
    /// Forward Euler, one step per report step, taken as exact (not validated; labelled so).
    Euler,
}

impl Integrator {
    /// Its name in specs and reports.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Validated => "validated",
            Integrator::Rk4 => "rk4",
            Integrator::Euler => "euler",
        }
    }
}

/// Whether a model is a stochastic differential equation or a stochastic map.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Time {
    /// `dX = f(X, u, t) dt + G(X, t) dW`: [`System::drift`](crate::System::drift) is `f`.
    #[default]
    Continuous,
    /// `X_(k+1) = f(X_k, u_k, t_k) + G(X_k, t_k) w_k` at the times `t_k = k period`, the `w_k`
    /// independent standard normal vectors: [`System::drift`](crate::System::drift) is the map
    /// `f` (the next state, not a rate) and [`System::diffusion`](crate::System::diffusion) the
    /// noise's gain `G` per step (method.md 8.16).
    Discrete {
        /// The sampling period: the time between two steps, `> 0`.
        period: f64,
    },
}

impl Time {
    /// The period of a discrete-time model, `None` for continuous time.
    pub fn period(self) -> Option<f64> {
        match self {
            Time::Continuous => None,
            Time::Discrete { period } => Some(period),
        }
    }
}

/// What the probability level of a PRS is about.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Guarantee {
    /// One event of probability at least `1 - delta` on which the state stays in the tube for
    /// all `t` in `[0, horizon]` at once (the default).
    #[default]
    Uniform,
    /// For each time `t` separately, `P(X_t in PRS_t) >= 1 - delta` (the paper's semantics).
    Pointwise,
}

impl Guarantee {
    /// Its name in specs and reports.
    pub fn name(self) -> &'static str {
        match self {
            Guarantee::Uniform => "uniform",
            Guarantee::Pointwise => "pointwise",
        }
    }
}

/// Where the contraction rate `c_t` (and the noise level `sigma_t`, the input gain `rho_t`) of
/// an analysis comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Rate {
    /// Certified per internal step on a region holding the time-uniform tube over that step
    /// (method.md section 8.3): needs `guarantee = uniform`, no global rate, no domain.
    #[default]
    Local,
    /// One rate for the whole run, certified by the compiler over the domain ([`Constants::c`]).
    Global,
    /// Estimated per report step from sample paths (the paper's approach for the unicycle):
    /// the pooled one-sided Lipschitz quotient between sampled states and the nominal. Not a
    /// guarantee, and labelled so.
    Empirical {
        /// Number of sample paths of the estimate.
        paths: u64,
    },
}

impl Rate {
    /// Its name in specs and reports.
    pub fn name(self) -> &'static str {
        match self {
            Rate::Local => "local",
            Rate::Global => "global",
            Rate::Empirical { .. } => "empirical",
        }
    }
}

/// The metric `P` an analysis asks for.
#[derive(Clone, Debug, PartialEq)]
pub enum MetricChoice {
    /// `P = I`.
    Identity,
    /// A given symmetric positive definite matrix, `n x n` row-major.
    Matrix(Vec<f64>),
    /// Synthesised by the compiler, for the PRS's volume at the horizon.
    Auto,
    /// `auto(states = [..])`: one metric per named state (indices), each chosen for that
    /// state's extent at the horizon; the PRS is the intersection of the sets of all of them,
    /// each at `delta / K` (method.md section 8.6).
    PerState(Vec<usize>),
}

/// A coordinate transform `y = T x` of an interval analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct Transform {
    /// `T`, `n x n` row-major.
    pub matrix: Vec<f64>,
    /// `T^-1` as computed by the compiler in floating point, `n x n` row-major (the engine
    /// encloses the exact inverse around it).
    pub inverse: Vec<f64>,
    /// Which [`System::frame`](crate::System::frame) holds the transformed system (analyses
    /// with the same `T` share one).
    pub frame: usize,
    /// Written in the spec or chosen by the compiler.
    pub source: TransformSource,
}

/// Where a coordinate transform comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TransformSource {
    /// Written in the spec (`transform = [[...]]`).
    Given,
    /// Chosen by the compiler (`transform = auto`) from the Jacobian `A` of the drift at the
    /// centre of the initial set (inputs at the input box's centre, `t = 0`).
    Auto(AutoFit),
}

/// How the compiler chose an automatic transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AutoFit {
    /// `T` (locally) minimises the logarithmic infinity norm
    /// `mu_inf(B) = max_i (B_ii + sum_(j != i) |B_ij|)` of `B = T A T^-1`, which bounds how fast
    /// the embedding's box grows; the identity when nothing beats it.
    LogNorm {
        /// `mu_inf(T A T^-1)`.
        chosen: f64,
        /// `mu_inf(A)`, the identity's.
        identity: f64,
    },
    /// The Jacobian at the centre is not finite: `T` is the identity.
    NonFiniteJacobian,
}

/// An `analysis NAME { ... }` block as written, with the defaults filled in.
#[derive(Clone, Debug, PartialEq)]
pub struct AnalysisSpec {
    /// Its name.
    pub name: String,
    /// Contraction or interval.
    pub method: Method,
    /// Probability level: the PRS holds the state with probability `>= 1 - delta`.
    pub delta: f64,
    /// Final time.
    pub horizon: f64,
    /// Time step of the nominal trajectory and of the report.
    pub step: f64,
    /// The metric asked for (the one used is [`Constants::metric`]).
    pub metric: MetricChoice,
    /// Radius rule.
    pub radius: RadiusRule,
    /// Where the contraction rate comes from (contraction method).
    pub rate: Rate,
    /// Inclusion function of the interval method.
    pub inclusion: Inclusion,
    /// Integrator.
    pub integrator: Integrator,
    /// What the probability level is about: all times at once, or each time separately.
    pub guarantee: Guarantee,
    /// The coordinate transform `y = T x` of the interval method, if given. An engine that
    /// cannot honour it must refuse the analysis rather than ignore it.
    pub transform: Option<Transform>,
    /// States to report (indices; all when empty).
    pub outputs: Vec<usize>,
    /// Whether validated runs add the first-order sets (method.md 8.8) to their PRS: the
    /// linearised flow's zonotope plus a certified remainder, intersected with the method's
    /// own set (up to [`crate::engine::MAX_FIRST_ORDER_STATES`] states).
    pub first_order: bool,
    /// How the initial box is cut into pieces, each run at the full delta, the PRS their union
    /// (method.md 8.11).
    pub split: Split,
}

/// How an analysis cuts its initial box into pieces (method.md 8.11, `split = [..]`): each
/// path starts in exactly one piece, so the union of the pieces' delta-PRS, each at the full
/// delta, is a delta-PRS of the whole box.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Split {
    /// One piece: the initial set itself.
    Off,
    /// `split = [k1, ..., kn]`: state `i`'s range cut into `k_i` equal parts, `k1 ... kn`
    /// pieces (each `k_i >= 1`; at most [`MAX_PIECES`] in all).
    Counts(Vec<usize>),
    /// `split = auto(pieces = N, seconds = S)`: the pieces whose sets are largest bisected,
    /// round by round, along their widest state (in the metric), while that shrinks their sets,
    /// the pieces number at most `pieces` and (with `seconds`) the refinement has run for less
    /// than that long (method.md 8.11).
    Auto {
        /// The most pieces.
        pieces: usize,
        /// The time budget: no round starts after this many seconds of the analysis' run.
        seconds: Option<u64>,
    },
}

/// The budget of `split = auto` without `pieces = N`.
pub const AUTO_PIECES: usize = 64;

/// The most pieces a split may have (`split = [..]`): each is a full run.
pub const MAX_PIECES: usize = 4096;

impl Split {
    /// The number of pieces (1 for [`Split::Off`], the budget for [`Split::Auto`]; saturating).
    pub fn pieces(&self) -> usize {
        match self {
            Split::Off => 1,
            Split::Counts(k) => k.iter().fold(1usize, |p, &k| p.saturating_mul(k)),
            Split::Auto { pieces, .. } => *pieces,
        }
    }
}

impl Default for AnalysisSpec {
    /// The language's defaults (docs/language.md) with a horizon of 1: contraction method,
    /// `delta = 1e-3`, `step = horizon / 100`, identity metric, amgf rule, certified rate,
    /// Jacobian inclusion, validated integration, a uniform guarantee, no transform, every
    /// state reported, first-order sets on, no split.
    fn default() -> Self {
        AnalysisSpec {
            name: String::new(),
            method: Method::Contraction,
            delta: 1e-3,
            horizon: 1.0,
            step: 0.01,
            metric: MetricChoice::Identity,
            radius: RadiusRule::Amgf,
            rate: Rate::Local,
            inclusion: Inclusion::Jacobian,
            integrator: Integrator::Validated,
            guarantee: Guarantee::Uniform,
            transform: None,
            outputs: Vec::new(),
            first_order: true,
            split: Split::Off,
        }
    }
}

/// One analysis of a model, with the constants certified for it.
#[derive(Clone, Debug, PartialEq)]
pub struct Analysis {
    /// The analysis as written.
    pub spec: AnalysisSpec,
    /// The certified constants, or why the compiler could not bound them; an engine refuses to
    /// run without them.
    pub constants: Result<Constants, NoConstants>,
}

/// Why the compiler could not bound an analysis' constants.
#[derive(Clone, Debug, PartialEq)]
pub enum NoConstants {
    /// An entry of `D_x f`, `G` or `D_u f` has an unbounded range over the domain (no `domain`
    /// box, or one too large).
    Unbounded {
        /// The entry, named: `d f[omega] / d theta`, `the diffusion entry G[x, w]`.
        entry: String,
        /// Its expression in the spec's syntax (a prefix, ending in `...` where it was cut).
        expression: String,
    },
    /// The metric is not an `n x n` symmetric positive definite matrix (or could not be
    /// certified as one).
    BadMetric {
        /// What is wrong with it.
        reason: String,
    },
    /// No bound could be certified for a constant (numerically hopeless data, e.g. entries
    /// near `f64::MAX`).
    NotCertified {
        /// `c`, `sigma` or `rho`.
        constant: String,
    },
}

impl std::error::Error for NoConstants {}

/// Constants of Assumption 1 for one metric, certified by the compiler over a [`Region`].
///
/// Sealed: read through accessors of the fields' names; made by the compiler and the code it
/// generates ([`Constants::from_parts`], hidden), or given by hand and labelled so
/// ([`Constants::given`], [`Provenance::Given`]). A caller cannot label numbers of its own as
/// certified, nor change a certified rate:
///
/// ```compile_fail,E0451
/// # use reachc_core::model::*;
/// let forged = Constants {
///     metric: vec![1.0], metric_region: MetricRegion::Given, c: -10.0, sigma: 0.0, rho: 0.0,
///     provenance: Provenance::Given, region: Region { domain: vec![], input_box: vec![],
///     time: Bounds::new(0.0, 1.0) }, also: vec![], alternatives: vec![],
/// };
/// ```
///
/// ```compile_fail,E0616
/// # fn edit(mut constants: reachc_core::model::Constants) {
/// constants.c = -10.0;
/// # }
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Constants {
    /// The metric `P`, `n x n` row-major, symmetric positive definite.
    pub(crate) metric: Vec<f64>,
    /// Where `P` comes from (given, or synthesised for which region).
    pub(crate) metric_region: MetricRegion,
    /// Contraction rate: `mu_P(D_x f) <= c` over the region, for all inputs and times (`inf`
    /// for a [`Rate::Empirical`] analysis: the compiler does not bound it then).
    pub(crate) c: f64,
    /// Noise level: `P^(1/2) G G' P^(1/2) <= sigma^2 I`.
    pub(crate) sigma: f64,
    /// Input gain: `|D_u f v|_P <= rho |v|_U`, where `|v|_U = max_j |v_j| / h_j` for the input
    /// box half-widths `h_j` (so the input box is the U-ball of radius 1 around its centre).
    pub(crate) rho: f64,
    /// How each constant was bounded.
    pub(crate) provenance: Provenance,
    /// What the constants hold for.
    pub(crate) region: Region,
    /// The analysis' further metrics (`metric = auto(states = [..])`), each with its own
    /// certified constants: the PRS is the intersection of the sets of this metric and of every
    /// one here, each computed at `delta / K` (`K = 1 + also.len()`).
    pub(crate) also: Vec<Constants>,
    /// Other metrics the engine runs the analysis with as well, keeping the result whose PRS
    /// has the smallest bounding box at the horizon (a choice from deterministic quantities:
    /// every candidate's result is valid). Used where the compiler cannot predict the PRS
    /// (`metric = auto` without bounded constants over the domain).
    pub(crate) alternatives: Vec<Constants>,
}

impl Constants {
    /// Constants given by hand for the model `info` (a hand-written system, a test): labelled
    /// [`Provenance::Given`], not certified by reachc, and taken to hold over the model's domain
    /// and input box at all times.
    pub fn given(info: &ModelInfo, metric: Vec<f64>, c: f64, sigma: f64, rho: f64) -> Constants {
        Constants {
            metric,
            metric_region: MetricRegion::Given,
            c,
            sigma,
            rho,
            provenance: Provenance::Given,
            region: info.region(f64::INFINITY),
            also: Vec::new(),
            alternatives: Vec::new(),
        }
    }
}

/// Where the metric `P` of an analysis comes from. Any `P` is sound (the rates are certified
/// for the `P` used); the region says where it was chosen to be tight.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MetricRegion {
    /// Given in the spec (`identity` or a matrix), or by hand.
    Given,
    /// Synthesised for the Jacobian over the domain (the global rate's region).
    Domain,
    /// Synthesised for the Jacobian over the initial set's bounding box during the first report
    /// step (where the tube starts; used when the domain admits no contracting metric).
    InitialSet,
    /// `metric = auto` without bounded constants over the domain: the identity, which gave a
    /// smaller PRS at the horizon than the metric synthesised over the initial set (the engine
    /// ran both, see [`Constants::alternatives`]).
    IdentityAtRun,
    /// A discrete-time model's `metric = auto` (method.md 8.16): the inverse of the deviation's
    /// covariance at the horizon for an affine map with additive noise, else the solution of
    /// `A' P A - P = -I` for the map's Jacobian `A` at the initial set's centre.
    Map,
}

/// The states, inputs and times over which [`Constants`] were certified. A run whose model
/// data differs (another domain or input box, a longer horizon) is not covered by them.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// Per state (the model's domain).
    pub domain: Vec<Bounds>,
    /// Per input (the model's input box).
    pub input_box: Vec<Bounds>,
    /// Times `[0, longest horizon of the spec]`.
    pub time: Bounds,
}

/// Where the constants of [`Constants`] come from.
#[derive(Clone, Debug, PartialEq)]
pub enum Provenance {
    /// Certified by the compiler: how it bounded each constant.
    Certified {
        /// The matrices `c` is the largest `mu_P` over; `None` when the compiler did not bound
        /// `c` ([`Rate::Empirical`]).
        c: Option<MatrixBound>,
        /// The matrices `sigma` is taken over.
        sigma: MatrixBound,
        /// How `rho` was bounded.
        rho: InputGain,
    },
    /// Given by hand (a hand-written system, a test): not certified by reachc.
    Given,
    /// A discrete-time model: the compiler bounds nothing (`c`, `sigma`, `rho` are infinite);
    /// the engine bounds the map's factor, the noise level and the input gain on each step's
    /// region at run time (method.md 8.16).
    Map,
    /// The compiler could not bound them over the domain (`c`, `sigma`, `rho` are infinite):
    /// only an analysis with [`Rate::Local`] can run, bounding them on the tube at run time.
    Unbounded {
        /// Why (the unbounded entry).
        why: String,
    },
}

/// The set of matrices (`D_x f`, `G` or `D_u f` over the region) a constant is the worst case
/// of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MatrixBound {
    /// The vertex matrices of the atom decomposition `M = M0 + sum a_k M_k`.
    Vertices {
        /// Number of vertex matrices.
        count: usize,
        /// Number of atoms with a non-degenerate range.
        atoms: usize,
        /// How many of them were fixed at one end by semidefiniteness.
        fixed: usize,
    },
    /// One interval matrix enclosing every entry (too many atoms for vertices).
    Hull {
        /// Number of atoms with a non-degenerate range.
        atoms: usize,
        /// How many of them were fixed at one end by semidefiniteness.
        fixed: usize,
        /// The most free atoms handled by vertices.
        vertex_limit: usize,
    },
}

/// How the input gain `rho` was bounded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputGain {
    /// The model has no inputs (`rho = 0`).
    NoInputs,
    /// The maximum over the input box's corners, for the matrices of `D_u f`.
    Corners(MatrixBound),
    /// Column by column (many inputs), for the matrices of `D_u f`.
    Columns(MatrixBound),
}
