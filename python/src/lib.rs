//! `reachc._native`: the Python bindings of reachc, over the interpreter backend (no cargo at
//! run time). The typed Python API is `python/reachc/__init__.py`; this module does the work
//! with exactly what `reachc check`, `reachc run --backend interp` and `reachc simulate
//! --backend interp` call: [`driver::load`] / [`driver::load_source`], [`prepare`],
//! [`Interpreter`], [`Reach`], [`simulate::simulate`] and the runtime's JSON reports.
//!
//! The GIL is released while an analysis runs or paths are simulated. A `KeyboardInterrupt`
//! (any pending signal) is checked between the batches of paths of a simulation and between
//! the runs of a sweep; a single run is not interrupted.

use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyIndexError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use reachc_compiler::analysis::Derivatives;
use reachc_compiler::backend::interp::Interpreter;
use reachc_compiler::backend::prepare;
use reachc_compiler::diagnostics::{render, Diagnostic as Diag, Severity};
use reachc_compiler::driver::{self, LoadError, Loaded};
use reachc_compiler::ir::{ExprId, Names};
use reachc_compiler::model::Model;
use reachc_runtime::engine::RunError;
use reachc_runtime::model::InitialSet;
use reachc_runtime::probability::{GoalLimit, SafetyLimit};
use reachc_runtime::prs::{DetSet, GoalMiss, GoalOutcome, Verdict};
use reachc_runtime::simulate::{self, InputMode, SimError, SimReport};
use reachc_runtime::{report, Bounds, InputPlan, Model as _, Prs, Reach};

create_exception!(
    _native,
    SpecError,
    PyException,
    "A spec that does not load: str() is the diagnostic reachc check prints."
);
create_exception!(
    _native,
    AnalysisError,
    PyException,
    "An analysis that cannot run or be simulated (the CLI skips or reports it)."
);

/// One diagnostic of a spec: its severity, message, and where (1-based line and column of its
/// primary span, in characters; end exclusive).
#[pyclass(module = "reachc._native", frozen, get_all)]
#[derive(Clone)]
struct Diagnostic {
    severity: String,
    message: String,
    line: usize,
    column: usize,
    end_line: usize,
    end_column: usize,
    label: String,
    help: Option<String>,
    notes: Vec<String>,
}

#[pymethods]
impl Diagnostic {
    fn __repr__(&self) -> String {
        format!(
            "Diagnostic({}, {}:{}: {})",
            self.severity, self.line, self.column, self.message
        )
    }
}

/// 1-based line and column (in characters) of byte `at` of `src`.
fn line_col(src: &str, at: usize) -> (usize, usize) {
    let at = at.min(src.len());
    let at = (0..=at)
        .rev()
        .find(|&i| src.is_char_boundary(i))
        .unwrap_or(0);
    let before = &src[..at];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[start..].chars().count() + 1)
}

fn diagnostic(d: &Diag, src: &str) -> Diagnostic {
    let span = d.span();
    let (line, column) = line_col(src, span.start);
    let (end_line, end_column) = line_col(src, span.end);
    Diagnostic {
        severity: match d.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        }
        .into(),
        message: d.message.clone(),
        line,
        column,
        end_line,
        end_column,
        label: d
            .labels
            .first()
            .map(|l| l.message.clone())
            .unwrap_or_default(),
        help: d.help.clone(),
        notes: d.notes.clone(),
    }
}

fn load_error(py: Python<'_>, e: LoadError) -> PyErr {
    match &e {
        LoadError::Io(msg) => pyo3::exceptions::PyOSError::new_err(msg.clone()),
        LoadError::Spec {
            diagnostics,
            source,
            ..
        } => {
            let err = SpecError::new_err(e.report(false));
            let items: Vec<Diagnostic> =
                diagnostics.iter().map(|d| diagnostic(d, source)).collect();
            if let Err(set) = err.value(py).setattr("diagnostics", items) {
                return set;
            }
            err
        }
    }
}

fn run_error(e: RunError) -> PyErr {
    match e {
        RunError::UnknownAnalysis { .. } => PyValueError::new_err(e.to_string()),
        e => AnalysisError::new_err(e.to_string()),
    }
}

/// What a spec holds once loaded: the interpreter (with its model info), the checked model
/// (for printing), the source and the warnings.
struct Inner {
    interp: Interpreter,
    model: Model,
    path: PathBuf,
    source: String,
    warnings: Vec<Diag>,
}

/// A loaded spec: parsed, checked, differentiated, its constants derived (`prepare`), ready to
/// run through the interpreter.
#[pyclass(module = "reachc._native", frozen)]
struct Spec {
    inner: Arc<Inner>,
}

fn make_spec(py: Python<'_>, loaded: Result<Loaded, LoadError>) -> PyResult<Spec> {
    let mut loaded = loaded.map_err(|e| load_error(py, e))?;
    let model = loaded.model.clone();
    let prepared = py.detach(|| prepare(&mut loaded.model));
    let mut warnings = loaded.warnings;
    warnings.extend(prepared.warnings.iter().cloned());
    let interp = Interpreter::new(loaded.model, &prepared);
    Ok(Spec {
        inner: Arc::new(Inner {
            interp,
            model,
            path: loaded.path,
            source: loaded.source,
            warnings,
        }),
    })
}

/// Loads the spec at `path` (what `reachc check` does).
#[pyfunction]
fn load(py: Python<'_>, path: PathBuf) -> PyResult<Spec> {
    let loaded = py.detach(|| driver::load(&path));
    make_spec(py, loaded)
}

