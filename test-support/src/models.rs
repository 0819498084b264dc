//! Model data for hand-written systems: a [`ModelInfo`] with nothing but names and an initial
//! box, for tests to fill in, and the paper's pendulum with its constants.
//!
//! This file is also compiled into reachc-core's own unit tests (`core/src/test_support.rs`),
//! so it takes the crate's names from its parent module.

use super::{Bounds, Constants, InitialSet, ModelInfo, ModelParts};

/// The model `name` with `states`, noise channels `noises` and the initial box `initial` (one
/// range per state): no inputs, unsafe or goal sets, or analyses, and no domain (the whole
/// space, one range per initial range). Tests set what else they need:
/// `ModelInfo::from_parts(ModelParts { inputs, ..model(...).into_parts() })`.
pub fn model(name: &str, states: &[&str], noises: &[&str], initial: &[(f64, f64)]) -> ModelInfo {
    let names = |names: &[&str]| names.iter().map(|s| s.to_string()).collect();
    let initial: Vec<Bounds> = initial.iter().map(|&(a, b)| Bounds::new(a, b)).collect();
    ModelInfo::from_parts(ModelParts {
        name: name.into(),
        states: names(states),
        inputs: vec![],
        noises: names(noises),
        input_box: vec![],
        domain: vec![Bounds::ENTIRE; initial.len()],
        initial: InitialSet::from_box(&initial),
        has_domain: false,
        affine: false,
        constant_diffusion: false,
        time: Default::default(),
        unsafe_sets: vec![],
        goals: vec![],
        analyses: vec![],
    })
}

/// The paper's metric `P` for the pendulum (Sec. VIII-B), row-major.
pub const PENDULUM_METRIC: [f64; 4] = [35.68, 2.21, 2.21, 1.27];

/// The model of [`Pendulum`](super::systems::Pendulum) (specs/pendulum.sde): states `theta`,
/// `omega`, noise `w`, from the box `[-pi/10, pi/10] x [-0.2, 0.2]`.
pub fn pendulum_model() -> ModelInfo {
    let a = std::f64::consts::PI / 10.0;
    model(
        "pendulum",
        &["theta", "omega"],
        &["w"],
        &[(-a, a), (-0.2, 0.2)],
    )
}

/// The paper's constants for [`pendulum_model`] (Sec. VIII-B): [`PENDULUM_METRIC`], `c =
/// -0.5`, `sigma = 0.1130`, no input.
pub fn pendulum_constants(info: &ModelInfo) -> Constants {
    Constants::given(info, PENDULUM_METRIC.to_vec(), -0.5, 0.1130, 0.0)
}
