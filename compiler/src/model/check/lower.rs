//! Lowering syntax-tree expressions to the IR, resolving names and checking arity.

use super::scope::{Symbol, VarKind};
use super::Checker;
use crate::diagnostics::{Diagnostic, Span};
use crate::ir::{ExprId, Func1, Func2, Var};
use crate::syntax::ast::{BinOp, Expr, ExprKind, Ident, UnOp};

/// Which variables an expression may use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Allow {
    /// Numbers, constants, loop variables and functions only.
    Constants,
    /// States, inputs, time, tables and lets as well (drift, lets).
    Model,
    /// `Model` plus noise channels (diffusion rows).
    WithNoise,
}

/// Built-in functions: name, and the arity as (min, max).
enum Builtin {
    F1(Func1),
    F2(Func2),
    /// min/max take two or more arguments and fold.
    Fold(Func2),
}

pub(super) const FUNCTION_NAMES: &[&str] = &[
    "sin", "cos", "tan", "exp", "log", "sqrt", "abs", "atan", "sinh", "cosh", "tanh", "sinc",
    "sign", "atan2", "min", "max",
];

fn builtin(name: &str) -> Option<Builtin> {
    use Builtin::*;
    Some(match name {
        "sin" => F1(Func1::Sin),
        "cos" => F1(Func1::Cos),
        "tan" => F1(Func1::Tan),
        "exp" => F1(Func1::Exp),
        "log" => F1(Func1::Log),
        "sqrt" => F1(Func1::Sqrt),
        "abs" => F1(Func1::Abs),
        "atan" => F1(Func1::Atan),
        "sinh" => F1(Func1::Sinh),
        "cosh" => F1(Func1::Cosh),
        "tanh" => F1(Func1::Tanh),
        "sinc" => F1(Func1::Sinc),
        "sign" => F1(Func1::Sign),
        "atan2" => F2(Func2::Atan2),
        "min" => Fold(Func2::Min),
        "max" => Fold(Func2::Max),
        _ => return None,
    })
}

/// Loop variables in scope, innermost last.
pub(super) type LoopEnv = [(String, i64)];

