//! Backends: from a checked, analysed model to something that computes reachable sets.
//!
//! [`prepare`] derives what every backend needs (Jacobians, the runtime's [`ModelInfo`](reachc_core::system::ModelInfo) with
//! the constants of each analysis); [`codegen`] emits a Rust crate implementing the runtime's
//! `System` trait; [`interp`] implements the same trait by evaluating the IR directly.

pub mod codegen;
pub mod crate_writer;
pub mod info;
pub mod interp;
pub mod mangle;

pub use info::{prepare, Prepared};
