//! Expressions by precedence (sums, products, unary minus, powers, primaries), lists, calls
//! and table columns, with the height of every tree bounded.

use super::{Fail, HExpr, Parser, P};
use crate::diagnostics::{Diagnostic, Span};
use crate::limits::MAX_HEIGHT;
use crate::syntax::ast::*;
use crate::syntax::lexer::Tok;

impl<'s> Parser<'s> {
    // ---- expressions --------------------------------------------------------------------
    //
    // The recursive functions below keep their frames small (diagnostics are built in separate
    // cold functions) because they recurse up to `MAX_DEPTH` times.

    pub(super) fn expr(&mut self) -> P<Expr> {
        Ok(self.expr_h(None)?.0)
    }

    pub(super) fn expr_from(&mut self, first: Option<HExpr>) -> P<HExpr> {
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
    pub(super) fn expr_h(&mut self, first: Option<HExpr>) -> P<HExpr> {
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
    pub(super) fn after_name(&mut self, name: Ident) -> P<HExpr> {
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
