//! Parser unit tests: real syntax trees, precedence, every item and statement kind, error
//! messages and spans, recovery and limits.

use crate::diagnostics::{span_of, Diagnostic, Span};
use crate::syntax::ast::*;
use crate::syntax::{parse, MAX_DIAGNOSTICS, MAX_SOURCE_LEN};

// ---- helpers ---------------------------------------------------------------------------------

#[test]
fn ranges_next_to_numbers() {
    assert_eq!(
        items("for i in 1..2 { let a = 1 }"),
        ["for i in 1..2 { let a = 1 }"]
    );
    assert_eq!(
        items("for i in 1 .. 2. { let a = .5 }"),
        ["for i in 1..2 { let a = 0.5 }"]
    );
    assert_eq!(
        items("state x[0..10] in [0., 1.]"),
        ["state x[0..10] in [0, 1]"]
    );
}

/// Parses and asserts there are no diagnostics.
fn ok(src: &str) -> Spec {
    let (spec, diags) = parse(src);
    assert!(
        diags.is_empty(),
        "unexpected diagnostics for {src:?}: {diags:#?}"
    );
    spec
}

/// Parses and returns the diagnostics (asserting there is at least one).
fn errs(src: &str) -> Vec<Diagnostic> {
    let (_, diags) = parse(src);
    assert!(!diags.is_empty(), "expected diagnostics for {src:?}");
    for d in &diags {
        let s = d.span();
        assert!(
            s.start <= s.end && s.end <= src.len(),
            "bad span {s:?} in {d:?}"
        );
    }
    diags
}

/// The only diagnostic for `src`.
fn one_err(src: &str) -> Diagnostic {
    let diags = errs(src);
    assert_eq!(
        diags.len(),
        1,
        "expected one diagnostic for {src:?}: {diags:#?}"
    );
    diags.into_iter().next().unwrap()
}

/// The value of `const c = SRC`.
fn expr(src: &str) -> Expr {
    let spec = ok(&format!("model m const c = {src}"));
    match spec.items.into_iter().next() {
        Some(Item::Const { value, .. }) => value,
        other => panic!("not a const: {other:?}"),
    }
}

fn id(name: &str, span: Span) -> Ident {
    Ident {
        name: name.to_string(),
        span,
    }
}

/// An S-expression rendering (no spans) for compact structural assertions.
fn sx(e: &Expr) -> String {
    match &e.kind {
        ExprKind::Num(v) => format!("{v}"),
        ExprKind::Name(n) => n.name.clone(),
        ExprKind::Index { base, index } => format!("{}[{}]", base.name, sx(index)),
        ExprKind::Field { base, field } => format!("{}.{}", base.name, field.name),
        ExprKind::Str(s) => format!("{s:?}"),
        ExprKind::Unary { expr, .. } => format!("(neg {})", sx(expr)),
        ExprKind::Binary { op, lhs, rhs } => {
            let o = match op {
                BinOp::Add => "+",
                BinOp::Sub => "-",
                BinOp::Mul => "*",
                BinOp::Div => "/",
                BinOp::Pow => "^",
            };
            format!("({o} {} {})", sx(lhs), sx(rhs))
        }
        ExprKind::Call { func, args } => {
            let args: Vec<String> = args
                .iter()
                .map(|a| match &a.name {
                    Some(n) => format!("{}={}", n.name, sx(&a.value)),
                    None => sx(&a.value),
                })
                .collect();
            format!("{}({})", func.name, args.join(", "))
        }
        ExprKind::List(es) => {
            let es: Vec<String> = es.iter().map(sx).collect();
            format!("[{}]", es.join(", "))
        }
    }
}

fn sx_target(t: &Target) -> String {
    match &t.index {
        Some(ix) => format!("{}[{}]", t.name.name, sx(ix)),
        None => t.name.name.clone(),
    }
}

fn sx_stmt(s: &Stmt) -> String {
    match s {
        Stmt::Equation { target, rhs, .. } => format!("{}' = {}", sx_target(target), sx(rhs)),
        Stmt::Update { target, rhs, .. } => format!("{} := {}", sx_target(target), sx(rhs)),
        Stmt::Row { target, rhs, .. } => format!("{}: {}", sx_target(target), sx(rhs)),
        Stmt::Member { target, set, .. } => format!("{} in {}", sx_target(target), sx(set)),
        Stmt::Field { key, value, .. } => format!("{} = {}", key.name, sx(value)),
        Stmt::Constraint { lhs, op, rhs, .. } => {
            let o = if *op == CmpOp::Le { "<=" } else { ">=" };
            format!("{} {o} {}", sx(lhs), sx(rhs))
        }
        Stmt::Let { target, value, .. } => format!("let {} = {}", sx_target(target), sx(value)),
        Stmt::For {
            var, range, body, ..
        } => format!(
            "for {} in {}..{} {}",
            var.name,
            sx(&range.lo),
            sx(&range.hi),
            sx_block(body)
        ),
    }
}

fn sx_block(b: &Block) -> String {
    let s: Vec<String> = b.stmts.iter().map(sx_stmt).collect();
    format!("{{ {} }}", s.join("; "))
}

