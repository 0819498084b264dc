//! The English of the core, in one place: the `Display` impls of every error type the core
//! returns, rendering their typed payloads (times as the decimals they stand for, [`time`]),
//! and of the constants' provenance ([`Provenance`], [`MetricRegion`], [`MatrixBound`],
//! [`InputGain`]), which the runtime's reports and the compiler's generated documentation both
//! print (the compiler cannot reach the runtime). The rest of the core builds values, never
//! sentences; the reports' prose lives in the runtime (`reachc_runtime::report`).

use crate::decimal::time;
use crate::engine::{
    Coverage, Detail, InitialSetError, Integrated, NonFiniteQuantity, Note, Problem, RunError,
    SetKind, SetPart, ThreadsError, TightenError, UnsafeSetError, UnsafeSetFault,
};
use crate::model::{InputGain, MatrixBound, MetricRegion, NoConstants, Provenance};
use crate::simulate::{
    Coded, InitialFault, MergeError, PartFault, PartFileError, RegionFault, RunDifference,
    RunOption, ShardError, SimError, SimInvalid, SimUsage, SpanFault,
};
use std::fmt::{self, Display, Formatter};

/// Writes `items` separated by `", "`.
/// A region's ranges, `s in [lo, hi], ...`, and the closing parenthesis.
fn region_list(f: &mut Formatter<'_>, region: &[(String, crate::Interval)]) -> fmt::Result {
    list(f, region, |f, (s, v)| {
        write!(f, "{s} in [{:.4e}, {:.4e}]", v.lo(), v.hi())
    })?;
    f.write_str(")")
}

fn list<T>(
    f: &mut Formatter<'_>,
    items: &[T],
    one: impl Fn(&mut Formatter<'_>, &T) -> fmt::Result,
) -> fmt::Result {
    for (k, item) in items.iter().enumerate() {
        if k > 0 {
            f.write_str(", ")?;
        }
        one(f, item)?;
    }
    Ok(())
}

impl Display for RunError {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            RunError::UnknownAnalysis { name, available } => write!(
                f,
                "no analysis `{name}` (available: {})",
                available.join(", ")
            ),
            RunError::Unsupported(m) => write!(f, "unsupported: {m}"),
            RunError::NoConstants(m) => write!(f, "no constants: {m}"),
            RunError::Invalid(m) => write!(f, "invalid analysis: {m}"),
            RunError::NonFinite(m) => write!(f, "numerical failure: {m}"),
        }
    }
}

/// The problem, then each note in parentheses.
impl Display for Detail {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.problem)?;
        for note in &self.notes {
            write!(f, " ({note})")?;
        }
        Ok(())
    }
}

impl Display for Note {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            Note::Piece(ranges) => {
                f.write_str("in the piece ")?;
                list(f, ranges, |f, (x, r)| {
                    write!(f, "{x} in [{}, {}]", r.lo, r.hi)
                })?;
                f.write_str(" of the split initial box")
            }
            Note::AloneFailed => f.write_str(
                "the linearised Gaussian set alone (method.md 8.12) could not be bounded over the \
                 horizon either",
            ),
        }
    }
}

impl Display for Coverage {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Coverage::Domain => "domain",
            Coverage::InputBox => "input box",
            Coverage::TimeRange => "time range",
        })
    }
}

impl Integrated {
    /// What is integrated, as the subject of a sentence.
    fn what(self) -> &'static str {
        match self {
            Integrated::Nominal => "the nominal trajectory",
            Integrated::Embedding => "the embedding system",
        }
    }

    /// What to try instead.
    fn hint(self) -> &'static str {
        match self {
            Integrated::Nominal => "a smaller report step or a shorter horizon may help",
            Integrated::Embedding => {
                "the other inclusion, a coordinate transform, the contraction method, a smaller \
                 report step or a shorter horizon may help"
            }
        }
    }
}