/// Loads spec text; `name` names it in diagnostics, tables' CSV paths are resolved against
/// `dir`.
#[pyfunction]
#[pyo3(signature = (text, name = "<string>".to_string(), dir = PathBuf::from(".")))]
fn loads(py: Python<'_>, text: String, name: String, dir: PathBuf) -> PyResult<Spec> {
    let loaded = py.detach(|| driver::load_source(Path::new(&name), text, &dir));
    make_spec(py, loaded)
}

fn names_of(v: &[reachc_compiler::model::Variable]) -> Vec<String> {
    v.iter().map(|x| x.name.clone()).collect()
}

fn mode(inputs: &str) -> PyResult<InputMode> {
    InputMode::parse(inputs).ok_or_else(|| {
        PyValueError::new_err(format!(
            "inputs `{inputs}`: expected random, corners or centre"
        ))
    })
}

/// Keeps signals (Ctrl-C) pending in the interpreter from a thread without the GIL: returns the
/// error to raise.
fn pending_signal() -> Option<PyErr> {
    Python::attach(|py| py.check_signals().err())
}

/// The payload of the unwinding that stops a simulation on a signal.
struct Interrupted(PyErr);

#[pymethods]
impl Spec {
    /// `model NAME`.
    #[getter]
    fn name(&self) -> &str {
        self.inner.interp.info().name()
    }

    /// The path given to `load`, or the name given to `loads`.
    #[getter]
    fn path(&self) -> String {
        self.inner.path.display().to_string()
    }

    #[getter]
    fn source(&self) -> &str {
        &self.inner.source
    }

    #[getter]
    fn states(&self) -> Vec<String> {
        self.inner.interp.info().states().to_vec()
    }

    #[getter]
    fn inputs(&self) -> Vec<String> {
        self.inner.interp.info().inputs().to_vec()
    }

    #[getter]
    fn noises(&self) -> Vec<String> {
        self.inner.interp.info().noises().to_vec()
    }

    /// The analyses' names, in spec order.
    #[getter]
    fn analyses(&self) -> Vec<String> {
        self.inner
            .interp
            .info()
            .analyses()
            .iter()
            .map(|a| a.spec.name.clone())
            .collect()
    }

    /// The named constants (`const`), in declaration order.
    #[getter]
    fn constants(&self) -> Vec<(String, f64)> {
        self.inner.model.constants.clone()
    }

    /// Warnings (checking and preparing), as structured items.
    #[getter]
    fn warnings(&self) -> Vec<Diagnostic> {
        self.inner
            .warnings
            .iter()
            .map(|d| diagnostic(d, &self.inner.source))
            .collect()
    }

    /// The warnings rendered as the CLI prints them (empty without warnings).
    fn render_warnings(&self) -> String {
        if self.inner.warnings.is_empty() {
            return String::new();
        }
        render(
            &self.inner.warnings,
            &self.path(),
            &self.inner.source,
            false,
        )
    }

    /// `(drift, diffusion, jacobian_x, jacobian_u, lets)` in `.sde` syntax, as `reachc inspect`
    /// prints them: the drift per state, the diffusion per state and noise channel, the
    /// Jacobians `D_x f` (equation x state) and `D_u f` (equation x input), shared
    /// sub-expressions as the `lets`, `(name, expression)`. Computed on each call (the
    /// Jacobians are differentiated on a copy of the model), the GIL released.
    fn expressions(&self, py: Python<'_>) -> Expressions {
        let inner = &*self.inner;
        py.detach(|| {
            let mut m = inner.model.clone();
            let d = Derivatives::of(&mut m);
            let (states, inputs, noises) = (
                names_of(&m.states),
                names_of(&m.inputs),
                names_of(&m.noises),
            );
            let names = Names {
                states: &states,
                inputs: &inputs,
                noises: &noises,
                tables: &m.tables,
            };
            let mut roots = m.drift.clone();
            let matrices = [&m.diffusion, &d.jac_x, &d.jac_u];
            for rows in matrices {
                roots.extend(rows.iter().flatten());
            }
            let shared = m.pool.to_sde_shared(&roots, &names);
            let mut texts = shared.exprs.into_iter();
            let drift: Vec<String> = texts.by_ref().take(m.drift.len()).collect();
            let mut grid = |rows: &Vec<Vec<ExprId>>| -> Vec<Vec<String>> {
                rows.iter()
                    .map(|r| texts.by_ref().take(r.len()).collect())
                    .collect()
            };
            let diffusion = grid(&m.diffusion);
            let jac_x = grid(&d.jac_x);
            let jac_u = grid(&d.jac_u);
            (drift, diffusion, jac_x, jac_u, shared.lets)
        })
    }

    /// The analysis `name` as the compiler prepared it: its parameters and certified constants
    /// (or why they could not be derived).
    fn analysis<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyDict>> {
        let a = self.inner.interp.info().analysis(name).ok_or_else(|| {
            run_error(RunError::UnknownAnalysis {
                name: name.to_string(),
                available: self.analyses(),
            })
        })?;
        let d = PyDict::new(py);
        let s = &a.spec;
        d.set_item("name", &s.name)?;
        d.set_item("method", s.method.name())?;
        d.set_item("delta", s.delta)?;
        d.set_item("horizon", s.horizon)?;
        d.set_item("step", s.step)?;
        d.set_item("integrator", s.integrator.name())?;
        d.set_item("guarantee", s.guarantee.name())?;
        d.set_item("rate", s.rate.name())?;
        match &a.constants {
            Ok(c) => {
                let k = PyDict::new(py);
                k.set_item("c", c.c())?;
                k.set_item("sigma", c.sigma())?;
                k.set_item("rho", c.rho())?;
                let n = self.inner.interp.info().states().len();
                let metric = Array2::from_shape_vec((n, n), c.metric().to_vec())
                    .map_err(|e| PyValueError::new_err(e.to_string()))?;
                k.set_item("metric", metric.into_pyarray(py))?;
                k.set_item(
                    "certified",
                    !matches!(c.provenance(), reachc_runtime::model::Provenance::Given),
                )?;
                k.set_item("metrics", 1 + c.also().len())?;
                d.set_item("constants", k)?;
                d.set_item("constants_error", py.None())?;
            }
            Err(why) => {
                d.set_item("constants", py.None())?;
                d.set_item("constants_error", why.to_string())?;
            }
        }
        Ok(d)
    }

