//! Engines computing delta-probabilistic reachable sets (method.md, sections 2, 4-6).
//!
//! A delta-PRS at time t is the Minkowski sum of a deterministic reachable set `Rbar_t` and the
//! stochastic ball `B_P(r_t)`, `r_t = sqrt(Psi_t kappa(n, delta))` (Theorem 2). Two engines
//! compute `Rbar_t`: the contraction engine (Proposition 2, `contraction.rs`), a P-ball
//! `B_P(x*_t, R_t)` around the nominal trajectory, and the interval engine (Proposition 3,
//! `interval.rs`), a box of an embedding system (or a parallelotope in coordinates `y = T x`).
//! Everything after `Rbar_t` is shared (`assemble.rs`): the stochastic radius, the safety
//! margins (`safety.rs`), the verdicts and the typed result [`Prs`].
//!
//! What is rigorous: the constants come certified from the compiler; `kappa`, `Psi_t`, `r1`,
//! `R_t`, `r_t` and the safety margins are computed in outward-rounded interval arithmetic with
//! the conservative end kept. What is not: the nominal trajectory and the embedding system are
//! integrated numerically (RK4 or Euler) and taken as exact. The result records this in its
//! [`Validation`](crate::prs::Validation).
//!
//! Runs go through [`Reach`](crate::Reach), which checks the analysis and its constants once;
//! [`run`] runs one analysis of a model as the spec wrote it.

mod alone;
mod assemble;
mod contraction;
mod culprit;
mod defect;
mod discrete;
mod embedding;
mod finite;
mod first_order;
mod gaussian;
pub(crate) mod goals;
mod hermite;
mod hints;
mod intersect;
pub(crate) mod interval;
pub(crate) mod linalg;
mod linearised;
mod local;
mod memo;
mod nominal;
mod problem;
mod r1;
pub(crate) mod radius;
mod rates;
mod rosenbrock;
pub(crate) mod safety;
mod tighten;
mod uniform;
pub(crate) mod union;

pub use contraction::MAX_BOX_STATES;
pub use culprit::{Culprit, Detail, Setting};
pub(crate) use first_order::gaussian_wanted;
pub use first_order::MAX_FIRST_ORDER_STATES;
pub use hints::WRAPPING_FACTOR;
pub use interval::interval_boxes;
pub use problem::{
    Constant, Coverage, InitialSetError, Integrated, JacobianEntry, NonFiniteQuantity, Note,
    Problem, SetKind, SetPart, ThreadsError, UnsafeSetError, UnsafeSetFault,
};
pub use r1::MAX_BALL_STATES;
pub use radius::MAX_VERTEX_COORDS;
pub use tighten::{tighten, Constraint, TightStep, TightenError, Tightening};

use crate::interval::Interval;
use crate::model::{
    AnalysisSpec, Bounds, Constants, InitialSet, Method, ModelInfo, NoConstants, RadiusRule, Split,
    Time, MAX_PIECES,
};
use crate::prs::Prs;
use crate::reach::InputPlan;
use crate::system::{Model, System};

/// Why an analysis could not run.
#[derive(Clone, Debug, PartialEq)]
pub enum RunError {
    /// The model has no analysis of that name.
    UnknownAnalysis {
        /// The name asked for.
        name: String,
        /// The analyses the model has.
        available: Vec<String>,
    },
    /// The analysis asks for something this engine does not do (yet), e.g. a coordinate
    /// transform for a system without the transformed frame.
    Unsupported(Detail),
    /// The compiler could not bound the constants of Assumption 1.
    NoConstants(Detail),
    /// The analysis or model data is inconsistent (bad delta, step, dimensions, metric...), or
    /// not covered by the certified constants.
    Invalid(Detail),
    /// A number of the run left the finite numbers (the nominal trajectory, a bound the engine
    /// needed, or a quantity of the result: the message says which, at which time and, where it
    /// has one, in which state), or the nominal could not be validated.
    NonFinite(Detail),
}

