//! The checker: syntax tree to [`Model`], reporting every problem it can find in one run.
//!
//! Passes, in order: constants, declarations and the `discrete` item (so names can be used
//! before the line that declares them, except constants and lets, which are ordered); then
//! lets, equations and blocks in source order; then completeness checks (every state has a
//! drift or update equation and an initial set); then, on a model without errors, the `transform = auto` choices (they need the
//! whole drift), and the transforms' frames.

mod analysis;
mod blocks;
mod csv;
mod discrete;
mod lower;
mod matrix;
mod scope;
mod sets;

use std::path::Path;

pub(crate) use matrix::normalised;
use scope::{Scope, Symbol, VarKind};

use super::{Ball, Bounds, GoalSet, InitialSet, Model, UnsafeSet, Variable};
use crate::diagnostics::{has_errors, Diagnostic, Span};
use crate::ir::{ExprId, Pool, Table};
use crate::limits::{MAX_INPUTS, MAX_NOISES, MAX_STATES};
use crate::syntax::ast::{Ident, Init, Item, Spec, VarDecl};

/// Checks a parsed spec. `spec_dir` is the directory CSV paths are relative to.
/// Returns the model if there were no errors, and every diagnostic (errors and warnings).
pub fn check(spec: &Spec, spec_dir: &Path) -> (Option<Model>, Vec<Diagnostic>) {
    let mut c = Checker {
        spec_dir,
        diags: Vec::new(),
        scope: Scope::default(),
        pool: Pool::new(),
        states: Vec::new(),
        inputs: Vec::new(),
        noises: Vec::new(),
        tables: Vec::new(),
        drift: Vec::new(),
        drift_failed: Vec::new(),
        init_failed: Vec::new(),
        diffusion: Vec::new(),
        domain: Vec::new(),
        has_domain: false,
        boxes: Vec::new(),
        input_box: Vec::new(),
        balls: Vec::new(),
        unsafe_sets: Vec::new(),
        goals: Vec::new(),
        set_numbers: Vec::new(),
        analyses: Vec::new(),
        auto_transforms: Vec::new(),
        constants: Vec::new(),
        discrete: None,
        has_update: false,
        mixed: false,
    };
    c.declarations(spec);
    c.bodies(spec);
    c.completeness(spec);
    c.goal_windows();
    if !has_errors(&c.diags) {
        c.auto_transforms();
    }
    c.number_frames();
    let mut diags = std::mem::take(&mut c.diags);
    // A mistake inside a `for` body is reported once, not once per iteration.
    let mut seen = std::collections::HashSet::new();
    diags.retain(|d| seen.insert((d.message.clone(), d.span())));
    if has_errors(&diags) {
        return (None, diags);
    }
    let zero = c.pool.num(0.0);
    let model = Model {
        name: spec
            .model
            .as_ref()
            .map_or_else(String::new, |m| m.name.clone()),
        doc: spec.doc.clone(),
        time: c.time(),
        drift: c
            .drift
            .iter()
            .map(|d| d.as_ref().map_or(zero, |(e, _)| *e))
            .collect(),
        diffusion: c
            .diffusion
            .iter()
            .map(|row| row.clone().unwrap_or_else(|| vec![zero; c.noises.len()]))
            .collect(),
        pool: c.pool,
        states: c.states,
        inputs: c.inputs,
        input_box: c
            .input_box
            .iter()
            .map(|b| b.unwrap_or(Bounds::ENTIRE))
            .collect(),
        noises: c.noises,
        initial: InitialSet {
            boxes: c.boxes,
            balls: c.balls.into_iter().map(|(b, _)| b).collect(),
        },
        domain: c.domain,
        has_domain: c.has_domain,
        tables: c.tables,
        unsafe_sets: c.unsafe_sets.into_iter().map(|(u, _)| u).collect(),
        goals: c.goals.into_iter().map(|(g, _, _)| g).collect(),
        set_numbers: c.set_numbers,
        analyses: c.analyses,
        constants: c.constants,
    };
    (Some(model), diags)
}

