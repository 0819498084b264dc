//! The tokenizer: turns spec text into tokens on demand (nom 8 recognizers over `&str`).
//!
//! Whitespace and comments are skipped; `///` lines before the first token are collected as the
//! spec's documentation. Lexical errors (stray characters, bad numbers, unterminated strings or
//! comments) are recorded as diagnostics; a stray character becomes a [`Tok::Error`] token, which
//! the parser treats as "already reported".

use nom::{
    branch::alt,
    bytes::complete::{tag, take_while},
    character::complete::{char, digit1, one_of, satisfy},
    combinator::{opt, recognize},
    IResult, Parser,
};

use crate::diagnostics::{Diagnostic, Span};

/// Reserved words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kw {
    Model,
    Const,
    State,
    Input,
    Noise,
    Table,
    Let,
    For,
    In,
    Drift,
    Diffusion,
    Domain,
    Discrete,
    Update,
    Initial,
    Unsafe,
    Goal,
    Analysis,
}

impl Kw {
    fn from_str(s: &str) -> Option<Kw> {
        Some(match s {
            "model" => Kw::Model,
            "const" => Kw::Const,
            "state" => Kw::State,
            "input" => Kw::Input,
            "noise" => Kw::Noise,
            "table" => Kw::Table,
            "let" => Kw::Let,
            "for" => Kw::For,
            "in" => Kw::In,
            "drift" => Kw::Drift,
            "diffusion" => Kw::Diffusion,
            "domain" => Kw::Domain,
            "discrete" => Kw::Discrete,
            "update" => Kw::Update,
            "initial" => Kw::Initial,
            "unsafe" => Kw::Unsafe,
            "goal" => Kw::Goal,
            "analysis" => Kw::Analysis,
            _ => return None,
        })
    }

    /// True for keywords that start a top-level item.
    pub(crate) fn starts_item(self) -> bool {
        self != Kw::In
    }

    /// True for keywords that can only start a top-level item (not a statement in a block).
    pub(crate) fn top_level_only(self) -> bool {
        !matches!(self, Kw::In | Kw::Let | Kw::For)
    }
}

/// The kind of a token.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Tok {
    Ident,
    Kw(Kw),
    /// A number literal (finite; an overflowing literal is reported and becomes `f64::MAX`).
    Num(f64),
    /// A string literal, escapes resolved.
    Str(String),
    LParen,
    RParen,
    LBracket,
    RBracket,
    LBrace,
    RBrace,
    Comma,
    Semi,
    Colon,
    Prime,
    Eq,
    Plus,
    Minus,
    Star,
    Slash,
    Caret,
    Dot,
    DotDot,
    Le,
    Ge,
    /// Stray characters (already reported by the lexer).
    Error,
    /// End of input (its span is `len..len`).
    Eof,
}

/// A token with its byte span.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Token {
    pub kind: Tok,
    pub span: Span,
    /// True if a newline (or the start of the file) precedes the token.
    pub line_start: bool,
}

/// An on-demand tokenizer.
pub(crate) struct Lexer<'s> {
    src: &'s str,
    pos: usize,
    seen_token: bool,
    /// Lexical errors found so far.
    pub diags: Vec<Diagnostic>,
    /// `///` lines before the first token (prefix and one following space stripped).
    pub docs: Vec<String>,
}

type Res<'a> = IResult<&'a str, &'a str>;

fn is_ident_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_'
}

fn is_ident_continue(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// `[A-Za-z_][A-Za-z0-9_]*`
fn ident(i: &str) -> Res<'_> {
    recognize((satisfy(is_ident_start), take_while(is_ident_continue))).parse(i)
}

/// `digits [. [digits]] [exp]` or `. digits [exp]`; a `.` followed by another `.` is left alone
/// so that `1..N` is `1`, `..`, `N`.
fn number(i: &str) -> Res<'_> {
    let (rest, mantissa) = alt((
        recognize((digit1, opt((char('.'), digit1)))),
        recognize((char('.'), digit1)),
    ))
    .parse(i)?;
    // A trailing dot (`5.`) belongs to the number unless it starts `..`.
    let rest = match rest.strip_prefix('.') {
        Some(after) if !mantissa.contains('.') && !after.starts_with('.') => after,
        _ => rest,
    };
    let (rest, _) = opt((one_of("eE"), opt(one_of("+-")), digit1)).parse(rest)?;
    Ok((rest, &i[..i.len() - rest.len()]))
}

