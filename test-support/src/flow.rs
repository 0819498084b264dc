//! Reference flows of a [`System`], independent of the engines: classical RK4 steps of the
//! drift (the noise-free flow sets must hold) and Euler-Maruyama paths of the SDE.

use crate::rng::Rng;
use reachc_core::System;

/// One classical RK4 step of `h` of the drift of `sys` from `x` at time `t` with the inputs `u`
/// held over the step.
pub fn rk4_step(sys: &dyn System, x: &mut [f64], u: &[f64], t: f64, h: f64) {
    let n = x.len();
    let f = |y: &[f64], t: f64| {
        let mut out = vec![0.0; n];
        sys.drift(y, u, t, &mut out);
        out
    };
    let k1 = f(x, t);
    let y: Vec<f64> = (0..n).map(|i| x[i] + 0.5 * h * k1[i]).collect();
    let k2 = f(&y, t + 0.5 * h);
    let y: Vec<f64> = (0..n).map(|i| x[i] + 0.5 * h * k2[i]).collect();
    let k3 = f(&y, t + 0.5 * h);
    let y: Vec<f64> = (0..n).map(|i| x[i] + h * k3[i]).collect();
    let k4 = f(&y, t + h);
    for i in 0..n {
        x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

/// Advances `x` from time `*t` to `until` by [`rk4_step`]s of `h` of the noise-free drift of
/// `sys` (no inputs): the reference flow for sets of noise-free models.
pub fn rk4(sys: &dyn System, x: &mut [f64], t: &mut f64, until: f64, h: f64) {
    while *t < until - 1e-12 {
        rk4_step(sys, x, &[], *t, h);
        *t += h;
    }
}

/// Advances `x` from time `*t` to `until` by Euler-Maruyama steps of `dt` of the SDE of `sys`
/// (no inputs), drawing one normal per noise channel and step from `rng`.
pub fn euler_maruyama(
    sys: &dyn System,
    x: &mut [f64],
    t: &mut f64,
    until: f64,
    dt: f64,
    rng: &mut Rng,
) {
    let (n, m) = (sys.n(), sys.m());
    let (mut f, mut g) = (vec![0.0; n], vec![0.0; n * m]);
    while *t < until - 1e-12 {
        sys.drift(x, &[], *t, &mut f);
        sys.diffusion(x, *t, &mut g);
        let dw: Vec<f64> = (0..m).map(|_| rng.normal() * dt.sqrt()).collect();
        for i in 0..n {
            x[i] += f[i] * dt + (0..m).map(|j| g[i * m + j] * dw[j]).sum::<f64>();
        }
        *t += dt;
    }
}
