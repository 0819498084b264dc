//! Hand-made sets for results built by hand.
//!
//! This file is also compiled into reachc-core's own unit tests (`core/src/test_support.rs`),
//! so it names nothing outside `std`.

/// A zonotope in the box `[lo, hi]` of two states: the box's centre and the generators `gens`
/// in units of its half-widths (flat, two entries per generator), inside the box when the
/// generators' absolute values sum to at most 1 per state.
pub fn zonotope_in_box(lo: &[f64], hi: &[f64], gens: &[[f64; 2]]) -> (Vec<f64>, Vec<f64>) {
    let center: Vec<f64> = (0..2).map(|i| 0.5 * (lo[i] + hi[i])).collect();
    let half: Vec<f64> = (0..2).map(|i| 0.5 * (hi[i] - lo[i])).collect();
    let generators = gens
        .iter()
        .flat_map(|g| [g[0] * half[0], g[1] * half[1]])
        .collect();
    (center, generators)
}
