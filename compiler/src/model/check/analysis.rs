//! `analysis NAME { key = value ... }` blocks.

use super::matrix;
use super::scope::did_you_mean;
use super::sets::Fields;
use super::Checker;
use crate::analysis::{choose_transform, jacobian_at, MAX_AUTO_STATES};
use crate::diagnostics::{Diagnostic, Span};
use crate::ir::ExprId;
use crate::limits::{MAX_REPORT_STEPS, MIN_REPORT_STEP};
use crate::model::{
    Analysis, AnalysisSpec, Bounds, Guarantee, Inclusion, Integrator, Method,
    MetricChoice as Metric, RadiusRule, Rate, Split, Transform, AUTO_PIECES, MAX_PIECES,
};
use crate::syntax::ast::{Arg, Block, Expr, ExprKind, Ident};
use reachc_core::engine::Setting;
use reachc_core::model::{AutoFit, InitialSet, TransformSource};
use reachc_core::Interval;

/// Most sample paths of an empirical rate estimate (they are all kept in memory).
const MAX_EMPIRICAL_PATHS: f64 = 20_000.0;

/// Most metrics of `metric = auto(states = [..])` (each costs a run; delta is shared).
const MAX_METRICS: usize = 8;
/// What `transform = ...` says: `auto` is resolved once the whole drift is known.
enum TransformKey {
    Given(Transform),
    Auto,
}

/// The `n x n` identity by rows.
fn identity_rows(n: usize) -> Vec<Vec<f64>> {
    (0..n)
        .map(|i| (0..n).map(|j| f64::from(u8::from(i == j))).collect())
        .collect()
}

const KEYS: &[&str] = &[
    "method",
    "delta",
    "horizon",
    "step",
    "metric",
    "radius",
    "rate",
    "inclusion",
    "integrator",
    "guarantee",
    "transform",
    "outputs",
    "first_order",
    "split",
];

