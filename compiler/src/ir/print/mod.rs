//! Printing expressions in `.sde` syntax.
//!
//! The printer is here; its unit tests are in `tests.rs`, with a strict test-only parser of the
//! grammar in `test_parser.rs` (for round trips).

use std::borrow::Cow;

use super::fold::Folded;
use super::node::{ExprId, Func1, Func2, Node, Var};
use super::pool::Pool;
use super::table::Table;

/// The names variables and tables print as.
#[derive(Clone, Copy, Debug)]
pub struct Names<'a> {
    /// State names, by index (family elements as `x[3]`; printed as given).
    pub states: &'a [String],
    /// Input names.
    pub inputs: &'a [String],
    /// Noise channel names.
    pub noises: &'a [String],
    /// The model's tables (their names and column names).
    pub tables: &'a [Table],
}

// Precedence levels, lowest first: what a printed expression's top-level operator is.
const ADD: u8 = 1; // a + b, a - b
const MUL: u8 = 2; // a * b, a / b
const NEG: u8 = 3; // -a
const POW: u8 = 4; // a ^ b
const ATOM: u8 = 5; // numbers, names, calls

/// A piece of output: text, or a sub-expression to print, parenthesised if its level is below
/// the given minimum.
enum Piece {
    Text(Cow<'static, str>),
    Expr(ExprId, u8),
}

fn text(s: impl Into<Cow<'static, str>>) -> Piece {
    Piece::Text(s.into())
}

/// A non-negative finite number, so that it parses back to the same `f64`: integers below
/// 1e16 in plain digits, everything else as Rust's shortest round-trip form (`0.1`, `1e-7`,
/// `1.5e300`), all of which the `.sde` number grammar accepts.
fn number(v: f64) -> String {
    debug_assert!(v >= 0.0 && v.is_finite());
    if v.fract() == 0.0 && v < 1e16 {
        format!("{v}")
    } else {
        format!("{v:?}")
    }
}

/// `Some(k)` if the coefficient `c` in (0, 1) prints better as a division by the integer `k`
/// (`x/2` for `0.5*x`), i.e. when `x/k` lowers back to exactly `c*x` (`1/k` exact).
fn reciprocal(c: f64) -> Option<f64> {
    if c <= 0.0 || c >= 1.0 {
        return None;
    }
    let k = 1.0 / c;
    (k.fract() == 0.0 && k <= 1000.0 && Folded::point(k).powi(-1) == Some(Folded::point(c)))
        .then_some(k)
}

/// A coefficient as printed: its value and, when `x/k` lowers back to exactly this
/// coefficient times `x`, the divisor `k` of its magnitude.
#[derive(Clone, Copy, Debug)]
struct Coef {
    value: f64,
    divisor: Option<f64>,
}

impl Coef {
    /// An exact coefficient.
    fn exact(c: f64) -> Coef {
        Coef {
            value: c,
            divisor: reciprocal(c.abs()),
        }
    }

    /// The coefficient of an enclosure (`x/3` lowers to `E * x` with `E` enclosing `1/3`): its
    /// floating-point value, and the divisor `k` when `1/k` folds to exactly this enclosure.
    fn enclosed(e: Folded) -> Coef {
        let m = e.approx.abs();
        let k = (1.0 / m).round();
        let magnitude = if e.approx < 0.0 {
            Folded {
                approx: m,
                exact: -e.exact,
            }
        } else {
            e
        };
        let divisor = ((2.0..=1000.0).contains(&k) && Folded::point(k).powi(-1) == Some(magnitude))
            .then_some(k);
        Coef {
            value: e.approx,
            divisor,
        }
    }

    /// `|self|`.
    fn abs(self) -> Coef {
        Coef {
            value: self.value.abs(),
            divisor: self.divisor,
        }
    }
}

impl Pool {
    /// `e` as an `.sde` expression that parses back to the same value (and, through the
    /// simplifying constructors, to the same node).
    ///
    /// Parentheses are minimal for the precedences `+ -` < `* /` < unary `-` < `^` (right
    /// associative); the numeric coefficient of a term is its sign (`a - 2*b`); negative integer
    /// exponents print as division (`x/y^2`); negative numbers are never an operand of `*`, `/`
    /// or `^` without parentheses (`(-2)^x`, `x^(-0.5)`). Time prints as `t`, tables as
    /// `table.column` whatever their argument (it is `t` in every spec). Two forms are outside
    /// the `.sde` grammar because no spec can write them: `sign(x)` (derivative of `abs`) and
    /// `(cos(x) - sinc(x))/x` for [`Func1::DSinc`], which equals it except at `x = 0`.
    ///
    /// Printing expands the DAG into a tree (shared sub-expressions repeat, so the text can be
    /// exponentially longer than the DAG: [`Pool::to_sde_shared`] names them instead) and uses
    /// an explicit stack, so any depth is fine.
    pub fn to_sde(&self, e: ExprId, names: &Names<'_>) -> String {
        self.to_sde_prefix(e, names, usize::MAX)
    }

