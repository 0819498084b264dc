//! Mutations of `.sde` text, drawn by proptest strategies: token-level (numbers replaced by
//! extremes, tokens deleted, repeated or swapped, identifiers renamed, parentheses nested,
//! matrices scaled), line-level (lines deleted, repeated, swapped or spliced in from another
//! seed, `for` loops repeated or nested, analysis keys given other values) and byte-level
//! (bytes set, inserted or cut, which also makes invalid UTF-8). A [`Mutant`] is plain data, so
//! the same seed and the same mutations give the same bytes.

use proptest::prelude::*;

use super::lex::{tokens, Kind, Token};

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

/// Numbers a mutation puts in place of a literal: boundaries of f64 and of integer types.
const EXTREMES: &[&str] = &[
    "0",
    "1",
    "-1",
    "0.0",
    "-0",
    "0.5",
    "1e308",
    "1.7976931348623157e308",
    "1e309",
    "1e-308",
    "1e-300",
    "5e-324",
    "1e-320",
    "1e-9",
    "1e6",
    "1e9",
    "1e15",
    "1e18",
    "100000",
    "2147483647",
    "2147483648",
    "4294967296",
    "9007199254740993",
    "18446744073709551616",
    "99999999999999999999999999999",
];

/// Names an identifier is renamed to: built-ins, keywords, Rust words, invalid and odd names.
const NAMES: &[&str] = &[
    "t", "pi", "e", "inf", "nan", "model", "state", "for", "in", "drift", "analysis", "x", "w",
    "_", "self", "Self", "crate", "fn", "main", "std", "r#x", "θ", "x0", "ref",
];

/// How deep a nesting mutation wraps a token in parentheses (the parser's limit is 200).
const DEPTHS: &[usize] = &[1, 20, 199, 200, 201, 1000, 100_000];

/// Factors a matrix mutation multiplies every entry by.
const SCALES: &[&str] = &["1e300", "1e-300", "1e154", "-1", "0"];

/// Ranges of the loops a `for` mutation wraps around a loop.
const LOOP_ENDS: &[&str] = &["2", "10", "1000", "1e9"];

/// Analysis keys and values to give them (some valid for the key, some for another key).
const ANALYSIS: &[(&str, &[&str])] = &[
    ("method", &["contraction", "interval", "euler"]),
    ("delta", &["0", "1", "1e-300", "0.999999", "1e-15", "0.5"]),
    (
        "horizon",
        &["1e6", "1e9", "1e-300", "1e308", "0.001", "100"],
    ),
    (
        "step",
        &["1e-300", "1e-6", "1e-3", "1e308", "0.5", "horizon"],
    ),
    (
        "metric",
        &[
            "identity",
            "auto",
            "auto(states = [x])",
            "[[1e300]]",
            "[[1, 0], [0, 1]]",
            "[]",
        ],
    ),
    (
        "radius",
        &[
            "amgf",
            "paper(eps = 1/16)",
            "paper(optimal)",
            "paper(eps = 1e-300)",
            "paper()",
        ],
    ),
    (
        "rate",
        &[
            "local",
            "global",
            "empirical(paths = 2)",
            "empirical(paths = 20000)",
            "empirical",
        ],
    ),
    ("inclusion", &["natural", "jacobian", "mixed"]),
    ("integrator", &["validated", "rk4", "euler"]),
    ("guarantee", &["uniform", "pointwise"]),
    (
        "transform",
        &[
            "auto",
            "[[0]]",
            "[[1, 0], [0, 1]]",
            "[[1, 1], [1, 1]]",
            "[[1e300]]",
        ],
    ),
    ("outputs", &["[]", "[t]", "[x]"]),
];

/// Whole lines a mutation inserts: declarations at and beyond the language's limits.
const LINES: &[&str] = &[
    "state big[1..1000000] = 0",
    "noise many[1..100000]",
    "const N = 1e308",
    "noise r#x",
    "input u in [1e308, -1e308]",
    "table fz = csv(\"/dev/null\")",
    "let fz = fz",
    "domain { }",
    "model again",
];

