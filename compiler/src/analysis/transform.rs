//! Coordinate transforms `y = T x` of the interval method (method.md, section 6).
//!
//! The transformed system is built symbolically: every state `x_i` is replaced by
//! `(T^-1 y)_i`, and the drift and diffusion become `f_y(y, u, t) = T f(T^-1 y, u, t)` and
//! `G_y(y, t) = T G(T^-1 y, t)`, rebuilt through the pool's simplifying constructors. The
//! simplification is the point: linear terms of `T f(T^-1 y)` merge (for the paper's pendulum,
//! `y1' = -15 y1 + 11 y2 + 2 sin(y2)`), so each `y_i` occurs once where the unsimplified
//! composition repeats it, and the natural inclusion stays tight instead of diverging.

use super::Derivatives;
use crate::ir::{ExprId, Var};
use crate::model::{Model, Transform};

/// A transformed system `y = T x`: its drift, diffusion and Jacobians, as expressions of the
/// model's pool in which `Var::State(j)` stands for `y_j`.
#[derive(Clone, Debug)]
pub struct Frame {
    /// `T` and `T^-1`.
    pub transform: Transform,
    /// `f_y`, one per coordinate `y_i`.
    pub drift: Vec<ExprId>,
    /// `G_y[i][k]`.
    pub diffusion: Vec<Vec<ExprId>>,
    /// `D_y f_y`, `D_u f_y` and `D_y G_y`.
    pub derivatives: Derivatives,
}

impl Frame {
    /// Builds the transformed system of `model` (adding its expressions to the model's pool).
    pub fn of(model: &mut Model, transform: &Transform) -> Frame {
        let (n, p) = (model.states.len(), model.inputs.len());
        let pool = &mut model.pool;
        let ys: Vec<ExprId> = (0..n as u32).map(|j| pool.var(Var::State(j))).collect();
        // x_i = sum_j (T^-1)_ij y_j.
        let xs: Vec<ExprId> = transform
            .inverse
            .chunks(n)
            .map(|row| combine(pool, row, &ys))
            .collect();
        let substituted = |pool: &mut crate::ir::Pool, e: ExprId| {
            pool.substitute(e, &mut |v| match v {
                Var::State(i) => Some(xs[i as usize]),
                _ => None,
            })
        };
        let f: Vec<ExprId> = model.drift.iter().map(|&e| substituted(pool, e)).collect();
        let g: Vec<Vec<ExprId>> = model
            .diffusion
            .iter()
            .map(|row| row.iter().map(|&e| substituted(pool, e)).collect())
            .collect();
        let m = model.noises.len();
        let drift: Vec<ExprId> = transform
            .matrix
            .chunks(n)
            .map(|row| combine(pool, row, &f))
            .collect();
        let diffusion: Vec<Vec<ExprId>> = transform
            .matrix
            .chunks(n)
            .map(|row| {
                (0..m)
                    .map(|k| {
                        let column: Vec<ExprId> = g.iter().map(|g_row| g_row[k]).collect();
                        combine(pool, row, &column)
                    })
                    .collect()
            })
            .collect();
        let derivatives = Derivatives::of_exprs(pool, n, p, &drift, &diffusion);
        Frame {
            transform: transform.clone(),
            drift,
            diffusion,
            derivatives,
        }
    }
}

/// `sum_j coef_j e_j`, simplified (zero coefficients dropped).
fn combine(pool: &mut crate::ir::Pool, coefs: &[f64], es: &[ExprId]) -> ExprId {
    let terms: Vec<ExprId> = coefs
        .iter()
        .zip(es)
        .filter(|(&c, _)| c != 0.0)
        .map(|(&c, &e)| {
            let c = pool.num(c);
            pool.mul(c, e)
        })
        .collect();
    pool.sum(&terms)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::driver::check_source;
    use crate::ir::Names;

    fn pendulum() -> Model {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../specs");
        let src = std::fs::read_to_string(dir.join("pendulum.sde")).unwrap();
        check_source(&src, &dir).0.unwrap()
    }

    /// The paper's pendulum in `y = T x` simplifies to one occurrence of each `y_i` per term:
    /// `y1' = -15 y1 + 11 y2 + 2 sin(y2)` (up to rounding of the folded coefficients).
    #[test]
    fn pendulum_frame_is_simplified() {
        let mut model = pendulum();
        let t = model.analyses[1].spec.transform.clone().unwrap();
        let frame = Frame::of(&mut model, &t);
        let names = ["y1".to_string(), "y2".to_string()];
        let noises = ["w".to_string()];
        let sde = Names {
            states: &names,
            inputs: &[],
            noises: &noises,
            tables: &model.tables,
        };
        let printed: Vec<String> = frame
            .drift
            .iter()
            .map(|&e| model.pool.to_sde(e, &sde))
            .collect();
        // Each y_j occurs once per equation (the composition repeats y2 in theta and omega).
        assert_eq!(printed, ["11*y2 - 15*y1 + 2*sin(y2)", "5*y1 - 5*y2"]);
    }

    /// `f_y(y) = T f(T^-1 y)` and `G_y = T G(T^-1 y)` by value at random points, and the frame's
    /// Jacobian against central differences.
    #[test]
    fn frame_matches_composition_and_differences() {
        let mut model = pendulum();
        let t = model.analyses[1].spec.transform.clone().unwrap();
        let frame = Frame::of(&mut model, &t);
        let eval = |model: &Model, roots: &[ExprId], x: &[f64]| -> Vec<f64> {
            let vars = crate::ir::VarValues {
                states: x,
                inputs: &[],
                noises: &[],
                time: 0.0,
            };
            let order = model.pool.reachable(roots);
            model.pool.eval_ordered(&order, roots, &vars, &model.tables)
        };
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for _ in 0..50 {
            let y = [next(), next()];
            let x: Vec<f64> = t
                .inverse
                .chunks(2)
                .map(|r| r[0] * y[0] + r[1] * y[1])
                .collect();
            let f = eval(&model, &model.drift, &x);
            let fy = eval(&model, &frame.drift, &y);
            for i in 0..2 {
                let want = t.matrix[2 * i] * f[0] + t.matrix[2 * i + 1] * f[1];
                assert!((fy[i] - want).abs() <= 1e-12 * (1.0 + want.abs()), "{fy:?}");
            }
            let g = eval(&model, &[model.diffusion[1][0]], &x)[0];
            let gy: Vec<ExprId> = frame.diffusion.iter().map(|r| r[0]).collect();
            let gy = eval(&model, &gy, &y);
            for (gyi, row) in gy.iter().zip(t.matrix.chunks(2)) {
                assert!((gyi - row[1] * g).abs() <= 1e-15);
            }
            let h = 1e-6;
            for j in 0..2 {
                let (mut yp, mut ym) = (y, y);
                yp[j] += h;
                ym[j] -= h;
                let (fp, fm) = (
                    eval(&model, &frame.drift, &yp),
                    eval(&model, &frame.drift, &ym),
                );
                let jac: Vec<ExprId> = frame.derivatives.jac_x.iter().map(|r| r[j]).collect();
                let jac = eval(&model, &jac, &y);
                for i in 0..2 {
                    let fd = (fp[i] - fm[i]) / (2.0 * h);
                    assert!(
                        (jac[i] - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                        "{jac:?} {fd}"
                    );
                }
            }
        }
    }
}