fn sx_decl(kw: &str, d: &VarDecl) -> String {
    let mut s = format!("{kw} {}", d.name.name);
    if let Some(f) = &d.family {
        s += &format!("[{}..{}]", sx(&f.lo), sx(&f.hi));
    }
    match &d.init {
        Some(Init::In(e)) => s += &format!(" in {}", sx(e)),
        Some(Init::Point(e)) => s += &format!(" = {}", sx(e)),
        None => {}
    }
    s
}

fn sx_item(i: &Item) -> String {
    match i {
        Item::Const { name, value, .. } => format!("const {} = {}", name.name, sx(value)),
        Item::State(d) => sx_decl("state", d),
        Item::Input(d) => sx_decl("input", d),
        Item::Noise(d) => sx_decl("noise", d),
        Item::Table { name, path, .. } => format!("table {} = csv({path:?})", name.name),
        Item::Stmt(s) => sx_stmt(s),
        Item::Drift { body, .. } => format!("drift {}", sx_block(body)),
        Item::Diffusion(b) => format!("diffusion {}", sx_block(b)),
        Item::Domain(b) => format!("domain {}", sx_block(b)),
        Item::Discrete { body, .. } => format!("discrete {}", sx_block(body)),
        Item::Update { body, .. } => format!("update {}", sx_block(body)),
        Item::Initial { kind, body, .. } => format!("initial {} {}", kind.name, sx_block(body)),
        Item::Unsafe {
            name, kind, body, ..
        } => format!("unsafe {} {} {}", name.name, kind.name, sx_block(body)),
        Item::Goal {
            name,
            parts,
            window,
            stay,
            ..
        } => {
            let parts: Vec<String> = parts
                .iter()
                .map(|(k, b)| format!("{} {}", k.name, sx_block(b)))
                .collect();
            let mut s = format!("goal {} {}", name.name, parts.join(" and "));
            if let Some(w) = window {
                s += &format!(" within {}", sx(w));
            }
            if stay.is_some() {
                s += " stay";
            }
            s
        }
        Item::Analysis { name, body, .. } => format!("analysis {} {}", name.name, sx_block(body)),
    }
}

/// All items of a clean parse, one rendering per item (after `model m`).
fn items(body: &str) -> Vec<String> {
    ok(&format!("model m\n{body}"))
        .items
        .iter()
        .map(sx_item)
        .collect()
}

fn num(v: f64, span: Span) -> Expr {
    Expr {
        kind: ExprKind::Num(v),
        span,
    }
}

fn name(n: &str, span: Span) -> Expr {
    Expr {
        kind: ExprKind::Name(id(n, span.clone())),
        span,
    }
}

fn bin(op: BinOp, lhs: Expr, rhs: Expr) -> Expr {
    let span = lhs.span.start..rhs.span.end;
    Expr {
        kind: ExprKind::Binary {
            op,
            lhs: Box::new(lhs),
            rhs: Box::new(rhs),
        },
        span,
    }
}

// ---- numbers -----------------------------------------------------------------------------

#[test]
fn numbers_in_every_form() {
    let cases = [
        ("1", 1.0),
        ("0.4", 0.4),
        ("1e-3", 1e-3),
        ("2.5E+2", 250.0),
        (".5", 0.5),
        ("5.", 5.0),
        ("5.e3", 5000.0),
        ("1E3", 1000.0),
        ("007", 7.0),
        ("1e-400", 0.0),
    ];
    for (text, v) in cases {
        let e = expr(text);
        // The literal starts after "model m const c = " (18 bytes).
        assert_eq!(e, num(v, 18..18 + text.len()), "literal {text}");
    }
}

#[test]
fn inf_and_nan_are_names_not_numbers() {
    assert_eq!(sx(&expr("inf")), "inf");
    assert_eq!(sx(&expr("nan")), "nan");
    assert_eq!(sx(&expr("infected + nano")), "(+ infected nano)");
}

#[test]
fn dot_dot_after_integer_is_a_range() {
    assert_eq!(
        items("state x[1..N] in [-1, 1]"),
        ["state x[1..N] in [(neg 1), 1]"]
    );
    assert_eq!(items("noise w[1..3]"), ["noise w[1..3]"]);
}

// ---- precedence --------------------------------------------------------------------------

#[test]
fn precedence_and_associativity() {
    let cases = [
        ("-x^2", "(neg (^ x 2))"),
        ("2^3^2", "(^ 2 (^ 3 2))"),
        ("a-b-c", "(- (- a b) c)"),
        ("a/b*c", "(* (/ a b) c)"),
        ("a+b*c", "(+ a (* b c))"),
        ("(a+b)*c", "(* (+ a b) c)"),
        ("-a*b", "(* (neg a) b)"),
        ("-pi/10", "(/ (neg pi) 10)"),
        ("--a", "(neg (neg a))"),
        ("2^-1", "(^ 2 (neg 1))"),
        ("-2^-x^2", "(neg (^ 2 (neg (^ x 2))))"),
        ("a - -b", "(- a (neg b))"),
        ("x[i-1] * ref.px", "(* x[(- i 1)] ref.px)"),
        ("sin(theta) + atan2(y, x)", "(+ sin(theta) atan2(y, x))"),
        ("min(a, b, c)", "min(a, b, c)"),
        ("f()", "f()"),
        ("paper(eps = 1/16)", "paper(eps=(/ 1 16))"),
        ("paper(optimal)", "paper(optimal)"),
        ("[[1, 0], [0, 2]]", "[[1, 0], [0, 2]]"),
        ("[]", "[]"),
        ("[1, 2,]", "[1, 2]"),
        ("\"s\"", "\"s\""),
    ];
    for (src, want) in cases {
        assert_eq!(sx(&expr(src)), want, "{src}");
    }
}

