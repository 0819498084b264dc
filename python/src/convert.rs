//! Conversions between Python arguments or arrays and reachc values.

use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use reachc_runtime::prs::GoalMiss;
use reachc_runtime::simulate::InputMode;
use reachc_runtime::{Bounds, InputPlan};

use crate::errors::run_error;

pub(crate) fn mode(inputs: &str) -> PyResult<InputMode> {
    InputMode::parse(inputs).ok_or_else(|| {
        PyValueError::new_err(format!(
            "inputs `{inputs}`: expected random, corners or centre"
        ))
    })
}

/// `x0` as boxes: array `(n, 2)` of `[lo, hi]` rows.
pub(crate) fn boxes_of(x0: ndarray_view::View2<'_>) -> PyResult<Vec<Bounds>> {
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
pub(crate) fn plan_of(inputs: Option<(Vec<f64>, Vec<Vec<f64>>)>) -> PyResult<Option<InputPlan>> {
    inputs
        .map(|(t, v)| InputPlan::steps(t, v).map_err(run_error))
        .transpose()
}

/// A goal miss as `(kind, time, unsafe set index)`, the JSON's names.
pub(crate) fn miss_fields(miss: &GoalMiss) -> (&'static str, Option<f64>, Option<usize>) {
    match *miss {
        GoalMiss::NoReportTime => ("no_report_time", None, None),
        GoalMiss::Unsafe { t, set } => ("unsafe", Some(t), Some(set)),
        GoalMiss::NotInside { t, .. } => ("not_inside", Some(t), None),
        GoalMiss::Leaves { t } => ("leaves", Some(t), None),
    }
}

pub(crate) fn array1<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    Array1::from_vec(v).into_pyarray(py)
}

pub(crate) fn array2<'py>(
    py: Python<'py>,
    rows: usize,
    cols: usize,
    v: Vec<f64>,
) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_vec((rows, cols), v)
        .expect("rows * cols values")
        .into_pyarray(py)
}
