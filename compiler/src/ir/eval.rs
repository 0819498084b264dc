//! Evaluation of expressions in any [`Arith`]: `f64` for point values, [`Interval`] for sound
//! enclosures.

use reachc_core::func;
use reachc_core::interval::Interval;

use super::node::{ExprId, Func1, Func2, Node, Var};
use super::pool::Pool;
use super::table::Table;

/// The arithmetic the evaluator runs in. `f64` and [`Interval`] implement it.
///
/// Implementations for sets must be inclusion functions (every operation encloses all values
/// of the real operation over its arguments); the interval one is.
pub trait Arith: Copy {
    /// A constant (for intervals: the point interval, exact).
    fn constant(v: f64) -> Self;
    /// A constant known to lie in `[lo, hi]` whose floating-point value is `approx`
    /// ([`Node::Enclosure`]): `approx` for points, `[lo, hi]` for intervals.
    fn enclosure(approx: f64, lo: f64, hi: f64) -> Self;
    /// `self + o`.
    fn add(self, o: Self) -> Self;
    /// `self - o`.
    fn sub(self, o: Self) -> Self;
    /// `self * o`.
    fn mul(self, o: Self) -> Self;
    /// `self / o`.
    fn div(self, o: Self) -> Self;
    /// `-self`.
    fn neg(self) -> Self;
    /// `self ^ n`.
    fn powi(self, n: i32) -> Self;
    /// The real power `self ^ o` (base must be positive).
    fn pow(self, o: Self) -> Self;
    /// `f(self)`.
    fn call1(self, f: Func1) -> Self;
    /// `f(self, o)`; for `atan2`, `self` is `y` and `o` is `x`.
    fn call2(self, f: Func2, o: Self) -> Self;
    /// Column `column` of `table` at time `at`.
    fn table(table: &Table, column: usize, at: Self) -> Self;
}

/// Values of the model's variables, indexed like [`Var`]'s payloads.
#[derive(Clone, Copy, Debug)]
pub struct VarValues<'a, T> {
    /// `x_i`.
    pub states: &'a [T],
    /// `u_j`.
    pub inputs: &'a [T],
    /// `w_k` (only meaningful before diffusion coefficients are extracted).
    pub noises: &'a [T],
    /// `t`.
    pub time: T,
}

impl Pool {
    /// Evaluates `roots`, sharing common sub-expressions: each node reachable from the roots is
    /// evaluated once, children first (increasing id order).
    ///
    /// `tables` are the model's tables, indexed by `Node::Table::table`. Panics if a variable or
    /// table index is out of range of `vars` / `tables` (a caller bug).
    pub fn eval<T: Arith>(
        &self,
        roots: &[ExprId],
        vars: &VarValues<'_, T>,
        tables: &[Table],
    ) -> Vec<T> {
        self.eval_ordered(&self.reachable(roots), roots, vars, tables)
    }

    /// [`Pool::eval`] with `order = self.reachable(roots)` supplied by the caller, who evaluates
    /// the same roots many times (the interpreter backend, once per integration step).
    pub fn eval_ordered<T: Arith>(
        &self,
        order: &[ExprId],
        roots: &[ExprId],
        vars: &VarValues<'_, T>,
        tables: &[Table],
    ) -> Vec<T> {
        debug_assert!(
            order.windows(2).all(|w| w[0] < w[1]),
            "order must be sorted"
        );
        // `order` is sorted: a child's value is found by binary search (no per-call allocation
        // proportional to the whole pool).
        let at = |vals: &[T], id: ExprId| vals[order.binary_search(&id).expect("child evaluated")];
        let mut vals: Vec<T> = Vec::with_capacity(order.len());
        for &id in order {
            let v = match self.node(id) {
                Node::Const(c) => T::constant(c.get()),
                Node::Enclosure { approx, lo, hi } => {
                    T::enclosure(approx.get(), lo.get(), hi.get())
                }
                Node::Var(v) => match *v {
                    Var::State(i) => vars.states[i as usize],
                    Var::Input(i) => vars.inputs[i as usize],
                    Var::Noise(i) => vars.noises[i as usize],
                    Var::Time => vars.time,
                },
                Node::Sum { constant, terms } => {
                    let mut acc = (constant.get() != 0.0).then(|| T::constant(constant.get()));
                    for &(t, c) in terms {
                        let x = at(&vals, t);
                        let c = c.get();
                        let scaled = |k: f64| if k == 1.0 { x } else { T::constant(k).mul(x) };
                        acc = Some(match acc {
                            None if c < 0.0 => scaled(-c).neg(),
                            None => scaled(c),
                            Some(a) if c < 0.0 => a.sub(scaled(-c)),
                            Some(a) => a.add(scaled(c)),
                        });
                    }
                    acc.unwrap_or_else(|| T::constant(0.0))
                }
                Node::Product { factors } => {
                    // numerator / denominator, so `x/y^2` is a division (as written) rather
                    // than a multiplication by a reciprocal power.
                    let mut num: Option<T> = None;
                    let mut den: Option<T> = None;
                    for &(b, e) in factors {
                        let x = at(&vals, b);
                        let (slot, k) = match e.checked_neg() {
                            Some(m) if e < 0 => (&mut den, m),
                            _ => (&mut num, e), // (i32::MIN stays: powi handles negatives)
                        };
                        let p = if k == 1 { x } else { x.powi(k) };
                        *slot = Some(match *slot {
                            None => p,
                            Some(a) => a.mul(p),
                        });
                    }
                    match (num, den) {
                        (Some(n), Some(d)) => n.div(d),
                        (Some(n), None) => n,
                        (None, Some(d)) => T::constant(1.0).div(d),
                        (None, None) => T::constant(1.0),
                    }
                }
                Node::Call1(f, a) => at(&vals, *a).call1(*f),
                Node::Call2(f, a, b) => at(&vals, *a).call2(*f, at(&vals, *b)),
                Node::Table { table, column, arg } => {
                    T::table(&tables[*table as usize], *column as usize, at(&vals, *arg))
                }
            };
            vals.push(v);
        }
        roots.iter().map(|&r| at(&vals, r)).collect()
    }
}

