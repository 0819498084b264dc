//! A strict test-only parser of the `.sde` expression grammar, for the printer's round trips.

use crate::ir::{ExprId, Func1, Func2, Names, Pool, Var};

/// A strict test-only parser for the `.sde` expression grammar (the real one lives in
/// `syntax`), lowering straight into a pool: `^` takes a power (not a negation) on its
/// right, so `2^-1` is rejected, as are stray characters.
struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    pool: &'a mut Pool,
    names: &'a Names<'a>,
}

impl Parser<'_> {
    fn peek(&mut self) -> u8 {
        while self.s.get(self.i) == Some(&b' ') {
            self.i += 1;
        }
        self.s.get(self.i).copied().unwrap_or(0)
    }
    fn eat(&mut self, c: u8) {
        assert_eq!(self.peek(), c, "expected {:?} at {}", c as char, self.i);
        self.i += 1;
    }
    fn expr(&mut self) -> ExprId {
        let mut a = self.term();
        loop {
            match self.peek() {
                b'+' => {
                    self.i += 1;
                    let b = self.term();
                    a = self.pool.add(a, b);
                }
                b'-' => {
                    self.i += 1;
                    let b = self.term();
                    a = self.pool.sub(a, b);
                }
                _ => return a,
            }
        }
    }
    fn term(&mut self) -> ExprId {
        let mut a = self.unary();
        loop {
            match self.peek() {
                b'*' => {
                    self.i += 1;
                    let b = self.unary();
                    a = self.pool.mul(a, b);
                }
                b'/' => {
                    self.i += 1;
                    let b = self.unary();
                    a = self.pool.div(a, b);
                }
                _ => return a,
            }
        }
    }
    fn unary(&mut self) -> ExprId {
        if self.peek() == b'-' {
            self.i += 1;
            let a = self.unary();
            return self.pool.neg(a);
        }
        self.power()
    }
    fn power(&mut self) -> ExprId {
        let a = self.primary();
        if self.peek() == b'^' {
            self.i += 1;
            let b = self.power();
            return self.pool.pow(a, b);
        }
        a
    }
    fn ident(&mut self) -> String {
        let start = self.i;
        while self
            .s
            .get(self.i)
            .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
        {
            self.i += 1;
        }
        String::from_utf8(self.s[start..self.i].to_vec()).unwrap()
    }
    fn primary(&mut self) -> ExprId {
        let c = self.peek();
        if c == b'(' {
            self.i += 1;
            let e = self.expr();
            self.eat(b')');
            return e;
        }
        if c.is_ascii_digit() || c == b'.' {
            let start = self.i;
            while self
                .s
                .get(self.i)
                .is_some_and(|c| c.is_ascii_digit() || *c == b'.')
            {
                self.i += 1;
            }
            if matches!(self.s.get(self.i), Some(b'e' | b'E')) {
                self.i += 1;
                if matches!(self.s.get(self.i), Some(b'+' | b'-')) {
                    self.i += 1;
                }
                while self.s.get(self.i).is_some_and(u8::is_ascii_digit) {
                    self.i += 1;
                }
            }
            let v: f64 = std::str::from_utf8(&self.s[start..self.i])
                .unwrap()
                .parse()
                .unwrap();
            return self.pool.num(v);
        }
        assert!(
            c.is_ascii_alphabetic() || c == b'_',
            "unexpected {:?} at {}",
            c as char,
            self.i
        );
        let mut name = self.ident();
        match self.s.get(self.i) {
            Some(b'(') => {
                self.i += 1;
                let mut args = vec![self.expr()];
                while self.peek() == b',' {
                    self.i += 1;
                    args.push(self.expr());
                }
                self.eat(b')');
                let f1 = |n: &str| {
                    Some(match n {
                        "sin" => Func1::Sin,
                        "cos" => Func1::Cos,
                        "tan" => Func1::Tan,
                        "exp" => Func1::Exp,
                        "log" => Func1::Log,
                        "sqrt" => Func1::Sqrt,
                        "abs" => Func1::Abs,
                        "atan" => Func1::Atan,
                        "sinh" => Func1::Sinh,
                        "cosh" => Func1::Cosh,
                        "tanh" => Func1::Tanh,
                        "sinc" => Func1::Sinc,
                        "sign" => Func1::Sign,
                        _ => return None,
                    })
                };
                if let Some(f) = f1(&name) {
                    assert_eq!(args.len(), 1);
                    return self.pool.call1(f, args[0]);
                }
                let f = match name.as_str() {
                    "atan2" => Func2::Atan2,
                    "min" => Func2::Min,
                    "max" => Func2::Max,
                    _ => panic!("unknown function {name}"),
                };
                assert_eq!(args.len(), 2);
                self.pool.call2(f, args[0], args[1])
            }
            Some(b'.') => {
                self.i += 1;
                let col = self.ident();
                let ti = self
                    .names
                    .tables
                    .iter()
                    .position(|t| t.name == name)
                    .unwrap();
                let ci = self.names.tables[ti].column_index(&col).unwrap();
                let t = self.pool.var(Var::Time);
                self.pool.table(ti as u32, ci as u32, t)
            }
            _ => {
                if self.s.get(self.i) == Some(&b'[') {
                    let start = self.i;
                    while self.s[self.i] != b']' {
                        self.i += 1;
                    }
                    self.i += 1;
                    name.push_str(std::str::from_utf8(&self.s[start..self.i]).unwrap());
                }
                let find = |l: &[String]| l.iter().position(|n| *n == name).map(|i| i as u32);
                let v = if name == "t" {
                    Var::Time
                } else if let Some(i) = find(self.names.states) {
                    Var::State(i)
                } else if let Some(i) = find(self.names.inputs) {
                    Var::Input(i)
                } else if let Some(i) = find(self.names.noises) {
                    Var::Noise(i)
                } else {
                    panic!("unknown name {name}")
                };
                self.pool.var(v)
            }
        }
    }
}

pub(super) fn parse(pool: &mut Pool, names: &Names<'_>, src: &str) -> ExprId {
    let mut p = Parser {
        s: src.as_bytes(),
        i: 0,
        pool,
        names,
    };
    let e = p.expr();
    assert_eq!(p.peek(), 0, "trailing input in {src:?} at {}", p.i);
    e
}
