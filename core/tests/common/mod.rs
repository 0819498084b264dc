//! What the core integration tests share: the paper's pendulum as a hand-written `System`.

use reachc_core::interval::Interval;
use reachc_core::System;

/// `theta' = omega`, `omega' = k sin(theta) - 20 theta - 20 omega` (the paper's pendulum for
/// `k = 10`, linear for `k = 0`), noise `0.1` on omega.
pub struct Pend {
    /// The gain of `sin(theta)`.
    pub k: f64,
}

impl Pend {
    /// The paper's pendulum (`k = 10`).
    pub const PAPER: Pend = Pend { k: 10.0 };
}

impl System for Pend {
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
        out[1] = self.k * x[0].sin() - 20.0 * x[0] - 20.0 * x[1];
    }
    fn drift_interval(&self, x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = x[1];
        out[1] = Interval::point(self.k) * x[0].sin() - 20.0 * x[0] - 20.0 * x[1];
    }
    fn jac_x(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out.copy_from_slice(&[0.0, 1.0, self.k * x[0].cos() - 20.0, -20.0]);
    }
    fn jac_x_interval(&self, x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::ZERO;
        out[1] = Interval::ONE;
        out[2] = Interval::point(self.k) * x[0].cos() - 20.0;
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
