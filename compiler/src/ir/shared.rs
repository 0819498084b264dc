//! Printing many expressions of one pool at once, with large shared sub-expressions named by
//! `let`s, so that the text stays linear in the size of the DAG (printed as trees, 20 lets that
//! each use the previous one twice are millions of characters).

use std::collections::HashMap;

use super::node::ExprId;
use super::pool::Pool;
use super::print::Names;

/// A shared sub-expression is named once it would print longer than this many bytes; shorter
/// ones are repeated (`cos(theta)` reads better than a name).
const MIN_NAMED: usize = 64;

/// Expressions printed with shared `let`s ([`Pool::to_sde_shared`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SharedText {
    /// `(name, expression)` in order: each uses only the names before it.
    pub lets: Vec<(String, String)>,
    /// Each root's text, in the order given (a root itself always prints in full).
    pub exprs: Vec<String>,
}

impl Pool {
    /// `roots` in `.sde` syntax, every sub-expression that is printed more than once and is
    /// longer than 64 bytes written once as a `let` named `_1`, `_2`, ... (with more leading
    /// underscores if a variable's name could clash). `let NAME = EXPR` lines followed by a
    /// root's text parse back to the root. The total length is at most linear in the number of
    /// nodes reachable from `roots` (times the longest node's own text).
    pub fn to_sde_shared(&self, roots: &[ExprId], names: &Names<'_>) -> SharedText {
        let nodes = self.reachable(roots);
        let mut uses: HashMap<ExprId, usize> = roots.iter().map(|&r| (r, 1)).collect();
        let mut refs = HashMap::with_capacity(nodes.len());
        for &n in &nodes {
            let (children, len) = self.print_refs(n, names);
            for &c in &children {
                *uses.entry(c).or_default() += 1;
            }
            refs.insert(n, (children, len));
        }
        let prefix = let_prefix(names);
        // Increasing ids are a topological order: a node's children are decided before it.
        let mut size: HashMap<ExprId, usize> = HashMap::with_capacity(nodes.len());
        let mut named: HashMap<ExprId, String> = HashMap::new();
        let mut order = Vec::new();
        for &n in &nodes {
            let (children, len) = &refs[&n];
            let inline = children.iter().fold(*len, |acc, c| {
                acc.saturating_add(named.get(c).map_or_else(|| size[c], String::len))
            });
            size.insert(n, inline);
            if inline > MIN_NAMED && uses.get(&n).copied().unwrap_or(0) >= 2 {
                named.insert(n, format!("{prefix}{}", named.len() + 1));
                order.push(n);
            }
        }
        let lookup = |id: ExprId| named.get(&id).map(String::as_str);
        SharedText {
            lets: order
                .iter()
                .map(|&n| (named[&n].clone(), self.print(n, names, usize::MAX, &lookup)))
                .collect(),
            exprs: roots
                .iter()
                .map(|&r| self.print(r, names, usize::MAX, &lookup))
                .collect(),
        }
    }
}

/// `_`, or more underscores if a variable or table is named like `_1`.
fn let_prefix(names: &Names<'_>) -> String {
    let mut prefix = "_".to_string();
    let all = || {
        names
            .states
            .iter()
            .chain(names.inputs)
            .chain(names.noises)
            .map(String::as_str)
            .chain(names.tables.iter().map(|t| t.name.as_str()))
    };
    while all().any(|n| {
        n.strip_prefix(prefix.as_str())
            .is_some_and(|rest| rest.starts_with(|c: char| c.is_ascii_digit()))
    }) {
        prefix.push('_');
    }
    prefix
}
