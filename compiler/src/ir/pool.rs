//! The hash-consed expression pool. Its constructors simplify, so every stored node is in the
//! canonical form documented on [`Node`].

// Fx hashing: ids and nodes are small keys hashed millions of times on large models, and
// hash-flooding is no concern for a compiler's own data.
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use reachc_core::interval::Interval;

use super::fold::Folded;
use super::node::{ExprId, Func1, Func2, Node, Var, F64};

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

    /// `Some((q, rest))` if `id` is the product `E * rest` of an enclosure `E` (exponent 1, the
    /// form an inexact coefficient takes, see [`Pool::scale`]) and other factors.
    fn enclosure_factor(&mut self, id: ExprId) -> Option<(Folded, ExprId)> {
        let Node::Product { factors } = self.node(id) else {
            return None;
        };
        let k = factors
            .iter()
            .position(|&(b, e)| e == 1 && matches!(self.node(b), Node::Enclosure { .. }))?;
        let q = self.folded(factors[k].0)?;
        let mut rest = factors.clone();
        rest.remove(k);
        let rest = match rest.as_slice() {
            &[(b, 1)] => b,
            _ => self.intern(Node::Product { factors: rest }),
        };
        Some((q, rest))
    }

    /// `q * t` for an inexact coefficient `q`: the product of `t` with the enclosure of `q`,
    /// built directly (the constructors would pull the enclosure out again).
    fn scale(&mut self, t: ExprId, q: Folded) -> ExprId {
        let e = self.folded_node(q);
        let mut factors: Vec<(ExprId, i32)> = match self.node(t) {
            Node::Product { factors } => factors.clone(),
            _ => vec![(t, 1)],
        };
        match factors.iter_mut().find(|(b, _)| *b == e) {
            Some(f) => f.1 += 1,
            None => factors.push((e, 1)),
        }
        factors.retain(|&(_, x)| x != 0);
        factors.sort_by_key(|&(id, _)| id);
        match factors.as_slice() {
            [] => self.num(1.0),
            &[(b, 1)] => b,
            _ => self.intern(Node::Product { factors }),
        }
    }

    pub(super) fn is_zero(&self, id: ExprId) -> bool {
        self.as_const(id) == Some(0.0)
    }

    /// `a + b`.
    pub fn add(&mut self, a: ExprId, b: ExprId) -> ExprId {
        self.build_sum(0.0, vec![(a, 1.0), (b, 1.0)])
    }

    /// `a - b`.
    pub fn sub(&mut self, a: ExprId, b: ExprId) -> ExprId {
        self.build_sum(0.0, vec![(a, 1.0), (b, -1.0)])
    }

    /// `-a`.
    pub fn neg(&mut self, a: ExprId) -> ExprId {
        self.build_sum(0.0, vec![(a, -1.0)])
    }

    /// The sum of `items` (0 if empty).
    pub fn sum(&mut self, items: &[ExprId]) -> ExprId {
        self.build_sum(0.0, items.iter().map(|&i| (i, 1.0)).collect())
    }

    /// `a * b`.
    pub fn mul(&mut self, a: ExprId, b: ExprId) -> ExprId {
        self.build_product(1.0, vec![(a, 1), (b, 1)])
    }

    /// `a / b`.
    pub fn div(&mut self, a: ExprId, b: ExprId) -> ExprId {
        self.build_product(1.0, vec![(a, 1), (b, -1)])
    }

    /// The product of `items` (1 if empty).
    pub fn product(&mut self, items: &[ExprId]) -> ExprId {
        self.build_product(1.0, items.iter().map(|&i| (i, 1)).collect())
    }

    /// `a^n` for an integer `n` (`a^0 = 1` for every `a`).
    pub fn powi(&mut self, a: ExprId, n: i32) -> ExprId {
        self.build_product(1.0, vec![(a, i64::from(n))])
    }

    /// `a^b`: an integer-valued constant `b` gives [`Pool::powi`], anything else the real power
    /// `Call2(Pow, a, b)` (`1^b = 1`; constants fold when the result is finite).
    pub fn pow(&mut self, a: ExprId, b: ExprId) -> ExprId {
        if let Some(n) = self.as_const(b) {
            if n.fract() == 0.0 && n.abs() <= f64::from(i32::MAX) {
                return self.powi(a, n as i32);
            }
        }
        if self.as_const(a) == Some(1.0) {
            return self.num(1.0);
        }
        if let (Some(x), Some(y)) = (self.folded(a), self.folded(b)) {
            let r = x.call2(Func2::Pow, y);
            if r.is_finite() {
                return self.folded_node(r);
            }
        }
        self.intern(Node::Call2(Func2::Pow, a, b))
    }

    /// `f(a)`, folded when `a` is a constant and the value is finite, with the identities
    /// `sqrt(x^2) = abs(x)` (more generally for even powers), `abs(c*x) = |c|*abs(x)`,
    /// `abs(x) = x` for non-negative `x` (`abs`, `exp`, `cosh`, `sqrt`, even powers),
    /// `log(exp(x)) = x`, `sign(sign(x)) = sign(x)`, and `f(-x) = -f(x)` / `f(x)` for odd / even `f`.
    pub fn call1(&mut self, f: Func1, a: ExprId) -> ExprId {
        if let Some(v) = self.folded(a) {
            let r = v.call1(f);
            if r.is_finite() {
                return self.folded_node(r);
            }
            return self.intern(Node::Call1(f, a));
        }
        let scaled = self.scaled_term(a);
        match (f, self.node(a)) {
            (Func1::Abs, Node::Call1(Func1::Abs | Func1::Exp | Func1::Cosh | Func1::Sqrt, _)) => {
                return a
            }
            (Func1::Abs, Node::Product { factors }) if factors.iter().all(|&(_, e)| e % 2 == 0) => {
                return a
            }
            (Func1::Sqrt, Node::Product { factors })
                if factors.iter().all(|&(_, e)| e % 2 == 0) =>
            {
                // sqrt(prod b^(2k)) = prod |b|^k
                let halves: Vec<(ExprId, i32)> = factors.iter().map(|&(b, e)| (b, e / 2)).collect();
                let items = halves
                    .into_iter()
                    .map(|(b, k)| {
                        let abs_b = self.call1(Func1::Abs, b);
                        (abs_b, i64::from(k))
                    })
                    .collect();
                return self.build_product(1.0, items);
            }
            (Func1::Log, &Node::Call1(Func1::Exp, x)) => return x,
            (Func1::Sign, Node::Call1(Func1::Sign, _)) => return a,
            _ => {}
        }
        if let Some((t, c)) = scaled {
            match f {
                Func1::Abs => {
                    let inner = self.call1(Func1::Abs, t);
                    return self.build_sum(0.0, vec![(inner, c.abs())]);
                }
                // Odd functions: f(-y) = -f(y).
                Func1::Sin
                | Func1::Tan
                | Func1::Atan
                | Func1::Sinh
                | Func1::Tanh
                | Func1::Sign
                | Func1::DSinc
                    if c < 0.0 =>
                {
                    let pos = self.build_sum(0.0, vec![(t, -c)]);
                    let inner = self.call1(f, pos);
                    return self.neg(inner);
                }
                // Even functions: f(-y) = f(y).
                Func1::Cos | Func1::Cosh | Func1::Sinc if c < 0.0 => {
                    let pos = self.build_sum(0.0, vec![(t, -c)]);
                    return self.call1(f, pos);
                }
                _ => {}
            }
        }
        self.intern(Node::Call1(f, a))
    }

    /// `f(a, b)` (`atan2(y = a, x = b)`), folded when both are constants and the value is
    /// finite; `min(a, a) = max(a, a) = a`, and `min`/`max` arguments are put in id order.
    pub fn call2(&mut self, f: Func2, a: ExprId, b: ExprId) -> ExprId {
        if f == Func2::Pow {
            return self.pow(a, b);
        }
        if let (Some(x), Some(y)) = (self.folded(a), self.folded(b)) {
            let r = x.call2(f, y);
            if r.is_finite() {
                return self.folded_node(r);
            }
        }
        match f {
            Func2::Min | Func2::Max if a == b => a,
            Func2::Min | Func2::Max => self.intern(Node::Call2(f, a.min(b), a.max(b))),
            _ => self.intern(Node::Call2(f, a, b)),
        }
    }

    /// Column `column` of table `table` interpolated at `arg` (never folded: the pool does not
    /// hold table data).
    pub fn table(&mut self, table: u32, column: u32, arg: ExprId) -> ExprId {
        self.intern(Node::Table { table, column, arg })
    }

    /// `Some((t, c))` if `id` is the scaled term `c*t` (a one-term `Sum` without constant).
    pub(super) fn scaled_term(&self, id: ExprId) -> Option<(ExprId, f64)> {
        match self.node(id) {
            Node::Sum { constant, terms } if constant.get() == 0.0 && terms.len() == 1 => {
                Some((terms[0].0, terms[0].1.get()))
            }
            _ => None,
        }
    }

    /// `constant + sum(c * e)` in canonical form: nested sums flattened (their coefficients
    /// multiplied through), constants folded, like terms collected, terms sorted by id.
    pub(super) fn build_sum(&mut self, constant: f64, items: Vec<(ExprId, f64)>) -> ExprId {
        let items = items
            .into_iter()
            .map(|(id, c)| (id, Folded::point(c)))
            .collect();
        self.build_sum_folded(Folded::point(constant), items)
    }

    /// [`Pool::build_sum`] with folded coefficients: arithmetic on coefficients is carried out
    /// in [`Folded`], and a coefficient that ends up inexact becomes an enclosure factor of its
    /// term ([`Pool::scale`]), an inexact constant an enclosure term.
    fn build_sum_folded(&mut self, constant: Folded, items: Vec<(ExprId, Folded)>) -> ExprId {
        let mut constant = constant;
        let mut terms: Vec<(ExprId, Folded)> = Vec::with_capacity(items.len());
        let mut work = items;
        while let Some((id, c)) = work.pop() {
            if c.is_zero() {
                continue;
            }
            if let Some(v) = self.folded(id) {
                let cv = c.mul(v);
                let sum = constant.add(cv);
                if cv.is_finite() && sum.is_finite() {
                    constant = sum;
                } else {
                    terms.push((id, c));
                }
                continue;
            }
            match self.node(id) {
                Node::Sum {
                    constant: k,
                    terms: ts,
                } => {
                    let ck = c.mul(Folded::point(k.get()));
                    let scaled: Vec<(ExprId, Folded)> = ts
                        .iter()
                        .map(|&(t, d)| (t, c.mul(Folded::point(d.get()))))
                        .collect();
                    let finite = ck.is_finite()
                        && constant.add(ck).is_finite()
                        && scaled
                            .iter()
                            .all(|&(_, cd)| cd.is_finite() && !cd.is_zero());
                    if finite {
                        constant = constant.add(ck);
                        work.extend(scaled);
                    } else {
                        terms.push((id, c));
                    }
                }
                Node::Product { .. } => match self.enclosure_factor(id) {
                    Some((q, rest)) if c.mul(q).is_finite() && !c.mul(q).is_zero() => {
                        work.push((rest, c.mul(q)));
                    }
                    _ => terms.push((id, c)),
                },
                _ => terms.push((id, c)),
            }
        }
        terms.sort_by_key(|&(id, _)| id);
        let mut merged: Vec<(ExprId, Folded)> = Vec::with_capacity(terms.len());
        for (id, c) in terms {
            match merged.last_mut() {
                // An overflowing coefficient leaves the term repeated rather than infinite.
                Some(last) if last.0 == id && last.1.add(c).is_finite() => last.1 = last.1.add(c),
                _ => merged.push((id, c)),
            }
        }
        merged.retain(|&(_, c)| !c.is_zero());
        let mut out: Vec<(ExprId, F64)> = Vec::with_capacity(merged.len() + 1);
        for (t, c) in merged {
            if c.is_exact() {
                out.push((t, F64::new(c.approx)));
            } else {
                let scaled = self.scale(t, c);
                out.push((scaled, F64::new(1.0)));
            }
        }
        let constant = if constant.is_exact() {
            constant.approx
        } else {
            if out.is_empty() {
                return self.folded_node(constant);
            }
            let e = self.folded_node(constant);
            out.push((e, F64::new(1.0)));
            0.0
        };
        out.sort_by_key(|&(id, _)| id);
        match out.as_slice() {
            [] => self.num(constant),
            &[(t, c)] if c.get() == 1.0 && constant == 0.0 => t,
            _ => self.intern(Node::Sum {
                constant: F64::new(constant),
                terms: out,
            }),
        }
    }

    /// `coef * prod(e ^ n)` in canonical form: nested products flattened, constants and the
    /// coefficients of scaled terms pulled out, `abs` dropped under even powers, like bases
    /// collected, bases sorted by id; a
    /// coefficient other than 1 ends up in a `Sum` (which distributes it over a `Sum` result).
    pub(super) fn build_product(&mut self, coef: f64, items: Vec<(ExprId, i64)>) -> ExprId {
        self.build_product_folded(Folded::point(coef), items)
    }

    /// [`Pool::build_product`] with a folded coefficient (enclosure factors are pulled into it).
    fn build_product_folded(&mut self, coef: Folded, items: Vec<(ExprId, i64)>) -> ExprId {
        let mut coef = coef;
        let mut factors: Vec<(ExprId, i64)> = Vec::with_capacity(items.len());
        let mut work = items;
        while let Some((id, e)) = work.pop() {
            if e == 0 {
                continue;
            }
            if let Some(v) = self.folded(id) {
                match v.powi(e) {
                    Some(p) if p.is_finite() && coef.mul(p).is_finite() => coef = coef.mul(p),
                    _ => factors.push((id, e)),
                }
                continue;
            }
            match self.node(id) {
                Node::Product { factors: fs } => {
                    let scaled: Option<Vec<(ExprId, i64)>> = fs
                        .iter()
                        .map(|&(b, fe)| i64::from(fe).checked_mul(e).map(|x| (b, x)))
                        .collect();
                    match scaled {
                        Some(scaled) => work.extend(scaled),
                        None => factors.push((id, e)),
                    }
                }
                Node::Sum { constant, terms } if constant.get() == 0.0 && terms.len() == 1 => {
                    let (t, c) = terms[0];
                    match Folded::point(c.get()).powi(e) {
                        Some(p) if p.is_finite() && !p.is_zero() && coef.mul(p).is_finite() => {
                            coef = coef.mul(p);
                            work.push((t, e));
                        }
                        _ => factors.push((id, e)),
                    }
                }
                _ => factors.push((id, e)),
            }
        }
        if coef.is_zero() {
            return self.num(0.0);
        }
        factors.sort_by_key(|&(id, _)| id);
        let mut merged: Vec<(ExprId, i64)> = Vec::with_capacity(factors.len());
        for (id, e) in factors {
            match merged.last_mut() {
                Some(last) if last.0 == id && last.1.checked_add(e).is_some() => last.1 += e,
                _ => merged.push((id, e)),
            }
        }
        merged.retain(|&(_, e)| e != 0);
        // |b|^(2k) = b^(2k): rebuild without the abs (terminates: one abs fewer each time).
        let unabs = |&(b, e): &(ExprId, i64)| match self.node(b) {
            &Node::Call1(Func1::Abs, inner) if e % 2 == 0 => Some((inner, e)),
            _ => None,
        };
        if merged.iter().any(|f| unabs(f).is_some()) {
            let items = merged.iter().map(|f| unabs(f).unwrap_or(*f)).collect();
            return self.build_product_folded(coef, items);
        }
        let mut out: Vec<(ExprId, i32)> = Vec::with_capacity(merged.len());
        let mut resort = false;
        for (b, e) in merged {
            match i32::try_from(e) {
                Ok(e) => out.push((b, e)),
                Err(_) => {
                    // An exponent beyond i32 (absurd, but must not panic): a real power node.
                    let n = self.num(e as f64);
                    out.push((self.intern(Node::Call2(Func2::Pow, b, n)), 1));
                    resort = true;
                }
            }
        }
        if resort {
            out.sort_by_key(|&(id, _)| id);
        }
        let p = match out.as_slice() {
            [] => return self.folded_node(coef),
            &[(b, 1)] => b,
            _ => self.intern(Node::Product { factors: out }),
        };
        if coef.is_one() {
            p
        } else {
            self.build_sum_folded(Folded::point(0.0), vec![(p, coef)])
        }
    }

    /// Ids of the nodes reachable from `roots` for which `skip` is false (not descending into
    /// skipped nodes), in increasing order. Iterative: DAG depth is not bounded by the parser.
    pub(super) fn collect(&self, roots: &[ExprId], skip: impl Fn(ExprId) -> bool) -> Vec<ExprId> {
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
    use super::*;
    use crate::ir::Names;
    use crate::ir::VarValues;

    struct Fx {
        pool: Pool,
        x: ExprId,
        y: ExprId,
        z: ExprId,
        names: Vec<String>,
    }

    fn fx() -> Fx {
        let mut pool = Pool::new();
        let x = pool.var(Var::State(0));
        let y = pool.var(Var::State(1));
        let z = pool.var(Var::State(2));
        Fx {
            pool,
            x,
            y,
            z,
            names: vec!["x".into(), "y".into(), "z".into()],
        }
    }

    impl Fx {
        fn show(&self, e: ExprId) -> String {
            let names = Names {
                states: &self.names,
                inputs: &[],
                noises: &[],
                tables: &[],
            };
            self.pool.to_sde(e, &names)
        }
        fn c(&mut self, v: f64) -> ExprId {
            self.pool.num(v)
        }
    }

    /// Random coefficients folded through nested sums, products, like terms and integer
    /// powers: the interval value of the folded expression at `x = 1` holds the exact rational
    /// value of the expression as built (the pool never rounds a coefficient silently), and the
    /// point value is what the same float operations give.
    #[test]
    fn folds_enclose_the_exact_coefficients() {
        use num_rational::BigRational;
        use reachc_test_support::rng::XorShift64;
        let q = |v: f64| BigRational::from_float(v).unwrap();
        let mut rng = XorShift64(0x9e37_79b9_7f4a_7c15);
        // decimals like 0.3, 1.7: most are not floats, so their products are inexact
        let mut next = || ((rng.next_u64() >> 11) % 41) as f64 / 10.0 - 2.0;
        let mut inexact = 0;
        for _ in 0..2000 {
            let mut f = fx();
            let x = f.x;
            // e = a*(b*x + c) + d*x^2/e2 ... built step by step, the exact value alongside.
            let (a, b, c, d) = (next(), next(), next(), next());
            let k = next();
            let k = if k == 0.0 { 1.5 } else { k };
            let (na, nb, nc, nd, nk) = (f.c(a), f.c(b), f.c(c), f.c(d), f.c(k));
            let bx = f.pool.mul(nb, x);
            let inner = f.pool.add(bx, nc);
            let outer = f.pool.mul(na, inner);
            let x2 = f.pool.powi(x, 2);
            let dx2 = f.pool.mul(nd, x2);
            let quot = f.pool.div(dx2, nk);
            let e = f.pool.add(outer, quot);
            let e = f.pool.add(e, quot);
            let exact = q(a) * (q(b) + q(c)) + q(2.0) * q(d) / q(k);
            let vars = VarValues {
                states: &[reachc_core::interval::Interval::ONE; 3][..],
                inputs: &[],
                noises: &[],
                time: reachc_core::interval::Interval::ZERO,
            };
            let got = f.pool.eval(&[e], &vars, &[])[0];
            assert!(
                q(got.lo()) <= exact && exact <= q(got.hi()),
                "a={a} b={b} c={c} d={d} k={k}: {got} misses {exact}"
            );
            inexact += usize::from(!got.is_point());
        }
        assert!(
            inexact > 500,
            "only {inexact} inexact folds: the test would be vacuous"
        );
    }

    #[test]
    fn like_terms() {
        let mut f = fx();
        let (x, y) = (f.x, f.y);
        let e = f.pool.add(x, x);
        assert_eq!(f.show(e), "2*x");
        let xy = f.pool.mul(x, y);
        let yx = f.pool.mul(y, x);
        assert_eq!(xy, yx);
        let e = f.pool.sub(xy, yx);
        assert_eq!(f.show(e), "0");
        // 2*(x + 3*y) - 6*y
        let three = f.c(3.0);
        let two = f.c(2.0);
        let six = f.c(6.0);
        let t3y = f.pool.mul(three, y);
        let inner = f.pool.add(x, t3y);
        let lhs = f.pool.mul(two, inner);
        let t6y = f.pool.mul(six, y);
        let e = f.pool.sub(lhs, t6y);
        assert_eq!(f.show(e), "2*x");
        let e = f.pool.sub(x, x);
        assert_eq!(f.show(e), "0");
        let e = f.pool.neg(x);
        let e = f.pool.neg(e);
        assert_eq!(e, x);
        // 2*x + 3*x
        let a = f.pool.mul(two, x);
        let b = f.pool.mul(three, x);
        let e = f.pool.add(a, b);
        assert_eq!(f.show(e), "5*x");
        // nested sums flatten: (x + 1) + (y + 2)
        let one = f.c(1.0);
        let a = f.pool.add(x, one);
        let b = f.pool.add(y, two);
        let e = f.pool.add(a, b);
        assert_eq!(f.show(e), "x + y + 3");
        assert!(matches!(f.pool.node(e), Node::Sum { terms, .. } if terms.len() == 2));
    }

    #[test]
    fn products() {
        let mut f = fx();
        let (x, y, z) = (f.x, f.y, f.z);
        let xx = f.pool.mul(x, x);
        assert_eq!(f.show(xx), "x^2");
        let xxx = f.pool.mul(xx, x);
        let e = f.pool.div(xxx, x);
        assert_eq!(f.show(e), "x^2");
        assert_eq!(e, xx);
        let e = f.pool.div(xx, x);
        assert_eq!(e, x);
        // (2*x)*y -> 2*(x*y)
        let two = f.c(2.0);
        let tx = f.pool.mul(two, x);
        let e = f.pool.mul(tx, y);
        let xy = f.pool.mul(x, y);
        assert_eq!(
            f.pool.node(e),
            &Node::Sum {
                constant: F64::new(0.0),
                terms: vec![(xy, F64::new(2.0))]
            }
        );
        assert_eq!(f.show(e), "2*x*y");
        // (x^2)^3
        let e = f.pool.powi(xx, 3);
        assert_eq!(f.show(e), "x^6");
        let zero = f.c(0.0);
        let e = f.pool.mul(x, zero);
        assert_eq!(f.show(e), "0");
        let one = f.c(1.0);
        assert_eq!(f.pool.mul(x, one), x);
        assert_eq!(f.pool.div(x, one), x);
        assert_eq!(f.pool.powi(x, 1), x);
        assert_eq!(f.pool.powi(x, 0), one);
        assert_eq!(f.pool.powi(zero, 3), zero);
        assert_eq!(f.pool.pow(one, y), one);
        // (x*y*z) / (y*z) = x ; x*y*z order independent
        let a = f.pool.product(&[x, y, z]);
        let b = f.pool.product(&[z, x, y]);
        assert_eq!(a, b);
        let yz = f.pool.mul(y, z);
        assert_eq!(f.pool.div(a, yz), x);
        // (2x)^2 = 4 x^2 ; (2x)/(4x) = 0.5
        let e = f.pool.powi(tx, 2);
        assert_eq!(f.show(e), "4*x^2");
        let four = f.c(4.0);
        let fx4 = f.pool.mul(four, x);
        let e = f.pool.div(tx, fx4);
        assert_eq!(f.pool.as_const(e), Some(0.5));
        // x / y^2
        let y2 = f.pool.powi(y, 2);
        let e = f.pool.div(x, y2);
        assert_eq!(f.show(e), "x/y^2");
        // 2 * (x + 1) distributes
        let x1 = f.pool.add(x, one);
        let e = f.pool.mul(two, x1);
        assert_eq!(f.show(e), "2*x + 2");
        // (x + 1) * y does not
        let e = f.pool.mul(x1, y);
        assert_eq!(f.show(e), "y*(x + 1)");
    }

    #[test]
    fn folding() {
        let mut f = fx();
        let two = f.c(2.0);
        let ten = f.c(10.0);
        let e = f.pool.pow(two, ten);
        assert_eq!(f.show(e), "1024");
        let zero = f.c(0.0);
        let e = f.pool.call1(Func1::Sin, zero);
        assert_eq!(f.show(e), "0");
        let e = f.pool.call1(Func1::Sinc, zero);
        assert_eq!(f.pool.as_const(e), Some(1.0));
        let one = f.c(1.0);
        let e = f.pool.div(one, zero);
        assert_eq!(f.pool.as_const(e), None);
        assert_eq!(f.show(e), "1/0");
        let m1 = f.c(-1.0);
        let e = f.pool.call1(Func1::Log, m1);
        assert_eq!(f.pool.as_const(e), None);
        assert_eq!(f.show(e), "log(-1)");
        let e = f.pool.call1(Func1::Sqrt, m1);
        assert_eq!(f.pool.as_const(e), None);
        let k = f.c(1000.0);
        let e = f.pool.call1(Func1::Exp, k);
        assert_eq!(f.pool.as_const(e), None);
        let half = f.c(0.5);
        let e = f.pool.pow(m1, half);
        assert_eq!(f.pool.as_const(e), None);
        assert_eq!(f.show(e), "(-1)^0.5");
        let big = f.c(1e308);
        let e = f.pool.add(big, big);
        assert_eq!(f.pool.as_const(e), None);
        let e = f.pool.mul(big, big);
        assert_eq!(f.pool.as_const(e), None);
        let x = f.x;
        let bx = f.pool.mul(big, x);
        let e = f.pool.mul(bx, ten);
        assert_eq!(f.pool.as_const(e), None);
        let e = f.pool.add(bx, bx); // coefficient would overflow: kept as two terms
        let vals = f
            .pool
            .eval(&[e], &VarValuesF::new(&[1.0, 0.0, 0.0]).v(), &[]);
        assert_eq!(vals[0], f64::INFINITY);
        let e = f.pool.div(x, zero);
        assert_eq!(f.show(e), "x/0");
        let e = f.pool.powi(zero, -1);
        assert_eq!(f.pool.as_const(e), None);
        // atan2(1, 0) = pi/2 is not a float: an enclosure of it, with the float for points.
        let e = f.pool.call2(Func2::Atan2, one, zero);
        assert_eq!(f.pool.as_const(e), None);
        assert_eq!(f.pool.as_value(e), Some(std::f64::consts::FRAC_PI_2));
        let Node::Enclosure { lo, hi, .. } = *f.pool.node(e) else {
            panic!("not an enclosure")
        };
        assert!(lo.get() < std::f64::consts::FRAC_PI_2 && std::f64::consts::FRAC_PI_2 < hi.get());
        let e = f.pool.call2(Func2::Min, two, ten);
        assert_eq!(f.pool.as_const(e), Some(2.0));
        // integer powers too large for i32 do not panic
        let xx = f.pool.powi(x, i32::MAX);
        let e = f.pool.mul(xx, xx);
        assert!(f.pool.as_const(e).is_none());
    }

    struct VarValuesF<'a>(&'a [f64]);
    impl<'a> VarValuesF<'a> {
        fn new(s: &'a [f64]) -> Self {
            VarValuesF(s)
        }
        fn v(&self) -> crate::ir::VarValues<'a, f64> {
            crate::ir::VarValues {
                states: self.0,
                inputs: &[],
                noises: &[],
                time: 0.0,
            }
        }
    }

    #[test]
    fn functions() {
        let mut f = fx();
        let (x, y) = (f.x, f.y);
        let x2 = f.pool.powi(x, 2);
        let e = f.pool.call1(Func1::Sqrt, x2);
        assert_eq!(f.show(e), "abs(x)");
        let a = f.pool.call1(Func1::Abs, x);
        assert_eq!(f.pool.call1(Func1::Abs, a), a);
        let ex = f.pool.call1(Func1::Exp, x);
        assert_eq!(f.pool.call1(Func1::Log, ex), x);
        let lx = f.pool.call1(Func1::Log, x);
        let e = f.pool.call1(Func1::Exp, lx);
        assert_eq!(f.show(e), "exp(log(x))");
        assert_eq!(f.pool.call2(Func2::Min, x, x), x);
        assert_eq!(
            f.pool.call2(Func2::Max, y, x),
            f.pool.call2(Func2::Max, x, y)
        );
        let nx = f.pool.neg(x);
        let e = f.pool.call1(Func1::Sin, nx);
        assert_eq!(f.show(e), "-sin(x)");
        let e = f.pool.call1(Func1::Cos, nx);
        assert_eq!(f.show(e), "cos(x)");
        let m3 = f.pool.num(-3.0);
        let m3x = f.pool.mul(m3, x);
        let e = f.pool.call1(Func1::Abs, m3x);
        assert_eq!(f.show(e), "3*abs(x)");
        let e = f.pool.call1(Func1::Abs, x2);
        assert_eq!(e, x2);
        let xy = f.pool.mul(x, y);
        let xy2 = f.pool.powi(xy, -2);
        let e = f.pool.call1(Func1::Sqrt, xy2);
        assert_eq!(f.show(e), "1/(abs(x)*abs(y))");
        let y4 = f.pool.powi(y, 4);
        let x2y4 = f.pool.mul(x2, y4);
        let e = f.pool.call1(Func1::Sqrt, x2y4);
        assert_eq!(f.show(e), "y^2*abs(x)");
        let ax = f.pool.call1(Func1::Abs, x);
        let e = f.pool.mul(ax, ax);
        assert_eq!(e, x2);
        let half = f.pool.num(0.5);
        let e = f.pool.pow(x, half);
        assert_eq!(f.show(e), "x^0.5");
        let three = f.pool.num(3.0);
        assert_eq!(f.pool.pow(x, three), f.pool.powi(x, 3));
    }

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

    #[test]
    fn canonical_invariants_hold() {
        // Children precede parents, sums/products sorted without repeats.
        let mut f = fx();
        let (x, y, z) = (f.x, f.y, f.z);
        let mut es = vec![x, y, z];
        for i in 0..200usize {
            let a = es[(i * 7 + 1) % es.len()];
            let b = es[(i * 13 + 2) % es.len()];
            let e = match i % 6 {
                0 => f.pool.add(a, b),
                1 => f.pool.mul(a, b),
                2 => f.pool.sub(a, b),
                3 => f.pool.div(a, b),
                4 => f.pool.call1(Func1::Sin, a),
                _ => {
                    let c = f.pool.num((i % 5) as f64 - 2.0);
                    f.pool.mul(c, a)
                }
            };
            es.push(e);
        }
        for i in 0..f.pool.len() {
            let id = ExprId(i as u32);
            for_each_child(f.pool.node(id), |c| assert!(c < id));
            match f.pool.node(id) {
                Node::Sum { terms, constant } => {
                    assert!(terms.windows(2).all(|w| w[0].0 < w[1].0));
                    assert!(terms.len() >= 2 || terms[0].1.get() != 1.0 || constant.get() != 0.0);
                    for &(t, c) in terms {
                        assert!(c.get() != 0.0);
                        assert!(!matches!(f.pool.node(t), Node::Sum { .. } | Node::Const(_)));
                    }
                }
                Node::Product { factors } => {
                    assert!(factors.windows(2).all(|w| w[0].0 < w[1].0));
                    assert!(factors.len() >= 2 || factors[0].1 != 1);
                    for &(b, e) in factors {
                        assert!(e != 0);
                        assert!(!matches!(f.pool.node(b), Node::Product { .. }));
                        // the only constant factor: an unevaluated division by zero
                        if let Some(v) = f.pool.as_const(b) {
                            assert!(v == 0.0 && e < 0);
                        }
                        assert!(f.pool.scaled_term(b).is_none());
                    }
                }
                _ => {}
            }
        }
    }

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
