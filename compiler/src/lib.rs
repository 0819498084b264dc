//! `reachc`: a compiler for stochastic reachability.
//!
//! The pipeline, one module per stage (data flows one way):
//! [`syntax`] (text to syntax tree) -> [`model`] (checked model, names resolved, expressions in
//! the [`ir`]) -> [`analysis`] (derivatives, atoms, interval bounds) -> [`cli`] (commands).
//! See `ARCHITECTURE.md` at the repository root for the map.

pub mod analysis;
pub mod backend;
pub mod cli;
pub mod config;
pub mod diagnostics;
pub mod driver;
pub mod ir;
pub mod model;
pub mod plot;
pub mod syntax;
pub use config::Config;
