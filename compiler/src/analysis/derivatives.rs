//! Exact symbolic Jacobians of the drift and diffusion.

use crate::ir::{ExprId, Var};
use crate::model::Model;

/// The Jacobians of a model, as IR expressions (the constant 0 where an entry vanishes).
#[derive(Clone, Debug)]
pub struct Derivatives {
    /// `D_x f`: `[equation i][state j] = d f_i / d x_j`.
    pub jac_x: Vec<Vec<ExprId>>,
    /// `D_u f`: `[equation i][input j] = d f_i / d u_j`.
    pub jac_u: Vec<Vec<ExprId>>,
    /// `D_x G`: `[state i][noise k][state j] = d G_ik / d x_j`.
    pub jac_g: Vec<Vec<Vec<ExprId>>>,
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
        let jac_g = model
            .diffusion
            .iter()
            .map(|row| row.iter().map(|&g| gradient(g, n, state)).collect())
            .collect();
        Derivatives {
            jac_x,
            jac_u,
            jac_g,
        }
    }
}
