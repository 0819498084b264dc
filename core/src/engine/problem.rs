//! What went wrong in a run, as data: the [`Problem`] inside each [`RunError`](super::RunError)
//! variant's [`Detail`](super::Detail), with the numbers, times, states and names it is about.
//! The words live in one place, `core/src/words.rs`.

use super::Setting;
use crate::interval::Interval;
use crate::model::{Bounds, Inclusion, Integrator, NoConstants, Rate};

/// One of the constants of Assumption 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Constant {
    /// The contraction rate `c`.
    C,
    /// The noise level `sigma`.
    Sigma,
    /// The input gain `rho`.
    Rho,
}

impl Constant {
    /// The constant's symbol: `c`, `sigma`, `rho`.
    pub fn symbol(self) -> &'static str {
        match self {
            Constant::C => "c",
            Constant::Sigma => "sigma",
            Constant::Rho => "rho",
        }
    }
}

/// The part of the model data certified constants must have been certified for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Coverage {
    /// The model's domain.
    Domain,
    /// The model's input box.
    InputBox,
    /// Times `[0, horizon]`.
    TimeRange,
}

/// What an engine integrates on validated internal steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Integrated {
    /// The contraction method's nominal trajectory.
    Nominal,
    /// The interval method's embedding system.
    Embedding,
}

/// Why an initial set (boxes and balls, one entry per state) cannot be used.
#[derive(Clone, Debug, PartialEq)]
pub enum InitialSetError {
    /// The set has `entries` per-state entries, the model `n` states.
    Entries {
        /// Per-state entries of the set.
        entries: usize,
        /// States of the model.
        n: usize,
    },
    /// The box of state `state` is not a bounded interval.
    UnboundedBox {
        /// The state's index.
        state: usize,
        /// Its range as given.
        range: Bounds,
    },
    /// Ball `ball` has a centre of the wrong length, or a radius that is negative or not
    /// finite.
    MalformedBall {
        /// The ball's index.
        ball: usize,
    },
    /// The metric of ball `ball` is not `k x k` for its `k` states.
    BallMetricSize {
        /// The ball's index.
        ball: usize,
        /// Its number of states.
        k: usize,
    },
    /// The metric of ball `ball` could not be certified positive definite.
    BallMetricIndefinite {
        /// The ball's index.
        ball: usize,
    },
    /// Ball `ball` names state `state`, beyond the model's `n`.
    BallState {
        /// The ball's index.
        ball: usize,
        /// The state index it names.
        state: usize,
        /// States of the model.
        n: usize,
    },
    /// State `state` is in neither a box nor a ball.
    Missing {
        /// The state's index.
        state: usize,
    },
}

/// Why an unsafe set does not fit the model.
#[derive(Clone, Debug, PartialEq)]
pub struct UnsafeSetError {
    /// The set's name.
    pub set: String,
    /// What is wrong with it.
    pub fault: UnsafeSetFault,
}

/// What is wrong with an unsafe set ([`UnsafeSetError`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnsafeSetFault {
    /// A half-space's normal has `entries` entries for `n` states.
    NormalLength {
        /// Entries of the normal.
        entries: usize,
        /// States of the model.
        n: usize,
    },
    /// A box names state `state`, beyond the model's `n`.
    State {
        /// The state index.
        state: usize,
        /// States of the model.
        n: usize,
    },
    /// A ball's states and centre do not match the model.
    Ball,
}

/// The worker threads could not be started.
#[derive(Clone, Debug, PartialEq)]
pub struct ThreadsError {
    /// The number of threads asked for.
    pub threads: usize,
    /// The thread pool's own error, as it prints it.
    pub cause: String,
}

