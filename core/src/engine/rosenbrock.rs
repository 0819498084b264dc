//! A linearly implicit (Rosenbrock) step for the validated nominal of stiff models (method.md
//! section 8.4): where RK4 is unstable at the step length the defect allows (`h |J| > 2`, a
//! fast decaying mode), the nominal's nodes come from ROS2 instead, which is L-stable: its fast
//! modes are damped at any step length, so a trajectory on the slow manifold keeps steps of the
//! slow dynamics' length. Nothing here needs to be rigorous: the curve between the nodes is the
//! same cubic whichever integrator made them, and `defect.rs` bounds its defect.

use crate::system::System;

/// The most states for which the nominal tries this step (a dense `n x n` factorisation per
/// step; larger models keep RK4).
pub(crate) const MAX_STATES: usize = 64;

/// `|J|_inf h` above which an RK4 step that failed is retried with ROS2 (RK4's stability region
/// reaches about 2.8 along the real and the imaginary axes; `|J|_inf` bounds the spectral
/// radius).
pub(crate) const RK4_LIMIT: f64 = 2.0;

/// The infinity norm of `D_x f` at `(x, u, t)`.
pub(crate) fn jacobian_norm(sys: &dyn System, x: &[f64], u: &[f64], t: f64) -> f64 {
    let n = x.len();
    let mut j = vec![0.0; n * n];
    sys.jac_x(x, u, t, &mut j);
    j.chunks(n.max(1))
        .map(|row| row.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// One ROS2 step (Verwer, Spee, Blom and Hundsdorfer, SIAM J. Sci. Comput. 20, 1999) of length
/// `h` from `x` at `t` with the input `u` held, `gamma = 1 + 1/sqrt(2)`, `W = I - gamma h J(x)`:
/// `W k1 = f(x, t)`, `W k2 = f(x + h k1, t + h) - 2 k1`, `x1 = x + h (3 k1 + k2) / 2`. Second
/// order and L-stable. `None` if `W` is singular to working precision.
pub(crate) fn ros2(sys: &dyn System, x: &[f64], u: &[f64], t: f64, h: f64) -> Option<Vec<f64>> {
    let n = x.len();
    let gamma = 1.0 + std::f64::consts::FRAC_1_SQRT_2;
    let mut w = vec![0.0; n * n];
    sys.jac_x(x, u, t, &mut w);
    for (k, v) in w.iter_mut().enumerate() {
        *v = if k / n == k % n { 1.0 } else { 0.0 } - gamma * h * *v;
    }
    let lu = Lu::factor(w, n)?;
    let mut k1 = vec![0.0; n];
    sys.drift(x, u, t, &mut k1);
    lu.solve(&mut k1);
    let stage: Vec<f64> = x.iter().zip(&k1).map(|(a, k)| a + h * k).collect();
    let mut k2 = vec![0.0; n];
    sys.drift(&stage, u, t + h, &mut k2);
    for (a, b) in k2.iter_mut().zip(&k1) {
        *a -= 2.0 * b;
    }
    lu.solve(&mut k2);
    Some(
        (0..n)
            .map(|i| x[i] + 0.5 * h * (3.0 * k1[i] + k2[i]))
            .collect(),
    )
}

/// An LU factorisation with partial pivoting of an `n x n` matrix (row-major).
struct Lu {
    a: Vec<f64>,
    pivots: Vec<usize>,
    n: usize,
}

impl Lu {
    /// `None` if a pivot is zero or not finite.
    fn factor(mut a: Vec<f64>, n: usize) -> Option<Lu> {
        let mut pivots = Vec::with_capacity(n);
        for c in 0..n {
            let p = (c..n).max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))?;
            let pivot = a[p * n + c];
            if pivot == 0.0 || !pivot.is_finite() {
                return None;
            }
            if p != c {
                for k in 0..n {
                    a.swap(c * n + k, p * n + k);
                }
            }
            pivots.push(p);
            for i in c + 1..n {
                let f = a[i * n + c] / pivot;
                a[i * n + c] = f;
                for k in c + 1..n {
                    a[i * n + k] -= f * a[c * n + k];
                }
            }
        }
        Some(Lu { a, pivots, n })
    }

    /// `b <- A^-1 b`.
    fn solve(&self, b: &mut [f64]) {
        let (a, n) = (&self.a, self.n);
        for (c, &p) in self.pivots.iter().enumerate() {
            b.swap(c, p);
        }
        for i in 0..n {
            let s: f64 = (0..i).map(|k| a[i * n + k] * b[k]).sum();
            b[i] -= s;
        }
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|k| a[i * n + k] * b[k]).sum();
            b[i] = (b[i] - s) / a[i * n + i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interval::Interval;

    /// `x' = A x` with `A = [[0, 1], [-k, -d]]`: the mass-spring-damper of `specs/msd.sde`
    /// with a stiff damper.
    struct Msd {
        k: f64,
        d: f64,
    }

    impl System for Msd {
        fn n(&self) -> usize {
            2
        }
        fn p(&self) -> usize {
            0
        }
        fn m(&self) -> usize {
            0
        }
        fn drift(&self, x: &[f64], _: &[f64], _: f64, out: &mut [f64]) {
            out[0] = x[1];
            out[1] = -self.k * x[0] - self.d * x[1];
        }
        fn drift_interval(
            &self,
            x: &[Interval],
            _: &[Interval],
            _: Interval,
            out: &mut [Interval],
        ) {
            out[0] = x[1];
            out[1] = Interval::point(-self.k) * x[0] - Interval::point(self.d) * x[1];
        }
        fn jac_x(&self, _: &[f64], _: &[f64], _: f64, out: &mut [f64]) {
            out.copy_from_slice(&[0.0, 1.0, -self.k, -self.d]);
        }
        fn jac_x_interval(
            &self,
            _: &[Interval],
            _: &[Interval],
            _: Interval,
            out: &mut [Interval],
        ) {
            for (o, v) in out.iter_mut().zip([0.0, 1.0, -self.k, -self.d]) {
                *o = Interval::point(v);
            }
        }
        fn jac_u(&self, _: &[f64], _: &[f64], _: f64, _: &mut [f64]) {}
        fn jac_u_interval(&self, _: &[Interval], _: &[Interval], _: Interval, _: &mut [Interval]) {}
        fn diffusion(&self, _: &[f64], _: f64, _: &mut [f64]) {}
        fn diffusion_interval(&self, _: &[Interval], _: Interval, _: &mut [Interval]) {}
    }

    /// On the stiff damper (`d = 1e5`, eigenvalues about `-4e-5` and `-1e5`), steps of 0.05
    /// (`|J| h = 5000`, where RK4 explodes) from a point on the slow manifold follow the exact
    /// solution `x(t) = x0 e^(lambda t)` to its second order, and a start off the manifold
    /// lands near it (the fast mode damped).
    #[test]
    fn ros2_follows_the_slow_mode_of_a_stiff_damper() {
        let sys = Msd { k: 4.0, d: 1e5 };
        // The slow eigenvalue, and its eigenvector (1, lambda).
        // (In the form without cancellation.)
        let lambda = -2.0 * sys.k / (sys.d + (sys.d * sys.d - 4.0 * sys.k).sqrt());
        let mut x = vec![1.0, lambda];
        let h = 0.05;
        for k in 1..=100 {
            x = ros2(&sys, &x, &[], 0.0, h).unwrap();
            let exact = (lambda * h * k as f64).exp();
            assert!((x[0] - exact).abs() < 1e-9, "step {k}: {} vs {exact}", x[0]);
            assert!((x[1] - lambda * exact).abs() < 1e-9 * lambda.abs());
        }
        let rk4 = crate::engine::nominal::rk4(&sys, &[1.0, 0.0], &[], 0.0, h);
        assert!(rk4[1].abs() > 1e3, "RK4 is unstable there: {rk4:?}");
        // Off the manifold (v = 0, 4e-5 from it): one step damps the fast mode by the
        // stability function's |R(-5000)| < 2e-4.
        let x = ros2(&sys, &[1.0, 0.0], &[], 0.0, h).unwrap();
        assert!((x[1] - lambda * x[0]).abs() < 4e-5 * 2e-4, "{x:?}");
        assert!((jacobian_norm(&sys, &x, &[], 0.0) - (sys.k + sys.d)).abs() < 1e-9);
    }

    /// The factorisation solves a system that needs pivoting, and refuses a singular one.
    #[test]
    fn lu_solves_with_pivoting() {
        let lu = Lu::factor(vec![0.0, 2.0, 1.0, 3.0, 1.0, 1.0, 2.0, 0.0, 1.0], 3).unwrap();
        let mut b = vec![5.0, 8.0, 5.0];
        lu.solve(&mut b);
        let a = [0.0, 2.0, 1.0, 3.0, 1.0, 1.0, 2.0, 0.0, 1.0];
        for i in 0..3 {
            let r: f64 = (0..3).map(|k| a[i * 3 + k] * b[k]).sum();
            assert!((r - [5.0, 8.0, 5.0][i]).abs() < 1e-12);
        }
        assert!(Lu::factor(vec![1.0, 2.0, 2.0, 4.0], 2).is_none());
    }
}
