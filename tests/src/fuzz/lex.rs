//! A lexer for mutation, not for parsing: it splits `.sde` text into tokens with their byte
//! ranges, so mutations replace, delete or repeat whole tokens and keep the rest of the text
//! (comments, layout) as it was. It accepts any text: what the real lexer would reject becomes a
//! one-character [`Kind::Other`] token.

use std::ops::Range;

/// What a token is, as far as the mutations care.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A number literal (`1`, `.5`, `2.5e-3`).
    Number,
    /// An identifier or a keyword.
    Ident,
    /// A string literal, quotes included.
    Str,
    /// Punctuation (`..`, `<=`, `>=` are one token) or any other character.
    Other,
}

/// A token: its kind and its bytes in the source.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Token {
    /// What it is.
    pub kind: Kind,
    /// Where it is.
    pub span: Range<usize>,
}

/// The tokens of `src`, in order; whitespace and comments are skipped.
pub fn tokens(src: &str) -> Vec<Token> {
    let b = src.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let start = i;
        let kind = match b[i] {
            c if c.is_ascii_whitespace() => {
                i += 1;
                continue;
            }
            b'/' if b.get(i + 1) == Some(&b'/') => {
                i = src[i..].find('\n').map_or(b.len(), |n| i + n);
                continue;
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                i = block_comment_end(b, i);
                continue;
            }
            b'"' => {
                i = string_end(b, i);
                Kind::Str
            }
            c if c.is_ascii_digit()
                || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit)) =>
            {
                i = number_end(b, i);
                Kind::Number
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                    i += 1;
                }
                Kind::Ident
            }
            _ => {
                let two = b.get(i..i + 2);
                i += if matches!(two, Some(b"..") | Some(b"<=") | Some(b">=")) {
                    2
                } else {
                    src[i..].chars().next().map_or(1, char::len_utf8)
                };
                Kind::Other
            }
        };
        out.push(Token {
            kind,
            span: start..i,
        });
    }
    out
}

/// The end of the (nesting) block comment that starts at `i`.
fn block_comment_end(b: &[u8], mut i: usize) -> usize {
    let mut depth = 0usize;
    while i < b.len() {
        if b[i..].starts_with(b"/*") {
            depth += 1;
            i += 2;
        } else if b[i..].starts_with(b"*/") {
            depth -= 1;
            i += 2;
            if depth == 0 {
                return i;
            }
        } else {
            i += 1;
        }
    }
    b.len()
}

/// The end of the string literal that starts at `i` (after its closing quote).
fn string_end(b: &[u8], mut i: usize) -> usize {
    i += 1;
    while i < b.len() {
        match b[i] {
            b'\\' => i += 2,
            b'"' => return i + 1,
            _ => i += 1,
        }
    }
    b.len()
}

/// The end of the number literal that starts at `i`; `1..N` stops before the `..`.
fn number_end(b: &[u8], mut i: usize) -> usize {
    let digits = |i: &mut usize| {
        while *i < b.len() && b[*i].is_ascii_digit() {
            *i += 1;
        }
    };
    digits(&mut i);
    if b.get(i) == Some(&b'.') && b.get(i + 1) != Some(&b'.') {
        i += 1;
        digits(&mut i);
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let mut j = i + 1;
        if matches!(b.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        if b.get(j).is_some_and(u8::is_ascii_digit) {
            i = j;
            digits(&mut i);
        }
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texts(src: &str) -> Vec<&str> {
        tokens(src).into_iter().map(|t| &src[t.span]).collect()
    }

    #[test]
    fn splits_numbers_ranges_comments_and_strings() {
        let src =
            "for i in 1..N { x[i]' = 2.5e-3 * .5 } // c\n/* a /* b */ */ csv(\"a\\\"b\") <= y";
        assert_eq!(
            texts(src),
            [
                "for",
                "i",
                "in",
                "1",
                "..",
                "N",
                "{",
                "x",
                "[",
                "i",
                "]",
                "'",
                "=",
                "2.5e-3",
                "*",
                ".5",
                "}",
                "csv",
                "(",
                "\"a\\\"b\"",
                ")",
                "<=",
                "y"
            ]
        );
        assert_eq!(tokens("1e")[0].kind, Kind::Number);
        assert_eq!(texts("1e x θ"), ["1", "e", "x", "θ"]);
    }
}
