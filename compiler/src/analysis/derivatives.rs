//! Exact symbolic Jacobians of the drift and diffusion.

use crate::ir::{ExprId, Var};
use crate::model::Model;

/// One non-zero entry of `D_x G`: `d G[row][noise] / d x[state]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GradEntry {
    /// The state `i` of the diffusion row.
    pub row: usize,
    /// The noise channel `k`.
    pub noise: usize,
    /// The state `j` differentiated against.
    pub state: usize,
    /// The derivative.
    pub expr: ExprId,
}

/// The Jacobians of a model, as IR expressions.
#[derive(Clone, Debug)]
pub struct Derivatives {
    /// `D_x f`: `[equation i][state j] = d f_i / d x_j` (the constant 0 where it vanishes).
    pub jac_x: Vec<Vec<ExprId>>,
    /// `D_u f`: `[equation i][input j] = d f_i / d u_j`.
    pub jac_u: Vec<Vec<ExprId>>,
    /// `D_x G`: its non-zero entries, ordered by (row, noise, state). Sparse because the dense
    /// tensor has n * m * n entries (10^9 for a 1000-state chain with a noise per state).
    pub jac_g: Vec<GradEntry>,
}

impl Derivatives {
    /// Differentiates the model's drift and diffusion (adding the derivatives to its pool).
    ///
    /// Only the variables an expression depends on are differentiated against, so the cost
    /// grows with the size of the expressions, not with n^2 (a 1000-state chain has a
    /// million Jacobian entries, almost all of them the shared constant 0).
    pub fn of(model: &mut Model) -> Derivatives {
        let n = model.states.len();
        let p = model.inputs.len();
        let pool = &mut model.pool;
        let zero = pool.num(0.0);
        let mut gradient = |e: ExprId, len: usize, pick: fn(Var) -> Option<u32>| {
            let mut row = vec![zero; len];
            for v in pool.vars_of(e) {
                if let Some(j) = pick(v) {
                    row[j as usize] = pool.diff(e, v);
                }
            }
            row
        };
        let state = |v| if let Var::State(j) = v { Some(j) } else { None };
        let input = |v| if let Var::Input(j) = v { Some(j) } else { None };
        let jac_x = model.drift.iter().map(|&f| gradient(f, n, state)).collect();
        let jac_u = model.drift.iter().map(|&f| gradient(f, p, input)).collect();
        let mut jac_g = Vec::new();
        for (row, g_row) in model.diffusion.iter().enumerate() {
            for (noise, &g) in g_row.iter().enumerate() {
                for v in pool.vars_of(g) {
                    if let Some(j) = state(v) {
                        let expr = pool.diff(g, v);
                        if pool.as_const(expr) != Some(0.0) {
                            jac_g.push(GradEntry {
                                row,
                                noise,
                                state: j as usize,
                                expr,
                            });
                        }
                    }
                }
            }
        }
        Derivatives {
            jac_x,
            jac_u,
            jac_g,
        }
    }
}