/// Operators and punctuation (longest first).
fn punct(i: &str) -> IResult<&str, Tok> {
    alt((
        tag("..").map(|_| Tok::DotDot),
        tag("<=").map(|_| Tok::Le),
        tag(">=").map(|_| Tok::Ge),
        one_of("()[]{},;:'=+-*/^.").map(|c| match c {
            '(' => Tok::LParen,
            ')' => Tok::RParen,
            '[' => Tok::LBracket,
            ']' => Tok::RBracket,
            '{' => Tok::LBrace,
            '}' => Tok::RBrace,
            ',' => Tok::Comma,
            ';' => Tok::Semi,
            ':' => Tok::Colon,
            '\'' => Tok::Prime,
            '=' => Tok::Eq,
            '+' => Tok::Plus,
            '-' => Tok::Minus,
            '*' => Tok::Star,
            '/' => Tok::Slash,
            '^' => Tok::Caret,
            _ => Tok::Dot,
        }),
    ))
    .parse(i)
}

/// True if `c` can start some token (or whitespace / comment).
fn starts_something(c: char, next: Option<char>) -> bool {
    match c {
        '<' | '>' => next == Some('='),
        c if c.is_ascii_whitespace() => true,
        c => is_ident_start(c) || c.is_ascii_digit() || "()[]{},;:'=+-*/^.\"".contains(c),
    }
}

/// Length in bytes of the run of characters at the start of `rest` that cannot start anything;
/// with `first`, the first character is taken as such whatever it is.
fn bad_run(rest: &str, first: bool) -> usize {
    let mut end = 0;
    let mut chars = rest.char_indices().peekable();
    while let Some((i, ch)) = chars.next() {
        let next = chars.peek().map(|&(_, n)| n);
        if (i > 0 || !first) && starts_something(ch, next) {
            break;
        }
        end = i + ch.len_utf8();
    }
    end
}

impl<'s> Lexer<'s> {
    /// A lexer over the whole of `src`.
    pub(crate) fn new(src: &'s str) -> Self {
        Lexer {
            src,
            // A leading byte-order mark is not part of the spec.
            pos: if src.starts_with('\u{feff}') { 3 } else { 0 },
            seen_token: false,
            diags: Vec::new(),
            docs: Vec::new(),
        }
    }

    /// Records a lexical error (dropped once the parser has given up, see
    /// [`super::parser::MAX_DIAGNOSTICS`]).
    fn report(&mut self, d: Diagnostic) {
        if self.diags.len() < super::parser::MAX_DIAGNOSTICS {
            self.diags.push(d);
        }
    }

    /// Byte offset of the next unread character.
    pub(crate) fn pos(&self) -> usize {
        self.pos
    }

