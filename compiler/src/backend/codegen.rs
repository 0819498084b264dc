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
//! A model with at most [`LANES_MAX_STATES`] states also gets `drift_x8` and `diffusion_x8`,
//! the drift and the diffusion of eight states and inputs at once over `reachc_runtime::X8` for
//! the Monte Carlo simulator: the same expression text as `drift` and `diffusion`, with values
//! that depend on a state or an input in lanes, and the constants, `t` and values of `t` alone
//! as plain `f64` (widened where they meet lanes), so every lane is bit for bit what the `f64`
//! method gives.
//!
//! A method larger than [`Options::split_above`] (a model with hundreds of states) is split into
//! `#[inline(never)]` helper functions of bounded size in private modules, called in sequence,
//! values crossing from one to a later one passing through a scratch array; its dense interval
//! Jacobian is then scattered from the sparse one. rustc compiles that in a minute where it
//! never finished one giant function; the results are the same, bit for bit.
//!
//! Meant to be read: its first line marks it `@generated` ([`generated_header`]), each method's
//! doc says what it computes and quotes the spec equations it implements (`docs`, bounded for
//! large models), and the modules `state`, `input` and `noise` name the index of each variable
//! (`indices`).
//!
//! The text has no inner attributes and no `//!` comments, so it can also be `include!`d. Spec
//! names become Rust identifiers only through [`mangle`] (the struct name, also lowercased in
//! the names of helper modules, and the index constants); otherwise they appear only in string
//! literals and doc comments, escaped. The output is deterministic.

use std::collections::{BTreeMap, BTreeSet};

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote, ToTokens};
use reachc_core::model::{
    Analysis, AutoFit, Ball, Bounds, Constants, GoalSet, Guarantee, Inclusion, InitialSet,
    InputGain, Integrator, MatrixBound, Method, MetricChoice, MetricRegion, ModelInfo, Moving,
    Provenance, RadiusRule, Rate, Slot, Split, TransformSource, UnsafeSet, UnsafeShape,
};

use super::{mangle, Prepared};
use crate::analysis::Derivatives;
use crate::ir::{ExprId, Func1, Func2, Names, Node, Pool, Var};
use crate::model::{Model, Variable};

mod docs;
mod indices;

use docs::{MethodDoc, SystemDocs};

/// When an output has at least this many zero entries, it is cleared with one `fill` instead
/// of one assignment per zero.
const FILL_THRESHOLD: usize = 8;

/// Models with at most this many states get `drift_x8` and `diffusion_x8` (the simulator runs
/// eight sample paths in lanes only for small models; larger ones keep the defaults, per
/// lane).
pub const LANES_MAX_STATES: usize = 4;

/// The default [`Options::split_above`]: every shipped spec but specs/chain1000.sde stays below
/// (the largest method of the others costs 140), so their code is one function per method.
pub const SPLIT_ABOVE: usize = 500;

/// The default [`Options::chunk_size`]: at most about 100 lines of generated code per function.
/// rustc's optimiser is superlinear in the size of a function, and the interval arithmetic it
/// inlines makes the code it sees much larger than the source (docs/benchmarks.md, "Large
/// generated crates").
pub const CHUNK_SIZE: usize = 100;

/// How [`generate_with`] writes code.
///
/// The cost of a method body is one unit per operand of each node it computes and one per
/// output it writes. Results are the same whatever the options, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// A method whose body would cost more than this is split into helper functions, called in
    /// sequence; a smaller one is a single function.
    pub split_above: usize,
    /// The largest cost of one helper function of a split method.
    pub chunk_size: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            split_above: SPLIT_ABOVE,
            chunk_size: CHUNK_SIZE,
        }
    }
}

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
    generate_with(model, prepared, &Options::default())
}

/// [`generate`] with explicit [`Options`].
pub fn generate_with(model: &Model, prepared: &Prepared, options: &Options) -> String {
    let name = format_ident!("{}", mangle::type_name(&model.name));
    let n = int(model.states.len());
    let p = int(model.inputs.len());
    let m = int(model.noises.len());

    let lanes = model.states.len() <= LANES_MAX_STATES;
    let spec_names =
        |vars: &[Variable]| -> Vec<String> { vars.iter().map(|v| v.name.clone()).collect() };
    let (states, inputs, noises) = (
        spec_names(&model.states),
        spec_names(&model.inputs),
        spec_names(&model.noises),
    );
    let names = Names {
        states: &states,
        inputs: &inputs,
        noises: &noises,
        tables: &model.tables,
    };
    // A frame's states are the coordinates `y = T x`, 1-based as specs and transform.rs write
    // them.
    let ys: Vec<String> = (1..=states.len()).map(|i| format!("y{i}")).collect();
    let frame_names = Names {
        states: &ys,
        ..names
    };
    let mut tables = Tables::default();
    let (bodies, helpers) = system_bodies(
        &model.pool,
        &mut tables,
        &name,
        (&model.drift, &model.diffusion),
        (&prepared.derivatives, &names),
        (options, lanes),
    );
    // The moving sets' numbers (method.md 8.15): an inherent method of the model's shape,
    // which the trait's `set_numbers` calls.
    let numbers_doc = docs::MethodDoc::set_numbers(&model.pool, &names, &model.set_numbers);
    let numbers_def = MethodDef {
        name: "set_numbers_of",
        kind: Kind::Interval,
        roots: &model.set_numbers,
        with_u: false,
        owner: &name,
        doc: &numbers_doc,
    };
    let (numbers_fn, numbers_helpers, set_numbers) = if model.set_numbers.is_empty() {
        (TokenStream::new(), TokenStream::new(), TokenStream::new())
    } else {
        let (f, h) = method_fn(&model.pool, &mut tables, &numbers_def, options);
        let lints = allow_lints();
        let f = quote! {
            #lints
            impl #name {
                #f
            }
        };
        let call = quote! {
            fn set_numbers(
                &self,
                t: reachc_runtime::Interval,
                out: &mut [reachc_runtime::Interval],
            ) {
                self.set_numbers_of_interval(&[], t, out);
            }
        };
        (f, h, call)
    };
    let mut frame_items = TokenStream::new();
    let mut frame_arms = TokenStream::new();
    for (k, frame) in prepared.frames.iter().enumerate() {
        let frame_name = format_ident!("{name}Frame{k}");
        let (frame_bodies, frame_helpers) = system_bodies(
            &model.pool,
            &mut tables,
            &frame_name,
            (&frame.drift, &frame.diffusion),
            (&frame.derivatives, &frame_names),
            (options, lanes),
        );
        let doc = format!(
            " `{name}` in the coordinates `y = T x`, `T = {}`: drift `T f(T^-1 y, u, t)`, \
             diffusion `T G(T^-1 y, t)` (the frame {k} of [`{name}`]'s `System::frame`).",
            matrix_text(&frame.transform.matrix, model.states.len())
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

            #frame_helpers
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
    let index_modules = indices::index_modules(&names);
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

        #numbers_fn

        #index_modules

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
            #set_numbers
        }

        #helpers

        #numbers_helpers

        #frame_items

        #statics

        #info_fn
    };
    generated_header("//") + &format_file(file)
}

