//! IR node types.

/// Index of a node in a [`super::Pool`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ExprId(pub u32);

impl ExprId {
    /// The id as an index into per-node tables.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// A finite `f64` with bitwise equality and hashing (`-0.0` is normalised to `0.0`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct F64(u64);

impl F64 {
    /// Wraps a finite value. Panics on NaN or infinity: the checker rejects those first.
    pub fn new(v: f64) -> Self {
        assert!(v.is_finite(), "IR constants must be finite, got {v}");
        F64(if v == 0.0 { 0.0f64 } else { v }.to_bits())
    }

    /// The value.
    pub fn get(self) -> f64 {
        f64::from_bits(self.0)
    }
}

/// A variable of the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Var {
    /// State `x_i` (index into the model's states).
    State(u32),
    /// Input `u_j`.
    Input(u32),
    /// Noise channel `w_k` (only in diffusion rows, before the coefficients are extracted).
    Noise(u32),
    /// Time `t`.
    Time,
}

/// One-argument functions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Func1 {
    /// sine
    Sin,
    /// cosine
    Cos,
    /// tangent
    Tan,
    /// exponential
    Exp,
    /// natural logarithm
    Log,
    /// square root
    Sqrt,
    /// absolute value
    Abs,
    /// arctangent
    Atan,
    /// hyperbolic sine
    Sinh,
    /// hyperbolic cosine
    Cosh,
    /// hyperbolic tangent
    Tanh,
    /// `sin(x)/x`, 1 at 0
    Sinc,
    /// sign of x (-1, 0, 1): appears only as the derivative of `abs`
    Sign,
    /// `d/dx sinc(x) = (cos(x) - sinc(x))/x`, 0 at 0: appears only as the derivative of `sinc`
    /// (a node of its own because the quotient form is 0/0 at 0, which point evaluation and
    /// interval bounds near 0 cannot recover from)
    DSinc,
}

/// Two-argument functions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Func2 {
    /// `atan2(y, x)`
    Atan2,
    /// minimum
    Min,
    /// maximum
    Max,
    /// `pow(a, b) = a^b` for a non-integer exponent (defined for a > 0, or a >= 0 with b > 0)
    Pow,
}

/// A node in canonical form.
///
/// Canonical form (enforced by the [`super::Pool`] constructors, never built by hand):
/// - numeric coefficients live only in `Sum`: `2*x` is `Sum { constant: 0, terms: [(x, 2)] }`;
/// - `Sum` terms are non-constant, non-`Sum` nodes, sorted by id, with non-zero coefficients and
///   no repeated term; a `Sum` has at least two terms or one term with coefficient != 1 or a
///   non-zero constant;
/// - `Product` factors are non-constant, non-`Product`, non-`Sum`-with-coefficient nodes sorted
///   by id, with non-zero integer exponents, no repeated base; a `Product` has at least two
///   factors or one factor with exponent != 1;
/// - a constant sub-expression is always folded, to `Const` when the folded value is exact and to
///   `Enclosure` when it is not (the pool never rounds a constant silently); a coefficient that
///   is not exact in floating point is an `Enclosure` factor of its term
///   (`Product { [(enclosure, 1), (term, 1)] }` with coefficient 1 in the `Sum`).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Node {
    /// A finite constant, exactly this value.
    Const(F64),
    /// A real constant known to lie in `[lo, hi]` (`lo < hi`): the exact value of a constant
    /// expression whose floating-point value is not exact (`1/3`, `sin(1)`, `0.2 * 0.3`, the
    /// entries of `T^-1`). Interval evaluation uses `[lo, hi]`, so the IR's enclosures hold the
    /// real-number expression; point evaluation uses `approx`, the value the same operations
    /// give in round-to-nearest floating point (inside `[lo, hi]`).
    Enclosure {
        /// The floating-point value (what point evaluation uses).
        approx: F64,
        /// A lower bound of the exact value.
        lo: F64,
        /// An upper bound of the exact value.
        hi: F64,
    },
    /// A model variable.
    Var(Var),
    /// `constant + sum(coef * term)`.
    Sum {
        /// The constant part.
        constant: F64,
        /// `(term, coefficient)` pairs.
        terms: Vec<(ExprId, F64)>,
    },
    /// `prod(base ^ exponent)` with integer exponents (negative for division).
    Product {
        /// `(base, exponent)` pairs.
        factors: Vec<(ExprId, i32)>,
    },
    /// A one-argument function.
    Call1(Func1, ExprId),
    /// A two-argument function.
    Call2(Func2, ExprId, ExprId),
    /// Column `column` of table `table`, linearly interpolated at `arg` (which is `t` in specs).
    Table {
        /// Index into the model's tables.
        table: u32,
        /// Index of the column in that table.
        column: u32,
        /// Where to read it (time).
        arg: ExprId,
    },
}