impl RunError {
    /// What the failure points at in the spec, if the engine knows.
    pub fn culprit(&self) -> Option<Culprit> {
        match self {
            RunError::UnknownAnalysis { .. } => None,
            RunError::Unsupported(d)
            | RunError::NoConstants(d)
            | RunError::Invalid(d)
            | RunError::NonFinite(d) => d.culprit,
        }
    }
}

impl RunError {
    /// The same failure, said to be of the piece of a split initial box with these ranges.
    pub(crate) fn in_piece(self, piece: Vec<(String, Bounds)>) -> RunError {
        self.noted(Note::Piece(piece))
    }

    /// The same failure with `note` added to its circumstances.
    pub(crate) fn noted(self, note: Note) -> RunError {
        let note = |mut d: Detail| {
            d.notes.push(note);
            d
        };
        match self {
            RunError::UnknownAnalysis { .. } => self,
            RunError::Unsupported(d) => RunError::Unsupported(note(d)),
            RunError::NoConstants(d) => RunError::NoConstants(note(d)),
            RunError::Invalid(d) => RunError::Invalid(note(d)),
            RunError::NonFinite(d) => RunError::NonFinite(note(d)),
        }
    }

    /// The problem of the failure (`None` for [`RunError::UnknownAnalysis`]).
    pub fn problem(&self) -> Option<&Problem> {
        match self {
            RunError::UnknownAnalysis { .. } => None,
            RunError::Unsupported(d)
            | RunError::NoConstants(d)
            | RunError::Invalid(d)
            | RunError::NonFinite(d) => Some(d.problem.as_ref()),
        }
    }
}

impl std::error::Error for RunError {}

/// Which constants an engine needs to be finite.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Needs {
    pub(crate) c: bool,
    pub(crate) sigma: bool,
    pub(crate) rho: bool,
}

/// What every run of an analysis shares, checked and derived once: the constants (covering the
/// model data), the dimensions, the rigorous Cholesky factor of `P` with an enclosure of the
/// diagonal of `P^-1`, and the precomputed safety checks.
pub(crate) struct Setup<'a> {
    pub(crate) consts: &'a Constants,
    pub(crate) n: usize,
    pub(crate) p: usize,
    /// Enclosure of the diagonal of `P^-1`.
    pub(crate) p_inv_diag: Vec<Interval>,
    /// One check per unsafe set of the model.
    pub(crate) checks: Vec<safety::Check>,
}

