//! The pendulum of `specs/pendulum.sde`, compiled by `build.rs` with `reachc_compiler::Config` and
//! included here: [`Pendulum`] implements `reachc_runtime::System` and `reachc_runtime::Model`
//! (its `info()` describes the spec's sets and analyses), and [`analysis`] names the analyses.

mod pendulum {
    reachc_runtime::include_sde!("pendulum");
}

pub use pendulum::*;
