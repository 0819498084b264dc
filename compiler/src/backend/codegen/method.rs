//! One generated `System` method: what it computes ([`MethodDef`]) and its code
//! ([`method_fn`]), a single function of one `let` per IR node reachable from its outputs, in
//! increasing id order (a topological order), so shared sub-expressions are computed once and
//! constant outputs cost nothing. A method too large for one function is handed to
//! [`super::chunk`].

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::chunk::chunked_method;
use super::docs::MethodDoc;
use super::emit::{is_leaf, node_cost, output, value_ident, Emitter, Kind};
use super::tables::Tables;
use super::Options;
use crate::ir::{ExprId, Node, Pool};

/// When an output has at least this many zero entries, it is cleared with one `fill` instead
/// of one assignment per zero.
const FILL_THRESHOLD: usize = 8;

/// What one generated `System` method computes.
pub(super) struct MethodDef<'a> {
    /// `drift`, `jac_x`, ... (`_interval` is appended for [`Kind::Interval`]).
    pub(super) name: &'a str,
    /// The arithmetic it runs in.
    pub(super) kind: Kind,
    /// The outputs, row-major.
    pub(super) roots: &'a [ExprId],
    /// Whether the method takes the inputs `u` (all but the diffusion do).
    pub(super) with_u: bool,
    /// The type implementing the method (for its helpers' module names).
    pub(super) owner: &'a Ident,
    /// What the method computes, with the equations.
    pub(super) doc: &'a MethodDoc,
}

impl MethodDef<'_> {
    /// The method's name: `name`, `name_interval` or `name_x8`.
    pub(super) fn fn_name(&self) -> Ident {
        match self.kind {
            Kind::F64 => format_ident!("{}", self.name),
            Kind::Interval => format_ident!("{}_interval", self.name),
            Kind::X8 => format_ident!("{}_x8", self.name),
        }
    }

    /// The type of the elements of `x`, `u` and `out`.
    pub(super) fn scalar(&self) -> TokenStream {
        match self.kind {
            Kind::F64 => quote!(f64),
            Kind::Interval => quote!(reachc_runtime::Interval),
            Kind::X8 => quote!(reachc_runtime::X8),
        }
    }

    /// The type of `t`: one time for all lanes.
    pub(super) fn time(&self) -> TokenStream {
        match self.kind {
            Kind::X8 => quote!(f64),
            Kind::F64 | Kind::Interval => self.scalar(),
        }
    }

    /// The parameters `x`, `u` (if the method takes them) and `t`, each named `_x` ... when
    /// the body does not read it.
    pub(super) fn params(&self, (uses_x, uses_u, uses_t): (bool, bool, bool)) -> TokenStream {
        let (scalar, time) = (self.scalar(), self.time());
        let x = param_name(uses_x, "x");
        let t = param_name(uses_t, "t");
        let u_param = if self.with_u {
            let u = param_name(uses_u, "u");
            quote!(#u: &[#scalar],)
        } else {
            TokenStream::new()
        };
        quote!(#x: &[#scalar], #u_param #t: #time)
    }

    /// `0.0`, `Interval::ZERO` or `X8::splat(0.0)` as the method body can name it.
    pub(super) fn zero(&self) -> TokenStream {
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

/// One `System` method (`drift`, `jac_x`, ... with `_interval` for [`Kind::Interval`]) writing
/// its roots (row-major) to `out`, and the helper functions it calls: none unless its body
/// would cost more than [`Options::split_above`] (see [`chunked_method`]).
pub(super) fn method_fn(
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
            Kind::Interval => e.interval_zero(),
        };
        body.extend(quote!(out.fill(#zero);));
    }
    for (k, &r) in roots.iter().enumerate() {
        body.extend(output(&mut e, k, r, fill));
    }

    let params = def.params((e.x_len > 0, e.u_len > 0, e.uses_t));
    let out = param_name(!roots.is_empty(), "out");
    let (fn_name, scalar) = (def.fn_name(), def.scalar());
    let use_interval = e.use_interval();
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
        fn #fn_name(&self, #params, #out: &mut [#scalar]) {
            #use_interval
            #body
        }
    };
    (method, TokenStream::new())
}
