//! Why a simulation, a merge or a part file failed, as data (the words are in
//! `crate::words`): [`SimError`] for a simulation or a recording of paths, [`MergeError`] for
//! parts that do not make one report, [`PartFileError`] for bytes that are not a part.

use super::shard::{Shard, ShardError};
use crate::engine::ThreadsError;
use crate::model::Bounds;

/// Why a simulation could not run.
#[derive(Clone, Debug, PartialEq)]
pub enum SimError {
    /// Bad options (a usage error).
    Usage(SimUsage),
    /// The model or result cannot be simulated (inconsistent data, unbounded initial set...).
    Invalid(SimInvalid),
}

/// Options a simulation refuses (the caller asked for something it cannot do).
#[derive(Clone, Debug, PartialEq)]
pub enum SimUsage {
    /// The number of paths is not in `1..=max`.
    Paths {
        /// The paths asked for.
        paths: u64,
        /// The most paths.
        max: u64,
    },
    /// More paths recorded than `max`.
    RecordedPaths {
        /// The paths asked for.
        paths: u64,
        /// The most paths recorded.
        max: u64,
    },
    /// A time step `dt` that is not positive and finite.
    Dt(f64),
    /// A time step `dt` given for a discrete-time model (its steps are its map's).
    DtDiscrete(f64),
    /// A time step `dt` (given or chosen) giving too many Euler steps.
    DtSteps(f64),
    /// A hold time that is not positive and finite.
    Hold(f64),
    /// A probability bound outside `[0, 1]`.
    ProbabilityBound(f64),
    /// Not one goal probability bound per goal set.
    GoalBounds {
        /// Bounds given.
        bounds: usize,
        /// Goal sets of the model.
        goals: usize,
    },
    /// A confidence outside `(0, 1)`.
    Confidence(f64),
    /// Too many Euler steps of `channels` noise channels: too many random numbers per path.
    TooManyDraws {
        /// Euler steps per path.
        steps: u64,
        /// Noise channels.
        channels: usize,
    },
    /// Too many Euler steps per recorded path.
    TooManyRecordedSteps(u64),
    /// Too many values to record: `paths` paths of `kept` states of `n` coordinates.
    TooManyValues {
        /// Paths.
        paths: u64,
        /// States kept per path.
        kept: u64,
        /// Coordinates per state.
        n: usize,
    },
    /// More shards than paths.
    Shards {
        /// The shard.
        shard: Shard,
        /// The paths of the whole run.
        paths: u64,
    },
    /// The exact quantiles would need more memory than `max_gib` GiB.
    QuantileMemory {
        /// Paths.
        paths: u64,
        /// The result's delta.
        delta: f64,
        /// Report times.
        steps: usize,
        /// States.
        n: usize,
        /// The bytes needed.
        bytes: u64,
        /// The most GiB.
        max_gib: u64,
    },
}

/// Data a simulation cannot use (the model or the result is inconsistent).
#[derive(Clone, Debug, PartialEq)]
pub enum SimInvalid {
    /// The result has `states` states and `steps` steps; the system `n` states.
    ResultSize {
        /// States of the result.
        states: usize,
        /// Report steps of the result.
        steps: usize,
        /// States of the system.
        n: usize,
    },
    /// The result's metric is not `n x n`.
    MetricSize,
    /// The result is under an input plan.
    InputPlan,
    /// The input box has `ranges` ranges, the system `p` inputs.
    InputRanges {
        /// Ranges of the input box.
        ranges: usize,
        /// Inputs of the system.
        p: usize,
    },
    /// An input range is not bounded.
    UnboundedInput(Bounds),
    /// The input box is not bounded or not one range per input (recording paths).
    InputBox,
    /// A nominal state has the wrong dimension.
    NominalSize,
    /// The report times do not start at 0 and increase.
    Times,
    /// An unsafe set or goal part does not fit the model.
    UnsafeSet(RegionFault),
    /// The span of report step `step` is malformed.
    Span {
        /// The report step.
        step: usize,
        /// What is wrong.
        fault: SpanFault,
    },
    /// The initial set cannot be sampled.
    Initial(InitialFault),
    /// The worker threads could not be started.
    Threads(ThreadsError),
    /// The part of the run could not be made a report.
    Merge(MergeError),
}

/// What is wrong with a set's shape ([`SimInvalid::UnsafeSet`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RegionFault {
    /// A box names a state out of range.
    State,
    /// A ball has a bad centre or state index.
    Ball,
    /// A half-space's normal has the wrong dimension.
    Normal,
}

/// What is wrong with a span of a result ([`SimInvalid::Span`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpanFault {
    /// A corner of the wrong dimension.
    Dimension,
    /// A lower corner not below its upper corner.
    Corners,
    /// A radius that is negative or NaN.
    Radius(f64),
}

/// Why an initial set cannot be sampled ([`SimInvalid::Initial`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InitialFault {
    /// `entries` per-state entries, `n` states.
    Entries {
        /// Entries of the set.
        entries: usize,
        /// States of the system.
        n: usize,
    },
    /// The box of `state` is not bounded.
    UnboundedBox {
        /// The state's index.
        state: usize,
        /// Its range.
        range: Bounds,
    },
    /// A ball with a bad centre or radius.
    Ball,
    /// `state` is in more than one part of the set (or out of range).
    Repeated {
        /// The state's index.
        state: usize,
    },
    /// A ball's metric is not positive definite.
    BallMetric,
    /// `state` has no initial value.
    Missing {
        /// The state's index.
        state: usize,
    },
}

