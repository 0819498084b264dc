//! The doc comments of generated code: the model struct's (the spec's own doc), each `System`
//! method's (what it computes, and the spec equations it implements, printed in the `.sde`
//! grammar by [`Pool::to_sde_prefix`]), a transformed frame's and `info()`'s (the constants of
//! each analysis and how they were obtained), and [`doc_attrs`], which makes any text safe as
//! `///` lines.
//!
//! Bounded, so that a 1000-state model gets a few lines per method rather than megabytes: at
//! most [`MAX_EQUATIONS`] equations per method (then how many more), each cut at [`MAX_LINE`]
//! characters (printing expands the expression DAG into a tree, which can be exponentially
//! larger, so only a prefix is ever printed).

use proc_macro2::{Ident, TokenStream};
use quote::quote;
use reachc_core::model::{ModelInfo, Rate, Time};

use super::emit::Kind;
use crate::analysis::Derivatives;
use crate::ir::{ExprId, Names, Pool};
use crate::model::Model;

/// The largest number of equations quoted in one method's doc.
const MAX_EQUATIONS: usize = 20;

/// The longest equation line, in characters; longer ones are cut and end in ` ...`.
const MAX_LINE: usize = 120;

/// The doc of one method, shared by its forms (`f64`, interval, lanes): a sentence saying what
/// it computes, and the equations.
pub(super) struct MethodDoc {
    what: &'static str,
    /// A fenced `text` block, so rustdoc shows `f[x]` and `*` as written.
    equations: String,
}

impl MethodDoc {
    /// The `#[doc]` attributes of the method's `kind` form ([`Kind::F64`] for a method without
    /// arithmetic).
    pub(super) fn attrs(&self, kind: Kind) -> TokenStream {
        let form = match kind {
            Kind::F64 => "",
            Kind::Interval => {
                "Interval form: encloses it for all arguments in the given intervals \
                 (outward-rounded arithmetic).\n\n"
            }
            Kind::X8 => {
                "Lanes form: eight states and inputs at once, each lane bit for bit what the \
                 `f64` form gives.\n\n"
            }
        };
        doc_attrs(&format!("{}.\n\n{form}{}", self.what, self.equations))
    }
}

/// The docs of one system's methods (the model's, or a transformed frame's).
pub(super) struct SystemDocs {
    /// `drift`, `drift_interval`, `drift_x8`.
    pub(super) drift: MethodDoc,
    /// `jac_x`, `jac_x_interval`.
    pub(super) jac_x: MethodDoc,
    /// `jac_x_sparse_interval`.
    pub(super) jac_x_sparse: MethodDoc,
    /// `jac_x_pattern`.
    pub(super) jac_x_pattern: MethodDoc,
    /// `jac_u`, `jac_u_interval`.
    pub(super) jac_u: MethodDoc,
    /// `diffusion`, `diffusion_interval`, `diffusion_x8`.
    pub(super) diffusion: MethodDoc,
}

impl SystemDocs {
    /// The docs of the system with this drift, diffusion, derivatives and the non-zero pattern
    /// of its `D_x f` (row, column, entry), its variables printed by `names`.
    pub(super) fn new(
        pool: &Pool,
        names: &Names<'_>,
        (drift, diffusion, time): (&[ExprId], &[Vec<ExprId>], Time),
        d: &Derivatives,
        pattern: &[(usize, usize, ExprId)],
    ) -> SystemDocs {
        let p = Printer { pool, names };
        let states = names.states;
        let d_f = |i: usize, var: &str| format!("d f[{}] / d {var}", states[i]);
        let jac_x = p.entries(pattern, |i, j| d_f(i, &states[j]));
        let jac_u = p.nonzero(&d.jac_u);
        let diffusion = p.nonzero(diffusion);
        let doc = |what, equations| MethodDoc { what, equations };
        SystemDocs {
            drift: match time {
                Time::Continuous => doc(
                    "The drift `f(x, u, t)`: `out[i]` is the right-hand side of the equation of \
                     state `i`",
                    block(drift.len(), |i| {
                        p.equation(format!("{}'", states[i]), drift[i])
                    }),
                ),
                Time::Discrete { .. } => doc(
                    "The map `f(x, u, t)` of a discrete-time model: `out[i]` is the next value \
                     of state `i` (its update equation)",
                    block(drift.len(), |i| p.equation(states[i].to_string(), drift[i])),
                ),
            },
            jac_x: doc(
                "The Jacobian `D_x f`, row-major: `out[i * n + j] = d f[i] / d x[j]`, 0 where \
                 `f[i]` does not depend on `x[j]`",
                jac_x.clone(),
            ),
            jac_x_sparse: doc(
                "The entries of `D_x f` at the positions of `jac_x_pattern`, in that order",
                jac_x,
            ),
            jac_x_pattern: doc(
                "The positions `(i, j)` of `D_x f` where `f[i]` depends on `x[j]`, row by row",
                block(pattern.len(), |k| {
                    let (i, j, _) = pattern[k];
                    cut(format!("({i}, {j}): {}", d_f(i, &states[j])))
                }),
            ),
            jac_u: doc(
                "The Jacobian `D_u f`, row-major: `out[i * p + j] = d f[i] / d u[j]`",
                p.entries(&jac_u, |i, j| d_f(i, &names.inputs[j])),
            ),
            diffusion: doc(
                "The diffusion matrix `G(x, t)`, row-major: `out[i * m + k] = G[i, k]`, the \
                 coefficient of noise channel `k` in the equation of state `i`",
                p.entries(&diffusion, |i, k| {
                    format!("G[{}, {}]", states[i], names.noises[k])
                }),
            ),
        }
    }
}

