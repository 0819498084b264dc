//! The pendulum's delta-PRS through the IR interpreter (contraction: 401 report steps, step
//! 0.01, horizon 4; interval in y = T x with each inclusion function: 400 Euler steps), the
//! embedding step of chains of 10, 100 and 1000 states, and `reachc build` (code generation, no
//! cargo) of the 1000-state chain. Compare with `cargo bench -p pendulum-buildrs` (generated
//! code).

use std::path::PathBuf;

use reachc_compiler::backend::{interp::Interpreter, prepare};
use reachc_runtime::System;

fn spec(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../specs")
        .join(name)
}

fn main() {
    divan::main();
}

fn pendulum() -> (Interpreter, reachc_runtime::ModelInfo) {
    let mut model = reachc_compiler::driver::load(&spec("pendulum.sde"))
        .unwrap()
        .model;
    let prepared = prepare(&mut model);
    (Interpreter::new(model, &prepared), prepared.info)
}

#[divan::bench]
fn contraction_prs_interpreted(bencher: divan::Bencher) {
    let (interp, info) = pendulum();
    let analysis = info.analysis("contraction").unwrap();
    bencher.bench(|| {
        reachc_runtime::engine::run_paired(&interp, &info, analysis)
            .unwrap()
            .steps()
            .len()
    });
}

/// The interval-based PRS of the pendulum in y = T x (the paper's Fig. 6, right): the analysis
/// `paper_interval` (400 Euler steps) with each inclusion function.
#[divan::bench(args = ["natural", "jacobian", "mixed"])]
fn interval_prs_interpreted(bencher: divan::Bencher, inclusion: &str) {
    interval_prs(bencher, "paper_interval", inclusion);
}

/// [`interval_prs_interpreted`] on validated steps (the spec's `interval`, time-uniform).
#[divan::bench(args = ["natural", "jacobian", "mixed"])]
fn validated_interval_prs_interpreted(bencher: divan::Bencher, inclusion: &str) {
    interval_prs(bencher, "interval", inclusion);
}

/// One whole interval analysis `name` with `inclusion`, timed.
fn interval_prs(bencher: divan::Bencher, name: &str, inclusion: &str) {
    let (interp, info) = pendulum();
    let analysis = with_inclusion(&info, name, inclusion);
    bencher.bench(|| {
        reachc_runtime::engine::run_paired(&interp, &info, &analysis)
            .unwrap()
            .steps()
            .len()
    });
}

/// The analysis `name` of `info` with the given inclusion function.
fn with_inclusion(
    info: &reachc_runtime::ModelInfo,
    name: &str,
    inclusion: &str,
) -> reachc_runtime::model::Analysis {
    use reachc_runtime::model::Inclusion;
    let mut a = info.analysis(name).unwrap().clone();
    a.spec.inclusion = match inclusion {
        "natural" => Inclusion::Natural,
        "mixed" => Inclusion::Mixed,
        _ => Inclusion::Jacobian,
    };
    a
}

/// The embedding system of `specs/chain1000.sde` resized to `n` states
/// (`engine::interval_boxes`, Jacobian inclusion): 10 Euler steps (divide by 10 for one step). The cost of a step grows with the
/// size of the expressions (linear in n for the chain), not with n^2.
#[divan::bench(args = [10, 100, 1000], sample_count = 20)]
fn chain_embedding_10_steps(bencher: divan::Bencher, n: usize) {
    let src = std::fs::read_to_string(spec("chain1000.sde"))
        .unwrap()
        .replace("const N = 1000", &format!("const N = {n}"));
    let mut model = reachc_compiler::driver::check_source(&src, &spec(""))
        .0
        .unwrap();
    let prepared = prepare(&mut model);
    let info = prepared.info.clone();
    let interp = Interpreter::new(model, &prepared);
    let mut a = with_inclusion(&info, "contraction", "jacobian").spec;
    a.method = reachc_runtime::model::Method::Interval;
    a.integrator = reachc_runtime::model::Integrator::Euler;
    a.horizon = 10.0 * a.step;
    bencher.bench(|| {
        reachc_runtime::engine::interval_boxes(&interp, &info, &a)
            .unwrap()
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
    let mut model = reachc_compiler::driver::load(&spec("chain1000.sde"))
        .unwrap()
        .model;
    let files = reachc_compiler::package::generate_files(
        &mut model,
        &reachc_compiler::package::CrateOptions::default(),
    )
    .unwrap();
    files.files.len()
}
