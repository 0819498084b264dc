//! `reachc._native`: the Python bindings of reachc, over the interpreter backend (no cargo at
//! run time). The typed Python API is `python/reachc/__init__.py`; this module does the work
//! with exactly what `reachc check`, `reachc run --backend interp` and `reachc simulate
//! --backend interp` call: [`driver::load`] / [`driver::load_source`], [`prepare`],
//! [`Interpreter`], [`Reach`], [`simulate::simulate`] and the runtime's JSON reports.
//!
//! The GIL is released while an analysis runs or paths are simulated. A `KeyboardInterrupt`
//! (any pending signal) is checked between the batches of paths of a simulation and between
//! the runs of a sweep; a single run is not interrupted.

mod convert;
mod errors;
mod probability;
mod reach;
mod result;
mod simulation;
mod spec;

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

use errors::Diagnostic;
use probability::{GoalProbabilityPy, SafetyProbabilityPy};
use reach::ReachHandle;
use result::ReachResult;
use simulation::Simulation;
use spec::{initial_box, load, loads, Spec};

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