/// Why parts cannot be merged, naming the offending parts by their labels (file names, for
/// `reachc simulate merge`).
#[derive(Clone, Debug, PartialEq)]
pub enum MergeError {
    /// The part `label` is not a valid part.
    Malformed {
        /// The part's label.
        label: String,
        /// What is wrong with it.
        fault: PartFault,
    },
    /// The first part's exact quantiles need more than `max_gib` GiB.
    QuantileMemory {
        /// The part's label.
        label: String,
        /// The quantile rank.
        rank: u64,
        /// Report times.
        steps: usize,
        /// States.
        n: usize,
        /// The most GiB.
        max_gib: u64,
    },
    /// Two parts of different simulations.
    OtherRun {
        /// The part's label.
        label: String,
        /// The first part's label.
        first: String,
        /// What differs.
        difference: RunDifference,
    },
    /// A part of another number of shards than the first.
    ShardCount {
        /// The part's label.
        label: String,
        /// Its shard.
        shard: Shard,
        /// The first part's label.
        first: String,
        /// The first part's number of shards.
        count: u64,
    },
    /// Two parts of the same shard.
    Repeated {
        /// The part's label.
        label: String,
        /// The other part's label.
        other: String,
        /// The shard.
        shard: Shard,
    },
    /// No parts.
    NoParts,
    /// Shards are missing.
    Missing {
        /// The first missing shards (at most 10).
        missing: Vec<Shard>,
        /// How many more are missing.
        more: u64,
        /// The shards there are.
        have: usize,
        /// The number of shards.
        count: u64,
    },
}

/// What differs between two parts' runs ([`MergeError::OtherRun`]).
#[derive(Clone, Debug, PartialEq)]
pub enum RunDifference {
    /// An option or name: `there` in this part, `first` in the first part (each as the part
    /// holds it).
    Option {
        /// Which.
        option: RunOption,
        /// This part's value.
        there: String,
        /// The first part's value.
        first: String,
    },
    /// The analysis' results or the sampling differ, with the same options.
    Results,
}

/// An option or name of a simulation run ([`RunDifference::Option`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RunOption {
    /// The reachc version.
    Version,
    /// The spec's SHA-256.
    Spec,
    /// The model's name.
    Model,
    /// The analysis' name.
    Analysis,
    /// The number of paths.
    Paths,
    /// The seed.
    Seed,
    /// The result's delta.
    Delta,
    /// `--dt`.
    Dt,
    /// `--inputs`.
    Inputs,
    /// `--hold`.
    Hold,
    /// `--confidence`.
    Confidence,
    /// The probability bound.
    ProbabilityBound,
    /// The goal probability bounds.
    GoalBounds,
}

/// What is wrong with a part read from a file ([`MergeError::Malformed`]).
#[derive(Clone, Debug, PartialEq)]
pub enum PartFault {
    /// Its shard does not fit its paths.
    Shard {
        /// The shard.
        shard: Shard,
        /// The paths of the whole run.
        paths: u64,
    },
    /// Its confidence or delta is out of range.
    Range {
        /// The confidence.
        confidence: f64,
        /// The delta.
        delta: f64,
    },
    /// Its statistics do not match its report times or unsafe sets.
    Statistics,
    /// Its quantile rank does not fit its paths.
    Rank {
        /// The rank.
        rank: u64,
        /// The paths.
        paths: u64,
    },
    /// Its counts are inconsistent with its `paths` paths.
    Counts {
        /// The part's paths.
        paths: u64,
    },
    /// `count` distances (of `state`, or of the metric) at report time `step`, not `kept`.
    Distances {
        /// Distances held.
        count: usize,
        /// The state, or `None` for the metric's distance.
        state: Option<usize>,
        /// The report time's index.
        step: usize,
        /// Distances expected.
        kept: u64,
    },
    /// The distances (of `state`, or of the metric) at report time `step` are not sorted.
    Unsorted {
        /// The state, or `None` for the metric's distance.
        state: Option<usize>,
        /// The report time's index.
        step: usize,
    },
}

/// Why bytes are not a part file.
#[derive(Clone, Debug, PartialEq)]
pub enum PartFileError {
    /// No part file header.
    NotAPart,
    /// Another format version.
    Version {
        /// The file's version.
        found: u32,
        /// The version this reachc reads.
        reads: u32,
    },
    /// `needed` bytes needed at byte `at`.
    Truncated {
        /// Bytes needed.
        needed: usize,
        /// Where.
        at: usize,
    },
    /// No checksum at the end.
    NoChecksum,
    /// The checksum does not match.
    Checksum,
    /// A byte that should be a flag.
    Flag {
        /// The byte.
        byte: u8,
        /// Where.
        at: usize,
    },
    /// A length that exceeds the file.
    Length {
        /// The length.
        length: u64,
        /// Where.
        at: usize,
    },
    /// Text that is not UTF-8.
    Utf8 {
        /// Where.
        at: usize,
    },
    /// An unknown code of an enum.
    Code {
        /// What the code is of.
        what: Coded,
        /// The code.
        code: u8,
        /// Where (`None`: not known).
        at: Option<usize>,
    },
    /// The noise entries do not fit in memory.
    NoiseEntries,
    /// Its shard is not one.
    Shard(ShardError),
    /// Bytes left before the checksum.
    Unexpected(usize),
}

/// What a code in a part file is of ([`PartFileError::Code`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coded {
    /// The analysis method.
    Method,
    /// The guarantee.
    Guarantee,
    /// The input mode.
    Inputs,
    /// How the initial states are sampled.
    InitialSampling,
    /// Where the time step comes from.
    DtSource,
    /// The kind of an unsafe set.
    UnsafeSet,
    /// The kind of noise.
    Noise,
}
