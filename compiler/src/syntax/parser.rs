//! Recursive-descent parser over the token stream of [`super::lexer`].
//!
//! Errors are pushed to a list as they are found and the parser recovers: inside a block it skips
//! to the next statement (a token at the start of a line, or a `;`, at the block's brace depth), and at top level it skips to the next item keyword at brace depth 0. Nesting depth and
//! expression height are bounded so that neither the parser nor later recursive passes (or
//! `Drop`) can overflow the stack.

use super::ast::*;
use super::lexer::{clip, Kw, Lexer, Tok, Token};
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

/// What a block may contain; drives the statement parser's expectations and messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ctx {
    /// A top-level `for`: lets and nested fors.
    TopFor,
    Drift,
    Diffusion,
    Domain,
    /// `key = value` fields (analysis, initial ball, unsafe ball).
    Fields,
    /// Unsafe box: memberships.
    Box,
    /// Unsafe halfspace: one constraint.
    Halfspace,
    /// Unknown unsafe kind (already reported): accept anything.
    Any,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Equation,
    Row,
    Member,
    Field,
    Constraint,
    Let,
    For,
}

impl Ctx {
    fn allows(self, k: Kind) -> bool {
        use Kind::*;
        match self {
            Ctx::TopFor => matches!(k, Let | For),
            Ctx::Drift => matches!(k, Equation | Let | For),
            Ctx::Diffusion => matches!(k, Row | Let | For),
            Ctx::Domain => matches!(k, Member | For),
            Ctx::Fields => k == Field,
            Ctx::Box => k == Member,
            Ctx::Halfspace => k == Constraint,
            Ctx::Any => true,
        }
    }