impl MethodDoc {
    /// The doc of `set_numbers`: the moving sets' numbers (method.md 8.15), printed by
    /// `names`.
    pub(super) fn set_numbers(pool: &Pool, names: &Names<'_>, roots: &[ExprId]) -> MethodDoc {
        let p = Printer { pool, names };
        MethodDoc {
            what: "The numbers of the moving unsafe and goal sets, functions of `t` and tables: \
                   `out[k]` is entry `k` of `ModelInfo`'s `Moving::number`",
            equations: block(roots.len(), |k| p.equation(format!("number {k}"), roots[k])),
        }
    }
}

/// Prints a system's expressions.
struct Printer<'a> {
    pool: &'a Pool,
    names: &'a Names<'a>,
}

impl Printer<'_> {
    /// The entries of `matrix` that are not the constant 0: (row, column, entry).
    fn nonzero(&self, matrix: &[Vec<ExprId>]) -> Vec<(usize, usize, ExprId)> {
        let mut out = Vec::new();
        for (i, row) in matrix.iter().enumerate() {
            for (j, &e) in row.iter().enumerate() {
                if self.pool.as_const(e) != Some(0.0) {
                    out.push((i, j, e));
                }
            }
        }
        out
    }

    /// The [`block`] of `entry(i, j) = e` for each (row, column, entry).
    fn entries(
        &self,
        entries: &[(usize, usize, ExprId)],
        entry: impl Fn(usize, usize) -> String,
    ) -> String {
        block(entries.len(), |k| {
            let (i, j, e) = entries[k];
            self.equation(entry(i, j), e)
        })
    }

    /// `lhs = e`, [`cut`] to [`MAX_LINE`] characters.
    fn equation(&self, lhs: String, e: ExprId) -> String {
        // A character takes at most 4 bytes: a prefix of this many is always long enough.
        let rhs = self.pool.to_sde_prefix(e, self.names, 4 * MAX_LINE);
        cut(format!("{lhs} = {rhs}"))
    }
}

/// Lines `line(k)` for `k` below `total` in a fenced block, at most [`MAX_EQUATIONS`] of them,
/// then how many were left out.
fn block(total: usize, line: impl Fn(usize) -> String) -> String {
    if total == 0 {
        return "Every entry is 0.".to_string();
    }
    let mut lines: Vec<String> = (0..total.min(MAX_EQUATIONS)).map(line).collect();
    if total > MAX_EQUATIONS {
        lines.push(format!("... and {} more", total - MAX_EQUATIONS));
    }
    fenced(&lines.join("\n"))
}