    fn rest(&self) -> &'s str {
        &self.src[self.pos..]
    }

    /// Byte offset of `rest` (a suffix of the source) in the source.
    fn offset(&self, rest: &str) -> usize {
        self.src.len() - rest.len()
    }

    /// Skips whitespace and comments; returns true if a newline was crossed.
    fn skip_trivia(&mut self) -> bool {
        let mut newline = false;
        loop {
            let rest = self.rest();
            let ws = rest.len()
                - rest
                    .trim_start_matches(|c: char| c.is_ascii_whitespace())
                    .len();
            if ws > 0 {
                newline |= rest[..ws].contains('\n');
                self.pos += ws;
                continue;
            }
            if rest.starts_with("//") {
                let end = rest.find('\n').unwrap_or(rest.len());
                let line = &rest[..end];
                if !self.seen_token && line.starts_with("///") && !line.starts_with("////") {
                    let text = &line[3..];
                    let text = text.strip_prefix(' ').unwrap_or(text);
                    self.docs.push(text.trim_end_matches('\r').to_string());
                }
                self.pos += end;
                continue;
            }
            if rest.starts_with("/*") {
                newline |= self.skip_block_comment();
                continue;
            }
            return newline;
        }
    }

    /// Skips a (nesting) block comment starting at `pos`; returns true if it contains a newline.
    fn skip_block_comment(&mut self) -> bool {
        let start = self.pos;
        let bytes = self.src.as_bytes();
        let mut i = self.pos + 2;
        let mut depth = 1usize;
        while i < bytes.len() && depth > 0 {
            if bytes[i] == b'/' && bytes.get(i + 1) == Some(&b'*') {
                depth += 1;
                i += 2;
            } else if bytes[i] == b'*' && bytes.get(i + 1) == Some(&b'/') {
                depth -= 1;
                i += 2;
            } else {
                i += 1;
            }
        }
        // `i` only ever stops after ASCII bytes or at the end, so it is a char boundary.
        self.pos = i.min(bytes.len());
        if depth > 0 {
            self.report(
                Diagnostic::error(
                    "unterminated block comment",
                    start..start + 2,
                    "comment starts here",
                )
                .with_help("close it with `*/` (block comments nest)"),
            );
        }
        self.src[start..self.pos].contains('\n')
    }

    /// The next token (after the end, `Eof` forever).
    pub(crate) fn next_token(&mut self) -> Token {
        let line_start = self.skip_trivia() || !self.seen_token;
        self.seen_token = true;
        let start = self.pos;
        let rest = self.rest();
        let (kind, end) = self.token_kind(rest, start);
        self.pos = end;
        Token {
            kind,
            span: start..end,
            line_start,
        }
    }

    fn token_kind(&mut self, rest: &'s str, start: usize) -> (Tok, usize) {
        let Some(c) = rest.chars().next() else {
            return (Tok::Eof, start);
        };
        if let Ok((after, word)) = ident(rest) {
            let end = self.offset(after);
            let glued = self.glued_name_end(end);
            return match Kw::from_str(word) {
                Some(kw) if glued == end => (Tok::Kw(kw), end),
                _ => (Tok::Ident, glued),
            };
        }
        if let Ok((after, text)) = number(rest) {
            return self.number_token(after, text, start);
        }
        if c == '"' {
            return self.string_token(rest, start);
        }
        if let Ok((after, tok)) = punct(rest) {
            return (tok, self.offset(after));
        }
        let end = start + bad_run(rest, true);
        self.bad_characters(c, start, end);
        (Tok::Error, end)
    }

    /// Where a name ending at `end` really ends: a name glued to characters that cannot start
    /// anything and then to more name (`r#x`, `a$b`) is one name with those characters
    /// reported, so the parser does not trip over its tail with a second, confusing error.
    fn glued_name_end(&mut self, mut end: usize) -> usize {
        loop {
            let rest = &self.src[end..];
            let bad = bad_run(rest, false);
            let Some(c) = rest.chars().next().filter(|_| bad > 0) else {
                return end;
            };
            let Ok((after, _)) = ident(&rest[bad..]) else {
                return end;
            };
            self.bad_characters(c, end, end + bad);
            end = self.offset(after);
        }
    }

    /// Reports the characters `start..end`, which cannot start anything; `c` is the first.
    fn bad_characters(&mut self, c: char, start: usize, end: usize) {
        let text = &self.src[start..end];
        let plural = if text.chars().count() > 1 { "s" } else { "" };
        let mut d = Diagnostic::error(
            format!("unexpected character{plural} `{}`", clip(text)),
            start..end,
            "not valid in a spec",
        );
        if c == '<' || c == '>' {
            d = d.with_help("only the comparisons `<=` and `>=` are supported");
        } else if !c.is_ascii() {
            d = d.with_help("names are ASCII: letters, digits and `_`");
        }
        self.report(d);
    }

    fn number_token(&mut self, after: &'s str, text: &str, start: usize) -> (Tok, usize) {
        let mut end = self.offset(after);
        // A number glued to a name (`2x`, `1e`) is one bad literal.
        let glued = after.len() - after.trim_start_matches(is_ident_continue).len();
        if glued > 0 {
            end += glued;
            self.report(
                Diagnostic::error(
                    format!("invalid number literal `{}`", clip(&self.src[start..end])),
                    start..end,
                    "not a number",
                )
                .with_help(
                    "a number looks like `2`, `0.5` or `2.5e-3`; write a product as `2 * x`",
                ),
            );
        }
        // The recognizer only accepts forms that Rust's float parser accepts.
        let value = text.parse::<f64>().unwrap_or(0.0);
        if value.is_infinite() {
            self.report(
                Diagnostic::error(
                    "number literal too large",
                    start..end,
                    "overflows a 64-bit float",
                )
                .with_help("the largest number is about 1.8e308"),
            );
            return (Tok::Num(f64::MAX), end);
        }
        (Tok::Num(value), end)
    }

    /// A string literal; an unterminated one is reported and becomes [`Tok::Error`].
    fn string_token(&mut self, rest: &'s str, start: usize) -> (Tok, usize) {
        let mut value = String::new();
        let mut chars = rest.char_indices().skip(1);
        while let Some((i, ch)) = chars.next() {
            match ch {
                '"' => return (Tok::Str(value), start + i + 1),
                '\n' => break,
                '\\' => match chars.next() {
                    Some((_, c @ ('"' | '\\'))) => value.push(c),
                    Some((j, c)) if c != '\n' => {
                        let at = start + j - 1..start + j + c.len_utf8();
                        self.report(
                            Diagnostic::error(
                                format!("unknown escape `\\{c}` in string"),
                                at,
                                "unknown escape",
                            )
                            .with_help("only `\\\"` and `\\\\` are escapes"),
                        );
                        value.push(c);
                    }
                    _ => break,
                },
                c => value.push(c),
            }
        }
        let end = start + rest.find('\n').unwrap_or(rest.len());
        let end = end.max(start + 1);
        self.report(
            Diagnostic::error(
                "unterminated string literal",
                start..end,
                "string starts here",
            )
            .with_help("close the string with `\"` on the same line"),
        );
        (Tok::Error, end)
    }
}

/// Shortens `text` for a message (at a char boundary).
pub(crate) fn clip(text: &str) -> String {
    const MAX: usize = 32;
    match text.char_indices().nth(MAX) {
        Some((i, _)) => format!("{}...", &text[..i]),
        None => text.to_string(),
    }
}
