//! The report grid, and the nominal trajectory `x*_t` of `x' = f(x, u_c, t)` (centre input)
//! integrated with one step of an unvalidated integrator per report step (`integrator = rk4` or
//! `euler`, labelled not validated; the default is `defect.rs`).

use crate::model::Integrator;
use crate::system::System;

/// The report times `0 = t_0 < t_1 < ... < t_N = horizon`, spaced by `step`; the last step is
/// shortened so the grid ends exactly on the horizon.
///
/// A ratio `horizon / step` that is an integer up to rounding (e.g. `4 / 0.01`) does not
/// produce an extra sliver step.
pub(crate) fn time_grid(horizon: f64, step: f64) -> Vec<f64> {
    let ratio = horizon / step;
    let n = ((ratio * (1.0 - 1e-12)).ceil() as usize).max(if horizon > 0.0 { 1 } else { 0 });
    let mut ts: Vec<f64> = (0..n).map(|k| k as f64 * step).collect();
    ts.push(horizon);
    ts
}

/// One classical Runge-Kutta step of length `h` from `x` at `t` with the input `u` held.
pub(crate) fn rk4(sys: &dyn System, x: &[f64], u: &[f64], t: f64, h: f64) -> Vec<f64> {
    rk4_step(&mut |x, t, out| sys.drift(x, u, t, out), x, t, h).0
}

/// The right-hand side of `x' = rhs(x, t)`, writing into its last argument.
pub(crate) type Rhs<'a> = dyn FnMut(&[f64], f64, &mut [f64]) + 'a;

/// One classical Runge-Kutta step of length `h` of `x' = rhs(x, t)` from `x` at `t`: the end
/// and the slope at the start.
pub(crate) fn rk4_step(rhs: &mut Rhs, x: &[f64], t: f64, h: f64) -> (Vec<f64>, Vec<f64>) {
    let n = x.len();
    let (mut k1, mut k2, mut k3, mut k4) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut tmp = vec![0.0; n];
    rhs(x, t, &mut k1);
    for i in 0..n {
        tmp[i] = x[i] + 0.5 * h * k1[i];
    }
    rhs(&tmp, t + 0.5 * h, &mut k2);
    for i in 0..n {
        tmp[i] = x[i] + 0.5 * h * k2[i];
    }
    rhs(&tmp, t + 0.5 * h, &mut k3);
    for i in 0..n {
        tmp[i] = x[i] + h * k3[i];
    }
    rhs(&tmp, t + h, &mut k4);
    let x1 = (0..n)
        .map(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
        .collect();
    (x1, k1)
}

/// Integrates `x' = f(x, u_k, t)` over the grid with one step of the (unvalidated) integrator
/// per report step, `u_k = inputs[k]` on `[t_k, t_(k+1)]`; `Err(k)` with the index of the first
/// grid time where a state is not finite.
pub(crate) fn integrate(
    sys: &dyn System,
    x0: &[f64],
    inputs: &[Vec<f64>],
    grid: &[f64],
    integrator: Integrator,
) -> Result<Vec<Vec<f64>>, usize> {
    let n = x0.len();
    let mut out = Vec::with_capacity(grid.len());
    out.push(x0.to_vec());
    let mut x = x0.to_vec();
    let mut f = vec![0.0; n];
    for (idx, w) in grid.windows(2).enumerate() {
        let (t, h) = (w[0], w[1] - w[0]);
        let u = &inputs[idx];
        x = match integrator {
            Integrator::Euler => {
                sys.drift(&x, u, t, &mut f);
                x.iter().zip(&f).map(|(xi, fi)| xi + h * fi).collect()
            }
            _ => rk4(sys, &x, u, t, h),
        };
        if x.iter().any(|v| !v.is_finite()) {
            return Err(idx + 1);
        }
        out.push(x.clone());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_lands_on_horizon() {
        let g = time_grid(4.0, 0.01);
        assert_eq!(g.len(), 401);
        assert_eq!(*g.last().unwrap(), 4.0);
        let g = time_grid(1.05, 0.1);
        assert_eq!(g.len(), 12);
        assert!((g[10] - 1.0).abs() < 1e-12);
        assert_eq!(g[11], 1.05);
        assert_eq!(time_grid(0.0, 0.1), vec![0.0]);
    }
}
