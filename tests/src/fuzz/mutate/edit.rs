//! Edits of `.sde` text on its tokens and lines: what each mutation does once its choices are
//! drawn.

use std::ops::Range;

use super::values::{ANALYSIS, NAMES};
use super::Pick;
use crate::fuzz::lex::{Kind, Token};

/// The token `at` picks among `toks`, if there is any.
pub fn token_at<'a>(toks: impl Iterator<Item = &'a Token>, at: &Pick) -> Option<&'a Token> {
    let toks: Vec<&Token> = toks.collect();
    (!toks.is_empty()).then(|| toks[at.of(toks.len())])
}

/// `src` with token `t` replaced by `with`.
pub fn replace(src: &str, t: &Token, with: &str) -> String {
    format!("{}{with}{}", &src[..t.span.start], &src[t.span.end..])
}

/// `src` with two disjoint ranges exchanged (equal or overlapping ranges leave it unchanged).
pub fn swap(src: &str, a: Range<usize>, b: Range<usize>) -> String {
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
pub fn edit_lines(src: &str, f: impl FnOnce(&mut Vec<String>)) -> String {
    let mut lines: Vec<String> = src.lines().map(str::to_string).collect();
    if !lines.is_empty() {
        f(&mut lines);
    }
    lines.join("\n") + "\n"
}

/// Renames the identifier `at` picks (all its occurrences, or that one only).
pub fn rename(src: &str, toks: &[Token], at: &Pick, to: &Pick, all: bool) -> String {
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
pub fn scale_matrix(src: &str, toks: &[Token], at: &Pick, factor: &str) -> String {
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

/// The block of the item or loop starting with `word` that `at` picks: the indices of that
/// token, of the `{` after it and of the matching `}`.
fn block(src: &str, toks: &[Token], word: &str, at: &Pick) -> Option<(usize, usize, usize)> {
    let starts: Vec<usize> = positions(src, toks, word).collect();
    let start = *starts.get(at.of(starts.len().max(1)))?;
    let open = (start..toks.len()).find(|&i| &src[toks[i].span.clone()] == "{")?;
    Some((start, open, closing(src, toks, open)?))
}

/// Repeats the `for` loop `at` picks right after itself, or wraps it in `times` loops.
pub fn for_loop(
    src: &str,
    toks: &[Token],
    at: &Pick,
    nest: bool,
    times: usize,
    end: &str,
) -> String {
    let Some((start, _, close)) = block(src, toks, "for", at) else {
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
pub fn analysis_key(src: &str, toks: &[Token], at: &Pick, key: &Pick, value: &Pick) -> String {
    let (key, values) = ANALYSIS[key.of(ANALYSIS.len())];
    let value = values[value.of(values.len())];
    let Some((_, open, close)) = block(src, toks, "analysis", at) else {
        return src.into();
    };
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
    use crate::fuzz::lex::tokens;

    const SPEC: &str = "model m\nstate x in [0, 1]\ndrift { x' = -x }\nanalysis a {\n    horizon = 4\n    radius = paper(eps = 1/16)\n    step = 0.1\n}\n";

    #[test]
    fn analysis_keys_are_replaced_whole_or_added() {
        let with = |key: &str, value: u64| {
            let k = ANALYSIS.iter().position(|(k, _)| *k == key).unwrap();
            analysis_key(SPEC, &tokens(SPEC), &Pick(0), &Pick(k as u64), &Pick(value))
        };
        let radius = with("radius", 0);
        assert!(radius.contains("radius = amgf\n    step = 0.1"), "{radius}");
        let rate = with("rate", 1);
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
