//! Blocks and statements: what each block may contain ([`Ctx`]), equations, update equations,
//! rows, memberships, fields, constraints, lets and fors, with recovery at the statement level.

use super::{Fail, HExpr, Parser, P};
use crate::diagnostics::{Diagnostic, Span};
use crate::limits::MAX_DEPTH;
use crate::syntax::ast::*;
use crate::syntax::lexer::{Kw, Tok};

/// What a block may contain; drives the statement parser's expectations and messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Ctx {
    /// A top-level `for`: lets and nested fors.
    TopFor,
    Drift,
    /// A discrete-time model's `update`: update equations `x = ..` (and drift equations
    /// `x' = ..`, which the checker refuses with a hint), lets and fors.
    Update,
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
    Update,
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
            Ctx::Update => matches!(k, Update | Equation | Let | For),
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
            Ctx::Update => "an `update` block",
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
            Ctx::Update => "an update `x = ...`, `let` or `for`",
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
            Ctx::Fields | Ctx::Update => "`=`",
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
            Ctx::Update => "an update equation (the next value) looks like `x = 0.9 * x`",
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

impl<'s> Parser<'s> {
    // ---- blocks and statements ----------------------------------------------------------

    /// `{ STMTS }`; an unclosed block is reported and returned as far as it goes.
    pub(super) fn block(&mut self, ctx: Ctx, owner: &str) -> P<Block> {
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

    /// A statement starting with a name: equation, update, row, member, field or constraint.
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
            Tok::Eq if ctx == Ctx::Update => Kind::Update,
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
            Kind::Update => Stmt::Update {
                target,
                rhs: self.expr()?,
                span: start..self.prev_end,
            },
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
    pub(super) fn let_stmt(&mut self) -> P<Stmt> {
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
    pub(super) fn for_stmt(&mut self, ctx: Ctx) -> P<Stmt> {
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
    pub(super) fn range(&mut self, help: &str) -> P<IndexRange> {
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
    pub(super) fn index(&mut self) -> P<HExpr> {
        let open = self.advance().span;
        self.enter("expression")?;
        let r = match self.expr_h(None) {
            Ok(ix) => self.expect_close(&Tok::RBracket, "`]`", open).map(|()| ix),
            Err(f) => Err(f),
        };
        self.leave();
        r
    }
}
