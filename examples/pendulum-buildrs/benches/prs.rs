//! The pendulum's delta-PRS with generated (compiled) code: contraction (401 report steps,
//! step 0.01, horizon 4) and interval in y = T x with each inclusion function (400 Euler
//! steps; the immrax comparison in docs/benchmarks.md). Compare with
//! `cargo bench -p reachc --bench prs` (the interpreter).

use pendulum_buildrs::{info, Pendulum};

fn main() {
    divan::main();
}

#[divan::bench]
fn contraction_prs_compiled(bencher: divan::Bencher) {
    let info = info();
    let analysis = info.analysis("contraction").unwrap();
    bencher.bench(|| {
        reachc_runtime::engine::run(&Pendulum, &info, analysis)
            .unwrap()
            .steps
            .len()
    });
}

/// The interval-based PRS of the pendulum in y = T x (the paper's Fig. 6, right), per
/// inclusion function: one whole analysis (box trajectory, stochastic radius, report).
#[divan::bench(args = ["natural", "jacobian", "mixed"])]
fn interval_prs_compiled(bencher: divan::Bencher, inclusion: &str) {
    let info = info();
    let analysis = interval_analysis(&info, inclusion);
    bencher.bench(|| {
        reachc_runtime::engine::run(&Pendulum, &info, &analysis)
            .unwrap()
            .steps
            .len()
    });
}

/// The boxes alone (`engine::interval_boxes`: the embedding system's 400 Euler steps in
/// y = T x), per inclusion function: what immrax computes per reach.
#[divan::bench(args = ["natural", "jacobian", "mixed"])]
fn interval_reach_compiled(bencher: divan::Bencher, inclusion: &str) {
    let info = info();
    let analysis = interval_analysis(&info, inclusion);
    bencher.bench(|| {
        reachc_runtime::engine::interval_boxes(&Pendulum, &info, &analysis.spec)
            .unwrap()
            .len()
    });
}

/// The pendulum's analysis `interval` with the given inclusion function.
fn interval_analysis(
    info: &reachc_runtime::ModelInfo,
    inclusion: &str,
) -> reachc_runtime::model::Analysis {
    use reachc_runtime::model::Inclusion;
    let mut analysis = info.analysis("interval").unwrap().clone();
    analysis.spec.inclusion = match inclusion {
        "natural" => Inclusion::Natural,
        "mixed" => Inclusion::Mixed,
        _ => Inclusion::Jacobian,
    };
    analysis
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
