//! The core of reachc: outward-rounded intervals, the [`System`] trait generated code
//! implements, the data model of a spec's sets and analyses, and the engines computing
//! delta-probabilistic reachable sets, with typed results. No dependencies (rayon with the
//! `parallel` feature, for Monte Carlo and the pieces of a split initial set).

pub mod chi2;
pub mod decimal;
pub mod engine;
pub mod func;
pub mod interval;
pub mod kappa;
pub mod lanes;
pub mod model;
pub mod probability;
pub mod prs;
mod reach;
mod sets;
pub mod simulate;
pub mod sweep;
pub mod system;
pub mod table;
#[cfg(test)]
mod test_support;
mod words;
mod workers;

pub use interval::Interval;
pub use lanes::X8;
pub use model::{Bounds, ModelInfo};
pub use prs::Prs;
pub use reach::{InputPlan, Reach};
pub use system::{Model, System};