    /// [`Pool::to_sde`] that stops once the text is longer than `max` bytes: the whole text if
    /// it is at most `max` bytes long, else a prefix of it longer than `max`. The expanded tree
    /// can be exponentially larger than the DAG, so this bounds the work, e.g. for docs.
    pub fn to_sde_prefix(&self, e: ExprId, names: &Names<'_>, max: usize) -> String {
        self.print(e, names, max, &|_| None)
    }

    /// [`Pool::to_sde_prefix`] where every sub-expression below `e` that `named` names prints
    /// as that name (the `let`s of [`Pool::to_sde_shared`]).
    pub(super) fn print<'n>(
        &self,
        e: ExprId,
        names: &Names<'_>,
        max: usize,
        named: &dyn Fn(ExprId) -> Option<&'n str>,
    ) -> String {
        let mut out = String::new();
        let mut stack = vec![Piece::Expr(e, 0)];
        let mut pieces = Vec::new();
        while let Some(p) = stack.pop() {
            if out.len() > max {
                break;
            }
            match p {
                Piece::Text(s) => out.push_str(&s),
                Piece::Expr(id, _) if id != e && named(id).is_some() => {
                    out.push_str(named(id).unwrap_or_default());
                }
                Piece::Expr(id, min) => {
                    self.pieces(id, names, &mut pieces);
                    let paren = self.level(id) < min;
                    if paren {
                        out.push('(');
                        stack.push(text(")"));
                    }
                    stack.extend(pieces.drain(..).rev());
                }
            }
        }
        out
    }

    /// The precedence level of the top-level operator `e` prints with.
    fn level(&self, e: ExprId) -> u8 {
        match self.node(e) {
            Node::Const(v) | Node::Enclosure { approx: v, .. } if v.get() < 0.0 => NEG,
            Node::Const(_) | Node::Enclosure { .. } | Node::Var(_) | Node::Table { .. } => ATOM,
            Node::Call1(Func1::DSinc, _) => MUL,
            Node::Call1(..) => ATOM,
            Node::Call2(Func2::Pow, ..) => POW,
            Node::Call2(..) => ATOM,
            Node::Product { factors } if factors.len() == 1 && factors[0].1 >= 2 => POW,
            Node::Product { .. } => MUL,
            // `c*t` prints as `2*x`, `-x`, `-x*y`, `x/2`: at worst a product of a negation.
            Node::Sum { constant, terms } if constant.get() == 0.0 && terms.len() == 1 => MUL,
            Node::Sum { .. } => ADD,
        }
    }

    /// The sub-expressions `e` prints (in order, with repeats) and the length of the rest of
    /// its text, counting the parentheses each sub-expression may get.
    pub(super) fn print_refs(&self, e: ExprId, names: &Names<'_>) -> (Vec<ExprId>, usize) {
        let mut pieces = Vec::new();
        self.pieces(e, names, &mut pieces);
        let mut refs = Vec::new();
        let mut len = 0;
        for p in pieces {
            match p {
                Piece::Text(s) => len += s.len(),
                Piece::Expr(id, _) => {
                    refs.push(id);
                    len += 2;
                }
            }
        }
        (refs, len)
    }

    /// The pieces `e` prints as (without its own parentheses).
    fn pieces(&self, e: ExprId, names: &Names<'_>, out: &mut Vec<Piece>) {
        match self.node(e) {
            // An enclosure prints as its floating-point value.
            Node::Const(v) | Node::Enclosure { approx: v, .. } => {
                let v = v.get();
                if v < 0.0 {
                    out.push(text("-"));
                }
                out.push(text(number(v.abs())));
            }
            Node::Var(v) => out.push(text(var_name(*v, names))),
            Node::Sum { constant, terms } => {
                let terms: Vec<(ExprId, f64)> = terms.iter().map(|&(t, c)| (t, c.get())).collect();
                self.sum_pieces(constant.get(), &terms, out);
            }
            // `E * rest` for an enclosure `E`: printed as a coefficient, with its sign.
            Node::Product { factors } if self.enclosure_of(factors).is_some() => {
                self.sum_pieces(0.0, &[(e, 1.0)], out);
            }
            Node::Product { factors } => self.product_pieces(factors, Coef::exact(1.0), out),
            Node::Call1(Func1::DSinc, a) => {
                out.push(text("(cos("));
                out.push(Piece::Expr(*a, 0));
                out.push(text(") - sinc("));
                out.push(Piece::Expr(*a, 0));
                out.push(text("))/"));
                out.push(Piece::Expr(*a, POW));
            }
            Node::Call1(f, a) => {
                out.push(text(func1_name(*f)));
                out.push(text("("));
                out.push(Piece::Expr(*a, 0));
                out.push(text(")"));
            }
            Node::Call2(Func2::Pow, a, b) => {
                out.push(Piece::Expr(*a, ATOM));
                out.push(text("^"));
                out.push(Piece::Expr(*b, POW)); // right associative: a^b^c = a^(b^c)
            }
            Node::Call2(f, a, b) => {
                out.push(text(match f {
                    Func2::Atan2 => "atan2(",
                    Func2::Min => "min(",
                    Func2::Max => "max(",
                    Func2::Pow => unreachable!("handled above"),
                }));
                out.push(Piece::Expr(*a, 0));
                out.push(text(", "));
                out.push(Piece::Expr(*b, 0));
                out.push(text(")"));
            }
            Node::Table { table, column, .. } => {
                let t = names.tables.get(*table as usize);
                let tname = t.map_or_else(|| format!("table#{table}"), |t| t.name.clone());
                let cname = t
                    .and_then(|t| t.columns.get(*column as usize))
                    .map_or_else(|| format!("column#{column}"), Clone::clone);
                out.push(text(format!("{tname}.{cname}")));
            }
        }
    }

