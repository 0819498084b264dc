//! Discrete-time models: the `discrete { period = .. }` item, `update` blocks (the map: the
//! next state), the mixing of continuous and discrete constructs, and what the analyses of a
//! discrete-time model may ask (horizon and report step whole numbers of periods; the settings
//! of continuous time refused).

use super::lower::LoopEnv;
use super::scope::VarKind;
use super::sets::Fields;
use super::Checker;
use crate::diagnostics::{Diagnostic, Span};
use crate::model::Time;
use crate::syntax::ast::{Block, Expr, ExprKind, Ident, Stmt};
use reachc_core::decimal::time as decimal;

/// Relative tolerance of a horizon or report step taken as a whole number of periods.
const WHOLE_TOLERANCE: f64 = 1e-9;

/// An analysis setting of continuous time, refused in a discrete-time model.
struct Refusal {
    /// Its key.
    key: &'static str,
    /// The values refused (`None`: every value: the key itself is refused).
    value: Option<fn(&ExprKind) -> bool>,
    /// How the diagnostic names it.
    what: &'static str,
    /// Why it does not apply, or what to write instead.
    why: &'static str,
}

/// The settings of continuous time: the integrator's, the certified rates', the interval
/// method's transform, the first-order and split sets', the paper's radius rules, the mixed
/// inclusion and the per-state metrics.
const REFUSED: &[Refusal] = &[
    Refusal {
        key: "rate",
        value: None,
        what: "`rate`",
        why: "the rates are bounded on each step of the map at run time",
    },
    Refusal {
        key: "integrator",
        value: None,
        what: "`integrator`",
        why: "the map is evaluated, not integrated",
    },
    Refusal {
        key: "transform",
        value: None,
        what: "`transform`",
        why: "the interval method steps the map's boxes as they are",
    },
    Refusal {
        key: "first_order",
        value: None,
        what: "`first_order`",
        why: "there is no linearised flow",
    },
    Refusal {
        key: "split",
        value: None,
        what: "`split`",
        why: "the initial box is not cut",
    },
    Refusal {
        key: "radius",
        value: Some(|e| matches!(e, ExprKind::Call { func, .. } if func.name == "paper")),
        what: "`radius = paper(..)`",
        why: "the paper's rules bound an SDE's tube: use `radius = amgf`",
    },
    Refusal {
        key: "inclusion",
        value: Some(|e| matches!(e, ExprKind::Name(id) if id.name == "mixed")),
        what: "`inclusion = mixed`",
        why: "use `inclusion = natural` or `jacobian`",
    },
    Refusal {
        key: "metric",
        value: Some(|e| matches!(e, ExprKind::Call { func, .. } if func.name == "auto")),
        what: "`metric = auto(states = [..])`",
        why: "use `metric = auto`, `identity` or a matrix",
    },
];

/// The `discrete` item of a model, as checked.
#[derive(Clone, Debug)]
pub(super) struct Discrete {
    /// The item, from its keyword to its `}`.
    pub span: Span,
    /// Its period, `None` if it had errors (reported).
    pub period: Option<f64>,
}

impl Discrete {
    /// The `discrete` keyword (the primary place of the item in a diagnostic).
    pub fn keyword(&self) -> Span {
        keyword(&self.span, "discrete")
    }
}

/// The span of `word` (an item's keyword, a field's key) at the start of `span`.
fn keyword(span: &Span, word: &str) -> Span {
    span.start..(span.start + word.len()).min(span.end)
}