    /// A handle on the analysis `name`: checked once, run many times.
    fn reach(slf: &Bound<'_, Self>, name: &str) -> PyResult<ReachHandle> {
        let inner = slf.get().inner.clone();
        // SAFETY: the reference points into `inner`, an `Arc` kept alive by the handle next to
        // the `Reach` (and dropped after it: fields drop in declaration order), never moved.
        let sys: &'static Interpreter = unsafe { &*(&inner.interp as *const _) };
        let reach = Reach::new(sys, name).map_err(run_error)?;
        Ok(ReachHandle {
            reach: SyncReach(reach),
            inner,
        })
    }

    /// Monte Carlo check of the analysis `name`, as `reachc simulate --backend interp`: the PRS
    /// (at `delta` if given), then `paths` Euler-Maruyama sample paths against it; with
    /// `probability`, the certified probability of safety checked against the paths too.
    #[pyo3(signature = (name, paths, seed = 0, dt = None, delta = None, inputs = "random", hold = None, confidence = 0.999, threads = None, probability = false))]
    #[allow(clippy::too_many_arguments)]
    fn simulate(
        &self,
        py: Python<'_>,
        name: &str,
        paths: u64,
        seed: u64,
        dt: Option<f64>,
        delta: Option<f64>,
        inputs: &str,
        hold: Option<f64>,
        confidence: f64,
        threads: Option<usize>,
        probability: bool,
    ) -> PyResult<Simulation> {
        if let Some(d) = delta {
            if !(d > 0.0 && d < 1.0) {
                return Err(PyValueError::new_err(format!(
                    "delta {d} must lie in (0, 1)"
                )));
            }
        }
        if threads == Some(0) {
            return Err(PyValueError::new_err("threads must be at least 1"));
        }
        let mut opts = simulate::Options {
            paths,
            seed,
            dt,
            inputs: mode(inputs)?,
            hold,
            confidence,
            threads,
            safety_bound: None,
            goal_bounds: Vec::new(),
        };
        let inner = &*self.inner;
        let result = py.detach(|| {
            let reach = Reach::new(&inner.interp, name).and_then(|r| match delta {
                Some(d) => r.with_delta(d),
                None => Ok(r),
            })?;
            // As `reachc simulate --probability`: the bound where it is defined.
            if probability && !inner.interp.info().unsafe_sets().is_empty() {
                opts.safety_bound = reach
                    .safety_probability()
                    .ok()
                    .and_then(|p| p.lower_bound());
            }
            reach.run()
        });
        // A result with a number that is not finite is a run error (RunError::NonFinite).
        let result = result.map_err(run_error)?;
        let sim = py.detach(|| {
            std::panic::catch_unwind(AssertUnwindSafe(|| {
                simulate::simulate(&inner.interp, &result, &opts, &mut |_, _| {
                    if let Some(e) = pending_signal() {
                        std::panic::resume_unwind(Box::new(Interrupted(e)));
                    }
                })
            }))
        });
        let sim = match sim {
            Ok(r) => r,
            Err(payload) => match payload.downcast::<Interrupted>() {
                Ok(i) => return Err(i.0),
                Err(other) => std::panic::resume_unwind(other),
            },
        };
        let report = sim.map_err(|e| match e {
            SimError::Usage(m) => PyValueError::new_err(m.to_string()),
            SimError::Invalid(m) => {
                AnalysisError::new_err(format!("analysis `{name}` cannot be simulated: {m}"))
            }
        })?;
        Ok(Simulation {
            report,
            prs: Arc::new(result),
        })
    }

    /// `paths` sample paths at the report times of a result (`times`), as `reachc plot` draws
    /// them: array `(paths, len(times), n)`, Euler steps of at most `dt` (default: one report
    /// step; `simulate` chooses its own from the dynamics).
    #[pyo3(signature = (times, paths, seed = 0, dt = None, inputs = "random", hold = None, center = None))]
    #[allow(clippy::too_many_arguments)]
    fn sample_paths<'py>(
        &self,
        py: Python<'py>,
        times: Vec<f64>,
        paths: u64,
        seed: u64,
        dt: Option<f64>,
        inputs: &str,
        hold: Option<f64>,
        center: Option<Vec<f64>>,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let opts = simulate::Options {
            paths,
            seed,
            dt,
            inputs: mode(inputs)?,
            hold,
            ..simulate::Options::default()
        };
        let inner = &*self.inner;
        let got = py.detach(|| {
            simulate::sample_paths(&inner.interp, inner.interp.info(), &times, center.as_deref(), &opts)
        });
        let got = got.map_err(|e| PyValueError::new_err(e.to_string()))?;
        let n = inner.interp.info().states().len();
        let flat: Vec<f64> = got.into_iter().flatten().collect();
        let arr = Array3::from_shape_vec((paths as usize, times.len(), n), flat)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(arr.into_pyarray(py))
    }

    fn __repr__(&self) -> String {
        format!(
            "Spec({:?}: {} states, analyses {:?})",
            self.inner.interp.info().name(),
            self.inner.interp.info().states().len(),
            self.analyses()
        )
    }
}