    /// `constant + sum(c*t)`. A positive term leads if there is one (`y - x`, not `-x + y`),
    /// else a positive constant (`1 - x^2`).
    fn sum_pieces(&self, constant: f64, terms: &[(ExprId, f64)], out: &mut Vec<Piece>) {
        let coefs: Vec<Coef> = terms.iter().map(|&(t, c)| self.coef(t, c)).collect();
        let lead = coefs.iter().position(|c| c.value > 0.0);
        if lead.is_none()
            && constant <= 0.0
            && terms.first().is_some_and(|&(t, _)| self.starts_with_sum(t))
        {
            // `-(a + b)*c` would parse as `(-(a + b))*c`, distributing the minus over `a + b`
            // (a different node); `-((a + b)*c)` does not.
            let negated: Vec<(ExprId, f64)> = terms.iter().map(|&(t, c)| (t, -c)).collect();
            out.push(text("-("));
            self.sum_pieces(-constant, &negated, out);
            out.push(text(")"));
            return;
        }
        let const_first = lead.is_none() && constant > 0.0;
        if const_first {
            out.push(text(number(constant)));
        }
        let mut first = !const_first;
        let order = lead
            .into_iter()
            .chain((0..terms.len()).filter(|&i| Some(i) != lead));
        for i in order {
            let (t, c) = (terms[i].0, coefs[i]);
            out.push(text(match (first, c.value < 0.0) {
                (true, true) => "-",
                (true, false) => "",
                (false, true) => " - ",
                (false, false) => " + ",
            }));
            first = false;
            self.term_pieces(t, c.abs(), out);
        }
        if constant != 0.0 && !const_first {
            out.push(text(if constant < 0.0 { " - " } else { " + " }));
            out.push(text(number(constant.abs())));
        }
    }

    /// Whether the term `t` prints starting with a parenthesised sum, as in `(a + b)*c`.
    fn starts_with_sum(&self, t: ExprId) -> bool {
        match self.node(t) {
            Node::Product { factors } => self.first_factor_is_sum(factors),
            _ => false,
        }
    }

    fn first_factor_is_sum(&self, factors: &[(ExprId, i32)]) -> bool {
        factors
            .iter()
            .find(|f| f.1 > 0)
            .is_some_and(|&(b, e)| e == 1 && matches!(self.node(b), Node::Sum { .. }))
    }

    /// A sum's term `c*t` without its sign (`c > 0`).
    fn term_pieces(&self, t: ExprId, c: Coef, out: &mut Vec<Piece>) {
        if let Node::Enclosure { .. } = self.node(t) {
            // An enclosed constant: its value is the coefficient (see `coef`).
            out.push(text(number(c.value)));
            return;
        }
        if let Node::Product { factors } = self.node(t) {
            let factors: Vec<(ExprId, i32)> = match self.enclosure_of(factors) {
                Some(k) => factors
                    .iter()
                    .enumerate()
                    .filter(|&(i, _)| i != k)
                    .map(|(_, &f)| f)
                    .collect(),
                None => factors.clone(),
            };
            return self.product_pieces(&factors, c, out);
        }
        if c.value == 1.0 {
            out.push(Piece::Expr(t, MUL));
        } else if let Some(k) = c.divisor {
            out.push(Piece::Expr(t, MUL));
            out.push(text("/"));
            out.push(text(number(k)));
        } else {
            out.push(text(number(c.value)));
            out.push(text("*"));
            out.push(Piece::Expr(t, POW));
        }
    }

