//! `Spec`: a loaded spec, and the functions that load one.

use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray2, PyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use reachc_compiler::analysis::Derivatives;
use reachc_compiler::backend::interp::Interpreter;
use reachc_compiler::backend::prepare;
use reachc_compiler::diagnostics::{render, Diagnostic as Diag};
use reachc_compiler::driver::{self, LoadError, Loaded};
use reachc_compiler::ir::{ExprId, Names};
use reachc_compiler::model::Model;
use reachc_runtime::engine::RunError;
use reachc_runtime::model::InitialSet;
use reachc_runtime::simulate::{self, SimError};
use reachc_runtime::{Model as _, Reach};

use crate::convert::{array2, mode};
use crate::errors::{diagnostic, load_error, pending_signal, run_error, Diagnostic, Interrupted};
use crate::reach::{ReachHandle, SyncReach};
use crate::simulation::Simulation;
use crate::AnalysisError;

/// What a spec holds once loaded: the interpreter (with its model info), the checked model
/// (for printing), the source and the warnings.
pub(crate) struct Inner {
    pub(crate) interp: Interpreter,
    model: Model,
    path: PathBuf,
    source: String,
    warnings: Vec<Diag>,
}

/// A loaded spec: parsed, checked, differentiated, its constants derived (`prepare`), ready to
/// run through the interpreter.
#[pyclass(module = "reachc._native", frozen)]
pub(crate) struct Spec {
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
pub(crate) fn load(py: Python<'_>, path: PathBuf) -> PyResult<Spec> {
    let loaded = py.detach(|| driver::load(&path));
    make_spec(py, loaded)
}

/// Loads spec text; `name` names it in diagnostics, tables' CSV paths are resolved against
/// `dir`.
#[pyfunction]
#[pyo3(signature = (text, name = "<string>".to_string(), dir = PathBuf::from(".")))]
pub(crate) fn loads(py: Python<'_>, text: String, name: String, dir: PathBuf) -> PyResult<Spec> {
    let loaded = py.detach(|| driver::load_source(Path::new(&name), text, &dir));
    make_spec(py, loaded)
}

fn names_of(v: &[reachc_compiler::model::Variable]) -> Vec<String> {
    v.iter().map(|x| x.name.clone()).collect()
}

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
            simulate::sample_paths(
                &inner.interp,
                inner.interp.info(),
                &times,
                center.as_deref(),
                &opts,
            )
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

/// The initial set of a spec as boxes, shape `(n, 2)` (NaN without a box part).
#[pyfunction]
pub(crate) fn initial_box<'py>(py: Python<'py>, spec: &Spec) -> Bound<'py, PyArray2<f64>> {
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
