//! The spec and its top-level items: the model line, declarations, tables, unsafe and goal
//! sets, and the blocks that follow item keywords.

use super::{Ctx, Fail, Parser, MAX_DIAGNOSTICS, P};
use crate::diagnostics::Diagnostic;
use crate::syntax::ast::*;
use crate::syntax::lexer::{Kw, Tok};

impl<'s> Parser<'s> {
    // ---- items --------------------------------------------------------------------------

    pub(super) fn spec(&mut self) -> Spec {
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
                                    `discrete`, `update`, `initial`, `unsafe`, `goal` or \
                                    `analysis`";
                    if self.at(&Tok::Ident)
                        && matches!(self.peek(), Tok::Prime | Tok::Colon | Tok::Kw(Kw::In))
                    {
                        help = "equations, rows and bounds go inside `drift { ... }`, \
                                `update { ... }`, `diffusion { ... }` or `domain { ... }`";
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
                let body = self.block(Ctx::Drift, "`drift`")?;
                Item::Drift {
                    body,
                    span: start..self.prev_end,
                }
            }
            Kw::Diffusion => {
                self.advance();
                Item::Diffusion(self.block(Ctx::Diffusion, "`diffusion`")?)
            }
            Kw::Domain => {
                self.advance();
                Item::Domain(self.block(Ctx::Domain, "`domain`")?)
            }
            Kw::Discrete => {
                self.advance();
                let body = self.block(Ctx::Fields, "`discrete`")?;
                Item::Discrete {
                    body,
                    span: start..self.prev_end,
                }
            }
            Kw::Update => {
                self.advance();
                let body = self.block(Ctx::Update, "`update`")?;
                Item::Update {
                    body,
                    span: start..self.prev_end,
                }
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
}
