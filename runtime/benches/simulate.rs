//! Monte Carlo path-steps per second on the paper's linear example (specs/linear.sde: n = 2,
//! two noise channels, step 0.01, horizon 1.5: 150 Euler-Maruyama steps per path). `Linear`
//! below is what `reachc build specs/linear.sde` generates for the methods the simulation calls
//! (drift and diffusion; the Jacobians are not used by it).
//!
//! Each iteration simulates `PATHS` paths; divan reports the time per iteration, so
//! path-steps/s = PATHS * 150 / time. `--threads` (divan) does not apply: the simulation uses
//! its own pool of `threads` workers.

use reachc_runtime::engine;
use reachc_runtime::interval::Interval;
use reachc_runtime::model::*;
use reachc_runtime::simulate::{self, Options};
use reachc_runtime::system::Paired;
use reachc_runtime::System;
use reachc_runtime::X8;
use reachc_test_support::models::model;

/// Paths per iteration.
const PATHS: u64 = 100_000;

fn main() {
    divan::main();
}

/// The generated model of specs/linear.sde.
struct Linear;

// As the generated code (which writes the folded constants as literals).
#[allow(clippy::approx_constant)]
impl System for Linear {
    fn n(&self) -> usize {
        2
    }
    fn p(&self) -> usize {
        0
    }
    fn m(&self) -> usize {
        2
    }
    fn drift(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        let v6 = -(0.4 * x[0]);
        let v8 = -(0.4 * x[1]);
        out[0] = v6;
        out[1] = v8;
    }
    #[inline]
    fn drift_x8(&self, x: &[X8], _u: &[X8], _t: f64, out: &mut [X8]) {
        let v6 = -(0.4 * x[0]);
        let v8 = -(0.4 * x[1]);
        out[0] = v6;
        out[1] = v8;
    }
    fn drift_interval(&self, x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = -(Interval::point(0.4) * x[0]);
        out[1] = -(Interval::point(0.4) * x[1]);
    }
    fn jac_x(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out.copy_from_slice(&[-0.4, 0.0, 0.0, -0.4]);
    }
    fn jac_x_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        for (o, v) in out.iter_mut().zip([-0.4, 0.0, 0.0, -0.4]) {
            *o = Interval::point(v);
        }
    }
    fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, _out: &mut [f64]) {}
    fn jac_u_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, _o: &mut [Interval]) {}
    fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
        out.copy_from_slice(&[1.4142135623730951, 0.0, 0.0, 1.4142135623730951]);
    }
    fn diffusion_interval(&self, _x: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::point(1.4142135623730951);
        out[1] = Interval::ZERO;
        out[2] = Interval::ZERO;
        out[3] = Interval::point(1.4142135623730951);
    }
}

/// The `amgf_rule` analysis of specs/linear.sde with the compiler's constants.
fn info() -> ModelInfo {
    let mut info = model("linear", &["x1", "x2"], &["w1", "w2"], &[(0.0, 0.0); 2]);
    let constants = Constants::given(
        &info,
        vec![1.0, 0.0, 0.0, 1.0],
        -0.4,
        1.4142135623730954,
        0.0,
    );
    info.analyses_mut().push(Analysis {
        spec: AnalysisSpec {
            name: "amgf_rule".into(),
            horizon: 1.5,
            step: 0.01,
            outputs: vec![0, 1],
            ..AnalysisSpec::default()
        },
        constants: Ok(constants),
    });
    info
}

/// `PATHS` paths of the linear example on 1 and 2 worker threads.
#[divan::bench(args = [1, 2], sample_count = 5, sample_size = 1)]
fn linear_100k_paths(bencher: divan::Bencher, threads: usize) {
    let info = info();
    let result = engine::run_paired(&Linear, &info, &info.analyses()[0]).unwrap();
    let opts = Options {
        paths: PATHS,
        threads: Some(threads),
        ..Options::default()
    };
    bencher.bench(|| {
        simulate::simulate(&Paired::new(&Linear, &info), &result, &opts, &mut |_, _| {})
            .unwrap()
            .horizon
            .outside_any
    });
}