impl Arith for f64 {
    fn constant(v: f64) -> Self {
        v
    }
    fn enclosure(approx: f64, _lo: f64, _hi: f64) -> Self {
        approx
    }
    fn add(self, o: Self) -> Self {
        self + o
    }
    fn sub(self, o: Self) -> Self {
        self - o
    }
    fn mul(self, o: Self) -> Self {
        self * o
    }
    fn div(self, o: Self) -> Self {
        self / o
    }
    fn neg(self) -> Self {
        -self
    }
    fn powi(self, n: i32) -> Self {
        f64::powi(self, n)
    }
    fn pow(self, o: Self) -> Self {
        reachc_core::func::pow(self, o)
    }
    fn call1(self, f: Func1) -> Self {
        match f {
            Func1::Sin => self.sin(),
            Func1::Cos => self.cos(),
            Func1::Tan => self.tan(),
            Func1::Exp => self.exp(),
            Func1::Log => self.ln(),
            Func1::Sqrt => self.sqrt(),
            Func1::Abs => self.abs(),
            Func1::Atan => self.atan(),
            Func1::Sinh => self.sinh(),
            Func1::Cosh => self.cosh(),
            Func1::Tanh => self.tanh(),
            Func1::Sinc => func::sinc(self),
            Func1::Sign => func::sign(self),
            Func1::DSinc => func::dsinc(self),
        }
    }
    fn call2(self, f: Func2, o: Self) -> Self {
        match f {
            Func2::Atan2 => self.atan2(o),
            Func2::Min => f64::min(self, o),
            Func2::Max => f64::max(self, o),
            Func2::Pow => reachc_core::func::pow(self, o),
        }
    }
    fn table(table: &Table, column: usize, at: Self) -> Self {
        table.eval_f64(column, at)
    }
}

