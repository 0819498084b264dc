//! Minimises a failing input: removes chunks of lines, then of tokens, as long as the input
//! still fails the same way (greedy delta debugging, with a cap on the number of runs).

use super::lex::tokens;

/// The smallest `input` found for which `fails` still holds, trying at most `runs` candidates.
pub fn minimise(input: &[u8], runs: usize, fails: &mut dyn FnMut(&[u8]) -> bool) -> Vec<u8> {
    let mut left = runs;
    let lines = split_lines(input);
    let mut best = reduce(lines, &mut left, fails).concat();
    if let Ok(text) = std::str::from_utf8(&best) {
        let units = split_tokens(text);
        best = reduce(units, &mut left, fails).concat();
    }
    best
}

/// Removes chunks of `units` (halves, quarters, ..., single units) while `fails` holds.
fn reduce(
    mut units: Vec<Vec<u8>>,
    left: &mut usize,
    fails: &mut dyn FnMut(&[u8]) -> bool,
) -> Vec<Vec<u8>> {
    let mut chunk = units.len().div_ceil(2).max(1);
    loop {
        let mut start = 0;
        while start < units.len() && *left > 0 {
            let end = (start + chunk).min(units.len());
            let candidate: Vec<u8> = units[..start]
                .iter()
                .chain(&units[end..])
                .flatten()
                .copied()
                .collect();
            *left -= 1;
            if fails(&candidate) {
                units.drain(start..end);
            } else {
                start = end;
            }
        }
        if chunk == 1 || *left == 0 {
            return units;
        }
        chunk = chunk.div_ceil(2);
    }
}

/// The lines of `input`, each with its newline.
fn split_lines(input: &[u8]) -> Vec<Vec<u8>> {
    input
        .split_inclusive(|&b| b == b'\n')
        .map(<[u8]>::to_vec)
        .collect()
}

/// The tokens of `text`, each with the text before it (so the units concatenate to `text`).
fn split_tokens(text: &str) -> Vec<Vec<u8>> {
    let mut units = Vec::new();
    let mut last = 0;
    for t in tokens(text) {
        units.push(text.as_bytes()[last..t.span.end].to_vec());
        last = t.span.end;
    }
    if last < text.len() {
        units.push(text.as_bytes()[last..].to_vec());
    }
    units
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_only_what_the_failure_needs() {
        let input = b"model m\nconst a = 1\nconst b = ((2))\nstate x = a\n";
        let mut fails = |s: &[u8]| String::from_utf8_lossy(s).contains("((2))");
        let small = minimise(input, 1000, &mut fails);
        assert_eq!(String::from_utf8_lossy(&small).trim(), "((2))");
    }
}