#[test]
fn binary_tree_with_spans() {
    // model m const c = a-b-c
    //                   ^18
    let e = expr("a-b-c");
    let want = bin(
        BinOp::Sub,
        bin(BinOp::Sub, name("a", 18..19), name("b", 20..21)),
        name("c", 22..23),
    );
    assert_eq!(e, want);
    let e = expr("-x^2");
    let want = Expr {
        kind: ExprKind::Unary {
            op: UnOp::Neg,
            expr: Box::new(bin(BinOp::Pow, name("x", 19..20), num(2.0, 21..22))),
        },
        span: 18..22,
    };
    assert_eq!(e, want);
    // Parentheses widen the span of the inner expression.
    assert_eq!(expr("(a)").span, 18..21);
}

// ---- items and statements ----------------------------------------------------------------

const PENDULUM: &str = "/// Inverted pendulum with state feedback.
model pendulum   // paper, Sec. VII-B
const g = 10
const K1 = -20
state theta in [-pi/10, pi/10]
state omega in [-0.2, 0.2]
noise w
drift {
  theta' = omega
  omega' = g * sin(theta) + K1 * theta - 20 * omega
}
diffusion { omega: 0.1 * w }
analysis contraction { delta = 1e-3  horizon = 4  step = 0.01  metric = auto  radius = paper(eps = 1/16) }
";

#[test]
fn pendulum() {
    let spec = ok(PENDULUM);
    assert_eq!(
        spec.doc.as_deref(),
        Some("Inverted pendulum with state feedback.")
    );
    let model_at = span_of(PENDULUM, "pendulum", 1);
    assert_eq!(spec.model, Some(id("pendulum", model_at)));
    let got: Vec<String> = spec.items.iter().map(sx_item).collect();
    assert_eq!(
        got,
        [
            "const g = 10",
            "const K1 = (neg 20)",
            "state theta in [(/ (neg pi) 10), (/ pi 10)]",
            "state omega in [(neg 0.2), 0.2]",
            "noise w",
            "drift { theta' = omega; omega' = (- (+ (* g sin(theta)) (* K1 theta)) (* 20 omega)) }",
            "diffusion { omega: (* 0.1 w) }",
            "analysis contraction { delta = 0.001; horizon = 4; step = 0.01; metric = auto; \
             radius = paper(eps=(/ 1 16)) }",
        ]
    );
    // Spans of a few nodes.
    let Item::Const {
        name: cname,
        value,
        span,
    } = &spec.items[1]
    else {
        panic!()
    };
    assert_eq!(cname, &id("K1", span_of(PENDULUM, "K1", 0)));
    assert_eq!(span, &span_of(PENDULUM, "const K1 = -20", 0));
    assert_eq!(value.span, span_of(PENDULUM, "-20", 0));
    let Item::State(theta) = &spec.items[2] else {
        panic!()
    };
    assert_eq!(
        theta.span,
        span_of(PENDULUM, "state theta in [-pi/10, pi/10]", 0)
    );
    assert_eq!(theta.family, None);
    let Item::Drift { body: block, .. } = &spec.items[5] else {
        panic!()
    };
    assert_eq!(block.span.start, span_of(PENDULUM, "{", 0).start);
    assert_eq!(block.span.end, span_of(PENDULUM, "}", 0).end);
    let Stmt::Equation { target, rhs, span } = &block.stmts[0] else {
        panic!()
    };
    assert_eq!(
        target,
        &Target {
            name: id("theta", span_of(PENDULUM, "theta", 1)),
            index: None,
            span: span_of(PENDULUM, "theta", 1),
        }
    );
    assert_eq!(rhs, &name("omega", span_of(PENDULUM, "omega", 1)));
    assert_eq!(span, &span_of(PENDULUM, "theta' = omega", 0));
    let Item::Diffusion(block) = &spec.items[6] else {
        panic!()
    };
    assert_eq!(block.span, span_of(PENDULUM, "{ omega: 0.1 * w }", 0));
    let Item::Analysis { name: an, span, .. } = &spec.items[7] else {
        panic!()
    };
    assert_eq!(an.name, "contraction");
    assert_eq!(span.end, PENDULUM.trim_end().len());
}

#[test]
fn doc_comments() {
    let spec = ok("/// one\n///two\n// plain\n///  three\n//// not doc\nmodel m /// not doc\n");
    assert_eq!(spec.doc.as_deref(), Some("one\ntwo\n three"));
    assert_eq!(ok("model m").doc, None);
}

#[test]
fn byte_order_mark_and_crlf() {
    let spec = ok("\u{feff}/// doc\r\nmodel m\r\nconst k = 1\r\n");
    assert_eq!(spec.doc.as_deref(), Some("doc"));
    assert_eq!(spec.model.unwrap().span, 18..19);
    assert_eq!(spec.items.len(), 1);
}

