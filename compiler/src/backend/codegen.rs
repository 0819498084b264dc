//! Rust code generation: a model's `System` implementation as straight-line code.
//!
//! [`generate`] returns the text of a generated crate's `src/lib.rs`: a unit struct named after
//! the model ([`super::mangle::type_name`]) implementing `reachc_runtime::System`, its sizes as
//! associated constants, the tables it reads as `static` arrays, and `info()` returning the
//! model's [`ModelInfo`](reachc_core::model::ModelInfo) (sets, analyses and derived constants)
//! as a literal.
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
//!
//! This module puts the file together ([`generate_with`], and `system_bodies` for the methods of
//! a system); each part has a module of its own: `emit` writes one IR node in a method's
//! arithmetic, `method` one `System` method as a single function, `chunk` a method too large for
//! one as bounded helper functions, `tables` the `static` tables the methods read, `docs` every
//! doc comment, `indices` the index constants, and `bake` the `info()` literal (the `Bake` trait,
//! one exhaustive impl per core type written).

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::{mangle, Prepared};
use crate::analysis::Derivatives;
use crate::ir::{ExprId, Names, Pool};
use crate::model::{Model, Time, Variable};

mod bake;
mod chunk;
mod docs;
mod emit;
mod indices;
mod method;
mod tables;

use bake::int;
use chunk::scratch_array;
use docs::{MethodDoc, SystemDocs};
use emit::Kind;
use method::{method_fn, MethodDef};
use tables::Tables;

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
        (&model.drift, &model.diffusion, model.time),
        (&prepared.derivatives, &names),
        (options, lanes),
    );
    // The moving sets' numbers (method.md 8.15): an inherent method of the model's shape,
    // which the trait's `set_numbers` calls.
    let numbers_doc = MethodDoc::set_numbers(&model.pool, &names, &model.set_numbers);
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
            (&frame.drift, &frame.diffusion, model.time),
            (&frame.derivatives, &frame_names),
            (options, lanes),
        );
        let doc = docs::frame_doc(&name, k, &frame.transform.matrix, model.states.len());
        let lints = allow_lints();
        let k = int(k);
        frame_arms.extend(quote! { #k => Some(&#frame_name), });
        frame_items.extend(quote! {
            #doc
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

    let struct_doc = docs::struct_doc(model);
    let lints = allow_lints();
    let analyses: Vec<String> = (prepared.info.analyses().iter())
        .map(|a| a.spec.name.clone())
        .collect();
    let index_modules = indices::index_modules(&names, &analyses);
    let statics = tables.statics(model);
    let info_fn = bake::info_fn(&prepared.info);
    let info_doc = docs::info_doc(&prepared.info);
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

        #info_doc
        impl reachc_runtime::Model for #name {
            fn info(&self) -> &reachc_runtime::model::ModelInfo {
                static INFO: std::sync::OnceLock<reachc_runtime::model::ModelInfo> =
                    std::sync::OnceLock::new();
                INFO.get_or_init(info)
            }
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

/// The `System` methods (f64 and interval) of a drift (a discrete-time model's map), diffusion
/// and their Jacobians, and the modules of helper functions of those split into chunks (see
/// [`chunk::chunked_method`]); with `lanes`, also `drift_x8` and `diffusion_x8` (unless they
/// would be chunked).
fn system_bodies(
    pool: &Pool,
    tables: &mut Tables,
    owner: &Ident,
    (drift, diffusion, time): (&[ExprId], &[Vec<ExprId>], Time),
    (d, names): (&Derivatives, &Names<'_>),
    (options, lanes): (&Options, bool),
) -> (TokenStream, TokenStream) {
    let nonzeros = d.jac_x_dependencies(pool, drift);
    let docs = SystemDocs::new(pool, names, (drift, diffusion, time), d, &nonzeros);
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
                reachc_runtime::app::main_with(&#krate::#ty)
            }
        })
}

/// Formats generated tokens with prettyplease. The tokens are produced here, so a parse failure
/// is a bug of this module.
fn format_file(tokens: TokenStream) -> String {
    let file: syn::File = syn::parse2(tokens).expect("generated code parses");
    prettyplease::unparse(&file)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain of `n` units as in specs/chain1000.sde, every unit also pulled by one shared
    /// value `c`, so some values are read by every chunk; prepared.
    pub(super) fn big_chain(n: usize) -> (Model, Prepared) {
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
    fn main_rs_parses() {
        let text = main_rs("van_der_pol", "VanDerPol");
        assert!(text.contains("reachc_runtime::app::main_with(&van_der_pol::VanDerPol"));
        syn::parse_file(&text).unwrap();
    }
}