    /// The block's name in messages.
    fn name(self) -> &'static str {
        match self {
            Ctx::TopFor => "a top-level `for`",
            Ctx::Drift => "a `drift` block",
            Ctx::Diffusion => "a `diffusion` block",
            Ctx::Domain => "a `domain` block",
            Ctx::Fields => "this block",
            Ctx::Box => "an unsafe `box`",
            Ctx::Halfspace => "an unsafe `halfspace`",
            Ctx::Any => "this block",
        }
    }

    /// What a statement in this block looks like.
    fn expected_stmt(self) -> &'static str {
        match self {
            Ctx::TopFor => "`let` or `for`",
            Ctx::Drift => "an equation `x' = ...`, `let` or `for`",
            Ctx::Diffusion => "a row `x: ...`, `let` or `for`",
            Ctx::Domain => "a bound `x in [lo, hi]` or `for`",
            Ctx::Fields => "a field `key = value`",
            Ctx::Box => "a bound `x in [lo, hi]`",
            Ctx::Halfspace => "a constraint `... <= ...` or `... >= ...`",
            Ctx::Any => "a statement",
        }
    }

    /// What follows the name at the start of a statement.
    fn after_name(self) -> &'static str {
        match self {
            Ctx::Drift => "`'`",
            Ctx::Diffusion => "`:`",
            Ctx::Domain | Ctx::Box => "`in`",
            Ctx::Fields => "`=`",
            Ctx::Halfspace => "`<=` or `>=`",
            Ctx::TopFor | Ctx::Any => "`'`, `:`, `in` or `=`",
        }
    }

    fn help(self) -> &'static str {
        match self {
            Ctx::TopFor => {
                "a top-level loop may only contain `let` definitions; equations go inside \
                 `drift { ... }`"
            }
            Ctx::Drift => "a drift equation looks like `x' = -x`",
            Ctx::Diffusion => "a diffusion row looks like `x: 0.1 * w`",
            Ctx::Domain => "a domain bound looks like `x in [-1, 1]`",
            Ctx::Fields => "a field looks like `key = value`",
            Ctx::Box => "a box bound looks like `x in [1, 2]`",
            Ctx::Halfspace => "a half-space looks like `x + 2 * y >= 3`",
            Ctx::Any => {
                "a statement looks like `x' = ...`, `x: ...`, `x in [lo, hi]` or `key = value`"
            }
        }
    }
}

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

    // ---- items --------------------------------------------------------------------------

    fn spec(&mut self) -> Spec {
        let first_span = self.tok.span.clone();
        let mut model: Option<Ident> = None;
        let mut saw_model = false;
        let mut items = Vec::new();
        loop {
            match self.tok.kind.clone() {
                Tok::Eof => break,
                Tok::Comma | Tok::Semi => {
                    self.advance();
                }
                Tok::Kw(Kw::Model) => {
                    let kw = self.advance().span;
                    let first_model = !saw_model;
                    saw_model = true;
                    match self.ident("a model name after `model`", Some("write `model NAME`")) {
                        Ok(name) => {
                            if let Some(prev) = &model {
                                self.diags.push(
                                    Diagnostic::error(
                                        "`model` appears twice",
                                        kw.start..name.span.end,
                                        "second `model`",
                                    )
                                    .with_label(prev.span.clone(), "first named here")
                                    .with_help("a spec describes one model; remove one of them"),
                                );
                            } else {
                                if first_model && !items.is_empty() {
                                    self.diags.push(
                                        Diagnostic::error(
                                            "`model NAME` must come first",
                                            kw.start..name.span.end,
                                            "after other items",
                                        )
                                        .with_help("move `model NAME` to the top of the spec"),
                                    );
                                }
                                model = Some(name);
                            }
                        }
                        Err(Fail) => self.recover_item(),
                    }
                }
                Tok::Kw(k) if k.starts_item() => match self.item(k) {
                    Ok(item) => items.push(item),
                    Err(Fail) => self.recover_item(),
                },
                Tok::Error => {
                    self.advance();
                }
                _ => {
                    let mut help = "items start with a keyword: `model`, `const`, `state`, `input`, \
                                    `noise`, `table`, `let`, `for`, `drift`, `diffusion`, `domain`, \
                                    `initial`, `unsafe`, `goal` or `analysis`";
                    if self.at(&Tok::Ident)
                        && matches!(self.peek(), Tok::Prime | Tok::Colon | Tok::Kw(Kw::In))
                    {
                        help = "equations, rows and bounds go inside `drift { ... }`, \
                                `diffusion { ... }` or `domain { ... }`";
                    }
                    let _ = self.expected("an item", Some(help));
                    self.recover_item();
                }
            }
        }
        if let Some(at) = self.stopped_at {
            self.diags.push(
                Diagnostic::error(
                    format!("too many syntax errors; stopped after {MAX_DIAGNOSTICS}"),
                    at..at,
                    "stopped here",
                )
                .with_help("fix the first errors and run again"),
            );
        }
        if !saw_model {
            let span = if self.src.trim().is_empty() {
                0..0
            } else {
                first_span
            };
            self.diags.push(
                Diagnostic::error("missing `model NAME`", span, "expected `model NAME` first")
                    .with_help("start the spec with `model NAME`"),
            );
        }
        let doc = if self.lexer.docs.is_empty() {
            None
        } else {
            Some(self.lexer.docs.join("\n"))
        };
        Spec { doc, model, items }
    }

    fn item(&mut self, kw: Kw) -> P<Item> {
        let start = self.tok.span.start;
        let item = match kw {
            Kw::Const => {
                self.advance();
                let help = Some("a constant looks like `const g = 9.81`");
                let name = self.ident("a constant name after `const`", help)?;
                self.expect(&Tok::Eq, "`=` after constant name", help)?;
                let value = self.expr()?;
                Item::Const {
                    name,
                    value,
                    span: start..self.prev_end,
                }
            }
            Kw::State => Item::State(self.var_decl(kw)?),
            Kw::Input => Item::Input(self.var_decl(kw)?),
            Kw::Noise => Item::Noise(self.var_decl(kw)?),
            Kw::Table => self.table()?,
            Kw::Let => Item::Stmt(self.let_stmt()?),
            Kw::For => Item::Stmt(self.for_stmt(Ctx::TopFor)?),
            Kw::Drift => {
                self.advance();
                Item::Drift(self.block(Ctx::Drift, "`drift`")?)
            }
            Kw::Diffusion => {
                self.advance();
                Item::Diffusion(self.block(Ctx::Diffusion, "`diffusion`")?)
            }
            Kw::Domain => {
                self.advance();
                Item::Domain(self.block(Ctx::Domain, "`domain`")?)
            }
            Kw::Initial => {
                self.advance();
                let help = "an initial set looks like \
                            `initial ball { over = [x, y] center = [0, 0] radius = 0.5 }`";
                let kind = self.ident("a set kind (`ball`) after `initial`", Some(help))?;
                if kind.name != "ball" {
                    self.diags.push(
                        Diagnostic::error(
                            format!("unknown initial set kind `{}`", kind.name),
                            kind.span.clone(),
                            "unknown kind",
                        )
                        .with_help("the initial set kind is `ball` (box components are given by `state x in [lo, hi]`)"),
                    );
                }
                let body = self.block(Ctx::Fields, "`initial ball`")?;
                Item::Initial {
                    kind,
                    body,
                    span: start..self.prev_end,
                }
            }
            Kw::Unsafe => self.unsafe_item()?,
            Kw::Goal => self.goal_item()?,
            Kw::Analysis => {
                self.advance();
                let help = "an analysis looks like `analysis main { horizon = 4 }`";
                let name = self.ident("an analysis name after `analysis`", Some(help))?;
                let body = self.block(Ctx::Fields, "`analysis`")?;
                Item::Analysis {
                    name,
                    body,
                    span: start..self.prev_end,
                }
            }
            Kw::Model | Kw::In => return Err(self.expected("an item", None)),
        };
        Ok(item)
    }

    /// `state|input|noise NAME [ [LO..HI] ] [in EXPR | = EXPR]`
    fn var_decl(&mut self, kw: Kw) -> P<VarDecl> {
        let start = self.advance().span.start;
        let (what, help) = match kw {
            Kw::State => (
                "state",
                "a state looks like `state x in [-1, 1]`, `state x = 0` or `state x`",
            ),
            Kw::Input => ("input", "an input needs bounds: `input u in [-1, 1]`"),
            _ => ("noise", "a noise looks like `noise w` or `noise w[1..3]`"),
        };
        let name = self.ident(&format!("a name after `{what}`"), Some(help))?;
        let family = if self.at(&Tok::LBracket) {
            let open = self.advance().span;
            let range = self.nested("expression", |p| p.range("a family looks like `x[1..N]`"))?;
            self.expect_close(&Tok::RBracket, "`]`", open)?;
            Some(range)
        } else {
            None
        };
        let init = match (&self.tok.kind, kw) {
            (Tok::Kw(Kw::In), Kw::State | Kw::Input) => {
                self.advance();
                Some(Init::In(self.expr()?))
            }
            (Tok::Eq, Kw::State) => {
                self.advance();
                Some(Init::Point(self.expr()?))
            }
            (_, Kw::Input) => {
                return Err(self.expected("`in` after input name", Some(help)));
            }
            (Tok::Kw(Kw::In) | Tok::Eq, _) => {
                let d = Diagnostic::error(
                    format!("unexpected {} after noise name", self.found()),
                    self.tok.span.clone(),
                    "a noise has no initial value",
                )
                .with_help("a noise is a Wiener process: write `noise w`");
                return Err(self.report_at_tok(d));
            }
            (t, Kw::State) if !self.ends_item(t) => {
                return Err(self.expected("`=` or `in` after state name", Some(help)));
            }
            _ => None,
        };
        Ok(VarDecl {
            name,
            family,
            init,
            span: start..self.prev_end,
        })
    }

    /// True if `t` can follow a complete item.
    fn ends_item(&self, t: &Tok) -> bool {
        match t {
            Tok::Eof | Tok::Comma | Tok::Semi | Tok::Error => true,
            Tok::Kw(k) => k.starts_item(),
            _ => false,
        }
    }

    /// `table NAME = csv("path")`
    fn table(&mut self) -> P<Item> {
        let start = self.advance().span.start;
        let help = Some("a table looks like `table ref = csv(\"ref.csv\")`");
        let name = self.ident("a table name after `table`", help)?;
        self.expect(&Tok::Eq, "`=` after table name", help)?;
        if !(self.at(&Tok::Ident) && self.text(&self.tok.span) == "csv") {
            return Err(self.expected("`csv(\"...\")`", help));
        }
        self.advance();
        let open = self.expect(&Tok::LParen, "`(` after `csv`", help)?;
        let (path, path_span) = match &self.tok.kind {
            Tok::Str(s) => (s.clone(), self.tok.span.clone()),
            _ => return Err(self.expected("a path string", help)),
        };
        self.advance();
        self.expect_close(&Tok::RParen, "`)`", open)?;
        Ok(Item::Table {
            name,
            path,
            path_span,
            span: start..self.prev_end,
        })
    }

    /// `unsafe NAME KIND { ... }`
    fn unsafe_item(&mut self) -> P<Item> {
        let start = self.advance().span.start;
        let help = "an unsafe set looks like `unsafe wall halfspace { x + y >= 3 }`";
        let name = self.ident("a set name after `unsafe`", Some(help))?;
        let (kind, body) = self.set_part("unsafe", help)?;
        Ok(Item::Unsafe {
            name,
            kind,
            body,
            span: start..self.prev_end,
        })
    }

    /// `goal NAME KIND { ... } [and KIND { ... }]... [within [T1, T2]] [stay]`
    fn goal_item(&mut self) -> P<Item> {
        let start = self.advance().span.start;
        let help = "a goal looks like `goal dock box { x in [0.9, 1.1] } within [2, 4]`";
        let name = self.ident("a goal name after `goal`", Some(help))?;
        let mut parts = vec![self.set_part("goal", help)?];
        while self.at_word("and") {
            self.advance();
            parts.push(self.set_part("goal", help)?);
        }
        let window = if self.at_word("within") {
            self.advance();
            Some(self.expr()?)
        } else {
            None
        };
        let stay = self.at_word("stay").then(|| self.advance().span);
        if self.at(&Tok::Ident) && !self.tok.line_start {
            let expected = match (&window, &stay) {
                (_, Some(_)) => "a new item after `stay`",
                (Some(_), None) => "`stay` or a new item",
                (None, None) => "`and`, `within`, `stay` or a new item",
            };
            return Err(self.report_at_tok(
                Diagnostic::error(
                    format!("expected {expected}, found {}", self.found()),
                    self.tok.span.clone(),
                    "unexpected here",
                )
                .with_help(
                    "after a goal's set come `and KIND { ... }` (an intersection), `within [T1, \
                     T2]` and `stay`, in that order",
                ),
            ));
        }
        Ok(Item::Goal {
            name,
            parts,
            window,
            stay,
            span: start..self.prev_end,
        })
    }

    /// Whether the current token is the identifier `word` (`and`, `within`, `stay`: words of
    /// a goal, not reserved).
    fn at_word(&self, word: &str) -> bool {
        self.at(&Tok::Ident) && self.text(&self.tok.span) == word
    }

    /// `KIND { ... }` of an unsafe set or a goal (`owner`): `box` (memberships), `ball`
    /// (fields) or `halfspace` (one constraint).
    fn set_part(&mut self, owner: &str, help: &str) -> P<(Ident, Block)> {
        let kind = self.ident(
            &format!("a set kind (`box`, `ball` or `halfspace`) after the {owner} set name"),
            Some(help),
        )?;
        let ctx = match kind.name.as_str() {
            "box" => Ctx::Box,
            "ball" => Ctx::Fields,
            "halfspace" => Ctx::Halfspace,
            other => {
                self.diags.push(
                    Diagnostic::error(
                        format!("unknown {owner} set kind `{other}`"),
                        kind.span.clone(),
                        "unknown kind",
                    )
                    .with_help("the kinds are `box`, `ball` and `halfspace`"),
                );
                Ctx::Any
            }
        };
        let errors_before = self.diags.len() + self.lexer.diags.len();
        let body = self.block(ctx, &format!("the {owner} set"))?;
        let clean = errors_before == self.diags.len() + self.lexer.diags.len();
        if ctx == Ctx::Halfspace && clean && body.stmts.len() != 1 {
            let a = if owner == "unsafe" { "an" } else { "a" };
            let msg = if body.stmts.is_empty() {
                format!("{a} {owner} `halfspace` needs a constraint")
            } else {
                format!("{a} {owner} `halfspace` has exactly one constraint")
            };
            self.diags.push(
                Diagnostic::error(msg, body.span.clone(), "in this block").with_help(format!(
                    "write one `{owner} NAME halfspace {{ ... }}` per half-space"
                )),
            );
        }
        Ok((kind, body))
    }

    // ---- blocks and statements ----------------------------------------------------------

    /// `{ STMTS }`; an unclosed block is reported and returned as far as it goes.
    fn block(&mut self, ctx: Ctx, owner: &str) -> P<Block> {
        let help = format!("{owner} is followed by a block `{{ ... }}`");
        let open = self.expect(&Tok::LBrace, &format!("`{{` after {owner}"), Some(&help))?;
        if self.depth >= MAX_DEPTH {
            self.diags.push(
                Diagnostic::error("blocks nested too deeply", open, "too deep").with_help(format!(
                    "blocks may be nested at most {MAX_DEPTH} levels deep"
                )),
            );
            self.skip_to_close();
            return Err(Fail);
        }
        self.depth += 1;
        let mut stmts = Vec::new();
        loop {
            match &self.tok.kind {
                Tok::Comma | Tok::Semi => {
                    self.advance();
                }
                Tok::RBrace => {
                    self.advance();
                    break;
                }
                Tok::Eof => {
                    let _ = self.expect_close(&Tok::RBrace, "`}`", open.clone());
                    break;
                }
                Tok::Kw(k) if k.top_level_only() => {
                    let _ = self.expect_close(&Tok::RBrace, "`}`", open.clone());
                    break;
                }
                _ => match self.stmt(ctx) {
                    Ok(Some(s)) => stmts.push(s),
                    Ok(None) => {}
                    Err(Fail) => self.recover_stmt(),
                },
            }
        }
        self.leave();
        Ok(Block {
            stmts,
            span: open.start..self.prev_end,
        })
    }

    /// Skips past the `}` matching an already consumed `{` (or to the end).
    fn skip_to_close(&mut self) {
        let mut depth = 1usize;
        loop {
            match self.tok.kind {
                Tok::Eof => return,
                Tok::LBrace => depth += 1,
                Tok::RBrace => {
                    depth -= 1;
                    if depth == 0 {
                        self.advance();
                        return;
                    }
                }
                _ => {}
            }
            self.advance();
        }
    }

    /// Reports a statement kind that the block does not allow.
    fn not_allowed(&mut self, ctx: Ctx, what: &str, span: Span) {
        self.diags.push(
            Diagnostic::error(
                format!("{what} is not allowed in {}", ctx.name()),
                span,
                "not allowed here",
            )
            .with_help(ctx.help()),
        );
    }

    /// One statement. `Ok(None)`: parsed but not allowed here (already reported).
    fn stmt(&mut self, ctx: Ctx) -> P<Option<Stmt>> {
        match self.tok.kind {
            Tok::Kw(Kw::Let) => {
                if !ctx.allows(Kind::Let) {
                    let span = self.tok.span.clone();
                    self.not_allowed(ctx, "`let`", span);
                    return Err(Fail);
                }
                self.let_stmt().map(Some)
            }
            Tok::Kw(Kw::For) => {
                if !ctx.allows(Kind::For) {
                    let span = self.tok.span.clone();
                    self.not_allowed(ctx, "`for`", span);
                    return Err(Fail);
                }
                self.for_stmt(ctx).map(Some)
            }
            Tok::Ident => self.name_stmt(ctx),
            _ if ctx.allows(Kind::Constraint) => self.constraint(None).map(Some),
            _ => Err(self.expected(ctx.expected_stmt(), Some(ctx.help()))),
        }
    }

    /// A statement starting with a name: equation, row, member, field or constraint.
    fn name_stmt(&mut self, ctx: Ctx) -> P<Option<Stmt>> {
        if ctx == Ctx::TopFor {
            return Err(self.expected(ctx.expected_stmt(), Some(ctx.help())));
        }
        let name = self.ident("a name", None)?;
        let start = name.span.start;
        let index = if self.at(&Tok::LBracket) {
            Some(self.index()?)
        } else {
            None
        };
        let kind = match self.tok.kind {
            Tok::Prime => Kind::Equation,
            Tok::Colon => Kind::Row,
            Tok::Kw(Kw::In) => Kind::Member,
            Tok::Eq if index.is_none() => Kind::Field,
            _ => Kind::Constraint,
        };
        if !ctx.allows(kind) {
            if kind == Kind::Constraint && index.is_some() && self.at(&Tok::Eq) {
                let span = start..self.prev_end;
                let d = Diagnostic::error(
                    format!("`{}` cannot be a field key", self.text(&span)),
                    span,
                    "indexed name",
                )
                .with_help(ctx.help());
                self.diags.push(d);
                return Err(Fail);
            }
            let what = format!(
                "{} after `{}`",
                ctx.after_name(),
                self.text(&(start..self.prev_end))
            );
            return Err(self.expected(&what, Some(ctx.help())));
        }
        if kind == Kind::Constraint {
            // The name (and index) is the first operand of the left-hand side.
            let first = match index {
                Some(ix) => {
                    let h = ix.1 + 1;
                    let e = Expr {
                        kind: ExprKind::Index {
                            base: name,
                            index: Box::new(ix.0),
                        },
                        span: start..self.prev_end,
                    };
                    (e, h)
                }
                None => self.after_name(name)?,
            };
            return self.constraint(Some(first)).map(Some);
        }
        let target = Target {
            name,
            index: index.map(|ix| Box::new(ix.0)),
            span: start..self.prev_end,
        };
        self.advance();
        let stmt = match kind {
            Kind::Equation => {
                let help = Some(ctx.help());
                self.expect(
                    &Tok::Eq,
                    &format!("`=` after `{}'`", self.text(&target.span)),
                    help,
                )?;
                let rhs = self.expr()?;
                Stmt::Equation {
                    target,
                    rhs,
                    span: start..self.prev_end,
                }
            }
            Kind::Row => Stmt::Row {
                target,
                rhs: self.expr()?,
                span: start..self.prev_end,
            },
            Kind::Member => Stmt::Member {
                target,
                set: self.expr()?,
                span: start..self.prev_end,
            },
            _ => Stmt::Field {
                key: target.name,
                value: self.expr()?,
                span: start..self.prev_end,
            },
        };
        Ok(Some(stmt))
    }

    /// `LHS <= RHS` or `LHS >= RHS`; `first` is an already parsed leading operand.
    fn constraint(&mut self, first: Option<HExpr>) -> P<Stmt> {
        let lhs = self.expr_from(first)?.0;
        let op = match self.tok.kind {
            Tok::Le => CmpOp::Le,
            Tok::Ge => CmpOp::Ge,
            _ => {
                return Err(self.expected("`<=` or `>=`", Some(Ctx::Halfspace.help())));
            }
        };
        self.advance();
        let rhs = self.expr()?;
        Ok(Stmt::Constraint {
            span: lhs.span.start..rhs.span.end,
            lhs,
            op,
            rhs,
        })
    }

    /// `let NAME = EXPR` or `let NAME[INDEX] = EXPR`
    fn let_stmt(&mut self) -> P<Stmt> {
        let start = self.advance().span.start;
        let help = Some("a definition looks like `let v = x + 1`");
        let name = self.ident("a name after `let`", help)?;
        let index = if self.at(&Tok::LBracket) {
            Some(Box::new(self.index()?.0))
        } else {
            None
        };
        let target = Target {
            span: name.span.start..self.prev_end,
            name,
            index,
        };
        self.expect(
            &Tok::Eq,
            &format!("`=` after `let {}`", self.text(&target.span)),
            help,
        )?;
        let value = self.expr()?;
        Ok(Stmt::Let {
            target,
            value,
            span: start..self.prev_end,
        })
    }

    /// `for VAR in LO..HI { STMTS }` (body in context `ctx`).
    fn for_stmt(&mut self, ctx: Ctx) -> P<Stmt> {
        let start = self.advance().span.start;
        let help = "a loop looks like `for i in 1..N { ... }`";
        let var = self.ident("a loop variable after `for`", Some(help))?;
        self.expect(&Tok::Kw(Kw::In), "`in` after the loop variable", Some(help))?;
        let range = self.range(help)?;
        let body = self.block(ctx, "the loop range")?;
        Ok(Stmt::For {
            var,
            range,
            body,
            span: start..self.prev_end,
        })
    }

    /// `LO..HI`
    fn range(&mut self, help: &str) -> P<IndexRange> {
        let lo = self.expr()?;
        self.expect(&Tok::DotDot, "`..` in the range", Some(help))?;
        let hi = self.expr()?;
        Ok(IndexRange {
            span: lo.span.start..hi.span.end,
            lo,
            hi,
        })
    }

    /// `[EXPR]` after a name.
    fn index(&mut self) -> P<HExpr> {
        let open = self.advance().span;
        self.enter("expression")?;
        let r = match self.expr_h(None) {
            Ok(ix) => self.expect_close(&Tok::RBracket, "`]`", open).map(|()| ix),
            Err(f) => Err(f),
        };
        self.leave();
        r
    }

    // ---- expressions --------------------------------------------------------------------
    //
    // The recursive functions below keep their frames small (diagnostics are built in separate
    // cold functions) because they recurse up to `MAX_DEPTH` times.

    fn expr(&mut self) -> P<Expr> {
        Ok(self.expr_h(None)?.0)
    }

    fn expr_from(&mut self, first: Option<HExpr>) -> P<HExpr> {
        self.expr_h(first)
    }

    #[cold]
    #[inline(never)]
    fn too_long(&mut self, op: Span) -> Fail {
        self.diags.push(
            Diagnostic::error(
                "expression too long",
                op,
                format!("more than {MAX_HEIGHT} operators deep here"),
            )
            .with_help(format!(
                "an expression may be at most {MAX_HEIGHT} operators deep; split it with `let`"
            )),
        );
        Fail
    }

    /// Builds `lhs op rhs` (`op_span`: the operator's token), enforcing the height limit; an
    /// expression over the limit is labelled at the operator that passes it, not as a whole
    /// (which may be megabytes long).
    fn binary(&mut self, op: BinOp, op_span: Span, lhs: HExpr, rhs: HExpr) -> P<HExpr> {
        let h = 1 + lhs.1.max(rhs.1);
        let span = lhs.0.span.start..rhs.0.span.end;
        // Heights count leaves as 1: `h - 1` operators on the longest path.
        if h - 1 > MAX_HEIGHT {
            return Err(self.too_long(op_span));
        }
        let kind = ExprKind::Binary {
            op,
            lhs: Box::new(lhs.0),
            rhs: Box::new(rhs.0),
        };
        Ok((Expr { kind, span }, h))
    }

    /// `a + b`, `a - b` (left associative); `first` is an already parsed leading primary.
    fn expr_h(&mut self, first: Option<HExpr>) -> P<HExpr> {
        let mut lhs = self.term(first)?;
        loop {
            let op = match self.tok.kind {
                Tok::Plus => BinOp::Add,
                Tok::Minus => BinOp::Sub,
                _ => return Ok(lhs),
            };
            let op_span = self.advance().span;
            let rhs = self.term(None)?;
            lhs = self.binary(op, op_span, lhs, rhs)?;
        }
    }

    /// `a * b`, `a / b` (left associative).
    fn term(&mut self, first: Option<HExpr>) -> P<HExpr> {
        let mut lhs = self.unary(first)?;
        loop {
            let op = match self.tok.kind {
                Tok::Star => BinOp::Mul,
                Tok::Slash => BinOp::Div,
                _ => return Ok(lhs),
            };
            let op_span = self.advance().span;
            let rhs = self.unary(None)?;
            lhs = self.binary(op, op_span, lhs, rhs)?;
        }
    }

    /// `-a` (binds looser than `^`).
    fn unary(&mut self, first: Option<HExpr>) -> P<HExpr> {
        if first.is_some() || !self.at(&Tok::Minus) {
            return self.power(first);
        }
        let start = self.tok.span.start;
        self.enter("expression")?;
        self.advance();
        let r = self.unary(None);
        self.leave();
        let (inner, h) = r?;
        let e = Expr {
            span: start..inner.span.end,
            kind: ExprKind::Unary {
                op: UnOp::Neg,
                expr: Box::new(inner),
            },
        };
        Ok((e, h + 1))
    }

    /// `a ^ b` (right associative; the exponent may carry a unary minus: `2^-1`).
    fn power(&mut self, first: Option<HExpr>) -> P<HExpr> {
        let base = match first {
            Some(f) => f,
            None => self.primary()?,
        };
        if !self.at(&Tok::Caret) {
            return Ok(base);
        }
        self.enter("expression")?;
        let op_span = self.advance().span;
        let r = self.unary(None);
        self.leave();
        self.binary(BinOp::Pow, op_span, base, r?)
    }

    fn primary(&mut self) -> P<HExpr> {
        match &self.tok.kind {
            Tok::Num(v) => {
                let kind = ExprKind::Num(*v);
                let span = self.advance().span;
                Ok((Expr { kind, span }, 1))
            }
            Tok::Str(_) => {
                let tok = self.advance();
                let kind = match tok.kind {
                    Tok::Str(s) => ExprKind::Str(s),
                    _ => unreachable_str(),
                };
                Ok((
                    Expr {
                        kind,
                        span: tok.span,
                    },
                    1,
                ))
            }
            Tok::Ident => {
                let name = self.ident("a name", None)?;
                self.after_name(name)
            }
            Tok::LParen => {
                let open = self.advance().span;
                self.enter("expression")?;
                let r = match self.expr_h(None) {
                    Ok(e) => self
                        .expect_close(&Tok::RParen, "`)`", open.clone())
                        .map(|()| e),
                    Err(f) => Err(f),
                };
                self.leave();
                let (mut inner, h) = r?;
                inner.span = open.start..self.prev_end;
                Ok((inner, h))
            }
            Tok::LBracket => {
                self.enter("expression")?;
                let r = self.list();
                self.leave();
                r
            }
            _ => Err(self.expected("an expression", None)),
        }
    }

    /// `[a, b, ...]` (trailing comma allowed).
    fn list(&mut self) -> P<HExpr> {
        let open = self.advance().span;
        let mut elems = Vec::new();
        let mut h = 0;
        while !self.at(&Tok::RBracket) {
            let (e, eh) = self.expr_h(None)?;
            h = h.max(eh);
            elems.push(e);
            if !self.eat(&Tok::Comma) {
                break;
            }
        }
        if !self.at(&Tok::RBracket) {
            return Err(self.expected_sep("`,` or `]`", open, "list opened here"));
        }
        self.advance();
        let e = Expr {
            kind: ExprKind::List(elems),
            span: open.start..self.prev_end,
        };
        Ok((e, h + 1))
    }

    /// "expected `,` or `)`" with a label at the opener.
    #[cold]
    #[inline(never)]
    fn expected_sep(&mut self, what: &str, open: Span, label: &str) -> Fail {
        let d = Diagnostic::error(
            format!("expected {what}, found {}", self.found()),
            self.tok.span.clone(),
            format!("expected {what}"),
        )
        .with_label(open, label);
        self.report_at_tok(d)
    }

    /// What may follow a name in an expression: `[index]`, `.field`, `(args)` or nothing.
    fn after_name(&mut self, name: Ident) -> P<HExpr> {
        let start = name.span.start;
        match self.tok.kind {
            Tok::LBracket => {
                let (ix, h) = self.index()?;
                let e = Expr {
                    kind: ExprKind::Index {
                        base: name,
                        index: Box::new(ix),
                    },
                    span: start..self.prev_end,
                };
                Ok((e, h + 1))
            }
            Tok::Dot => {
                self.advance();
                let field = self.column(&name)?;
                let e = Expr {
                    span: start..field.span.end,
                    kind: ExprKind::Field { base: name, field },
                };
                Ok((e, 1))
            }
            Tok::LParen => {
                self.enter("expression")?;
                let r = self.call_args();
                self.leave();
                let (args, h) = r?;
                let e = Expr {
                    kind: ExprKind::Call { func: name, args },
                    span: start..self.prev_end,
                };
                Ok((e, h + 1))
            }
            _ => {
                let span = name.span.clone();
                Ok((
                    Expr {
                        kind: ExprKind::Name(name),
                        span,
                    },
                    1,
                ))
            }
        }
    }

    /// The column name after `table.`.
    #[inline(never)]
    fn column(&mut self, table: &Ident) -> P<Ident> {
        let help = format!("a table column looks like `{}.column`", table.name);
        self.ident("a column name after `.`", Some(&help))
    }

    /// `(ARG, ...)` where ARG is `EXPR` or `NAME = EXPR`; returns the arguments and their
    /// greatest height.
    fn call_args(&mut self) -> P<(Vec<Arg>, usize)> {
        let open = self.advance().span;
        let mut args = Vec::new();
        let mut h = 0;
        while !self.at(&Tok::RParen) {
            let name = if self.at(&Tok::Ident) && self.peek() == &Tok::Eq {
                let span = self.advance().span;
                self.advance();
                Some(Ident {
                    name: self.text(&span).to_string(),
                    span,
                })
            } else {
                None
            };
            let (value, vh) = self.expr_h(None)?;
            h = h.max(vh);
            args.push(Arg { name, value });
            if !self.eat(&Tok::Comma) {
                break;
            }
        }
        if !self.at(&Tok::RParen) {
            return Err(self.expected_sep("`,` or `)`", open, "arguments start here"));
        }
        self.advance();
        Ok((args, h))
    }
}

/// Never called: the token was just matched as a string.
#[cold]
fn unreachable_str() -> ExprKind {
    ExprKind::Str(String::new())
}

#[cfg(test)]
mod tests;