impl Display for Problem {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            Problem::SplitPieces { pieces, max } => {
                write!(
                    f,
                    "split = auto(pieces = {pieces}) must allow 1 to {max} pieces"
                )
            }
            Problem::SplitCounts { counts, n, max } => write!(
                f,
                "split = {counts:?} must give one count of at least 1 per state ({n}), at most \
                 {max} pieces in all"
            ),
            Problem::Delta(delta) => write!(f, "delta = {delta} must lie in (0, 1)"),
            Problem::Step { step, min } => {
                write!(f, "step = {step} must be finite and at least {min:e}")
            }
            Problem::Horizon(h) => write!(f, "horizon = {h} must be non-negative and finite"),
            Problem::TooManyReportSteps(k) => {
                write!(f, "horizon / step = {k} report steps is too many")
            }
            Problem::PaperEps(eps) => {
                write!(f, "the paper rule's eps = {eps} must lie in (0, 1)")
            }
            Problem::Output { index, n } => {
                write!(f, "output state index {index} is out of range (n = {n})")
            }
            Problem::NoStates => f.write_str("the model has no states"),
            Problem::StateNames { names, n } => {
                write!(f, "the model info names {names} states, the system has {n}")
            }
            Problem::InputRanges { ranges, p } => {
                write!(
                    f,
                    "the input box has {ranges} ranges, the system has {p} inputs"
                )
            }
            Problem::MovingNumbers { set } => {
                write!(f, "the moving numbers of set `{set}` do not fit its shape")
            }
            Problem::UnboundedInput { input, range } => write!(
                f,
                "input box of input {input} is [{}, {}] (must be bounded)",
                range.lo, range.hi
            ),
            Problem::UnsafeSet(e) => write!(f, "{e}"),
            Problem::InitialSet(e) => write!(f, "{e}"),
            Problem::InitialBoxSize { ranges, n } => {
                write!(
                    f,
                    "the initial box has {ranges} ranges, the model {n} states"
                )
            }
            Problem::InitialOutsideDomain {
                state,
                range,
                domain,
            } => write!(
                f,
                "the initial set leaves the domain in state `{state}` ([{}, {}] is not in [{}, \
                 {}]): the constants hold only in the domain",
                range.lo, range.hi, domain.lo, domain.hi
            ),
            Problem::PlanTimes => f.write_str(
                "an input plan needs increasing times starting at 0, one value per time",
            ),
            Problem::PlanValueSize { entries, p } => {
                write!(
                    f,
                    "an input plan value has {entries} entries, the model {p} inputs"
                )
            }
            Problem::PlanValueOutside(u) => write!(
                f,
                "the input plan value {u:?} leaves the input box, where the constants hold"
            ),
            Problem::NoGoal { goal, goals } => {
                write!(f, "no goal {goal}: the model has {goals} goal sets")
            }
            Problem::MetricSize { entries, n } => {
                write!(f, "the metric has {entries} entries, expected {n} x {n}")
            }
            Problem::MetricIndefinite => {
                f.write_str("the metric P is not (certifiably) symmetric positive definite")
            }
            Problem::LocalMetricIndefinite => f.write_str("the metric is not positive definite"),
            Problem::MissingConstants {
                analysis,
                needs,
                why,
            } => {
                write!(f, "analysis `{analysis}` has no constants (")?;
                list(f, needs, |f, c| f.write_str(c.symbol()))?;
                write!(f, "): {why}")
            }
            Problem::ConstantNotFinite { constant, value } => {
                write!(f, "{} = {value} is not finite", constant.symbol())
            }
            Problem::NotCovered { analysis, what } => write!(
                f,
                "the constants of analysis `{analysis}` were certified for another {what} than \
                 the model's: change the spec and compile it again"
            ),
            Problem::LocalPointwise => f.write_str(
                "local rates with a pointwise guarantee (the proof that the process never leaves \
                 the regions needs the time-uniform tube): use `rate = global`",
            ),
            Problem::IntervalRate(rate) => write!(
                f,
                "a {} rate with the interval method (it uses a certified rate)",
                rate.name()
            ),
            Problem::PlanWithEmpiricalRate => f.write_str(
                "an input plan with an empirical rate (its sample paths draw random inputs)",
            ),
            Problem::SplitNotABox => f.write_str(
                "splitting an initial set that is not a box (an initial ball): give the states \
                 ranges, or remove `split`",
            ),
            Problem::LocalRatesNeedDiagonal { max } => write!(
                f,
                "local rates for more than {max} states need a diagonal metric (give `metric = \
                 identity` or `rate = global`)"
            ),
            Problem::NoFrame { analysis, frame } => write!(
                f,
                "analysis `{analysis}` has a coordinate transform but the system has no frame \
                 {frame} (code generated by an older reachc: regenerate it)"
            ),
            Problem::SafetyNeedsUniform => f.write_str(
                "a probability of safety over the horizon needs `guarantee = uniform` (a \
                 pointwise PRS bounds each time separately, not the path)",
            ),
            Problem::SafetyNeedsUnsafeSets => {
                f.write_str("a probability of safety needs unsafe sets (the model has none)")
            }
            Problem::GoalNeedsUniform => f.write_str(
                "a probability of reaching a goal needs `guarantee = uniform` (a pointwise PRS \
                 bounds each time separately, not the path)",
            ),
            Problem::TransformSize { n, matrix, inverse } => write!(
                f,
                "the transform must be {n} x {n} (it has {matrix} entries, its inverse {inverse})"
            ),
            Problem::TransformNotFinite => {
                f.write_str("the transform or its inverse has non-finite entries")
            }
            Problem::TransformIllConditioned(r) => write!(
                f,
                "the transform's inverse is inaccurate (|I - T^-1 T| = {r:.3e}): T is too \
                 ill-conditioned"
            ),
            Problem::FrameSize {
                frame,
                states,
                inputs,
                n,
                p,
            } => write!(
                f,
                "frame {frame} has {states} states and {inputs} inputs, the system {n} and {p}"
            ),
            Problem::NominalNotFinite {
                t,
                integrator,
                step,
            } => write!(
                f,
                "the nominal trajectory is not finite at t = {} ({} integration, step {step}; the \
                 default validated integrator reports where and why a step fails)",
                time(*t),
                integrator.name()
            ),
            Problem::EmbeddingNotFinite {
                t,
                inclusion,
                integrator,
                step,
            } => write!(
                f,
                "the embedding system's box is not finite at t = {} (the {} inclusion diverged \
                 with {} integration, step {step}; try the validated integrator, the other \
                 inclusion or a coordinate transform)",
                time(*t),
                inclusion.name(),
                integrator.name()
            ),
            Problem::TooManySteps { what, limit, t } => write!(
                f,
                "{} needs more than {limit} validated steps before t = {} ({})",
                what.what(),
                time(*t),
                what.hint()
            ),
            Problem::TooManyStepsInInterval {
                what,
                limit,
                window,
                t,
            } => write!(
                f,
                "{} needs more than {limit} validated steps in the report interval [{}, {}] (at \
                 t = {}): it grows without bound there, or is too stiff for this report step \
                 ({})",
                what.what(),
                time(window[0]),
                time(window[1]),
                time(*t),
                what.hint()
            ),
            Problem::NominalStepTooSmall { t, min_step } => write!(
                f,
                "the nominal trajectory cannot be validated at t = {}: the step shrank below \
                 {min_step:e} without bounding the defect (the drift is too large or not smooth \
                 here: a shorter horizon or a smaller report step may help)",
                time(*t)
            ),
            Problem::EmbeddingStepTooSmall { t, min_step, width } => write!(
                f,
                "the embedding system cannot be validated at t = {}: the step would have to be \
                 shorter than {min_step:e} (a millionth of the report step), with the box \
                 {width:e} wide and growing without bound there (try the other inclusion, a \
                 coordinate transform, the contraction method or a shorter horizon)",
                time(*t)
            ),
            Problem::LeavesDomain { state, t } => write!(
                f,
                "the nominal trajectory leaves the domain in state {state} near t = {}: the \
                 constants hold only in the domain (enlarge it, or shorten the horizon)",
                time(*t)
            ),
            Problem::LocalRates { t, region, entry } => {
                write!(
                    f,
                    "the local rates cannot be certified at t = {}: no region around the tube \
                     holds the tube its own rates give (last region tried: ",
                    time(*t)
                )?;
                region_list(f, region)?;
                if let Some(e) = entry {
                    write!(
                        f,
                        "; the Jacobian entry d f[{}] / d {} grew to [{:.4e}, {:.4e}] there",
                        e.row,
                        e.col,
                        e.value.lo(),
                        e.value.hi()
                    )?;
                }
                f.write_str(". A shorter horizon, a smaller initial set or less noise may help")
            }
            Problem::DiscreteSetting(setting) => write!(
                f,
                "`{}` as given does not apply to a discrete-time model",
                setting.key()
            ),
            Problem::NotWholePeriods {
                setting,
                value,
                period,
            } => write!(
                f,
                "{} = {value} is not a whole number of periods (period {period})",
                setting.key()
            ),
            Problem::TooManyMapSteps { steps, max } => write!(
                f,
                "the horizon is {steps} steps of the map, more than the {max} a run may take: a \
                 shorter horizon or a longer period may help"
            ),
            Problem::MapFactor {
                t,
                region,
                pointwise,
            } => {
                write!(
                    f,
                    "the map's factor or noise level cannot be bounded on the step from t = {} \
                     (region: ",
                    time(*t)
                )?;
                region_list(f, region)?;
                if *pointwise {
                    f.write_str(
                        ": a pointwise guarantee bounds them over the whole domain; \
                         `guarantee = uniform` bounds them on the tube, or give a `domain`",
                    )
                } else {
                    f.write_str(". A shorter horizon, a smaller initial set or less noise may help")
                }
            }
            Problem::MapNotFinite { t } => write!(
                f,
                "the interval method's box of the map is not finite at t = {}: the contraction \
                 method or a shorter horizon may help",
                time(*t)
            ),
            Problem::EmpiricalSampling(e) => {
                write!(f, "sampling paths for the empirical rate: {e}")
            }
            Problem::EmpiricalPathNotFinite(t) => write!(
                f,
                "a sample path of the empirical rate estimate is not finite at t = {}",
                time(*t)
            ),
            Problem::EmpiricalRateNotFinite(t) => write!(
                f,
                "no finite empirical rate at t = {} (every sample equals the nominal, or a drift \
                 is not finite)",
                time(*t)
            ),
            Problem::NotFinite { t, what } => {
                write!(f, "the PRS is not finite from t = {} on: {what}", time(*t))
            }
            Problem::Threads(e) => write!(f, "{e}"),
        }
    }
}

