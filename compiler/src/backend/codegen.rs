//! Rust code generation: a model's `System` implementation as straight-line code.
//!
//! [`generate`] returns the text of a generated crate's `src/lib.rs`: a unit struct named after
//! the model ([`super::mangle::type_name`]) implementing `reachc_runtime::System`, its sizes as
//! associated constants, the tables it reads as `static` arrays, and `info()` returning the
//! model's [`ModelInfo`] (sets, analyses and derived constants) as a literal.
//!
//! Every method evaluates its outputs (drift, Jacobian or diffusion entries) as one `let` per
//! IR node reachable from them, in increasing id order (a topological order), so shared
//! sub-expressions are computed once and constant outputs cost nothing. Each node is computed
//! with exactly the operations, in exactly the order, of [`crate::ir::Pool::eval`], so the
//! `f64` methods agree with the interpreter bit for bit and the interval methods give the same
//! enclosures. `sinc`, `sign`, `sinc'` and table interpolation call the same
//! `reachc_runtime::{func, table}` functions the interpreter uses.
//!
//! The text has no inner attributes and no `//!` comments, so it can also be `include!`d. Spec
//! names never become Rust identifiers (except the mangled struct name): they appear only in
//! string literals and doc comments, escaped. The output is deterministic.

use std::collections::BTreeMap;

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote, ToTokens};
use reachc_runtime::system::{
    Analysis, Constants, Inclusion, InitialBall, InitialSet, Integrator, Method, ModelInfo,
    RadiusRule, Rate, UnsafeSet, UnsafeShape,
};

use super::{mangle, Prepared};
use crate::analysis::Derivatives;
use crate::ir::{ExprId, Func1, Func2, Node, Pool, Var};
use crate::model::Model;

/// When an output has at least this many zero entries, it is cleared with one `fill` instead
/// of one assignment per zero.
const FILL_THRESHOLD: usize = 8;

/// Lints generated code may trip over without being wrong: literals that happen to be close to
/// `std` constants (`pi / 2` folded by the compiler), long exact literals, and (pedantic) the
/// style of machine-written code (`v12`/`v17`, long straight-line methods, spec text in docs).
fn allow_lints() -> TokenStream {
    quote! {
        #[allow(
            clippy::approx_constant,
            clippy::excessive_precision,
            clippy::unreadable_literal,
            clippy::similar_names,
            clippy::too_many_lines,
            clippy::wildcard_imports,
            clippy::doc_markdown
        )]
    }
}

/// The text of the generated crate's `src/lib.rs` for `model`, with what [`super::prepare`]
/// derived from it: the Jacobians (computed on its pool), the transformed systems of its
/// coordinate transforms, and its sets, analyses and constants.
///
/// Panics only on a malformed model (a noise variable inside the drift or a diffusion
/// coefficient, or a table index out of range), which the checker rules out.
pub fn generate(model: &Model, prepared: &Prepared) -> String {
    let name = format_ident!("{}", mangle::type_name(&model.name));
    let n = int(model.states.len());
    let p = int(model.inputs.len());
    let m = int(model.noises.len());

    let mut tables = Tables::default();
    let bodies = system_bodies(
        &model.pool,
        &mut tables,
        &model.drift,
        &model.diffusion,
        &prepared.derivatives,
    );
    let mut frame_items = TokenStream::new();
    let mut frame_arms = TokenStream::new();
    for (k, frame) in prepared.frames.iter().enumerate() {
        let frame_name = format_ident!("{name}Frame{k}");
        let frame_bodies = system_bodies(
            &model.pool,
            &mut tables,
            &frame.drift,
            &frame.diffusion,
            &frame.derivatives,
        );
        let doc = format!(
            " `{name}` in the coordinates `y = T x`, `T = {}`: drift `T f(T^-1 y, u, t)`, \
             diffusion `T G(T^-1 y, t)` (the frame {k} of [`{name}`]'s `System::frame`).",
            matrix_text(&frame.transform.matrix)
        );
        let lints = allow_lints();
        let k = int(k);
        frame_arms.extend(quote! { #k => Some(&#frame_name), });
        frame_items.extend(quote! {
            #[doc = #doc]
            #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
            pub struct #frame_name;

            #lints
            impl reachc_runtime::System for #frame_name {
                fn n(&self) -> usize {
                    #name::N
                }
                fn p(&self) -> usize {
                    #name::P
                }
                fn m(&self) -> usize {
                    #name::M
                }
                #frame_bodies
            }
        });
    }
    let frame_fn = if prepared.frames.is_empty() {
        TokenStream::new()
    } else {
        quote! {
            fn frame(&self, k: usize) -> Option<&dyn reachc_runtime::System> {
                match k {
                    #frame_arms
                    _ => None,
                }
            }
        }
    };

    let struct_doc = struct_doc(model);
    let lints = allow_lints();
    let statics = tables.statics(model);
    let info_fn = info_fn(&prepared.info);
    let file = quote! {
        #struct_doc
        #lints
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct #name;

        impl #name {
            /// Number of states `n`.
            pub const N: usize = #n;
            /// Number of inputs `p`.
            pub const P: usize = #p;
            /// Number of noise channels `m`.
            pub const M: usize = #m;
        }

        #lints
        impl reachc_runtime::System for #name {
            fn n(&self) -> usize {
                Self::N
            }
            fn p(&self) -> usize {
                Self::P
            }
            fn m(&self) -> usize {
                Self::M
            }
            #bodies
            #frame_fn
        }

        #frame_items

        #statics

        #info_fn
    };
    format_file(file)
}