impl<'a> Setup<'a> {
    /// Checks `spec` and the model data against `sys` and the certified `constants`, and
    /// derives what the engines share.
    pub(crate) fn new(
        sys: &dyn System,
        info: &ModelInfo,
        spec: &AnalysisSpec,
        constants: &'a Result<Constants, NoConstants>,
        needs: Needs,
    ) -> Result<Setup<'a>, RunError> {
        let consts = constants.as_ref().map_err(|why| {
            let needs = [
                (Constant::C, needs.c),
                (Constant::Sigma, needs.sigma),
                (Constant::Rho, needs.rho),
            ]
            .iter()
            .filter(|(_, used)| *used)
            .map(|(name, _)| *name)
            .collect();
            RunError::NoConstants(
                Problem::MissingConstants {
                    analysis: spec.name.clone(),
                    needs,
                    why: why.clone(),
                }
                .into(),
            )
        })?;
        Setup::with(sys, info, spec, consts, needs)
    }

    /// [`Setup::new`] for constants known to exist (a further metric of the analysis).
    pub(crate) fn with(
        sys: &dyn System,
        info: &ModelInfo,
        spec: &AnalysisSpec,
        consts: &'a Constants,
        needs: Needs,
    ) -> Result<Setup<'a>, RunError> {
        let (n, p) = (sys.n(), sys.p());
        validate(info, spec, n, p)?;
        covered(info, spec, consts)?;
        let metric = &consts.metric;
        if metric.len() != n * n {
            return Err(RunError::Invalid(
                Detail::from(Problem::MetricSize {
                    entries: metric.len(),
                    n,
                })
                .at_setting(Setting::Metric),
            ));
        }
        for (what, v, used) in [
            (Constant::C, consts.c, needs.c),
            (Constant::Sigma, consts.sigma, needs.sigma),
            (Constant::Rho, consts.rho, needs.rho),
        ] {
            if used && !v.is_finite() {
                return Err(RunError::NoConstants(
                    Problem::ConstantNotFinite {
                        constant: what,
                        value: v,
                    }
                    .into(),
                ));
            }
        }
        // Rigorous factorisation of P, used by every P^-1 quantity.
        let chol = linalg::cholesky(&linalg::to_intervals(metric), n).ok_or_else(|| {
            RunError::Invalid(Detail::from(Problem::MetricIndefinite).at_setting(Setting::Metric))
        })?;
        let p_inv_diag = linalg::inverse_diagonal(&chol, n);
        let checks = safety::Check::all(&info.unsafe_sets, n, &chol, &p_inv_diag)
            .map_err(|e| RunError::Invalid(Problem::UnsafeSet(e).into()))?;
        Ok(Setup {
            consts,
            n,
            p,
            p_inv_diag,
            checks,
        })
    }
}

/// The input box as intervals, one per input.
pub(crate) fn input_intervals(info: &ModelInfo) -> Vec<Interval> {
    info.input_box
        .iter()
        .map(|b| Interval::new(b.lo, b.hi))
        .collect()
}

/// The embedding's boxes of a `Reach`'s runs (`memo.rs`).
pub(crate) type BoxMemo = memo::Memo<interval::Boxes>;

/// The inputs of a run.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Inputs<'a> {
    /// Anywhere in the input box (the nominal takes its centre).
    Box,
    /// Following a plan (inside the input box).
    Plan(&'a InputPlan),
}

/// One run of an analysis: the model, the analysis as run, its setup, where it starts and its
/// inputs.
pub(crate) struct Run<'a> {
    pub(crate) sys: &'a dyn System,
    pub(crate) info: &'a ModelInfo,
    pub(crate) spec: &'a AnalysisSpec,
    pub(crate) setup: &'a Setup<'a>,
    pub(crate) initial: &'a InitialSet,
    pub(crate) inputs: Inputs<'a>,
    /// The embedding's boxes already computed for the same `Reach` ([`BoxMemo`]).
    pub(crate) memo: &'a BoxMemo,
    /// The share of delta of the linearised Gaussian sets (method.md 8.10), when the run is
    /// to compute them (the rest of the run then holds at `spec.delta`, the two shares summing
    /// to the analysis' delta).
    pub(crate) gaussian: Option<f64>,
}

impl Run<'_> {
    /// The nominal input on each report step `[t_k, t_(k+1))` of `grid` (one entry per grid
    /// time; the last is unused), and `r2`, the input uncertainty in the input norm.
    pub(crate) fn nominal_inputs(&self, grid: &[f64]) -> (Vec<Vec<f64>>, f64) {
        match self.inputs {
            Inputs::Box => {
                let centre: Vec<f64> = self
                    .info
                    .input_box
                    .iter()
                    .map(|b| Interval::new(b.lo, b.hi).mid())
                    .collect();
                (vec![centre; grid.len()], self.input_radius())
            }
            Inputs::Plan(plan) => (
                grid.iter().map(|&t| plan.at(t).to_vec()).collect(),
                self.input_radius(),
            ),
        }
    }

    /// `r2`, the input uncertainty in the input norm: the input box is the U-ball of radius 1
    /// around its centre ([`Constants::rho`]); a known plan has none.
    pub(crate) fn input_radius(&self) -> f64 {
        match self.inputs {
            Inputs::Box if self.setup.p > 0 => 1.0,
            Inputs::Box | Inputs::Plan(_) => 0.0,
        }
    }
}