/// `(drift, diffusion, jacobian_x, jacobian_u, lets)` in `.sde` syntax.
type Expressions = (
    Vec<String>,
    Vec<Vec<String>>,
    Vec<Vec<String>>,
    Vec<Vec<String>>,
    Vec<(String, String)>,
);

/// A [`Reach`] over the interpreter, which is `Sync`: the `dyn System` erases that.
struct SyncReach(Reach<'static>);
// SAFETY: the system behind the `Reach` is an `Interpreter` (Send + Sync: `reachc simulate`
// shares it between threads), the rest of the `Reach` is plain data.
unsafe impl Send for SyncReach {}
unsafe impl Sync for SyncReach {}

/// One analysis of a spec, checked once (constants checked against the model, metric
/// factorised): run it from the spec's initial set or from other boxes, as often as needed.
#[pyclass(module = "reachc._native", frozen, name = "Reach")]
struct ReachHandle {
    // Declared before `inner`: dropped first.
    reach: SyncReach,
    inner: Arc<Inner>,
}

/// `x0` as boxes: array `(n, 2)` of `[lo, hi]` rows.
fn boxes_of(x0: ndarray_view::View2<'_>) -> PyResult<Vec<Bounds>> {
    if x0.ncols() != 2 {
        return Err(PyValueError::new_err(format!(
            "an initial box is an array of shape (n, 2) ([lo, hi] per state), not {:?}",
            x0.shape()
        )));
    }
    Ok(x0
        .rows()
        .into_iter()
        .map(|r| Bounds::new(r[0], r[1]))
        .collect())
}

mod ndarray_view {
    pub type View2<'a> = numpy::ndarray::ArrayView2<'a, f64>;
}

/// An input plan from `(times, values)`.
fn plan_of(inputs: Option<(Vec<f64>, Vec<Vec<f64>>)>) -> PyResult<Option<InputPlan>> {
    inputs
        .map(|(t, v)| InputPlan::steps(t, v).map_err(run_error))
        .transpose()
}

impl ReachHandle {
    fn run_one(&self, x0: Option<&[Bounds]>, plan: Option<&InputPlan>) -> PyResult<Prs> {
        let r = &self.reach.0;
        // A result with a number that is not finite is a run error (RunError::NonFinite).
        match (x0, plan) {
            (None, None) => r.run(),
            (Some(b), None) => r.from_box(b),
            (Some(b), Some(p)) => r.from_box_with(b, p),
            (None, Some(p)) => r.from_set_with(self.inner.interp.info().initial(), p),
        }
        .map_err(run_error)
    }
}

#[pymethods]
impl ReachHandle {
    /// The analysis' name.
    #[getter]
    fn name(&self) -> String {
        self.reach.0.analysis().name.clone()
    }

    /// Runs the analysis (GIL released): from the spec's initial set, or from the box `x0`
    /// (array `(n, 2)`), for any input in the input box or under the plan `inputs = (times,
    /// values)` (the input `values[k]` from `times[k]` on).
    #[pyo3(signature = (x0 = None, inputs = None))]
    fn run(
        &self,
        py: Python<'_>,
        x0: Option<PyReadonlyArray2<'_, f64>>,
        inputs: Option<(Vec<f64>, Vec<Vec<f64>>)>,
    ) -> PyResult<ReachResult> {
        let x0 = x0.map(|a| boxes_of(a.as_array())).transpose()?;
        let plan = plan_of(inputs)?;
        let prs = py.detach(|| self.run_one(x0.as_deref(), plan.as_ref()))?;
        Ok(ReachResult { prs: Arc::new(prs) })
    }

    /// Runs the analysis from each box of `boxes` (array `(m, n, 2)`), the GIL released;
    /// pending signals (Ctrl-C) are checked between runs.
    fn sweep(
        &self,
        py: Python<'_>,
        boxes: PyReadonlyArray3<'_, f64>,
    ) -> PyResult<Vec<ReachResult>> {
        let arr = boxes.as_array();
        let all: Vec<Vec<Bounds>> = arr
            .outer_iter()
            .map(|b| boxes_of(b))
            .collect::<PyResult<_>>()?;
        let mut out = Vec::with_capacity(all.len());
        for b in &all {
            py.check_signals()?;
            let prs = py.detach(|| self.run_one(Some(b), None))?;
            out.push(ReachResult { prs: Arc::new(prs) });
        }
        Ok(out)
    }

    /// A certified lower bound of the probability that no unsafe set is entered on `[0, T]`,
    /// for every start in the spec's initial set and every input (`reachc run
    /// --probability`; about a dozen runs, the GIL released).
    fn safety_probability(&self, py: Python<'_>) -> PyResult<SafetyProbabilityPy> {
        let p = py
            .detach(|| self.reach.0.safety_probability())
            .map_err(run_error)?;
        let sets = self.inner.interp.info().unsafe_sets();
        let name = |set: usize| Some(sets[set].name.clone());
        let (limit, t, set, why) = match &p.limit {
            SafetyLimit::Resolution => ("resolution", None, None, None),
            SafetyLimit::Floor => ("floor", None, None, None),
            SafetyLimit::Stochastic { t, set } => ("stochastic", Some(*t), name(*set), None),
            SafetyLimit::Deterministic { t, set } => ("deterministic", Some(*t), name(*set), None),
            SafetyLimit::Failed { delta, why } => {
                ("failed", Some(*delta), None, Some(why.to_string()))
            }
        };
        Ok(SafetyProbabilityPy {
            horizon: p.horizon,
            lower_bound: p.lower_bound(),
            delta: p.delta,
            not_shown_at: p.not_shown_at,
            limit: limit.to_string(),
            limit_t: t,
            limit_set: set,
            limit_why: why,
            runs: p.runs,
            proved: p.validation.not_validated.is_empty(),
            conditional_on_domain: p.validation.conditional_on_domain,
            text: report::probability::line(sets, &p),
        })
    }

    /// A certified lower bound of the probability of reaching the goal set `goal` (its name),
    /// avoiding the unsafe sets until then (with `stay`: and staying in it to the horizon),
    /// for every start and input (`reachc run --probability`; about a dozen runs, the GIL
    /// released).
    fn goal_probability(&self, py: Python<'_>, goal: &str) -> PyResult<GoalProbabilityPy> {
        let info = &self.inner.interp.info();
        let Some(g) = info.goals().iter().position(|x| x.name == goal) else {
            let names: Vec<&str> = info.goals().iter().map(|x| x.name.as_str()).collect();
            return Err(PyValueError::new_err(format!(
                "no goal `{goal}` (the goals: {})",
                names.join(", ")
            )));
        };
        let p = py
            .detach(|| self.reach.0.goal_probability(g))
            .map_err(run_error)?;
        let sets = info.unsafe_sets();
        let (limit, t, set, why) = match &p.limit {
            GoalLimit::Resolution => ("resolution", None, None, None),
            GoalLimit::Floor => ("floor", None, None, None),
            GoalLimit::NotShown(miss) => {
                let (kind, t, set) = miss_fields(miss);
                (kind, t, set.map(|s| sets[s].name.clone()), None)
            }
            GoalLimit::Failed { delta, why } => {
                ("failed", Some(*delta), None, Some(why.to_string()))
            }
        };
        let horizon = self.reach.0.analysis().horizon;
        Ok(GoalProbabilityPy {
            goal: goal.to_string(),
            lower_bound: p.lower_bound(),
            delta: p.delta,
            t: p.t,
            not_shown_at: p.not_shown_at,
            limit: limit.to_string(),
            limit_t: t,
            limit_set: set,
            limit_why: why,
            runs: p.runs,
            proved: p.validation.not_validated.is_empty(),
            conditional_on_domain: p.validation.conditional_on_domain,
            text: report::probability::goal_line(info.goals(), sets, horizon, &p),
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Reach({:?} of model {:?})",
            self.reach.0.analysis().name,
            self.inner.interp.info().name()
        )
    }
}

/// A certified lower bound of the probability of safety (`Reach.safety_probability`): the
/// fields of the JSON's `safety_probability`, the limit flattened (`limit_t` is the time of a
/// `stochastic` or `deterministic` limit and the `delta` of a `failed` one), and `text` the
/// summary's line.
#[pyclass(module = "reachc._native", frozen, get_all, name = "SafetyProbability")]
struct SafetyProbabilityPy {
    horizon: f64,
    lower_bound: Option<f64>,
    delta: Option<f64>,
    not_shown_at: Option<f64>,
    limit: String,
    limit_t: Option<f64>,
    limit_set: Option<String>,
    limit_why: Option<String>,
    runs: usize,
    proved: bool,
    conditional_on_domain: bool,
    text: String,
}

#[pymethods]
impl SafetyProbabilityPy {
    fn __repr__(&self) -> String {
        self.text.clone()
    }
}

/// A certified lower bound of the probability of reaching a goal (`Reach.goal_probability`):
/// the fields of the JSON's `goals[].probability`, the limit flattened (`limit` one of
/// `resolution`, `floor`, `failed`, `no_report_time`, `unsafe`, `not_inside`, `leaves`;
/// `limit_t` its time, or the `delta` of a `failed` one), and `text` the summary's line.
#[pyclass(module = "reachc._native", frozen, get_all, name = "GoalProbability")]
struct GoalProbabilityPy {
    goal: String,
    lower_bound: Option<f64>,
    delta: Option<f64>,
    t: Option<f64>,
    not_shown_at: Option<f64>,
    limit: String,
    limit_t: Option<f64>,
    limit_set: Option<String>,
    limit_why: Option<String>,
    runs: usize,
    proved: bool,
    conditional_on_domain: bool,
    text: String,
}

#[pymethods]
impl GoalProbabilityPy {
    fn __repr__(&self) -> String {
        self.text.clone()
    }
}

/// A goal miss as `(kind, time, unsafe set index)`, the JSON's names.
fn miss_fields(miss: &GoalMiss) -> (&'static str, Option<f64>, Option<usize>) {
    match *miss {
        GoalMiss::NoReportTime => ("no_report_time", None, None),
        GoalMiss::Unsafe { t, set } => ("unsafe", Some(t), Some(set)),
        GoalMiss::NotInside { t, .. } => ("not_inside", Some(t), None),
        GoalMiss::Leaves { t } => ("leaves", Some(t), None),
    }
}

/// A computed delta-PRS.
#[pyclass(module = "reachc._native", frozen, name = "Result")]
struct ReachResult {
    prs: Arc<Prs>,
}

fn array1<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    Array1::from_vec(v).into_pyarray(py)
}

fn array2<'py>(
    py: Python<'py>,
    rows: usize,
    cols: usize,
    v: Vec<f64>,
) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_vec((rows, cols), v)
        .expect("rows * cols values")
        .into_pyarray(py)
}

