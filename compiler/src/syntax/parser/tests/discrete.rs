//! Discrete-time models: `discrete { period = .. }` and `update { x = .. }` (rendered `x := ..`
//! by the tests' S-expressions, to tell an update equation from a field).

use super::*;

#[test]
fn discrete_and_update_items() {
    let got = items(
        "discrete { period = 0.1 }\n\
         update {\n\
             let v = x1 + x2\n\
             x1 = x1 + 0.1 * x2\n\
             x[1] = 0.9 * x[1]\n\
             for i in 2..3 { x[i] = x[i - 1] }\n\
         }",
    );
    assert_eq!(
        got,
        [
            "discrete { period = 0.1 }",
            "update { let v = (+ x1 x2); x1 := (+ x1 (* 0.1 x2)); x[1] := (* 0.9 x[1]); \
             for i in 2..3 { x[i] := x[(- i 1)] } }",
        ]
    );
}

#[test]
fn discrete_and_update_spans() {
    let src = "model m\ndiscrete { period = 1/10 }\nupdate { x[2] = -x[1] }";
    let spec = ok(src);
    let Item::Discrete { body, span } = &spec.items[0] else {
        panic!("{:?}", spec.items[0])
    };
    assert_eq!(span, &span_of(src, "discrete { period = 1/10 }", 0));
    assert_eq!(body.span, span_of(src, "{ period = 1/10 }", 0));
    let Stmt::Field { key, span, .. } = &body.stmts[0] else {
        panic!("{:?}", body.stmts[0])
    };
    assert_eq!(key, &id("period", span_of(src, "period", 0)));
    assert_eq!(span, &span_of(src, "period = 1/10", 0));
    let Item::Update { body, span } = &spec.items[1] else {
        panic!("{:?}", spec.items[1])
    };
    assert_eq!(span, &span_of(src, "update { x[2] = -x[1] }", 0));
    let Stmt::Update { target, rhs, span } = &body.stmts[0] else {
        panic!("{:?}", body.stmts[0])
    };
    assert_eq!(target.name, id("x", span_of(src, "x", 0)));
    assert_eq!(target.span, span_of(src, "x[2]", 0));
    assert_eq!(
        target.index.as_deref(),
        Some(&num(2.0, span_of(src, "2", 0)))
    );
    assert_eq!(rhs.span, span_of(src, "-x[1]", 0));
    assert_eq!(span, &span_of(src, "x[2] = -x[1]", 0));
    // A `drift` item's span starts at its keyword too (the checker points at it).
    let src = "model m\ndrift { x' = 1 }";
    let Item::Drift { body, span } = &ok(src).items[0] else {
        panic!()
    };
    assert_eq!(span, &span_of(src, "drift { x' = 1 }", 0));
    assert_eq!(body.span, span_of(src, "{ x' = 1 }", 0));
}

/// `x' = ..` in `update` parses (the checker refuses it with a hint); `x = ..` in `drift`
/// does not.
#[test]
fn derivative_in_update_parses_next_value_in_drift_does_not() {
    assert_eq!(items("update { x' = -x }"), ["update { x' = (neg x) }"]);
    let d = one_err("model m\ndrift { x = -x }");
    assert_eq!(d.message, "expected `'` after `x`, found `=`");
}

#[test]
fn err_update_contents() {
    let src = "model m\nupdate { x: w }";
    let d = one_err(src);
    assert_eq!(d.message, "expected `=` after `x`, found `:`");
    assert_eq!(d.span(), span_of(src, ":", 0));
    assert_eq!(
        d.help.as_deref(),
        Some("an update equation (the next value) looks like `x = 0.9 * x`")
    );
    let d = one_err("model m\nupdate { 4 }");
    assert_eq!(
        d.message,
        "expected an update `x = ...`, `let` or `for`, found `4`"
    );
    let d = one_err("model m\ndiscrete { period: 1 }");
    assert_eq!(d.message, "expected `=` after `period`, found `:`");
}

/// `discrete` and `update` are reserved; an unclosed `update` stops at the next item.
#[test]
fn discrete_words_are_keywords() {
    // Recovery then parses `update` as an item (which lacks its block).
    let d = &errs("model m\nstate update = 0")[0];
    assert_eq!(
        d.message,
        "expected a name after `state`, found keyword `update`"
    );
    let d = &errs("model m\nlet discrete = 1")[0];
    assert_eq!(
        d.message,
        "expected a name after `let`, found keyword `discrete`"
    );
    let src = "model m\nupdate { x = 1\nanalysis a { horizon = 1 }";
    let (spec, diags) = parse(src);
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(diags[0].message, "expected `}`, found keyword `analysis`");
    assert_eq!(spec.items.len(), 2);
}