impl Display for InitialSetError {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match *self {
            InitialSetError::Entries { entries, n } => write!(
                f,
                "the initial set has {entries} per-state entries, the model has {n} states"
            ),
            InitialSetError::UnboundedBox { state, range } => write!(
                f,
                "initial box of state {state} is [{}, {}] (must be bounded)",
                range.lo, range.hi
            ),
            InitialSetError::MalformedBall { ball } => {
                write!(f, "initial ball #{ball} is malformed")
            }
            InitialSetError::BallMetricSize { ball, k } => {
                write!(f, "initial ball #{ball}: metric is not {k} x {k}")
            }
            InitialSetError::BallMetricIndefinite { ball } => write!(
                f,
                "initial ball #{ball}: metric is not (certifiably) positive definite"
            ),
            InitialSetError::BallState { ball, state, n } => {
                write!(f, "initial ball #{ball} refers to state {state} (n = {n})")
            }
            InitialSetError::Missing { state } => write!(
                f,
                "state {state} is in neither an initial box nor an initial ball"
            ),
        }
    }
}

impl std::error::Error for InitialSetError {}

impl Display for UnsafeSetError {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        write!(f, "unsafe set `{}`: ", self.set)?;
        match self.fault {
            UnsafeSetFault::NormalLength { entries, n } => {
                write!(f, "normal has {entries} entries, n = {n}")
            }
            UnsafeSetFault::State { state, n } => write!(f, "refers to state {state}, n = {n}"),
            UnsafeSetFault::Ball => f.write_str("states and centre do not match the model"),
        }
    }
}

