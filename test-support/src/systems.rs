//! Hand-written [`System`]s: the paper's pendulum and diagonal linear SDEs (with an input or
//! without), for tests that need a model without compiling a spec.
//!
//! This file is also compiled into reachc-core's own unit tests (`core/src/test_support.rs`),
//! so it takes the crate's names from its parent module.

use super::{Interval, System};

/// `theta' = omega`, `omega' = k sin(theta) - 20 theta - 20 omega`, noise `0.1 dW` on omega:
/// the paper's pendulum for `k = 10` (specs/pendulum.sde), linear for `k = 0`. One noise
/// channel on the second state: a constant `G` that is not diagonal.
pub struct Pendulum {
    /// The gain of `sin(theta)`.
    pub k: f64,
}

impl Pendulum {
    /// The paper's pendulum (`k = 10`).
    pub const PAPER: Pendulum = Pendulum { k: 10.0 };
}

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
    fn jac_u_interval(&self, _: &[Interval], _: &[Interval], _: Interval, _: &mut [Interval]) {}
    fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
        out.copy_from_slice(&[0.0, 0.1]);
    }
    fn diffusion_interval(&self, _x: &[Interval], _t: Interval, out: &mut [Interval]) {
        out[0] = Interval::ZERO;
        out[1] = Interval::point(0.1);
    }
}

/// `dx_i = (a x_i + b u) dt + s dW_i` for each of `n` states: one noise channel per state and
/// one input shared by all (`b = 0`: no input). In the identity metric its rate is `c = a` and
/// its noise bound `sigma = s`.
pub struct Linear {
    /// The number of states (and of noise channels).
    pub n: usize,
    /// The drift's diagonal.
    pub a: f64,
    /// The input's gain (0: the model has no input).
    pub b: f64,
    /// The diffusion's diagonal.
    pub s: f64,
}

impl Linear {
    /// `dx = (-x + u) dt + 0.1 dW`, one state, `u` in the model's input box.
    pub const WITH_INPUT: Linear = Linear {
        n: 1,
        a: -1.0,
        b: 1.0,
        s: 0.1,
    };
}

impl System for Linear {
    fn n(&self) -> usize {
        self.n
    }
    fn p(&self) -> usize {
        usize::from(self.b != 0.0)
    }
    fn m(&self) -> usize {
        self.n
    }
    fn drift(&self, x: &[f64], u: &[f64], _t: f64, out: &mut [f64]) {
        for i in 0..self.n {
            out[i] = self.a * x[i] + u.first().map_or(0.0, |u| self.b * u);
        }
    }
    fn drift_interval(&self, x: &[Interval], u: &[Interval], _t: Interval, out: &mut [Interval]) {
        for i in 0..self.n {
            out[i] = Interval::point(self.a) * x[i]
                + u.first()
                    .map_or(Interval::ZERO, |&u| Interval::point(self.b) * u);
        }
    }
    fn jac_x(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out.fill(0.0);
        for i in 0..self.n {
            out[i * self.n + i] = self.a;
        }
    }
    fn jac_x_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out.fill(Interval::ZERO);
        for i in 0..self.n {
            out[i * self.n + i] = Interval::point(self.a);
        }
    }
    fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out.fill(self.b);
    }
    fn jac_u_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, out: &mut [Interval]) {
        out.fill(Interval::point(self.b));
    }
    fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
        out.fill(0.0);
        for i in 0..self.n {
            out[i * self.n + i] = self.s;
        }
    }
    fn diffusion_interval(&self, _x: &[Interval], _t: Interval, out: &mut [Interval]) {
        out.fill(Interval::ZERO);
        for i in 0..self.n {
            out[i * self.n + i] = Interval::point(self.s);
        }
    }
}
