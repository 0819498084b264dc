//! The expression emitter: one IR node as Rust code, in the arithmetic of a method ([`Kind`]:
//! `f64`, intervals or eight lanes).
//!
//! Each node is computed with exactly the operations, in exactly the order, of
//! [`crate::ir::Pool::eval`], so the `f64` methods agree with the interpreter bit for bit and
//! the interval methods give the same enclosures. [`Emitter`] also records what a method body
//! reads (`x`, `u`, `t`, `Interval`), so the method writers ([`super::method`],
//! [`super::chunk`]) can name their parameters.

use std::collections::BTreeSet;

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::bake::{float, int};
use super::tables::{column_ident, times_ident, Tables};
use crate::ir::{ExprId, Func1, Func2, Node, Pool, Var};

/// The arithmetic a method runs in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    /// Plain `f64`.
    F64,
    /// `reachc_runtime::Interval`, outward-rounded.
    Interval,
    /// `reachc_runtime::X8` for the values that depend on a state or an input, `f64` for the
    /// others.
    X8,
}

/// Emits one method: `let`s for the non-leaf nodes reachable from the non-constant outputs,
/// then the outputs.
pub(super) struct Emitter<'a> {
    pool: &'a Pool,
    kind: Kind,
    /// Whether the body names `Interval` (then it gets a local `use`).
    uses_interval: bool,
    /// One past the largest index of `x` read (0: `x` is not read).
    pub(super) x_len: usize,
    /// One past the largest index of `u` read (0: `u` is not read).
    pub(super) u_len: usize,
    /// Whether the body reads `t`.
    pub(super) uses_t: bool,
    /// The path of the file's top level, where the tables are (`super::` in a helper module).
    pub(super) top: TokenStream,
    /// [`Kind::X8`]: the `let`s emitted so far whose value is in lanes (depends on a state or
    /// an input).
    lanes: BTreeSet<ExprId>,
}

impl<'a> Emitter<'a> {
    /// An emitter for a body in `kind` arithmetic at the file's top level (see [`Self::top`]).
    pub(super) fn new(pool: &'a Pool, kind: Kind) -> Self {
        Emitter {
            pool,
            kind,
            uses_interval: false,
            x_len: 0,
            u_len: 0,
            uses_t: false,
            top: TokenStream::new(),
            lanes: BTreeSet::new(),
        }
    }

    /// Whether the value of `id` is in lanes (`X8`): only in [`Kind::X8`], and there exactly
    /// when it depends on a state or an input; constants and values of `t` alone stay `f64`.
    /// A node is asked for after its `let` (children come first).
    fn in_lanes(&self, id: ExprId) -> bool {
        self.kind == Kind::X8
            && match self.pool.node(id) {
                Node::Var(v) => matches!(v, Var::State(_) | Var::Input(_)),
                Node::Const(_) | Node::Enclosure { .. } => false,
                _ => self.lanes.contains(&id),
            }
    }

