//! Monte Carlo check of every shipped spec's analyses through the interpreter backend: each
//! delta-PRS (recomputed at delta = 0.01) holds the simulated states at every report time.
//! The 10^5-path version of this check is a documented command (docs/results.md).

use reachc_compiler::backend::{interp::Interpreter, prepare};
use reachc_compiler::driver::load;
use reachc_e2e::{relative, shipped_specs};
use reachc_runtime::engine::RunError;
use reachc_runtime::report::simulation::summary;
use reachc_runtime::simulate::{self, Options};
use reachc_runtime::system::Paired;
use reachc_runtime::Reach;

#[test]
fn every_shipped_spec_passes_the_coverage_check() {
    let mut checked = Vec::new();
    for spec in shipped_specs() {
        let mut model = load(&spec).unwrap().model;
        let prepared = prepare(&mut model);
        let info = prepared.info.clone();
        let interp = Interpreter::new(model, &prepared);
        // n = 1000: fewer paths keep the test short.
        let paths = if info.states().len() > 100 {
            200
        } else {
            1_000
        };
        for analysis in info.analyses() {
            let name = format!("{} / {}", relative(&spec), analysis.spec.name);
            let reach =
                Reach::for_analysis(&interp, &info, analysis).and_then(|r| r.with_delta(0.01));
            let result = match reach.and_then(|r| r.run()) {
                Ok(r) => r,
                // No constants (the unicycle's tracking controller): no PRS to check.
                Err(RunError::NoConstants(_) | RunError::Unsupported(_)) => continue,
                Err(e) => panic!("{name}: {e}"),
            };
            let opts = Options {
                paths,
                seed: 1,
                ..Options::default()
            };
            let report =
                simulate::simulate(&Paired::new(&interp, &info), &result, &opts, &mut |_, _| {})
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(report.passed(), "{name}:\n{}", summary(&report));
            // Not vacuous: the quantile is a sizeable part of the PRS radius somewhere.
            let ratio = report
                .steps
                .iter()
                .map(|s| s.quantile / s.prs_radius)
                .fold(0.0, f64::max);
            assert!(
                ratio > 0.05,
                "{name}: largest quantile / PRS radius {ratio}"
            );
            checked.push(name);
        }
    }
    assert!(checked.len() >= 10, "{checked:?}");
}
