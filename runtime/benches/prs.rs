//! Timing of the contraction-based delta-PRS engine on the paper's pendulum (n = 2, hand-written
//! `System`, constants c = -0.5, P = [[35.68, 2.21], [2.21, 1.27]], sigma = 0.1130).
//!
//! Divan's throughput column (items = report steps) gives the time per step. `run` includes the
//! one-off costs (kappa, metric factorisation, result allocation); the 4000-step case amortises
//! them, so its per-step time is the marginal cost of a step (RK4 nominal + interval radii).

use divan::counter::ItemsCount;
use divan::Bencher;
use reachc_runtime::engine;
use reachc_runtime::interval::Interval;
use reachc_runtime::system::{
    Analysis, Constants, InitialSet, Integrator, Method, ModelInfo, RadiusRule, UnsafeSet,
    UnsafeShape,
};
use reachc_runtime::System;

fn main() {
    divan::main();
}

/// `theta' = omega`, `omega' = 10 sin(theta) - 20 theta - 20 omega`, `G = [0, 0.1]'`.
struct Pendulum;

impl System for Pendulum {
    fn n(&self) -> usize {
        2
    }
    fn p(&self) -> usize {
        0
    }
    fn m(&self) -> usize {
        1
    }
    fn drift(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = x[1];
        out[1] = 10.0 * x[0].sin() - 20.0 * x[0] - 20.0 * x[1];
    }
    fn drift_interval(&self, x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = x[1];
        out[1] = 10.0 * x[0].sin() - 20.0 * x[0] - 20.0 * x[1];
    }
    fn jac_x(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out.copy_from_slice(&[0.0, 1.0, 10.0 * x[0].cos() - 20.0, -20.0]);
    }
    fn jac_x_interval(&self, x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::ZERO;
        out[1] = Interval::ONE;
        out[2] = 10.0 * x[0].cos() - 20.0;
        out[3] = Interval::point(-20.0);
    }
    fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, _out: &mut [f64]) {}
    fn jac_u_interval(
        &self,
        _x: &[Interval],
        _u: &[Interval],
        _t: Interval,
        _out: &mut [Interval],
    ) {
    }
    fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
        out.copy_from_slice(&[0.0, 0.1]);
    }
    fn diffusion_interval(&self, _x: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::ZERO;
        out[1] = Interval::point(0.1);
    }
}

fn setup(step: f64, with_unsafe: bool) -> (ModelInfo, Analysis) {
    let pi10 = std::f64::consts::PI / 10.0;
    let info = ModelInfo {
        name: "pendulum".into(),
        states: vec!["theta".into(), "omega".into()],
        inputs: vec![],
        noises: vec!["w".into()],
        input_box: vec![],
        initial: InitialSet {
            boxes: vec![Some((-pi10, pi10)), Some((-0.2, 0.2))],
            balls: vec![],
        },
        domain: vec![(f64::NEG_INFINITY, f64::INFINITY); 2],
        has_domain: false,
        unsafe_sets: if with_unsafe {
            vec![
                UnsafeSet {
                    name: "theta_high".into(),
                    shape: UnsafeShape::HalfSpace {
                        normal: vec![1.0, 0.0],
                        offset: 1.0,
                    },
                },
                UnsafeSet {
                    name: "ball".into(),
                    shape: UnsafeShape::Ball {
                        states: vec![0, 1],
                        center: vec![0.0, 5.0],
                        radius: 0.5,
                    },
                },
            ]
        } else {
            vec![]
        },
        analyses: vec![],
    };
    let analysis = Analysis {
        name: "contraction".into(),
        method: Method::Contraction,
        delta: 1e-3,
        horizon: 4.0,
        step,
        radius: RadiusRule::Amgf,
        integrator: Integrator::Rk4,
        outputs: vec![],
        constants: Some(Constants {
            metric: vec![35.68, 2.21, 2.21, 1.27],
            c: -0.5,
            sigma: 0.1130,
            rho: 0.0,
            how: "paper".into(),
        }),
        constants_error: None,
    };
    (info, analysis)
}

/// Full `engine::run`, horizon 4: step 0.01 (401 report times) and 0.001 (4001).
#[divan::bench(args = [0.01, 0.001])]
fn contraction_run(bencher: Bencher, step: f64) {
    let (info, analysis) = setup(step, false);
    let steps = (4.0 / step).round() as usize + 1;
    bencher
        .counter(ItemsCount::new(steps))
        .bench(|| engine::run(&Pendulum, divan::black_box(&info), &analysis).unwrap());
}

/// Same with two unsafe sets checked at every step (half-space and ball).
#[divan::bench(args = [0.01])]
fn contraction_run_with_safety(bencher: Bencher, step: f64) {
    let (info, analysis) = setup(step, true);
    let steps = (4.0 / step).round() as usize + 1;
    bencher
        .counter(ItemsCount::new(steps))
        .bench(|| engine::run(&Pendulum, divan::black_box(&info), &analysis).unwrap());
}