/// A quantity of a result that is not finite ([`Problem::NotFinite`]), with its value.
#[derive(Clone, Debug, PartialEq)]
pub enum NonFiniteQuantity {
    /// The stochastic radius `r_t` overflowed while `Psi_t` is finite.
    Radius {
        /// `r_t`.
        r_t: f64,
        /// `Psi_t`.
        psi: f64,
    },
    /// `Psi_t` overflowed: the noise grows faster than the contraction damps it.
    Psi {
        /// `r_t`.
        r_t: f64,
        /// The contraction rate of the step.
        c: f64,
        /// The noise level of the step.
        sigma: f64,
    },
    /// The deterministic set grew without bound.
    Deterministic {
        /// Which kind of set.
        set: SetKind,
        /// Which of its numbers.
        part: SetPart,
    },
    /// The span over the report interval, in state `state`, is `[lo, hi]`.
    Span {
        /// The state's name (`#i` where the result names none).
        state: String,
        /// The span's lower end.
        lo: f64,
        /// Its upper end.
        hi: f64,
    },
    /// The radius of the PRS.
    PrsRadius(f64),
    /// The span's radius over the report interval.
    SpanRadius(f64),
    /// The pointwise radius `r_pointwise`.
    PointwiseRadius(f64),
}

/// The kind of a deterministic set ([`NonFiniteQuantity::Deterministic`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SetKind {
    /// The contraction method's ball (its radius is `R_t`).
    Ball,
    /// The interval method's box.
    Box,
    /// The interval method's parallelotope (a box in `y = T x`).
    Parallelotope,
    /// The first-order zonotope.
    Zonotope,
}

/// The number of a deterministic set that is not finite.
#[derive(Clone, Debug, PartialEq)]
pub enum SetPart {
    /// Its centre in state `state` is `value`.
    Centre {
        /// The state's name (`#i` where the result names none).
        state: String,
        /// The centre's coordinate.
        value: f64,
    },
    /// Its radius (`R_t` for a ball, the P-radius otherwise) is `value`.
    Radius(f64),
    /// Its hull in state `state` is `[lo, hi]`.
    Hull {
        /// The state's name.
        state: String,
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
    },
    /// Its remainder ball's radius is `value`.
    Remainder(f64),
    /// Its bounds in coordinate `coordinate` of `y = T x` are `[lo, hi]`.
    Corners {
        /// The coordinate's index.
        coordinate: usize,
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
    },
}

/// The Jacobian entry `d f[row] / d col` over a region ([`Problem::LocalRates`]).
#[derive(Clone, Debug, PartialEq)]
pub struct JacobianEntry {
    /// The state whose drift is differentiated.
    pub row: String,
    /// The state it is differentiated by.
    pub col: String,
    /// The entry's enclosure.
    pub value: Interval,
}

/// What went wrong, with what it is about. Grouped by what a caller can act on; the
/// [`RunError`](super::RunError) variant holding it says the kind of failure, and the
/// [`Detail`](super::Detail)'s culprit what in the spec to change.
#[derive(Clone, Debug, PartialEq)]
pub enum Problem {
    // The analysis settings (`RunError::Invalid`, pointing at the setting).
    /// `split = auto(pieces = N)` outside `1..=max`.
    SplitPieces {
        /// `N`.
        pieces: usize,
        /// The most pieces allowed.
        max: usize,
    },
    /// `split = [..]` without one count of at least 1 per state, or too many pieces.
    SplitCounts {
        /// The counts given.
        counts: Vec<usize>,
        /// States of the model.
        n: usize,
        /// The most pieces allowed.
        max: usize,
    },
    /// `delta` outside `(0, 1)`.
    Delta(f64),
    /// The report step is not finite or below `min`.
    Step {
        /// The step.
        step: f64,
        /// The smallest step allowed.
        min: f64,
    },
    /// The horizon is negative or not finite.
    Horizon(f64),
    /// `horizon / step` report steps are too many.
    TooManyReportSteps(f64),
    /// The paper rule's `eps` outside `(0, 1)`.
    PaperEps(f64),
    /// An output index beyond the model's `n` states.
    Output {
        /// The index.
        index: usize,
        /// States of the model.
        n: usize,
    },

