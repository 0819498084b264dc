//! The syntax tree of a `.sde` spec, exactly as written (no names resolved, no loops unrolled).
//!
//! Every node carries the byte span it was parsed from so later passes can point at it.

use crate::diagnostics::Span;

/// An identifier as written.
#[derive(Clone, Debug, PartialEq)]
pub struct Ident {
    /// The name (ASCII letters, digits, `_`; not starting with a digit).
    pub name: String,
    /// Where it was written.
    pub span: Span,
}

/// A whole spec file.
#[derive(Clone, Debug, PartialEq)]
pub struct Spec {
    /// `///` doc-comment lines before `model`, joined with newlines (without the `///`).
    pub doc: Option<String>,
    /// The `model NAME` line (the parser reports a missing one and leaves this `None`).
    pub model: Option<Ident>,
    /// Every top-level item, in source order.
    pub items: Vec<Item>,
}

/// A top-level item.
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    /// `const NAME = EXPR`
    Const {
        /// The name.
        name: Ident,
        /// Its value (an expression over numbers and earlier constants).
        value: Expr,
        /// The whole item.
        span: Span,
    },
    /// `state NAME`, `state NAME in EXPR`, `state NAME = EXPR`, `state NAME[LO..HI] ...`
    State(VarDecl),
    /// `input NAME in EXPR` (also indexed: `input u[1..M] in [-1, 1]`).
    Input(VarDecl),
    /// `noise NAME` (also indexed: `noise w[1..3]`).
    Noise(VarDecl),
    /// `table NAME = csv("path.csv")`
    Table {
        /// The table's name (columns are read as `NAME.COLUMN`).
        name: Ident,
        /// The path string as written (relative to the spec file).
        path: String,
        /// Span of the path string literal.
        path_span: Span,
        /// The whole item.
        span: Span,
    },
    /// A top-level `let` or `for` (definitions for intermediate quantities).
    Stmt(Stmt),
    /// `drift { ... }`: equations `x' = EXPR`, lets, for loops.
    Drift {
        /// The statements.
        body: Block,
        /// The whole item, from the keyword.
        span: Span,
    },
    /// `diffusion { ... }`: rows `x: EXPR` (linear in the noise names), lets, for loops.
    Diffusion(Block),
    /// `domain { ... }`: memberships `x in [lo, hi]`, for loops.
    Domain(Block),
    /// `discrete { period = EXPR }`: the model is discrete time, stepped every `period`.
    Discrete {
        /// Its fields (`period`).
        body: Block,
        /// The whole item, from the keyword.
        span: Span,
    },
    /// `update { ... }`: the next state of a discrete-time model: update equations `x = EXPR`,
    /// lets, for loops.
    Update {
        /// The statements.
        body: Block,
        /// The whole item, from the keyword.
        span: Span,
    },
    /// `initial KIND { ... }` (KIND is `ball`): fields `over = [..]`, `center`, `radius`, `metric`.
    Initial {
        /// The kind of set (`ball`).
        kind: Ident,
        /// Its fields.
        body: Block,
        /// The whole item.
        span: Span,
    },
    /// `unsafe NAME KIND { ... }` (KIND is `box`, `ball` or `halfspace`).
    Unsafe {
        /// The set's name (used in verdicts).
        name: Ident,
        /// `box`, `ball` or `halfspace`.
        kind: Ident,
        /// Memberships (box), fields (ball), or one constraint (halfspace).
        body: Block,
        /// The whole item.
        span: Span,
    },
    /// `goal NAME KIND { ... } [and KIND { ... }]... [within [T1, T2]] [stay]` (method.md 8.13).
    Goal {
        /// The goal's name (used in verdicts).
        name: Ident,
        /// The sets whose intersection is the goal: each `box`, `ball` or `halfspace` with its
        /// block, as for unsafe sets.
        parts: Vec<(Ident, Block)>,
        /// `within [T1, T2]`: when entering counts.
        window: Option<Expr>,
        /// `stay` (remain in the goal until the horizon): the word, if written.
        stay: Option<Span>,
        /// The whole item.
        span: Span,
    },
    /// `analysis NAME { key = value ... }`
    Analysis {
        /// The analysis name.
        name: Ident,
        /// Its `key = value` fields.
        body: Block,
        /// The whole item.
        span: Span,
    },
}

/// A `state`, `input` or `noise` declaration.
#[derive(Clone, Debug, PartialEq)]
pub struct VarDecl {
    /// The name.
    pub name: Ident,
    /// `[LO..HI]` after the name: an indexed family (both bounds inclusive).
    pub family: Option<IndexRange>,
    /// `in EXPR` (a set, usually an interval `[lo, hi]`) or `= EXPR` (a point).
    pub init: Option<Init>,
    /// The whole declaration.
    pub span: Span,
}

/// An inclusive integer range `LO..HI` (in `x[1..N]` and `for i in 1..N`).
#[derive(Clone, Debug, PartialEq)]
pub struct IndexRange {
    /// First index.
    pub lo: Expr,
    /// Last index (inclusive).
    pub hi: Expr,
    /// The `LO..HI` text.
    pub span: Span,
}

