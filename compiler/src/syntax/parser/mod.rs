//! Recursive-descent parser over the token stream of [`super::lexer`].
//!
//! Errors are pushed to a list as they are found and the parser recovers: inside a block it skips
//! to the next statement (a token at the start of a line, or a `;`, at the block's brace depth), and at top level it skips to the next item keyword at brace depth 0. Nesting depth and
//! expression height are bounded so that neither the parser nor later recursive passes (or
//! `Drop`) can overflow the stack.
//!
//! The parser's state, its token plumbing and error recovery are here; the grammar is in
//! `items.rs` (the spec and its top-level items), `statements.rs` (blocks and statements) and
//! `expressions.rs` (expressions, by precedence); `tests.rs` holds the unit tests.

use super::ast::*;
use super::lexer::{clip, Lexer, Tok, Token};
use crate::diagnostics::{Diagnostic, Span};

pub use crate::limits::{MAX_DEPTH, MAX_HEIGHT, MAX_SOURCE_LEN};

/// After this many diagnostics the parser stops (and says so).
pub const MAX_DIAGNOSTICS: usize = 500;

/// Marker: a diagnostic has already been recorded; the caller should recover.
#[derive(Debug)]
struct Fail;

type P<T> = Result<T, Fail>;

/// An expression with the height of its tree.
type HExpr = (Expr, usize);

mod expressions;
mod items;
mod statements;

use statements::Ctx;

/// The error for a spec of more than [`MAX_SOURCE_LEN`] bytes (at `0..0`: the file is not kept).
pub(crate) fn too_large() -> Diagnostic {
    Diagnostic::error(
        format!("spec file too large: more than {MAX_SOURCE_LEN} bytes (8 MiB)"),
        0..0,
        "file rejected",
    )
    .with_help("a spec this large is generated: use families and `for` loops instead")
}

/// Parses `src`; see [`super::parse`].
pub(crate) fn parse_spec(src: &str) -> (Spec, Vec<Diagnostic>) {
    if src.len() > MAX_SOURCE_LEN {
        let spec = Spec {
            doc: None,
            model: None,
            items: Vec::new(),
        };
        return (spec, vec![too_large()]);
    }
    let mut p = Parser::new(src);
    let spec = p.spec();
    let mut diags = std::mem::take(&mut p.lexer.diags);
    diags.append(&mut p.diags);
    diags.sort_by_key(|d| d.span().start);
    (spec, diags)
}

struct Parser<'s> {
    src: &'s str,
    lexer: Lexer<'s>,
    tok: Token,
    peeked: Option<Token>,
    /// End of the last consumed token.
    prev_end: usize,
    depth: usize,
    diags: Vec<Diagnostic>,
    /// Only one "found end of file" error is reported.
    eof_reported: bool,
    /// Set when too many errors were found: the token stream was cut short here.
    stopped_at: Option<usize>,
}

impl<'s> Parser<'s> {
    fn new(src: &'s str) -> Self {
        let mut lexer = Lexer::new(src);
        let tok = lexer.next_token();
        Parser {
            src,
            lexer,
            tok,
            peeked: None,
            prev_end: 0,
            depth: 0,
            diags: Vec::new(),
            eof_reported: false,
            stopped_at: None,
        }
    }

    // ---- token plumbing -------------------------------------------------------------------

    fn advance(&mut self) -> Token {
        let next = match self.peeked.take() {
            Some(t) => t,
            None => self.lex(),
        };
        let tok = std::mem::replace(&mut self.tok, next);
        if tok.kind != Tok::Eof {
            self.prev_end = tok.span.end;
        }
        tok
    }

    /// The next token from the lexer, or the end once too many errors were reported.
    fn lex(&mut self) -> Token {
        if self.stopped_at.is_none() && self.diags.len() + self.lexer.diags.len() < MAX_DIAGNOSTICS
        {
            return self.lexer.next_token();
        }
        if self.stopped_at.is_none() {
            self.stopped_at = Some(self.lexer.pos());
            // The cut is not a real end of file: no "found end of file" errors.
            self.eof_reported = true;
        }
        let end = self.src.len();
        Token {
            kind: Tok::Eof,
            span: end..end,
            line_start: true,
        }
    }

    fn peek(&mut self) -> &Tok {
        if self.peeked.is_none() {
            self.peeked = Some(self.lex());
        }
        &self.peeked.as_ref().expect("just filled").kind
    }

    fn at(&self, kind: &Tok) -> bool {
        &self.tok.kind == kind
    }

    fn eat(&mut self, kind: &Tok) -> bool {
        if self.at(kind) {
            self.advance();
            true
        } else {
            false
        }
    }

