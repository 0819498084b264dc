//! Test support (feature `test-util`): a hand-written system paired with hand-made model data,
//! for tests of code that takes a [`Model`] (the runtime's command line, the Monte Carlo).

use super::{Model, System};
use crate::interval::Interval;
use crate::lanes::X8;
use crate::model::ModelInfo;

/// `sys` with the model data `info`, as a [`Model`]. Every [`System`] method is forwarded,
/// the provided ones included, so the pair behaves as `sys` does.
#[derive(Clone, Copy)]
pub struct Paired<'a, S: ?Sized> {
    sys: &'a S,
    info: &'a ModelInfo,
}

impl<'a, S: System + ?Sized> Paired<'a, S> {
    /// `sys` with `info`.
    pub fn new(sys: &'a S, info: &'a ModelInfo) -> Paired<'a, S> {
        Paired { sys, info }
    }
}

impl<S: System + ?Sized> Model for Paired<'_, S> {
    fn info(&self) -> &ModelInfo {
        self.info
    }
}

impl<S: System + ?Sized> System for Paired<'_, S> {
    fn n(&self) -> usize {
        self.sys.n()
    }
    fn p(&self) -> usize {
        self.sys.p()
    }
    fn m(&self) -> usize {
        self.sys.m()
    }
    fn drift(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
        self.sys.drift(x, u, t, out);
    }
    fn drift_x8(&self, x: &[X8], u: &[X8], t: f64, out: &mut [X8]) {
        self.sys.drift_x8(x, u, t, out);
    }
    fn drift_interval(&self, x: &[Interval], u: &[Interval], t: Interval, out: &mut [Interval]) {
        self.sys.drift_interval(x, u, t, out);
    }
    fn jac_x(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
        self.sys.jac_x(x, u, t, out);
    }
    fn jac_x_interval(&self, x: &[Interval], u: &[Interval], t: Interval, out: &mut [Interval]) {
        self.sys.jac_x_interval(x, u, t, out);
    }
    fn jac_x_pattern(&self) -> Vec<(usize, usize)> {
        self.sys.jac_x_pattern()
    }
    fn jac_x_sparse_interval(
        &self,
        x: &[Interval],
        u: &[Interval],
        t: Interval,
        out: &mut [Interval],
    ) {
        self.sys.jac_x_sparse_interval(x, u, t, out);
    }
    fn jac_u(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
        self.sys.jac_u(x, u, t, out);
    }
    fn jac_u_interval(&self, x: &[Interval], u: &[Interval], t: Interval, out: &mut [Interval]) {
        self.sys.jac_u_interval(x, u, t, out);
    }
    fn diffusion(&self, x: &[f64], t: f64, out: &mut [f64]) {
        self.sys.diffusion(x, t, out);
    }
    fn diffusion_x8(&self, x: &[X8], t: f64, out: &mut [X8]) {
        self.sys.diffusion_x8(x, t, out);
    }
    fn diffusion_interval(&self, x: &[Interval], t: Interval, out: &mut [Interval]) {
        self.sys.diffusion_interval(x, t, out);
    }
    fn frame(&self, k: usize) -> Option<&dyn System> {
        self.sys.frame(k)
    }
    fn set_numbers(&self, t: Interval, out: &mut [Interval]) {
        self.sys.set_numbers(t, out);
    }
}