/// State of one check run.
struct Checker<'a> {
    spec_dir: &'a Path,
    diags: Vec<Diagnostic>,
    scope: Scope,
    pool: Pool,
    states: Vec<Variable>,
    inputs: Vec<Variable>,
    noises: Vec<Variable>,
    tables: Vec<Table>,
    /// Per state: its drift and the span of the equation.
    drift: Vec<Option<(ExprId, Span)>>,
    /// Per state: an equation was written but had errors (so "no equation" is not reported).
    drift_failed: Vec<bool>,
    /// States whose written initial set had errors (so "no initial set" is not reported).
    init_failed: Vec<usize>,
    /// Per state: its diffusion row (one coefficient per noise channel).
    diffusion: Vec<Option<Vec<ExprId>>>,
    domain: Vec<Bounds>,
    has_domain: bool,
    /// Per state: the box or point written in its declaration.
    boxes: Vec<Option<Bounds>>,
    /// Per input: its range.
    input_box: Vec<Option<Bounds>>,
    /// Initial balls, with the `initial` block of each.
    balls: Vec<(Ball, Span)>,
    /// Unsafe sets, with the `unsafe` item of each.
    unsafe_sets: Vec<(UnsafeSet, Span)>,
    /// Goal sets, with the `goal` item of each and its window's span.
    goals: Vec<(GoalSet, Span, Option<Span>)>,
    /// The expressions of the moving sets' numbers (`Moving::number` indexes them).
    set_numbers: Vec<ExprId>,
    analyses: Vec<super::Analysis>,
    /// Analyses with `transform = auto` (index, span of `auto`), chosen after the checks.
    auto_transforms: Vec<(usize, Span)>,
    constants: Vec<(String, f64)>,
    /// The `discrete` item (the first, if given twice): the model is discrete time.
    discrete: Option<discrete::Discrete>,
    /// Whether the spec has an `update` block.
    has_update: bool,
    /// A continuous-time construct in a discrete-time model or the reverse was reported (so
    /// states are not also reported without equation).
    mixed: bool,
}

