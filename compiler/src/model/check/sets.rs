//! Initial balls, unsafe sets, and the `key = value` field blocks they share with analyses.

use std::collections::HashMap;

use super::lower::Allow;
use super::matrix;
use super::scope::{did_you_mean, VarKind};
use super::Checker;
use crate::diagnostics::{Diagnostic, Span};
use crate::ir::{ExprId, Var, VarValues};
use crate::model::{Ball, Bounds, GoalSet, Moving, Slot, UnsafeSet, UnsafeShape, Variable};
use crate::syntax::ast::{Block, CmpOp, Expr, ExprKind, Ident, Stmt, Target};
use reachc_core::Interval;

/// The fields of a block, by key.
pub(super) type Fields<'s> = HashMap<&'s str, (&'s Expr, Span)>;

/// The numbers of a set's shape that move (method.md 8.15), each with its expression.
type MovingNumbers = Vec<(Slot, ExprId)>;

impl Checker<'_> {
    /// Collects `key = value` fields, reporting unknown keys (with a suggestion), duplicates and
    /// statements that are not fields.
    pub(super) fn fields<'s>(&mut self, body: &'s Block, keys: &[&str], what: &str) -> Fields<'s> {
        let mut out: Fields<'s> = HashMap::new();
        for s in &body.stmts {
            let Stmt::Field { key, value, span } = s else {
                self.unexpected(
                    s,
                    &format!("in {what}"),
                    &format!("{what} holds fields: {}", keys.join(", ")),
                );
                continue;
            };
            if !keys.contains(&key.name.as_str()) {
                let mut d = Diagnostic::error(
                    format!("unknown key `{}` in {what}", key.name),
                    key.span.clone(),
                    "unknown key",
                );
                d = match did_you_mean(&key.name, keys.iter().copied()) {
                    Some(k) => d.with_help(format!("did you mean `{k}`?")),
                    None => d.with_note(format!("the keys are: {}", keys.join(", "))),
                };
                self.diags.push(d);
                continue;
            }
            if let Some((_, first)) = out.get(key.name.as_str()) {
                let first = first.clone();
                self.diags.push(
                    Diagnostic::error(
                        format!("`{}` is given twice in {what}", key.name),
                        span.clone(),
                        "given again",
                    )
                    .with_label(first, "first given here"),
                );
                continue;
            }
            out.insert(&key.name, (value, span.clone()));
        }
        out
    }

    /// A list of constants.
    pub(super) fn vector(&mut self, e: &Expr) -> Option<Vec<f64>> {
        let ExprKind::List(items) = &e.kind else {
            return self.fail(
                Diagnostic::error("expected a list of numbers", e.span.clone(), "not a list")
                    .with_help("write `[a, b, ...]`"),
            );
        };
        let vals: Vec<Option<f64>> = items.iter().map(|x| self.constant(x, &[])).collect();
        vals.into_iter().collect()
    }

    /// A matrix: a list of lists of constants (squareness is checked by the caller).
    pub(super) fn matrix(&mut self, e: &Expr) -> Option<Vec<Vec<f64>>> {
        let ExprKind::List(rows) = &e.kind else {
            return self.fail(
                Diagnostic::error("expected a matrix", e.span.clone(), "not a matrix")
                    .with_help("write rows as lists: `[[1, 0], [0, 1]]`"),
            );
        };
        let rows: Vec<Option<Vec<f64>>> = rows.iter().map(|r| self.vector(r)).collect();
        rows.into_iter().collect()
    }

    /// A list of state names (or family elements with constant indices).
    pub(super) fn state_list(&mut self, e: &Expr) -> Option<Vec<usize>> {
        let ExprKind::List(items) = &e.kind else {
            return self.fail(
                Diagnostic::error("expected a list of states", e.span.clone(), "not a list")
                    .with_help("write `[x, y]`"),
            );
        };
        let mut out = Vec::new();
        for item in items {
            let target = match &item.kind {
                ExprKind::Name(name) => Target {
                    name: name.clone(),
                    index: None,
                    span: item.span.clone(),
                },
                ExprKind::Index { base, index } => Target {
                    name: base.clone(),
                    index: Some(index.clone()),
                    span: item.span.clone(),
                },
                _ => {
                    return self.fail(Diagnostic::error(
                        "expected a state name",
                        item.span.clone(),
                        "not a state",
                    ))
                }
            };
            let i = self.target(&target, VarKind::State, &[])?;
            if out.contains(&i) {
                return self.fail(Diagnostic::error(
                    format!("state `{}` is listed twice", self.states[i].name),
                    item.span.clone(),
                    "repeated",
                ));
            }
            out.push(i);
        }
        Some(out)
    }

    /// `over`, `center` and `radius` of an initial ball (constants); `over` defaults to all
    /// states.
    fn ball_fields(&mut self, f: &Fields, span: &Span) -> Option<(Vec<usize>, Vec<f64>, f64)> {
        let constant = |c: &mut Self, e: &Expr| c.constant(e, &[]).map(|v| (v, None));
        let (states, center, (radius, _)) = self.ball_numbers(f, span, constant)?;
        Some((states, center.into_iter().map(|(v, _)| v).collect(), radius))
    }

    /// `over`, `center` and `radius` of a ball, each number read by `number` (its value, and
    /// its expression when it moves); `over` defaults to all states.
    #[allow(clippy::type_complexity)] // (states, centre, radius), each number with its motion
    fn ball_numbers(
        &mut self,
        f: &Fields,
        span: &Span,
        mut number: impl FnMut(&mut Self, &Expr) -> Option<(f64, Option<ExprId>)>,
    ) -> Option<(
        Vec<usize>,
        Vec<(f64, Option<ExprId>)>,
        (f64, Option<ExprId>),
    )> {
        let states = match f.get("over") {
            Some((e, _)) => self.state_list(e)?,
            None => (0..self.states.len()).collect(),
        };
        let center_expr = self.required(f, "center", span, "ball")?;
        let ExprKind::List(items) = &center_expr.kind else {
            return self.fail(
                Diagnostic::error(
                    "expected a list of numbers",
                    center_expr.span.clone(),
                    "not a list",
                )
                .with_help("write `[a, b, ...]`"),
            );
        };
        let center: Vec<Option<(f64, Option<ExprId>)>> =
            items.iter().map(|x| number(self, x)).collect();
        let center = center.into_iter().collect::<Option<Vec<_>>>()?;
        let radius_expr = self.required(f, "radius", span, "ball")?;
        let radius = number(self, radius_expr)?;
        if center.len() != states.len() {
            return self.fail(Diagnostic::error(
                format!(
                    "the centre has {} entries but the ball is over {} states",
                    center.len(),
                    states.len()
                ),
                center_expr.span.clone(),
                "wrong length",
            ));
        }
        if radius.0 < 0.0 {
            return self.fail(Diagnostic::error(
                format!("the radius {} is negative", radius.0),
                radius_expr.span.clone(),
                "must be >= 0",
            ));
        }
        Some((states, center, radius))
    }

    /// A required field, or a diagnostic at the block.
    pub(super) fn required<'s>(
        &mut self,
        f: &Fields<'s>,
        key: &str,
        span: &Span,
        what: &str,
    ) -> Option<&'s Expr> {
        match f.get(key) {
            Some((e, _)) => Some(e),
            None => self.fail(Diagnostic::error(
                format!("{what} needs `{key}`"),
                span.clone(),
                format!("no `{key} = ...`"),
            )),
        }
    }

    /// `initial ball { over = [..] center = [..] radius = r metric = [[..]] }`.
    pub(super) fn initial_set(&mut self, kind: &Ident, body: &Block, span: Span) {
        if kind.name != "ball" {
            self.diags.push(
                Diagnostic::error(
                    format!("unknown initial set kind `{}`", kind.name),
                    kind.span.clone(),
                    "expected `ball`",
                )
                .with_help("boxes and points are written on the states: `state x in [LO, HI]`"),
            );
            return;
        }
        let f = self.fields(
            body,
            &["over", "center", "radius", "metric"],
            "an initial ball",
        );
        let Some((states, center, radius)) = self.ball_fields(&f, &span) else {
            return;
        };
        let metric = match f.get("metric") {
            None => None,
            Some((e, _)) => {
                let Some(m) = self.matrix(e) else { return };
                if let Err(err) =
                    matrix::check_square(&m, states.len()).and_then(|()| matrix::check_spd(&m))
                {
                    self.diags.push(Diagnostic::error(format!("bad ball metric: {err}"), e.span.clone(), "here")
                        .with_help("the metric must be symmetric positive definite, one row per state of the ball"));
                    return;
                }
                Some(m)
            }
        };
        for &s in &states {
            let earlier = self
                .balls
                .iter()
                .find(|(b, _)| b.states.contains(&s))
                .map(|(_, span)| span.clone());
            if self.boxes[s].is_some() || earlier.is_some() {
                let mut d = Diagnostic::error(
                    format!("state `{}` gets two initial sets", self.states[s].name),
                    span.clone(),
                    "this ball",
                )
                .with_label(self.states[s].span.clone(), "declared here");
                if let Some(e) = earlier {
                    d = d.with_label(e, "an earlier ball");
                }
                self.diags.push(d.with_help(
                    "a state has a box or point in its declaration, or belongs to one ball",
                ));
                return;
            }
        }
        self.balls.push((
            Ball {
                states,
                center,
                radius,
                metric: metric.map(|m| m.concat()),
            },
            span,
        ));
    }

    /// `unsafe NAME box|ball|halfspace { ... }`.
    pub(super) fn unsafe_set(&mut self, name: &Ident, kind: &Ident, body: &Block, span: Span) {
        let first = self.unsafe_sets.iter().find(|(u, _)| u.name == name.name);
        if self.defined_twice("unsafe set", name, first.map(|(_, span)| span.clone())) {
            return;
        }
        if let Some((shape, moving)) = self.set_shape(kind, body, &span, "unsafe") {
            let moving = self.moving(0, moving);
            self.unsafe_sets.push((
                UnsafeSet {
                    name: name.name.clone(),
                    shape,
                    moving,
                },
                span,
            ));
        }
    }

    /// `goal NAME KIND { ... } [and KIND { ... }]... [within [T1, T2]] [stay]` (method.md
    /// 8.13): the parts as for unsafe sets, refused where they are certainly empty together
    /// (boxes with no common point, a half-space missing the box of the others); the window
    /// two constants `0 <= T1 <= T2` (checked against each analysis' horizon by
    /// [`Checker::goal_windows`]).
    pub(super) fn goal_set(
        &mut self,
        name: &Ident,
        parts: &[(Ident, Block)],
        window: Option<&Expr>,
        stay: bool,
        span: Span,
    ) {
        let first = self.goals.iter().find(|(g, _, _)| g.name == name.name);
        if self.defined_twice("goal", name, first.map(|(_, span, _)| span.clone())) {
            return;
        }
        let shapes: Vec<Option<(UnsafeShape, MovingNumbers)>> = parts
            .iter()
            .map(|(kind, body)| self.set_shape(kind, body, &span, "goal"))
            .collect();
        let window = match window {
            None => Some(None),
            Some(e) => self.goal_window(e).map(|w| Some((w, e.span.clone()))),
        };
        let (Some(parts), Some(window)) = (shapes.into_iter().collect::<Option<Vec<_>>>(), window)
        else {
            return;
        };
        let (parts, numbers): (Vec<UnsafeShape>, Vec<MovingNumbers>) = parts.into_iter().unzip();
        let moving: Vec<Moving> = numbers
            .into_iter()
            .enumerate()
            .flat_map(|(j, m)| self.moving(j, m))
            .collect();
        // (A moving goal may be empty at some times and not at others: its verdict says so.)
        let why = moving
            .is_empty()
            .then(|| empty(&parts, &self.states))
            .flatten();
        if let Some(why) = why {
            self.diags.push(
                Diagnostic::error(
                    format!("goal `{}` is empty: {why}", name.name),
                    span,
                    "no state is in every part",
                )
                .with_help("a goal is the intersection of its parts: widen or drop one"),
            );
            return;
        }
        self.goals.push((
            GoalSet {
                name: name.name.clone(),
                parts,
                moving,
                window: window.as_ref().map(|(w, _)| *w),
                stay,
            },
            span,
            window.map(|(_, s)| s),
        ));
    }

    /// `within [T1, T2]`: constants with `0 <= T1 <= T2 < inf`.
    fn goal_window(&mut self, e: &Expr) -> Option<Bounds> {
        let w = self.interval(e, &[])?;
        if !(w.lo >= 0.0 && w.hi.is_finite()) {
            return self.fail(
                Diagnostic::error(
                    format!("the window [{}, {}] is not inside [0, inf)", w.lo, w.hi),
                    e.span.clone(),
                    "a window of times",
                )
                .with_help("write `within [T1, T2]` with 0 <= T1 <= T2"),
            );
        }
        Some(w)
    }

    /// Every goal's window inside each analysis' `[0, T]` (a window past the horizon asks
    /// about times the analysis does not cover).
    pub(super) fn goal_windows(&mut self) {
        let mut found = Vec::new();
        for (g, _, span) in &self.goals {
            let (Some(w), Some(span)) = (g.window, span) else {
                continue;
            };
            for a in &self.analyses {
                if w.hi > a.spec.horizon {
                    found.push(
                        Diagnostic::error(
                            format!(
                                "the window of goal `{}` ends at {}, after the horizon {} of \
                                 analysis `{}`",
                                g.name, w.hi, a.spec.horizon, a.spec.name
                            ),
                            span.clone(),
                            "outside [0, T]",
                        )
                        .with_label(a.name_span.clone(), "this analysis")
                        .with_help("end the window by the horizon, or lengthen the horizon"),
                    );
                }
            }
        }
        self.diags.extend(found);
    }

    /// `KIND { ... }` of an unsafe set or a goal (`owner`) as a region (at `t = 0`), with the
    /// numbers that move (method.md 8.15).
    fn set_shape(
        &mut self,
        kind: &Ident,
        body: &Block,
        span: &Span,
        owner: &str,
    ) -> Option<(UnsafeShape, MovingNumbers)> {
        let a = if owner == "unsafe" { "an" } else { "a" };
        match kind.name.as_str() {
            "box" => self.unsafe_box(body, &format!("{a} {owner} box")),
            "ball" => {
                let what = format!("{a} {owner} ball");
                let f = self.fields(body, &["over", "center", "radius"], &what);
                self.set_ball(&f, span)
            }
            "halfspace" => self.halfspace(body),
            other => {
                let mut d = Diagnostic::error(
                    format!("unknown {owner} set kind `{other}`"),
                    kind.span.clone(),
                    "expected box, ball or halfspace",
                );
                if let Some(s) = did_you_mean(other, ["box", "ball", "halfspace"]) {
                    d = d.with_help(format!("did you mean `{s}`?"));
                }
                self.fail(d)
            }
        }
    }

    fn unsafe_box(&mut self, body: &Block, what: &str) -> Option<(UnsafeShape, MovingNumbers)> {
        let mut sides: Vec<(usize, Bounds)> = Vec::new();
        let mut moving = Vec::new();
        let mut ok = true;
        for s in &body.stmts {
            let Stmt::Member { target, set, .. } = s else {
                self.unexpected(
                    s,
                    &format!("in {what}"),
                    &format!("{what} holds memberships like `px in [1, 2]`"),
                );
                ok = false;
                continue;
            };
            let (i, b) = (
                self.target(target, VarKind::State, &[]),
                self.set_interval(set),
            );
            let (Some(i), Some((b, lo, hi))) = (i, b) else {
                ok = false;
                continue;
            };
            if sides.iter().any(|(j, _)| *j == i) {
                self.diags.push(Diagnostic::error(
                    format!("state `{}` is bounded twice", self.states[i].name),
                    target.span.clone(),
                    "again",
                ));
                ok = false;
                continue;
            }
            let k = sides.len();
            moving.extend(lo.map(|e| (Slot::Lo(k), e)));
            moving.extend(hi.map(|e| (Slot::Hi(k), e)));
            sides.push((i, b));
        }
        if ok && sides.is_empty() {
            return self.fail(
                Diagnostic::error(
                    format!("{what} needs at least one side"),
                    body.span.clone(),
                    "empty",
                )
                .with_help("write `px in [1, 2]`"),
            );
        }
        ok.then_some((UnsafeShape::Box(sides), moving))
    }

    fn halfspace(&mut self, body: &Block) -> Option<(UnsafeShape, MovingNumbers)> {
        let [Stmt::Constraint { lhs, op, rhs, span }] = body.stmts.as_slice() else {
            return self.fail(
                Diagnostic::error(
                    "a half-space is one linear constraint",
                    body.span.clone(),
                    "expected one `EXPR >= EXPR`",
                )
                .with_help("write `halfspace { px + 2 * py >= 3 }`"),
            );
        };
        let l = self.lower(lhs, Allow::Model, &[]);
        let r = self.lower(rhs, Allow::Model, &[]);
        let (l, r) = (l?, r?);
        // Normalise to `g(x) >= 0`, then split g into normal . x - offset.
        let g = match op {
            CmpOp::Ge => self.pool.sub(l, r),
            CmpOp::Le => self.pool.sub(r, l),
        };
        let not_linear = |c: &mut Self| {
            c.fail(
                Diagnostic::error(
                    "a half-space must be linear in the states",
                    span.clone(),
                    "not linear",
                )
                .with_help("use only constants times states: `a * px + b * py >= c`"),
            )
        };
        let mut normal = vec![0.0; self.states.len()];
        for v in self.pool.vars_of(g) {
            // Only states make the normal. Time (and tables) may move the offset; an input or
            // a noise channel in the offset is refused below, by name.
            let Var::State(i) = v else {
                continue;
            };
            let d = self.pool.diff(g, v);
            let Some(a) = self.pool.as_value(d) else {
                return not_linear(self);
            };
            normal[i as usize] = a;
        }
        if normal.iter().all(|a| *a == 0.0) {
            return self.fail(Diagnostic::error(
                "the half-space does not depend on any state",
                span.clone(),
                "no state here",
            ));
        }
        // `g(x) = normal . x - offset(t)`: the offset is `-g(0)`.
        let zero = self.pool.num(0.0);
        let at_zero = self
            .pool
            .substitute(g, &mut |v| matches!(v, Var::State(_)).then_some(zero));
        let offset = self.pool.neg(at_zero);
        let moving_span = lhs.span.start..rhs.span.end;
        let (offset, moving) = match self.set_number(offset, &moving_span)? {
            (v, None) => (v, Vec::new()),
            (v, Some(e)) => (v, vec![(Slot::Offset, e)]),
        };
        Some((UnsafeShape::HalfSpace { normal, offset }, moving))
    }

    /// A number of an unsafe or goal set, lowered: its value at `t = 0`, and its expression
    /// when it moves (depends on `t` or a table, method.md 8.15); states, inputs and noise are
    /// refused at `span`.
    fn set_number(&mut self, id: ExprId, span: &Span) -> Option<(f64, Option<ExprId>)> {
        if let Some(v) = self.pool.as_value(id) {
            return Some((v, None));
        }
        if let Some(v) = self.pool.vars_of(id).into_iter().find(|v| *v != Var::Time) {
            let what = match v {
                Var::State(i) => format!("state `{}`", self.states[i as usize].name),
                Var::Input(i) => format!("input `{}`", self.inputs[i as usize].name),
                _ => "a noise channel".to_string(),
            };
            return self.fail(
                Diagnostic::error(
                    format!("a set's bounds, centre and radius may depend on `t` and tables only, not on {what}"),
                    span.clone(),
                    "not a function of t and tables",
                )
                .with_help("a set that moves is written with `t` or a table column, e.g. `x >= 1 + 0.5 * t` or `x in [lead.x - 1, lead.x + 1]`"),
            );
        }
        let at_zero = VarValues {
            states: &[],
            inputs: &[],
            noises: &[],
            time: 0.0,
        };
        let v = self.pool.eval(&[id], &at_zero, &self.tables)[0];
        if !v.is_finite() {
            return self.fail(Diagnostic::error(
                format!("this number of the set is {v} at t = 0"),
                span.clone(),
                "not finite",
            ));
        }
        Some((v, Some(id)))
    }

    /// A set's number written as the expression `e` (see [`Checker::set_number`]).
    fn set_number_of(&mut self, e: &Expr) -> Option<(f64, Option<ExprId>)> {
        let id = self.lower(e, Allow::Model, &[])?;
        self.set_number(id, &e.span)
    }

    /// A box side `[LO, HI]` of a set: its bounds at `t = 0` and the ends that move.
    fn set_interval(&mut self, e: &Expr) -> Option<(Bounds, Option<ExprId>, Option<ExprId>)> {
        let [lo, hi] = self.interval_ends(e)?;
        let (lo, hi) = (self.set_number_of(lo), self.set_number_of(hi));
        let ((lo, lo_moves), (hi, hi_moves)) = (lo?, hi?);
        // (A moving side may cross later: the set is then empty at those times.)
        let b = self.ordered(lo, hi, e)?;
        Some((b, lo_moves, hi_moves))
    }

    /// `over`, `center` and `radius` of an unsafe or goal ball; `over` defaults to all states.
    fn set_ball(&mut self, f: &Fields, span: &Span) -> Option<(UnsafeShape, MovingNumbers)> {
        let (states, center, (radius, radius_moves)) =
            self.ball_numbers(f, span, Self::set_number_of)?;
        let mut moving: MovingNumbers = center
            .iter()
            .enumerate()
            .filter_map(|(k, (_, e))| e.map(|e| (Slot::Center(k), e)))
            .collect();
        moving.extend(radius_moves.map(|e| (Slot::Radius, e)));
        let center = center.into_iter().map(|(v, _)| v).collect();
        Some((
            UnsafeShape::Ball {
                states,
                center,
                radius,
            },
            moving,
        ))
    }

    /// The moving numbers of part `part` of a set, registered as the model's set numbers.
    fn moving(&mut self, part: usize, numbers: MovingNumbers) -> Vec<Moving> {
        numbers
            .into_iter()
            .map(|(slot, e)| {
                self.set_numbers.push(e);
                Moving {
                    part,
                    slot,
                    number: self.set_numbers.len() - 1,
                }
            })
            .collect()
    }
}

