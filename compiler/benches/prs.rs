//! The contraction delta-PRS of the pendulum through the IR interpreter: 401 report steps
//! (step 0.01, horizon 4). Compare with `cargo bench -p pendulum-buildrs` (generated code), and
//! `reachc build` (code generation, no cargo) of the 1000-state chain.

use std::path::PathBuf;

use reachc::backend::{interp::Interpreter, prepare};
use reachc_runtime::System;

fn spec(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../specs")
        .join(name)
}

fn main() {
    divan::main();
}

fn pendulum() -> (Interpreter, reachc_runtime::system::ModelInfo) {
    let mut model = reachc::driver::load(&spec("pendulum.sde")).unwrap().model;
    let prepared = prepare(&mut model);
    (Interpreter::new(model, &prepared), prepared.info)
}

#[divan::bench]
fn contraction_prs_interpreted(bencher: divan::Bencher) {
    let (interp, info) = pendulum();
    let analysis = info
        .analyses
        .iter()
        .find(|a| a.name == "contraction")
        .unwrap();
    bencher.bench(|| {
        reachc_runtime::engine::run(&interp, &info, analysis)
            .unwrap()
            .steps
            .len()
    });
}

/// One drift evaluation (the nominal trajectory's inner loop).
#[divan::bench]
fn drift_interpreted(bencher: divan::Bencher) {
    let (interp, _) = pendulum();
    bencher.bench(|| {
        let mut out = [0.0; 2];
        interp.drift(divan::black_box(&[0.1, 0.2]), &[], 0.0, &mut out);
        out[1]
    });
}

/// `reachc build --no-compile` of the 1000-state chain in memory: load, prepare (derivatives,
/// certified constants), generate and format the crate's sources.
#[divan::bench(sample_count = 5)]
fn build_chain1000_without_cargo() -> usize {
    let mut model = reachc::driver::load(&spec("chain1000.sde")).unwrap().model;
    let files = reachc::backend::crate_writer::generate_files(
        &mut model,
        &reachc::backend::crate_writer::CrateOptions::default(),
    )
    .unwrap();
    files.files.len()
}
