//! A discrete-time model as the simulation's loops step it (method.md 8.16): the loops take
//! `x + h f(x) + G(x) sqrt(h) z`, so a map `x -> f(x) + G(x) z` is simulated as the system
//! whose drift is the increment `f(x) - x`, with `h = sqrt(h) = 1` ([`Span::map`]): one step
//! of the loops is one step of the map, the noise exact (no discretisation error; rounding
//! of `x + (f(x) - x)` aside, within an ulp of `f(x)`).
//!
//! [`Span::map`]: super::paths::Span::map

use crate::interval::Interval;
use crate::lanes::X8;
use crate::system::System;

/// The increments `f(x) - x` of the map `f` of a discrete-time system.
pub(crate) struct Increments<'a, S: ?Sized>(pub(crate) &'a S);

impl<S: System + ?Sized> System for Increments<'_, S> {
    fn n(&self) -> usize {
        self.0.n()
    }
    fn p(&self) -> usize {
        self.0.p()
    }
    fn m(&self) -> usize {
        self.0.m()
    }
    fn drift(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
        self.0.drift(x, u, t, out);
        for (o, v) in out.iter_mut().zip(x) {
            *o -= v;
        }
    }
    fn drift_x8(&self, x: &[X8], u: &[X8], t: f64, out: &mut [X8]) {
        self.0.drift_x8(x, u, t, out);
        for (o, v) in out.iter_mut().zip(x) {
            *o = *o - *v;
        }
    }
    fn drift_interval(&self, x: &[Interval], u: &[Interval], t: Interval, out: &mut [Interval]) {
        self.0.drift_interval(x, u, t, out);
        for (o, v) in out.iter_mut().zip(x) {
            *o -= *v;
        }
    }
    fn jac_x(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
        self.0.jac_x(x, u, t, out);
        let n = x.len();
        for i in 0..n {
            out[i * n + i] -= 1.0;
        }
    }
    fn jac_x_interval(&self, x: &[Interval], u: &[Interval], t: Interval, out: &mut [Interval]) {
        self.0.jac_x_interval(x, u, t, out);
        let n = x.len();
        for i in 0..n {
            out[i * n + i] -= Interval::ONE;
        }
    }
    fn jac_u(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
        self.0.jac_u(x, u, t, out);
    }
    fn jac_u_interval(&self, x: &[Interval], u: &[Interval], t: Interval, out: &mut [Interval]) {
        self.0.jac_u_interval(x, u, t, out);
    }
    fn diffusion(&self, x: &[f64], t: f64, out: &mut [f64]) {
        self.0.diffusion(x, t, out);
    }
    fn diffusion_x8(&self, x: &[X8], t: f64, out: &mut [X8]) {
        self.0.diffusion_x8(x, t, out);
    }
    fn diffusion_interval(&self, x: &[Interval], t: Interval, out: &mut [Interval]) {
        self.0.diffusion_interval(x, t, out);
    }
    fn set_numbers(&self, t: Interval, out: &mut [Interval]) {
        self.0.set_numbers(t, out);
    }
}