impl Checker<'_> {
    /// Records an error and returns `None` so callers can `return self.fail(...)`.
    fn fail<T>(&mut self, d: Diagnostic) -> Option<T> {
        self.diags.push(d);
        None
    }

    /// Reports the `what` (an analysis, an unsafe set) called `name` defined again, given
    /// `first`, the span of its first definition if there is one; `true` if it was.
    fn defined_twice(&mut self, what: &str, name: &Ident, first: Option<Span>) -> bool {
        let Some(first) = first else { return false };
        self.diags.push(
            Diagnostic::error(
                format!("{what} `{}` is defined twice", name.name),
                name.span.clone(),
                "again",
            )
            .with_label(first, "first defined here"),
        );
        true
    }

    /// Defines `name`, reporting a duplicate (with the earlier definition) or a builtin clash.
    fn define(&mut self, name: &Ident, sym: Symbol) -> bool {
        if scope::BUILTIN_NAMES.contains(&name.name.as_str())
            || lower::FUNCTION_NAMES.contains(&name.name.as_str())
        {
            self.diags.push(
                Diagnostic::error(
                    format!("`{}` is built in and cannot be redefined", name.name),
                    name.span.clone(),
                    "choose another name",
                )
                .with_note("built-in names: t (time), pi, and the function names"),
            );
            // Defined anyway, so its uses do not cascade into "undefined" errors.
        }
        if let Some((old, span)) = self.scope.get(&name.name) {
            let d = Diagnostic::error(
                format!("`{}` is defined twice", name.name),
                name.span.clone(),
                "defined again here",
            )
            .with_label(
                span.clone(),
                format!("first defined here as {}", old.describe()),
            )
            .with_help("rename one of them");
            self.diags.push(d);
            return false;
        }
        self.scope
            .symbols
            .insert(name.name.clone(), (sym, name.span.clone()));
        true
    }

    /// First pass: constants (in order), states, inputs, noise and tables.
    fn declarations(&mut self, spec: &Spec) {
        for item in &spec.items {
            match item {
                Item::Const { name, value, .. } => {
                    if let Some(v) = self.constant(value, &[]) {
                        if self.define(name, Symbol::Const(v)) {
                            self.constants.push((name.name.clone(), v));
                        }
                    }
                }
                Item::State(d) => self.declare(d, VarKind::State),
                Item::Input(d) => self.declare(d, VarKind::Input),
                Item::Noise(d) => self.declare(d, VarKind::Noise),
                Item::Discrete { body, span } => self.discrete_item(body, span),
                Item::Table {
                    name,
                    path,
                    path_span,
                    ..
                } => {
                    let full = self.spec_dir.join(path);
                    match csv::load(&name.name, &full, path) {
                        Ok(t) => {
                            let idx = self.tables.len() as u32;
                            if self.define(name, Symbol::Table(idx)) {
                                self.tables.push(t);
                            }
                        }
                        Err(e) => {
                            self.diags.push(
                                Diagnostic::error(
                                    format!("cannot load table `{}`", name.name),
                                    path_span.clone(),
                                    e,
                                )
                                .with_note(
                                    "a table is a CSV file with a header line; the first column is time",
                                ),
                            );
                            self.define(name, Symbol::Poisoned);
                        }
                    }
                }
                _ => {}
            }
        }
        let n = self.states.len();
        self.drift = vec![None; n];
        self.drift_failed = vec![false; n];
        self.diffusion = vec![None; n];
        self.domain = vec![Bounds::ENTIRE; n];
    }

    /// Declares a state, input or noise (family), with its initial set or range.
    fn declare(&mut self, d: &VarDecl, kind: VarKind) {
        let bounds = self.decl_bounds(d, kind);
        let init_failed = kind == VarKind::State && d.init.is_some() && bounds.is_none();
        let list = match kind {
            VarKind::State => &self.states,
            VarKind::Input => &self.inputs,
            VarKind::Noise => &self.noises,
        };
        let first = list.len() as u32;
        let (what, max) = match kind {
            VarKind::State => ("states", MAX_STATES),
            VarKind::Input => ("inputs", MAX_INPUTS),
            VarKind::Noise => ("noise channels", MAX_NOISES),
        };
        let room = max - list.len().min(max);
        let (sym, names) = match &d.family {
            None if room == 0 => {
                self.diags.push(Diagnostic::error(
                    format!("too many {what}"),
                    d.name.span.clone(),
                    format!("a model has at most {max} {what}"),
                ));
                self.define(&d.name, Symbol::Poisoned);
                return;
            }
            None => (Symbol::Var(kind, first), vec![d.name.name.clone()]),
            Some(range) => {
                let lo = self.integer(&range.lo, &[]);
                let hi = self.integer(&range.hi, &[]);
                let (Some(lo), Some(hi)) = (lo, hi) else {
                    self.define(&d.name, Symbol::Poisoned);
                    return;
                };
                let count = (i128::from(hi) - i128::from(lo) + 1).max(0);
                if count == 0 || count > room as i128 {
                    let diag = Diagnostic::error(
                        format!(
                            "the family `{}[{lo}..{hi}]` has {count} elements",
                            d.name.name
                        ),
                        range.span.clone(),
                        if count == 0 {
                            "must have at least 1 element".to_string()
                        } else {
                            format!("a model has at most {max} {what}")
                        },
                    );
                    self.diags.push(diag);
                    self.define(&d.name, Symbol::Poisoned);
                    return;
                }
                let names = (lo..=hi).map(|i| format!("{}[{i}]", d.name.name)).collect();
                (
                    Symbol::Family {
                        kind,
                        first,
                        lo,
                        hi,
                    },
                    names,
                )
            }
        };
        if !self.define(&d.name, sym) {
            return;
        }
        if init_failed {
            self.init_failed
                .extend(first as usize..first as usize + names.len());
        }
        let count = names.len();
        let vars = names.into_iter().map(|name| Variable {
            name,
            span: d.span.clone(),
        });
        match kind {
            VarKind::State => {
                self.states.extend(vars);
                self.boxes.extend(std::iter::repeat_n(bounds, count));
            }
            VarKind::Input => {
                self.inputs.extend(vars);
                self.input_box.extend(std::iter::repeat_n(bounds, count));
            }
            VarKind::Noise => self.noises.extend(vars),
        }
    }

    /// The box written in a declaration: the initial set for states, the range for inputs.
    fn decl_bounds(&mut self, d: &VarDecl, kind: VarKind) -> Option<Bounds> {
        match (&d.init, kind) {
            (None, VarKind::Input) => self.fail(
                Diagnostic::error(
                    format!("input `{}` has no range", d.name.name),
                    d.name.span.clone(),
                    "inputs must be bounded",
                )
                .with_help(format!("write `input {} in [LO, HI]`", d.name.name)),
            ),
            (None, _) => None,
            (Some(_), VarKind::Noise) => self.fail(
                Diagnostic::error(
                    format!(
                        "noise channel `{}` cannot have a value or range",
                        d.name.name
                    ),
                    d.span.clone(),
                    "a noise channel is a standard Wiener process",
                )
                .with_help("scale it in the diffusion block instead: `x: 0.1 * w`"),
            ),
            (Some(Init::In(set)), _) => self.interval(set, &[]),
            (Some(Init::Point(e)), _) => {
                let v = self.constant(e, &[])?;
                Some(Bounds { lo: v, hi: v })
            }
        }
    }

    /// Third pass: every state has a drift (or update) equation and an initial set.
    fn completeness(&mut self, spec: &Spec) {
        if spec.model.is_none() {
            return; // the parser already reported it; the rest would be noise
        }
        let equations = self.discrete_complete() && !self.mixed;
        let (word, example) = if self.is_discrete() {
            ("update", "")
        } else {
            ("drift", "'")
        };
        let mut in_ball = vec![false; self.states.len()];
        for (b, _) in &self.balls {
            for &s in &b.states {
                in_ball[s] = true;
            }
        }
        for (i, s) in self.states.iter().enumerate() {
            if equations && self.drift[i].is_none() && !self.drift_failed[i] {
                self.diags.push(
                    Diagnostic::error(
                        format!("state `{}` has no {word} equation", s.name),
                        s.span.clone(),
                        "declared here",
                    )
                    .with_help(format!(
                        "add `{}{example} = ...` to the {word} block",
                        s.name
                    )),
                );
            }
            if self.boxes[i].is_none() && !in_ball[i] && !self.init_failed.contains(&i) {
                self.diags.push(
                    Diagnostic::error(
                        format!("state `{}` has no initial set", s.name),
                        s.span.clone(),
                        "declared here",
                    )
                    .with_help(format!(
                        "write `state {} in [LO, HI]`, `state {} = VALUE`, or cover it by an `initial ball`",
                        s.name, s.name
                    )),
                );
            }
        }
        // A declaration with errors (a family too large) was already reported.
        let declared = spec.items.iter().any(|i| matches!(i, Item::State(_)));
        if self.states.is_empty() && !declared {
            let span = spec.model.as_ref().map_or(0..0, |m| m.span.clone());
            self.diags.push(
                Diagnostic::error(
                    "the model has no states",
                    span,
                    "declare at least one state",
                )
                .with_help("write `state x in [LO, HI]` and a drift equation `x' = ...`"),
            );
        }
    }
}