/// Why the intersection of `parts` is certainly empty, if it is: two boxes with no common point
/// in a state, or a half-space that misses the box the box parts bound (when they bound every
/// state it involves).
fn empty(parts: &[UnsafeShape], states: &[Variable]) -> Option<String> {
    let mut b = vec![Bounds::ENTIRE; states.len()];
    for p in parts {
        if let UnsafeShape::Box(sides) = p {
            for &(i, side) in sides {
                let (lo, hi) = (b[i].lo.max(side.lo), b[i].hi.min(side.hi));
                if lo > hi {
                    return Some(format!(
                        "its boxes bound `{}` to ranges with no common point",
                        states[i].name
                    ));
                }
                b[i] = Bounds::new(lo, hi);
            }
        }
    }
    for p in parts {
        if let UnsafeShape::HalfSpace { normal, offset } = p {
            // The largest `normal . x` over the box, rounded up.
            let top = normal
                .iter()
                .zip(&b)
                .filter(|(a, _)| **a != 0.0)
                .fold(Interval::ZERO, |s, (&a, x)| {
                    s + Interval::point(a) * Interval::new(x.lo, x.hi)
                })
                .hi();
            if top < *offset {
                return Some("a half-space misses the box its other parts bound".into());
            }
        }
    }
    None
}
