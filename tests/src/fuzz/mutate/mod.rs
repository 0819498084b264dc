//! Mutations of `.sde` text, drawn by proptest strategies: token-level (numbers replaced by
//! extremes, tokens deleted, repeated or swapped, identifiers renamed, parentheses nested,
//! matrices scaled), line-level (lines deleted, repeated, swapped or spliced in from another
//! seed, `for` loops repeated or nested, analysis keys given other values) and byte-level
//! (bytes set, inserted or cut, which also makes invalid UTF-8). A [`Mutant`] is plain data, so
//! the same seed and the same mutations give the same bytes.

use proptest::prelude::*;

mod edit;
mod values;

use super::lex::{tokens, Kind};
use edit::{analysis_key, edit_lines, for_loop, rename, replace, scale_matrix, swap, token_at};
use values::{DEPTHS, EXTREMES, LINES, LOOP_ENDS, SCALES};

/// A choice among however many candidates a spec turns out to have: a mutation is drawn before
/// the text it applies to is known.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pick(pub u64);

impl Pick {
    /// The candidate this picks among `n` (`n > 0`).
    pub fn of(self, n: usize) -> usize {
        (self.0 % n as u64) as usize
    }
}

fn any_pick() -> impl Strategy<Value = Pick> {
    any::<u64>().prop_map(Pick)
}

/// A change to the text of a spec.
#[derive(Clone, Debug)]
pub enum TextMutation {
    /// A number literal replaced by one of `EXTREMES`.
    Number(Pick, Pick),
    /// A token deleted.
    DeleteToken(Pick),
    /// A token written twice.
    DuplicateToken(Pick),
    /// Two tokens exchanged.
    SwapTokens(Pick, Pick),
    /// A line deleted.
    DeleteLine(Pick),
    /// A line written twice.
    DuplicateLine(Pick),
    /// Two lines exchanged.
    SwapLines(Pick, Pick),
    /// Up to four lines of another seed (`seed`, first line, count) inserted before a line.
    Splice(Pick, Pick, usize, Pick),
    /// An identifier renamed (every occurrence, or the one chosen) to one of `NAMES`, to
    /// another identifier of the spec, or to a 300-character name.
    Rename(Pick, Pick, bool),
    /// A number or identifier wrapped in `DEPTHS` parentheses.
    Nest(Pick, Pick),
    /// Every number of a matrix `[[..]]` multiplied by one of `SCALES`.
    ScaleMatrix(Pick, Pick),
    /// A `for` loop written twice, or wrapped in 1 to 3 loops over `1..LOOP_ENDS`.
    ForLoop(Pick, bool, usize, Pick),
    /// An analysis key given one of its `ANALYSIS` values (replaced, or added).
    AnalysisKey(Pick, Pick, Pick),
    /// One of `LINES` inserted before a line.
    InsertLine(Pick, Pick),
}

/// A change to the bytes of a spec, applied after the text mutations.
#[derive(Clone, Debug)]
pub enum ByteMutation {
    /// A byte set to a value.
    Set(Pick, u8),
    /// Bytes inserted.
    Insert(Pick, Vec<u8>),
    /// The text cut at a byte.
    Truncate(Pick),
}

/// One mutant: which seed, and what is changed.
#[derive(Clone, Debug)]
pub struct Mutant {
    /// Which seed, among the candidates of the command.
    pub seed: Pick,
    /// Text mutations, applied in order.
    pub text: Vec<TextMutation>,
    /// An optional byte mutation, applied last.
    pub bytes: Option<ByteMutation>,
}

