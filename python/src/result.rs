//! `Result`: a computed delta-PRS.

use std::sync::Arc;

use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::{PyIndexError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use reachc_runtime::prs::{DetSet, GoalOutcome, Verdict};
use reachc_runtime::{report, Prs};

use crate::convert::{array1, array2, miss_fields};

/// A computed delta-PRS.
#[pyclass(module = "reachc._native", frozen, name = "Result")]
pub(crate) struct ReachResult {
    pub(crate) prs: Arc<Prs>,
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