impl std::error::Error for UnsafeSetError {}

impl Display for ThreadsError {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        write!(f, "cannot start {} threads: {}", self.threads, self.cause)
    }
}

impl std::error::Error for ThreadsError {}

impl SetKind {
    /// The set, as the subject of a sentence.
    fn subject(self) -> &'static str {
        match self {
            SetKind::Ball => "the deterministic ball",
            SetKind::Box => "the deterministic box",
            SetKind::Parallelotope => "the deterministic parallelotope",
            SetKind::Zonotope => "the first-order zonotope",
        }
    }

    /// The name of its radius.
    fn radius(self) -> &'static str {
        match self {
            SetKind::Ball => "radius R_t",
            SetKind::Box | SetKind::Parallelotope | SetKind::Zonotope => "P-radius",
        }
    }
}

impl Display for NonFiniteQuantity {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            NonFiniteQuantity::Radius { r_t, psi } => write!(
                f,
                "the stochastic radius r_t = {r_t} (Psi_t = {psi:e}) overflowed"
            ),
            NonFiniteQuantity::Psi { r_t, c, sigma } => write!(
                f,
                "the stochastic radius r_t = {r_t}: Psi_t overflowed (c = {c}, sigma = {sigma}: \
                 the noise grows faster than the contraction damps it; a shorter horizon or less \
                 noise may help)"
            ),
            NonFiniteQuantity::Deterministic { set, part } => {
                let kind = set.subject();
                match part {
                    SetPart::Centre { state, value } => {
                        write!(f, "{kind}'s centre in state `{state}` is {value}")?
                    }
                    SetPart::Radius(v) => write!(f, "{kind}'s {} is {v}", set.radius())?,
                    SetPart::Hull { state, lo, hi } => {
                        write!(f, "{kind}'s hull in state `{state}` is [{lo}, {hi}]")?
                    }
                    SetPart::Remainder(v) => write!(f, "{kind}'s remainder is {v}")?,
                    SetPart::Corners { coordinate, lo, hi } => write!(
                        f,
                        "{kind}'s bounds in coordinate {coordinate} (y = T x) are [{lo}, {hi}]"
                    )?,
                }
                f.write_str(" (the deterministic reachable set grew without bound)")
            }
            NonFiniteQuantity::Span { state, lo, hi } => write!(
                f,
                "the span over the report interval in state `{state}` is [{lo}, {hi}]"
            ),
            NonFiniteQuantity::PrsRadius(v) => write!(f, "the radius of the PRS is {v}"),
            NonFiniteQuantity::SpanRadius(v) => {
                write!(f, "the span's radius over the report interval is {v}")
            }
            NonFiniteQuantity::PointwiseRadius(v) => {
                write!(f, "the pointwise radius r_pointwise is {v}")
            }
        }
    }
}

