//! Timing of `kappa(n, delta)` for the three radius rules.
//!
//! Target: under 10 ms per `(n, delta)` in release for `n = 1000`, `delta = 1e-15` (amgf).

use reachc_core::kappa::{kappa_amgf, kappa_paper, kappa_paper_optimal};

fn main() {
    divan::main();
}

const CASES: [(usize, f64); 6] = [
    (1, 1e-9),
    (2, 1e-3),
    (10, 1e-9),
    (100, 1e-6),
    (1000, 1e-3),
    (1000, 1e-15),
];

#[divan::bench(args = CASES)]
fn amgf(args: (usize, f64)) -> f64 {
    let (n, delta) = divan::black_box(args);
    kappa_amgf(n, delta)
}

#[divan::bench(args = CASES)]
fn paper_1_16(args: (usize, f64)) -> f64 {
    let (n, delta) = divan::black_box(args);
    kappa_paper(n, delta, 1.0 / 16.0)
}

#[divan::bench(args = CASES)]
fn paper_optimal(args: (usize, f64)) -> (f64, f64) {
    let (n, delta) = divan::black_box(args);
    kappa_paper_optimal(n, delta)
}