    // The model data (`RunError::Invalid`).
    /// The model has no states.
    NoStates,
    /// The model info names `names` states, the system has `n`.
    StateNames {
        /// States named.
        names: usize,
        /// States of the system.
        n: usize,
    },
    /// The input box has `ranges` ranges, the system `p` inputs.
    InputRanges {
        /// Ranges of the input box.
        ranges: usize,
        /// Inputs of the system.
        p: usize,
    },
    /// The moving numbers of a set do not fit its shape.
    MovingNumbers {
        /// The set's name.
        set: String,
    },
    /// The range of input `input` is not bounded.
    UnboundedInput {
        /// The input's index.
        input: usize,
        /// Its range.
        range: Bounds,
    },
    /// An unsafe set does not fit the model.
    UnsafeSet(UnsafeSetError),
    /// The initial set is malformed.
    InitialSet(InitialSetError),
    /// An initial box has `ranges` ranges, the model `n` states.
    InitialBoxSize {
        /// Ranges given.
        ranges: usize,
        /// States of the model.
        n: usize,
    },
    /// The initial set leaves the domain in one state (the culprit).
    InitialOutsideDomain {
        /// The state's name.
        state: String,
        /// The set's range in that state.
        range: Bounds,
        /// The domain's range in that state.
        domain: Bounds,
    },
    /// An input plan whose times do not start at 0 and increase, or without one value per
    /// time.
    PlanTimes,
    /// An input plan value with `entries` entries, the model `p` inputs.
    PlanValueSize {
        /// Entries of the value.
        entries: usize,
        /// Inputs of the model.
        p: usize,
    },
    /// An input plan value outside the input box.
    PlanValueOutside(Vec<f64>),
    /// No goal `goal`: the model has `goals`.
    NoGoal {
        /// The index asked for.
        goal: usize,
        /// Goal sets of the model.
        goals: usize,
    },

    // The metric and the constants.
    /// The metric has `entries` entries, not `n x n` (`RunError::Invalid`).
    MetricSize {
        /// Entries of the metric.
        entries: usize,
        /// States of the model.
        n: usize,
    },
    /// The metric `P` could not be certified symmetric positive definite (`RunError::Invalid`).
    MetricIndefinite,
    /// The metric could not be factorised for local rates (`RunError::Invalid`).
    LocalMetricIndefinite,
    /// The analysis has no constants (`RunError::NoConstants`).
    MissingConstants {
        /// The analysis' name.
        analysis: String,
        /// The constants its method needs.
        needs: Vec<Constant>,
        /// Why the compiler has none.
        why: NoConstants,
    },
    /// A constant the method needs is not finite (`RunError::NoConstants`).
    ConstantNotFinite {
        /// Which.
        constant: Constant,
        /// Its value.
        value: f64,
    },
    /// The constants were certified for other model data (`RunError::Invalid`).
    NotCovered {
        /// The analysis' name.
        analysis: String,
        /// Which part of the model data differs.
        what: Coverage,
    },

    // Combinations the engine does not run (`RunError::Unsupported`).
    /// Local rates with a pointwise guarantee.
    LocalPointwise,
    /// A rate other than the certified one with the interval method.
    IntervalRate(Rate),
    /// An input plan with an empirical rate.
    PlanWithEmpiricalRate,
    /// Splitting an initial set that is not a box.
    SplitNotABox,
    /// Local rates for more than `max` states need a diagonal metric.
    LocalRatesNeedDiagonal {
        /// The most states with a dense metric.
        max: usize,
    },
    /// A coordinate transform whose frame the system does not have.
    NoFrame {
        /// The analysis' name.
        analysis: String,
        /// The frame asked for.
        frame: usize,
    },
    /// A probability of safety with a pointwise guarantee.
    SafetyNeedsUniform,
    /// A probability of safety for a model without unsafe sets.
    SafetyNeedsUnsafeSets,
    /// A probability of reaching a goal with a pointwise guarantee.
    GoalNeedsUniform,

    // The coordinate transform (`RunError::Invalid`, pointing at `transform`).
    /// `T` or its inverse is not `n x n`.
    TransformSize {
        /// States of the model.
        n: usize,
        /// Entries of `T`.
        matrix: usize,
        /// Entries of its inverse.
        inverse: usize,
    },
    /// `T` or its inverse has non-finite entries.
    TransformNotFinite,
    /// `|I - T^-1 T| >= 1/2`: `T` is too ill-conditioned.
    TransformIllConditioned(f64),
    /// The frame's dimensions differ from the system's.
    FrameSize {
        /// The frame.
        frame: usize,
        /// Its states.
        states: usize,
        /// Its inputs.
        inputs: usize,
        /// The system's states.
        n: usize,
        /// The system's inputs.
        p: usize,
    },

