//! The checked model: names resolved, constants evaluated, families unrolled, tables loaded,
//! every expression lowered to the IR. Built from the syntax tree by [`check`].

mod check;

pub use check::check;

use crate::diagnostics::Span;
use crate::ir::{ExprId, Pool, Table};

// The analysis settings are the runtime's own types: the compiler hands them on unchanged.
pub use reachc_core::system::{Inclusion, Integrator, Method, RadiusRule, Rate};

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
    /// Noise channels (independent Wiener processes).
    pub noises: Vec<Variable>,
    /// `f_i(x, u, t)`, one per state.
    pub drift: Vec<ExprId>,
    /// `G[i][k](x, t)`: row per state, column per noise channel (the constant 0 where absent).
    pub diffusion: Vec<Vec<ExprId>>,
    /// The initial set.
    pub initial: InitialSet,
    /// Per state, the box where Assumption 1's bounds are taken (infinite bounds by default).
    pub domain: Vec<Bounds>,
    /// Whether a `domain` block was given (results are then conditional on staying inside it).
    pub has_domain: bool,
    /// Tabulated signals.
    pub tables: Vec<Table>,
    /// Unsafe sets.
    pub unsafe_sets: Vec<UnsafeSet>,
    /// The analyses to run.
    pub analyses: Vec<Analysis>,
    /// Named constants with their values, in declaration order.
    pub constants: Vec<(String, f64)>,
}

/// A closed interval `[lo, hi]` of reals; `lo` may be `-inf` and `hi` `+inf`.
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
}

/// A state, input or noise channel (one element of a family counts as one variable).
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    /// The name as it is printed in `.sde` syntax: `theta`, or `x[3]` for family elements.
    pub name: String,
    /// The declaration.
    pub span: Span,
    /// For inputs: the input box. For states with a box or point initial condition: that box.
    /// `None` for noise channels and for states in an initial ball.
    pub bounds: Option<Bounds>,
}

/// The initial set: the product of the per-state boxes (in [`Variable::bounds`]) and balls.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct InitialSet {
    /// Balls over groups of states; every state is in exactly one ball or has a box.
    pub balls: Vec<Ball>,
}

/// `{ x : |x_S - center|_M <= radius }` over the states `S`.
#[derive(Clone, Debug, PartialEq)]
pub struct Ball {
    /// Indices of the states it constrains.
    pub states: Vec<usize>,
    /// Its centre (one entry per state in `states`).
    pub center: Vec<f64>,
    /// Its radius (>= 0).
    pub radius: f64,
    /// The metric `M` (symmetric positive definite, `states.len()` square); identity if `None`.
    pub metric: Option<Vec<Vec<f64>>>,
    /// The `initial` block.
    pub span: Span,
}

/// A named unsafe set.
#[derive(Clone, Debug, PartialEq)]
pub struct UnsafeSet {
    /// Its name.
    pub name: String,
    /// The `unsafe` item.
    pub span: Span,
    /// Its shape.
    pub shape: UnsafeShape,
}

/// The shapes of unsafe sets.
#[derive(Clone, Debug, PartialEq)]
pub enum UnsafeShape {
    /// A box over some states (the others unconstrained): `(state, bounds)` pairs.
    Box(Vec<(usize, Bounds)>),
    /// A Euclidean ball over some states.
    Ball {
        /// The states it constrains.
        states: Vec<usize>,
        /// Its centre.
        center: Vec<f64>,
        /// Its radius.
        radius: f64,
    },
    /// `{ x : normal . x >= offset }` (`normal` has one entry per state).
    HalfSpace {
        /// Outward normal of the safe side.
        normal: Vec<f64>,
        /// Offset.
        offset: f64,
    },
}

/// The metric `P` for the contraction method.
#[derive(Clone, Debug, PartialEq)]
pub enum Metric {
    /// `P = I`.
    Identity,
    /// A given symmetric positive definite matrix.
    Matrix(Vec<Vec<f64>>),
    /// Synthesised by the compiler.
    Auto,
}

/// A coordinate transform `y = T x` of an interval analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct Transform {
    /// `T`, square and invertible, by rows.
    pub matrix: Vec<Vec<f64>>,
    /// `T^-1` computed in floating point (Gauss-Jordan with partial pivoting), by rows.
    pub inverse: Vec<Vec<f64>>,
}

/// An `analysis NAME { ... }` block, with defaults filled in.
#[derive(Clone, Debug, PartialEq)]
pub struct Analysis {
    /// Its name.
    pub name: String,
    /// The block.
    pub span: Span,
    /// `method` (default contraction).
    pub method: Method,
    /// `delta` in (0, 1) (default 1e-3).
    pub delta: f64,
    /// `horizon` > 0 (required).
    pub horizon: f64,
    /// `step` in (0, horizon] (default horizon / 100).
    pub step: f64,
    /// `metric` (default identity).
    pub metric: Metric,
    /// `radius` (default amgf).
    pub radius: RadiusRule,
    /// `rate`: where the contraction rate comes from (default certified; contraction only).
    pub rate: Rate,
    /// `inclusion` (default jacobian).
    pub inclusion: Inclusion,
    /// `integrator` (default rk4).
    pub integrator: Integrator,
    /// `transform`: the coordinate change `y = T x` (interval method only).
    pub transform: Option<Transform>,
    /// `outputs`: indices of the states to report (default all).
    pub outputs: Vec<usize>,
}