/// A change to the text of a spec.
#[derive(Clone, Debug)]
pub enum TextMutation {
    /// A number literal replaced by one of [`EXTREMES`].
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
    /// An identifier renamed (every occurrence, or the one chosen) to one of [`NAMES`], to
    /// another identifier of the spec, or to a 300-character name.
    Rename(Pick, Pick, bool),
    /// A number or identifier wrapped in [`DEPTHS`] parentheses.
    Nest(Pick, Pick),
    /// Every number of a matrix `[[..]]` multiplied by one of [`SCALES`].
    ScaleMatrix(Pick, Pick),
    /// A `for` loop written twice, or wrapped in 1 to 3 loops over `1..`[`LOOP_ENDS`].
    ForLoop(Pick, bool, usize, Pick),
    /// An analysis key given one of its [`ANALYSIS`] values (replaced, or added).
    AnalysisKey(Pick, Pick, Pick),
    /// One of [`LINES`] inserted before a line.
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

/// The token `at` picks among `toks`, if there is any.
fn token_at<'a>(toks: impl Iterator<Item = &'a Token>, at: &Pick) -> Option<&'a Token> {
    let toks: Vec<&Token> = toks.collect();
    (!toks.is_empty()).then(|| toks[at.of(toks.len())])
}

/// `src` with token `t` replaced by `with`.
fn replace(src: &str, t: &Token, with: &str) -> String {
    format!("{}{with}{}", &src[..t.span.start], &src[t.span.end..])
}

/// `src` with two disjoint ranges exchanged (equal or overlapping ranges leave it unchanged).
fn swap(src: &str, a: std::ops::Range<usize>, b: std::ops::Range<usize>) -> String {
    let (a, b) = if a.start <= b.start { (a, b) } else { (b, a) };
    if a.end > b.start {
        return src.into();
    }
    format!(
        "{}{}{}{}{}",
        &src[..a.start],
        &src[b.clone()],
        &src[a.end..b.start],
        &src[a],
        &src[b.end..]
    )
}

/// `src` with its lines edited by `f` (not called when there are no lines).
fn edit_lines(src: &str, f: impl FnOnce(&mut Vec<String>)) -> String {
    let mut lines: Vec<String> = src.lines().map(str::to_string).collect();
    if !lines.is_empty() {
        f(&mut lines);
    }
    lines.join("\n") + "\n"
}

/// Renames the identifier `at` picks (all its occurrences, or that one only).
fn rename(src: &str, toks: &[Token], at: &Pick, to: &Pick, all: bool) -> String {
    let idents: Vec<&Token> = toks.iter().filter(|t| t.kind == Kind::Ident).collect();
    let Some(target) = token_at(idents.iter().copied(), at) else {
        return src.into();
    };
    let long = "n".repeat(300);
    let choices: Vec<&str> = NAMES
        .iter()
        .copied()
        .chain([long.as_str()])
        .chain(idents.iter().map(|t| &src[t.span.clone()]))
        .collect();
    let new = choices[to.of(choices.len())];
    let old = &src[target.span.clone()];
    let mut out = String::with_capacity(src.len());
    let mut last = 0;
    for t in &idents {
        if (all && &src[t.span.clone()] == old) || t.span == target.span {
            out.push_str(&src[last..t.span.start]);
            out.push_str(new);
            last = t.span.end;
        }
    }
    out + &src[last..]
}

/// The index of the token closing the bracket `open` opens (`(`, `[` or `{`), if any.
fn closing(src: &str, toks: &[Token], open: usize) -> Option<usize> {
    let mut depth = 0i64;
    for (i, t) in toks.iter().enumerate().skip(open) {
        match &src[t.span.clone()] {
            "(" | "[" | "{" => depth += 1,
            ")" | "]" | "}" => depth -= 1,
            _ => {}
        }
        if depth == 0 {
            return Some(i);
        }
    }
    None
}

/// Indices of the tokens whose text is `word`.
fn positions<'a>(
    src: &'a str,
    toks: &'a [Token],
    word: &'a str,
) -> impl Iterator<Item = usize> + 'a {
    toks.iter()
        .enumerate()
        .filter(move |(_, t)| &src[t.span.clone()] == word)
        .map(|(i, _)| i)
}

/// Multiplies every number of the matrix `[[..]]` `at` picks by `factor`.
fn scale_matrix(src: &str, toks: &[Token], at: &Pick, factor: &str) -> String {
    let starts: Vec<usize> = positions(src, toks, "[")
        .filter(|&i| toks.get(i + 1).is_some_and(|t| &src[t.span.clone()] == "["))
        .collect();
    if starts.is_empty() {
        return src.into();
    }
    let open = starts[at.of(starts.len())];
    let close = closing(src, toks, open).unwrap_or(toks.len() - 1);
    let mut out = src[..toks[open].span.start].to_string();
    let mut last = toks[open].span.start;
    for t in toks[open..=close].iter().filter(|t| t.kind == Kind::Number) {
        out.push_str(&src[last..t.span.start]);
        out.push_str(&format!("({} * {factor})", &src[t.span.clone()]));
        last = t.span.end;
    }
    out + &src[last..]
}

