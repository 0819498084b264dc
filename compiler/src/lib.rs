//! `reachc-compiler`: the reachc compiler as a library (the `reachc` command line is the crate
//! `reachc`; build scripts use [`Config`]).
//!
//! The pipeline, one module per stage (data flows one way):
//! [`syntax`] (text to syntax tree) -> [`model`] (checked model, names resolved, expressions in
//! the [`ir`], sets and analyses in the data model of `reachc-core`) -> [`analysis`] (derivatives,
//! atoms, interval bounds, certified constants) -> [`backend`] (generated Rust, or the IR
//! interpreter) -> [`package`] (generated crates on disk and in the cache, compiled with cargo).
//! See `ARCHITECTURE.md` at the repository root for the map.

pub mod analysis;
pub mod backend;
pub mod config;
pub mod diagnostics;
pub mod driver;
pub mod ir;
pub mod limits;
pub mod model;
pub mod package;
pub mod syntax;
pub use config::Config;
