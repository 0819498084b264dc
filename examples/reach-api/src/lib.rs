//! The Duffing oscillator of `specs/duffing.sde` (a hardening spring with a bounded forcing `u`
//! and state-dependent noise), compiled by `build.rs`, and what a downstream crate does with
//! it through the typed API: sweep initial boxes ([`sweep`]) and follow a known forcing
//! ([`forced`]).

mod duffing {
    reachc_runtime::include_sde!("duffing");
}

pub use duffing::*;

use reachc_runtime::engine::RunError;
use reachc_runtime::{Bounds, InputPlan, Prs, Reach};

/// The initial box of width `0.2 x 0.2` centred at `(x0, 0)`.
pub fn start(x0: f64) -> [Bounds; 2] {
    [Bounds::new(x0 - 0.1, x0 + 0.1), Bounds::new(-0.1, 0.1)]
}

/// The PRS of the analysis `contraction` from each initial box `start(x0)`.
pub fn sweep(reach: &Reach<'_>, centres: &[f64]) -> Result<Vec<Prs>, RunError> {
    centres
        .iter()
        .map(|&x0| reach.from_box(&start(x0)))
        .collect()
}

/// The forcing pushes with `+0.05` until `t = 2`, then with `-0.05`.
pub fn forcing() -> InputPlan {
    InputPlan::steps(vec![0.0, 2.0], vec![vec![0.05], vec![-0.05]])
        .expect("increasing times from 0, one value each")
}

/// The PRS from `start(x0)` under [`forcing`] (no input uncertainty left).
pub fn forced(reach: &Reach<'_>, x0: f64) -> Result<Prs, RunError> {
    reach.from_box_with(&start(x0), &forcing())
}