/// Repeats the `for` loop `at` picks right after itself, or wraps it in `times` loops.
fn for_loop(src: &str, toks: &[Token], at: &Pick, nest: bool, times: usize, end: &str) -> String {
    let fors: Vec<usize> = positions(src, toks, "for").collect();
    if fors.is_empty() {
        return src.into();
    }
    let start = fors[at.of(fors.len())];
    let Some(open) = (start..toks.len()).find(|&i| &src[toks[i].span.clone()] == "{") else {
        return src.into();
    };
    let Some(close) = closing(src, toks, open) else {
        return src.into();
    };
    let span = toks[start].span.start..toks[close].span.end;
    let body = &src[span.clone()];
    let new = if nest {
        (0..times).fold(body.to_string(), |b, k| {
            format!("for fz{k} in 1..{end} {{ {b} }}")
        })
    } else {
        format!("{body}\n{body}")
    };
    format!("{}{new}{}", &src[..span.start], &src[span.end..])
}

/// Gives the analysis block `at` picks a key from [`ANALYSIS`] and one of its values: replaces
/// the key's value if the block has it, adds the key otherwise.
fn analysis_key(src: &str, toks: &[Token], at: &Pick, key: &Pick, value: &Pick) -> String {
    let (key, values) = ANALYSIS[key.of(ANALYSIS.len())];
    let value = values[value.of(values.len())];
    let blocks: Vec<usize> = positions(src, toks, "analysis").collect();
    if blocks.is_empty() {
        return src.into();
    }
    let start = blocks[at.of(blocks.len())];
    let Some(open) = (start..toks.len()).find(|&i| &src[toks[i].span.clone()] == "{") else {
        return src.into();
    };
    let close = closing(src, toks, open).unwrap_or(toks.len() - 1);
    let text = |i: usize| &src[toks[i].span.clone()];
    let field = |i: usize| toks[i].kind == Kind::Ident && i + 1 < close && text(i + 1) == "=";
    let existing = (open + 1..close).find(|&i| text(i) == key && field(i));
    match existing {
        Some(k) => {
            // The value runs from after `=` to the next field at depth 0 or the block's end.
            let first = k + 2;
            let (mut depth, mut end) = (0i64, first);
            while end < close && (depth > 0 || end == first || !field(end)) {
                match text(end) {
                    "(" | "[" => depth += 1,
                    ")" | "]" => depth -= 1,
                    _ => {}
                }
                end += 1;
            }
            let from = toks[k + 1].span.end;
            let to = if end > first {
                toks[end - 1].span.end
            } else {
                from
            };
            format!("{} {value}{}", &src[..from], &src[to..])
        }
        None => {
            let at = toks[open].span.end;
            format!("{}\n    {key} = {value}\n{}", &src[..at], &src[at..])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: &str = "model m\nstate x in [0, 1]\ndrift { x' = -x }\nanalysis a {\n    horizon = 4\n    radius = paper(eps = 1/16)\n    step = 0.1\n}\n";

    #[test]
    fn analysis_keys_are_replaced_whole_or_added() {
        let k = |name: &str| ANALYSIS.iter().position(|(k, _)| *k == name).unwrap();
        let radius = analysis_key(
            SPEC,
            &tokens(SPEC),
            &Pick(0),
            &Pick(k("radius") as u64),
            &Pick(0),
        );
        assert!(radius.contains("radius = amgf\n    step = 0.1"), "{radius}");
        let rate = analysis_key(
            SPEC,
            &tokens(SPEC),
            &Pick(0),
            &Pick(k("rate") as u64),
            &Pick(1),
        );
        assert!(rate.contains("analysis a {\n    rate = global\n"), "{rate}");
    }

    #[test]
    fn for_loops_nest_and_matrices_scale() {
        let src = "for i in 1..3 { let d[i] = i }\nmetric = [[1, 2], [2, 5]]\n";
        let nested = for_loop(src, &tokens(src), &Pick(0), true, 2, "10");
        assert!(
            nested.starts_with(
                "for fz1 in 1..10 { for fz0 in 1..10 { for i in 1..3 { let d[i] = i } } }"
            ),
            "{nested}"
        );
        let scaled = scale_matrix(src, &tokens(src), &Pick(0), "1e300");
        assert!(
            scaled.contains("[[(1 * 1e300), (2 * 1e300)], [(2 * 1e300), (5 * 1e300)]]"),
            "{scaled}"
        );
    }
}
