//! Exact symbolic differentiation, memoised per `(node, variable)`.

use super::node::{ExprId, Func1, Func2, Node, Var};
use super::pool::Pool;

impl Pool {
    /// The exact derivative `d e / d v`, simplified.
    ///
    /// Memoised on `(node, v)` for the life of the pool, so each DAG node is differentiated once
    /// per variable and shared sub-expressions give shared derivatives: the result's size is
    /// linear in the size of `e`'s DAG. Iterative (children first, in id order), so deep
    /// expressions cannot overflow the stack.
    ///
    /// Non-smooth functions get their derivative away from kinks: `abs' = sign`,
    /// `min(a, b)' = a'*(1 + s)/2 + b'*(1 - s)/2` with `s = sign(b - a)` (the average at ties,
    /// which interval evaluation turns into the hull), `sign' = 0`.
    /// `sinc' = dsinc` ([`Func1::DSinc`]); `dsinc' = -sinc(x) - 2*dsinc(x)/x` (0/0 at 0: second
    /// derivatives of `sinc` are not needed by the analyses).
    ///
    /// Differentiating w.r.t. [`Var::Time`] through a table whose argument depends on time is not
    /// supported (tables are piecewise linear, their slope is not a table of the model): it is a
    /// debug assertion failure and 0 in release builds. Tables depend only on `t`, so derivatives
    /// w.r.t. states, inputs and noise channels are exact.
    pub fn diff(&mut self, e: ExprId, v: Var) -> ExprId {
        if let Some(&d) = self.diff_memo.get(&(e, v)) {
            return d;
        }
        let order = self.collect(&[e], |id| self.diff_memo.contains_key(&(id, v)));
        for id in order {
            let d = self.diff_node(id, v);
            self.diff_memo.insert((id, v), d);
        }
        self.diff_memo[&(e, v)]
    }

    /// Derivative of the child `c` (already computed: children come first).
    fn d(&self, c: ExprId, v: Var) -> ExprId {
        self.diff_memo[&(c, v)]
    }

    fn diff_node(&mut self, id: ExprId, v: Var) -> ExprId {
        let zero = self.num(0.0);
        let node = self.node(id).clone();
        match node {
            Node::Const(_) | Node::Enclosure { .. } => zero,
            Node::Var(w) => {
                if w == v {
                    self.num(1.0)
                } else {
                    zero
                }
            }
            Node::Sum { terms, .. } => {
                let items: Vec<(ExprId, f64)> = terms
                    .iter()
                    .map(|&(t, c)| (self.d(t, v), c.get()))
                    .filter(|&(dt, _)| !self.is_zero(dt))
                    .collect();
                self.build_sum(0.0, items)
            }
            Node::Product { factors } => {
                // sum_i e_i * b_i^(e_i - 1) * b_i' * prod_{j != i} b_j^e_j
                let mut items: Vec<(ExprId, f64)> = Vec::new();
                for (i, &(b, e)) in factors.iter().enumerate() {
                    let db = self.d(b, v);
                    if self.is_zero(db) {
                        continue;
                    }
                    let mut fs: Vec<(ExprId, i64)> = factors
                        .iter()
                        .map(|&(bj, ej)| (bj, i64::from(ej)))
                        .collect();
                    fs[i].1 -= 1;
                    fs.push((db, 1));
                    items.push((self.build_product(f64::from(e), fs), 1.0));
                }
                self.build_sum(0.0, items)
            }
            Node::Call1(f, a) => {
                let da = self.d(a, v);
                if self.is_zero(da) || f == Func1::Sign {
                    return zero;
                }
                let g = self.d_call1(f, a, id);
                self.mul(g, da)
            }
            Node::Call2(f, a, b) => {
                let (da, db) = (self.d(a, v), self.d(b, v));
                if self.is_zero(da) && self.is_zero(db) {
                    return zero;
                }
                self.d_call2(f, a, b, id, da, db)
            }
            Node::Table { arg, .. } => {
                let da = self.d(arg, v);
                debug_assert!(
                    self.is_zero(da),
                    "derivative of a table through its argument (w.r.t. {v:?}) is not supported"
                );
                zero
            }
        }
    }