impl Checker<'_> {
    pub(super) fn analysis(&mut self, name: &Ident, body: &Block, span: Span) {
        let first = self.analyses.iter().find(|a| a.spec.name == name.name);
        if self.defined_twice("analysis", name, first.map(|a| a.span.clone())) {
            return;
        }
        let mut f = self.fields(body, KEYS, "an analysis");
        // A discrete-time model: its settings of continuous time are refused (and dropped, so
        // that the rest is checked with the defaults); its times are whole numbers of periods.
        let discrete = self.discrete.as_ref().map(|d| d.period);
        let refused = discrete.is_some() && self.refuse_continuous(&mut f);
        let n = self.states.len();
        let method = self.choice(
            &f,
            "method",
            &[
                ("contraction", Method::Contraction),
                ("interval", Method::Interval),
            ],
            Method::Contraction,
        );
        let inclusion = self.choice(
            &f,
            "inclusion",
            &[
                ("natural", Inclusion::Natural),
                ("jacobian", Inclusion::Jacobian),
                ("mixed", Inclusion::Mixed),
            ],
            Inclusion::Jacobian,
        );
        let integrator = self.choice(
            &f,
            "integrator",
            &[
                ("validated", Integrator::Validated),
                ("rk4", Integrator::Rk4),
                ("euler", Integrator::Euler),
            ],
            Integrator::Validated,
        );
        let guarantee = self.choice(
            &f,
            "guarantee",
            &[
                ("uniform", Guarantee::Uniform),
                ("pointwise", Guarantee::Pointwise),
            ],
            Guarantee::Uniform,
        );
        let first_order = self.choice(&f, "first_order", &[("on", true), ("off", false)], true);
        let delta = self.number(&f, "delta", 1e-3, |d| {
            (d > 0.0 && d < 1.0)
                .then_some(())
                .ok_or("delta must be in (0, 1)")
        });
        let (horizon, step) = match discrete {
            None => self.continuous_times(&f, name),
            Some(Some(period)) => self.discrete_times(&f, name, period),
            // The period had errors (reported): no times to check against it.
            Some(None) => (None, None),
        };
        let metric = match f.get("metric") {
            None => Some(Metric::Identity),
            Some((e, _)) => match &e.kind {
                ExprKind::Name(id) if id.name == "identity" => Some(Metric::Identity),
                ExprKind::Name(id) if id.name == "auto" => Some(Metric::Auto),
                ExprKind::Call { func, args } if func.name == "auto" => self.per_state(e, args),
                ExprKind::List(_) => self
                    .square(e, n, "metric", true)
                    .map(|m| Metric::Matrix(m.concat())),
                _ => self.fail(Diagnostic::error(
                    "unknown metric",
                    e.span.clone(),
                    "expected `identity`, `auto`, `auto(states = [..])` or a matrix",
                )),
            },
        };
        let radius = match f.get("radius") {
            None => Some(RadiusRule::Amgf),
            Some((e, _)) => self.radius_rule(e),
        };
        // Local rates need the time-uniform tube; a pointwise analysis defaults to the global
        // rate.
        let rate = match f.get("rate") {
            None if guarantee == Some(Guarantee::Pointwise) => Some(Rate::Global),
            None => Some(Rate::Local),
            Some((e, _)) => self.rate(e),
        };
        let transform = match f.get("transform") {
            None => Some(None),
            Some((e, _)) => self.transform(e, n).map(Some),
        };
        let outputs = match f.get("outputs") {
            None => Some((0..n).collect()),
            Some((e, _)) => self.state_list(e),
        };
        let (
            Some(method),
            Some(inclusion),
            Some(integrator),
            Some(guarantee),
            Some(delta),
            Some(horizon),
            Some(step),
        ) = (
            method, inclusion, integrator, guarantee, delta, horizon, step,
        )
        else {
            return;
        };
        let split = match f.get("split") {
            None => Some(Split::Off),
            Some((e, _)) => self.split(e, n),
        };
        let (
            Some(metric),
            Some(radius),
            Some(rate),
            Some(transform),
            Some(outputs),
            Some(first_order),
            Some(split),
        ) = (metric, radius, rate, transform, outputs, first_order, split)
        else {
            return;
        };
        if refused {
            return;
        }
        // A discrete-time analysis: the settings of continuous time are fixed (the engine
        // bounds the map's factors per step, locally).
        let (rate, integrator, first_order) = if discrete.is_some() {
            (Rate::Local, Integrator::default(), false)
        } else {
            (rate, integrator, first_order)
        };
        if let (Rate::Local, Guarantee::Pointwise, Some((e, _))) = (rate, guarantee, f.get("rate"))
        {
            self.fail::<()>(
                Diagnostic::error(
                    "local rates need `guarantee = uniform`",
                    e.span.clone(),
                    "with a pointwise guarantee",
                )
                .with_help(
                    "the proof that the process never leaves the regions of the local rates uses \
                     the time-uniform tube: remove `guarantee = pointwise`, or write \
                     `rate = global`",
                ),
            );
            return;
        }
        if let (Rate::Empirical { .. }, Some((e, _))) = (rate, f.get("rate")) {
            let conflict = if method != Method::Contraction {
                Some((
                    "needs `method = contraction`",
                    "the interval method uses a certified rate (`local` or `global`)",
                ))
            } else if matches!(metric, Metric::Auto | Metric::PerState(_)) {
                Some((
                    "cannot be combined with `metric = auto`",
                    "the metric is synthesised from the certified (global) rate; give \
                     `metric = identity` or a matrix",
                ))
            } else {
                None
            };
            if let Some((what, help)) = conflict {
                self.fail::<()>(
                    Diagnostic::error(
                        format!("`rate = {}` {what}", rate.name()),
                        e.span.clone(),
                        "here",
                    )
                    .with_help(help),
                );
                return;
            }
        }
        // The time-uniform tube is built on the averaged-MGF bound (method.md section 8.2).
        if let (Guarantee::Uniform, RadiusRule::Paper(_) | RadiusRule::PaperOptimal, Some((e, _))) =
            (guarantee, radius, f.get("radius"))
        {
            self.fail::<()>(
                Diagnostic::error(
                    "the paper's radius rule holds at each time separately",
                    e.span.clone(),
                    "a pointwise rule",
                )
                .with_help(
                    "add `guarantee = pointwise` (the paper's semantics), or use `radius = amgf` \
                     for a tube that holds at all times at once",
                ),
            );
            return;
        }
        if let (Some(written), Some((e, _))) = (&transform, f.get("transform")) {
            if method != Method::Interval {
                self.fail::<()>(
                    Diagnostic::error(
                        "a coordinate transform needs `method = interval`",
                        e.span.clone(),
                        "the contraction method does not use it",
                    )
                    .with_help(
                        "remove `transform`, or set `method = interval` (the metric plays its \
                         role for the contraction method)",
                    ),
                );
                return;
            }
            if let TransformKey::Auto = written {
                // Chosen once the whole drift is known (`auto_transforms`).
                self.auto_transforms
                    .push((self.analyses.len(), e.span.clone()));
            }
        }
        let transform = match transform {
            Some(TransformKey::Given(t)) => Some(t),
            Some(TransformKey::Auto) | None => None,
        };
        self.analyses.push(Analysis {
            spec: AnalysisSpec {
                name: name.name.clone(),
                method,
                delta,
                horizon,
                step,
                metric,
                radius,
                rate,
                inclusion,
                integrator,
                guarantee,
                transform,
                outputs,
                first_order,
                split,
            },
            span,
            name_span: name.span.clone(),
            settings: Setting::ALL
                .into_iter()
                .filter_map(|s| f.get(s.key()).map(|(_, span)| (s, span.clone())))
                .collect(),
        });
    }

    /// The horizon and report step of a continuous-time analysis: the step in
    /// `(0, horizon]`, `horizon / 100` by default.
    fn continuous_times(&mut self, f: &Fields, name: &Ident) -> (Option<f64>, Option<f64>) {
        let horizon = self.horizon(f, name);
        let step = horizon.and_then(|h| {
            self.number(f, "step", h / 100.0, |s| {
                if s <= 0.0 {
                    Err("the step must be positive")
                } else if s > h {
                    Err("the step is larger than the horizon")
                } else {
                    Ok(())
                }
            })
        });
        let step = step.and_then(|s| self.report_steps(f, horizon?, s).then_some(s));
        (horizon, step)
    }

    /// The horizon: required, positive.
    pub(super) fn horizon(&mut self, f: &Fields, name: &Ident) -> Option<f64> {
        match f.get("horizon") {
            Some(_) => self.number(f, "horizon", 0.0, |h| {
                (h > 0.0)
                    .then_some(())
                    .ok_or("the horizon must be positive")
            }),
            None => self.fail(
                Diagnostic::error(
                    format!("analysis `{}` has no horizon", name.name),
                    name.span.clone(),
                    "needs `horizon = ...`",
                )
                .with_help("add e.g. `horizon = 4` (the final time)"),
            ),
        }
    }

    /// A keyword value from `options`, or `default` if the key is absent.
    fn choice<T: Copy>(
        &mut self,
        f: &Fields,
        key: &str,
        options: &[(&str, T)],
        default: T,
    ) -> Option<T> {
        let Some((e, _)) = f.get(key) else {
            return Some(default);
        };
        let words: Vec<&str> = options.iter().map(|(w, _)| *w).collect();
        if let ExprKind::Name(id) = &e.kind {
            if let Some((_, v)) = options.iter().find(|(w, _)| *w == id.name) {
                return Some(*v);
            }
            let mut d = Diagnostic::error(
                format!("unknown {key} `{}`", id.name),
                id.span.clone(),
                format!("expected {}", words.join(", ")),
            );
            if let Some(s) = did_you_mean(&id.name, words.iter().copied()) {
                d = d.with_help(format!("did you mean `{s}`?"));
            }
            return self.fail(d);
        }
        self.fail(Diagnostic::error(
            format!("expected a {key}"),
            e.span.clone(),
            format!("expected {}", words.join(", ")),
        ))
    }

    /// A constant field checked by `valid`, or `default` if absent.
    pub(super) fn number(
        &mut self,
        f: &Fields,
        key: &str,
        default: f64,
        valid: impl Fn(f64) -> Result<(), &'static str>,
    ) -> Option<f64> {
        let Some((e, _)) = f.get(key) else {
            return Some(default);
        };
        let v = self.constant(e, &[])?;
        match valid(v) {
            Ok(()) => Some(v),
            Err(msg) => self.fail(Diagnostic::error(
                format!("{msg}, but it is {v}"),
                e.span.clone(),
                "out of range",
            )),
        }
    }

    /// Whether `horizon / step` is within [`MAX_REPORT_STEPS`] (reported at `step`, or at
    /// `horizon` when the step is the default): every report step is kept in the result.
    /// Also whether the step is at least [`MIN_REPORT_STEP`].
    pub(super) fn report_steps(&mut self, f: &Fields, horizon: f64, step: f64) -> bool {
        let steps = horizon / step;
        let (message, label, help) = if step < MIN_REPORT_STEP {
            (
                format!("the report step is {step:e}; at least {MIN_REPORT_STEP:e}"),
                "report step too short",
                "the integrators subdivide a report step down to a millionth of it, which must \
                 stay a normal floating-point number: change the unit of time",
            )
        } else if steps > MAX_REPORT_STEPS {
            (
                format!("{steps:.3e} report steps (horizon / step); at most {MAX_REPORT_STEPS:e}"),
                "too many report steps",
                "every report step is kept in the result: use a larger step or a shorter horizon",
            )
        } else {
            return true;
        };
        let Some((e, _)) = f.get("step").or_else(|| f.get("horizon")) else {
            return true; // unreachable: the horizon is given when it is positive
        };
        self.diags
            .push(Diagnostic::error(message, e.span.clone(), label).with_help(help));
        false
    }

    /// A coordinate transform: `auto`, or an invertible n x n matrix (with its inverse; its
    /// frame is numbered by `number_frames`).
    fn transform(&mut self, e: &Expr, n: usize) -> Option<TransformKey> {
        match &e.kind {
            ExprKind::Name(id) if id.name == "auto" => {
                if n > MAX_AUTO_STATES {
                    return self.fail(
                        Diagnostic::error(
                            format!(
                                "`transform = auto` handles at most {MAX_AUTO_STATES} states, \
                                 this model has {n}"
                            ),
                            e.span.clone(),
                            "too many states",
                        )
                        .with_help(
                            "give the transform as a matrix, or remove it (the transformed \
                             drift of a chosen T is dense: n^2 terms)",
                        ),
                    );
                }
                Some(TransformKey::Auto)
            }
            ExprKind::List(_) => {
                let matrix = self.square(e, n, "transform", false)?;
                // `square` checked invertibility by the same elimination, so this succeeds.
                let inverse = matrix::inverse(&matrix).ok()?.concat();
                Some(TransformKey::Given(Transform {
                    matrix: matrix.concat(),
                    inverse,
                    frame: 0,
                    source: TransformSource::Given,
                }))
            }
            _ => self.fail(Diagnostic::error(
                "unknown transform",
                e.span.clone(),
                "expected `auto` or a matrix",
            )),
        }
    }

    /// Chooses the transform of every `transform = auto` analysis: one `T` for all of them,
    /// from the drift's Jacobian at the initial set's centre (inputs at the input box's
    /// centre, `t = 0`). Runs after the checks, on a model without errors.
    pub(super) fn auto_transforms(&mut self) {
        let pending = std::mem::take(&mut self.auto_transforms);
        if pending.is_empty() {
            return;
        }
        let n = self.states.len();
        let (matrix, fit) = match self.centre_jacobian() {
            Ok(a) => {
                let chosen = choose_transform(&a);
                let rows: Vec<Vec<f64>> = chosen
                    .matrix
                    .row_iter()
                    .map(|r| r.iter().copied().collect())
                    .collect();
                let fit = AutoFit::LogNorm {
                    chosen: chosen.log_norm,
                    identity: chosen.identity_log_norm,
                };
                (rows, fit)
            }
            Err(why) => {
                for (_, span) in &pending {
                    self.diags.push(
                        Diagnostic::warning(
                            "`transform = auto` falls back to the identity",
                            span.clone(),
                            "no Jacobian to choose T from",
                        )
                        .with_note(why.clone()),
                    );
                }
                (identity_rows(n), AutoFit::NonFiniteJacobian)
            }
        };
        // The chooser caps cond(T) far below the checker's singularity threshold; should the
        // elimination still refuse T, the identity is what nothing beating it gives.
        let (matrix, inverse, fit) = match matrix::inverse(&matrix) {
            Ok(inverse) => (matrix, inverse, fit),
            Err(_) => {
                let fit = match fit {
                    AutoFit::LogNorm { identity, .. } => AutoFit::LogNorm {
                        chosen: identity,
                        identity,
                    },
                    AutoFit::NonFiniteJacobian => AutoFit::NonFiniteJacobian,
                };
                (identity_rows(n), identity_rows(n), fit)
            }
        };
        let transform = Transform {
            matrix: matrix.concat(),
            inverse: inverse.concat(),
            frame: 0,
            source: TransformSource::Auto(fit),
        };
        for (index, _) in pending {
            if let Some(a) = self.analyses.get_mut(index) {
                a.spec.transform = Some(transform.clone());
            }
        }
    }

    /// `D_x f` at the initial set's centre, the inputs' centre and `t = 0`, or why not.
    fn centre_jacobian(&mut self) -> Result<nalgebra::DMatrix<f64>, String> {
        let initial = InitialSet {
            boxes: self.boxes.clone(),
            balls: self.balls.iter().map(|(b, _)| b.clone()).collect(),
        };
        let centre = |b: &Bounds| Interval::new(b.lo, b.hi).mid();
        let x: Vec<f64> = initial
            .bounding_box()
            .map_err(|e| e.to_string())?
            .iter()
            .map(centre)
            .collect();
        let u: Vec<f64> = self
            .input_box
            .iter()
            .map(|b| b.as_ref().map_or(0.0, centre))
            .collect();
        let zero = self.pool.num(0.0);
        let drift: Vec<ExprId> = self
            .drift
            .iter()
            .map(|d| d.as_ref().map_or(zero, |(e, _)| *e))
            .collect();
        let a = jacobian_at(&mut self.pool, &drift, &self.tables, (&x, &u, 0.0));
        match a.iter().position(|v| !v.is_finite()) {
            None => Ok(a),
            Some(k) => {
                let (i, j) = (k % x.len(), k / x.len());
                Err(format!(
                    "d {}' / d {} = {} at the centre of the initial set {x:?} (inputs {u:?}, \
                     t = 0)",
                    self.states[i].name,
                    self.states[j].name,
                    a[(i, j)]
                ))
            }
        }
    }

    /// Numbers the frames of the coordinate transforms: analyses with the same `T` share one
    /// (the transformed system backends generate once), in order of first use.
    pub(super) fn number_frames(&mut self) {
        let mut frames: Vec<Vec<f64>> = Vec::new();
        for t in self
            .analyses
            .iter_mut()
            .filter_map(|a| a.spec.transform.as_mut())
        {
            t.frame = match frames.iter().position(|m| *m == t.matrix) {
                Some(k) => k,
                None => {
                    frames.push(t.matrix.clone());
                    frames.len() - 1
                }
            };
        }
    }

    /// An n x n matrix, symmetric positive definite (`spd`: an analysis metric, returned
    /// normalised by a power of two) or non-singular.
    fn square(&mut self, e: &Expr, n: usize, key: &str, spd: bool) -> Option<Vec<Vec<f64>>> {
        let m = self.matrix(e)?;
        let m = if spd { matrix::normalised(m) } else { m };
        let check = matrix::check_square(&m, n).and_then(|()| {
            if spd {
                matrix::check_spd(&m)
            } else {
                matrix::inverse(&m).map(drop)
            }
        });
        match check {
            Ok(()) => Some(m),
            Err(err) => {
                let need = if spd {
                    "symmetric positive definite"
                } else {
                    "square and invertible"
                };
                self.fail(
                    Diagnostic::error(format!("bad {key}: {err}"), e.span.clone(), "here")
                        .with_help(format!(
                            "the {key} must be {need}, {n} x {n} (one row per state)"
                        )),
                )
            }
        }
    }

    /// `split = [k1, ..., kn]`: one whole count of at least 1 per state, at most
    /// [`MAX_PIECES`] pieces in all (method.md 8.11).
    fn split(&mut self, e: &Expr, n: usize) -> Option<Split> {
        match &e.kind {
            ExprKind::Name(id) if id.name == "auto" => Some(Split::Auto {
                pieces: AUTO_PIECES,
                seconds: None,
            }),
            ExprKind::Call { func, args } if func.name == "auto" => self.auto_split(e, args),
            ExprKind::List(items) => self.split_counts(e, items, n),
            _ => self.fail(
                Diagnostic::error(
                    "unknown split",
                    e.span.clone(),
                    "expected a list of counts or `auto`",
                )
                .with_help(format!(
                    "write one count per state ({n}), e.g. `split = [{}]`: state i's initial \
                     range is cut into that many equal parts; or `split = auto` (at most \
                     {AUTO_PIECES} pieces, `auto(pieces = N, seconds = S)` for other budgets)",
                    vec!["2"; n].join(", ")
                )),
            ),
        }
    }

    /// `split = [k1, ..., kn]` (the list `items` of `e`).
    fn split_counts(&mut self, e: &Expr, items: &[Expr], n: usize) -> Option<Split> {
        if items.len() != n {
            return self.fail(
                Diagnostic::error(
                    format!(
                        "split has {} count{}, the model {n} state{}",
                        items.len(),
                        if items.len() == 1 { "" } else { "s" },
                        if n == 1 { "" } else { "s" }
                    ),
                    e.span.clone(),
                    "one count per state",
                )
                .with_help("in the order the states are declared; 1 leaves a state whole"),
            );
        }
        let counts = items
            .iter()
            .map(|item| {
                self.piece_count(
                    item,
                    "a split count",
                    "1 leaves the state's range whole, k cuts it into k equal parts",
                )
            })
            .collect::<Option<Vec<_>>>()?;
        let split = Split::Counts(counts);
        if split.pieces() > MAX_PIECES {
            return self.fail(
                Diagnostic::error(
                    format!("split into {} pieces; at most {MAX_PIECES}", split.pieces()),
                    e.span.clone(),
                    "too many pieces",
                )
                .with_help("each piece is a full run of the analysis: use smaller counts"),
            );
        }
        Some(split)
    }

    /// `split = auto(pieces = N, seconds = S)`, either argument optional, each at most once: a
    /// budget of 1 to [`MAX_PIECES`] pieces (default [`AUTO_PIECES`]) and a whole number of
    /// seconds after which no round of cuts starts.
    fn auto_split(&mut self, e: &Expr, args: &[Arg]) -> Option<Split> {
        let (mut pieces, mut seconds) = (None, None);
        for arg in args {
            let name = arg.name.as_ref().map(|n| n.name.as_str());
            let problem = match name {
                Some("pieces") if pieces.is_some() => Some("given twice"),
                Some("seconds") if seconds.is_some() => Some("given twice"),
                Some("pieces" | "seconds") => None,
                _ => Some("expected `pieces = N` or `seconds = S`"),
            };
            if let Some(problem) = problem {
                return self.fail(
                    Diagnostic::error("bad `auto` split", arg.value.span.clone(), problem)
                        .with_help(
                            "`auto` takes a budget of pieces and one of time, each at most \
                             once: `auto(pieces = 16, seconds = 30)`",
                        ),
                );
            }
            if name == Some("pieces") {
                pieces = Some(self.piece_count(
                    &arg.value,
                    "the pieces of an automatic split",
                    "each piece is a full run of the analysis",
                )?);
            } else {
                seconds = Some(self.seconds(&arg.value)?);
            }
        }
        if args.is_empty() {
            return self.fail(
                Diagnostic::error(
                    "bad `auto` split",
                    e.span.clone(),
                    "expected `pieces = N` or `seconds = S`",
                )
                .with_help("write `split = auto` or `split = auto(pieces = 16, seconds = 30)`"),
            );
        }
        Some(Split::Auto {
            pieces: pieces.unwrap_or(AUTO_PIECES),
            seconds,
        })
    }

    /// The time budget of an automatic split: a whole number of seconds from 0 to a year.
    fn seconds(&mut self, e: &Expr) -> Option<u64> {
        const YEAR: f64 = 365.0 * 86400.0;
        let v = self.constant(e, &[])?;
        if v >= 0.0 && v.fract() == 0.0 && v <= YEAR {
            return Some(v as u64);
        }
        self.fail(
            Diagnostic::error(
                format!(
                    "the time budget of an automatic split must be a whole number of seconds \
                     from 0 to {YEAR}, but it is {v}"
                ),
                e.span.clone(),
                "not a number of seconds",
            )
            .with_help(
                "no round of cuts starts after it; the whole box always runs: `seconds = 30`",
            ),
        )
    }

    /// A whole number from 1 to [`MAX_PIECES`] (`what` names it in the diagnostic).
    fn piece_count(&mut self, e: &Expr, what: &str, help: &str) -> Option<usize> {
        let v = self.constant(e, &[])?;
        if v >= 1.0 && v.fract() == 0.0 && v <= MAX_PIECES as f64 {
            return Some(v as usize);
        }
        self.fail(
            Diagnostic::error(
                format!("{what} must be a whole number from 1 to {MAX_PIECES}, but it is {v}"),
                e.span.clone(),
                "not a count",
            )
            .with_help(help),
        )
    }

    /// `auto(states = [a, b, ..])`: one metric per named state (at most
    /// [`MAX_METRICS`]).
    fn per_state(&mut self, e: &Expr, args: &[Arg]) -> Option<Metric> {
        let help = "write e.g. `auto(states = [theta, omega])`: one metric per named state";
        let [a] = args else {
            return self.fail(
                Diagnostic::error(
                    "`auto` takes one argument, `states = [..]`",
                    e.span.clone(),
                    "here",
                )
                .with_help(help),
            );
        };
        if a.name.as_ref().is_none_or(|n| n.name != "states") {
            let span = a
                .name
                .as_ref()
                .map_or(a.value.span.clone(), |n| n.span.clone());
            return self.fail(
                Diagnostic::error("`auto` takes `states = [..]`", span, "expected `states`")
                    .with_help(help),
            );
        }
        let states = self.state_list(&a.value)?;
        if states.is_empty() || states.len() > MAX_METRICS {
            return self.fail(
                Diagnostic::error(
                    format!("`auto(states = ..)` names 1 to {MAX_METRICS} states"),
                    a.value.span.clone(),
                    format!("{} states", states.len()),
                )
                .with_help(help),
            );
        }
        Some(Metric::PerState(states))
    }

    /// `local`, `global` or `empirical(paths = N)`.
    fn rate(&mut self, e: &Expr) -> Option<Rate> {
        let help = "write `local`, `global` or `empirical(paths = 2000)`";
        let bad = |msg: &str, span: Span, label: &str| {
            Diagnostic::error(msg, span, label).with_help(help)
        };
        match &e.kind {
            ExprKind::Name(id) if id.name == "local" => Some(Rate::Local),
            ExprKind::Name(id) if id.name == "global" => Some(Rate::Global),
            ExprKind::Call { func, args } if func.name == "empirical" => {
                let key = "paths";
                let [a] = args.as_slice() else {
                    return self.fail(bad(
                        &format!("`{}` takes one argument, `{key} = ...`", func.name),
                        e.span.clone(),
                        "here",
                    ));
                };
                if a.name.as_ref().is_none_or(|n| n.name != key) {
                    let (span, label) = match &a.name {
                        Some(n) => (n.span.clone(), format!("unknown argument `{}`", n.name)),
                        None => (a.value.span.clone(), "expected a named argument".into()),
                    };
                    return self.fail(bad(
                        &format!("`{}` takes `{key} = ...`", func.name),
                        span,
                        &label,
                    ));
                }
                let v = self.constant(&a.value, &[])?;
                if (2.0..=MAX_EMPIRICAL_PATHS).contains(&v) && v.fract() == 0.0 {
                    return Some(Rate::Empirical { paths: v as u64 });
                }
                self.fail(bad(
                    &format!(
                        "the number of paths must be a whole number in [2, {MAX_EMPIRICAL_PATHS}], \
                         but it is {v}"
                    ),
                    a.value.span.clone(),
                    "out of range",
                ))
            }
            _ => self.fail(bad(
                "unknown rate",
                e.span.clone(),
                "expected local, global or empirical(...)",
            )),
        }
    }

    /// `amgf`, `paper(eps = x)` or `paper(optimal)`.
    fn radius_rule(&mut self, e: &Expr) -> Option<RadiusRule> {
        let help = "write `amgf`, `paper(eps = 1/16)` or `paper(optimal)`";
        match &e.kind {
            ExprKind::Name(id) if id.name == "amgf" => Some(RadiusRule::Amgf),
            ExprKind::Call { func, args } if func.name == "paper" => match args.as_slice() {
                [a] if a.name.is_none()
                    && matches!(&a.value.kind, ExprKind::Name(id) if id.name == "optimal") =>
                {
                    Some(RadiusRule::PaperOptimal)
                }
                [a] if a.name.as_ref().is_some_and(|n| n.name == "eps") => {
                    let eps = self.constant(&a.value, &[])?;
                    if eps > 0.0 && eps < 1.0 {
                        Some(RadiusRule::Paper(eps))
                    } else {
                        self.fail(Diagnostic::error(
                            format!("eps must be in (0, 1), but it is {eps}"),
                            a.value.span.clone(),
                            "out of range",
                        ))
                    }
                }
                _ => self.fail(
                    Diagnostic::error(
                        "bad arguments to `paper`",
                        e.span.clone(),
                        "expected `eps = NUMBER` or `optimal`",
                    )
                    .with_help(help),
                ),
            },
            _ => self.fail(
                Diagnostic::error(
                    "unknown radius rule",
                    e.span.clone(),
                    "expected amgf or paper(...)",
                )
                .with_help(help),
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::diagnostics::Severity;
    use crate::driver::check_source;
    use crate::model::Model;
    use reachc_core::model::{AutoFit, TransformSource};

    fn check(analyses: &str, drift: &str) -> (Model, Vec<crate::diagnostics::Diagnostic>) {
        let src = format!(
            "model m\nstate x in [0, 2]\nstate y in [-1, 1]\ndrift {{ {drift} }}\n{analyses}"
        );
        let (model, diags) = check_source(&src, std::path::Path::new("."));
        (model.expect("the spec checks"), diags)
    }

    /// Every `auto` gets the same `T` and frame; frames are numbered in order of first use.
    #[test]
    fn auto_transforms_share_a_frame() {
        let (model, diags) = check(
            "analysis a { method = interval  horizon = 1  transform = auto }\n\
             analysis b { method = interval  horizon = 1  transform = [[1, 1], [0, 1]] }\n\
             analysis c { method = interval  horizon = 1  transform = auto }",
            "x' = y  y' = -4 * x - 5 * y",
        );
        assert!(diags.is_empty(), "{diags:?}");
        let t: Vec<_> = model
            .analyses
            .iter()
            .map(|a| a.spec.transform.clone().unwrap())
            .collect();
        assert_eq!([t[0].frame, t[1].frame, t[2].frame], [0, 1, 0]);
        assert_eq!(t[0], t[2]);
        assert_eq!(t[1].source, TransformSource::Given);
        let TransformSource::Auto(AutoFit::LogNorm { chosen, identity }) = t[0].source else {
            panic!("{:?}", t[0].source);
        };
        assert_eq!(identity, 1.0);
        assert!(chosen < -0.98, "{chosen}");
    }

    /// A Jacobian that is not finite at the centre (`sqrt` at 0): the identity, and a warning
    /// on `auto`.
    #[test]
    fn non_finite_jacobian_falls_back_to_the_identity() {
        let (model, diags) = check(
            "analysis a { method = interval  horizon = 1  transform = auto }",
            "x' = -sqrt(x - 1)  y' = -y",
        );
        let [d] = diags.as_slice() else {
            panic!("{diags:?}");
        };
        assert_eq!(d.severity, Severity::Warning);
        assert!(d.message.contains("falls back to the identity"), "{d:?}");
        let t = model.analyses[0].spec.transform.clone().unwrap();
        assert_eq!(t.matrix, [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(t.source, TransformSource::Auto(AutoFit::NonFiniteJacobian));
    }
}