#[test]
fn comments_and_separators() {
    let got = items("/* a /* nested */ comment */ const a = 1; const b = 2, state x\n;;");
    assert_eq!(got, ["const a = 1", "const b = 2", "state x"]);
    let got = items("drift { x' = 1; y' = 2, z' = 3 }");
    assert_eq!(got, ["drift { x' = 1; y' = 2; z' = 3 }"]);
}

#[test]
fn declarations() {
    let got = items(
        "state a\nstate b in [0, 1]\nstate c = 0.5\nstate x[1..N] in [-1, 1]\n\
         state y[1..2] = 0\ninput u in [-1, 1]\ninput v[1..M] in [0, 1]\nnoise w\nnoise n[1..3]\n\
         const type = 2",
    );
    assert_eq!(
        got,
        [
            "state a",
            "state b in [0, 1]",
            "state c = 0.5",
            "state x[1..N] in [(neg 1), 1]",
            "state y[1..2] = 0",
            "input u in [(neg 1), 1]",
            "input v[1..M] in [0, 1]",
            "noise w",
            "noise n[1..3]",
            "const type = 2",
        ]
    );
    let src = "model m\nstate x[1..N] in [-1, 1]";
    let Item::State(d) = &ok(src).items[0] else {
        panic!()
    };
    let fam = d.family.as_ref().unwrap();
    assert_eq!(fam.span, span_of(src, "1..N", 0));
    assert_eq!(fam.lo, num(1.0, span_of(src, "1", 0)));
    assert_eq!(fam.hi, name("N", span_of(src, "N", 0)));
    assert_eq!(d.span, span_of(src, "state x[1..N] in [-1, 1]", 0));
}