fn text_mutation() -> impl Strategy<Value = TextMutation> {
    let i = any_pick;
    prop_oneof![
        3 => (i(), i()).prop_map(|(a, b)| TextMutation::Number(a, b)),
        1 => i().prop_map(TextMutation::DeleteToken),
        1 => i().prop_map(TextMutation::DuplicateToken),
        1 => (i(), i()).prop_map(|(a, b)| TextMutation::SwapTokens(a, b)),
        1 => i().prop_map(TextMutation::DeleteLine),
        1 => i().prop_map(TextMutation::DuplicateLine),
        1 => (i(), i()).prop_map(|(a, b)| TextMutation::SwapLines(a, b)),
        1 => (i(), i(), 1..=4usize, i()).prop_map(|(s, l, n, at)| TextMutation::Splice(s, l, n, at)),
        2 => (i(), i(), any::<bool>()).prop_map(|(a, b, all)| TextMutation::Rename(a, b, all)),
        1 => (i(), i()).prop_map(|(a, b)| TextMutation::Nest(a, b)),
        1 => (i(), i()).prop_map(|(a, b)| TextMutation::ScaleMatrix(a, b)),
        1 => (i(), any::<bool>(), 1..=3usize, i())
            .prop_map(|(a, nest, k, end)| TextMutation::ForLoop(a, nest, k, end)),
        3 => (i(), i(), i()).prop_map(|(a, k, v)| TextMutation::AnalysisKey(a, k, v)),
        1 => (i(), i()).prop_map(|(a, b)| TextMutation::InsertLine(a, b)),
    ]
}

fn byte_mutation() -> impl Strategy<Value = ByteMutation> {
    prop_oneof![
        (any_pick(), any::<u8>()).prop_map(|(a, b)| ByteMutation::Set(a, b)),
        (any_pick(), prop::collection::vec(any::<u8>(), 1..4))
            .prop_map(|(a, b)| ByteMutation::Insert(a, b)),
        any_pick().prop_map(ByteMutation::Truncate),
    ]
}

/// Mutants for `check`: one to three mutations of any kind (mostly one), and a byte mutation
/// in one case of ten.
pub fn mutant() -> impl Strategy<Value = Mutant> {
    let count = prop_oneof![6 => Just(1usize), 3 => Just(2usize), 1 => Just(3usize)];
    (
        any_pick(),
        count.prop_flat_map(|n| prop::collection::vec(text_mutation(), n)),
        prop::option::weighted(0.1, byte_mutation()),
    )
        .prop_map(|(seed, text, bytes)| Mutant { seed, text, bytes })
}

/// Mutants for `run`: one or two of the mutations that usually keep a spec valid (numbers,
/// analysis keys, matrices, lines repeated, loops), so most mutants reach the analyses.
pub fn valid_mutant() -> impl Strategy<Value = Mutant> {
    let i = any_pick;
    let mutation = prop_oneof![
        3 => (i(), i()).prop_map(|(a, b)| TextMutation::Number(a, b)),
        4 => (i(), i(), i()).prop_map(|(a, k, v)| TextMutation::AnalysisKey(a, k, v)),
        1 => (i(), i()).prop_map(|(a, b)| TextMutation::ScaleMatrix(a, b)),
        1 => (i(), Just(false), Just(1usize), i())
            .prop_map(|(a, nest, k, end)| TextMutation::ForLoop(a, nest, k, end)),
    ];
    (any_pick(), prop::collection::vec(mutation, 1..=2)).prop_map(|(seed, text)| Mutant {
        seed,
        text,
        bytes: None,
    })
}

impl Mutant {
    /// The mutant's bytes: `seeds[seed]` mutated (the other seeds are what
    /// [`TextMutation::Splice`] takes lines from). The caller picks `seed` with [`Mutant::seed`]
    /// among the seeds its command accepts.
    pub fn apply(&self, seed: usize, seeds: &[String]) -> Vec<u8> {
        let mut text = seeds[seed].clone();
        for m in &self.text {
            text = m.apply(&text, seeds);
        }
        let mut bytes = text.into_bytes();
        if let Some(m) = &self.bytes {
            m.apply(&mut bytes);
        }
        bytes
    }
}

