//! Symbolic analysis of a checked model: exact Jacobians, their split into atoms, and
//! outward-rounded interval bounds of every entry over the domain (method.md section 3).

mod atoms;
mod bounds;
mod derivatives;

pub use atoms::{split_atoms, Atom, AtomSplit};
pub use bounds::{bound_matrix, eval_box, time_range};
pub use derivatives::{Derivatives, GradEntry};