/// The `System` methods (f64 and interval) of a drift, diffusion and their Jacobians.
fn system_bodies(
    pool: &Pool,
    tables: &mut Tables,
    drift: &[ExprId],
    diffusion: &[Vec<ExprId>],
    d: &Derivatives,
) -> TokenStream {
    let flat = |m: &[Vec<ExprId>]| -> Vec<ExprId> { m.iter().flatten().copied().collect() };
    let (jac_x, jac_u, diffusion) = (flat(&d.jac_x), flat(&d.jac_u), flat(diffusion));
    let methods = [
        ("drift", drift, true),
        ("jac_x", &jac_x[..], true),
        ("jac_u", &jac_u[..], true),
        ("diffusion", &diffusion[..], false),
    ];
    let mut bodies = TokenStream::new();
    for (method, roots, with_u) in methods {
        for kind in [Kind::F64, Kind::Interval] {
            bodies.extend(method_fn(pool, tables, method, kind, roots, with_u));
        }
    }
    let nonzeros = d.jac_x_dependencies(pool, drift);
    let sparse: Vec<ExprId> = nonzeros.iter().map(|&(_, _, e)| e).collect();
    bodies.extend(method_fn(
        pool,
        tables,
        "jac_x_sparse",
        Kind::Interval,
        &sparse,
        true,
    ));
    let pattern = nonzeros.iter().map(|&(i, j, _)| {
        let (i, j) = (int(i), int(j));
        quote!((#i, #j))
    });
    bodies.extend(quote! {
        fn jac_x_pattern(&self) -> Vec<(usize, usize)> {
            const PATTERN: &[(usize, usize)] = &[#(#pattern),*];
            PATTERN.to_vec()
        }
    });
    bodies
}

/// `[[a, b], [c, d]]`, for docs.
fn matrix_text(m: &[Vec<f64>]) -> String {
    let rows: Vec<String> = m
        .iter()
        .map(|r| {
            let r: Vec<String> = r.iter().map(|&v| short(v)).collect();
            format!("[{}]", r.join(", "))
        })
        .collect();
    format!("[{}]", rows.join(", "))
}

/// The text of the generated crate's `src/main.rs`: the command line of the runtime, run on
/// the model `crate_ident::type_name`.
///
/// Panics if `crate_ident` or `type_name` is not a Rust identifier (pass the results of
/// [`mangle::crate_ident`] and [`mangle::type_name`]).
pub fn main_rs(crate_ident: &str, type_name: &str) -> String {
    let krate = format_ident!("{}", crate_ident);
    let ty = format_ident!("{}", type_name);
    format_file(quote! {
        fn main() -> std::process::ExitCode {
            reachc_runtime::app::main_with(&#krate::#ty, &#krate::info())
        }
    })
}

/// Formats generated tokens with prettyplease. The tokens are produced here, so a parse failure
/// is a bug of this module.
fn format_file(tokens: TokenStream) -> String {
    let file: syn::File = syn::parse2(tokens).expect("generated code parses");
    prettyplease::unparse(&file)
}

/// The arithmetic a method runs in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    F64,
    Interval,
}

/// The `(table, column)` pairs read by the generated code, in a deterministic order.
#[derive(Default)]
struct Tables {
    used: BTreeMap<u32, Vec<u32>>,
}

impl Tables {
    fn note(&mut self, table: u32, column: u32) {
        let cols = self.used.entry(table).or_default();
        if !cols.contains(&column) {
            cols.push(column);
            cols.sort_unstable();
        }
    }

    fn statics(&self, model: &Model) -> TokenStream {
        let lints = allow_lints();
        let mut out = TokenStream::new();
        for (&t, cols) in &self.used {
            let table = &model.tables[t as usize];
            let k = int(table.times.len());
            let times_ident = times_ident(t);
            let times = table.times.iter().map(|&v| float(v));
            let doc = doc_attrs(&format!(
                "Sample times of table `{}` ({k} rows).",
                table.name
            ));
            out.extend(quote! {
                #doc
                #lints
                static #times_ident: [f64; #k] = [#(#times),*];
            });
            for &c in cols {
                let ident = column_ident(t, c);
                let values = table.values[c as usize].iter().map(|&v| float(v));
                let doc = doc_attrs(&format!(
                    "Column `{}` of table `{}`, linearly interpolated in time.",
                    table.columns[c as usize], table.name
                ));
                out.extend(quote! {
                    #doc
                    #lints
                    static #ident: [f64; #k] = [#(#values),*];
                });
            }
        }
        out
    }
}

/// An unsuffixed integer literal (`quote` would print `2usize`).
fn int(i: usize) -> Literal {
    Literal::usize_unsuffixed(i)
}

fn times_ident(table: u32) -> Ident {
    format_ident!("T{}_TIMES", table)
}

fn column_ident(table: u32, column: u32) -> Ident {
    format_ident!("T{}_C{}", table, column)
}

fn value_ident(id: ExprId) -> Ident {
    format_ident!("v{}", id.0)
}

/// An `f64` literal that reads back as exactly `v` (shortest round-trip form); negative values
/// as unary minus, non-finite ones as the `f64` constants.
fn float(v: f64) -> TokenStream {
    if v.is_nan() {
        return quote!(f64::NAN);
    }
    if v.is_infinite() {
        return if v > 0.0 {
            quote!(f64::INFINITY)
        } else {
            quote!(f64::NEG_INFINITY)
        };
    }
    let lit: Literal = format!("{:?}", v.abs())
        .parse()
        .expect("a float's Debug form is a literal");
    if v.is_sign_negative() {
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}

/// Emits one method: `let`s for the non-leaf nodes reachable from the non-constant outputs,
/// then the outputs.
struct Emitter<'a> {
    pool: &'a Pool,
    kind: Kind,
    /// Whether the body names `Interval` (then it gets a local `use`).
    uses_interval: bool,
    uses_x: bool,
    uses_u: bool,
    uses_t: bool,
}

impl Emitter<'_> {
    /// A constant in the method's arithmetic.
    fn constant(&mut self, v: f64) -> TokenStream {
        let lit = float(v);
        match self.kind {
            Kind::F64 => lit,
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
            Node::Var(v) => match *v {
                Var::State(i) => {
                    self.uses_x = true;
                    let i = int(i as usize);
                    quote!(x[#i])
                }
                Var::Input(j) => {
                    self.uses_u = true;
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
        if matches!(self.pool.node(recv), Node::Const(_)) {
            let ty = match self.kind {
                Kind::F64 => quote!(f64),
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
    fn node_expr(&mut self, id: ExprId, tables: &mut Tables) -> TokenStream {
        match self.pool.node(id) {
            Node::Const(_) | Node::Var(_) => self.operand(id),
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
                let times = times_ident(*table);
                let values = column_ident(*table, *column);
                let a = self.operand(*arg);
                match self.kind {
                    Kind::F64 => quote!(reachc_runtime::table::eval(&#times, &#values, #a)),
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
                return match (self.kind, f) {
                    (Kind::F64, Func1::Sinc) => quote!(reachc_runtime::func::sinc(#x)),
                    (Kind::F64, Func1::Sign) => quote!(reachc_runtime::func::sign(#x)),
                    (Kind::F64, _) => quote!(reachc_runtime::func::dsinc(#x)),
                    (Kind::Interval, Func1::Sinc) => self.method(a, "sinc", &[]),
                    (Kind::Interval, Func1::Sign) => self.method(a, "sign", &[]),
                    (Kind::Interval, _) => quote!(reachc_runtime::func::dsinc_interval(#x)),
                };
            }
        };
        self.method(a, method, &[])
    }

    fn call2(&mut self, f: Func2, a: ExprId, b: ExprId) -> TokenStream {
        let y = self.operand(b);
        match (f, self.kind) {
            (Func2::Atan2, _) => self.method(a, "atan2", &[y]),
            (Func2::Pow, Kind::F64) => self.method(a, "powf", &[y]),
            (Func2::Pow, Kind::Interval) => self.method(a, "pow", &[y]),
            (Func2::Min | Func2::Max, kind) => {
                let x = self.operand(a);
                let m = format_ident!("{}", if f == Func2::Min { "min" } else { "max" });
                match kind {
                    Kind::F64 => quote!(f64::#m(#x, #y)),
                    Kind::Interval => {
                        self.uses_interval = true;
                        quote!(Interval::#m(#x, #y))
                    }
                }
            }
        }
    }
}

/// One `System` method (`drift`, `jac_x`, ... with `_interval` for [`Kind::Interval`]) writing
/// `roots` (row-major) to `out`.
fn method_fn(
    pool: &Pool,
    tables: &mut Tables,
    method: &str,
    kind: Kind,
    roots: &[ExprId],
    with_u: bool,
) -> TokenStream {
    let mut e = Emitter {
        pool,
        kind,
        uses_interval: false,
        uses_x: false,
        uses_u: false,
        uses_t: false,
    };
    let zeros = roots
        .iter()
        .filter(|&&r| pool.as_const(r) == Some(0.0))
        .count();
    let fill = zeros >= FILL_THRESHOLD;
    let live: Vec<ExprId> = roots
        .iter()
        .copied()
        .filter(|&r| !matches!(pool.node(r), Node::Const(_)))
        .collect();

    let mut body = TokenStream::new();
    for id in pool.reachable(&live) {
        if matches!(pool.node(id), Node::Const(_) | Node::Var(_)) {
            continue;
        }
        let v = value_ident(id);
        let expr = e.node_expr(id, tables);
        body.extend(quote!(let #v = #expr;));
    }
    if fill {
        let zero = match kind {
            Kind::F64 => quote!(0.0),
            Kind::Interval => {
                e.uses_interval = true;
                quote!(Interval::ZERO)
            }
        };
        body.extend(quote!(out.fill(#zero);));
    }
    for (k, &r) in roots.iter().enumerate() {
        let value = match pool.as_const(r) {
            Some(c) if c == 0.0 && fill => continue,
            Some(c) if c == 0.0 && kind == Kind::Interval => {
                e.uses_interval = true;
                quote!(Interval::ZERO)
            }
            _ => e.operand(r),
        };
        let k = int(k);
        body.extend(quote!(out[#k] = #value;));
    }

    let name_for = |used: bool, name: &str| {
        if used {
            format_ident!("{}", name)
        } else {
            format_ident!("_{}", name)
        }
    };
    let x = name_for(e.uses_x, "x");
    let u = name_for(e.uses_u, "u");
    let t = name_for(e.uses_t, "t");
    let out = name_for(!roots.is_empty(), "out");
    let (fn_name, scalar) = match kind {
        Kind::F64 => (format_ident!("{}", method), quote!(f64)),
        Kind::Interval => (
            format_ident!("{}_interval", method),
            quote!(reachc_runtime::Interval),
        ),
    };
    let use_interval = if e.uses_interval {
        quote!(
            use reachc_runtime::Interval;
        )
    } else {
        TokenStream::new()
    };
    let u_param = if with_u {
        quote!(#u: &[#scalar],)
    } else {
        TokenStream::new()
    };
    quote! {
        fn #fn_name(&self, #x: &[#scalar], #u_param #t: #scalar, #out: &mut [#scalar]) {
            #use_interval
            #body
        }
    }
}

/// One line of text made safe for a `///` comment: control characters (a bare carriage return
/// is an error in doc comments) and bidirectional-text overrides (denied by rustc's
/// `text_direction_codepoint_in_comment`) are written as `\u{..}` escapes.
fn sanitize_doc_line(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    for ch in line.chars() {
        let bidi = matches!(ch, '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}'
            | '\u{200E}' | '\u{200F}' | '\u{061C}');
        if (ch.is_control() && ch != '\t') || bidi {
            out.extend(ch.escape_unicode());
        } else {
            out.push(ch);
        }
    }
    out
}

/// `#[doc = "..."]` attributes, one per line of `text` (each becomes a `///` line). The text is
/// only ever a string literal, so it cannot close the comment or inject code.
fn doc_attrs(text: &str) -> TokenStream {
    let mut out = TokenStream::new();
    for line in text.split('\n') {
        let line = sanitize_doc_line(line.strip_suffix('\r').unwrap_or(line));
        let line = if line.is_empty() {
            String::new()
        } else {
            format!(" {line}")
        };
        out.extend(quote!(#[doc = #line]));
    }
    out
}

/// `text` in a Markdown code block marked `text`, so rustdoc neither interprets it (no
/// intra-doc links from `f[x]`, no emphasis) nor runs indented parts as doctests. The fence is
/// longer than any run of backticks in `text`, so the text cannot close it.
fn fenced(text: &str) -> String {
    let mut longest = 0;
    let mut run = 0;
    for ch in text.chars() {
        run = if ch == '`' { run + 1 } else { 0 };
        longest = longest.max(run);
    }
    let fence = "`".repeat(longest.max(2) + 1);
    format!("{fence}text\n{text}\n{fence}")
}

/// The struct's doc: the model name and the spec's own doc comment, verbatim in a code block.
fn struct_doc(model: &Model) -> TokenStream {
    let mut text = format!(
        "The model `{}`, generated by reachc: implements `reachc_runtime::System`.",
        model.name.replace('`', "'")
    );
    if let Some(doc) = model.doc.as_deref().filter(|d| !d.trim().is_empty()) {
        text.push_str("\n\n");
        text.push_str(&fenced(doc));
    }
    doc_attrs(&text)
}

/// A number for prose: 4 significant digits.
fn short(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let rounded: f64 = format!("{v:.3e}").parse().unwrap_or(v);
    format!("{rounded}")
}

fn string(s: &str) -> TokenStream {
    quote!(String::from(#s))
}

/// `Vec::from([items])` (a plain expression: prettyplease formats it, unlike `vec![..]`).
fn list(items: impl IntoIterator<Item = TokenStream>) -> TokenStream {
    let mut items = items.into_iter().peekable();
    if items.peek().is_none() {
        return quote!(Vec::new());
    }
    quote!(Vec::from([#(#items),*]))
}

fn range((lo, hi): (f64, f64)) -> TokenStream {
    let (lo, hi) = (float(lo), float(hi));
    quote!((#lo, #hi))
}

fn indices(is: &[usize]) -> TokenStream {
    list(is.iter().map(|&i| int(i).into_token_stream()))
}

fn option<T>(v: &Option<T>, f: impl FnOnce(&T) -> TokenStream) -> TokenStream {
    match v {
        Some(x) => {
            let x = f(x);
            quote!(Some(#x))
        }
        None => quote!(None),
    }
}

/// Lists of floats longer than this (metrics are n x n) become `static` arrays inside `info()`
/// instead of temporaries (a million-entry array on the stack would overflow it); mostly-zero
/// ones are stored as `(index, value)` pairs.
const STATIC_FLOATS: usize = 64;

/// Builds the `info()` expression; long float lists go to `statics`.
#[derive(Default)]
struct InfoWriter {
    statics: TokenStream,
    count: usize,
    /// Whether the `sparse` helper is needed.
    uses_sparse: bool,
}

impl InfoWriter {
    fn floats(&mut self, vs: &[f64]) -> TokenStream {
        if vs.len() <= STATIC_FLOATS {
            return list(vs.iter().map(|&v| float(v)));
        }
        let ident = format_ident!("DATA_{}", self.count);
        self.count += 1;
        let nonzero: Vec<(usize, f64)> = vs
            .iter()
            .copied()
            .enumerate()
            .filter(|&(_, v)| v.to_bits() != 0)
            .collect();
        if nonzero.len() * 2 < vs.len() {
            // mostly zeros (an identity metric of a large model): (index, value) pairs
            self.uses_sparse = true;
            let k = int(nonzero.len());
            let len = int(vs.len());
            let pairs = nonzero.iter().map(|&(i, v)| {
                let (i, v) = (int(i), float(v));
                quote!((#i, #v))
            });
            self.statics
                .extend(quote!(static #ident: [(usize, f64); #k] = [#(#pairs),*];));
            return quote!(sparse(#len, &#ident));
        }
        let k = int(vs.len());
        let vs = vs.iter().map(|&v| float(v));
        self.statics
            .extend(quote!(static #ident: [f64; #k] = [#(#vs),*];));
        quote!(#ident.to_vec())
    }

    fn initial_set(&mut self, s: &InitialSet) -> TokenStream {
        let boxes = list(s.boxes.iter().map(|b| option(b, |&r| range(r))));
        let balls: Vec<TokenStream> = s
            .balls
            .iter()
            .map(|b: &InitialBall| {
                let states = indices(&b.states);
                let center = self.floats(&b.center);
                let radius = float(b.radius);
                let metric = option(&b.metric, |m| self.floats(m));
                quote!(InitialBall { states: #states, center: #center, radius: #radius, metric: #metric })
            })
            .collect();
        let balls = list(balls);
        quote!(InitialSet { boxes: #boxes, balls: #balls })
    }

    fn unsafe_set(&mut self, u: &UnsafeSet) -> TokenStream {
        let name = string(&u.name);
        let shape = match &u.shape {
            UnsafeShape::Box(sides) => {
                let sides = list(sides.iter().map(|&(i, r)| {
                    let (i, r) = (int(i), range(r));
                    quote!((#i, #r))
                }));
                quote!(UnsafeShape::Box(#sides))
            }
            UnsafeShape::Ball {
                states,
                center,
                radius,
            } => {
                let (states, center, radius) =
                    (indices(states), self.floats(center), float(*radius));
                quote!(UnsafeShape::Ball { states: #states, center: #center, radius: #radius })
            }
            UnsafeShape::HalfSpace { normal, offset } => {
                let (normal, offset) = (self.floats(normal), float(*offset));
                quote!(UnsafeShape::HalfSpace { normal: #normal, offset: #offset })
            }
        };
        quote!(UnsafeSet { name: #name, shape: #shape })
    }

    fn constants(&mut self, c: &Constants) -> TokenStream {
        let metric = self.floats(&c.metric);
        let (cc, sigma, rho) = (float(c.c), float(c.sigma), float(c.rho));
        let how = string(&c.how);
        quote!(Constants { metric: #metric, c: #cc, sigma: #sigma, rho: #rho, how: #how })
    }

    fn analysis(&mut self, a: &Analysis) -> TokenStream {
        let name = string(&a.name);
        let method = match a.method {
            Method::Contraction => quote!(Method::Contraction),
            Method::Interval => quote!(Method::Interval),
        };
        let (delta, horizon, step) = (float(a.delta), float(a.horizon), float(a.step));
        let radius = match a.radius {
            RadiusRule::Amgf => quote!(RadiusRule::Amgf),
            RadiusRule::Paper(eps) => {
                let eps = float(eps);
                quote!(RadiusRule::Paper(#eps))
            }
            RadiusRule::PaperOptimal => quote!(RadiusRule::PaperOptimal),
        };
        let rate = match a.rate {
            Rate::Certified => quote!(Rate::Certified),
            Rate::Empirical { paths } => quote!(Rate::Empirical { paths: #paths }),
        };
        let integrator = match a.integrator {
            Integrator::Rk4 => quote!(Integrator::Rk4),
            Integrator::Euler => quote!(Integrator::Euler),
        };
        let inclusion = match a.inclusion {
            Inclusion::Natural => quote!(Inclusion::Natural),
            Inclusion::Jacobian => quote!(Inclusion::Jacobian),
            Inclusion::Mixed => quote!(Inclusion::Mixed),
        };
        let outputs = indices(&a.outputs);
        let transform = option(&a.transform, |t| {
            let (matrix, inverse, frame) = (
                self.floats(&t.matrix),
                self.floats(&t.inverse),
                int(t.frame),
            );
            quote!(Transform { matrix: #matrix, inverse: #inverse, frame: #frame })
        });
        let consts = option(&a.constants, |c| self.constants(c));
        let error = option(&a.constants_error, |s| string(s));
        quote! {
            Analysis {
                name: #name,
                method: #method,
                delta: #delta,
                horizon: #horizon,
                step: #step,
                radius: #radius,
                rate: #rate,
                integrator: #integrator,
                inclusion: #inclusion,
                outputs: #outputs,
                transform: #transform,
                constants: #consts,
                constants_error: #error,
            }
        }
    }
}

/// The doc of `info()`: what it holds and, per analysis, its constants and how they were
/// obtained.
fn info_doc(info: &ModelInfo) -> TokenStream {
    let mut text = format!(
        "Names, sets and analyses of the model `{}`, with the constants of Assumption 1\n\
         the compiler derived for each analysis (and how).",
        info.name.replace('`', "'")
    );
    let one_line = |s: &str| s.split_whitespace().collect::<Vec<_>>().join(" ");
    let mut list = Vec::new();
    for a in &info.analyses {
        let method = match a.method {
            Method::Contraction => "contraction",
            Method::Interval => "interval",
        };
        let what = match (&a.constants, &a.constants_error) {
            (Some(c), _) => format!(
                "c = {}, sigma = {}, rho = {}\n    {}",
                match a.rate {
                    Rate::Certified => short(c.c),
                    Rate::Empirical { paths } => format!("empirical ({paths} paths)"),
                },
                short(c.sigma),
                short(c.rho),
                one_line(&c.how)
            ),
            (None, Some(e)) => format!("no constants\n    {}", one_line(e)),
            (None, None) => "no constants".to_string(),
        };
        list.push(format!("{} ({method}): {what}", one_line(&a.name)));
    }
    if !list.is_empty() {
        text.push_str("\n\n");
        text.push_str(&fenced(&list.join("\n")));
    }
    doc_attrs(&text)
}

/// `pub fn info() -> ModelInfo`, the given `info` as a literal.
fn info_fn(info: &ModelInfo) -> TokenStream {
    let doc = info_doc(info);
    let lints = allow_lints();
    let mut w = InfoWriter::default();
    let name = string(&info.name);
    let names = |v: &[String]| list(v.iter().map(|s| string(s)));
    let (states, inputs, noises) = (
        names(&info.states),
        names(&info.inputs),
        names(&info.noises),
    );
    let input_box = list(info.input_box.iter().map(|&r| range(r)));
    let initial = w.initial_set(&info.initial);
    let domain = list(info.domain.iter().map(|&r| range(r)));
    let has_domain = info.has_domain;
    let unsafe_sets: Vec<TokenStream> = info.unsafe_sets.iter().map(|u| w.unsafe_set(u)).collect();
    let unsafe_sets = list(unsafe_sets);
    let analyses: Vec<TokenStream> = info.analyses.iter().map(|a| w.analysis(a)).collect();
    let analyses = list(analyses);
    let mut statics = w.statics;
    if w.uses_sparse {
        statics.extend(quote! {
            fn sparse(len: usize, entries: &[(usize, f64)]) -> Vec<f64> {
                let mut v = vec![0.0; len];
                for &(i, x) in entries {
                    v[i] = x;
                }
                v
            }
        });
    }
    quote! {
        #doc
        #lints
        #[must_use]
        pub fn info() -> reachc_runtime::system::ModelInfo {
            use reachc_runtime::system::*;
            #statics
            ModelInfo {
                name: #name,
                states: #states,
                inputs: #inputs,
                noises: #noises,
                input_box: #input_box,
                initial: #initial,
                domain: #domain,
                has_domain: #has_domain,
                unsafe_sets: #unsafe_sets,
                analyses: #analyses,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_round_trip() {
        for v in [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            -2.5e-300,
            1e300,
            5e-324,
            f64::MAX,
            -f64::MIN_POSITIVE,
        ] {
            let text = float(v).to_string().replace(' ', "");
            let back: f64 = text.parse().unwrap();
            assert_eq!(back.to_bits(), v.to_bits(), "{v} -> {text}");
        }
        assert_eq!(
            float(f64::INFINITY).to_string().replace(' ', ""),
            "f64::INFINITY"
        );
        assert_eq!(
            float(f64::NEG_INFINITY).to_string().replace(' ', ""),
            "f64::NEG_INFINITY"
        );
    }

    #[test]
    fn doc_lines_are_sanitized() {
        let d = doc_attrs("a\r\nb\u{202E}c\u{0}\n*/ } fn evil() {");
        let text = format_file(quote!(#d pub struct S;));
        assert!(text.contains("/// a\n"), "{text}");
        assert!(text.contains(r"b\u{202e}c\u{0}"), "{text}");
        assert!(!text.contains('\r') && !text.contains('\u{202E}'));
        let file = syn::parse_file(&text).unwrap();
        assert_eq!(file.items.len(), 1);
    }

    #[test]
    fn main_rs_parses() {
        let text = main_rs("van_der_pol", "VanDerPol");
        assert!(text.contains("reachc_runtime::app::main_with(&van_der_pol::VanDerPol"));
        syn::parse_file(&text).unwrap();
    }
}