    /// The index of the enclosure factor (exponent 1) of a product, the form an inexact
    /// coefficient takes.
    fn enclosure_of(&self, factors: &[(ExprId, i32)]) -> Option<usize> {
        factors
            .iter()
            .position(|&(b, e)| e == 1 && matches!(self.node(b), Node::Enclosure { .. }))
    }

    /// The coefficient term `t` prints with in a sum where its coefficient is `c`: `c` itself,
    /// or `c` times the enclosure factor of a product.
    fn coef(&self, t: ExprId, c: f64) -> Coef {
        if let Node::Enclosure { approx, .. } = self.node(t) {
            return Coef {
                value: c * approx.get(),
                divisor: None,
            };
        }
        let enclosed = match self.node(t) {
            Node::Product { factors } => self.enclosure_of(factors).map(|k| factors[k].0),
            _ => None,
        };
        match enclosed.map(|e| self.node(e)) {
            Some(&Node::Enclosure { approx, lo, hi }) => {
                let e = Folded {
                    approx: approx.get(),
                    exact: reachc_core::interval::Interval::new(lo.get(), hi.get()),
                };
                if c == 1.0 {
                    Coef::enclosed(e)
                } else {
                    Coef {
                        value: c * e.approx,
                        divisor: None,
                    }
                }
            }
            _ => Coef::exact(c),
        }
    }

    /// `coef * prod(b^e)` (`coef > 0`) as `c*a*b^2/(k*d*e^3)`; as `(a + b)*c/d*k` when a
    /// factor is a sum (`k*(a + b)` would parse as a distributed sum, a different node).
    fn product_pieces(&self, factors: &[(ExprId, i32)], coef: Coef, out: &mut Vec<Piece>) {
        let tail = coef.value != 1.0
            && factors
                .iter()
                .any(|&(b, e)| e.unsigned_abs() == 1 && matches!(self.node(b), Node::Sum { .. }));
        let (num_coef, den_coef) = if coef.value == 1.0 || tail {
            (None, None)
        } else if let Some(k) = coef.divisor {
            (None, Some(k))
        } else {
            (Some(coef.value), None)
        };
        let factor = |b: ExprId, e: u32, out: &mut Vec<Piece>| {
            if e == 1 {
                out.push(Piece::Expr(b, POW));
            } else {
                out.push(Piece::Expr(b, ATOM));
                out.push(text(format!("^{e}")));
            }
        };
        let mut n = 0;
        if let Some(c) = num_coef {
            out.push(text(number(c)));
            n += 1;
        }
        for &(b, e) in factors.iter().filter(|f| f.1 > 0) {
            if n > 0 {
                out.push(text("*"));
            }
            factor(b, e.unsigned_abs(), out);
            n += 1;
        }
        if n == 0 {
            out.push(text("1"));
        }
        let den = usize::from(den_coef.is_some()) + factors.iter().filter(|f| f.1 < 0).count();
        if den > 0 {
            out.push(text(if den > 1 { "/(" } else { "/" }));
            let mut d = 0;
            if let Some(k) = den_coef {
                out.push(text(number(k)));
                d += 1;
            }
            for &(b, e) in factors.iter().filter(|f| f.1 < 0) {
                if d > 0 {
                    out.push(text("*"));
                }
                factor(b, e.unsigned_abs(), out);
                d += 1;
            }
            if den > 1 {
                out.push(text(")"));
            }
        }
        if tail {
            match coef.divisor {
                Some(k) => out.push(text(format!("/{}", number(k)))),
                None => out.push(text(format!("*{}", number(coef.value)))),
            }
        }
    }
}

fn var_name(v: Var, names: &Names<'_>) -> String {
    let pick = |list: &[String], i: u32, kind: &str| {
        list.get(i as usize)
            .cloned()
            .unwrap_or_else(|| format!("{kind}#{i}")) // not valid syntax: a caller bug shows
    };
    match v {
        Var::State(i) => pick(names.states, i, "state"),
        Var::Input(i) => pick(names.inputs, i, "input"),
        Var::Noise(i) => pick(names.noises, i, "noise"),
        Var::Time => "t".into(),
    }
}

fn func1_name(f: Func1) -> &'static str {
    match f {
        Func1::Sin => "sin",
        Func1::Cos => "cos",
        Func1::Tan => "tan",
        Func1::Exp => "exp",
        Func1::Log => "log",
        Func1::Sqrt => "sqrt",
        Func1::Abs => "abs",
        Func1::Atan => "atan",
        Func1::Sinh => "sinh",
        Func1::Cosh => "cosh",
        Func1::Tanh => "tanh",
        Func1::Sinc => "sinc",
        Func1::Sign => "sign",
        Func1::DSinc => "dsinc", // printed specially; kept for completeness
    }
}

#[cfg(test)]
mod test_parser;
#[cfg(test)]
mod tests;