    /// `f'(a)` where `fa` is the node `f(a)` itself (reused: `exp' = exp`).
    fn d_call1(&mut self, f: Func1, a: ExprId, fa: ExprId) -> ExprId {
        match f {
            Func1::Sin => self.call1(Func1::Cos, a),
            Func1::Cos => {
                let s = self.call1(Func1::Sin, a);
                self.neg(s)
            }
            // 1 + tan^2: reuses the tan node, no cos needed.
            Func1::Tan => {
                let t2 = self.powi(fa, 2);
                self.build_sum(1.0, vec![(t2, 1.0)])
            }
            Func1::Exp => fa,
            Func1::Log => self.powi(a, -1),
            Func1::Sqrt => self.build_product(0.5, vec![(fa, -1)]),
            Func1::Abs => self.call1(Func1::Sign, a),
            Func1::Atan => {
                let a2 = self.powi(a, 2);
                let den = self.build_sum(1.0, vec![(a2, 1.0)]);
                self.powi(den, -1)
            }
            Func1::Sinh => self.call1(Func1::Cosh, a),
            Func1::Cosh => self.call1(Func1::Sinh, a),
            Func1::Tanh => {
                let t2 = self.powi(fa, 2);
                self.build_sum(1.0, vec![(t2, -1.0)])
            }
            Func1::Sinc => self.call1(Func1::DSinc, a),
            Func1::DSinc => {
                // sinc'' = -sinc - 2 sinc'/x
                let s = self.call1(Func1::Sinc, a);
                let q = self.build_product(1.0, vec![(fa, 1), (a, -1)]);
                self.build_sum(0.0, vec![(s, -1.0), (q, -2.0)])
            }
            Func1::Sign => self.num(0.0),
        }
    }

