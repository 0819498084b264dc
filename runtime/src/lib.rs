//! Runtime for `reachc`-generated crates: outward-rounded intervals, the [`System`] trait the
//! generated code implements, and the engines computing delta-probabilistic reachable sets.

pub mod app;
pub mod engine;
pub mod func;
mod include;
pub mod interval;
pub mod kappa;
pub mod lanes;
pub mod simulate;
pub mod system;
pub mod table;

pub use interval::Interval;
pub use lanes::X8;
pub use system::System;
