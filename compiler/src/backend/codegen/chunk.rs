//! Splitting a method too large for one function (a model with hundreds of states) into
//! `#[inline(never)]` helper functions of bounded size in private modules, called in sequence,
//! values crossing from one to a later one passing through a scratch array ([`chunked_method`]).
//! rustc compiles that in a minute where it never finished one giant function; every node is
//! still emitted by [`Emitter::node_expr`], so the results are the same, bit for bit.

use std::collections::{BTreeMap, BTreeSet};

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::allow_lints;
use super::bake::int;
use super::emit::{children, is_leaf, node_cost, output, value_ident, Emitter};
use super::method::MethodDef;
use super::tables::Tables;
use crate::ir::{ExprId, Pool};

/// One step of a chunked method: a node's `let` or the assignment of output `k`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Step {
    /// The `let` of a node.
    Let(ExprId),
    /// The assignment of output `k`.
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
pub(super) fn scratch_array(name: &str, zero: &TokenStream, len: usize) -> TokenStream {
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
pub(super) fn chunked_method(
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
    let params = def.params((uses_x, uses_u, uses_t));
    let doc = def.doc.attrs(def.kind);
    let method = quote! {
        #doc
        fn #fn_name(&self, #params, out: &mut [#scalar]) {
            #fill
            #scratch
            #calls
        }
    };
    (method, helpers)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::codegen::tests::big_chain;
    use crate::backend::codegen::{generate, generate_with, Options};

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
}