    fn d_call2(
        &mut self,
        f: Func2,
        a: ExprId,
        b: ExprId,
        fab: ExprId,
        da: ExprId,
        db: ExprId,
    ) -> ExprId {
        match f {
            Func2::Atan2 => {
                // atan2(y = a, x = b)' = (x y' - y x') / (x^2 + y^2)
                let p = self.mul(b, da);
                let q = self.mul(a, db);
                let num = self.sub(p, q);
                let a2 = self.powi(a, 2);
                let b2 = self.powi(b, 2);
                let den = self.add(a2, b2);
                self.div(num, den)
            }
            Func2::Min | Func2::Max => {
                let diff = self.sub(b, a);
                let s = self.call1(Func1::Sign, diff);
                // (1 + s)/2 selects a for min (b > a), (1 - s)/2 selects b.
                let sel_a = if f == Func2::Min { 0.5 } else { -0.5 };
                let ha = self.build_sum(0.5, vec![(s, sel_a)]);
                let hb = self.build_sum(0.5, vec![(s, -sel_a)]);
                let ta = self.mul(ha, da);
                let tb = self.mul(hb, db);
                self.add(ta, tb)
            }
            Func2::Pow => {
                // (a^b)' = b a^(b-1) a' + a^b log(a) b'
                let mut items = Vec::new();
                if !self.is_zero(da) {
                    let one = self.num(1.0);
                    let bm1 = self.sub(b, one);
                    let p = self.pow(a, bm1);
                    items.push((self.product(&[b, p, da]), 1.0));
                }
                if !self.is_zero(db) {
                    let l = self.call1(Func1::Log, a);
                    items.push((self.product(&[fab, l, db]), 1.0));
                }
                self.build_sum(0.0, items)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_exprs::sin_chain;
    use super::super::{Names, Table, VarValues};
    use super::*;
    use reachc_test_support::rng::Rng;

    const X: Var = Var::State(0);
    const Y: Var = Var::State(1);
    const U: Var = Var::Input(0);
    const W: Var = Var::Noise(0);

    /// A battery of expressions covering every function, with the box to sample in (chosen to
    /// stay in each function's domain).
    fn battery(p: &mut Pool) -> Vec<(&'static str, ExprId)> {
        let x = p.var(X);
        let y = p.var(Y);
        let u = p.var(U);
        let w = p.var(W);
        let t = p.var(Var::Time);
        let c = |p: &mut Pool, v: f64| p.num(v);
        let mut out = Vec::new();
        macro_rules! push {
            ($name:expr, $e:expr) => {{
                let e = $e;
                out.push(($name, e));
            }};
        }
        let xy = p.mul(x, y);
        push!("x*y", xy);
        let s = p.call1(Func1::Sin, xy);
        push!("sin(x*y)", s);
        let e = p.call1(Func1::Cos, x);
        let e = p.mul(e, u);
        push!("cos(x)*u", e);
        let e = p.call1(Func1::Tan, x);
        push!("tan(x)", e);
        let e = p.call1(Func1::Exp, y);
        let e = p.mul(e, x);
        push!("x*exp(y)", e);
        let x2 = p.powi(x, 2);
        let k = c(p, 1.5);
        let x2p = p.add(x2, k);
        let e = p.call1(Func1::Log, x2p);
        push!("log(x^2+1.5)", e);
        let e = p.call1(Func1::Sqrt, x2p);
        push!("sqrt(x^2+1.5)", e);
        let e = p.call1(Func1::Abs, x);
        let e = p.mul(e, y);
        push!("abs(x)*y", e);
        let e = p.call1(Func1::Atan, xy);
        push!("atan(x*y)", e);
        let e = p.call1(Func1::Sinh, x);
        push!("sinh(x)", e);
        let e = p.call1(Func1::Cosh, y);
        push!("cosh(y)", e);
        let e = p.call1(Func1::Tanh, xy);
        push!("tanh(x*y)", e);
        let e = p.call1(Func1::Sinc, x);
        push!("sinc(x)", e);
        let e = p.call1(Func1::Sinc, xy);
        let e = p.add(e, w);
        push!("sinc(x*y) + w", e);
        let e = p.call1(Func1::Sign, x);
        let e = p.mul(e, y);
        push!("sign(x)*y", e);
        let e = p.call2(Func2::Atan2, y, x);
        push!("atan2(y, x)", e);
        let e = p.call2(Func2::Min, x, y);
        let e = p.mul(e, x);
        push!("min(x, y)*x", e);
        let e = p.call2(Func2::Max, x2, y);
        push!("max(x^2, y)", e);
        let h = c(p, 0.7);
        let e = p.pow(x2p, h);
        push!("(x^2+1.5)^0.7", e);
        let e = p.pow(x2p, y);
        push!("(x^2+1.5)^y", e);
        let e = p.div(x, y);
        let e = p.sub(e, xy);
        push!("x/y - x*y", e);
        let e = p.powi(xy, -3);
        push!("(x*y)^-3", e);
        let e = p.table(0, 0, t);
        let e = p.mul(e, x);
        push!("tab.a*x", e);
        let e = p.mul(s, s);
        let e = p.call1(Func1::Exp, e);
        push!("exp(sin(xy)^2)", e);
        let ds = p.call1(Func1::DSinc, x);
        push!("dsinc(x)", ds);
        let e = p.call1(Func1::Cos, s);
        let e = p.mul(e, u);
        let e = p.add(e, x2);
        push!("cos(sin(xy))*u + x^2", e);
        out
    }

    fn table() -> Table {
        Table {
            name: "tab".into(),
            columns: vec!["a".into()],
            times: vec![0.0, 1.0, 2.0],
            values: vec![vec![1.0, 3.0, -1.0]],
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let mut p = Pool::new();
        let exprs = battery(&mut p);
        let tables = [table()];
        // The seed 7, spread by the golden-ratio multiplier.
        let mut rng = Rng(7u64.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
        let vars = [X, Y, U, W];
        for (name, e) in exprs {
            let ds: Vec<ExprId> = vars.iter().map(|&v| p.diff(e, v)).collect();
            for _ in 0..40 {
                let pt = [
                    rng.range(-2.0, 2.0),
                    rng.range(0.3, 2.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                ];
                // Stay away from kinks (abs, sign, min/max ties) and tan's poles.
                if pt[0].abs() < 0.05
                    || pt[0].cos().abs() < 0.2
                    || (pt[0] - pt[1]).abs() < 0.05
                    || (pt[0] * pt[0] - pt[1]).abs() < 0.05
                {
                    continue;
                }
                let time = rng.range(0.1, 1.9);
                let eval = |p: &Pool, pt: &[f64; 4], roots: &[ExprId]| {
                    let vv = VarValues {
                        states: &pt[0..2],
                        inputs: &pt[2..3],
                        noises: &pt[3..4],
                        time,
                    };
                    p.eval(roots, &vv, &tables)
                };
                let got = eval(&p, &pt, &ds);
                for (k, &dk) in got.iter().enumerate() {
                    let h = 1e-5;
                    let mut a = pt;
                    let mut b = pt;
                    a[k] -= h;
                    b[k] += h;
                    let fa = eval(&p, &a, &[e])[0];
                    let fb = eval(&p, &b, &[e])[0];
                    let fd = (fb - fa) / (2.0 * h);
                    let err = (fd - dk).abs() / (1.0 + dk.abs());
                    assert!(
                        err < 1e-6,
                        "{name}: d/d{:?} at {pt:?}: symbolic {dk}, finite difference {fd}",
                        vars[k]
                    );
                }
            }
        }
    }

    #[test]
    fn dsinc_values() {
        let mut p = Pool::new();
        let x = p.var(X);
        let s = p.call1(Func1::Sinc, x);
        let d = p.diff(s, X);
        let dd = p.diff(d, X);
        let at = |p: &Pool, e: ExprId, v: f64| {
            p.eval(
                &[e],
                &VarValues {
                    states: &[v],
                    inputs: &[],
                    noises: &[],
                    time: 0.0,
                },
                &[],
            )[0]
        };
        assert_eq!(at(&p, d, 0.0), 0.0);
        // continuous through the series/formula switch and matching (cos x - sinc x)/x
        for v in [1e-9f64, 1e-4, 0.0999, 0.1, 0.1001, 0.5, 3.0, -7.0] {
            let want = (v.cos() - v.sin() / v) / v;
            let got = at(&p, d, v);
            assert!(
                (got - want).abs() <= 1e-9 * (1.0 + want.abs()),
                "{v}: {got} vs {want}"
            );
        }
        // second derivative away from 0: -1/3 near 0
        let v = 0.3f64;
        let want = -(v.sin() / v) - 2.0 * ((v.cos() - v.sin() / v) / v) / v;
        assert!((at(&p, dd, v) - want).abs() < 1e-9);
    }

    #[test]
    fn derivative_forms() {
        let mut p = Pool::new();
        let x = p.var(X);
        let y = p.var(Y);
        let names_s = ["x".to_string(), "y".to_string()];
        let names = Names {
            states: &names_s,
            inputs: &[],
            noises: &[],
            tables: &[],
        };
        let show = |p: &Pool, e| p.to_sde(e, &names);
        let e = p.powi(x, 3);
        let d = p.diff(e, X);
        assert_eq!(show(&p, d), "3*x^2");
        let xy = p.mul(x, y);
        let d = p.diff(xy, X);
        assert_eq!(d, y);
        let e = p.call1(Func1::Sin, xy);
        let d = p.diff(e, Y);
        assert_eq!(show(&p, d), "x*cos(x*y)");
        let e = p.call1(Func1::Exp, x);
        assert_eq!(p.diff(e, X), e);
        let e = p.call1(Func1::Log, x);
        let d = p.diff(e, X);
        assert_eq!(show(&p, d), "1/x");
        let e = p.call1(Func1::Sqrt, x);
        let d = p.diff(e, X);
        assert_eq!(show(&p, d), "1/(2*sqrt(x))");
        let e = p.call1(Func1::Tanh, x);
        let d = p.diff(e, X);
        assert_eq!(show(&p, d), "1 - tanh(x)^2");
        let e = p.call1(Func1::Abs, x);
        let d = p.diff(e, X);
        assert_eq!(show(&p, d), "sign(x)");
        assert_eq!(p.diff(e, Y), p.num(0.0));
        let e = p.call1(Func1::Sinc, x);
        let d = p.diff(e, X);
        assert_eq!(show(&p, d), "(cos(x) - sinc(x))/x");
        // linear expressions have constant derivatives
        let two = p.num(2.0);
        let tx = p.mul(two, x);
        let e = p.sub(tx, y);
        let d = p.diff(e, Y);
        assert_eq!(p.as_const(d), Some(-1.0));
    }

    #[test]
    fn derivative_size_is_linear() {
        let mut p = Pool::new();
        let x = p.var(X);
        let mut e = x;
        for _ in 0..30 {
            e = p.call1(Func1::Sin, e);
        }
        let input = p.count_nodes(&[e]);
        let before = p.len();
        let d = p.diff(e, X);
        assert!(
            p.len() - before < 5 * input,
            "{} new nodes",
            p.len() - before
        );
        assert!(p.count_nodes(&[d]) < 5 * input);
        // second derivative stays bounded too
        let dd = p.diff(d, X);
        assert!(p.count_nodes(&[dd]) < 20 * input);

        // x1 * x2 * ... * x200, built one multiplication at a time; the full gradient.
        let mut p = Pool::new();
        let xs: Vec<ExprId> = (0..200).map(|i| p.var(Var::State(i))).collect();
        let mut e = xs[0];
        for &xi in &xs[1..] {
            e = p.mul(e, xi);
        }
        let input = p.count_nodes(&[e]);
        let before = p.len();
        let grads: Vec<ExprId> = (0..200).map(|i| p.diff(e, Var::State(i))).collect();
        assert!(
            p.len() - before < 10 * input,
            "{} new nodes",
            p.len() - before
        );
        assert!(p.count_nodes(&grads) < 10 * input);

        // A long let-style chain: deep DAG, no stack overflow, linear derivative.
        let mut p = Pool::new();
        let e = sin_chain(&mut p, 20_000);
        let input = p.count_nodes(&[e]);
        let d = p.diff(e, X);
        assert!(p.count_nodes(&[d]) < 10 * input);
        let _ = p.depends_on(e, Var::Time);
        let zero = p.num(0.0);
        let _ = p.substitute(e, &mut |v| (v == Y).then_some(zero));
    }

    #[test]
    fn memo_reuses_derivatives() {
        let mut p = Pool::new();
        let x = p.var(X);
        let s = p.call1(Func1::Sin, x);
        let e = p.mul(s, s);
        let d1 = p.diff(e, X);
        let n = p.len();
        let d2 = p.diff(e, X);
        assert_eq!(d1, d2);
        assert_eq!(p.len(), n);
    }
}
