//! The second pass: lets, `for` unrolling, drift (or update) equations, diffusion rows and the
//! domain.

use super::lower::{Allow, LoopEnv};
use super::scope::{Symbol, VarKind};
use super::Checker;
use crate::diagnostics::{Diagnostic, Span};
use crate::ir::{ExprId, Var};
use crate::limits::MAX_UNROLLED;
use crate::model::Bounds;
use crate::syntax::ast::{Expr, ExprKind, Item, Spec, Stmt, Target};

/// A statement handler: gets each non-`let`, non-`for` statement after unrolling.
type Handler<'h, 'a> = &'h mut dyn FnMut(&mut Checker<'a>, &Stmt, &LoopEnv);

impl<'a> Checker<'a> {
    /// Second pass: items with bodies, in source order.
    pub(super) fn bodies(&mut self, spec: &Spec) {
        let mut budget = MAX_UNROLLED;
        for item in &spec.items {
            match item {
                Item::Stmt(s) => self.walk(
                    std::slice::from_ref(s),
                    "at the top level",
                    true,
                    &mut budget,
                    &mut |c, s, _| {
                        c.unexpected(
                            s,
                            "at the top level",
                            "only `let` and `for` can stand outside a block",
                        )
                    },
                ),
                Item::Drift { body, span } if self.is_discrete() => {
                    self.drift_in_discrete(body, span, &mut budget)
                }
                Item::Drift { body, .. } => self.walk(
                    &body.stmts,
                    "in drift",
                    true,
                    &mut budget,
                    &mut |c, s, env| c.drift_stmt(s, env),
                ),
                Item::Update { body, span } => self.update_block(body, span, &mut budget),
                Item::Diffusion(b) => self.walk(
                    &b.stmts,
                    "in diffusion",
                    true,
                    &mut budget,
                    &mut |c, s, env| c.diffusion_stmt(s, env),
                ),
                Item::Domain(b) => {
                    self.has_domain = true;
                    self.walk(
                        &b.stmts,
                        "in domain",
                        false,
                        &mut budget,
                        &mut |c, s, env| c.domain_stmt(s, env),
                    )
                }
                Item::Initial { kind, body, span } => self.initial_set(kind, body, span.clone()),
                Item::Unsafe {
                    name,
                    kind,
                    body,
                    span,
                } => self.unsafe_set(name, kind, body, span.clone()),
                Item::Goal {
                    name,
                    parts,
                    window,
                    stay,
                    span,
                } => self.goal_set(name, parts, window.as_ref(), stay.is_some(), span.clone()),
                Item::Analysis { name, body, span } => self.analysis(name, body, span.clone()),
                Item::Const { .. }
                | Item::State(_)
                | Item::Input(_)
                | Item::Noise(_)
                | Item::Table { .. }
                | Item::Discrete { .. } => {}
            }
        }
    }

    /// Runs `handler` on every statement of `stmts`, unrolling `for` loops and defining lets.
    pub(super) fn walk(
        &mut self,
        stmts: &[Stmt],
        place: &str,
        allow_let: bool,
        budget: &mut usize,
        handler: Handler<'_, 'a>,
    ) {
        let mut env = Vec::new();
        self.walk_in(stmts, place, allow_let, budget, &mut env, handler);
    }

    fn walk_in(
        &mut self,
        stmts: &[Stmt],
        place: &str,
        allow_let: bool,
        budget: &mut usize,
        env: &mut Vec<(String, i64)>,
        handler: Handler<'_, 'a>,
    ) {
        for s in stmts {
            if !self.spend(budget, 1, head_span(s)) {
                return;
            }
            match s {
                Stmt::For {
                    var, range, body, ..
                } => {
                    if self.scope.get(&var.name).is_some()
                        || env.iter().any(|(n, _)| *n == var.name)
                    {
                        self.diags.push(
                            Diagnostic::error(
                                format!("loop variable `{}` hides another name", var.name),
                                var.span.clone(),
                                "already defined",
                            )
                            .with_help("use a fresh name such as `i`, `j` or `k`"),
                        );
                        continue;
                    }
                    let (Some(lo), Some(hi)) =
                        (self.integer(&range.lo, env), self.integer(&range.hi, env))
                    else {
                        continue;
                    };
                    // Each iteration counts, so loops with empty bodies are bounded too.
                    let iterations = usize::try_from(i128::from(hi) - i128::from(lo) + 1);
                    if !self.spend(budget, iterations.unwrap_or(0), head_span(s)) {
                        return;
                    }
                    for i in lo..=hi {
                        env.push((var.name.clone(), i));
                        self.walk_in(&body.stmts, place, allow_let, budget, env, handler);
                        env.pop();
                        if *budget == 0 {
                            return;
                        }
                    }
                }
                Stmt::Let { target, value, .. } if allow_let => self.define_let(target, value, env),
                Stmt::Let { .. } => self.unexpected(
                    s,
                    place,
                    "`let` is allowed at the top level and in drift and diffusion",
                ),
                _ => handler(self, s, env),
            }
        }
    }

