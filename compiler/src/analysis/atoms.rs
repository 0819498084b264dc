//! Splitting a matrix of expressions into `M0 + sum_k a_k M_k` with scalar atoms `a_k`.
//!
//! `mu_P` is convex, so bounding it over the vertices of the atoms' box bounds it over the hull
//! of all matrices the model can produce (method.md section 3). For the pendulum this yields
//! `J0 = [[0, 1], [-20, -20]]`, one atom `cos(theta)` in `[-1, 1]` with `J1 = [[0, 0], [10, 0]]`:
//! the paper's `conv{A1, A2}`.

use crate::ir::{ExprId, Node, Pool};

/// One atom: a non-constant scalar sub-expression and where it enters the matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct Atom {
    /// The atom `a_k` (a non-constant expression, without numeric coefficient).
    pub expr: ExprId,
    /// `M_k` as sparse entries `(row, column, coefficient)`.
    pub entries: Vec<(usize, usize, f64)>,
}

/// `M = M0 + sum_k a_k M_k`.
#[derive(Clone, Debug, PartialEq)]
pub struct AtomSplit {
    /// The constant part `M0`.
    pub constant: Vec<Vec<f64>>,
    /// The atoms, in order of first appearance (row-major).
    pub atoms: Vec<Atom>,
}

/// Splits `matrix` (rows of expressions) into constant part and atoms.
///
/// An entry `c0 + sum c_i t_i` (a canonical sum) contributes `c0` to `M0` and each term `t_i`
/// as an atom with coefficient `c_i`; any other non-constant entry is one atom with
/// coefficient 1. Equal terms in different entries are one atom (hash-consing makes them the
/// same id), so `cos(theta)` appearing twice is still one atom.
pub fn split_atoms(pool: &Pool, matrix: &[Vec<ExprId>]) -> AtomSplit {
    let cols = matrix.first().map_or(0, Vec::len);
    let mut constant = vec![vec![0.0; cols]; matrix.len()];
    let mut atoms: Vec<Atom> = Vec::new();
    let mut index: rustc_hash::FxHashMap<ExprId, usize> = Default::default();
    let mut add = |expr: ExprId, i: usize, j: usize, c: f64| {
        let k = *index.entry(expr).or_insert_with(|| {
            atoms.push(Atom {
                expr,
                entries: Vec::new(),
            });
            atoms.len() - 1
        });
        atoms[k].entries.push((i, j, c));
    };
    for (i, row) in matrix.iter().enumerate() {
        for (j, &e) in row.iter().enumerate() {
            match pool.node(e) {
                Node::Const(c) => constant[i][j] = c.get(),
                Node::Sum {
                    constant: c0,
                    terms,
                } => {
                    constant[i][j] = c0.get();
                    for (t, c) in terms {
                        add(*t, i, j, c.get());
                    }
                }
                _ => add(e, i, j, 1.0),
            }
        }
    }
    AtomSplit { constant, atoms }
}