impl Display for SimError {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            SimError::Usage(m) => write!(f, "{m}"),
            SimError::Invalid(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for SimError {}

impl Display for SimUsage {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match *self {
            SimUsage::Paths { paths, max } => write!(
                f,
                "the number of paths must be between 1 and {max}, not {paths}"
            ),
            SimUsage::RecordedPaths { paths, max } => {
                write!(f, "at most {max} paths can be recorded, not {paths}")
            }
            SimUsage::Dt(dt) => write!(f, "dt = {dt} must be positive and finite"),
            SimUsage::DtDiscrete(dt) => write!(
                f,
                "dt = {dt}: a discrete-time model is simulated one step of its map at a time, \
                 exactly; leave out --dt"
            ),
            SimUsage::DtSteps(dt) => write!(f, "dt = {dt} gives too many Euler steps"),
            SimUsage::Hold(hold) => {
                write!(f, "the hold time {hold} must be positive and finite")
            }
            SimUsage::ProbabilityBound(b) => {
                write!(f, "the probability bound {b} must lie in [0, 1]")
            }
            SimUsage::GoalBounds { bounds, goals } => {
                write!(f, "{bounds} goal probability bounds for {goals} goal sets")
            }
            SimUsage::Confidence(c) => write!(f, "the confidence {c} must lie in (0, 1)"),
            SimUsage::TooManyDraws { steps, channels } => write!(
                f,
                "{steps} Euler steps of {channels} noise channels are too many random numbers \
                 per path"
            ),
            SimUsage::TooManyRecordedSteps(steps) => {
                write!(f, "{steps} Euler steps per path are too many")
            }
            SimUsage::TooManyValues { paths, kept, n } => write!(
                f,
                "{paths} paths of {kept} states of {n} coordinates are too many values to record"
            ),
            SimUsage::Shards { shard, paths } => write!(
                f,
                "shard {shard} of {paths} paths: the number of shards must be at most the number \
                 of paths"
            ),
            SimUsage::QuantileMemory {
                paths,
                delta,
                steps,
                n,
                bytes,
                max_gib,
            } => write!(
                f,
                "exact quantiles of {paths} paths at delta = {delta} over {steps} report times \
                 and {n} states need {:.1} GiB (more than {max_gib} GiB): use fewer paths",
                bytes as f64 / f64::from(1u32 << 30)
            ),
        }
    }
}

impl Display for SimInvalid {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            SimInvalid::ResultSize { states, steps, n } => write!(
                f,
                "the result has {states} states and {steps} steps; the system has {n} states"
            ),
            SimInvalid::MetricSize => f.write_str("the result's metric is not n x n"),
            SimInvalid::InputPlan => f.write_str(
                "sets under an input plan cannot be simulated (the paths draw inputs from the \
                 input box)",
            ),
            SimInvalid::InputRanges { ranges, p } => {
                write!(
                    f,
                    "the input box has {ranges} ranges, the system has {p} inputs"
                )
            }
            SimInvalid::UnboundedInput(b) => {
                write!(f, "the input box [{}, {}] is not bounded", b.lo, b.hi)
            }
            SimInvalid::InputBox => {
                f.write_str("the input box must be bounded, one range per input")
            }
            SimInvalid::NominalSize => f.write_str("a nominal state has the wrong dimension"),
            SimInvalid::Times => f.write_str("the report times must start at 0 and increase"),
            SimInvalid::UnsafeSet(fault) => f.write_str(match fault {
                RegionFault::State => "an unsafe set has a state index out of range",
                RegionFault::Ball => "an unsafe set has a bad centre or state index",
                RegionFault::Normal => "an unsafe set has a normal of the wrong dimension",
            }),
            SimInvalid::Span { step, fault } => {
                write!(f, "the span of report step {step} has ")?;
                match fault {
                    SpanFault::Dimension => f.write_str("a corner of the wrong dimension"),
                    SpanFault::Corners => {
                        f.write_str("a lower corner that is not below its upper corner")
                    }
                    SpanFault::Radius(r) => write!(f, "the radius {r}"),
                }
            }
            SimInvalid::Initial(fault) => write!(f, "{fault}"),
            SimInvalid::Threads(e) => write!(f, "{e}"),
            SimInvalid::Merge(e) => write!(f, "{e}"),
        }
    }
}

