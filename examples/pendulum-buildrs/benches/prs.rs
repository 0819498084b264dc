//! The pendulum's delta-PRS with generated (compiled) code: contraction (401 report steps,
//! step 0.01, horizon 4, validated nominal) and interval in y = T x with each inclusion
//! function: the paper's set-up (`paper_interval`, 400 Euler steps: like for like with immrax
//! in docs/benchmarks.md) and reachc's default (`interval`, validated steps). Compare with
//! `cargo bench -p reachc-compiler --bench prs` (the interpreter).

use pendulum_buildrs::{analysis, Pendulum};
use reachc_runtime::model::Inclusion;
use reachc_runtime::{Model, Reach};

fn main() {
    divan::main();
}

#[divan::bench]
fn contraction_prs_compiled(bencher: divan::Bencher) {
    bencher.bench(|| {
        reachc_runtime::engine::run(&Pendulum, analysis::CONTRACTION)
            .unwrap()
            .steps()
            .len()
    });
}

/// The interval-based PRS of the pendulum in y = T x (the paper's Fig. 6, right, 400 Euler
/// steps), per inclusion function: one whole analysis (box trajectory, stochastic radius,
/// report).
#[divan::bench(args = ["natural", "jacobian", "mixed"])]
fn interval_prs_compiled(bencher: divan::Bencher, inclusion: &str) {
    interval_prs(bencher, analysis::PAPER_INTERVAL, inclusion);
}

/// [`interval_prs_compiled`] on validated steps (the spec's `interval`, time-uniform).
#[divan::bench(args = ["natural", "jacobian", "mixed"])]
fn validated_interval_prs_compiled(bencher: divan::Bencher, inclusion: &str) {
    interval_prs(bencher, analysis::INTERVAL, inclusion);
}

/// One whole interval analysis `name` with `inclusion`, timed.
fn interval_prs(bencher: divan::Bencher, name: &str, inclusion: &str) {
    let inclusion = inclusion_named(inclusion);
    bencher.bench(|| {
        Reach::new(&Pendulum, name)
            .unwrap()
            .with_inclusion(inclusion)
            .run()
            .unwrap()
            .steps()
            .len()
    });
}

/// The boxes alone (`engine::interval_boxes`: the embedding system's 400 Euler steps in
/// y = T x), per inclusion function: what immrax computes per reach.
#[divan::bench(args = ["natural", "jacobian", "mixed"])]
fn interval_reach_compiled(bencher: divan::Bencher, inclusion: &str) {
    let info = Pendulum.info();
    let mut spec = info
        .analysis(analysis::PAPER_INTERVAL)
        .unwrap()
        .spec
        .clone();
    spec.inclusion = inclusion_named(inclusion);
    bencher.bench(|| {
        reachc_runtime::engine::interval_boxes(&Pendulum, info, &spec)
            .unwrap()
            .len()
    });
}

/// The inclusion function named `name`.
fn inclusion_named(name: &str) -> Inclusion {
    match name {
        "natural" => Inclusion::Natural,
        "mixed" => Inclusion::Mixed,
        _ => Inclusion::Jacobian,
    }
}

/// One drift evaluation (the nominal trajectory's inner loop).
#[divan::bench]
fn drift_compiled(bencher: divan::Bencher) {
    use reachc_runtime::System;
    bencher.bench(|| {
        let mut out = [0.0; 2];
        Pendulum.drift(divan::black_box(&[0.1, 0.2]), &[], 0.0, &mut out);
        out[1]
    });
}
