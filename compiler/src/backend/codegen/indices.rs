//! The index constants of a generated model, by spec name: `pub mod state { pub const THETA:
//! usize = 0; ... }`, and `input` and `noise` likewise, so that code using the model can write
//! `x[state::THETA]`; and the names of its analyses, `pub mod analysis { pub const
//! CONTRACTION: &str = "contraction"; ... }`, for `Reach::new(&Model, analysis::CONTRACTION)`.
//! One module per kind, so that names of different kinds cannot clash; the names are
//! [`mangle::const_names`], distinct within a kind.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::bake::int;
use super::docs::doc_attrs;
use crate::backend::mangle;
use crate::ir::Names;

/// One kind of variable: its module, the constant for a name that has no letters or digits,
/// how one is called in a doc, and the module's doc.
struct IndexKind {
    module: &'static str,
    fallback: &'static str,
    label: &'static str,
    doc: &'static str,
}

const STATE: IndexKind = IndexKind {
    module: "state",
    fallback: "STATE",
    label: "State",
    doc: "The index of each state in `x` by spec name: its equation in `f`, its row of the \
          Jacobians and of `G`, its column of `D_x f`.",
};

const INPUT: IndexKind = IndexKind {
    module: "input",
    fallback: "INPUT",
    label: "Input",
    doc: "The index of each input in `u` by spec name: its column of `D_u f`.",
};

const NOISE: IndexKind = IndexKind {
    module: "noise",
    fallback: "NOISE",
    label: "Noise channel",
    doc: "The index of each noise channel by spec name: its column of `G`.",
};

const ANALYSIS: IndexKind = IndexKind {
    module: "analysis",
    fallback: "ANALYSIS",
    label: "Analysis",
    doc: "The name of each analysis, for `Reach::new` and `engine::run`.",
};

/// The modules `state`, `input` and `noise` of the model with these names, and `analysis` of
/// its analyses' names (a kind without names has none).
pub(super) fn index_modules(names: &Names<'_>, analyses: &[String]) -> TokenStream {
    [
        (&STATE, names.states),
        (&INPUT, names.inputs),
        (&NOISE, names.noises),
    ]
    .into_iter()
    .filter(|(_, names)| !names.is_empty())
    .map(|(kind, names)| index_module(kind, names, |i, _| quote!(usize = #i)))
    .chain(
        (!analyses.is_empty())
            .then(|| index_module(&ANALYSIS, analyses, |_, name| quote!(&str = #name))),
    )
    .collect()
}

/// `pub mod MODULE { pub const NAME: TYPE = VALUE; ... }`, each constant documented with the
/// spec name; `value(i, name)` is `TYPE = VALUE` of the `i`-th name.
fn index_module(
    kind: &IndexKind,
    names: &[String],
    value: impl Fn(proc_macro2::Literal, &str) -> TokenStream,
) -> TokenStream {
    let consts = mangle::const_names(names, kind.fallback)
        .into_iter()
        .zip(names)
        .enumerate()
        .map(|(i, (ident, name))| {
            let ident = format_ident!("{ident}");
            let doc = doc_attrs(&format!("{} `{}`.", kind.label, name.replace('`', "'")));
            let value = value(int(i), name);
            quote! {
                #doc
                pub const #ident: #value;
            }
        });
    let (module, doc) = (format_ident!("{}", kind.module), doc_attrs(kind.doc));
    quote! {
        #doc
        pub mod #module {
            #(#consts)*
        }
    }
}
