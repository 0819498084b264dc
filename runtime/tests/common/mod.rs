//! What the runtime's integration tests share (`mod common;` in each test file).

#![allow(dead_code)] // each test file uses some of it

use reachc_runtime::app::run_cli;
use reachc_runtime::model::{Analysis, AnalysisSpec, Constants, Method, ModelInfo, NoConstants};
use reachc_runtime::system::Paired;
use reachc_runtime::System;

/// The analysis `name` of the decay models (`dx = -x dt + s dW` from about 1): `method` over
/// `[0, 1]` in report steps of 0.1 at `delta = 0.01`, with `constants`.
pub fn decay_analysis(
    name: &str,
    method: Method,
    constants: Result<Constants, NoConstants>,
) -> Analysis {
    Analysis {
        spec: AnalysisSpec {
            name: name.into(),
            method,
            delta: 0.01,
            horizon: 1.0,
            step: 0.1,
            ..AnalysisSpec::default()
        },
        constants,
    }
}

/// A generated binary's `main` for `sys` and `info` on the command line `args`: its exit code,
/// stdout and stderr.
pub fn run_main<S: System + Sync>(
    sys: &S,
    info: &ModelInfo,
    args: &[&str],
) -> (u8, String, String) {
    let args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = run_cli(&Paired::new(sys, info), &args, &mut out, &mut err);
    (
        code,
        String::from_utf8(out).unwrap(),
        String::from_utf8(err).unwrap(),
    )
}
