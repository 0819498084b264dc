//! Exact symbolic Jacobians of the drift and diffusion.

use crate::ir::{ExprId, Pool, Var};
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
    /// The entries `(i, j)` of `D_x f` where `f_i` depends on `x_j`, with their expressions, in
    /// row-major order (the layout of the runtime's `System::jac_x_pattern`). This is the
    /// dependency structure, so it also lists entries whose derivative vanishes although `f_i`
    /// depends on `x_j` (e.g. through `sign`): engines may rely on `f_i` ignoring the others.
    pub fn jac_x_dependencies(&self, pool: &Pool, drift: &[ExprId]) -> Vec<(usize, usize, ExprId)> {
        let mut out = Vec::new();
        for (i, (&f, row)) in drift.iter().zip(&self.jac_x).enumerate() {
            let mut cols: Vec<usize> = pool
                .vars_of(f)
                .into_iter()
                .filter_map(|v| match v {
                    Var::State(j) => Some(j as usize),
                    _ => None,
                })
                .collect();
            cols.sort_unstable();
            out.extend(cols.into_iter().map(|j| (i, j, row[j])));
        }
        out
    }

    /// Differentiates the model's drift and diffusion (adding the derivatives to its pool).
    ///
    /// Only the variables an expression depends on are differentiated against, so the cost
    /// grows with the size of the expressions, not with n^2 (a 1000-state chain has a
    /// million Jacobian entries, almost all of them the shared constant 0).
    pub fn of(model: &mut Model) -> Derivatives {
        let (n, p) = (model.states.len(), model.inputs.len());
        Derivatives::of_exprs(&mut model.pool, n, p, &model.drift, &model.diffusion)
    }

    /// The Jacobians of a drift and diffusion given as expressions of `pool` over `n` states and
    /// `p` inputs (e.g. a transformed system's, see [`super::Frame`]).
    pub fn of_exprs(
        pool: &mut Pool,
        n: usize,
        p: usize,
        drift: &[ExprId],
        diffusion: &[Vec<ExprId>],
    ) -> Derivatives {
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
        let jac_x = drift.iter().map(|&f| gradient(f, n, state)).collect();
        let jac_u = drift.iter().map(|&f| gradient(f, p, input)).collect();
        let mut jac_g = Vec::new();
        for (row, g_row) in diffusion.iter().enumerate() {
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