impl Checker<'_> {
    /// Lowers `e`, reporting every problem; `None` if any was found.
    pub(super) fn lower(&mut self, e: &Expr, allow: Allow, env: &LoopEnv) -> Option<ExprId> {
        let id = match &e.kind {
            ExprKind::Num(v) => self.pool.num(*v),
            ExprKind::Name(id) => self.lower_name(id, allow, env)?,
            ExprKind::Index { base, index } => self.lower_index(base, index, allow, env)?,
            ExprKind::Field { base, field } => self.lower_field(base, field, allow)?,
            ExprKind::Str(_) => {
                return self.fail(Diagnostic::error(
                    "a string is not a number",
                    e.span.clone(),
                    "strings are only used in `csv(\"...\")`",
                ))
            }
            ExprKind::List(_) => {
                return self.fail(Diagnostic::error(
                    "a list is not a number",
                    e.span.clone(),
                    "a scalar expression is needed here",
                ))
            }
            ExprKind::Unary {
                op: UnOp::Neg,
                expr,
            } => {
                let a = self.lower(expr, allow, env)?;
                self.pool.neg(a)
            }
            ExprKind::Binary { op, lhs, rhs } => {
                let a = self.lower(lhs, allow, env);
                let b = self.lower(rhs, allow, env);
                let (a, b) = (a?, b?);
                if *op == BinOp::Div && self.pool.as_const(b) == Some(0.0) {
                    return self.fail(Diagnostic::error(
                        "division by zero",
                        rhs.span.clone(),
                        "this is 0",
                    ));
                }
                let id = match op {
                    BinOp::Add => self.pool.add(a, b),
                    BinOp::Sub => self.pool.sub(a, b),
                    BinOp::Mul => self.pool.mul(a, b),
                    BinOp::Div => self.pool.div(a, b),
                    BinOp::Pow => self.pool.pow(a, b),
                };
                self.check_folded(id, &[a, b], e.span.clone())?
            }
            ExprKind::Call { func, args } => {
                self.lower_call(func, args, e.span.clone(), allow, env)?
            }
        };
        Some(id)
    }

    /// Lowers an expression that must be a constant and returns its value.
    pub(super) fn constant(&mut self, e: &Expr, env: &LoopEnv) -> Option<f64> {
        let id = self.lower(e, Allow::Constants, env)?;
        // Every leaf is a number here and folding failures were reported, so this is a constant
        // (its floating-point value when the fold was not exact).
        self.pool.as_value(id)
    }

    /// Lowers an expression that must be an integer constant (indices, loop bounds).
    pub(super) fn integer(&mut self, e: &Expr, env: &LoopEnv) -> Option<i64> {
        let v = self.constant(e, env)?;
        if v.fract() != 0.0 || v.abs() > 1e15 {
            return self.fail(Diagnostic::error(
                format!("an index must be an integer, but this is {v}"),
                e.span.clone(),
                "not an integer",
            ));
        }
        Some(v as i64)
    }

    /// A node built from constant arguments that did not fold to a constant overflowed or left
    /// its domain (e.g. `1/0`, `log(-1)`): report it.
    fn check_folded(&mut self, id: ExprId, args: &[ExprId], span: Span) -> Option<ExprId> {
        let all_const = args.iter().all(|a| self.pool.as_value(*a).is_some());
        if all_const && self.pool.as_value(id).is_none() {
            return self.fail(
                Diagnostic::error(
                    "this constant expression has no finite value",
                    span,
                    "evaluates to infinity or NaN",
                )
                .with_help(
                    "check for division by zero, overflow, or a function outside its domain",
                ),
            );
        }
        Some(id)
    }

    fn lower_name(&mut self, id: &Ident, allow: Allow, env: &LoopEnv) -> Option<ExprId> {
        if let Some((_, v)) = env.iter().rev().find(|(n, _)| *n == id.name) {
            return Some(self.pool.num(*v as f64));
        }
        match id.name.as_str() {
            "pi" => return Some(self.pool.num(std::f64::consts::PI)),
            "t" => {
                return if allow == Allow::Constants {
                    self.not_constant(id, "time")
                } else {
                    Some(self.pool.var(Var::Time))
                }
            }
            _ => {}
        }
        let Some((sym, def)) = self.scope.get(&id.name).cloned() else {
            // Euler's number, unless the spec defines its own `e` (a common name for an error).
            if id.name == "e" {
                return Some(self.pool.num(std::f64::consts::E));
            }
            return self.undefined(id);
        };
        match sym {
            Symbol::Poisoned => None,
            Symbol::Const(v) => Some(self.pool.num(v)),
            Symbol::Var(kind, i) => self.var_ref(id, kind, i, allow),
            Symbol::Let(e) => {
                if allow == Allow::Constants {
                    return self.not_constant(id, "a let definition");
                }
                Some(e)
            }
            Symbol::Family { .. } | Symbol::LetFamily(_) => self.fail(
                Diagnostic::error(
                    format!("`{}` is {}; use one element of it", id.name, sym.describe()),
                    id.span.clone(),
                    "needs an index",
                )
                .with_label(def, "defined here")
                .with_help(format!("write `{}[i]` with an index", id.name)),
            ),
            Symbol::Table(_) => self.fail(
                Diagnostic::error(
                    format!("`{}` is a table; read one of its columns", id.name),
                    id.span.clone(),
                    "needs a column",
                )
                .with_label(def, "defined here")
                .with_help(format!("write `{}.COLUMN`", id.name)),
            ),
        }
    }

    fn var_ref(&mut self, id: &Ident, kind: VarKind, i: u32, allow: Allow) -> Option<ExprId> {
        match (kind, allow) {
            (_, Allow::Constants) => self.not_constant(id, kind.word()),
            (VarKind::Noise, Allow::Model) => self.fail(
                Diagnostic::error(
                    format!("noise channel `{}` used outside a diffusion row", id.name),
                    id.span.clone(),
                    "noise is not allowed here",
                )
                .with_help(format!(
                    "noise enters through `diffusion {{ STATE: COEFFICIENT * {} }}`",
                    id.name
                )),
            ),
            (VarKind::State, _) => Some(self.pool.var(Var::State(i))),
            (VarKind::Input, _) => Some(self.pool.var(Var::Input(i))),
            (VarKind::Noise, Allow::WithNoise) => Some(self.pool.var(Var::Noise(i))),
        }
    }

    fn not_constant(&mut self, id: &Ident, what: &str) -> Option<ExprId> {
        self.fail(Diagnostic::error(
            format!(
                "`{}` is {what}, but a constant expression is needed here",
                id.name
            ),
            id.span.clone(),
            "not a constant",
        ))
    }

    fn undefined(&mut self, id: &Ident) -> Option<ExprId> {
        let mut d = Diagnostic::error(
            format!("undefined name `{}`", id.name),
            id.span.clone(),
            "not defined",
        );
        if let Some(s) = self.scope.suggest(&id.name, []) {
            d = d.with_help(format!("did you mean `{s}`?"));
        }
        self.fail(d)
    }

    fn lower_index(
        &mut self,
        base: &Ident,
        index: &Expr,
        allow: Allow,
        env: &LoopEnv,
    ) -> Option<ExprId> {
        let Some((sym, def)) = self.scope.get(&base.name).cloned() else {
            return self.undefined(base);
        };
        let i = self.integer(index, env)?;
        match sym {
            Symbol::Poisoned => None,
            Symbol::Family {
                kind,
                first,
                lo,
                hi,
            } => {
                if i < lo || i > hi {
                    return self.out_of_range(base, index.span.clone(), i, lo, hi, def);
                }
                self.var_ref(base, kind, first + (i - lo) as u32, allow)
            }
            Symbol::LetFamily(map) => match map.get(&i) {
                Some(e) if allow != Allow::Constants => Some(*e),
                Some(_) => self.not_constant(base, "a let definition"),
                None => self.fail(
                    Diagnostic::error(
                        format!("`{}[{i}]` is not defined", base.name),
                        index.span.clone(),
                        "no such element",
                    )
                    .with_label(def, "the family is defined here"),
                ),
            },
            other => self.fail(
                Diagnostic::error(
                    format!(
                        "`{}` is {}, which cannot be indexed",
                        base.name,
                        other.describe()
                    ),
                    base.span.clone(),
                    "not a family",
                )
                .with_label(def, "defined here"),
            ),
        }
    }

    pub(super) fn out_of_range<T>(
        &mut self,
        base: &Ident,
        span: Span,
        i: i64,
        lo: i64,
        hi: i64,
        def: Span,
    ) -> Option<T> {
        self.fail(
            Diagnostic::error(
                format!("index {i} is outside `{}[{lo}..{hi}]`", base.name),
                span,
                "out of range",
            )
            .with_label(def, "declared here"),
        )
    }

    fn lower_field(&mut self, base: &Ident, field: &Ident, allow: Allow) -> Option<ExprId> {
        let Some((sym, def)) = self.scope.get(&base.name).cloned() else {
            return self.undefined(base);
        };
        let Symbol::Table(t) = sym else {
            if matches!(sym, Symbol::Poisoned) {
                return None;
            }
            return self.fail(
                Diagnostic::error(
                    format!("`{}` is {}, not a table", base.name, sym.describe()),
                    base.span.clone(),
                    "`.COLUMN` reads a table column",
                )
                .with_label(def, "defined here"),
            );
        };
        if allow == Allow::Constants {
            return self.not_constant(base, "a table (a signal in time)");
        }
        let table = &self.tables[t as usize];
        let Some(col) = table.columns.iter().position(|c| *c == field.name) else {
            let mut d = Diagnostic::error(
                format!("table `{}` has no column `{}`", base.name, field.name),
                field.span.clone(),
                "no such column",
            )
            .with_note(format!("its columns are: {}", table.columns.join(", ")));
            if let Some(s) =
                super::scope::did_you_mean(&field.name, table.columns.iter().map(String::as_str))
            {
                d = d.with_help(format!("did you mean `{s}`?"));
            }
            return self.fail(d);
        };
        let time = self.pool.var(Var::Time);
        Some(self.pool.table(t, col as u32, time))
    }

    fn lower_call(
        &mut self,
        func: &Ident,
        args: &[crate::syntax::ast::Arg],
        span: Span,
        allow: Allow,
        env: &LoopEnv,
    ) -> Option<ExprId> {
        let Some(b) = builtin(&func.name) else {
            let mut d = Diagnostic::error(
                format!("unknown function `{}`", func.name),
                func.span.clone(),
                "not a function",
            );
            let suggestion = super::scope::did_you_mean(&func.name, FUNCTION_NAMES.iter().copied());
            d = match suggestion {
                Some(s) => d.with_help(format!("did you mean `{s}`?")),
                None => d.with_note(format!("the functions are: {}", FUNCTION_NAMES.join(", "))),
            };
            return self.fail(d);
        };
        if let Some(named) = args.iter().find_map(|a| a.name.as_ref()) {
            return self.fail(Diagnostic::error(
                format!("`{}` takes no named arguments", func.name),
                named.span.clone(),
                "remove `NAME =`",
            ));
        }
        let (min, max) = match b {
            Builtin::F1(_) => (1, 1),
            Builtin::F2(_) => (2, 2),
            Builtin::Fold(_) => (2, usize::MAX),
        };
        if args.len() < min || args.len() > max {
            let expected = match (min, max) {
                (1, 1) => "1 argument".to_string(),
                (a, b) if a == b => format!("{a} arguments"),
                (a, _) => format!("at least {a} arguments"),
            };
            let given = match args.len() {
                1 => "1 was given".to_string(),
                k => format!("{k} were given"),
            };
            return self.fail(Diagnostic::error(
                format!("`{}` takes {expected}, but {given}", func.name),
                span,
                format!("expected {expected}"),
            ));
        }
        let lowered: Vec<Option<ExprId>> = args
            .iter()
            .map(|a| self.lower(&a.value, allow, env))
            .collect();
        let ids: Vec<ExprId> = lowered.into_iter().collect::<Option<_>>()?;
        let id = match b {
            Builtin::F1(f) => self.pool.call1(f, ids[0]),
            Builtin::F2(f) => self.pool.call2(f, ids[0], ids[1]),
            Builtin::Fold(f) => ids[1..]
                .iter()
                .fold(ids[0], |acc, &x| self.pool.call2(f, acc, x)),
        };
        self.check_folded(id, &ids, span)
    }
}