impl Display for InitialFault {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match *self {
            InitialFault::Entries { entries, n } => write!(
                f,
                "the initial set has {entries} entries, the system has {n} states"
            ),
            InitialFault::UnboundedBox { state, range } => write!(
                f,
                "the initial box of state {state} is [{}, {}]: it must be bounded",
                range.lo, range.hi
            ),
            InitialFault::Ball => f.write_str("an initial ball has a bad centre or radius"),
            InitialFault::Repeated { state } => write!(
                f,
                "state {state} is in more than one part of the initial set"
            ),
            InitialFault::BallMetric => {
                f.write_str("an initial ball's metric is not positive definite")
            }
            InitialFault::Missing { state } => write!(f, "state {state} has no initial value"),
        }
    }
}

impl Display for MergeError {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            MergeError::Malformed { label, fault } => {
                write!(f, "`{label}` is not a valid part: {fault}")
            }
            MergeError::QuantileMemory {
                label,
                rank,
                steps,
                n,
                max_gib,
            } => write!(
                f,
                "`{label}`: exact quantiles of rank {rank} over {steps} report times and {n} \
                 states need more than {max_gib} GiB"
            ),
            MergeError::OtherRun {
                label,
                first,
                difference,
            } => write!(
                f,
                "`{label}` and `{first}` are not parts of the same simulation: {difference}"
            ),
            MergeError::ShardCount {
                label,
                shard,
                first,
                count,
            } => write!(
                f,
                "`{label}` is shard {shard} but `{first}` is one of {count} shards"
            ),
            MergeError::Repeated {
                label,
                other,
                shard,
            } => write!(f, "`{label}` and `{other}` are both shard {shard}"),
            MergeError::NoParts => f.write_str("no parts to merge"),
            MergeError::Missing {
                missing,
                more,
                have,
                count,
            } => {
                write!(
                    f,
                    "missing shard{} ",
                    if missing.len() > 1 { "s" } else { "" }
                )?;
                list(f, missing, |f, s| write!(f, "{s}"))?;
                if *more > 0 {
                    write!(f, " and {more} more")?;
                }
                write!(f, " (have {have} of {count})")
            }
        }
    }
}