    /// `v`, a value of `f64` type, as lanes: `X8::splat(v)`.
    pub(super) fn splat(v: &TokenStream) -> TokenStream {
        quote!(reachc_runtime::X8::splat(#v))
    }

    /// `use reachc_runtime::Interval;` if the body names `Interval`.
    pub(super) fn use_interval(&self) -> TokenStream {
        if self.uses_interval {
            quote!(
                use reachc_runtime::Interval;
            )
        } else {
            TokenStream::new()
        }
    }

    /// `Interval::ZERO`, as the body names it (with the local `use`).
    pub(super) fn interval_zero(&mut self) -> TokenStream {
        self.uses_interval = true;
        quote!(Interval::ZERO)
    }

    /// A constant in the method's arithmetic.
    fn constant(&mut self, v: f64) -> TokenStream {
        let lit = float(v);
        match self.kind {
            Kind::F64 | Kind::X8 => lit,
            Kind::Interval => {
                self.uses_interval = true;
                quote!(Interval::point(#lit))
            }
        }
    }

    /// The value of a node as an operand: leaves inline, other nodes by their `let` name.
    fn operand(&mut self, id: ExprId) -> TokenStream {
        match self.pool.node(id) {
            Node::Const(c) => self.constant(c.get()),
            &Node::Enclosure { approx, lo, hi } => match self.kind {
                Kind::F64 | Kind::X8 => float(approx.get()),
                Kind::Interval => {
                    self.uses_interval = true;
                    let (lo, hi) = (float(lo.get()), float(hi.get()));
                    quote!(Interval::new(#lo, #hi))
                }
            },
            Node::Var(v) => match *v {
                Var::State(i) => {
                    self.x_len = self.x_len.max(i as usize + 1);
                    let i = int(i as usize);
                    quote!(x[#i])
                }
                Var::Input(j) => {
                    self.u_len = self.u_len.max(j as usize + 1);
                    let j = int(j as usize);
                    quote!(u[#j])
                }
                Var::Time => {
                    self.uses_t = true;
                    quote!(t)
                }
                Var::Noise(k) => panic!("noise channel {k} in a generated expression"),
            },
            _ => {
                let v = value_ident(id);
                quote!(#v)
            }
        }
    }

    /// `recv.method(args)`; in function-call form when the receiver is a constant (a method on
    /// a float literal has an ambiguous type).
    fn method(&mut self, recv: ExprId, method: &str, args: &[TokenStream]) -> TokenStream {
        let m = format_ident!("{}", method);
        let r = self.operand(recv);
        if matches!(
            self.pool.node(recv),
            Node::Const(_) | Node::Enclosure { .. }
        ) {
            let ty = match self.kind {
                Kind::F64 | Kind::X8 => quote!(f64),
                Kind::Interval => {
                    self.uses_interval = true;
                    quote!(Interval)
                }
            };
            quote!(#ty::#m(#r #(, #args)*))
        } else {
            quote!(#r.#m(#(#args),*))
        }
    }

    /// The expression computing node `id` from its children, mirroring `Pool::eval`.
    pub(super) fn node_expr(&mut self, id: ExprId, tables: &mut Tables) -> TokenStream {
        if children(self.pool.node(id))
            .into_iter()
            .any(|c| self.in_lanes(c))
        {
            self.lanes.insert(id);
        }
        match self.pool.node(id) {
            Node::Const(_) | Node::Enclosure { .. } | Node::Var(_) => self.operand(id),
            Node::Sum { constant, terms } => {
                let c = constant.get();
                let mut acc = (c != 0.0).then(|| self.constant(c));
                for &(t, k) in terms {
                    let x = self.operand(t);
                    let k = k.get();
                    let scaled = |e: &mut Self, k: f64| {
                        if k == 1.0 {
                            x.clone()
                        } else {
                            let kk = e.constant(k);
                            quote!(#kk * #x)
                        }
                    };
                    acc = Some(match acc {
                        None if k < 0.0 => {
                            if -k == 1.0 {
                                quote!(-#x)
                            } else {
                                let s = scaled(self, -k);
                                quote!(-(#s))
                            }
                        }
                        None => scaled(self, k),
                        Some(a) if k < 0.0 => {
                            let s = scaled(self, -k);
                            quote!(#a - #s)
                        }
                        Some(a) => {
                            let s = scaled(self, k);
                            quote!(#a + #s)
                        }
                    });
                }
                acc.unwrap_or_else(|| self.constant(0.0))
            }
            Node::Product { factors } => {
                let mut num: Vec<TokenStream> = Vec::new();
                let mut den: Vec<TokenStream> = Vec::new();
                for &(b, e) in factors {
                    let (slot, k) = match e.checked_neg() {
                        Some(m) if e < 0 => (&mut den, m),
                        _ => (&mut num, e),
                    };
                    let p = if k == 1 {
                        self.operand(b)
                    } else {
                        let k = if k == i32::MIN {
                            quote!(i32::MIN)
                        } else {
                            let lit = Literal::i32_unsuffixed(k.abs());
                            if k < 0 {
                                quote!(-#lit)
                            } else {
                                quote!(#lit)
                            }
                        };
                        self.method(b, "powi", &[k])
                    };
                    slot.push(p);
                }
                // left to right, as `eval` multiplies them
                let chain = |v: Vec<TokenStream>| v.into_iter().reduce(|a, b| quote!(#a * #b));
                let many = den.len() > 1;
                let num = chain(num);
                let den = chain(den).map(|d| if many { quote!((#d)) } else { d });
                match (num, den) {
                    (Some(n), Some(d)) => quote!(#n / #d),
                    (Some(n), None) => n,
                    (None, Some(d)) => {
                        let one = self.constant(1.0);
                        quote!(#one / #d)
                    }
                    (None, None) => self.constant(1.0),
                }
            }
            Node::Call1(f, a) => self.call1(*f, *a),
            Node::Call2(f, a, b) => self.call2(*f, *a, *b),
            Node::Table { table, column, arg } => {
                tables.note(*table, *column);
                let a = self.operand(*arg);
                let (top, times, values) = (
                    &self.top,
                    times_ident(*table),
                    column_ident(*table, *column),
                );
                let (times, values) = (quote!(#top #times), quote!(#top #values));
                match self.kind {
                    _ if self.in_lanes(*arg) => {
                        quote!(#a.map(|at| reachc_runtime::table::eval(&#times, &#values, at)))
                    }
                    Kind::F64 | Kind::X8 => {
                        quote!(reachc_runtime::table::eval(&#times, &#values, #a))
                    }
                    Kind::Interval => {
                        quote!(reachc_runtime::table::eval_interval(&#times, &#values, #a))
                    }
                }
            }
        }
    }

    fn call1(&mut self, f: Func1, a: ExprId) -> TokenStream {
        let method = match f {
            Func1::Sin => "sin",
            Func1::Cos => "cos",
            Func1::Tan => "tan",
            Func1::Exp => "exp",
            Func1::Log => "ln",
            Func1::Sqrt => "sqrt",
            Func1::Abs => "abs",
            Func1::Atan => "atan",
            Func1::Sinh => "sinh",
            Func1::Cosh => "cosh",
            Func1::Tanh => "tanh",
            Func1::Sinc | Func1::Sign | Func1::DSinc => {
                let x = self.operand(a);
                let name = match f {
                    Func1::Sinc => "sinc",
                    Func1::Sign => "sign",
                    _ => "dsinc",
                };
                let func = format_ident!("{name}");
                let func = quote!(reachc_runtime::func::#func);
                return match self.kind {
                    Kind::Interval if f == Func1::DSinc => {
                        quote!(reachc_runtime::func::dsinc_interval(#x))
                    }
                    Kind::Interval => self.method(a, name, &[]),
                    _ if self.in_lanes(a) => quote!(#x.map(#func)),
                    Kind::F64 | Kind::X8 => quote!(#func(#x)),
                };
            }
        };
        self.method(a, method, &[])
    }

    fn call2(&mut self, f: Func2, a: ExprId, b: ExprId) -> TokenStream {
        let y = self.operand(b);
        let (a_lanes, b_lanes) = (self.in_lanes(a), self.in_lanes(b));
        match (f, self.kind) {
            (Func2::Min | Func2::Max, kind) => {
                let x = self.operand(a);
                let m = format_ident!("{}", if f == Func2::Min { "min" } else { "max" });
                match kind {
                    _ if a_lanes || b_lanes => quote!(reachc_runtime::X8::#m(#x, #y)),
                    Kind::F64 | Kind::X8 => quote!(f64::#m(#x, #y)),
                    Kind::Interval => {
                        self.uses_interval = true;
                        quote!(Interval::#m(#x, #y))
                    }
                }
            }
            // An `f64` receiver and an argument in lanes: the receiver widened to lanes.
            (Func2::Atan2 | Func2::Pow, _) if !a_lanes && b_lanes => {
                let x = Self::splat(&self.operand(a));
                let m = format_ident!("{}", if f == Func2::Atan2 { "atan2" } else { "powf" });
                quote!(#x.#m(#y))
            }
            (Func2::Atan2, _) => self.method(a, "atan2", &[y]),
            (Func2::Pow, Kind::F64 | Kind::X8) if a_lanes => self.method(a, "powf", &[y]),
            (Func2::Pow, Kind::F64 | Kind::X8) => {
                let x = self.operand(a);
                quote!(reachc_runtime::func::pow(#x, #y))
            }
            (Func2::Pow, Kind::Interval) => self.method(a, "pow", &[y]),
        }
    }
}

/// The name of the `let` holding node `id`, `v12`.
pub(super) fn value_ident(id: ExprId) -> Ident {
    format_ident!("v{}", id.0)
}

/// Whether `id` is a leaf (constant, enclosure or variable), written inline rather than as a
/// `let`.
pub(super) fn is_leaf(pool: &Pool, id: ExprId) -> bool {
    matches!(
        pool.node(id),
        Node::Const(_) | Node::Enclosure { .. } | Node::Var(_)
    )
}

/// The operands of a node, in the order [`Emitter::node_expr`] reads them.
pub(super) fn children(node: &Node) -> Vec<ExprId> {
    match node {
        Node::Const(_) | Node::Enclosure { .. } | Node::Var(_) => Vec::new(),
        Node::Sum { terms, .. } => terms.iter().map(|&(t, _)| t).collect(),
        Node::Product { factors } => factors.iter().map(|&(b, _)| b).collect(),
        Node::Call1(_, a) | Node::Table { arg: a, .. } => vec![*a],
        Node::Call2(_, a, b) => vec![*a, *b],
    }
}

/// The size of a node's `let`, for splitting methods: its number of operands (at least 1).
pub(super) fn node_cost(pool: &Pool, id: ExprId) -> usize {
    children(pool.node(id)).len().max(1)
}

/// The statement writing output `k`, `roots[k] = r`; `None` for a zero already written by
/// `out.fill`.
pub(super) fn output(e: &mut Emitter, k: usize, r: ExprId, fill: bool) -> Option<TokenStream> {
    let value = match e.pool.as_const(r) {
        Some(c) if c == 0.0 && fill => return None,
        Some(c) if c == 0.0 && e.kind == Kind::Interval => e.interval_zero(),
        // a constant or a value of `t` alone, in every lane
        _ if e.kind == Kind::X8 && !e.in_lanes(r) => Emitter::splat(&e.operand(r)),
        _ => e.operand(r),
    };
    let k = int(k);
    Some(quote!(out[#k] = #value;))
}