fn verdict_dict<'py>(py: Python<'py>, prs: &Prs) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    match prs.verdict() {
        Verdict::Safe => d.set_item("verdict", "safe")?,
        Verdict::NoUnsafeSets => d.set_item("verdict", "no unsafe sets")?,
        Verdict::NotShownSafe { t, step, set } => {
            d.set_item("verdict", "not shown safe")?;
            d.set_item("t", t)?;
            d.set_item("step", step)?;
            d.set_item("set", &prs.unsafe_sets()[set].name)?;
        }
    }
    Ok(d)
}

#[pymethods]
impl ReachResult {
    #[getter]
    fn model(&self) -> &str {
        self.prs.model()
    }

    #[getter]
    fn analysis(&self) -> &str {
        self.prs.analysis()
    }

    #[getter]
    fn method(&self) -> &str {
        self.prs.method().name()
    }

    #[getter]
    fn delta(&self) -> f64 {
        self.prs.delta()
    }

    #[getter]
    fn states(&self) -> Vec<String> {
        self.prs.states().to_vec()
    }

    /// The report times, shape `(k,)`.
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.prs.steps().iter().map(|s| s.t).collect())
    }

    /// The nominal state (the centre of the deterministic set), shape `(k, n)`.
    #[getter]
    fn nominal<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let v = self
            .prs
            .steps()
            .iter()
            .flat_map(|s| s.nominal().iter().copied())
            .collect();
        array2(py, self.prs.steps().len(), self.prs.n(), v)
    }

    /// `(lo, hi)`: a rigorous bounding box of the PRS at each report time, shapes `(k, n)`
    /// (NaN where no box is available).
    #[getter]
    fn hull_bounds<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>) {
        let (k, n) = (self.prs.steps().len(), self.prs.n());
        let (mut lo, mut hi) = (Vec::with_capacity(k * n), Vec::with_capacity(k * n));
        for i in 0..k {
            match self.prs.hull_at(i) {
                Some(b) => {
                    lo.extend(b.iter().map(|b| b.lo));
                    hi.extend(b.iter().map(|b| b.hi));
                }
                None => {
                    lo.extend(std::iter::repeat_n(f64::NAN, n));
                    hi.extend(std::iter::repeat_n(f64::NAN, n));
                }
            }
        }
        (array2(py, k, n, lo), array2(py, k, n, hi))
    }

    /// The stochastic radius `r_t` (in the metric's norm), shape `(k,)`.
    #[getter]
    fn r<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.prs.steps().iter().map(|s| s.r_t).collect())
    }

    /// The radius of the deterministic set around the nominal state, shape `(k,)`.
    #[getter]
    fn det_radius<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(
            py,
            self.prs.steps().iter().map(|s| s.det.radius()).collect(),
        )
    }

    /// The radius of a metric ball around the nominal state holding the PRS, shape `(k,)`.
    #[getter]
    fn prs_radius<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.prs.steps().iter().map(|s| s.prs_radius).collect())
    }

    /// The contraction rate on the step ending at each report time, shape `(k,)`.
    #[getter]
    fn rates<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.prs.steps().iter().map(|s| s.c).collect())
    }

    /// The noise level on the step ending at each report time, shape `(k,)`.
    #[getter]
    fn sigmas<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.prs.steps().iter().map(|s| s.sigma).collect())
    }

    /// The safety margins, shape `(k, m)` for `m` unsafe sets (`> 0`: shown safe).
    #[getter]
    fn margins<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let m = self.prs.unsafe_sets().len();
        let v = self
            .prs
            .steps()
            .iter()
            .flat_map(|s| s.margins.iter().copied())
            .collect();
        array2(py, self.prs.steps().len(), m, v)
    }

    /// The names of the unsafe sets.
    #[getter]
    fn unsafe_sets(&self) -> Vec<String> {
        self.prs
            .unsafe_sets()
            .iter()
            .map(|u| u.name.clone())
            .collect()
    }

    /// Per goal set: `{"name", "window": (t1, t2), "stay", "status": "reached" | "not_shown" |
    /// "needs_uniform", "t", "margin" (reached), "why", "why_t", "why_set" (not shown),
    /// "margins"}` (`margins` per report time), as in the JSON's `goals`.
    #[getter]
    fn goals<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.prs
            .goals()
            .iter()
            .map(|g| {
                let d = PyDict::new(py);
                d.set_item("name", &g.name)?;
                d.set_item("window", (g.window.lo, g.window.hi))?;
                d.set_item("stay", g.stay)?;
                match &g.outcome {
                    GoalOutcome::Reached { t, margin } => {
                        d.set_item("status", "reached")?;
                        d.set_item("t", t)?;
                        d.set_item("margin", margin)?;
                    }
                    GoalOutcome::NeedsUniform => d.set_item("status", "needs_uniform")?,
                    GoalOutcome::NotShown(miss) => {
                        let (kind, t, set) = miss_fields(miss);
                        d.set_item("status", "not_shown")?;
                        d.set_item("why", kind)?;
                        d.set_item("why_t", t)?;
                        d.set_item("why_set", set.map(|s| &self.prs.unsafe_sets()[s].name))?;
                    }
                }
                d.set_item("margins", array1(py, g.margins.clone()))?;
                Ok(d)
            })
            .collect()
    }

    /// The metric `P`, shape `(n, n)`.
    #[getter]
    fn metric<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let n = self.prs.n();
        array2(py, n, n, self.prs.constants().metric.clone())
    }

    /// `{"verdict": "safe" | "no unsafe sets" | "not shown safe", and for the last "t", "step",
    /// "set"}`.
    fn verdict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        verdict_dict(py, &self.prs)
    }

    /// Whether `x` certainly lies in the PRS at report time `t` (None if `t` is not one).
    fn contains(&self, x: Vec<f64>, t: f64) -> PyResult<Option<bool>> {
        if x.len() != self.prs.n() {
            return Err(PyValueError::new_err(format!(
                "x has {} values, the model {} states",
                x.len(),
                self.prs.n()
            )));
        }
        Ok(self.prs.contains(&x, t))
    }

    /// A rigorous bounding box of the PRS at report time `t`, shape `(n, 2)`.
    fn hull<'py>(&self, py: Python<'py>, t: f64) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let k = self
            .prs
            .step_index(t)
            .ok_or_else(|| PyIndexError::new_err(format!("{t} is not a report time")))?;
        let b = self
            .prs
            .hull_at(k)
            .ok_or_else(|| PyValueError::new_err("no bounding box for this set"))?;
        let v = b.iter().flat_map(|b| [b.lo, b.hi]).collect();
        Ok(array2(py, b.len(), 2, v))
    }

    /// The deterministic set at report time `t`, as in the JSON's `det_set`: `shape` (`p_ball`,
    /// `box`, `parallelotope` or `zonotope`), `center` and `radius` (a metric ball around the
    /// centre holding it), and by shape `lo`, `hi` (a box's corners; a parallelotope's in
    /// `y = T x`), `hull_lo`, `hull_hi` (the interval hull of a parallelotope or of a
    /// zonotope without its ball), `generators` (a zonotope's, shape `(k, n)`) and `remainder`
    /// (the metric radius of the ball added to the zonotope).
    fn det_set<'py>(&self, py: Python<'py>, t: f64) -> PyResult<Bound<'py, PyDict>> {
        let k = self
            .prs
            .step_index(t)
            .ok_or_else(|| PyIndexError::new_err(format!("{t} is not a report time")))?;
        let det = &self.prs.steps()[k].det;
        let d = PyDict::new(py);
        d.set_item("shape", det.shape())?;
        d.set_item("center", array1(py, det.center().to_vec()))?;
        d.set_item("radius", det.radius())?;
        if let Some((lo, hi)) = det.corners() {
            d.set_item("lo", array1(py, lo.to_vec()))?;
            d.set_item("hi", array1(py, hi.to_vec()))?;
        }
        match det {
            DetSet::Parallelotope {
                hull_lo, hull_hi, ..
            }
            | DetSet::Zonotope {
                hull_lo, hull_hi, ..
            } => {
                d.set_item("hull_lo", array1(py, hull_lo.clone()))?;
                d.set_item("hull_hi", array1(py, hull_hi.clone()))?;
            }
            DetSet::Ball { .. } | DetSet::Box { .. } => {}
        }
        if let DetSet::Zonotope {
            generators,
            remainder,
            ..
        } = det
        {
            let n = self.prs.n();
            let rows = generators.len() / n.max(1);
            d.set_item("generators", array2(py, rows, n, generators.clone()))?;
            d.set_item("remainder", *remainder)?;
        }
        Ok(d)
    }

    /// The further sets of an intersection (the PRS is the intersection of this result's own
    /// set and theirs): the further metrics' results, the interval box of a contraction run,
    /// first-order zonotopes; each a result of its own (its sets, metric, hulls, membership).
    #[getter]
    fn members(&self) -> Vec<ReachResult> {
        results(self.prs.also())
    }

    /// A split result's pieces (method.md 8.11; empty without a split): each piece's own
    /// result, from its part of the initial box, at the same delta; the PRS is their union.
    #[getter]
    fn pieces(&self) -> Vec<ReachResult> {
        results(self.prs.pieces())
    }

    /// What this result is within an intersection: `"own"` for an analysis' result,
    /// `"metric"`, `"box"`, `"first_order"` or `"linearised"` for a member.
    #[getter]
    fn role(&self) -> &'static str {
        self.prs.role().name()
    }

    /// The CLI's `ANALYSIS.json`, byte for byte (with its final newline).
    fn to_json(&self) -> String {
        report::to_json(&self.prs) + "\n"
    }

    /// The CLI's summary of the result.
    fn summary(&self) -> String {
        report::summary(&self.prs)
    }

    /// The CLI's `ANALYSIS.csv`.
    fn to_csv(&self) -> String {
        let mut csv = Vec::new();
        let _ = report::write_csv(&self.prs, &mut csv);
        String::from_utf8_lossy(&csv).into_owned()
    }

    fn __repr__(&self) -> String {
        format!(
            "Result({:?} of {:?}: {} report times)",
            self.prs.analysis(),
            self.prs.model(),
            self.prs.steps().len()
        )
    }
}