impl std::error::Error for MergeError {}

impl Display for RunDifference {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            RunDifference::Option {
                option,
                there,
                first,
            } => {
                let name = match option {
                    RunOption::Version => "reachc version",
                    RunOption::Spec => "spec (SHA-256)",
                    RunOption::Model => "model",
                    RunOption::Analysis => "analysis",
                    RunOption::Paths => "paths",
                    RunOption::Seed => "seed",
                    RunOption::Delta => "delta",
                    RunOption::Dt => "dt",
                    RunOption::Inputs => "inputs",
                    RunOption::Hold => "hold",
                    RunOption::Confidence => "confidence",
                    RunOption::ProbabilityBound => "probability bound",
                    RunOption::GoalBounds => "goal probability bounds",
                };
                write!(f, "{name} {there} there, {first} in the first part")
            }
            RunDifference::Results => {
                f.write_str("the analysis' results or the sampling differ (same options)")
            }
        }
    }
}

impl Display for PartFault {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        let of = |state: Option<usize>| state.map_or(String::new(), |i| format!(" of state {i}"));
        match *self {
            PartFault::Shard { shard, paths } => write!(f, "shard {shard} of {paths} paths"),
            PartFault::Range { confidence, delta } => {
                write!(f, "confidence {confidence} or delta {delta} out of range")
            }
            PartFault::Statistics => {
                f.write_str("its statistics do not match its report times or unsafe sets")
            }
            PartFault::Rank { rank, paths } => write!(f, "quantile rank {rank} of {paths} paths"),
            PartFault::Counts { paths } => {
                write!(f, "counts inconsistent with its {paths} paths")
            }
            PartFault::Distances {
                count,
                state,
                step,
                kept,
            } => write!(
                f,
                "{count} distances{} at report time {step}, expected {kept}",
                of(state)
            ),
            PartFault::Unsorted { state, step } => write!(
                f,
                "the distances{} at report time {step} are not sorted",
                of(state)
            ),
        }
    }
}

impl Display for PartFileError {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            PartFileError::NotAPart => {
                f.write_str("not a reachc simulate part file (no `reachc simulate part` header)")
            }
            PartFileError::Version { found, reads } => write!(
                f,
                "part file format version {found}; this reachc reads version {reads}"
            ),
            PartFileError::Truncated { needed, at } => {
                write!(f, "truncated: {needed} bytes needed at byte {at}")
            }
            PartFileError::NoChecksum => f.write_str("truncated: no checksum"),
            PartFileError::Checksum => {
                f.write_str("corrupt or truncated: the checksum does not match")
            }
            PartFileError::Flag { byte, at } => write!(f, "byte {byte} at {at} is not a flag"),
            PartFileError::Length { length, at } => {
                write!(f, "a length of {length} at byte {at} exceeds the file")
            }
            PartFileError::Utf8 { at } => write!(f, "the text at byte {at} is not UTF-8"),
            PartFileError::Code { what, code, at } => {
                let what = match what {
                    Coded::Method => "method",
                    Coded::Guarantee => "guarantee",
                    Coded::Inputs => "inputs",
                    Coded::InitialSampling => "initial sampling",
                    Coded::DtSource => "dt source",
                    Coded::UnsafeSet => "unsafe set",
                    Coded::Noise => "noise",
                };
                write!(f, "unknown {what} code {code}")?;
                match at {
                    Some(at) => write!(f, " at byte {at}"),
                    None => Ok(()),
                }
            }
            PartFileError::NoiseEntries => f.write_str("noise entries overflow"),
            PartFileError::Shard(e) => write!(f, "{e}"),
            PartFileError::Unexpected(k) => {
                write!(f, "{k} unexpected bytes before the checksum")
            }
        }
    }
}

