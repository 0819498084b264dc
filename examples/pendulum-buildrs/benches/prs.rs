//! The contraction delta-PRS of the pendulum with generated (compiled) code: 401 report steps
//! (step 0.01, horizon 4). Compare with `cargo bench -p reachc --bench prs` (the interpreter).

use pendulum_buildrs::{info, Pendulum};

fn main() {
    divan::main();
}

#[divan::bench]
fn contraction_prs_compiled(bencher: divan::Bencher) {
    let info = info();
    let analysis = info
        .analyses
        .iter()
        .find(|a| a.name == "contraction")
        .unwrap();
    bencher.bench(|| {
        reachc_runtime::engine::run(&Pendulum, &info, analysis)
            .unwrap()
            .steps
            .len()
    });
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
