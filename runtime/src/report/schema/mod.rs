//! The JSON documents reachc writes, as one set of types for writing and for reading: the
//! result file of `reachc run` ([`ResultJson`], docs/results.md), the Monte Carlo report of
//! `reachc simulate` ([`SimJson`]) and the shapes of sets ([`ShapeJson`], also
//! `reachc inspect --json`). The runtime fills them from typed results
//! ([`to_json`](super::to_json), [`simulation::to_json`](super::simulation::to_json)); the plots
//! read them back. Whatever is written reads back and writes again as the same text
//! (`tests/tests/schema.rs`).
//!
//! Names of closed sets of choices are enums ([`Method`], [`Shape`], [`Status`], ...). A number
//! that may be non-finite is written as `null` (serde_json's rule) and read back as NaN, or as
//! an unbounded end of a range; a number the engine checks finite (the deterministic sets, the
//! radii) is a plain number, so a `null` there is a damaged file. Fields that files of older
//! versions lack read as their defaults.

mod names;
mod nullable;
mod probability;
mod result;
mod shape;
mod simulation;
mod text;

pub use names::{
    DtSource, DtStatus, GoalStatus, Guarantee, Inclusion, InputMode, Integrator, Method, MetricRef,
    RateSource, Role, Rule, Shape, Status, TransformSource, UniformBound, UnsafeKind,
};
pub use probability::{
    GoalLimitJson, GoalMissJson, GoalProbabilityJson, LimitJson, ProbabilityJson, SearchLimitJson,
};
pub use result::{
    AutoJson, ConstantsJson, DetSetJson, GaussianJson, GoalJson, HintJson, LogNormJson, PieceJson,
    PieceStepJson, RateJson, ResultJson, RuleJson, SpanJson, SplitJson, StepJson, TransformJson,
    UnsafeJson, ValidationJson, VerdictJson,
};
pub use shape::{ShapeJson, SideJson};
pub use simulation::{
    CoverageJson, DtRuleJson, HorizonJson, InputsJson, SafetyJson, SimGoalJson, SimJson,
    SimStateJson, SimStepJson, SimUnsafeJson, TubeJson,
};
