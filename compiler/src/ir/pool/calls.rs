//! The simplifying constructors of function calls and table lookups: constants folded,
//! and the identities of `abs`, `sqrt`, `log`, `sign`, odd and even functions.

use super::Pool;
use crate::ir::node::{ExprId, Func1, Func2, Node};

impl Pool {
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
}

#[cfg(test)]
mod tests {
    use super::super::fixture::fx;
    use super::*;

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
}
