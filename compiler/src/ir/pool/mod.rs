//! The hash-consed expression pool. Its constructors simplify, so every stored node is in the
//! canonical form documented on [`Node`].
//!
//! The pool itself is here (storage, interning, leaves and constants); the simplifying
//! constructors of sums, products and powers are in `arith.rs`, those of function calls in
//! `calls.rs`, and the traversals (reachability, variables, substitution) in `walk.rs`.

mod arith;
mod calls;
#[cfg(test)]
mod fixture;
mod walk;

// Fx hashing: ids and nodes are small keys hashed millions of times on large models, and
// hash-flooding is no concern for a compiler's own data.
use rustc_hash::FxHashMap as HashMap;

use reachc_core::interval::Interval;

use super::fold::Folded;
use super::node::{ExprId, Node, Var, F64};

/// A hash-consed DAG of expressions.
///
/// Nodes are only ever added (ids stay valid), a node's children have smaller ids than the node,
/// and structurally equal nodes share one id. All constructors simplify (see [`Node`] for the
/// canonical form): constants fold, like terms and like factors are collected, and `0`/`1`
/// identities disappear.
///
/// Constant folding never rounds silently (`fold.rs`): a fold whose floating-point value is
/// exact gives a `Const`, any other an `Enclosure` of the exact value (with the floating-point
/// value for point evaluation), so the IR of `x/3` is `E * x` with `E` enclosing `1/3`, and the
/// interval evaluation of every expression encloses the real-number expression it was built
/// from.
///
/// Folding that would produce a non-finite value (`1/0`, `log(-1)`, `exp(1000)`, a coefficient
/// overflowing to infinity) is not done: the node is kept unevaluated, even if this leaves a
/// constant child in a `Sum` or `Product` (the only departure from the canonical form; the
/// checker reports such constant expressions). Constructors never panic except [`Pool::num`]
/// on a non-finite argument.
#[derive(Clone, Debug, Default)]
pub struct Pool {
    nodes: Vec<Node>,
    map: HashMap<Node, ExprId>,
    /// `d node / d var`, filled by `diff` (in `diff.rs`).
    pub(super) diff_memo: HashMap<(ExprId, Var), ExprId>,
}

/// Calls `f` on each child of `node`.
pub(super) fn for_each_child(node: &Node, mut f: impl FnMut(ExprId)) {
    match node {
        Node::Const(_) | Node::Enclosure { .. } | Node::Var(_) => {}
        Node::Sum { terms, .. } => terms.iter().for_each(|&(t, _)| f(t)),
        Node::Product { factors } => factors.iter().for_each(|&(b, _)| f(b)),
        Node::Call1(_, a) => f(*a),
        Node::Call2(_, a, b) => {
            f(*a);
            f(*b);
        }
        Node::Table { arg, .. } => f(*arg),
    }
}

impl Pool {
    /// An empty pool.
    pub fn new() -> Self {
        Self::default()
    }

    /// The node with id `id`.
    pub fn node(&self, id: ExprId) -> &Node {
        &self.nodes[id.index()]
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the pool has no nodes.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Returns the id of `node`, adding it if it is new. Callers guarantee canonical form.
    pub(super) fn intern(&mut self, node: Node) -> ExprId {
        if let Some(&id) = self.map.get(&node) {
            return id;
        }
        let id = ExprId(u32::try_from(self.nodes.len()).expect("expression pool overflow"));
        self.nodes.push(node.clone());
        self.map.insert(node, id);
        id
    }

    /// The constant `v`. Panics if `v` is not finite.
    pub fn num(&mut self, v: f64) -> ExprId {
        self.intern(Node::Const(F64::new(v)))
    }

    /// The variable `v`.
    pub fn var(&mut self, v: Var) -> ExprId {
        self.intern(Node::Var(v))
    }

    /// The value of `id` if it is an exact constant (not an [`Node::Enclosure`]).
    pub fn as_const(&self, id: ExprId) -> Option<f64> {
        match self.node(id) {
            Node::Const(c) => Some(c.get()),
            _ => None,
        }
    }

    /// The floating-point value of `id` if it is a constant, exact or enclosed: what the spec's
    /// settings and sets take as the value of a constant expression (its round-to-nearest
    /// value, docs/language.md).
    pub fn as_value(&self, id: ExprId) -> Option<f64> {
        self.folded(id).map(|f| f.approx)
    }

    /// The constant `id` as a [`Folded`] value, if it is one.
    fn folded(&self, id: ExprId) -> Option<Folded> {
        match *self.node(id) {
            Node::Const(c) => Some(Folded::point(c.get())),
            Node::Enclosure { approx, lo, hi } => Some(Folded {
                approx: approx.get(),
                exact: Interval::new(lo.get(), hi.get()),
            }),
            _ => None,
        }
    }

    /// The constant whose floating-point value is `approx` and whose exact value lies in
    /// `exact`: a `Const` when `exact` is a point, else an [`Node::Enclosure`]. Panics if
    /// `approx` or `exact` is not finite.
    pub fn enclosure(&mut self, approx: f64, exact: Interval) -> ExprId {
        if exact.is_point() {
            return self.num(exact.lo());
        }
        assert!(
            exact.lo() <= approx && approx <= exact.hi(),
            "{approx} outside {exact}"
        );
        self.intern(Node::Enclosure {
            approx: F64::new(approx),
            lo: F64::new(exact.lo()),
            hi: F64::new(exact.hi()),
        })
    }

    /// The node of a folded constant.
    fn folded_node(&mut self, v: Folded) -> ExprId {
        self.enclosure(v.approx, v.exact)
    }

    pub(super) fn is_zero(&self, id: ExprId) -> bool {
        self.as_const(id) == Some(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::fixture::fx;
    use super::*;
    use crate::ir::Func1;

    #[test]
    fn hash_consing() {
        let mut f = fx();
        let (x, y) = (f.x, f.y);
        let build = |p: &mut Pool| {
            let s = p.call1(Func1::Sin, x);
            let a = p.mul(s, y);
            let b = p.add(a, x);
            p.call1(Func1::Exp, b)
        };
        let n0 = f.pool.len();
        let a = build(&mut f.pool);
        let n1 = f.pool.len();
        let b = build(&mut f.pool);
        assert_eq!(a, b);
        assert_eq!(f.pool.len(), n1);
        assert!(n1 > n0);
        assert_eq!(f.pool.var(Var::State(0)), x);
        let z1 = f.pool.num(0.0);
        let z2 = f.pool.num(-0.0);
        assert_eq!(z1, z2);
    }
}