/// Runs the analysis `name` of the model as the spec wrote it (its initial set, inputs
/// anywhere in the input box). The same as [`Reach::new`](crate::Reach::new) then
/// [`Reach::run`](crate::Reach::run).
pub fn run(model: &dyn Model, name: &str) -> Result<Prs, RunError> {
    crate::Reach::new(model, name)?.run()
}

/// Runs `analysis` (one built by hand) of the system `sys` with the model data `info`: test
/// support (feature `test-util`), for tests of what the engines do with unusual data.
#[cfg(feature = "test-util")]
#[doc(hidden)]
pub fn run_paired(
    sys: &dyn System,
    info: &ModelInfo,
    analysis: &crate::model::Analysis,
) -> Result<Prs, RunError> {
    crate::Reach::for_analysis(sys, info, analysis)?.run()
}

pub(crate) use intersect::intersect;
pub(crate) use safety::deterministic_limit;

/// Runs the engine of the analysis' method; a result with a number that is not finite is a
/// [`RunError::NonFinite`].
pub(crate) fn run_engine(run: &Run) -> Result<Prs, RunError> {
    let prs = match (run.info.time, run.spec.method) {
        (Time::Discrete { period }, _) => discrete::run(run, period),
        (Time::Continuous, Method::Contraction) => contraction::run(run),
        (Time::Continuous, Method::Interval) => interval::run(run, run.spec.inclusion),
    }?;
    finite::check(&prs)?;
    Ok(prs)
}

/// The linearised Gaussian set of a run alone at its whole delta (method.md 8.12), for an
/// analysis whose own sets cannot be bounded (`failed` says why); `None` where that set does
/// not apply or cannot be bounded either.
pub(crate) fn run_alone(run: &Run, failed: &RunError) -> Result<Option<Prs>, RunError> {
    let Some(prs) = alone::run(run, failed)? else {
        return Ok(None);
    };
    finite::check(&prs)?;
    Ok(Some(prs))
}

/// Shortest report step an analysis may have: the integrators subdivide a report step down to
/// a millionth of it and halve from there, so far shorter steps would reach subnormal
/// numbers, where `t + h == t` and no step makes progress (the front end's limit too).
pub const MIN_REPORT_STEP: f64 = 1e-100;

