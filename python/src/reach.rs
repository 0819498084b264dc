//! `Reach`: one analysis of a spec, checked once and run many times.

use std::sync::Arc;

use numpy::{PyReadonlyArray2, PyReadonlyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use reachc_runtime::probability::{GoalLimit, SafetyLimit};
use reachc_runtime::{report, Bounds, InputPlan, Model as _, Prs, Reach};

use crate::convert::{boxes_of, miss_fields, plan_of};
use crate::errors::run_error;
use crate::probability::{GoalProbabilityPy, SafetyProbabilityPy};
use crate::result::ReachResult;
use crate::spec::Inner;

/// A [`Reach`] over the interpreter, which is `Sync`: the `dyn System` erases that.
pub(crate) struct SyncReach(pub(crate) Reach<'static>);
// SAFETY: the system behind the `Reach` is an `Interpreter` (Send + Sync: `reachc simulate`
// shares it between threads), the rest of the `Reach` is plain data.
unsafe impl Send for SyncReach {}
unsafe impl Sync for SyncReach {}

/// One analysis of a spec, checked once (constants checked against the model, metric
/// factorised): run it from the spec's initial set or from other boxes, as often as needed.
#[pyclass(module = "reachc._native", frozen, name = "Reach")]
pub(crate) struct ReachHandle {
    // Declared before `inner`: dropped first.
    pub(crate) reach: SyncReach,
    pub(crate) inner: Arc<Inner>,
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