impl TextMutation {
    /// `src` with this mutation applied (unchanged when the spec has nothing it applies to).
    pub fn apply(&self, src: &str, seeds: &[String]) -> String {
        let toks = tokens(src);
        let of = |kind: Kind| toks.iter().filter(move |t| t.kind == kind);
        match self {
            TextMutation::Number(at, v) => token_at(of(Kind::Number), at).map_or_else(
                || src.into(),
                |t| replace(src, t, EXTREMES[v.of(EXTREMES.len())]),
            ),
            TextMutation::DeleteToken(at) => {
                token_at(toks.iter(), at).map_or_else(|| src.into(), |t| replace(src, t, ""))
            }
            TextMutation::DuplicateToken(at) => token_at(toks.iter(), at).map_or_else(
                || src.into(),
                |t| replace(src, t, &format!("{0} {0}", &src[t.span.clone()])),
            ),
            TextMutation::SwapTokens(a, b) => {
                match (token_at(toks.iter(), a), token_at(toks.iter(), b)) {
                    (Some(a), Some(b)) => swap(src, a.span.clone(), b.span.clone()),
                    _ => src.into(),
                }
            }
            TextMutation::DeleteLine(at) => edit_lines(src, |l| {
                l.remove(at.of(l.len()));
            }),
            TextMutation::DuplicateLine(at) => edit_lines(src, |l| {
                let i = at.of(l.len());
                l.insert(i, l[i].clone());
            }),
            TextMutation::SwapLines(a, b) => edit_lines(src, |l| {
                let n = l.len();
                l.swap(a.of(n), b.of(n));
            }),
            TextMutation::Splice(seed, first, count, at) => {
                let other: Vec<&str> = seeds[seed.of(seeds.len())].lines().collect();
                let start = first.of(other.len().max(1)).min(other.len());
                let lines = &other[start..(start + count).min(other.len())];
                edit_lines(src, |l| {
                    let i = at.of(l.len() + 1);
                    l.splice(i..i, lines.iter().map(|s| s.to_string()));
                })
            }
            TextMutation::Rename(at, to, all) => rename(src, &toks, at, to, *all),
            TextMutation::Nest(at, depth) => {
                let atoms = toks
                    .iter()
                    .filter(|t| matches!(t.kind, Kind::Number | Kind::Ident));
                token_at(atoms, at).map_or_else(
                    || src.into(),
                    |t| {
                        let d = DEPTHS[depth.of(DEPTHS.len())];
                        let inner = &src[t.span.clone()];
                        replace(
                            src,
                            t,
                            &format!("{}{inner}{}", "(".repeat(d), ")".repeat(d)),
                        )
                    },
                )
            }
            TextMutation::ScaleMatrix(at, factor) => {
                scale_matrix(src, &toks, at, SCALES[factor.of(SCALES.len())])
            }
            TextMutation::ForLoop(at, nest, times, end) => {
                let end = LOOP_ENDS[end.of(LOOP_ENDS.len())];
                for_loop(src, &toks, at, *nest, *times, end)
            }
            TextMutation::AnalysisKey(at, key, value) => analysis_key(src, &toks, at, key, value),
            TextMutation::InsertLine(at, line) => edit_lines(src, |l| {
                let i = at.of(l.len() + 1);
                l.insert(i, LINES[line.of(LINES.len())].to_string());
            }),
        }
    }
}

impl ByteMutation {
    /// Applies the mutation to `bytes`.
    pub fn apply(&self, bytes: &mut Vec<u8>) {
        let n = bytes.len();
        match self {
            ByteMutation::Set(at, b) if n > 0 => bytes[at.of(n)] = *b,
            ByteMutation::Set(..) => {}
            ByteMutation::Insert(at, b) => {
                let i = at.of(n + 1);
                bytes.splice(i..i, b.iter().copied());
            }
            ByteMutation::Truncate(at) => bytes.truncate(at.of(n + 1)),
        }
    }
}