    fn text(&self, span: &Span) -> &'s str {
        &self.src[span.clone()]
    }

    /// How the current token is shown in "found ..." messages.
    fn found(&self) -> String {
        match &self.tok.kind {
            Tok::Eof => "end of file".to_string(),
            Tok::Kw(_) => format!("keyword `{}`", self.text(&self.tok.span)),
            Tok::Str(_) => format!("string `{}`", clip(self.text(&self.tok.span))),
            _ => format!("`{}`", clip(self.text(&self.tok.span))),
        }
    }

    /// Records `d` unless the current token already carries an error (a stray character, or a
    /// second end-of-file error). Always returns `Fail`.
    fn report_at_tok(&mut self, d: Diagnostic) -> Fail {
        match self.tok.kind {
            Tok::Error => {}
            Tok::Eof if self.eof_reported => {}
            Tok::Eof => {
                self.eof_reported = true;
                self.diags.push(d);
            }
            _ => self.diags.push(d),
        }
        Fail
    }

    /// "expected WHAT, found TOKEN" at the current token.
    #[cold]
    #[inline(never)]
    fn expected(&mut self, what: &str, help: Option<&str>) -> Fail {
        let label = if self.at(&Tok::Eof) {
            format!("expected {what}")
        } else {
            format!("expected {what} here")
        };
        let mut d = Diagnostic::error(
            format!("expected {what}, found {}", self.found()),
            self.tok.span.clone(),
            label,
        );
        if let Some(h) = help {
            d = d.with_help(h);
        }
        self.report_at_tok(d)
    }

    fn expect(&mut self, kind: &Tok, what: &str, help: Option<&str>) -> P<Span> {
        if self.at(kind) {
            Ok(self.advance().span)
        } else {
            Err(self.expected(what, help))
        }
    }

    /// Expects a closing delimiter, pointing back at its opener.
    #[cold]
    #[inline(never)]
    fn expect_close_failed(&mut self, what: &str, open: Span) -> Fail {
        let d = Diagnostic::error(
            format!("expected {what}, found {}", self.found()),
            self.tok.span.clone(),
            format!("expected {what}"),
        )
        .with_label(open, "opened here");
        self.report_at_tok(d)
    }

    fn expect_close(&mut self, kind: &Tok, what: &str, open: Span) -> P<()> {
        if self.eat(kind) {
            return Ok(());
        }
        Err(self.expect_close_failed(what, open))
    }

    fn ident(&mut self, what: &str, help: Option<&str>) -> P<Ident> {
        if self.at(&Tok::Ident) {
            let span = self.advance().span;
            Ok(Ident {
                name: self.text(&span).to_string(),
                span,
            })
        } else if matches!(self.tok.kind, Tok::Kw(_)) {
            let kw = self.text(&self.tok.span);
            let mut d = Diagnostic::error(
                format!("expected {what}, found keyword `{kw}`"),
                self.tok.span.clone(),
                "a reserved keyword",
            )
            .with_note(format!(
                "`{kw}` is a reserved keyword and cannot be used as a name"
            ));
            if let Some(h) = help {
                d = d.with_help(h);
            }
            Err(self.report_at_tok(d))
        } else {
            Err(self.expected(what, help))
        }
    }

    fn enter(&mut self, what: &str) -> P<()> {
        if self.depth >= MAX_DEPTH {
            return Err(self.too_deep(what));
        }
        self.depth += 1;
        Ok(())
    }

    #[cold]
    #[inline(never)]
    fn too_deep(&mut self, what: &str) -> Fail {
        {
            let d = Diagnostic::error(
                format!("{what} nested too deeply"),
                self.tok.span.clone(),
                format!("more than {MAX_DEPTH} levels of nesting"),
            )
            .with_help("simplify it, or split it with `let` definitions");
            self.report_at_tok(d)
        }
    }

    fn leave(&mut self) {
        self.depth -= 1;
    }

    /// Runs `f` one nesting level deeper.
    fn nested<T>(&mut self, what: &str, f: impl FnOnce(&mut Self) -> P<T>) -> P<T> {
        self.enter(what)?;
        let r = f(self);
        self.leave();
        r
    }

    // ---- recovery -----------------------------------------------------------------------

    /// Skips to the next item keyword at brace depth 0 (always moving at least one token
    /// unless already at such a keyword or the end).
    fn recover_item(&mut self) {
        let mut depth = 0usize;
        let mut first = true;
        loop {
            match &self.tok.kind {
                Tok::Eof => return,
                Tok::Kw(k) if depth == 0 && k.starts_item() && !first => return,
                Tok::Kw(k) if depth == 0 && k.top_level_only() => return,
                Tok::LBrace => depth += 1,
                Tok::RBrace => depth = depth.saturating_sub(1),
                _ => {}
            }
            first = false;
            self.advance();
        }
    }

    /// Skips to the start of the next statement in the current block: a token at the start of a
    /// line, or a `;`, at the block's brace depth (not `,`, which is common inside lists); stops
    /// before the block's `}` and before top-level item keywords.
    fn recover_stmt(&mut self) {
        let mut depth = 0usize;
        let mut first = true;
        loop {
            match &self.tok.kind {
                Tok::Eof => return,
                Tok::RBrace if depth == 0 => return,
                Tok::Kw(k) if depth == 0 && k.top_level_only() => return,
                Tok::Semi if depth == 0 => return,
                _ if depth == 0 && !first && self.tok.line_start => return,
                Tok::LBrace => depth += 1,
                Tok::RBrace => depth -= 1,
                _ => {}
            }
            first = false;
            self.advance();
        }
    }
}

#[cfg(test)]
mod tests;