/// `line` if it has at most [`MAX_LINE`] characters, else its beginning and ` ...`, cut at a
/// space in its second half if there is one (so that no name or number is cut in two).
fn cut(line: String) -> String {
    if line.chars().count() <= MAX_LINE {
        return line;
    }
    let keep: String = line.chars().take(MAX_LINE - 4).collect();
    let end = keep
        .rfind(' ')
        .filter(|&space| space > MAX_LINE / 2)
        .unwrap_or(keep.len());
    format!("{} ...", &keep[..end])
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
pub(super) fn doc_attrs(text: &str) -> TokenStream {
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
pub(super) fn struct_doc(model: &Model) -> TokenStream {
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

/// The doc of the transformed frame `k` of the model `name`, `y = T x` for the `n x n`
/// row-major `matrix` `T`.
pub(super) fn frame_doc(name: &Ident, k: usize, matrix: &[f64], n: usize) -> TokenStream {
    let doc = format!(
        " `{name}` in the coordinates `y = T x`, `T = {}`: drift `T f(T^-1 y, u, t)`, \
         diffusion `T G(T^-1 y, t)` (the frame {k} of [`{name}`]'s `System::frame`).",
        matrix_text(matrix, n)
    );
    quote!(#[doc = #doc])
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

/// The doc of `info()`: what it holds and, per analysis, its constants and how they were
/// obtained.
pub(super) fn info_doc(info: &ModelInfo) -> TokenStream {
    let mut text = format!(
        "Names, sets and analyses of the model `{}`, with the constants of Assumption 1\n\
         the compiler derived for each analysis (and how).",
        info.name().replace('`', "'")
    );
    let one_line = |s: &str| s.split_whitespace().collect::<Vec<_>>().join(" ");
    let mut list = Vec::new();
    for a in info.analyses() {
        let method = a.spec.method.name();
        let what = match &a.constants {
            Ok(c) => format!(
                "c = {}, sigma = {}, rho = {}\n    {}",
                match a.spec.rate {
                    Rate::Global => short(c.c()),
                    Rate::Local => format!("local (global {})", short(c.c())),
                    Rate::Empirical { paths } => format!("empirical ({paths} paths)"),
                },
                short(c.sigma()),
                short(c.rho()),
                one_line(&c.provenance().to_string())
            ),
            Err(e) => format!("no constants\n    {}", one_line(&e.to_string())),
        };
        list.push(format!("{} ({method}): {what}", one_line(&a.spec.name)));
    }
    if !list.is_empty() {
        text.push_str("\n\n");
        text.push_str(&fenced(&list.join("\n")));
    }
    doc_attrs(&text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ir::{Func1, Var};

    #[test]
    fn doc_lines_are_sanitized() {
        let d = doc_attrs("a\r\nb\u{202E}c\u{0}\n*/ } fn evil() {");
        let text = crate::backend::codegen::format_file(quote!(#d pub struct S;));
        assert!(text.contains("/// a\n"), "{text}");
        assert!(text.contains(r"b\u{202e}c\u{0}"), "{text}");
        assert!(!text.contains('\r') && !text.contains('\u{202E}'));
        let file = syn::parse_file(&text).unwrap();
        assert_eq!(file.items.len(), 1);
    }

    #[test]
    fn long_expressions_are_cut() {
        let mut pool = Pool::new();
        let x = pool.var(Var::State(0));
        // sum of sin(k x), k = 1..100: hundreds of characters when printed.
        let e = (1..=100).fold(x, |acc, k| {
            let k = pool.num(f64::from(k));
            let kx = pool.mul(k, x);
            let s = pool.call1(Func1::Sin, kx);
            pool.add(acc, s)
        });
        let states = ["x".to_string()];
        let names = Names {
            states: &states,
            inputs: &[],
            noises: &[],
            tables: &[],
        };
        let p = Printer {
            pool: &pool,
            names: &names,
        };
        let line = p.equation("x'".to_string(), e);
        assert!(
            line.starts_with("x' = ") && line.ends_with(" ..."),
            "{line}"
        );
        assert!(line.chars().count() <= MAX_LINE, "{line}");
        assert_eq!(p.equation("x'".to_string(), x), "x' = x");
    }

    #[test]
    fn long_lines_are_cut_at_a_space() {
        let short = "x' = y".to_string();
        assert_eq!(cut(short.clone()), short);
        let words = "x' = ".to_string() + &"alpha + ".repeat(30);
        let line = cut(words.clone());
        assert!(line.chars().count() <= MAX_LINE, "{line}");
        let kept = line.strip_suffix(" ...").unwrap();
        assert!(kept.len() > MAX_LINE / 2, "{line}");
        assert!(words.strip_prefix(kept).unwrap().starts_with(' '), "{line}");
        // No space to cut at (and characters of several bytes): cut anywhere.
        let line = cut("é".repeat(200));
        assert_eq!(line, "é".repeat(MAX_LINE - 4) + " ...");
    }

    #[test]
    fn blocks_are_bounded() {
        assert_eq!(block(0, |_| unreachable!()), "Every entry is 0.");
        assert_eq!(block(2, |k| format!("e{k}")), "```text\ne0\ne1\n```");
        let text = block(1000, |k| format!("e{k}"));
        assert_eq!(text.lines().count(), MAX_EQUATIONS + 3, "{text}");
        assert!(text.contains("\ne19\n... and 980 more\n"), "{text}");
    }
}