/// The initial value or set written in a declaration.
#[derive(Clone, Debug, PartialEq)]
pub enum Init {
    /// `in EXPR`: the value is a set (an interval list `[lo, hi]`).
    In(Expr),
    /// `= EXPR`: a point.
    Point(Expr),
}

/// A `{ ... }` block of statements.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// The statements, in order.
    pub stmts: Vec<Stmt>,
    /// From `{` to `}`.
    pub span: Span,
}

/// A reference to a (possibly indexed) name on the left of a statement: `x` or `x[i + 1]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Target {
    /// The name.
    pub name: Ident,
    /// The index expression, for families.
    pub index: Option<Box<Expr>>,
    /// The whole target.
    pub span: Span,
}

/// Comparison in a half-space constraint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CmpOp {
    /// `<=`
    Le,
    /// `>=`
    Ge,
}

/// A statement inside a block (or at top level, for `let` and `for`).
#[derive(Clone, Debug, PartialEq)]
pub enum Stmt {
    /// `x' = EXPR` (drift equation).
    Equation {
        /// The state.
        target: Target,
        /// Right-hand side.
        rhs: Expr,
        /// The whole statement.
        span: Span,
    },
    /// `x = EXPR` (update equation of a discrete-time model: the next value of `x`).
    Update {
        /// The state.
        target: Target,
        /// Right-hand side (at step `k`).
        rhs: Expr,
        /// The whole statement.
        span: Span,
    },
    /// `x: EXPR` (diffusion row: a linear combination of noise names).
    Row {
        /// The state.
        target: Target,
        /// Right-hand side.
        rhs: Expr,
        /// The whole statement.
        span: Span,
    },
    /// `x in EXPR` (domain, unsafe box).
    Member {
        /// The state.
        target: Target,
        /// The set (an interval list).
        set: Expr,
        /// The whole statement.
        span: Span,
    },
    /// `key = EXPR` (fields of analysis, initial and unsafe ball blocks).
    Field {
        /// The key.
        key: Ident,
        /// Its value.
        value: Expr,
        /// The whole statement.
        span: Span,
    },
    /// `EXPR <= EXPR` or `EXPR >= EXPR` (half-spaces).
    Constraint {
        /// Left side.
        lhs: Expr,
        /// Direction.
        op: CmpOp,
        /// Right side.
        rhs: Expr,
        /// The whole statement.
        span: Span,
    },
    /// `let NAME = EXPR` or `let NAME[INDEX] = EXPR` (inside `for`).
    Let {
        /// The defined name (and index, for families).
        target: Target,
        /// Its value.
        value: Expr,
        /// The whole statement.
        span: Span,
    },
    /// `for VAR in LO..HI { ... }`: unrolled at compile time.
    For {
        /// The loop variable.
        var: Ident,
        /// The range.
        range: IndexRange,
        /// The body.
        body: Block,
        /// The whole statement.
        span: Span,
    },
}

/// A unary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnOp {
    /// `-x`
    Neg,
}

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `^` (right associative, binds tighter than unary minus: `-x^2 = -(x^2)`).
    Pow,
}

/// A named or positional argument: `f(x)` or `paper(eps = 1/16)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Arg {
    /// `Some(name)` for `name = value`.
    pub name: Option<Ident>,
    /// The value.
    pub value: Expr,
}

/// An expression.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    /// What it is.
    pub kind: ExprKind,
    /// Where it was written.
    pub span: Span,
}

/// The kinds of expression.
#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// A numeric literal (always finite and non-negative; `-` is a unary operator).
    Num(f64),
    /// A name: constant, state, input, noise, let, loop variable, `t`, `pi`, `e`, or a keyword-like
    /// value in an analysis (`auto`, `identity`, `rk4`).
    Name(Ident),
    /// `x[i]`: an element of an indexed family.
    Index {
        /// The family.
        base: Ident,
        /// The index (an integer expression of loop variables and constants).
        index: Box<Expr>,
    },
    /// `table.column`: a tabulated signal read at time `t`.
    Field {
        /// The table.
        base: Ident,
        /// The column.
        field: Ident,
    },
    /// A string literal (only meaningful in a few analysis fields).
    Str(String),
    /// `-x`
    Unary {
        /// The operator.
        op: UnOp,
        /// The operand.
        expr: Box<Expr>,
    },
    /// `a op b`
    Binary {
        /// The operator.
        op: BinOp,
        /// Left operand.
        lhs: Box<Expr>,
        /// Right operand.
        rhs: Box<Expr>,
    },
    /// `f(args)`: a built-in function, or a configuration value such as `paper(eps = 1/16)`.
    Call {
        /// The function name.
        func: Ident,
        /// The arguments.
        args: Vec<Arg>,
    },
    /// `[a, b, ...]`: an interval `[lo, hi]`, a vector, a matrix (list of lists) or a list of names.
    List(Vec<Expr>),
}