/// The first line of every generated file, after the comment marker of its language (`//`,
/// `#`): made by which reachc, not to be edited, and the `@generated` marker that review tools
/// and rustfmt's `format_generated_files` recognise. No timestamp or path: the output stays
/// deterministic.
pub fn generated_header(comment: &str) -> String {
    let version = env!("CARGO_PKG_VERSION");
    format!(
        "{comment} Generated by reachc {version} (@generated): do not edit, regenerate it from \
         the spec.\n"
    )
}

/// The `System` methods (f64 and interval) of a drift, diffusion and their Jacobians, and the
/// modules of helper functions of those split into chunks (see [`chunked_method`]); with
/// `lanes`, also `drift_x8` and `diffusion_x8` (unless they would be chunked).
fn system_bodies(
    pool: &Pool,
    tables: &mut Tables,
    owner: &Ident,
    (drift, diffusion): (&[ExprId], &[Vec<ExprId>]),
    (d, names): (&Derivatives, &Names<'_>),
    (options, lanes): (&Options, bool),
) -> (TokenStream, TokenStream) {
    let nonzeros = d.jac_x_dependencies(pool, drift);
    let docs = SystemDocs::new(pool, names, (drift, diffusion), d, &nonzeros);
    let flat = |m: &[Vec<ExprId>]| -> Vec<ExprId> { m.iter().flatten().copied().collect() };
    let (jac_x, jac_u, diffusion) = (flat(&d.jac_x), flat(&d.jac_u), flat(diffusion));
    let methods = [
        ("drift", drift, true, &docs.drift),
        ("jac_x", &jac_x[..], true, &docs.jac_x),
        ("jac_u", &jac_u[..], true, &docs.jac_u),
        ("diffusion", &diffusion[..], false, &docs.diffusion),
    ];
    let sparse: Vec<ExprId> = nonzeros.iter().map(|&(_, _, e)| e).collect();
    let def = MethodDef {
        name: "jac_x_sparse",
        kind: Kind::Interval,
        roots: &sparse,
        with_u: true,
        owner,
        doc: &docs.jac_x_sparse,
    };
    let (sparse_fn, sparse_helpers) = method_fn(pool, tables, &def, options);
    // A sparse Jacobian large enough to be split: the dense one is scattered from it rather
    // than computed by as much code again (its other entries are the constant 0).
    let scatter = (!sparse_helpers.is_empty()).then(|| {
        let n = drift.len();
        let index = nonzeros.iter().map(|&(i, j, _)| int(i * n + j));
        let nonzeros = scratch_array(
            "nonzeros",
            &quote!(reachc_runtime::Interval::ZERO),
            sparse.len(),
        );
        let doc = docs.jac_x.attrs(Kind::Interval);
        quote! {
            #doc
            fn jac_x_interval(
                &self,
                x: &[reachc_runtime::Interval],
                u: &[reachc_runtime::Interval],
                t: reachc_runtime::Interval,
                out: &mut [reachc_runtime::Interval],
            ) {
                const INDEX: &[usize] = &[#(#index),*];
                out.fill(reachc_runtime::Interval::ZERO);
                #nonzeros
                self.jac_x_sparse_interval(x, u, t, &mut nonzeros);
                for (&k, &v) in INDEX.iter().zip(&nonzeros) {
                    out[k] = v;
                }
            }
        }
    });

    let mut bodies = TokenStream::new();
    let mut helpers = TokenStream::new();
    for (name, roots, with_u, doc) in methods {
        for kind in [Kind::F64, Kind::Interval] {
            if let (Some(method), ("jac_x", Kind::Interval)) = (&scatter, (name, kind)) {
                bodies.extend(method.clone());
                continue;
            }
            let def = MethodDef {
                name,
                kind,
                roots,
                with_u,
                owner,
                doc,
            };
            let (method, parts) = method_fn(pool, tables, &def, options);
            bodies.extend(method);
            helpers.extend(parts);
        }
    }
    if lanes {
        let x8 = [
            ("drift", drift, true, &docs.drift),
            ("diffusion", &diffusion[..], false, &docs.diffusion),
        ];
        for (name, roots, with_u, doc) in x8 {
            let def = MethodDef {
                name,
                kind: Kind::X8,
                roots,
                with_u,
                owner,
                doc,
            };
            // Never split: a method that would be is left to the trait's default.
            let (method, _) = method_fn(pool, tables, &def, options);
            bodies.extend(method);
        }
    }
    bodies.extend(sparse_fn);
    helpers.extend(sparse_helpers);
    let pattern = nonzeros.iter().map(|&(i, j, _)| {
        let (i, j) = (int(i), int(j));
        quote!((#i, #j))
    });
    // No arithmetic: the plain form of the doc.
    let doc = docs.jac_x_pattern.attrs(Kind::F64);
    bodies.extend(quote! {
        #doc
        fn jac_x_pattern(&self) -> Vec<(usize, usize)> {
            const PATTERN: &[(usize, usize)] = &[#(#pattern),*];
            PATTERN.to_vec()
        }
    });
    (bodies, helpers)
}

/// An `n x n` row-major matrix as text for docs, `[[a, b], [c, d]]`.
fn matrix_text(m: &[f64], n: usize) -> String {
    let rows: Vec<String> = m
        .chunks(n.max(1))
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
    generated_header("//")
        + &format_file(quote! {
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
    /// `reachc_runtime::X8` for the values that depend on a state or an input, `f64` for the
    /// others.
    X8,
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
    /// One past the largest index of `x` read (0: `x` is not read).
    x_len: usize,
    /// One past the largest index of `u` read (0: `u` is not read).
    u_len: usize,
    uses_t: bool,
    /// The path of the file's top level, where the tables are (`super::` in a helper module).
    top: TokenStream,
    /// [`Kind::X8`]: the `let`s emitted so far whose value is in lanes (depends on a state or
    /// an input).
    lanes: BTreeSet<ExprId>,
}

impl<'a> Emitter<'a> {
    fn new(pool: &'a Pool, kind: Kind) -> Self {
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
    fn splat(v: &TokenStream) -> TokenStream {
        quote!(reachc_runtime::X8::splat(#v))
    }

    /// `use reachc_runtime::Interval;` if the body names `Interval`.
    fn use_interval(&self) -> TokenStream {
        if self.uses_interval {
            quote!(
                use reachc_runtime::Interval;
            )
        } else {
            TokenStream::new()
        }
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
    fn node_expr(&mut self, id: ExprId, tables: &mut Tables) -> TokenStream {
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

/// What one generated `System` method computes.
struct MethodDef<'a> {
    /// `drift`, `jac_x`, ... (`_interval` is appended for [`Kind::Interval`]).
    name: &'a str,
    kind: Kind,
    /// The outputs, row-major.
    roots: &'a [ExprId],
    /// Whether the method takes the inputs `u` (all but the diffusion do).
    with_u: bool,
    /// The type implementing the method (for its helpers' module names).
    owner: &'a Ident,
    /// What the method computes, with the equations.
    doc: &'a MethodDoc,
}

impl MethodDef<'_> {
    fn fn_name(&self) -> Ident {
        match self.kind {
            Kind::F64 => format_ident!("{}", self.name),
            Kind::Interval => format_ident!("{}_interval", self.name),
            Kind::X8 => format_ident!("{}_x8", self.name),
        }
    }

    /// The type of the elements of `x`, `u` and `out`.
    fn scalar(&self) -> TokenStream {
        match self.kind {
            Kind::F64 => quote!(f64),
            Kind::Interval => quote!(reachc_runtime::Interval),
            Kind::X8 => quote!(reachc_runtime::X8),
        }
    }

    /// The type of `t`: one time for all lanes.
    fn time(&self) -> TokenStream {
        match self.kind {
            Kind::X8 => quote!(f64),
            Kind::F64 | Kind::Interval => self.scalar(),
        }
    }

    /// `0.0`, `Interval::ZERO` or `X8::splat(0.0)` as the method body can name it.
    fn zero(&self) -> TokenStream {
        match self.kind {
            Kind::F64 => quote!(0.0),
            Kind::Interval => quote!(reachc_runtime::Interval::ZERO),
            Kind::X8 => Emitter::splat(&quote!(0.0)),
        }
    }
}

/// `x`, or `_x` when the body does not read it.
fn param_name(used: bool, name: &str) -> Ident {
    if used {
        format_ident!("{}", name)
    } else {
        format_ident!("_{}", name)
    }
}

/// Whether `id` is a leaf (constant, enclosure or variable), written inline rather than as a
/// `let`.
fn is_leaf(pool: &Pool, id: ExprId) -> bool {
    matches!(
        pool.node(id),
        Node::Const(_) | Node::Enclosure { .. } | Node::Var(_)
    )
}

/// The operands of a node, in the order [`Emitter::node_expr`] reads them.
fn children(node: &Node) -> Vec<ExprId> {
    match node {
        Node::Const(_) | Node::Enclosure { .. } | Node::Var(_) => Vec::new(),
        Node::Sum { terms, .. } => terms.iter().map(|&(t, _)| t).collect(),
        Node::Product { factors } => factors.iter().map(|&(b, _)| b).collect(),
        Node::Call1(_, a) | Node::Table { arg: a, .. } => vec![*a],
        Node::Call2(_, a, b) => vec![*a, *b],
    }
}

/// The size of a node's `let`, for splitting methods: its number of operands (at least 1).
fn node_cost(pool: &Pool, id: ExprId) -> usize {
    children(pool.node(id)).len().max(1)
}

/// The statement writing output `k`, `roots[k] = r`; `None` for a zero already written by
/// `out.fill`.
fn output(e: &mut Emitter, k: usize, r: ExprId, fill: bool) -> Option<TokenStream> {
    let value = match e.pool.as_const(r) {
        Some(c) if c == 0.0 && fill => return None,
        Some(c) if c == 0.0 && e.kind == Kind::Interval => {
            e.uses_interval = true;
            quote!(Interval::ZERO)
        }
        // a constant or a value of `t` alone, in every lane
        _ if e.kind == Kind::X8 && !e.in_lanes(r) => Emitter::splat(&e.operand(r)),
        _ => e.operand(r),
    };
    let k = int(k);
    Some(quote!(out[#k] = #value;))
}

/// One `System` method (`drift`, `jac_x`, ... with `_interval` for [`Kind::Interval`]) writing
/// its roots (row-major) to `out`, and the helper functions it calls: none unless its body
/// would cost more than [`Options::split_above`] (see [`chunked_method`]).
fn method_fn(
    pool: &Pool,
    tables: &mut Tables,
    def: &MethodDef,
    options: &Options,
) -> (TokenStream, TokenStream) {
    let (kind, roots) = (def.kind, def.roots);
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
    let lets: Vec<ExprId> = pool
        .reachable(&live)
        .into_iter()
        .filter(|&id| !is_leaf(pool, id))
        .collect();
    let writes = if fill {
        roots.len() - zeros
    } else {
        roots.len()
    };
    let cost = lets.iter().map(|&id| node_cost(pool, id)).sum::<usize>() + writes;
    if cost > options.split_above {
        if kind == Kind::X8 {
            // Only small models run in lanes; a method that large keeps the trait's default.
            return (TokenStream::new(), TokenStream::new());
        }
        return chunked_method(pool, tables, def, fill, options.chunk_size);
    }

    let mut e = Emitter::new(pool, kind);
    let mut body = TokenStream::new();
    for id in lets {
        let v = value_ident(id);
        let expr = e.node_expr(id, tables);
        body.extend(quote!(let #v = #expr;));
    }
    if fill {
        let zero = match kind {
            Kind::F64 | Kind::X8 => def.zero(),
            Kind::Interval => {
                e.uses_interval = true;
                quote!(Interval::ZERO)
            }
        };
        body.extend(quote!(out.fill(#zero);));
    }
    for (k, &r) in roots.iter().enumerate() {
        body.extend(output(&mut e, k, r, fill));
    }

    let x = param_name(e.x_len > 0, "x");
    let u = param_name(e.u_len > 0, "u");
    let t = param_name(e.uses_t, "t");
    let out = param_name(!roots.is_empty(), "out");
    let (fn_name, scalar, time) = (def.fn_name(), def.scalar(), def.time());
    let use_interval = e.use_interval();
    let u_param = if def.with_u {
        quote!(#u: &[#scalar],)
    } else {
        TokenStream::new()
    };
    // The simulator's vector loop calls `drift_x8` once per step of eight paths: inlined, its
    // lanes stay in vector registers (a call passes them through memory) and it is compiled
    // with the loop's processor extensions (fused multiply-adds in `X8::sin`).
    let inline = if kind == Kind::X8 {
        quote!(#[inline(always)])
    } else {
        TokenStream::new()
    };
    let doc = def.doc.attrs(kind);
    let method = quote! {
        #doc
        #inline
        fn #fn_name(&self, #x: &[#scalar], #u_param #t: #time, #out: &mut [#scalar]) {
            #use_interval
            #body
        }
    };
    (method, TokenStream::new())
}

/// One step of a chunked method: a node's `let` or the assignment of output `k`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Step {
    Let(ExprId),
    Out(usize),
}

/// The steps of a chunked method: for each output in turn, the nodes it needs that are not
/// computed yet (depth first, operands in order), then its assignment; zeros written by
/// `out.fill` are left out. A topological order in which a node is computed close to where it
/// is read, so few values cross from one chunk to another.
fn steps(pool: &Pool, roots: &[ExprId], fill: bool) -> Vec<Step> {
    let mut seen = vec![false; pool.len()];
    let mut steps = Vec::new();
    // (node, its operands, how many of them were visited)
    let mut stack: Vec<(ExprId, Vec<ExprId>, usize)> = Vec::new();
    for (k, &r) in roots.iter().enumerate() {
        if fill && pool.as_const(r) == Some(0.0) {
            continue;
        }
        if !is_leaf(pool, r) && !seen[r.index()] {
            seen[r.index()] = true;
            stack.push((r, children(pool.node(r)), 0));
            while let Some((id, operands, next)) = stack.last_mut() {
                if let Some(&c) = operands.get(*next) {
                    *next += 1;
                    if !is_leaf(pool, c) && !seen[c.index()] {
                        seen[c.index()] = true;
                        stack.push((c, children(pool.node(c)), 0));
                    }
                } else {
                    steps.push(Step::Let(*id));
                    stack.pop();
                }
            }
        }
        steps.push(Step::Out(k));
    }
    steps
}

/// Scratch arrays of up to this many values live on the stack (64 KiB of intervals); longer
/// ones are allocated.
const STACK_SCRATCH: usize = 4096;

/// `let mut NAME = [zero; len];`, or a `Vec` when longer than [`STACK_SCRATCH`].
fn scratch_array(name: &str, zero: &TokenStream, len: usize) -> TokenStream {
    let (name, n) = (format_ident!("{name}"), int(len));
    if len <= STACK_SCRATCH {
        quote!(let mut #name = [#zero; #n];)
    } else {
        quote! {
            #[allow(clippy::useless_vec)]
            let mut #name = vec![#zero; #n];
        }
    }
}

/// The helper functions of a chunked method are grouped in modules of this many: rustc compiles
/// each module as its own codegen unit, in parallel.
const PARTS_PER_MODULE: usize = 8;

/// A method too large for one function (rustc's optimiser is superlinear in the size of a
/// function: a 1000-state chain did not compile in 16 minutes): its [`steps`] are cut into
/// chunks of cost at most `chunk_size` (see [`node_cost`]), each an `#[inline(never)]` function
/// `NAME_partK`, called in order by the method. The functions are grouped in private modules
/// `OWNER_NAME_G` (the owner's type name in lowercase), [`PARTS_PER_MODULE`] to a module. A
/// value computed in one chunk and read in later ones goes through a scratch array `s` the
/// method owns (a slot is reused once its last reader has loaded it). Every node is still
/// computed by [`Emitter::node_expr`], so results stay bit-identical to the single-function
/// form.
fn chunked_method(
    pool: &Pool,
    tables: &mut Tables,
    def: &MethodDef,
    fill: bool,
    chunk_size: usize,
) -> (TokenStream, TokenStream) {
    let mut chunks: Vec<Vec<Step>> = Vec::new();
    let mut current: Vec<Step> = Vec::new();
    let mut cost = 0;
    for step in steps(pool, def.roots, fill) {
        let c = match step {
            Step::Let(id) => node_cost(pool, id),
            Step::Out(_) => 1,
        };
        if cost + c > chunk_size && !current.is_empty() {
            chunks.push(std::mem::take(&mut current));
            cost = 0;
        }
        current.push(step);
        cost += c;
    }
    if !current.is_empty() {
        chunks.push(current);
    }

    // Where each value is computed, which earlier values each chunk reads, and the last chunk
    // reading each value that crosses chunks.
    let mut defined: BTreeMap<ExprId, usize> = BTreeMap::new();
    let mut imports: Vec<BTreeSet<ExprId>> = vec![BTreeSet::new(); chunks.len()];
    let mut last_read: BTreeMap<ExprId, usize> = BTreeMap::new();
    for (c, chunk) in chunks.iter().enumerate() {
        for &step in chunk {
            let reads = match step {
                Step::Let(id) => {
                    defined.insert(id, c);
                    children(pool.node(id))
                }
                Step::Out(k) => vec![def.roots[k]],
            };
            for r in reads {
                if let Some(&d) = defined.get(&r).filter(|&&d| d != c) {
                    debug_assert!(d < c, "steps are topologically ordered");
                    imports[c].insert(r);
                    last_read.insert(r, c);
                }
            }
        }
    }
    let mut slots: BTreeMap<ExprId, usize> = BTreeMap::new();
    let mut free: Vec<usize> = Vec::new();
    let mut len = 0;
    for (c, chunk) in chunks.iter().enumerate() {
        // Loads come first in a chunk, so a slot read for the last time is free for the
        // chunk's own stores.
        free.extend(
            imports[c]
                .iter()
                .filter(|id| last_read[id] == c)
                .map(|id| slots[id]),
        );
        for &step in chunk {
            if let Step::Let(id) = step {
                if last_read.contains_key(&id) {
                    let slot = free.pop().unwrap_or_else(|| {
                        len += 1;
                        len - 1
                    });
                    slots.insert(id, slot);
                }
            }
        }
    }

    let (fn_name, scalar, time) = (def.fn_name(), def.scalar(), def.time());
    let owner = def.owner.to_string().to_ascii_lowercase();
    let (mut uses_x, mut uses_u, mut uses_t) = (false, false, false);
    let mut helpers = TokenStream::new();
    let mut module = TokenStream::new();
    let mut calls = TokenStream::new();
    for (c, chunk) in chunks.iter().enumerate() {
        let mut e = Emitter::new(pool, def.kind);
        e.top = quote!(super::);
        let mut body = TokenStream::new();
        // One past the largest index of `s` and of `out` used.
        let (mut s_len, mut out_len) = (0, 0);
        for id in &imports[c] {
            s_len = s_len.max(slots[id] + 1);
            let (v, slot) = (value_ident(*id), int(slots[id]));
            body.extend(quote!(let #v = s[#slot];));
        }
        let mut stores = false;
        for &step in chunk {
            match step {
                Step::Let(id) => {
                    let v = value_ident(id);
                    let expr = e.node_expr(id, tables);
                    body.extend(quote!(let #v = #expr;));
                    if let Some(&slot) = slots.get(&id) {
                        s_len = s_len.max(slot + 1);
                        let slot = int(slot);
                        body.extend(quote!(s[#slot] = #v;));
                        stores = true;
                    }
                }
                Step::Out(k) => {
                    body.extend(output(&mut e, k, def.roots[k], fill));
                    out_len = k + 1;
                }
            }
        }
        uses_x |= e.x_len > 0;
        uses_u |= e.u_len > 0;
        uses_t |= e.uses_t;
        // Parameters, and each slice cut to the prefix the chunk indexes, so that the bounds
        // checks of its constant indices fold into one per slice.
        let (mut params, mut args, mut prefixes) =
            (TokenStream::new(), TokenStream::new(), TokenStream::new());
        if e.uses_t {
            params.extend(quote!(t: #time,));
            args.extend(quote!(t,));
        }
        // `arg` passes the slice: `x`, `out` (the method's parameters) or `&mut s` (its array).
        let mut slice = |name: &str, len: usize, mutable: bool, arg: TokenStream| {
            if len == 0 {
                return;
            }
            let (ident, len) = (format_ident!("{name}"), int(len));
            args.extend(quote!(#arg,));
            if mutable {
                params.extend(quote!(#ident: &mut [#scalar],));
                prefixes.extend(quote!(let #ident = &mut #ident[..#len];));
            } else {
                params.extend(quote!(#ident: &[#scalar],));
                prefixes.extend(quote!(let #ident = &#ident[..#len];));
            }
        };
        slice("x", e.x_len, false, quote!(x));
        slice("u", e.u_len, false, quote!(u));
        let s_arg = if stores { quote!(&mut s) } else { quote!(&s) };
        slice("s", s_len, stores, s_arg);
        slice("out", out_len, true, quote!(out));
        let part = format_ident!("{fn_name}_part{c}");
        let doc = format!(" Part {} of {} of `{fn_name}`.", c + 1, chunks.len());
        let use_interval = e.use_interval();
        module.extend(quote! {
            #[doc = #doc]
            #[inline(never)]
            pub(super) fn #part(#params) {
                #use_interval
                #prefixes
                #body
            }
        });
        let group = c / PARTS_PER_MODULE;
        let module_name = format_ident!("{owner}_{fn_name}_{group}");
        calls.extend(quote!(#module_name::#part(#args);));
        if (c + 1) % PARTS_PER_MODULE == 0 || c + 1 == chunks.len() {
            let doc = format!(" Helpers of `{}::{fn_name}` (group {group}).", def.owner);
            let lints = allow_lints();
            helpers.extend(quote! {
                #[doc = #doc]
                #lints
                mod #module_name {
                    #module
                }
            });
            module = TokenStream::new();
        }
    }

    let zero = def.zero();
    let fill = if fill {
        quote!(out.fill(#zero);)
    } else {
        TokenStream::new()
    };
    let scratch = match len {
        0 => TokenStream::new(),
        len => scratch_array("s", &zero, len),
    };
    let x = param_name(uses_x, "x");
    let u = param_name(uses_u, "u");
    let t = param_name(uses_t, "t");
    let u_param = if def.with_u {
        quote!(#u: &[#scalar],)
    } else {
        TokenStream::new()
    };
    let doc = def.doc.attrs(def.kind);
    let method = quote! {
        #doc
        fn #fn_name(&self, #x: &[#scalar], #u_param #t: #time, out: &mut [#scalar]) {
            #fill
            #scratch
            #calls
        }
    };
    (method, helpers)
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

fn range(b: Bounds) -> TokenStream {
    let (lo, hi) = (float(b.lo), float(b.hi));
    quote!(Bounds::new(#lo, #hi))
}

/// The moving numbers of a set (method.md 8.15) as a `Vec<Moving>` literal.
fn moving(ms: &[Moving]) -> TokenStream {
    list(ms.iter().map(|m| {
        let (part, number) = (int(m.part), int(m.number));
        let slot = match m.slot {
            Slot::Offset => quote!(Slot::Offset),
            Slot::Lo(k) => {
                let k = int(k);
                quote!(Slot::Lo(#k))
            }
            Slot::Hi(k) => {
                let k = int(k);
                quote!(Slot::Hi(#k))
            }
            Slot::Center(k) => {
                let k = int(k);
                quote!(Slot::Center(#k))
            }
            Slot::Radius => quote!(Slot::Radius),
        };
        quote!(Moving { part: #part, slot: #slot, number: #number })
    }))
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

/// Lists of floats (and of names) longer than this (metrics are n x n) become `static` arrays
/// inside `info()` instead of temporaries (a million-entry array on the stack would overflow
/// it); mostly-zero float lists are stored as `(index, value)` pairs.
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
    /// A list of names; longer than [`STATIC_FLOATS`], a `static` array `IDENT` of `&str`
    /// turned into `String`s (one `String::from` per name in one expression, with its unwinding
    /// paths, cost rustc's optimiser about 40 s for the 2000 names of specs/chain1000.sde).
    fn names(&mut self, ident: &str, names: &[String]) -> TokenStream {
        if names.len() <= STATIC_FLOATS {
            return list(names.iter().map(|s| string(s)));
        }
        let ident = format_ident!("{ident}");
        let k = int(names.len());
        self.statics
            .extend(quote!(static #ident: [&str; #k] = [#(#names),*];));
        quote!(#ident.iter().map(|&s| String::from(s)).collect())
    }

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
            .map(|b: &Ball| {
                let states = indices(&b.states);
                let center = self.floats(&b.center);
                let radius = float(b.radius);
                let metric = option(&b.metric, |m| self.floats(m));
                quote!(Ball { states: #states, center: #center, radius: #radius, metric: #metric })
            })
            .collect();
        let balls = list(balls);
        quote!(InitialSet { boxes: #boxes, balls: #balls })
    }

    fn unsafe_set(&mut self, u: &UnsafeSet) -> TokenStream {
        let name = string(&u.name);
        let shape = self.shape(&u.shape);
        let moving = moving(&u.moving);
        quote!(UnsafeSet { name: #name, shape: #shape, moving: #moving })
    }

    fn goal(&mut self, g: &GoalSet) -> TokenStream {
        let name = string(&g.name);
        let parts: Vec<TokenStream> = g.parts.iter().map(|p| self.shape(p)).collect();
        let parts = list(parts);
        let moving = moving(&g.moving);
        let window = option(&g.window, |&w| range(w));
        let stay = g.stay;
        quote!(GoalSet { name: #name, parts: #parts, moving: #moving, window: #window, stay: #stay })
    }

    fn shape(&mut self, shape: &UnsafeShape) -> TokenStream {
        match shape {
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
        }
    }

    fn constants(&mut self, c: &Constants, info: &ModelInfo) -> TokenStream {
        let also: Vec<TokenStream> = c.also.iter().map(|k| self.constants(k, info)).collect();
        let also = list(also);
        let alternatives: Vec<TokenStream> = c
            .alternatives
            .iter()
            .map(|k| self.constants(k, info))
            .collect();
        let alternatives = list(alternatives);
        let metric = self.floats(&c.metric);
        let (cc, sigma, rho) = (float(c.c), float(c.sigma), float(c.rho));
        let provenance = provenance(&c.provenance);
        // The region is the model's domain and input box (bound once in `info()`).
        let r = &c.region;
        let domain = if r.domain == info.domain {
            quote!(domain.clone())
        } else {
            list(r.domain.iter().map(|&b| range(b)))
        };
        let input_box = if r.input_box == info.input_box {
            quote!(input_box.clone())
        } else {
            list(r.input_box.iter().map(|&b| range(b)))
        };
        let time = range(r.time);
        let metric_region = match c.metric_region {
            MetricRegion::Given => quote!(MetricRegion::Given),
            MetricRegion::Domain => quote!(MetricRegion::Domain),
            MetricRegion::InitialSet => quote!(MetricRegion::InitialSet),
            MetricRegion::IdentityAtRun => quote!(MetricRegion::IdentityAtRun),
        };
        quote! {
            Constants {
                metric: #metric,
                metric_region: #metric_region,
                c: #cc,
                sigma: #sigma,
                rho: #rho,
                provenance: #provenance,
                region: Region { domain: #domain, input_box: #input_box, time: #time },
                also: #also,
                alternatives: #alternatives,
            }
        }
    }

    fn analysis(&mut self, a: &Analysis, info: &ModelInfo) -> TokenStream {
        let a_spec = &a.spec;
        let name = string(&a_spec.name);
        let method = match a_spec.method {
            Method::Contraction => quote!(Method::Contraction),
            Method::Interval => quote!(Method::Interval),
        };
        let (delta, horizon, step) = (
            float(a_spec.delta),
            float(a_spec.horizon),
            float(a_spec.step),
        );
        let metric = match &a_spec.metric {
            MetricChoice::Identity => quote!(MetricChoice::Identity),
            MetricChoice::Auto => quote!(MetricChoice::Auto),
            MetricChoice::PerState(states) => {
                let states = states.iter().map(|&i| quote!(#i));
                quote!(MetricChoice::PerState(vec![#(#states),*]))
            }
            MetricChoice::Matrix(m) => {
                let m = self.floats(m);
                quote!(MetricChoice::Matrix(#m))
            }
        };
        let radius = match a_spec.radius {
            RadiusRule::Amgf => quote!(RadiusRule::Amgf),
            RadiusRule::Paper(eps) => {
                let eps = float(eps);
                quote!(RadiusRule::Paper(#eps))
            }
            RadiusRule::PaperOptimal => quote!(RadiusRule::PaperOptimal),
        };
        let rate = match a_spec.rate {
            Rate::Local => quote!(Rate::Local),
            Rate::Global => quote!(Rate::Global),
            Rate::Empirical { paths } => quote!(Rate::Empirical { paths: #paths }),
        };
        let integrator = match a_spec.integrator {
            Integrator::Validated => quote!(Integrator::Validated),
            Integrator::Rk4 => quote!(Integrator::Rk4),
            Integrator::Euler => quote!(Integrator::Euler),
        };
        let guarantee = match a_spec.guarantee {
            Guarantee::Uniform => quote!(Guarantee::Uniform),
            Guarantee::Pointwise => quote!(Guarantee::Pointwise),
        };
        let inclusion = match a_spec.inclusion {
            Inclusion::Natural => quote!(Inclusion::Natural),
            Inclusion::Jacobian => quote!(Inclusion::Jacobian),
            Inclusion::Mixed => quote!(Inclusion::Mixed),
        };
        let outputs = indices(&a_spec.outputs);
        let first_order = a_spec.first_order;
        let split = match &a_spec.split {
            Split::Off => quote!(Split::Off),
            Split::Counts(k) => {
                let k = indices(k);
                quote!(Split::Counts(#k))
            }
            Split::Auto { pieces, seconds } => {
                let pieces = int(*pieces);
                let seconds = option(seconds, |&s| {
                    let s = proc_macro2::Literal::u64_unsuffixed(s);
                    quote!(#s)
                });
                quote!(Split::Auto { pieces: #pieces, seconds: #seconds })
            }
        };
        let transform = option(&a_spec.transform, |t| {
            let (matrix, inverse, frame) = (
                self.floats(&t.matrix),
                self.floats(&t.inverse),
                int(t.frame),
            );
            let source = match t.source {
                TransformSource::Given => quote!(TransformSource::Given),
                TransformSource::Auto(AutoFit::LogNorm { chosen, identity }) => {
                    let (chosen, identity) = (float(chosen), float(identity));
                    quote!(TransformSource::Auto(AutoFit::LogNorm {
                        chosen: #chosen,
                        identity: #identity,
                    }))
                }
                TransformSource::Auto(AutoFit::NonFiniteJacobian) => {
                    quote!(TransformSource::Auto(AutoFit::NonFiniteJacobian))
                }
            };
            quote!(Transform {
                matrix: #matrix,
                inverse: #inverse,
                frame: #frame,
                source: #source,
            })
        });
        let constants = match &a.constants {
            Ok(c) => {
                let c = self.constants(c, info);
                quote!(Ok(#c))
            }
            Err(e) => {
                let e = string(e);
                quote!(Err(#e))
            }
        };
        quote! {
            Analysis {
                spec: AnalysisSpec {
                    name: #name,
                    method: #method,
                    delta: #delta,
                    horizon: #horizon,
                    step: #step,
                    metric: #metric,
                    radius: #radius,
                    rate: #rate,
                    inclusion: #inclusion,
                    integrator: #integrator,
                    guarantee: #guarantee,
                    transform: #transform,
                    outputs: #outputs,
                    first_order: #first_order,
                    split: #split,
                },
                constants: #constants,
            }
        }
    }
}

/// The literal of a [`Provenance`].
fn provenance(p: &Provenance) -> TokenStream {
    let matrix = |m: &MatrixBound| match *m {
        MatrixBound::Vertices {
            count,
            atoms,
            fixed,
        } => {
            let (count, atoms, fixed) = (int(count), int(atoms), int(fixed));
            quote!(MatrixBound::Vertices { count: #count, atoms: #atoms, fixed: #fixed })
        }
        MatrixBound::Hull {
            atoms,
            fixed,
            vertex_limit,
        } => {
            let (atoms, fixed, limit) = (int(atoms), int(fixed), int(vertex_limit));
            quote!(MatrixBound::Hull { atoms: #atoms, fixed: #fixed, vertex_limit: #limit })
        }
    };
    match p {
        Provenance::Given => quote!(Provenance::Given),
        Provenance::Unbounded { why } => {
            let why = string(why);
            quote!(Provenance::Unbounded { why: #why })
        }
        Provenance::Certified { c, sigma, rho } => {
            let c = option(c, matrix);
            let sigma = matrix(sigma);
            let rho = match rho {
                InputGain::NoInputs => quote!(InputGain::NoInputs),
                InputGain::Corners(m) => {
                    let m = matrix(m);
                    quote!(InputGain::Corners(#m))
                }
                InputGain::Columns(m) => {
                    let m = matrix(m);
                    quote!(InputGain::Columns(#m))
                }
            };
            quote!(Provenance::Certified { c: #c, sigma: #sigma, rho: #rho })
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
        let method = a.spec.method.name();
        let what = match &a.constants {
            Ok(c) => format!(
                "c = {}, sigma = {}, rho = {}\n    {}",
                match a.spec.rate {
                    Rate::Global => short(c.c),
                    Rate::Local => format!("local (global {})", short(c.c)),
                    Rate::Empirical { paths } => format!("empirical ({paths} paths)"),
                },
                short(c.sigma),
                short(c.rho),
                one_line(&c.provenance.to_string())
            ),
            Err(e) => format!("no constants\n    {}", one_line(e)),
        };
        list.push(format!("{} ({method}): {what}", one_line(&a.spec.name)));
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
    let (states, inputs, noises) = (
        w.names("STATES", &info.states),
        w.names("INPUTS", &info.inputs),
        w.names("NOISES", &info.noises),
    );
    let input_box = list(info.input_box.iter().map(|&r| range(r)));
    let initial = w.initial_set(&info.initial);
    let domain = list(info.domain.iter().map(|&r| range(r)));
    let has_domain = info.has_domain;
    let affine = info.affine;
    let constant_diffusion = info.constant_diffusion;
    let unsafe_sets: Vec<TokenStream> = info.unsafe_sets.iter().map(|u| w.unsafe_set(u)).collect();
    let unsafe_sets = list(unsafe_sets);
    let goals: Vec<TokenStream> = info.goals.iter().map(|g| w.goal(g)).collect();
    let goals = list(goals);
    let analyses: Vec<TokenStream> = info.analyses.iter().map(|a| w.analysis(a, info)).collect();
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
        pub fn info() -> reachc_runtime::model::ModelInfo {
            use reachc_runtime::model::*;
            #statics
            let domain: Vec<Bounds> = #domain;
            let input_box: Vec<Bounds> = #input_box;
            ModelInfo {
                name: #name,
                states: #states,
                inputs: #inputs,
                noises: #noises,
                input_box: input_box.clone(),
                initial: #initial,
                domain: domain.clone(),
                has_domain: #has_domain,
                affine: #affine,
                constant_diffusion: #constant_diffusion,
                unsafe_sets: #unsafe_sets,
                goals: #goals,
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

    /// A chain of `n` units as in specs/chain1000.sde, every unit also pulled by one shared
    /// value `c`, so some values are read by every chunk; prepared.
    fn big_chain(n: usize) -> (Model, Prepared) {
        let source = format!(
            "model big\n\
             const N = {n}\n\
             state x[1..N] in [-0.1, 0.1]\n\
             noise w[1..N]\n\
             let c = sin(x[1])\n\
             for i in 1..N-1 {{ let d[i] = tanh(x[i + 1] - x[i]) }}\n\
             drift {{\n\
                 x[1]' = -2 * x[1] + d[1] + c\n\
                 for i in 2..N-1 {{ x[i]' = -2 * x[i] + d[i] - d[i - 1] + c }}\n\
                 x[N]' = -2 * x[N] - d[N - 1] + c\n\
             }}\n\
             diffusion {{ for i in 1..N {{ x[i]: 0.05 * w[i] }} }}\n"
        );
        let (model, diagnostics) = crate::driver::check_source(&source, std::path::Path::new("."));
        let mut model = model.unwrap_or_else(|| panic!("{diagnostics:?}"));
        let prepared = crate::backend::prepare(&mut model);
        (model, prepared)
    }

    /// The functions of a generated file (methods, and helpers in modules): name and statement
    /// count.
    fn functions(code: &str) -> Vec<(String, usize)> {
        fn walk(items: &[syn::Item], out: &mut Vec<(String, usize)>) {
            for item in items {
                match item {
                    syn::Item::Impl(i) => {
                        for f in &i.items {
                            if let syn::ImplItem::Fn(f) = f {
                                out.push((f.sig.ident.to_string(), f.block.stmts.len()));
                            }
                        }
                    }
                    syn::Item::Fn(f) => out.push((f.sig.ident.to_string(), f.block.stmts.len())),
                    syn::Item::Mod(m) => walk(&m.content.as_ref().unwrap().1, out),
                    _ => {}
                }
            }
        }
        let mut out = Vec::new();
        walk(&syn::parse_file(code).unwrap().items, &mut out);
        out
    }

    #[test]
    fn large_methods_are_split_into_bounded_functions() {
        let (model, prepared) = big_chain(600);
        let small = Options {
            split_above: 40,
            chunk_size: 40,
        };
        for options in [Options::default(), small] {
            let chunk_size = options.chunk_size;
            let code = generate_with(&model, &prepared, &options);
            let fns = functions(&code);
            let methods = [
                "drift",
                "drift_interval",
                "jac_x",
                "jac_x_sparse_interval",
                "diffusion",
                "diffusion_interval",
            ];
            for name in methods {
                let parts = fns
                    .iter()
                    .filter(|(f, _)| f.starts_with(&format!("{name}_part")))
                    .count();
                assert!(parts >= 2, "{name} in {parts} parts at {chunk_size}");
                // The method only calls its parts (after out.fill and the scratch array).
                let calls = code.matches(&format!("::{name}_part")).count();
                assert_eq!(calls, parts, "{name}");
                let stmts = fns.iter().find(|(f, _)| *f == name).unwrap().1;
                assert!(stmts <= parts + 2, "{name}: {stmts} statements");
            }
            // The dense interval Jacobian is scattered from the sparse one.
            assert!(code.contains("self.jac_x_sparse_interval(x, u, t, &mut nonzeros);"));
            assert!(!fns
                .iter()
                .any(|(f, _)| f.starts_with("jac_x_interval_part")));
            // Each part: at most `chunk_size` steps (lets and outputs, each costing at least 1),
            // as many loads and stores, and a few slice prefixes.
            for (name, stmts) in fns.iter().filter(|(f, _)| f.contains("_part")) {
                assert!(*stmts <= 3 * chunk_size + 5, "{name}: {stmts} statements");
            }
            assert!(code.contains("#[inline(never)]"));
            // Grouped in modules (codegen units).
            let groups = code.matches("mod big_drift_interval_").count();
            let parts = fns
                .iter()
                .filter(|(f, _)| f.starts_with("drift_interval_part"));
            assert_eq!(groups, parts.count().div_ceil(PARTS_PER_MODULE));
            // Depth-first order keeps few values live across chunks (`c`, a neighbour's
            // coupling), and slots are reused: the scratch arrays stay tiny.
            for len in code.split("let mut s = [").skip(1) {
                let len: usize = len
                    .split(';')
                    .nth(1)
                    .and_then(|l| l.split(']').next())
                    .and_then(|l| l.trim().parse().ok())
                    .unwrap();
                assert!(len <= 4, "scratch of {len} at {chunk_size}");
            }
        }
        // A small model stays one function per method (at the default options).
        let (model, prepared) = big_chain(30);
        let code = generate(&model, &prepared);
        assert!(!code.contains("_part0"), "{code}");
        assert!(functions(&code)
            .iter()
            .all(|(name, _)| !name.contains("_part")));
    }

    #[test]
    fn docs_stay_small_for_large_models() {
        let (model, prepared) = big_chain(600);
        let code = generate(&model, &prepared);
        // The drift's two forms and the diffusion's two quote 20 equations of 600 each.
        assert_eq!(code.matches("/// ... and 580 more").count(), 4);
        // Per method: a few lines of prose and at most 21 of equations, each bounded.
        let start = code.find("impl reachc_runtime::System for Big {").unwrap();
        let methods = &code[start..start + code[start..].find("\n}\n").unwrap()];
        let doc_lines = methods.lines().filter(|l| l.starts_with("    ///")).count();
        let count = methods.matches("\n    fn ").count();
        assert!(
            doc_lines <= count * 30,
            "{doc_lines} lines for {count} methods"
        );
        assert!(methods.lines().all(|l| l.len() < 200), "{methods}");
        // One constant per state and per noise channel, and no module for the missing inputs.
        assert!(code.contains("pub mod state {") && code.contains("pub mod noise {"));
        assert!(!code.contains("pub mod input"));
        assert!(code.contains("    /// State `x[600]`.\n    pub const X_600: usize = 599;\n"));
        assert!(code.contains("    /// Noise channel `w[1]`.\n    pub const W_1: usize = 0;\n"));
    }

    #[test]
    fn generated_files_start_with_the_marker() {
        let (model, prepared) = big_chain(3);
        for text in [generate(&model, &prepared), main_rs("big", "Big")] {
            let first = text.lines().next().unwrap();
            assert!(first.starts_with("// Generated by reachc "), "{first}");
            assert!(first.contains("@generated"), "{first}");
        }
    }

    #[test]
    fn chunk_steps_are_topological_and_complete() {
        let (model, prepared) = big_chain(50);
        let pool = &model.pool;
        let roots: Vec<ExprId> = prepared
            .derivatives
            .jac_x
            .iter()
            .flatten()
            .copied()
            .collect();
        let steps = steps(pool, &roots, true);
        let mut done = vec![false; pool.len()];
        let mut outputs = Vec::new();
        for step in &steps {
            match *step {
                Step::Let(id) => {
                    assert!(!done[id.index()], "{id:?} computed twice");
                    for c in children(pool.node(id)) {
                        assert!(is_leaf(pool, c) || done[c.index()], "{c:?} before {id:?}");
                    }
                    done[id.index()] = true;
                }
                Step::Out(k) => {
                    let r = roots[k];
                    assert!(is_leaf(pool, r) || done[r.index()]);
                    outputs.push(k);
                }
            }
        }
        // Every output but the zeros (written by `out.fill`), in order.
        let nonzero: Vec<usize> = (0..roots.len())
            .filter(|&k| pool.as_const(roots[k]) != Some(0.0))
            .collect();
        assert_eq!(outputs, nonzero);
        let live: Vec<ExprId> = roots
            .iter()
            .copied()
            .filter(|&r| !is_leaf(pool, r))
            .collect();
        let needed = pool.reachable(&live);
        assert!(needed
            .iter()
            .all(|&id| is_leaf(pool, id) || done[id.index()]));
    }

    #[test]
    fn main_rs_parses() {
        let text = main_rs("van_der_pol", "VanDerPol");
        assert!(text.contains("reachc_runtime::app::main_with(&van_der_pol::VanDerPol"));
        syn::parse_file(&text).unwrap();
    }
}