#[test]
fn table_and_columns() {
    let src = "model m\ntable ref = csv(\"ref.csv\")\nlet e = x - ref.px";
    let spec = ok(src);
    assert_eq!(
        spec.items[0],
        Item::Table {
            name: id("ref", span_of(src, "ref", 0)),
            path: "ref.csv".to_string(),
            path_span: span_of(src, "\"ref.csv\"", 0),
            span: span_of(src, "table ref = csv(\"ref.csv\")", 0),
        }
    );
    let Item::Stmt(Stmt::Let { value, .. }) = &spec.items[1] else {
        panic!()
    };
    let Expr {
        kind: ExprKind::Binary { rhs, .. },
        ..
    } = value
    else {
        panic!()
    };
    assert_eq!(
        **rhs,
        Expr {
            kind: ExprKind::Field {
                base: id("ref", span_of(src, "ref", 2)),
                field: id("px", span_of(src, "px", 0)),
            },
            span: span_of(src, "ref.px", 0),
        }
    );
    assert_eq!(
        items(r#"table t = csv("a \"q\" \\ b")"#),
        [r#"table t = csv("a \"q\" \\ b")"#]
    );
}

#[test]
fn lets_and_fors() {
    let got = items(
        "let v = x + 1\nfor i in 1..N { let y[i] = x[i] * 2  for j in 1..2 { let z = 1 } }\n\
         drift { let s = 1 for i in 2..N { x[i]' = x[i-1] - x[i] } x[1]' = -x[1] }",
    );
    assert_eq!(
        got,
        [
            "let v = (+ x 1)",
            "for i in 1..N { let y[i] = (* x[i] 2); for j in 1..2 { let z = 1 } }",
            "drift { let s = 1; for i in 2..N { x[i]' = (- x[(- i 1)] x[i]) }; x[1]' = (neg x[1]) }",
        ]
    );
    let src = "model m\ndrift { for i in 2..N { x[i]' = x[i-1] } }";
    let Item::Drift { body: b, .. } = &ok(src).items[0] else {
        panic!()
    };
    let Stmt::For {
        var,
        range,
        body,
        span,
    } = &b.stmts[0]
    else {
        panic!()
    };
    assert_eq!(var, &id("i", span_of(src, "i", 1)));
    assert_eq!(range.span, span_of(src, "2..N", 0));
    assert_eq!(span, &span_of(src, "for i in 2..N { x[i]' = x[i-1] }", 0));
    let Stmt::Equation { target, .. } = &body.stmts[0] else {
        panic!()
    };
    assert_eq!(target.span, span_of(src, "x[i]", 0));
    assert_eq!(
        target.index.as_deref(),
        Some(&name("i", span_of(src, "i", 3)))
    );
}

#[test]
fn blocks() {
    let got = items(
        "diffusion { omega: 0.1 * w  x[1]: w[1] for k in 1..2 { x[k]: 0.1 * w[k] } }\n\
         domain { theta in [-1, 1] for i in 1..N { x[i] in [-2, 2] } }\n\
         initial ball { over = [x, y] center = [0, 0] radius = 0.5 metric = [[1, 0], [0, 2]] }\n\
         unsafe wall halfspace { px + 2 * py >= 3 }\n\
         unsafe low halfspace { -px <= sin(t) }\n\
         unsafe b box { px in [1, 2]  py in [3, 4] }\n\
         unsafe c ball { over = [px, py]  center = [2, 3]  radius = 0.5 }\n\
         unsafe d halfspace { x[2] + ref.px >= 0 }\n\
         analysis main { method = interval horizon = 4 transform = [[1, 0], [0, 1]] outputs = [x] }",
    );
    assert_eq!(
        got,
        [
            "diffusion { omega: (* 0.1 w); x[1]: w[1]; for k in 1..2 { x[k]: (* 0.1 w[k]) } }",
            "domain { theta in [(neg 1), 1]; for i in 1..N { x[i] in [(neg 2), 2] } }",
            "initial ball { over = [x, y]; center = [0, 0]; radius = 0.5; metric = [[1, 0], [0, 2]] }",
            "unsafe wall halfspace { (+ px (* 2 py)) >= 3 }",
            "unsafe low halfspace { (neg px) <= sin(t) }",
            "unsafe b box { px in [1, 2]; py in [3, 4] }",
            "unsafe c ball { over = [px, py]; center = [2, 3]; radius = 0.5 }",
            "unsafe d halfspace { (+ x[2] ref.px) >= 0 }",
            "analysis main { method = interval; horizon = 4; transform = [[1, 0], [0, 1]]; outputs = [x] }",
        ]
    );
    let src = "model m\nunsafe wall halfspace { px + 2 * py >= 3 }";
    let Item::Unsafe {
        name: n,
        kind,
        body,
        span,
    } = &ok(src).items[0]
    else {
        panic!()
    };
    assert_eq!(n, &id("wall", span_of(src, "wall", 0)));
    assert_eq!(kind, &id("halfspace", span_of(src, "halfspace", 0)));
    assert_eq!(
        span,
        &span_of(src, "unsafe wall halfspace { px + 2 * py >= 3 }", 0)
    );
    let Stmt::Constraint { op, span, rhs, .. } = &body.stmts[0] else {
        panic!()
    };
    assert_eq!(*op, CmpOp::Ge);
    assert_eq!(span, &span_of(src, "px + 2 * py >= 3", 0));
    assert_eq!(rhs, &num(3.0, span_of(src, "3", 0)));
    let src = "model m\ndomain { theta in [-1, 1] }";
    let Item::Domain(b) = &ok(src).items[0] else {
        panic!()
    };
    let Stmt::Member { target, set, span } = &b.stmts[0] else {
        panic!()
    };
    assert_eq!(target.name, id("theta", span_of(src, "theta", 0)));
    assert_eq!(set.span, span_of(src, "[-1, 1]", 0));
    assert_eq!(span, &span_of(src, "theta in [-1, 1]", 0));
}

#[test]
fn field_and_row_spans() {
    let src = "model m\ninitial ball { radius = 0.5 }\ndiffusion { x: w }";
    let spec = ok(src);
    let Item::Initial { kind, body, span } = &spec.items[0] else {
        panic!()
    };
    assert_eq!(kind, &id("ball", span_of(src, "ball", 0)));
    assert_eq!(span, &span_of(src, "initial ball { radius = 0.5 }", 0));
    assert_eq!(
        body.stmts[0],
        Stmt::Field {
            key: id("radius", span_of(src, "radius", 0)),
            value: num(0.5, span_of(src, "0.5", 0)),
            span: span_of(src, "radius = 0.5", 0),
        }
    );
    let Item::Diffusion(b) = &spec.items[1] else {
        panic!()
    };
    assert_eq!(
        b.stmts[0],
        Stmt::Row {
            target: Target {
                name: id("x", span_of(src, "x", 0)),
                index: None,
                span: span_of(src, "x", 0),
            },
            rhs: name("w", span_of(src, "w", 0)),
            span: span_of(src, "x: w", 0),
        }
    );
}

#[test]
fn empty_blocks_and_free_form_layout() {
    assert_eq!(items("drift {}"), ["drift {  }"]);
    assert_eq!(
        items("drift\n{\nx'\n=\n1\n}const\nk\n=\n2"),
        ["drift { x' = 1 }", "const k = 2"]
    );
}

// ---- errors --------------------------------------------------------------------------------

#[test]
fn err_state_without_in_or_eq() {
    let src = "model m\nstate x + 1";
    let d = one_err(src);
    assert_eq!(
        d.message,
        "expected `=` or `in` after state name, found `+`"
    );
    assert_eq!(d.span(), span_of(src, "+", 0));
    assert!(d.help.unwrap().contains("state x in [-1, 1]"));
}

#[test]
fn err_missing_model() {
    let d = one_err("const a = 1");
    assert_eq!(d.message, "missing `model NAME`");
    assert_eq!(d.help.as_deref(), Some("start the spec with `model NAME`"));
    assert_eq!(d.span(), 0..5);
    let d = one_err("");
    assert_eq!(d.message, "missing `model NAME`");
    assert_eq!(d.span(), 0..0);
}

#[test]
fn err_model_twice_and_late() {
    let src = "model a\nmodel b";
    let d = one_err(src);
    assert_eq!(d.message, "`model` appears twice");
    assert_eq!(d.span(), span_of(src, "model b", 0));
    assert_eq!(d.labels[1].span, span_of(src, "a", 0));
    let (spec, _) = parse(src);
    assert_eq!(spec.model.unwrap().name, "a");
    let d = one_err("const k = 1\nmodel m");
    assert_eq!(d.message, "`model NAME` must come first");
}

#[test]
fn err_drift_without_prime() {
    let src = "model m\ndrift { x = -x }";
    let d = one_err(src);
    assert_eq!(d.message, "expected `'` after `x`, found `=`");
    assert_eq!(d.span(), span_of(src, "=", 0));
    assert_eq!(
        d.help.as_deref(),
        Some("a drift equation looks like `x' = -x`")
    );
    let d = one_err("model m\ndrift { x' -x }");
    assert_eq!(d.message, "expected `=` after `x'`, found `-`");
}

#[test]
fn err_unexpected_character() {
    let src = "model m\nconst θ = 1";
    let diags = errs(src);
    assert_eq!(diags[0].message, "unexpected character `θ`");
    assert_eq!(diags[0].span(), span_of(src, "θ", 0));
    assert_eq!(diags[0].span().len(), 2);
    let src = "model m\nunsafe w halfspace { x < 3 }";
    let d = one_err(src);
    assert_eq!(d.message, "unexpected character `<`");
    assert!(d.help.unwrap().contains("<="));
    // Stray characters are reported once, not again by the parser.
    let d = one_err("model m\nconst k = 1 + #");
    assert_eq!(d.message, "unexpected character `#`");
    let d = one_err("model m\nconst k = 1 + €€€ 2");
    assert_eq!(d.message, "unexpected characters `€€€`");
}

#[test]
fn err_number_literals() {
    let src = "model m\nconst big = 1e999";
    let d = one_err(src);
    assert_eq!(d.message, "number literal too large");
    assert_eq!(d.span(), span_of(src, "1e999", 0));
    let src = "model m\nconst k = 2x";
    let d = one_err(src);
    assert_eq!(d.message, "invalid number literal `2x`");
    assert_eq!(d.span(), span_of(src, "2x", 0));
    let d = one_err("model m\nconst k = 1e");
    assert_eq!(d.message, "invalid number literal `1e`");
    let d = one_err("model m\nconst k = 1.5.3");
    assert_eq!(d.message, "expected an item, found `.3`");
}

#[test]
fn err_end_of_file() {
    let src = "model m\ndrift { x' = 1";
    let d = one_err(src);
    assert_eq!(d.message, "expected `}`, found end of file");
    assert_eq!(d.span(), src.len()..src.len());
    assert_eq!(d.labels[1].span, span_of(src, "{", 0));
    let src = "model m\nconst k = ";
    let d = one_err(src);
    assert_eq!(d.message, "expected an expression, found end of file");
    assert_eq!(d.span(), src.len()..src.len());
    // Deeply unclosed: still one end-of-file error.
    let d = one_err("model m\ndrift { for i in 1..2 { for j in 1..2 { x' = (1");
    assert!(d.message.ends_with("found end of file"), "{d:?}");
}

#[test]
fn err_keyword_as_name() {
    let src = "model m\nconst in = 3";
    let d = one_err(src);
    assert_eq!(
        d.message,
        "expected a constant name after `const`, found keyword `in`"
    );
    assert_eq!(d.span(), span_of(src, "in", 0));
    assert!(d.notes[0].contains("reserved keyword"));
    // Recovery then parses `drift` as an item (which lacks its block).
    let d = &errs("model m\nstate drift")[0];
    assert_eq!(
        d.message,
        "expected a name after `state`, found keyword `drift`"
    );
}

#[test]
fn err_unclosed_paren() {
    let src = "model m\nconst k = (1 + 2\nstate x";
    let d = one_err(src);
    assert_eq!(d.message, "expected `)`, found keyword `state`");
    assert_eq!(d.span(), span_of(src, "state", 0));
    assert_eq!(d.labels[1].span, span_of(src, "(", 0));
    let (spec, _) = parse(src);
    assert_eq!(spec.items.len(), 1, "the state after the bad const is kept");
    let d = one_err("model m\nconst k = [1, 2 3]");
    assert_eq!(d.message, "expected `,` or `]`, found `3`");
    let d = one_err("model m\nconst k = f(1 2)");
    assert_eq!(d.message, "expected `,` or `)`, found `2`");
}

#[test]
fn err_top_level_statement() {
    let src = "model m\nx' = 1";
    let d = one_err(src);
    assert_eq!(d.message, "expected an item, found `x`");
    assert_eq!(d.span(), span_of(src, "x", 0));
    assert!(d.help.unwrap().contains("drift"));
    let d = one_err("model m\nconst k = 1 2");
    assert_eq!(d.message, "expected an item, found `2`");
    let d = one_err("model m\nfor i in 1..2 { x' = 1 }");
    assert_eq!(d.message, "expected `let` or `for`, found `x`");
}

#[test]
fn err_block_contents() {
    let d = one_err("model m\ndomain { let a = 1 }");
    assert_eq!(d.message, "`let` is not allowed in a `domain` block");
    let d = one_err("model m\ndiffusion { x' = w }");
    assert_eq!(d.message, "expected `:` after `x`, found `'`");
    assert_eq!(
        d.help.as_deref(),
        Some("a diffusion row looks like `x: 0.1 * w`")
    );
    let d = one_err("model m\nanalysis a { horizon: 4 }");
    assert_eq!(d.message, "expected `=` after `horizon`, found `:`");
    let d = one_err("model m\nanalysis a { 4 }");
    assert_eq!(d.message, "expected a field `key = value`, found `4`");
    let d = one_err("model m\nunsafe w box { x = 1 }");
    assert_eq!(d.message, "expected `in` after `x`, found `=`");
    let d = one_err("model m\nunsafe w halfspace { x + 1 }");
    assert_eq!(d.message, "expected `<=` or `>=`, found `}`");
    let d = one_err("model m\nunsafe w halfspace { x <= 1  y >= 2 }");
    assert_eq!(
        d.message,
        "an unsafe `halfspace` has exactly one constraint"
    );
    let d = one_err("model m\nunsafe w polytope { x <= 1 }");
    assert_eq!(d.message, "unknown unsafe set kind `polytope`");
    let d = one_err("model m\ninitial box { over = [x] }");
    assert_eq!(d.message, "unknown initial set kind `box`");
    let d = one_err("model m\nanalysis a { x[1] = 2 }");
    assert_eq!(d.message, "`x[1]` cannot be a field key");
}

#[test]
fn err_declarations() {
    let d = one_err("model m\ninput u = 1");
    assert_eq!(d.message, "expected `in` after input name, found `=`");
    let d = one_err("model m\nnoise w in [0, 1]");
    assert_eq!(d.message, "unexpected keyword `in` after noise name");
    let d = one_err("model m\nstate x[1 3] in [0, 1]");
    assert_eq!(d.message, "expected `..` in the range, found `3`");
    let d = one_err("model m\ntable r = load(\"a.csv\")");
    assert_eq!(d.message, "expected `csv(\"...\")`, found `load`");
    let d = one_err("model m\ntable r = csv(a.csv)");
    assert_eq!(d.message, "expected a path string, found `a`");
    let d = one_err("model m\nconst k 1");
    assert_eq!(d.message, "expected `=` after constant name, found `1`");
    let d = one_err("model m\nfor i = 1..2 { let a = i }");
    assert_eq!(
        d.message,
        "expected `in` after the loop variable, found `=`"
    );
    let d = one_err("model m\ndrift x' = 1");
    assert_eq!(d.message, "expected `{` after `drift`, found `x`");
}

#[test]
fn err_strings_and_comments() {
    let src = "model m\ntable r = csv(\"a.csv)\nconst k = 1";
    let d = one_err(src);
    assert_eq!(d.message, "unterminated string literal");
    assert_eq!(d.span(), span_of(src, "\"a.csv)", 0));
    let src = "model m /* never closed";
    let d = one_err(src);
    assert_eq!(d.message, "unterminated block comment");
    assert_eq!(d.span(), span_of(src, "/*", 0));
    let d = one_err("model m\ntable r = csv(\"a\\n\")");
    assert_eq!(d.message, "unknown escape `\\n` in string");
}

// ---- recovery ----------------------------------------------------------------------------

#[test]
fn recovery_reports_every_item_error() {
    let src = "model m\n\
               const a = * 2\n\
               state x + 1\n\
               const ok1 = 1\n\
               drift { x' = ) }\n\
               noise w\n\
               analysis { horizon = 4 }\n\
               const ok2 = 2\n";
    let (spec, diags) = parse(src);
    let msgs: Vec<&str> = diags.iter().map(|d| d.message.as_str()).collect();
    assert_eq!(
        msgs,
        [
            "expected an expression, found `*`",
            "expected `=` or `in` after state name, found `+`",
            "expected an expression, found `)`",
            "expected an analysis name after `analysis`, found `{`",
        ]
    );
    let got: Vec<String> = spec.items.iter().map(sx_item).collect();
    assert_eq!(
        got,
        ["const ok1 = 1", "drift {  }", "noise w", "const ok2 = 2"]
    );
}

#[test]
fn recovery_inside_blocks_keeps_good_statements() {
    let src = "model m\n\
               drift {\n  x' = 1 + * 2\n  y' = + 2\n  z' = 3\n  w = 4\n  v' = 5\n}\n\
               const k = 1";
    let (spec, diags) = parse(src);
    let msgs: Vec<&str> = diags.iter().map(|d| d.message.as_str()).collect();
    assert_eq!(
        msgs,
        [
            "expected an expression, found `*`",
            "expected an expression, found `+`",
            "expected `'` after `w`, found `=`",
        ]
    );
    let got: Vec<String> = spec.items.iter().map(sx_item).collect();
    assert_eq!(got, ["drift { z' = 3; v' = 5 }", "const k = 1"]);
}

#[test]
fn recovery_from_unclosed_block() {
    let src = "model m\ndrift { x' = 1\nstate y in [0, 1]";
    let (spec, diags) = parse(src);
    assert_eq!(diags.len(), 1);
    assert_eq!(diags[0].message, "expected `}`, found keyword `state`");
    let got: Vec<String> = spec.items.iter().map(sx_item).collect();
    assert_eq!(got, ["drift { x' = 1 }", "state y in [0, 1]"]);
}

#[test]
fn recovery_skips_braces_of_broken_items() {
    let src = "model m\nunsafe 3 box { for i in 1..2 { x in [0, 1] } let q = 1 }\nconst k = 1";
    let (spec, diags) = parse(src);
    assert_eq!(diags.len(), 1, "{diags:#?}");
    let got: Vec<String> = spec.items.iter().map(sx_item).collect();
    assert_eq!(got, ["const k = 1"]);
}

// ---- limits ------------------------------------------------------------------------------

fn assert_nested_too_deeply(src: &str) {
    let (_, diags) = parse(src);
    assert_eq!(
        diags.len(),
        1,
        "{:?}",
        diags.iter().map(|d| &d.message).collect::<Vec<_>>()
    );
    assert_eq!(diags[0].message, "expression nested too deeply");
}

#[test]
fn deep_nesting_is_a_diagnostic() {
    let n = 10_000;
    assert_nested_too_deeply(&format!(
        "model m\nconst k = {}1{}",
        "(".repeat(n),
        ")".repeat(n)
    ));
    assert_nested_too_deeply(&format!("model m\nconst k = {}1", "-".repeat(n)));
    assert_nested_too_deeply(&format!("model m\nconst k = {}", "[".repeat(n)));
    assert_nested_too_deeply(&format!("model m\nconst k = 2{}", "^2".repeat(n)));
    assert_nested_too_deeply(&format!(
        "model m\nconst k = {}1{}",
        "f(".repeat(n),
        ")".repeat(n)
    ));
    assert_nested_too_deeply(&format!(
        "model m\nconst k = {}1{}",
        "x[".repeat(n),
        "]".repeat(n)
    ));
    assert_nested_too_deeply(&format!("model m\ndrift {{ x' = {} }}", "(".repeat(n)));
    // Just under the limit is fine.
    let ok_depth = 150;
    ok(&format!(
        "model m\nconst k = {}1{}",
        "(".repeat(ok_depth),
        ")".repeat(ok_depth)
    ));
    ok(&format!("model m\nconst k = {}1", "-".repeat(ok_depth)));
}

#[test]
fn deep_blocks_are_a_diagnostic() {
    let n = 10_000;
    let src = format!(
        "model m\ndrift {{ {} x' = 1 {} }}\nconst k = 1",
        "for i in 1..2 { ".repeat(n),
        "} ".repeat(n)
    );
    let (spec, diags) = parse(&src);
    assert_eq!(
        diags.len(),
        1,
        "{:?}",
        diags.iter().map(|d| &d.message).collect::<Vec<_>>()
    );
    assert_eq!(diags[0].message, "blocks nested too deeply");
    assert_eq!(spec.items.len(), 2);
}

#[test]
fn long_chains_are_bounded() {
    ok(&format!("model m\nconst k = 1{}", " + 1".repeat(900)));
    let d = one_err(&format!("model m\nconst k = 1{}", " + 1".repeat(20_000)));
    assert_eq!(d.message, "expression too long");
}

#[test]
fn too_large_source() {
    let src = format!("model m\n{}", " ".repeat(MAX_SOURCE_LEN));
    let (spec, diags) = parse(&src);
    assert_eq!(diags.len(), 1);
    assert_eq!(diags[0].span(), 0..0);
    assert!(diags[0].message.contains("too large"));
    assert_eq!(spec.items.len(), 0);
    let (_, diags) = parse(&"x".repeat(10_000_000));
    assert_eq!(diags.len(), 1);
    // A large valid file parses.
    let n = 50_000;
    let (spec, diags) = parse(&format!("model m\n{}", "const k = 1\n".repeat(n)));
    assert!(diags.is_empty());
    assert_eq!(spec.items.len(), n);
}

#[test]
fn non_ascii_never_panics() {
    for src in [
        "θ",
        "model θ",
        "model m\ndrift { θ' = 1 }",
        "\"θ",
        "/// θ\nmodel m",
        "1θ",
        "é.5",
    ] {
        let (_, diags) = parse(src);
        for d in &diags {
            for l in &d.labels {
                assert!(src.is_char_boundary(l.span.start) && src.is_char_boundary(l.span.end));
            }
        }
    }
}

#[test]
fn error_flood_is_capped() {
    for junk in ["#a", "const = ", "\"\\q\\q", "1e999 "] {
        let src = format!("model m\n{}", junk.repeat(1_000_000));
        let (_, diags) = parse(&src);
        assert!(
            diags.len() <= MAX_DIAGNOSTICS + 2,
            "{junk}: {}",
            diags.len()
        );
        assert!(diags.len() > 100, "{junk}: {}", diags.len());
        assert!(diags
            .last()
            .unwrap()
            .message
            .starts_with("too many syntax errors"));
    }
}

/// Goal sets: one or more parts joined by `and`, an optional window, an optional `stay`; the
/// words are not reserved (a state may be called `stay`), and a goal ends at the next line's item.
#[test]
fn goals() {
    assert_eq!(
        items(
            "goal dock box { x in [0.9, 1.1] } within [2, 4]\n\
             goal park ball { over = [x, y] center = [0, 0] radius = 0.2 } stay\n\
             goal lane halfspace { y >= -1 } and halfspace { y <= 1 } and box { x in [4, 5] } \
             within [0, T] stay\n\
             state stay in [0, 1]"
        ),
        [
            "goal dock box { x in [0.9, 1.1] } within [2, 4]",
            "goal park ball { over = [x, y]; center = [0, 0]; radius = 0.2 } stay",
            "goal lane halfspace { y >= (neg 1) } and halfspace { y <= 1 } and box { x in [4, 5] } \
             within [0, T] stay",
            "state stay in [0, 1]",
        ]
    );
}

mod discrete;