    /// Takes `n` units of the unrolling budget; `false` (after reporting at `span`, the first
    /// time) once it is spent.
    fn spend(&mut self, budget: &mut usize, n: usize, span: Span) -> bool {
        if *budget == 0 {
            return false;
        }
        if n < *budget {
            *budget -= n;
            return true;
        }
        *budget = 0;
        self.diags.push(
            Diagnostic::error(
                format!("`for` loops unroll to more than {MAX_UNROLLED} statements"),
                span,
                "the limit is passed here",
            )
            .with_help("a model this large is beyond what the analyses can use; make it smaller"),
        );
        false
    }

    fn define_let(&mut self, target: &Target, value: &Expr, env: &LoopEnv) {
        let Some(e) = self.lower(value, Allow::Model, env) else {
            return;
        };
        let Some(index) = &target.index else {
            self.define(&target.name, Symbol::Let(e));
            return;
        };
        let Some(i) = self.integer(index, env) else {
            return;
        };
        match self.scope.symbols.get_mut(&target.name.name) {
            Some((Symbol::LetFamily(map), def)) => {
                if map.insert(i, e).is_some() {
                    let def = def.clone();
                    self.diags.push(
                        Diagnostic::error(
                            format!("`{}[{i}]` is defined twice", target.name.name),
                            target.span.clone(),
                            "defined again here",
                        )
                        .with_label(def, "the family is first defined here"),
                    );
                }
            }
            _ => {
                let map = std::iter::once((i, e)).collect();
                self.define(&target.name, Symbol::LetFamily(map));
            }
        }
    }

    /// Reports a statement of the wrong kind for its block.
    pub(super) fn unexpected(&mut self, s: &Stmt, place: &str, help: &str) {
        let what = match s {
            Stmt::Equation { .. } => "a drift equation",
            Stmt::Update { .. } => "an update equation",
            Stmt::Row { .. } => "a diffusion row",
            Stmt::Member { .. } => "a membership `x in [..]`",
            Stmt::Field { .. } => "a field `key = value`",
            Stmt::Constraint { .. } => "a constraint",
            Stmt::Let { .. } => "a `let`",
            Stmt::For { .. } => "a `for` loop",
        };
        self.diags.push(
            Diagnostic::error(
                format!("{what} is not allowed {place}"),
                stmt_span(s),
                "misplaced",
            )
            .with_help(help.to_string()),
        );
    }

    /// Resolves `x` or `x[i]` to a variable index of the given kind.
    pub(super) fn target(&mut self, t: &Target, kind: VarKind, env: &LoopEnv) -> Option<usize> {
        let Some((sym, def)) = self.scope.get(&t.name.name).cloned() else {
            let mut d = Diagnostic::error(
                format!("undefined {} `{}`", kind.word(), t.name.name),
                t.name.span.clone(),
                "not defined",
            );
            if let Some(s) = self.scope.suggest(&t.name.name, []) {
                d = d.with_help(format!("did you mean `{s}`?"));
            }
            return self.fail(d);
        };
        let (k, idx) = match (&sym, &t.index) {
            (Symbol::Poisoned, _) => return None,
            (Symbol::Var(k, i), None) => (*k, *i as usize),
            (
                Symbol::Family {
                    kind: k,
                    first,
                    lo,
                    hi,
                },
                Some(index),
            ) => {
                let i = self.integer(index, env)?;
                if i < *lo || i > *hi {
                    return self.out_of_range(&t.name, index.span.clone(), i, *lo, *hi, def);
                }
                (*k, (*first as i64 + i - lo) as usize)
            }
            (Symbol::Family { .. }, None) => {
                return self.fail(
                    Diagnostic::error(
                        format!("`{}` is a family; name one element", t.name.name),
                        t.span.clone(),
                        "needs an index",
                    )
                    .with_help(format!(
                        "write `{}[i]` inside `for i in LO..HI {{ ... }}`",
                        t.name.name
                    )),
                )
            }
            _ => {
                return self.fail(
                    Diagnostic::error(
                        format!(
                            "`{}` is {}, but a {} is needed here",
                            t.name.name,
                            sym.describe(),
                            kind.word()
                        ),
                        t.span.clone(),
                        format!("not a {}", kind.word()),
                    )
                    .with_label(def, "defined here"),
                )
            }
        };
        if k != kind {
            return self.fail(
                Diagnostic::error(
                    format!(
                        "`{}` is a {}, but a {} is needed here",
                        t.name.name,
                        k.word(),
                        kind.word()
                    ),
                    t.span.clone(),
                    format!("not a {}", kind.word()),
                )
                .with_label(def, "declared here"),
            );
        }
        Some(idx)
    }