    // The numbers of the run (`RunError::NonFinite`, but for `LeavesDomain`).
    /// The nominal trajectory (unvalidated integrator) is not finite at `t`.
    NominalNotFinite {
        /// The report time.
        t: f64,
        /// The integrator used.
        integrator: Integrator,
        /// The report step.
        step: f64,
    },
    /// The embedding system's box (unvalidated integrator) is not finite at `t`.
    EmbeddingNotFinite {
        /// The report time.
        t: f64,
        /// The inclusion used.
        inclusion: Inclusion,
        /// The integrator used.
        integrator: Integrator,
        /// The report step.
        step: f64,
    },
    /// Validating `what` needs more than `limit` internal steps before `t`.
    TooManySteps {
        /// What is integrated.
        what: Integrated,
        /// The most steps.
        limit: usize,
        /// Where the budget ran out.
        t: f64,
    },
    /// Validating `what` needs more than `limit` internal steps in one report interval.
    TooManyStepsInInterval {
        /// What is integrated.
        what: Integrated,
        /// The most steps in one report interval.
        limit: usize,
        /// The report interval.
        window: [f64; 2],
        /// Where the budget ran out.
        t: f64,
    },
    /// The nominal's step shrank below `min_step` at `t` without bounding the defect.
    NominalStepTooSmall {
        /// Where.
        t: f64,
        /// The smallest step.
        min_step: f64,
    },
    /// The embedding system's step would have to shrink below `min_step` at `t`, its box
    /// `width` wide.
    EmbeddingStepTooSmall {
        /// Where.
        t: f64,
        /// The smallest step.
        min_step: f64,
        /// The box's largest width.
        width: f64,
    },
    /// The nominal trajectory leaves the domain (in the culprit state) near `t`
    /// (`RunError::Invalid`).
    LeavesDomain {
        /// The state's index.
        state: usize,
        /// Where.
        t: f64,
    },
    /// No region around the tube holds the tube its own local rates give, at `t`.
    LocalRates {
        /// Where.
        t: f64,
        /// The last region tried, per state.
        region: Vec<(String, Interval)>,
        /// The Jacobian entry that grew most there, when known.
        entry: Option<JacobianEntry>,
    },
    /// The sample paths of the empirical rate could not be drawn (`RunError::Invalid`).
    EmpiricalSampling(Box<crate::simulate::SimError>),
    /// A sample path of the empirical rate estimate is not finite at `t`.
    EmpiricalPathNotFinite(f64),
    /// No finite empirical rate at `t`.
    EmpiricalRateNotFinite(f64),
    /// A number of the result is not finite from `t` on.
    NotFinite {
        /// The first such report time.
        t: f64,
        /// Which number.
        what: NonFiniteQuantity,
    },
    /// A setting that does not apply to discrete-time models (`RunError::Unsupported`).
    DiscreteSetting(Setting),
    /// A discrete-time analysis' horizon or report step is not a whole number of periods
    /// (`RunError::Invalid`).
    NotWholePeriods {
        /// `horizon` or `step`.
        setting: Setting,
        /// Its value.
        value: f64,
        /// The model's period.
        period: f64,
    },
    /// A discrete-time analysis' horizon is more steps of the map than a run may take
    /// (`RunError::Invalid`).
    TooManyMapSteps {
        /// The horizon in periods.
        steps: usize,
        /// The most steps.
        max: usize,
    },
    /// The factor or the noise level of a discrete-time model's map cannot be bounded on the
    /// region of the step starting at `t` (an unbounded Jacobian or diffusion entry there).
    MapFactor {
        /// The step's start.
        t: f64,
        /// The region, per state.
        region: Vec<(String, Interval)>,
        /// The region is the domain (a pointwise guarantee).
        pointwise: bool,
    },
    /// The box of a discrete-time model's interval method is not finite at `t`.
    MapNotFinite {
        /// Where.
        t: f64,
    },
    /// The worker threads could not be started (`RunError::Invalid`).
    Threads(ThreadsError),
}

/// Circumstances of a failure, said after its problem (in the order they were added).
#[derive(Clone, Debug, PartialEq)]
pub enum Note {
    /// The failure is of one piece of a split initial box: its ranges, per state.
    Piece(Vec<(String, Bounds)>),
    /// The linearised Gaussian set alone could not be bounded over the horizon either.
    AloneFailed,
}