/// Checks the analysis parameters and the model dimensions.
pub(crate) fn validate(
    info: &ModelInfo,
    a: &AnalysisSpec,
    n: usize,
    p: usize,
) -> Result<(), RunError> {
    let bad = |m: Problem| Err(RunError::Invalid(m.into()));
    let bad_setting =
        |s: Setting, m: Problem| Err(RunError::Invalid(Detail::from(m).at_setting(s)));
    if let Split::Auto { pieces, .. } = a.split {
        if !(1..=MAX_PIECES).contains(&pieces) {
            return bad_setting(
                Setting::Split,
                Problem::SplitPieces {
                    pieces,
                    max: MAX_PIECES,
                },
            );
        }
    }
    if let Split::Counts(k) = &a.split {
        if k.len() != n || k.contains(&0) || a.split.pieces() > MAX_PIECES {
            return bad_setting(
                Setting::Split,
                Problem::SplitCounts {
                    counts: k.clone(),
                    n,
                    max: MAX_PIECES,
                },
            );
        }
    }
    if !(a.delta > 0.0 && a.delta < 1.0) {
        return bad_setting(Setting::Delta, Problem::Delta(a.delta));
    }
    if !(a.step >= MIN_REPORT_STEP && a.step.is_finite()) {
        return bad_setting(
            Setting::Step,
            Problem::Step {
                step: a.step,
                min: MIN_REPORT_STEP,
            },
        );
    }
    if !(a.horizon >= 0.0 && a.horizon.is_finite()) {
        return bad_setting(Setting::Horizon, Problem::Horizon(a.horizon));
    }
    if a.horizon / a.step > 1e8 {
        return bad_setting(
            Setting::Step,
            Problem::TooManyReportSteps(a.horizon / a.step),
        );
    }
    if let RadiusRule::Paper(eps) = a.radius {
        if !(eps > 0.0 && eps < 1.0) {
            return bad_setting(Setting::Radius, Problem::PaperEps(eps));
        }
    }
    if n == 0 {
        return bad(Problem::NoStates);
    }
    if info.states.len() != n {
        return bad(Problem::StateNames {
            names: info.states.len(),
            n,
        });
    }
    if info.input_box.len() != p {
        return bad(Problem::InputRanges {
            ranges: info.input_box.len(),
            p,
        });
    }
    let unsafe_parts = info
        .unsafe_sets
        .iter()
        .map(|u| (&u.name, std::slice::from_ref(&u.shape), &u.moving));
    let goal_parts = info
        .goals
        .iter()
        .map(|g| (&g.name, &g.parts[..], &g.moving));
    for (name, parts, moving) in unsafe_parts.chain(goal_parts) {
        if !moving.iter().all(|m| crate::sweep::fits(m, parts)) {
            return bad(Problem::MovingNumbers { set: name.clone() });
        }
    }
    for (j, b) in info.input_box.iter().enumerate() {
        if Interval::try_new(b.lo, b.hi).is_none_or(|iv| !iv.is_bounded()) {
            return bad(Problem::UnboundedInput {
                input: j,
                range: *b,
            });
        }
    }
    if let Some(&i) = a.outputs.iter().find(|&&i| i >= n) {
        return bad_setting(Setting::Outputs, Problem::Output { index: i, n });
    }
    Ok(())
}

/// Checks that the constants cover the model data: they were certified over its domain, its
/// input box and times up to at least the horizon. Editing any of those in a [`ModelInfo`]
/// after the compiler certified it gives this error, not a result labelled certified.
fn covered(info: &ModelInfo, spec: &AnalysisSpec, consts: &Constants) -> Result<(), RunError> {
    let region = &consts.region;
    let what = if region.domain != info.domain {
        Coverage::Domain
    } else if region.input_box != info.input_box {
        Coverage::InputBox
    } else if !(spec.horizon <= region.time.hi && region.time.lo <= 0.0) {
        Coverage::TimeRange
    } else {
        return Ok(());
    };
    Err(RunError::Invalid(
        Problem::NotCovered {
            analysis: spec.name.clone(),
            what,
        }
        .into(),
    ))
}

/// Checks an initial set against the model: one entry per state, and inside the domain when the
/// spec has one and `in_domain` asks for it (the global constants hold only there).
pub(crate) fn check_initial(
    info: &ModelInfo,
    initial: &InitialSet,
    in_domain: bool,
) -> Result<(), RunError> {
    let n = info.states.len();
    let (center, half) = radius::initial_center_and_halfwidths(initial, n)
        .map_err(|e| RunError::Invalid(Problem::InitialSet(e).into()))?;
    if info.has_domain && in_domain {
        for i in 0..n {
            // Boxes as given; ball coordinates by their bounding boxes (rounded outward).
            let Bounds { lo, hi } = initial.boxes[i].unwrap_or_else(|| {
                let (c, h) = (Interval::point(center[i]), Interval::point(half[i]));
                Bounds::new((c - h).lo(), (c + h).hi())
            });
            let domain = info.domain[i];
            if lo < domain.lo || hi > domain.hi {
                return Err(RunError::Invalid(
                    Detail::from(Problem::InitialOutsideDomain {
                        state: info.states[i].clone(),
                        range: Bounds { lo, hi },
                        domain,
                    })
                    .at(Culprit::State(i)),
                ));
            }
        }
    }
    Ok(())
}
