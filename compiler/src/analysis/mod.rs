//! Symbolic analysis of a checked model: exact Jacobians, their split into atoms, and
//! outward-rounded interval bounds of every entry over the domain (method.md section 3); the
//! constants, metrics and coordinate transforms derived from them.

mod atoms;
mod auto_transform;
mod bounds;
mod contraction;
mod derivatives;
mod metric;
mod objective;
mod psd;
#[cfg(feature = "sdp")]
pub mod sdp;
mod stein;
mod transform;

pub use atoms::{split_atoms, Atom, AtomSplit};
pub use auto_transform::{
    choose_transform, jacobian_at, log_norm_inf, AutoTransform, MAX_AUTO_STATES, MAX_CONDITION,
};
pub use bounds::{bound_matrix, eval_box, time_range};
pub use contraction::{
    constants, constants_without_rate, ConstantsError, MAX_SIGN_INPUTS, MAX_VERTEX_ATOMS,
};
pub use derivatives::{Derivatives, GradEntry};
pub use metric::{synthesize_metric, synthesize_metric_over, FULL_METRIC_MAX_DIM};
pub use objective::{metric_for_result, Objective};
pub use stein::{map_metric, stein, MAX_KRONECKER_STATES};
pub use transform::Frame;