/// Each of `prs` as a result of its own (a member of an intersection, a piece of a split).
fn results(prs: &[Prs]) -> Vec<ReachResult> {
    prs.iter()
        .map(|p| ReachResult {
            prs: Arc::new(p.clone()),
        })
        .collect()
}

/// A Monte Carlo check of a PRS.
#[pyclass(module = "reachc._native", frozen)]
struct Simulation {
    report: SimReport,
    prs: Arc<Prs>,
}

#[pymethods]
impl Simulation {
    #[getter]
    fn analysis(&self) -> &str {
        &self.report.analysis
    }

    #[getter]
    fn paths(&self) -> u64 {
        self.report.paths
    }

    #[getter]
    fn seed(&self) -> u64 {
        self.report.seed
    }

    /// The largest Euler-Maruyama step used (the steps may differ between report intervals).
    #[getter]
    fn dt(&self) -> f64 {
        self.report.dt.max
    }

    #[getter]
    fn delta(&self) -> f64 {
        self.report.delta
    }

    /// Whether the coverage check passed.
    #[getter]
    fn passed(&self) -> bool {
        self.report.passed()
    }

    /// The PRS that was checked.
    #[getter]
    fn result(&self) -> ReachResult {
        ReachResult {
            prs: self.prs.clone(),
        }
    }

