//! The checked model: names resolved, constants evaluated, families unrolled, tables loaded,
//! every expression lowered to the IR. Built from the syntax tree by [`check`].

mod check;

pub use check::check;
/// A metric scaled by a power of two to a largest entry in `[1, 2)` (as given metrics are).
pub(crate) use check::normalised as normalised_metric;

use crate::diagnostics::Span;
use crate::ir::{ExprId, Pool, Table};
use reachc_core::engine::Setting;
pub use reachc_core::model::Time;

// The sets and analyses are the core's data model: the checker lowers straight into it and the
// backends hand it on unchanged.
pub use reachc_core::model::{
    AnalysisSpec, Ball, Bounds, GoalSet, Guarantee, Inclusion, InitialSet, Integrator, Method,
    MetricChoice, Moving, RadiusRule, Rate, Slot, Split, Transform, UnsafeSet, UnsafeShape,
    AUTO_PIECES, MAX_PIECES,
};

/// A checked spec, ready for analysis and code generation.
#[derive(Clone, Debug)]
pub struct Model {
    /// `model NAME`.
    pub name: String,
    /// The doc comment before `model`.
    pub doc: Option<String>,
    /// All expressions of the model.
    pub pool: Pool,
    /// States, in declaration order (families unrolled: `x[1]`, `x[2]`, ...).
    pub states: Vec<Variable>,
    /// Bounded deterministic inputs.
    pub inputs: Vec<Variable>,
    /// The input box, one range per input.
    pub input_box: Vec<Bounds>,
    /// Noise channels (independent Wiener processes).
    pub noises: Vec<Variable>,
    /// Continuous time (`drift`) or discrete time (`discrete { period = .. }` and `update`).
    pub time: Time,
    /// `f_i(x, u, t)`, one per state: the drift, or in discrete time the map (the next state).
    pub drift: Vec<ExprId>,
    /// `G[i][k](x, t)`: row per state, column per noise channel (the constant 0 where absent).
    pub diffusion: Vec<Vec<ExprId>>,
    /// The initial set: per-state boxes (points are degenerate boxes) and balls.
    pub initial: InitialSet,
    /// Per state, the box where Assumption 1's bounds are taken (infinite bounds by default).
    pub domain: Vec<Bounds>,
    /// Whether a `domain` block was given (results are then conditional on staying inside it).
    pub has_domain: bool,
    /// Tabulated signals.
    pub tables: Vec<Table>,
    /// Unsafe sets.
    pub unsafe_sets: Vec<UnsafeSet>,
    /// Goal sets (method.md 8.13).
    pub goals: Vec<GoalSet>,
    /// The numbers of the moving unsafe and goal sets as expressions of `t` and tables
    /// (method.md 8.15), indexed by `Moving::number`: `System::set_numbers`.
    pub set_numbers: Vec<ExprId>,
    /// The analyses to run.
    pub analyses: Vec<Analysis>,
    /// Named constants with their values, in declaration order.
    pub constants: Vec<(String, f64)>,
}

/// A state, input or noise channel (one element of a family counts as one variable).
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    /// The name as it is printed in `.sde` syntax: `theta`, or `x[3]` for family elements.
    pub name: String,
    /// The declaration.
    pub span: Span,
}

/// An `analysis NAME { ... }` block, with defaults filled in, and where it was written.
#[derive(Clone, Debug, PartialEq)]
pub struct Analysis {
    /// The analysis (the runtime's data model).
    pub spec: AnalysisSpec,
    /// The block.
    pub span: Span,
    /// The name after `analysis`.
    pub name_span: Span,
    /// The settings written in the block, each with its `key = value` field (the places a
    /// run-time failure's [`Setting`] points at; a default points at the block).
    pub settings: Vec<(Setting, Span)>,
}
