//! The expression IR: a hash-consed DAG of scalar expressions with a simplifier built into its
//! constructors, exact symbolic derivatives, printing in the `.sde` grammar, and evaluation in
//! `f64` and in outward-rounded intervals.
//!
//! Invariants every pass may rely on:
//! - a node's children always have smaller ids than the node (the pool is append-only), so
//!   iterating ids in increasing order is a topological order;
//! - structurally equal nodes have equal ids (hash-consing), so sub-expressions are shared;
//! - every node is in canonical simplified form (see [`Node`]).

mod diff;
mod eval;
mod fold;
mod node;
mod pool;
mod print;
mod shared;
mod table;
#[cfg(test)]
mod test_exprs;

pub use eval::{Arith, VarValues};
pub use node::{ExprId, Func1, Func2, Node, Var, F64};
pub use pool::Pool;
pub use print::Names;
pub use shared::SharedText;
pub use table::Table;