impl Checker<'_> {
    /// `discrete { period = EXPR }` (first pass, in source order: the period may use the
    /// constants above it).
    pub(super) fn discrete_item(&mut self, body: &Block, span: &Span) {
        if let Some(first) = &self.discrete {
            let first = first.keyword();
            self.diags.push(
                Diagnostic::error(
                    "`discrete` is given twice",
                    keyword(span, "discrete"),
                    "again",
                )
                .with_label(first, "first given here")
                .with_help("a model has one period: remove one of them"),
            );
            return;
        }
        let f = self.fields(body, &["period"], "`discrete`");
        let period = self
            .required(&f, "period", span, "`discrete`")
            .and_then(|e| self.period(e));
        self.discrete = Some(Discrete {
            span: span.clone(),
            period,
        });
    }

    /// The period: a finite positive constant.
    fn period(&mut self, e: &Expr) -> Option<f64> {
        let v = self.constant(e, &[])?;
        if v.is_finite() && v > 0.0 {
            return Some(v);
        }
        self.fail(
            Diagnostic::error(
                format!("the period must be finite and positive, but it is {v}"),
                e.span.clone(),
                "out of range",
            )
            .with_help("the period is the time between two steps of the map, e.g. `period = 0.1`"),
        )
    }

    /// Whether the model is discrete time (a `discrete` item, even one with errors).
    pub(super) fn is_discrete(&self) -> bool {
        self.discrete.is_some()
    }

    /// The model's time: discrete with the period checked (a period with errors was reported,
    /// and no model is built), else continuous.
    pub(super) fn time(&self) -> Time {
        match &self.discrete {
            Some(Discrete {
                period: Some(period),
                ..
            }) => Time::Discrete { period: *period },
            _ => Time::Continuous,
        }
    }

    /// What a state's equation is called: `drift` or, in a discrete-time model, `update`.
    pub(super) fn equation_word(&self) -> &'static str {
        if self.is_discrete() {
            "update"
        } else {
            "drift"
        }
    }

    /// An `update` block (second pass). In a discrete-time model its equations define the map;
    /// in a continuous-time one it is an error (its lets are still defined, so that their uses
    /// do not cascade into further errors).
    pub(super) fn update_block(&mut self, body: &Block, span: &Span, budget: &mut usize) {
        self.has_update = true;
        let at = keyword(span, "update");
        if !self.is_discrete() {
            self.mixed = true;
            self.diags.push(
                Diagnostic::error(
                    "`update` needs a discrete-time model",
                    at.clone(),
                    "the next state of a discrete-time model",
                )
                .with_help(
                    "add `discrete { period = .. }` (the time between two steps); a \
                     continuous-time model gives `drift { x' = .. }`",
                ),
            );
            return self.walk(&body.stmts, "in update", true, budget, &mut |_, _, _| {});
        }
        self.walk(&body.stmts, "in update", true, budget, &mut |c, s, env| {
            c.update_stmt(s, env, &at)
        });
    }

    /// A `drift` item (`span`, from its keyword) of a discrete-time model: an error at its
    /// keyword and the `discrete` item's (its lets are still defined).
    pub(super) fn drift_in_discrete(&mut self, body: &Block, span: &Span, budget: &mut usize) {
        let Some(discrete) = &self.discrete else {
            return;
        };
        let at = discrete.keyword();
        self.mixed = true;
        self.diags.push(
            Diagnostic::error(
                "a discrete-time model has no `drift`",
                keyword(span, "drift"),
                "a drift (continuous time)",
            )
            .with_label(at, "the model is discrete time")
            .with_help(
                "a discrete-time model gives `update { x = .. }`: the next state, not its \
                 derivative",
            ),
        );
        self.walk(&body.stmts, "in drift", true, budget, &mut |_, _, _| {});
    }

    /// A statement of `update` (whose keyword is `at`) after unrolling.
    fn update_stmt(&mut self, s: &Stmt, env: &LoopEnv, at: &Span) {
        match s {
            Stmt::Update { target, rhs, span } => self.equation(target, rhs, span, env),
            Stmt::Equation { target, span, .. } => {
                let index = if target.index.is_some() { "[..]" } else { "" };
                self.diags.push(
                    Diagnostic::error(
                        "a drift equation is not allowed in update",
                        span.clone(),
                        "a derivative",
                    )
                    .with_label(at.clone(), "in this discrete-time update")
                    .with_help(format!(
                        "in discrete time write the next value `{}{index} = ..`",
                        target.name.name
                    )),
                );
                // Reported here: the state must not also be called "without equation".
                if let Some(i) = self.target(target, VarKind::State, env) {
                    self.drift_failed[i] = true;
                }
            }
            _ => self.unexpected(
                s,
                "in update",
                "update holds next values like `x = 0.9 * x`, `let` and `for`",
            ),
        }
    }

    /// The completeness of the equations of a discrete-time model: it has an `update` block.
    /// `false` when it has none (reported), so that no state is reported without equation.
    pub(super) fn discrete_complete(&mut self) -> bool {
        let Some(discrete) = &self.discrete else {
            return true;
        };
        if self.has_update {
            return true;
        }
        let at = discrete.keyword();
        self.diags.push(
            Diagnostic::error(
                "a discrete-time model needs an `update` block",
                at,
                "discrete time declared here",
            )
            .with_help("give the next state, one equation per state: `update { x = 0.9 * x }`"),
        );
        false
    }

    /// Reports the analysis settings of continuous time in a discrete-time model (keys, and
    /// the values `radius = paper(..)`, `inclusion = mixed`, `metric = auto(states = [..])`),
    /// each at its key, and removes them from `f` so that the rest of the check sees the
    /// defaults. `true` if any was given.
    pub(super) fn refuse_continuous(&mut self, f: &mut Fields) -> bool {
        let mut refused = false;
        for r in REFUSED {
            let Some((e, span)) = f.get(r.key) else {
                continue;
            };
            if r.value.is_some_and(|refuse| !refuse(&e.kind)) {
                continue;
            }
            self.diags.push(
                Diagnostic::error(
                    format!("{} does not apply to discrete-time models", r.what),
                    keyword(span, r.key),
                    "continuous time only",
                )
                .with_help(format!(
                    "{} does not apply to discrete-time models ({}): remove it",
                    r.what, r.why
                )),
            );
            f.remove(r.key);
            refused = true;
        }
        refused
    }

    /// The horizon and report step of a discrete-time analysis: whole numbers `K >= 1` and
    /// `1 <= j <= K` of periods (to a relative [`WHOLE_TOLERANCE`]), stored as exactly
    /// `K * period` and `j * period`; the step defaults to one period.
    pub(super) fn discrete_times(
        &mut self,
        f: &Fields,
        name: &Ident,
        period: f64,
    ) -> (Option<f64>, Option<f64>) {
        let horizon = self.horizon(f, name).and_then(|h| {
            let (e, _) = f.get("horizon")?;
            self.periods(e, h, period, "horizon", u64::MAX)
        });
        let Some(horizon) = horizon else {
            return (None, None);
        };
        let last = (horizon / period).round() as u64;
        let step = match f.get("step") {
            None => Some(period),
            Some((e, _)) => self
                .number(f, "step", period, |s| {
                    (s > 0.0).then_some(()).ok_or("the step must be positive")
                })
                .and_then(|s| self.periods(e, s, period, "step", last)),
        };
        let step = step.filter(|&s| self.report_steps(f, horizon, s));
        (Some(horizon), step)
    }

    /// `value` (written at `e`, the `key`'s) as a whole number `1..=most` of periods, times the
    /// period; or a diagnostic naming the nearest whole numbers.
    fn periods(&mut self, e: &Expr, value: f64, period: f64, key: &str, most: u64) -> Option<f64> {
        let ratio = value / period;
        let k = ratio.round();
        let whole = (ratio - k).abs() <= WHOLE_TOLERANCE * k.max(1.0);
        if whole && k >= 1.0 && k <= most as f64 {
            return Some(k * period);
        }
        let candidates: Vec<f64> = if k > most as f64 {
            vec![most as f64]
        } else {
            let low = ratio.floor().max(1.0);
            let high = ratio.ceil().max(1.0);
            if low == high {
                vec![low]
            } else {
                vec![low, high]
            }
        };
        let written: Vec<String> = candidates
            .iter()
            .map(|&k| {
                let s = if k == 1.0 { "" } else { "s" };
                format!("`{key} = {}` ({k} period{s})", decimal(k * period))
            })
            .collect();
        let (message, label) = if k > most as f64 {
            (
                format!(
                    "the report step is {} periods, longer than the horizon's {most}",
                    decimal(ratio)
                ),
                "longer than the horizon",
            )
        } else {
            (
                format!(
                    "the {key} of a discrete-time model is a whole number of periods ({}), but \
                     it is {value} ({} periods)",
                    decimal(period),
                    decimal(ratio)
                ),
                "not a whole number of periods",
            )
        };
        self.fail(
            Diagnostic::error(message, e.span.clone(), label)
                .with_help(format!("write {}", written.join(" or "))),
        )
    }
}

#[cfg(test)]
mod tests;
