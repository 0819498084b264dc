//! The symbol table of the checker and did-you-mean suggestions.

use std::collections::HashMap;

use crate::diagnostics::Span;
use crate::ir::ExprId;

/// Which kind of model variable a name denotes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum VarKind {
    State,
    Input,
    Noise,
}

impl VarKind {
    pub(super) fn word(self) -> &'static str {
        match self {
            VarKind::State => "state",
            VarKind::Input => "input",
            VarKind::Noise => "noise channel",
        }
    }

    pub(super) fn with_article(self) -> String {
        match self {
            VarKind::Input => "an input".into(),
            k => format!("a {}", k.word()),
        }
    }
}

/// What a name refers to.
#[derive(Clone, Debug)]
pub(super) enum Symbol {
    Const(f64),
    /// A scalar variable: its index among the variables of its kind.
    Var(VarKind, u32),
    /// A family `x[lo..hi]` whose element `x[lo]` has index `first`.
    Family {
        kind: VarKind,
        first: u32,
        lo: i64,
        hi: i64,
    },
    Table(u32),
    Let(ExprId),
    LetFamily(HashMap<i64, ExprId>),
    /// A name whose definition failed (already reported): uses are silently skipped so one
    /// mistake does not cascade into follow-up errors.
    Poisoned,
}

impl Symbol {
    pub(super) fn describe(&self) -> String {
        match self {
            Symbol::Const(_) => "a constant".into(),
            Symbol::Var(k, _) => k.with_article(),
            Symbol::Family { kind, .. } => format!("{} family", kind.with_article()),
            Symbol::Table(_) => "a table".into(),
            Symbol::Let(_) => "a let definition".into(),
            Symbol::LetFamily(_) => "an indexed let definition".into(),
            Symbol::Poisoned => "an erroneous definition".into(),
        }
    }
}

/// Names defined so far, with the span of each definition (for "defined here" labels).
#[derive(Default)]
pub(super) struct Scope {
    pub(super) symbols: HashMap<String, (Symbol, Span)>,
}

/// Names every spec has and cannot redefine. (`e` is built in too, but a spec may define its
/// own `e`, which then hides Euler's number.)
pub(super) const BUILTIN_NAMES: &[&str] = &["t", "pi"];

impl Scope {
    pub(super) fn get(&self, name: &str) -> Option<&(Symbol, Span)> {
        self.symbols.get(name)
    }

    /// The closest known name (or function) to `name`, if close enough to be a likely typo.
    pub(super) fn suggest<'a>(
        &'a self,
        name: &str,
        extra: impl IntoIterator<Item = &'a str>,
    ) -> Option<String> {
        // `e` and `t` are one edit from every one-letter name: suggesting them is noise.
        let builtins = BUILTIN_NAMES
            .iter()
            .copied()
            .filter(|b| name.len() > 2 || b.len() > 1);
        let candidates = self
            .symbols
            .iter()
            .filter(|(_, (s, _))| !matches!(s, Symbol::Poisoned))
            .map(|(k, _)| k.as_str())
            .chain(builtins)
            .chain(extra);
        did_you_mean(name, candidates)
    }
}

/// The candidate with the smallest edit distance to `name`, if that distance is small
/// relative to the name's length. Ties go to the longest common prefix (`sinn` -> `sin`, not
/// `sign`), then alphabetical order, for stable output.
pub(super) fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<String> {
    let limit = (name.chars().count() / 3).max(1);
    let prefix = |c: &str| {
        c.chars()
            .zip(name.chars())
            .take_while(|(a, b)| a == b)
            .count()
    };
    candidates
        .into_iter()
        .filter(|c| *c != name)
        .map(|c| (edit_distance(name, c), usize::MAX - prefix(c), c))
        .filter(|(d, _, _)| *d <= limit)
        .min()
        .map(|(_, _, c)| c.to_string())
}

/// Optimal-string-alignment distance: insertions, deletions, substitutions and adjacent
/// transpositions (`omgea` -> `omega` is one edit) each cost one.
fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, v) in d[0].iter_mut().enumerate() {
        *v = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            d[i][j] = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                d[i][j] = d[i][j].min(d[i - 2][j - 2] + 1);
            }
        }
    }
    d[a.len()][b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances() {
        assert_eq!(edit_distance("omega", "omgea"), 1);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("theta", "theta"), 0);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }

    #[test]
    fn suggestions() {
        let names = ["theta", "omega", "g", "K1"];
        assert_eq!(did_you_mean("thetta", names), Some("theta".into()));
        assert_eq!(did_you_mean("omeg", names), Some("omega".into()));
        assert_eq!(did_you_mean("zzzzzz", names), None);
        assert_eq!(did_you_mean("K2", names), Some("K1".into()));
        assert_eq!(did_you_mean("omgea", names), Some("omega".into()));
        assert_eq!(did_you_mean("sinn", ["sign", "sin"]), Some("sin".into()));
    }
}
