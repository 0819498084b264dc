//! Printing expressions in `.sde` syntax.

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
mod tests {
    use super::super::test_exprs::{sin_chain, FUNC1};
    use super::super::VarValues;
    use super::*;
    use reachc_test_support::rng::XorShift64;

    /// A strict test-only parser for the `.sde` expression grammar (the real one lives in
    /// `syntax`), lowering straight into a pool: `^` takes a power (not a negation) on its
    /// right, so `2^-1` is rejected, as are stray characters.
    struct Parser<'a> {
        s: &'a [u8],
        i: usize,
        pool: &'a mut Pool,
        names: &'a Names<'a>,
    }

    impl Parser<'_> {
        fn peek(&mut self) -> u8 {
            while self.s.get(self.i) == Some(&b' ') {
                self.i += 1;
            }
            self.s.get(self.i).copied().unwrap_or(0)
        }
        fn eat(&mut self, c: u8) {
            assert_eq!(self.peek(), c, "expected {:?} at {}", c as char, self.i);
            self.i += 1;
        }
        fn expr(&mut self) -> ExprId {
            let mut a = self.term();
            loop {
                match self.peek() {
                    b'+' => {
                        self.i += 1;
                        let b = self.term();
                        a = self.pool.add(a, b);
                    }
                    b'-' => {
                        self.i += 1;
                        let b = self.term();
                        a = self.pool.sub(a, b);
                    }
                    _ => return a,
                }
            }
        }
        fn term(&mut self) -> ExprId {
            let mut a = self.unary();
            loop {
                match self.peek() {
                    b'*' => {
                        self.i += 1;
                        let b = self.unary();
                        a = self.pool.mul(a, b);
                    }
                    b'/' => {
                        self.i += 1;
                        let b = self.unary();
                        a = self.pool.div(a, b);
                    }
                    _ => return a,
                }
            }
        }
        fn unary(&mut self) -> ExprId {
            if self.peek() == b'-' {
                self.i += 1;
                let a = self.unary();
                return self.pool.neg(a);
            }
            self.power()
        }
        fn power(&mut self) -> ExprId {
            let a = self.primary();
            if self.peek() == b'^' {
                self.i += 1;
                let b = self.power();
                return self.pool.pow(a, b);
            }
            a
        }
        fn ident(&mut self) -> String {
            let start = self.i;
            while self
                .s
                .get(self.i)
                .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
            {
                self.i += 1;
            }
            String::from_utf8(self.s[start..self.i].to_vec()).unwrap()
        }
        fn primary(&mut self) -> ExprId {
            let c = self.peek();
            if c == b'(' {
                self.i += 1;
                let e = self.expr();
                self.eat(b')');
                return e;
            }
            if c.is_ascii_digit() || c == b'.' {
                let start = self.i;
                while self
                    .s
                    .get(self.i)
                    .is_some_and(|c| c.is_ascii_digit() || *c == b'.')
                {
                    self.i += 1;
                }
                if matches!(self.s.get(self.i), Some(b'e' | b'E')) {
                    self.i += 1;
                    if matches!(self.s.get(self.i), Some(b'+' | b'-')) {
                        self.i += 1;
                    }
                    while self.s.get(self.i).is_some_and(u8::is_ascii_digit) {
                        self.i += 1;
                    }
                }
                let v: f64 = std::str::from_utf8(&self.s[start..self.i])
                    .unwrap()
                    .parse()
                    .unwrap();
                return self.pool.num(v);
            }
            assert!(
                c.is_ascii_alphabetic() || c == b'_',
                "unexpected {:?} at {}",
                c as char,
                self.i
            );
            let mut name = self.ident();
            match self.s.get(self.i) {
                Some(b'(') => {
                    self.i += 1;
                    let mut args = vec![self.expr()];
                    while self.peek() == b',' {
                        self.i += 1;
                        args.push(self.expr());
                    }
                    self.eat(b')');
                    let f1 = |n: &str| {
                        Some(match n {
                            "sin" => Func1::Sin,
                            "cos" => Func1::Cos,
                            "tan" => Func1::Tan,
                            "exp" => Func1::Exp,
                            "log" => Func1::Log,
                            "sqrt" => Func1::Sqrt,
                            "abs" => Func1::Abs,
                            "atan" => Func1::Atan,
                            "sinh" => Func1::Sinh,
                            "cosh" => Func1::Cosh,
                            "tanh" => Func1::Tanh,
                            "sinc" => Func1::Sinc,
                            "sign" => Func1::Sign,
                            _ => return None,
                        })
                    };
                    if let Some(f) = f1(&name) {
                        assert_eq!(args.len(), 1);
                        return self.pool.call1(f, args[0]);
                    }
                    let f = match name.as_str() {
                        "atan2" => Func2::Atan2,
                        "min" => Func2::Min,
                        "max" => Func2::Max,
                        _ => panic!("unknown function {name}"),
                    };
                    assert_eq!(args.len(), 2);
                    self.pool.call2(f, args[0], args[1])
                }
                Some(b'.') => {
                    self.i += 1;
                    let col = self.ident();
                    let ti = self
                        .names
                        .tables
                        .iter()
                        .position(|t| t.name == name)
                        .unwrap();
                    let ci = self.names.tables[ti].column_index(&col).unwrap();
                    let t = self.pool.var(Var::Time);
                    self.pool.table(ti as u32, ci as u32, t)
                }
                _ => {
                    if self.s.get(self.i) == Some(&b'[') {
                        let start = self.i;
                        while self.s[self.i] != b']' {
                            self.i += 1;
                        }
                        self.i += 1;
                        name.push_str(std::str::from_utf8(&self.s[start..self.i]).unwrap());
                    }
                    let find = |l: &[String]| l.iter().position(|n| *n == name).map(|i| i as u32);
                    let v = if name == "t" {
                        Var::Time
                    } else if let Some(i) = find(self.names.states) {
                        Var::State(i)
                    } else if let Some(i) = find(self.names.inputs) {
                        Var::Input(i)
                    } else if let Some(i) = find(self.names.noises) {
                        Var::Noise(i)
                    } else {
                        panic!("unknown name {name}")
                    };
                    self.pool.var(v)
                }
            }
        }
    }

    fn parse(pool: &mut Pool, names: &Names<'_>, src: &str) -> ExprId {
        let mut p = Parser {
            s: src.as_bytes(),
            i: 0,
            pool,
            names,
        };
        let e = p.expr();
        assert_eq!(p.peek(), 0, "trailing input in {src:?} at {}", p.i);
        e
    }

    struct Fx {
        states: Vec<String>,
        inputs: Vec<String>,
        noises: Vec<String>,
        tables: Vec<Table>,
    }

    fn fx() -> Fx {
        Fx {
            states: vec!["x".into(), "y".into(), "z[3]".into()],
            inputs: vec!["u".into()],
            noises: vec!["w".into()],
            tables: vec![Table {
                name: "wind".into(),
                columns: vec!["gust".into()],
                times: vec![0.0, 1.0],
                values: vec![vec![0.0, 2.0]],
            }],
        }
    }

    impl Fx {
        fn names(&self) -> Names<'_> {
            Names {
                states: &self.states,
                inputs: &self.inputs,
                noises: &self.noises,
                tables: &self.tables,
            }
        }
    }

    /// Builds each case from source with the test parser, checks the printed form, and checks
    /// that the printed form parses back to the same node.
    #[test]
    fn canonical_printing() {
        let f = fx();
        let names = f.names();
        let mut p = Pool::new();
        // fix variable ids: x, y, z[3], u, w, t
        for v in [
            Var::State(0),
            Var::State(1),
            Var::State(2),
            Var::Input(0),
            Var::Noise(0),
            Var::Time,
        ] {
            p.var(v);
        }
        let cases = [
            ("x - 2*y", "x - 2*y"),
            ("x + -2*y", "x - 2*y"),
            ("-x + y", "y - x"),
            ("x + x", "2*x"),
            ("x*y - y*x", "0"),
            ("2*(x + 3*y) - 6*y", "2*x"),
            ("x*x*x/x", "x^2"),
            ("2^10", "1024"),
            ("sin(0)", "0"),
            ("x*0", "0"),
            ("1/0", "1/0"),
            ("x/y^2", "x/y^2"),
            ("x*y^(0-2)", "x/y^2"),
            ("2*x*y/z[3]", "2*x*y/z[3]"),
            ("(x + 1)^2", "(x + 1)^2"),
            ("-x^2", "-x^2"),
            ("(-2)^x", "(-2)^x"),
            ("x^(-0.5)", "x^(-0.5)"),
            ("x^(0-0.5)", "x^(-0.5)"),
            ("2^x^y", "2^x^y"),
            ("(2^x)^y", "(2^x)^y"),
            ("x^y^2", "x^y^2"),
            ("(x^2)^0.5", "(x^2)^0.5"),
            ("0.0000001*x + 1.5e300", "1e-7*x + 1.5e300"),
            ("x/2", "x/2"),
            ("0.5*x", "x/2"),
            ("x*0.1", "0.1*x"),
            ("1.5*x", "1.5*x"),
            ("sin(x)*cos(y)", "sin(x)*cos(y)"),
            (
                "atan2(y, x) + min(y, x) - max(x, y)",
                "atan2(y, x) + min(x, y) - max(x, y)",
            ),
            ("wind.gust*x", "x*wind.gust"),
            ("t*u + w", "w + u*t"),
            ("1 - tanh(x)^2", "1 - tanh(x)^2"),
            ("x - 3", "x - 3"),
            ("0 - 3", "-3"),
            ("1/(x*y)", "1/(x*y)"),
            ("x/y/z[3]^2/2", "x/(2*y*z[3]^2)"),
            ("exp(0 - x)", "exp(-x)"),
            ("-(x*y)", "-x*y"),
            ("-2*x/y", "-2*x/y"),
            ("0 - 1/x", "-1/x"),
            ("sqrt(x + y)", "sqrt(x + y)"),
            ("(x + y)*(x - y)", "(x + y)*(x - y)"),
            ("(x + 1)^y", "(x + 1)^y"),
            ("z[3]^2 + 1", "z[3]^2 + 1"),
            ("sign(x)*abs(x)", "sign(x)*abs(x)"),
            ("1/(x + 1)^2", "1/(x + 1)^2"),
            ("-sinc(x)", "-sinc(x)"),
            ("2*(x + 1)", "2*x + 2"),
            ("sqrt(x^2)", "abs(x)"),
            ("log(exp(x))", "x"),
            ("sin(-x)", "-sin(x)"),
            ("(2*x)^2*y", "4*x^2*y"),
            ("x^2*(0 - 3)/y", "-3*x^2/y"),
            ("(x + y)/3", "x/3 + y/3"),
            (
                "1e16*x + 123456789012345680000",
                "1e16*x + 1.2345678901234568e20",
            ),
            ("-(x + 1)", "-x - 1"),
            ("x - (y - x)", "2*x - y"),
            // sums first in a product (the `x + y` node is older than the function calls)
            ("(x + y)*cosh(x)*3", "(x + y)*cosh(x)*3"),
            ("(x + y)*sinh(x)/2 + 1", "(x + y)*sinh(x)/2 + 1"),
            ("(x + y)*atan(x)/y*(0-3)", "-((x + y)*atan(x)/y*3)"),
            ("0 - (x + y)*tan(x)", "-((x + y)*tan(x))"),
            ("-(x + y)*exp(y)", "(-x - y)*exp(y)"),
            ("1 - (x + y)*log(y)", "1 - (x + y)*log(y)"),
            ("(x + y)/cos(y)*3", "(x + y)/cos(y)*3"),
            ("0.2/(x + y)", "1/(x + y)*0.2"),
            // `1/5` is not a float: an enclosure, printed as the division that rebuilds it
            ("x/5", "x/5"),
            ("(0-1.5)/(x + y)", "-1/(x + y)*1.5"),
        ];
        let mut failures = Vec::new();
        for (src, want) in cases {
            let e = parse(&mut p, &names, src);
            let got = p.to_sde(e, &names);
            if got != want {
                failures.push(format!("{src:?}: printed {got:?}, expected {want:?}"));
                continue;
            }
            let back = parse(&mut p, &names, &got);
            if back != e && !has_unfolded_constant(&p, e) {
                failures.push(format!("{src:?}: {got:?} parses to a different node"));
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }

    /// Printed forms go through the real front end (`syntax::parse` + `model::check`) and come
    /// back printed identically: the printer's precedences and number formats match the parser.
    #[test]
    fn real_front_end_round_trip() {
        let printed = [
            "x - 2*y",
            "y - x",
            "x/y^2",
            "2*x*y/z[3]",
            "(x + 1)^2",
            "-x^2",
            "x^(-0.5)",
            "2^x^y",
            "(2^x)^y",
            "x^y^2",
            "(x^2)^0.5",
            "1e-7*x + 1.5e300",
            "x/2",
            "1.5*x",
            "atan2(y, x) + min(x, y) - max(x, y)",
            "u*t",
            "1 - tanh(x)^2",
            "-3",
            "x/(2*y*z[3]^2)",
            "exp(-x)",
            "-x*y",
            "-2*x/y",
            "-1/x",
            "(x + y)*(x - y)",
            "(x + 1)^y",
            "-((x + y)*sin(x))",
            "(x + y)*sin(x)/2 + 1",
            "(-x - y)*sin(x)",
            "1/(x + y)/5",
            "-1/(x + y)*1.5",
            "sinc(x)*sign(y) + abs(u) + sqrt(x) + log(y) + sinh(x) + cosh(y) + atan(x) + tan(y)",
            "1e16*x + 1.2345678901234568e20",
        ];
        for want in printed {
            let src = format!(
                "model m\nstate x in [1, 2]\nstate y in [1, 2]\nstate z[3..3] in [1, 2]\n\
                 input u in [0, 1]\nlet first = x + y + z[3] + u + t\n\
                 drift {{ x' = {want}\n y' = first\n z[3]' = 0 }}\n"
            );
            let (spec, diags) = crate::syntax::parse(&src);
            assert!(diags.is_empty(), "{want}: {diags:?}");
            let (model, diags) = crate::model::check(&spec, std::path::Path::new("."));
            let model = model.unwrap_or_else(|| panic!("{want}: {diags:?}"));
            let states: Vec<String> = model.states.iter().map(|v| v.name.clone()).collect();
            let inputs: Vec<String> = model.inputs.iter().map(|v| v.name.clone()).collect();
            let names = Names {
                states: &states,
                inputs: &inputs,
                noises: &[],
                tables: &model.tables,
            };
            assert_eq!(model.pool.to_sde(model.drift[0], &names), want);
        }
    }

    #[test]
    fn derivative_printing() {
        let f = fx();
        let names = f.names();
        let mut p = Pool::new();
        let x = p.var(Var::State(0));
        let s = p.call1(Func1::Sinc, x);
        let d = p.diff(s, Var::State(0));
        assert_eq!(p.to_sde(d, &names), "(cos(x) - sinc(x))/x");
        let two = p.num(2.0);
        let e = p.mul(d, two);
        assert_eq!(p.to_sde(e, &names), "2*((cos(x) - sinc(x))/x)");
        let e = p.pow(d, x);
        assert_eq!(p.to_sde(e, &names), "((cos(x) - sinc(x))/x)^x");
    }

    fn random_expr(p: &mut Pool, rng: &mut XorShift64, depth: u32) -> ExprId {
        let leaf = depth == 0 || rng.below(4) == 0;
        if leaf {
            return match rng.below(8) {
                0 => p.num([0.5, 2.0, 3.0, -1.5, 0.1, 7.0, 1e-7, 1.0][rng.below(8) as usize]),
                1 => p.var(Var::Input(0)),
                2 => p.var(Var::Time),
                3 => p.var(Var::State(2)),
                4 => {
                    let t = p.var(Var::Time);
                    p.table(0, 0, t)
                }
                5 => p.var(Var::State(1)),
                _ => p.var(Var::State(0)),
            };
        }
        let a = random_expr(p, rng, depth - 1);
        let b = random_expr(p, rng, depth - 1);
        match rng.below(14) {
            0 | 1 => p.add(a, b),
            2 | 3 => p.sub(a, b),
            4 | 5 => p.mul(a, b),
            6 => p.div(a, b),
            7 => p.neg(a),
            8 => p.powi(a, [2, 3, -1, -2][rng.below(4) as usize]),
            9 => p.pow(a, b),
            10 => {
                // Not `dsinc`: only derivatives make it (it prints as a quotient).
                let fs = &FUNC1[..FUNC1.len() - 1];
                p.call1(fs[rng.below(fs.len() as u64) as usize], a)
            }
            11 => p.call2(
                [Func2::Min, Func2::Max, Func2::Atan2][rng.below(3) as usize],
                a,
                b,
            ),
            12 => {
                let h = p.num(0.5);
                p.pow(a, h)
            }
            _ => {
                let c = p.num(-3.0);
                let ca = p.mul(c, a);
                p.add(ca, b)
            }
        }
    }

    /// Whether `e` contains a constant sub-expression left unevaluated (like `x/0`), which the
    /// checker rejects: for those `x^-1*0^-1` prints as `1/(x*0)`, which lowers to `1/0`.
    fn has_unfolded_constant(p: &Pool, e: ExprId) -> bool {
        p.reachable(&[e]).into_iter().any(|id| {
            let mut n = 0;
            let mut consts = 0;
            super::super::pool::for_each_child(p.node(id), |c| {
                n += 1;
                consts += usize::from(p.as_const(c).is_some());
            });
            consts > 0
                && (consts == n || matches!(p.node(id), Node::Sum { .. } | Node::Product { .. }))
        })
    }

    /// Random expressions print to strings that parse back to the very same node.
    #[test]
    fn random_round_trip() {
        let f = fx();
        let names = f.names();
        let mut p = Pool::new();
        let mut rng = XorShift64(0x5eed_1234_abcd_0001);
        for _ in 0..3000 {
            let e = random_expr(&mut p, &mut rng, 5);
            let s = p.to_sde(e, &names);
            let back = parse(&mut p, &names, &s);
            if back != e && !has_unfolded_constant(&p, e) {
                // Accept only value-equal results (float re-association of folded constants;
                // an enclosure prints as its floating-point value, which lowers to an exact
                // constant unless it prints as the division that rebuilds it).
                let s2 = p.to_sde(back, &names);
                let pt = VarValues {
                    states: &[0.7, 1.3, 2.1],
                    inputs: &[0.4],
                    noises: &[0.0],
                    time: 0.3,
                };
                let v = p.eval(&[e, back], &pt, &f.tables);
                let same = v[0] == v[1]
                    || (v[0] - v[1]).abs() <= 1e-12 * v[0].abs()
                    || (v[0].is_nan() && v[1].is_nan());
                assert!(same, "{s}\n  re-prints as {s2}\n  values {v:?}");
                let enclosed = p
                    .reachable(&[e])
                    .into_iter()
                    .any(|id| matches!(p.node(id), Node::Enclosure { .. }));
                assert!(enclosed, "not idempotent: {s}\n  re-prints as {s2}");
            }
        }
    }

    #[test]
    fn deep_expressions_print_without_recursion() {
        let f = fx();
        let names = f.names();
        let mut p = Pool::new();
        let e = sin_chain(&mut p, 50_000);
        let s = p.to_sde(e, &names);
        assert!(s.starts_with("x + y*sin(x + y*sin("), "{}", &s[..40]);
        assert!(s.ends_with(&format!("y*sin(x){}", ")".repeat(24_999))));
        assert!(s.len() > 250_000);
    }

    #[test]
    fn prefixes_stop_early() {
        let f = fx();
        let names = f.names();
        let mut p = Pool::new();
        let x = p.var(Var::State(0));
        // Each level repeats the one below twice when printed: 2^k copies of `x`.
        let doubling = |p: &mut Pool, levels: usize| {
            (0..levels).fold(x, |e, _| {
                let (s, c) = (p.call1(Func1::Sin, e), p.call1(Func1::Cos, e));
                p.add(s, c)
            })
        };
        let small = doubling(&mut p, 8);
        let whole = p.to_sde(small, &names);
        assert_eq!(p.to_sde_prefix(small, &names, whole.len()), whole);
        let cut = p.to_sde_prefix(small, &names, 100);
        assert!(
            cut.len() > 100 && cut.len() < 200 && whole.starts_with(&cut),
            "{cut}"
        );
        // 2^60 copies: only the prefix is printed.
        let huge = doubling(&mut p, 60);
        let cut = p.to_sde_prefix(huge, &names, 100);
        assert!(cut.len() > 100 && cut.len() < 1000, "{cut}");
        assert!(cut.starts_with("sin(sin(sin("), "{cut}");
    }
}