    /// An interval `[lo, hi]` of constants with `lo <= hi`.
    pub(super) fn interval(&mut self, e: &Expr, env: &LoopEnv) -> Option<Bounds> {
        let [lo, hi] = self.interval_ends(e)?;
        let (lo, hi) = (self.constant(lo, env), self.constant(hi, env));
        let (lo, hi) = (lo?, hi?);
        self.ordered(lo, hi, e)
    }

    /// `Bounds { lo, hi }`, or a diagnostic at `e` when `lo > hi`.
    pub(super) fn ordered(&mut self, lo: f64, hi: f64, e: &Expr) -> Option<Bounds> {
        if lo > hi {
            return self.fail(
                Diagnostic::error(
                    format!(
                        "empty interval: the lower end {lo} is greater than the upper end {hi}"
                    ),
                    e.span.clone(),
                    "empty",
                )
                .with_help("swap the ends"),
            );
        }
        Some(Bounds { lo, hi })
    }

    /// The two ends of an interval `[LO, HI]`.
    pub(super) fn interval_ends<'e>(&mut self, e: &'e Expr) -> Option<&'e [Expr; 2]> {
        let ExprKind::List(items) = &e.kind else {
            return self.fail(
                Diagnostic::error("expected an interval", e.span.clone(), "not an interval")
                    .with_help("write `[LO, HI]`"),
            );
        };
        if items.len() != 2 {
            return self.fail(
                Diagnostic::error(
                    format!(
                        "an interval has two ends, but this list has {}",
                        items.len()
                    ),
                    e.span.clone(),
                    "not an interval",
                )
                .with_help("write `[LO, HI]`"),
            );
        }
        items.as_slice().try_into().ok()
    }

    fn drift_stmt(&mut self, s: &Stmt, env: &LoopEnv) {
        let Stmt::Equation { target, rhs, span } = s else {
            return self.unexpected(
                s,
                "in drift",
                "drift holds equations like `x' = -x`, `let` and `for`",
            );
        };
        self.equation(target, rhs, span, env);
    }

    /// A state's equation: its drift, or in a discrete-time model its next value (`span`: the
    /// statement); one per state.
    pub(super) fn equation(&mut self, target: &Target, rhs: &Expr, span: &Span, env: &LoopEnv) {
        let i = self.target(target, VarKind::State, env);
        let e = self.lower(rhs, Allow::Model, env);
        let Some(i) = i else { return };
        let Some(e) = e else {
            // Reported already; the state must not also be called "without equation".
            self.drift_failed[i] = true;
            return;
        };
        if let Some((_, first)) = &self.drift[i] {
            let first = first.clone();
            self.diags.push(
                Diagnostic::error(
                    format!(
                        "state `{}` has two {} equations",
                        self.states[i].name,
                        self.equation_word()
                    ),
                    span.clone(),
                    "second equation",
                )
                .with_label(first, "first equation"),
            );
            return;
        }
        self.drift[i] = Some((e, span.clone()));
    }

    fn diffusion_stmt(&mut self, s: &Stmt, env: &LoopEnv) {
        let Stmt::Row { target, rhs, span } = s else {
            return self.unexpected(
                s,
                "in diffusion",
                "diffusion holds rows like `x: 0.1 * w`, `let` and `for`",
            );
        };
        let i = self.target(target, VarKind::State, env);
        let e = self.lower(rhs, Allow::WithNoise, env);
        let (Some(i), Some(e)) = (i, e) else { return };
        if self.diffusion[i].is_some() {
            self.diags.push(
                Diagnostic::error(
                    format!("state `{}` has two diffusion rows", self.states[i].name),
                    span.clone(),
                    "second row",
                )
                .with_help("write one row as a sum: `x: a * w1 + b * w2`"),
            );
            return;
        }
        if let Some(row) = self.noise_coefficients(e, rhs) {
            self.diffusion[i] = Some(row);
        }
    }

    /// Splits a diffusion row `sum_k G_k * w_k` into its coefficients, checking linearity.
    fn noise_coefficients(&mut self, e: ExprId, rhs: &Expr) -> Option<Vec<ExprId>> {
        let zero = self.pool.num(0.0);
        let mut row = vec![zero; self.noises.len()];
        for v in self.pool.vars_of(e) {
            if let Var::Noise(k) = v {
                row[k as usize] = self.pool.diff(e, v);
            }
        }
        let rest = self
            .pool
            .substitute(e, &mut |v| matches!(v, Var::Noise(_)).then_some(zero));
        if self.pool.as_const(rest) != Some(0.0) {
            return self.fail(
                Diagnostic::error(
                    "a diffusion row must be a combination of noise channels",
                    rhs.span.clone(),
                    "has a term without a noise channel",
                )
                .with_help("write `x: COEFFICIENT * w`; deterministic terms belong in the drift"),
            );
        }
        for &g in &row {
            let vars = self.pool.vars_of(g);
            if vars.iter().any(|v| matches!(v, Var::Noise(_))) {
                return self.fail(
                    Diagnostic::error("a diffusion row must be linear in the noise channels", rhs.span.clone(), "noise enters non-linearly")
                        .with_help("each noise channel may only be multiplied by a coefficient that depends on states and time"),
                );
            }
            if vars.iter().any(|v| matches!(v, Var::Input(_))) {
                return self.fail(
                    Diagnostic::error(
                        "a diffusion coefficient depends on an input",
                        rhs.span.clone(),
                        "uses an input",
                    )
                    .with_note("the method assumes G(x, t): inputs may only enter the drift"),
                );
            }
        }
        Some(row)
    }

    fn domain_stmt(&mut self, s: &Stmt, env: &LoopEnv) {
        let Stmt::Member { target, set, span } = s else {
            return self.unexpected(
                s,
                "in domain",
                "domain holds memberships like `x in [-1, 1]` and `for`",
            );
        };
        let i = self.target(target, VarKind::State, env);
        let b = self.interval(set, env);
        let (Some(i), Some(b)) = (i, b) else { return };
        if self.domain[i] != Bounds::ENTIRE {
            self.diags.push(Diagnostic::error(
                format!(
                    "state `{}` is bounded twice in the domain",
                    self.states[i].name
                ),
                span.clone(),
                "second bound",
            ));
            return;
        }
        if let Some(init) = self.boxes[i] {
            if init.lo < b.lo || init.hi > b.hi {
                self.diags.push(Diagnostic::error(
                    format!(
                        "the initial set of `{}` is not inside the domain",
                        self.states[i].name
                    ),
                    span.clone(),
                    format!(
                        "domain [{}, {}] does not contain [{}, {}]",
                        b.lo, b.hi, init.lo, init.hi
                    ),
                ));
            }
        }
        self.domain[i] = b;
    }
}

/// The span of a statement's first line: a `for` loop's head (`for i in LO..HI`), so that a
/// diagnostic about the loop does not underline its whole body.
fn head_span(s: &Stmt) -> Span {
    match s {
        Stmt::For { span, range, .. } => span.start..range.span.end,
        _ => stmt_span(s),
    }
}

/// The span of a statement.
pub(super) fn stmt_span(s: &Stmt) -> crate::diagnostics::Span {
    match s {
        Stmt::Equation { span, .. }
        | Stmt::Update { span, .. }
        | Stmt::Row { span, .. }
        | Stmt::Member { span, .. }
        | Stmt::Field { span, .. }
        | Stmt::Constraint { span, .. }
        | Stmt::Let { span, .. }
        | Stmt::For { span, .. } => span.clone(),
    }
}
