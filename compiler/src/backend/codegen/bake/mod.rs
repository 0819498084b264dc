//! Core values written as Rust expressions for the generated crate: `info()`, which returns
//! the model's [`ModelInfo`] (names, sets, analyses and their certified constants), and the
//! literals ([`float`], [`int`]) every part of the generated code writes numbers with.
//!
//! Each core type written into generated code implements [`Bake`] by destructuring its value
//! exhaustively (every field named, no `..`; every variant matched, no wildcard arm), so that
//! a field or variant added to a core type fails to compile here instead of being silently
//! left out of generated crates. Plain structs and enums of data-less variants get their impls
//! from the `bake_struct!` and `bake_unit_enum!` macros, which destructure and match the same
//! way. The impls are in [`sets`] (initial, unsafe and goal sets and their moving numbers) and
//! [`analyses`] (analyses, constants and their provenance); [`ModelInfo`]'s, here, writes the
//! body of `info()`.

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use reachc_core::model::{Bounds, ModelInfo, ModelParts};

use super::allow_lints;

/// `PATH { a: .., b: .. }` from the bindings `a`, `b`, ... (the fields of a value just
/// destructured), each baked with `baker` in the order listed: the order in which the
/// `DATA_k` statics of their long lists are numbered. A field destructured but left out of
/// the list is an unused variable, which the workspace's lints reject.
macro_rules! bake_fields {
    ($baker:ident, $($path:ident)::+ { $($field:ident),+ $(,)? }) => {{
        $(let $field = $field.bake($baker);)+
        quote!($($path)::+ { $($field: #$field),+ })
    }};
}

/// [`Bake`] for structs written as `Type { a: .., b: .. }`, every field baked in the order
/// listed (see `bake_fields`). The value is destructured with a pattern naming exactly the
/// fields listed, without `..`: a field missing from the list does not compile.
macro_rules! bake_struct {
    ($($ty:ident { $($field:ident),+ $(,)? })+) => {$(
        #[doc = concat!("`", stringify!($ty), " { .. }`, every field written out.")]
        impl Bake for $ty {
            fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
                let $ty { $($field),+ } = self;
                bake_fields!(baker, $ty { $($field),+ })
            }
        }
    )+};
}

/// [`Bake`] for enums whose variants hold no data, each written as `Type::Variant`: an
/// exhaustive `match` over the variants listed, without a wildcard arm, so a variant missing
/// from the list does not compile.
macro_rules! bake_unit_enum {
    ($($ty:ident { $($variant:ident),+ $(,)? })+) => {$(
        #[doc = concat!("`", stringify!($ty), "::Variant`.")]
        impl Bake for $ty {
            fn bake(&self, _: &mut Baker<'_>) -> TokenStream {
                match self {
                    $($ty::$variant => quote!($ty::$variant),)+
                }
            }
        }
    )+};
}

mod analyses;
mod sets;

/// A core value that can be written as a Rust expression rebuilding it, inside `info()`
/// (where `reachc_runtime::model::*` is in scope and the model's domain and input box are
/// bound, see [`Baker`]).
///
/// Implementations destructure the value exhaustively, so that a new field or variant of a core
/// type is a compile error here.
pub(super) trait Bake {
    /// The expression, its long lists moved to `baker`'s statics.
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream;

    /// A list of such values as a `Vec` expression: `Vec::from([..])` unless the type
    /// overrides it (a long list of floats becomes a `static`).
    fn bake_list(items: &[Self], baker: &mut Baker<'_>) -> TokenStream
    where
        Self: Sized,
    {
        list(items.iter().map(|item| item.bake(baker)))
    }
}

/// Lists of floats (and of names) longer than this (metrics are n x n) become `static` arrays
/// inside `info()` instead of temporaries (a million-entry array on the stack would overflow
/// it); mostly-zero float lists are stored as `(index, value)` pairs.
const STATIC_FLOATS: usize = 64;

/// Writes the values of one model's `info()`: collects the `static` arrays long lists become,
/// and knows the model's domain and input box, which `info()` binds once as `domain` and
/// `input_box` (the regions of the constants share them).
pub(super) struct Baker<'a> {
    /// The model's domain, bound as `domain`.
    domain: &'a [Bounds],
    /// The model's input box, bound as `input_box`.
    input_box: &'a [Bounds],
    /// The `static` items written so far.
    statics: TokenStream,
    /// How many `DATA_k` statics were written.
    count: usize,
    /// Whether the `sparse` helper is needed.
    uses_sparse: bool,
}

impl<'a> Baker<'a> {
    /// A baker for the `info()` of the model `info`.
    fn new(info: &'a ModelInfo) -> Self {
        Baker {
            domain: info.domain(),
            input_box: info.input_box(),
            statics: TokenStream::new(),
            count: 0,
            uses_sparse: false,
        }
    }

    /// A list of names; longer than [`STATIC_FLOATS`], a `static` array `IDENT` of `&str`
    /// turned into `String`s (one `String::from` per name in one expression, with its unwinding
    /// paths, cost rustc's optimiser about 40 s for the 2000 names of specs/chain1000.sde).
    fn names(&mut self, ident: &str, names: &[String]) -> TokenStream {
        if names.len() <= STATIC_FLOATS {
            return String::bake_list(names, self);
        }
        let ident = format_ident!("{ident}");
        let k = int(names.len());
        self.statics
            .extend(quote!(static #ident: [&str; #k] = [#(#names),*];));
        quote!(#ident.iter().map(|&s| String::from(s)).collect())
    }

    /// A list of floats; longer than [`STATIC_FLOATS`], a `static` array `DATA_k` (of
    /// `(index, value)` pairs when mostly zeros) turned into a `Vec`.
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

    /// The statics written so far, and the `sparse` helper if they need it; taken out.
    fn take_statics(&mut self) -> TokenStream {
        let mut statics = std::mem::take(&mut self.statics);
        if std::mem::take(&mut self.uses_sparse) {
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
        statics
    }
}

/// `fn info() -> ModelInfo`, the given `info` built through its hidden constructor: the
/// model type's `Model::info` calls it once.
pub(super) fn info_fn(info: &ModelInfo) -> TokenStream {
    let lints = allow_lints();
    let body = info.bake(&mut Baker::new(info));
    quote! {
        /// The model data, built once by `Model::info`.
        #lints
        fn info() -> reachc_runtime::model::ModelInfo #body
    }
}

/// A block: the `use` of the model types, the statics, the bindings `domain` and `input_box`,
/// then the `ModelInfo` through its hidden constructor. Baked with the [`Baker`] made for this model.
impl Bake for ModelInfo {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        let ModelParts {
            name,
            states,
            inputs,
            noises,
            input_box,
            initial,
            domain,
            has_domain,
            affine,
            constant_diffusion,
            time,
            unsafe_sets,
            goals,
            analyses,
        } = self.clone().into_parts();
        let name = name.bake(baker);
        let (states, inputs, noises) = (
            baker.names("STATES", &states),
            baker.names("INPUTS", &inputs),
            baker.names("NOISES", &noises),
        );
        let input_box = input_box.bake(baker);
        let initial = initial.bake(baker);
        let domain = domain.bake(baker);
        let has_domain = has_domain.bake(baker);
        let affine = affine.bake(baker);
        let constant_diffusion = constant_diffusion.bake(baker);
        let time = time.bake(baker);
        let unsafe_sets = unsafe_sets.bake(baker);
        let goals = goals.bake(baker);
        let analyses = analyses.bake(baker);
        let statics = baker.take_statics();
        quote!({
            use reachc_runtime::model::*;
            #statics
            let domain: Vec<Bounds> = #domain;
            let input_box: Vec<Bounds> = #input_box;
            ModelInfo::from_parts(ModelParts {
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
                time: #time,
                unsafe_sets: #unsafe_sets,
                goals: #goals,
                analyses: #analyses,
            })
        })
    }
}

/// An unsuffixed integer literal (`quote` would print `2usize`).
pub(super) fn int(i: usize) -> Literal {
    Literal::usize_unsuffixed(i)
}

/// An `f64` literal that reads back as exactly `v` (shortest round-trip form); negative values
/// as unary minus, non-finite ones as the `f64` constants.
pub(super) fn float(v: f64) -> TokenStream {
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

/// `PATH(value)`: a variant (or any constructor) holding one value.
fn variant(path: TokenStream, value: &impl Bake, baker: &mut Baker<'_>) -> TokenStream {
    let value = value.bake(baker);
    quote!(#path(#value))
}

/// `Vec::from([items])` (a plain expression: prettyplease formats it, unlike `vec![..]`).
fn list(items: impl IntoIterator<Item = TokenStream>) -> TokenStream {
    let mut items = items.into_iter().peekable();
    if items.peek().is_none() {
        return quote!(Vec::new());
    }
    quote!(Vec::from([#(#items),*]))
}

/// A shortest round-trip literal ([`float`]); a list of them may become a `static`.
impl Bake for f64 {
    fn bake(&self, _: &mut Baker<'_>) -> TokenStream {
        float(*self)
    }

    fn bake_list(items: &[Self], baker: &mut Baker<'_>) -> TokenStream {
        baker.floats(items)
    }
}

/// An unsuffixed literal ([`int`]).
impl Bake for usize {
    fn bake(&self, _: &mut Baker<'_>) -> TokenStream {
        let lit = int(*self);
        quote!(#lit)
    }
}

/// An unsuffixed literal.
impl Bake for u64 {
    fn bake(&self, _: &mut Baker<'_>) -> TokenStream {
        let lit = Literal::u64_unsuffixed(*self);
        quote!(#lit)
    }
}

/// `true` or `false`.
impl Bake for bool {
    fn bake(&self, _: &mut Baker<'_>) -> TokenStream {
        quote!(#self)
    }
}

/// `String::from("...")`.
impl Bake for String {
    fn bake(&self, _: &mut Baker<'_>) -> TokenStream {
        quote!(String::from(#self))
    }
}

/// `Bounds::new(lo, hi)`.
impl Bake for Bounds {
    fn bake(&self, _: &mut Baker<'_>) -> TokenStream {
        let Bounds { lo, hi } = *self;
        let (lo, hi) = (float(lo), float(hi));
        quote!(Bounds::new(#lo, #hi))
    }
}

/// `Vec::from([..])`, or what the element type writes lists as ([`Bake::bake_list`]).
impl<T: Bake> Bake for Vec<T> {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        T::bake_list(self, baker)
    }
}

/// `Some(..)` or `None`.
impl<T: Bake> Bake for Option<T> {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            Some(x) => variant(quote!(Some), x, baker),
            None => quote!(None),
        }
    }
}

/// `Ok(..)` or `Err(..)`.
impl<T: Bake, E: Bake> Bake for Result<T, E> {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            Ok(x) => variant(quote!(Ok), x, baker),
            Err(e) => variant(quote!(Err), e, baker),
        }
    }
}

/// `(a, b)`.
impl<A: Bake, B: Bake> Bake for (A, B) {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        let (a, b) = self;
        let (a, b) = (a.bake(baker), b.bake(baker));
        quote!((#a, #b))
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
}