impl std::error::Error for PartFileError {}

impl Display for NoConstants {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            NoConstants::Unbounded { entry, expression } => {
                write!(f, "{entry} = {expression} is unbounded over the domain")
            }
            NoConstants::BadMetric { reason } => write!(f, "invalid metric: {reason}"),
            NoConstants::NotCertified { constant } => {
                write!(f, "could not certify a bound for {constant}")
            }
        }
    }
}

impl Display for MetricRegion {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            MetricRegion::Given => "given in the spec",
            MetricRegion::Domain => "synthesised for the Jacobian over the domain",
            MetricRegion::InitialSet => {
                "synthesised for the Jacobian over the initial set during the first report step"
            }
            MetricRegion::Map => {
                "chosen for the map at the initial set's centre (the inverse of the deviation's \
                 covariance at the horizon for an affine map with additive noise, else the \
                 solution of A' P A - P = -I)"
            }
            MetricRegion::IdentityAtRun => {
                "the identity: a smaller PRS at the horizon than the metric synthesised over the \
                 initial set (both were run)"
            }
        })
    }
}

impl Display for MatrixBound {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        let fixed_note = |fixed: usize| {
            if fixed == 0 {
                String::new()
            } else {
                format!(", {fixed} fixed at one end by semidefiniteness")
            }
        };
        match *self {
            MatrixBound::Vertices {
                count,
                atoms,
                fixed,
            } => write!(
                f,
                "max over {count} vertex matri{} ({atoms} atom{}{})",
                if count == 1 { "x" } else { "ces" },
                if atoms == 1 { "" } else { "s" },
                fixed_note(fixed)
            ),
            MatrixBound::Hull {
                atoms,
                fixed,
                vertex_limit,
            } => write!(
                f,
                "interval-matrix bound ({atoms} atoms{}, {} free > {vertex_limit}, too many \
                 vertices)",
                fixed_note(fixed),
                atoms - fixed
            ),
        }
    }
}

impl Display for InputGain {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            InputGain::NoInputs => f.write_str("no inputs"),
            InputGain::Corners(m) => write!(f, "{m}, max over the input box's corners"),
            InputGain::Columns(m) => write!(f, "{m}, column bound (many inputs)"),
        }
    }
}

impl Display for Provenance {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        let (c, sigma, rho) =
            match self {
                Provenance::Certified { c, sigma, rho } => (c, sigma, rho),
                Provenance::Given => return f.write_str("given by hand, not certified by reachc"),
                Provenance::Map => return f.write_str(
                    "a discrete-time model: the map's factors are bounded on each step's region \
                     at run time",
                ),
                Provenance::Unbounded { why } => {
                    return write!(f, "not bounded over the domain ({why})");
                }
            };
        match c {
            Some(c) => write!(f, "c: {c}; ")?,
            None => f.write_str("c: not bounded by the compiler; ")?,
        }
        write!(f, "sigma: {sigma}; rho: {rho}; certified by interval LDL'")
    }
}

impl Display for TightenError {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            TightenError::Malformed { index, what } => write!(f, "constraint {index}: {what}"),
            TightenError::UnsafeSet(name) => {
                write!(f, "unsafe set `{name}` does not fit the model")
            }
            TightenError::NoDeviationBound => f.write_str(
                "the result is the linearised Gaussian set alone (method.md 8.12): it bounds the \
                 state, not its distance from the nominal, so it gives no tightening",
            ),
            TightenError::Metric => f.write_str("the result's metric is not positive definite"),
        }
    }
}

impl Display for ShardError {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            ShardError::NoShards => write!(f, "the number of shards must be at least 1"),
            ShardError::IndexTooLarge { index, count } => write!(
                f,
                "shard {index}/{count}: the index must be below the number of shards (0-based)"
            ),
            ShardError::Syntax { text } => {
                write!(
                    f,
                    "shard `{text}`: expected I/K with whole numbers, e.g. 0/8"
                )
            }
        }
    }
}