    /// Per-report-time statistics as arrays of shape `(k,)`: `times`, `r`, `prs_radius`,
    /// `quantile`, `max`, `outside` (int64), `fraction`, `cp_upper`; and of shape `(k, n)`,
    /// per state: `state_quantile` (the half-width about the nominal holding `1 - delta` of
    /// the paths), `state_max`, `state_prs` (the PRS's bounding-box half-width).
    fn steps<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.report.steps;
        let d = PyDict::new(py);
        let col = |f: fn(&simulate::SimStep) -> f64| array1(py, s.iter().map(f).collect());
        d.set_item("times", col(|s| s.t))?;
        d.set_item("r", col(|s| s.r_t))?;
        d.set_item("prs_radius", col(|s| s.prs_radius))?;
        d.set_item("quantile", col(|s| s.quantile))?;
        d.set_item("max", col(|s| s.max))?;
        d.set_item("fraction", col(|s| s.fraction))?;
        d.set_item("cp_upper", col(|s| s.cp_upper))?;
        let outside: Vec<i64> = s.iter().map(|s| s.outside as i64).collect();
        d.set_item("outside", Array1::from_vec(outside).into_pyarray(py))?;
        let n = self.report.states.len();
        let per_state = |f: fn(&simulate::StateSpread) -> f64| {
            let v = s.iter().flat_map(|s| s.states.iter().map(f)).collect();
            array2(py, s.len(), n, v)
        };
        d.set_item("state_quantile", per_state(|v| v.quantile))?;
        d.set_item("state_max", per_state(|v| v.max))?;
        d.set_item("state_prs", per_state(|v| v.prs))?;
        Ok(d)
    }

    /// The coverage statistics: the horizon's, the tube's (uniform results) and the check's.
    fn coverage<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = &self.report;
        let d = PyDict::new(py);
        d.set_item("passed", r.verdict.passed)?;
        d.set_item("decided_by", r.verdict.decided_by.name())?;
        d.set_item("pointwise_passed", r.verdict.pointwise_passed)?;
        d.set_item("alpha", r.verdict.alpha)?;
        d.set_item("failing_steps", r.verdict.failing_steps)?;
        d.set_item("worst_t", r.verdict.worst_t)?;
        d.set_item("worst_outside", r.verdict.worst_outside)?;
        d.set_item("worst_cp_lower", r.verdict.worst_cp_lower)?;
        d.set_item("outside_any", r.horizon.outside_any)?;
        d.set_item("outside_any_fraction", r.horizon.fraction)?;
        d.set_item("outside_any_cp_upper", r.horizon.cp_upper)?;
        match &r.tube {
            Some(t) => {
                d.set_item("tube_outside", t.outside)?;
                d.set_item("tube_fraction", t.fraction)?;
                d.set_item("tube_cp_upper", t.cp_upper)?;
                d.set_item("tube_cp_lower", t.cp_lower)?;
            }
            None => d.set_item("tube_outside", py.None())?,
        }
        d.set_item("diverged", r.diverged)?;
        d.set_item("left_domain", r.left_domain)?;
        Ok(d)
    }

    /// The CLI's `ANALYSIS.sim.json`, byte for byte (with its final newline).
    fn to_json(&self) -> String {
        report::simulation::to_json(&self.report) + "\n"
    }

    /// The CLI's summary.
    fn summary(&self) -> String {
        report::simulation::summary(&self.report)
    }

    fn __repr__(&self) -> String {
        format!(
            "Simulation({:?}: {} paths, seed {}, {})",
            self.report.analysis,
            self.report.paths,
            self.report.seed,
            if self.report.passed() {
                "passed"
            } else {
                "failed"
            }
        )
    }
}

/// The initial set of a spec as boxes, shape `(n, 2)` (NaN without a box part).
#[pyfunction]
fn initial_box<'py>(py: Python<'py>, spec: &Spec) -> Bound<'py, PyArray2<f64>> {
    let init: &InitialSet = spec.inner.interp.info().initial();
    let n = spec.inner.interp.info().states().len();
    let v = init
        .boxes
        .iter()
        .flat_map(|b| match b {
            Some(b) => [b.lo, b.hi],
            None => [f64::NAN, f64::NAN],
        })
        .collect();
    array2(py, n, 2, v)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SpecError", m.py().get_type::<SpecError>())?;
    m.add("AnalysisError", m.py().get_type::<AnalysisError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<Diagnostic>()?;
    m.add_class::<Spec>()?;
    m.add_class::<ReachHandle>()?;
    m.add_class::<ReachResult>()?;
    m.add_class::<SafetyProbabilityPy>()?;
    m.add_class::<GoalProbabilityPy>()?;
    m.add_class::<Simulation>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(loads, m)?)?;
    m.add_function(wrap_pyfunction!(initial_box, m)?)?;
    Ok(())
}