impl Arith for Interval {
    fn constant(v: f64) -> Self {
        Interval::point(v)
    }
    fn enclosure(_approx: f64, lo: f64, hi: f64) -> Self {
        Interval::new(lo, hi)
    }
    fn add(self, o: Self) -> Self {
        self + o
    }
    fn sub(self, o: Self) -> Self {
        self - o
    }
    fn mul(self, o: Self) -> Self {
        self * o
    }
    fn div(self, o: Self) -> Self {
        self / o
    }
    fn neg(self) -> Self {
        -self
    }
    fn powi(self, n: i32) -> Self {
        Interval::powi(self, n)
    }
    fn pow(self, o: Self) -> Self {
        Interval::pow(self, o)
    }
    fn call1(self, f: Func1) -> Self {
        match f {
            Func1::Sin => self.sin(),
            Func1::Cos => self.cos(),
            Func1::Tan => self.tan(),
            Func1::Exp => self.exp(),
            Func1::Log => self.ln(),
            Func1::Sqrt => self.sqrt(),
            Func1::Abs => self.abs(),
            Func1::Atan => self.atan(),
            Func1::Sinh => self.sinh(),
            Func1::Cosh => self.cosh(),
            Func1::Tanh => self.tanh(),
            Func1::Sinc => self.sinc(),
            Func1::Sign => self.sign(),
            Func1::DSinc => func::dsinc_interval(self),
        }
    }
    fn call2(self, f: Func2, o: Self) -> Self {
        match f {
            Func2::Atan2 => self.atan2(o),
            Func2::Min => Interval::min(self, o),
            Func2::Max => Interval::max(self, o),
            Func2::Pow => Interval::pow(self, o),
        }
    }
    fn table(table: &Table, column: usize, at: Self) -> Self {
        table.eval_interval(column, at)
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_exprs::FUNC1;
    use super::*;
    use reachc_test_support::rng::Rng;

    fn table() -> Table {
        Table {
            name: "tab".into(),
            columns: vec!["a".into(), "b".into()],
            times: vec![0.0, 0.5, 1.0, 3.0],
            values: vec![vec![1.0, 3.0, -1.0, 0.5], vec![0.0, 0.1, 0.2, 0.3]],
        }
    }

    /// Expressions over x0, x1 (states), u (input), t, covering every node kind and function.
    fn exprs(p: &mut Pool) -> Vec<ExprId> {
        let x = p.var(Var::State(0));
        let y = p.var(Var::State(1));
        let u = p.var(Var::Input(0));
        let t = p.var(Var::Time);
        let mut out = vec![];
        let xy = p.mul(x, y);
        let two = p.num(2.0);
        let s = p.call1(Func1::Sin, xy);
        let c = p.call1(Func1::Cos, x);
        let sc = p.mul(s, c);
        out.push(p.add(sc, u));
        for f in FUNC1 {
            let arg = if matches!(f, Func1::Log | Func1::Sqrt) {
                let x2 = p.powi(x, 2);
                p.add(x2, two)
            } else {
                p.add(x, y)
            };
            let e = p.call1(f, arg);
            out.push(p.mul(e, u));
        }
        for f in [Func2::Atan2, Func2::Min, Func2::Max] {
            out.push(p.call2(f, x, y));
        }
        let y2 = p.powi(y, 2);
        let base = p.add(y2, two);
        out.push(p.pow(base, x));
        let d = p.div(x, base);
        out.push(p.sub(d, xy));
        let inv = p.powi(base, -3);
        out.push(p.mul(inv, x));
        let tab = p.table(0, 0, t);
        let tab2 = p.table(0, 1, t);
        let e = p.mul(tab, x);
        out.push(p.add(e, tab2));
        out
    }

    #[test]
    fn f64_values() {
        let mut p = Pool::new();
        let x = p.var(Var::State(0));
        let y = p.var(Var::State(1));
        let xy = p.mul(x, y);
        let three = p.num(3.0);
        let e = p.sub(xy, three);
        let y2 = p.powi(y, 2);
        let q = p.div(x, y2);
        let vars = VarValues {
            states: &[2.0, 4.0],
            inputs: &[],
            noises: &[],
            time: 0.0,
        };
        let v = p.eval(&[e, q, xy], &vars, &[]);
        assert_eq!(v, vec![5.0, 0.125, 8.0]);
        let s = p.call1(Func1::Sinc, x);
        let zero = VarValues {
            states: &[0.0, 0.0],
            inputs: &[],
            noises: &[],
            time: 0.0,
        };
        assert_eq!(p.eval(&[s], &zero, &[]), vec![1.0]);
        let sg = p.call1(Func1::Sign, x);
        assert_eq!(p.eval(&[sg], &zero, &[]), vec![0.0]);
        let time = p.var(Var::Time);
        let tab = p.table(0, 0, time);
        let at = |time| {
            let v = VarValues {
                states: &[0.0, 0.0],
                inputs: &[],
                noises: &[],
                time,
            };
            p.eval(&[tab], &v, &[table()])[0]
        };
        assert_eq!(at(0.25), 2.0);
        assert_eq!(at(-1.0), 1.0);
        assert_eq!(at(9.0), 0.5);
    }

    #[test]
    fn intervals_enclose_points() {
        let mut p = Pool::new();
        let es = exprs(&mut p);
        let tables = [table()];
        let mut rng = Rng(0x1234_5678_9abc_def1);
        for round in 0..300 {
            // random box (some straddling 0, some wide, some thin)
            let mut bx = [(0.0, 0.0); 4];
            for b in bx.iter_mut() {
                let c = rng.range(-3.0, 3.0);
                let r = match round % 3 {
                    0 => rng.range(0.0, 0.01),
                    1 => rng.range(0.0, 1.0),
                    _ => rng.range(0.0, 4.0),
                };
                *b = (c - r, c + r);
            }
            let iv: Vec<Interval> = bx.iter().map(|&(l, h)| Interval::new(l, h)).collect();
            let ivars = VarValues {
                states: &iv[0..2],
                inputs: &iv[2..3],
                noises: &[],
                time: iv[3],
            };
            let enc = p.eval(&es, &ivars, &tables);
            for _ in 0..20 {
                let pt: Vec<f64> = bx.iter().map(|&(l, h)| rng.range(l, h)).collect();
                let fvars = VarValues {
                    states: &pt[0..2],
                    inputs: &pt[2..3],
                    noises: &[],
                    time: pt[3],
                };
                let vals = p.eval(&es, &fvars, &tables);
                for (k, (&v, &i)) in vals.iter().zip(&enc).enumerate() {
                    if v.is_finite() {
                        assert!(
                            i.contains(v),
                            "expr {k}: {v} not in {i} for box {bx:?} at {pt:?}"
                        );
                    }
                }
            }
        }
    }
}
