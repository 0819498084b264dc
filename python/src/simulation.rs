//! `Simulation`: a Monte Carlo check of a PRS.

use std::sync::Arc;

use numpy::ndarray::Array1;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use reachc_runtime::simulate::{self, SimReport};
use reachc_runtime::{report, Prs};

use crate::convert::{array1, array2};
use crate::result::ReachResult;

/// A Monte Carlo check of a PRS.
#[pyclass(module = "reachc._native", frozen)]
pub(crate) struct Simulation {
    pub(crate) report: SimReport,
    pub(crate) prs: Arc<Prs>,
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
