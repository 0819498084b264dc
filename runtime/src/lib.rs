//! Runtime for `reachc`-generated crates: the core (`reachc-core`: intervals, the [`System`]
//! trait, the data model, the engines and their typed results) re-exported, plus reports (JSON,
//! CSV, text; feature `report`), parallel Monte Carlo (feature `simulate`) and the `main` of
//! generated binaries (feature `app`).

pub use reachc_core::{engine, func, interval, kappa, lanes, simulate, system, table};
pub use reachc_core::{Interval, System, X8};

#[cfg(feature = "app")]
pub mod app;
mod include;
