//! Traversals of the pool: the nodes reachable from roots, the variables an expression
//! uses, and substitution of variables through the simplifying constructors.

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use super::{for_each_child, Pool};
use crate::ir::node::{ExprId, Node, Var};

impl Pool {
    /// Ids of the nodes reachable from `roots` for which `skip` is false (not descending into
    /// skipped nodes), in increasing order. Iterative: DAG depth is not bounded by the parser.
    pub(in crate::ir) fn collect(
        &self,
        roots: &[ExprId],
        skip: impl Fn(ExprId) -> bool,
    ) -> Vec<ExprId> {
        let mut seen: HashSet<ExprId> = HashSet::default();
        let mut stack: Vec<ExprId> = Vec::new();
        for &r in roots {
            if !skip(r) && seen.insert(r) {
                stack.push(r);
            }
        }
        while let Some(id) = stack.pop() {
            for_each_child(self.node(id), |c| {
                if !skip(c) && seen.insert(c) {
                    stack.push(c);
                }
            });
        }
        let mut out: Vec<ExprId> = seen.into_iter().collect();
        out.sort_unstable();
        out
    }

    /// All nodes reachable from `roots` (roots included), in increasing id order, which is a
    /// topological order (children first).
    pub fn reachable(&self, roots: &[ExprId]) -> Vec<ExprId> {
        self.collect(roots, |_| false)
    }

    /// Number of distinct nodes reachable from `roots` (the DAG size, not the tree size).
    pub fn count_nodes(&self, roots: &[ExprId]) -> usize {
        self.reachable(roots).len()
    }

    /// The variables `e` depends on, sorted and deduplicated.
    pub fn vars_of(&self, e: ExprId) -> Vec<Var> {
        // Leaves are most entries of large sparse Jacobians and diffusion matrices.
        match self.node(e) {
            Node::Const(_) => return Vec::new(),
            Node::Var(v) => return vec![*v],
            _ => {}
        }
        let mut vars: Vec<Var> = self
            .reachable(&[e])
            .into_iter()
            .filter_map(|id| match self.node(id) {
                Node::Var(v) => Some(*v),
                _ => None,
            })
            .collect();
        vars.sort_unstable();
        vars.dedup();
        vars
    }

    /// Whether `v` occurs in `e` (syntactically: `x - x` was already simplified away).
    pub fn depends_on(&self, e: ExprId, v: Var) -> bool {
        let target = Node::Var(v);
        let Some(&vid) = self.map.get(&target) else {
            return false; // the variable was never created
        };
        if vid > e {
            return false; // children have smaller ids
        }
        let mut seen: HashSet<ExprId> = HashSet::default();
        let mut stack = vec![e];
        while let Some(id) = stack.pop() {
            if id == vid {
                return true;
            }
            for_each_child(self.node(id), |c| {
                if c >= vid && seen.insert(c) {
                    stack.push(c);
                }
            });
        }
        false
    }

    /// `e` with each variable `v` replaced by `f(v)` where that is `Some`, rebuilt through the
    /// simplifying constructors. `f` is called once per variable occurring in `e`; unchanged
    /// sub-expressions keep their ids.
    pub fn substitute(&mut self, e: ExprId, f: &mut dyn FnMut(Var) -> Option<ExprId>) -> ExprId {
        let order = self.reachable(&[e]);
        let mut map: HashMap<ExprId, ExprId> =
            HashMap::with_capacity_and_hasher(order.len(), Default::default());
        for id in order {
            let node = self.node(id).clone();
            let m = |c: ExprId| map[&c];
            let new = match node {
                Node::Const(_) | Node::Enclosure { .. } => id,
                Node::Var(v) => f(v).unwrap_or(id),
                Node::Sum { constant, terms } => {
                    if terms.iter().all(|&(t, _)| m(t) == t) {
                        id
                    } else {
                        let items = terms.iter().map(|&(t, c)| (m(t), c.get())).collect();
                        self.build_sum(constant.get(), items)
                    }
                }
                Node::Product { factors } => {
                    if factors.iter().all(|&(b, _)| m(b) == b) {
                        id
                    } else {
                        let items = factors.iter().map(|&(b, e)| (m(b), i64::from(e))).collect();
                        self.build_product(1.0, items)
                    }
                }
                Node::Call1(g, a) => {
                    let a2 = m(a);
                    if a2 == a {
                        id
                    } else {
                        self.call1(g, a2)
                    }
                }
                Node::Call2(g, a, b) => {
                    let (a2, b2) = (m(a), m(b));
                    if (a2, b2) == (a, b) {
                        id
                    } else {
                        self.call2(g, a2, b2)
                    }
                }
                Node::Table { table, column, arg } => {
                    let a2 = m(arg);
                    if a2 == arg {
                        id
                    } else {
                        self.table(table, column, a2)
                    }
                }
            };
            map.insert(id, new);
        }
        map[&e]
    }
}

#[cfg(test)]
mod tests {
    use super::super::fixture::fx;
    use super::*;
    use crate::ir::Func1;

    #[test]
    fn substitute_and_vars() {
        let mut f = fx();
        let (x, y, z) = (f.x, f.y, f.z);
        let s = f.pool.call1(Func1::Sin, x);
        let e = f.pool.mul(s, y);
        let e = f.pool.add(e, z);
        assert_eq!(
            f.pool.vars_of(e),
            vec![Var::State(0), Var::State(1), Var::State(2)]
        );
        assert!(f.pool.depends_on(e, Var::State(1)));
        assert!(!f.pool.depends_on(e, Var::Time));
        assert!(!f.pool.depends_on(s, Var::State(2)));
        let zero = f.pool.num(0.0);
        let r = f
            .pool
            .substitute(e, &mut |v| (v == Var::State(0)).then_some(zero));
        assert_eq!(r, z);
        let r = f
            .pool
            .substitute(e, &mut |v| (v == Var::State(2)).then_some(x));
        assert_eq!(f.show(r), "x + y*sin(x)");
        let same = f.pool.substitute(e, &mut |_| None);
        assert_eq!(same, e);
        assert_eq!(f.pool.reachable(&[s]), vec![x, s]);
        assert_eq!(f.pool.count_nodes(&[e, s]), 6);
    }
}
