//! The simplifying constructors of sums, products and powers: the canonical forms of
//! [`Node::Sum`] and [`Node::Product`], coefficients folded exactly or as enclosures.

use super::Pool;
use crate::ir::fold::Folded;
use crate::ir::node::{ExprId, Func1, Func2, Node, F64};

impl Pool {
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

    /// `Some((t, c))` if `id` is the scaled term `c*t` (a one-term `Sum` without constant).
    pub(in crate::ir) fn scaled_term(&self, id: ExprId) -> Option<(ExprId, f64)> {
        match self.node(id) {
            Node::Sum { constant, terms } if constant.get() == 0.0 && terms.len() == 1 => {
                Some((terms[0].0, terms[0].1.get()))
            }
            _ => None,
        }
    }

    /// `constant + sum(c * e)` in canonical form: nested sums flattened (their coefficients
    /// multiplied through), constants folded, like terms collected, terms sorted by id.
    pub(in crate::ir) fn build_sum(&mut self, constant: f64, items: Vec<(ExprId, f64)>) -> ExprId {
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
    pub(in crate::ir) fn build_product(&mut self, coef: f64, items: Vec<(ExprId, i64)>) -> ExprId {
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
}

#[cfg(test)]
mod tests {
    use super::super::fixture::fx;
    use super::super::for_each_child;
    use super::*;
    use crate::ir::VarValues;

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
}
