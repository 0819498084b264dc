//! Backends: from a checked, analysed model to something that computes reachable sets.
//!
//! [`prepare`] derives what every backend needs (Jacobians, the runtime's [`ModelInfo`](reachc_core::model::ModelInfo) with
//! the constants of each analysis); [`codegen`] emits a Rust crate implementing the runtime's
//! `System` trait; [`interp`] implements the same trait by evaluating the IR directly. Generated
//! crates are written to disk and compiled by [`crate::package`].

pub mod codegen;
pub mod info;
pub mod interp;
pub mod mangle;

pub use info::{prepare, Prepared};

use crate::diagnostics::Diagnostic;
use crate::model::Model;

/// [`prepare`], with errors (if any) as diagnostics.
pub(crate) fn prepared(model: &mut Model) -> Result<Prepared, Vec<Diagnostic>> {
    Ok(prepare(model))
}
