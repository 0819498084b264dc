//! Discrete-time models in the checker: the model it builds (its time, its map through the
//! interpreter), the mixing of continuous and discrete constructs, the analyses' refused
//! settings and their horizons and steps, each diagnostic with its message and span.

use std::path::Path;

use crate::backend::{interp::Interpreter, prepare};
use crate::diagnostics::{span_of, Diagnostic, Severity};
use crate::driver::check_source;
use crate::model::{Guarantee, Integrator, Method, MetricChoice, Model, Rate, Split, Time};
use reachc_core::System;

/// The brief's chain, with a let, a table-free use of `t` and an input in the map.
const CHAIN: &str = "model chain
discrete { period = 0.1 }
state x1 in [-1, 1]
state x2 = 0
input u in [-0.1, 0.1]
noise w1
update {
    let v = x1 + x2
    x1 = x1 + 0.1 * x2
    x2 = 0.9 * x2 - 0.1 * x1 + u + 0.01 * sin(t) + 0.001 * v
}
diffusion { x2: 0.05 * w1 }
";

/// The model of `src`, asserting it checks without diagnostics.
fn model(src: &str) -> Model {
    let (model, diags) = check_source(src, Path::new("."));
    assert!(diags.is_empty(), "{diags:#?}");
    model.expect("no errors")
}

/// The errors of `src` (asserting it does not check, and that there are only errors).
fn errors(src: &str) -> Vec<Diagnostic> {
    let (model, diags) = check_source(src, Path::new("."));
    assert!(model.is_none(), "{src} checks");
    assert!(diags.iter().all(|d| d.severity == Severity::Error));
    diags
}

/// The only error of `src`.
fn one_error(src: &str) -> Diagnostic {
    let diags = errors(src);
    let [d] = diags.as_slice() else {
        panic!("expected one error: {diags:#?}");
    };
    d.clone()
}

/// The chain with `analysis` appended.
fn chain_with(analysis: &str) -> String {
    format!("{CHAIN}{analysis}\n")
}

#[test]
fn the_model_is_discrete_and_its_drift_is_the_map() {
    let mut m = model(&chain_with("analysis a { horizon = 1 }"));
    assert_eq!(m.time, Time::Discrete { period: 0.1 });
    let prepared = prepare(&mut m);
    assert_eq!(prepared.info.time(), Time::Discrete { period: 0.1 });
    let interp = Interpreter::new(m, &prepared);
    let (x, u, t) = ([0.5, -0.2], [0.05], 0.3);
    let mut next = [0.0; 2];
    interp.drift(&x, &u, t, &mut next);
    let v = x[0] + x[1];
    let expected = [
        x[0] + 0.1 * x[1],
        0.9 * x[1] - 0.1 * x[0] + u[0] + 0.01 * f64::sin(t) + 0.001 * v,
    ];
    for (got, want) in next.iter().zip(expected) {
        assert!((got - want).abs() <= 1e-15, "{next:?} {expected:?}");
    }
    let mut g = [0.0; 2];
    interp.diffusion(&x, t, &mut g);
    assert_eq!(g, [0.0, 0.05]);
}

/// Update equations in `for` loops over families: a shift register.
#[test]
fn update_equations_in_loops() {
    let mut m = model(
        "model shift\ndiscrete { period = 1 }\nstate x[1..3] in [0, 1]\n\
         update { for i in 1..2 { x[i] = x[i + 1] }  x[3] = 0.5 * x[1] }",
    );
    assert_eq!(m.time, Time::Discrete { period: 1.0 });
    let prepared = prepare(&mut m);
    let interp = Interpreter::new(m, &prepared);
    let mut next = [0.0; 3];
    interp.drift(&[1.0, 2.0, 3.0], &[], 0.0, &mut next);
    assert_eq!(next, [2.0, 3.0, 0.5]);
}

#[test]
fn continuous_models_stay_continuous() {
    let m = model("model m\nstate x in [0, 1]\ndrift { x' = -x }");
    assert_eq!(m.time, Time::Continuous);
}

#[test]
fn update_without_discrete() {
    let src = "model m\nstate x in [0, 1]\nupdate { let v = 2 * x  x = 0.5 * v }";
    let d = one_error(src);
    assert_eq!(d.message, "`update` needs a discrete-time model");
    assert_eq!(d.span(), span_of(src, "update", 0));
    let help = d.help.unwrap();
    assert!(help.starts_with("add `discrete { period = .. }`"), "{help}");
}

#[test]
fn drift_in_a_discrete_model() {
    let src = "model m\ndiscrete { period = 0.5 }\nstate x in [0, 1]\n\
               drift { x' = -x }\nupdate { x = 0.5 * x }";
    let d = one_error(src);
    assert_eq!(d.message, "a discrete-time model has no `drift`");
    assert_eq!(d.span(), span_of(src, "drift", 0));
    assert_eq!(d.labels[1].span, span_of(src, "discrete", 0));
    assert!(d
        .help
        .unwrap()
        .starts_with("a discrete-time model gives `update { x = .. }`"));
}

#[test]
fn derivative_in_update() {
    let src = "model m\ndiscrete { period = 0.5 }\nstate x in [0, 1]\nstate y[1..1] = 0\n\
               update { x' = -x  y[1] = y[1] }";
    let d = one_error(src);
    assert_eq!(d.message, "a drift equation is not allowed in update");
    assert_eq!(d.span(), span_of(src, "x' = -x", 0));
    assert_eq!(d.labels[1].span, span_of(src, "update", 0));
    assert_eq!(
        d.help.as_deref(),
        Some("in discrete time write the next value `x = ..`")
    );
}

#[test]
fn discrete_without_update() {
    let src = "model m\ndiscrete { period = 0.5 }\nstate x in [0, 1]";
    let d = one_error(src);
    assert_eq!(d.message, "a discrete-time model needs an `update` block");
    assert_eq!(d.span(), span_of(src, "discrete", 0));
}

#[test]
fn update_equations_missing_or_repeated() {
    let src = "model m\ndiscrete { period = 0.5 }\nstate x in [0, 1]\nstate y = 0\n\
               update { x = 0.5 * x  x = x }";
    let diags = errors(src);
    assert_eq!(diags.len(), 2, "{diags:#?}");
    let twice = diags.iter().find(|d| d.message.contains("two")).unwrap();
    assert_eq!(twice.message, "state `x` has two update equations");
    assert_eq!(twice.span(), span_of(src, "x = x", 0));
    assert_eq!(twice.labels[1].span, span_of(src, "x = 0.5 * x", 0));
    let missing = diags.iter().find(|d| d.message.contains("no")).unwrap();
    assert_eq!(missing.message, "state `y` has no update equation");
    assert_eq!(missing.span(), span_of(src, "state y = 0", 0));
    assert_eq!(
        missing.help.as_deref(),
        Some("add `y = ...` to the update block")
    );
}

#[test]
fn discrete_item_errors() {
    let body = "state x in [0, 1]\nupdate { x = x }";
    let src = format!("model m\ndiscrete {{ period = 0 }}\n{body}");
    let d = one_error(&src);
    assert_eq!(
        d.message,
        "the period must be finite and positive, but it is 0"
    );
    assert_eq!(
        d.span(),
        span_of(&src, "0 }", 0).start..span_of(&src, "0 }", 0).start + 1
    );
    let src = format!("model m\ndiscrete {{ period = x }}\n{body}");
    assert_eq!(one_error(&src).span(), span_of(&src, "x", 0));
    let src = format!("model m\ndiscrete {{ }}\n{body}");
    let d = one_error(&src);
    assert_eq!(d.message, "`discrete` needs `period`");
    assert_eq!(d.span(), span_of(&src, "discrete { }", 0));
    let src = format!("model m\ndiscrete {{ period = 1  periods = 2 }}\n{body}");
    let d = one_error(&src);
    assert_eq!(d.message, "unknown key `periods` in `discrete`");
    assert_eq!(d.span(), span_of(&src, "periods", 0));
    let src = format!("model m\ndiscrete {{ period = 1  period = 2 }}\n{body}");
    let d = one_error(&src);
    assert_eq!(d.message, "`period` is given twice in `discrete`");
    assert_eq!(d.span(), span_of(&src, "period = 2", 0));
    let src = format!("model m\ndiscrete {{ period = 1 }}\ndiscrete {{ period = 2 }}\n{body}");
    let d = one_error(&src);
    assert_eq!(d.message, "`discrete` is given twice");
    assert_eq!(d.span(), span_of(&src, "discrete", 1));
    assert_eq!(d.labels[1].span, span_of(&src, "discrete", 0));
}

/// The period is a constant expression of the constants above it; `t` is `k * period` in the
/// map.
#[test]
fn period_from_constants() {
    let m = model(
        "model m\nconst h = 1 / 8\ndiscrete { period = 2 * h }\nstate x in [0, 1]\n\
         update { x = x + t }",
    );
    assert_eq!(m.time, Time::Discrete { period: 0.25 });
}

#[test]
fn continuous_settings_are_refused_at_their_keys() {
    for (field, key, message) in [
        ("rate = local", "rate", "`rate`"),
        ("integrator = rk4", "integrator", "`integrator`"),
        ("transform = auto", "transform", "`transform`"),
        ("first_order = off", "first_order", "`first_order`"),
        ("split = [2, 1]", "split", "`split`"),
        (
            "radius = paper(eps = 0.1)  guarantee = pointwise",
            "radius",
            "`radius = paper(..)`",
        ),
        ("inclusion = mixed", "inclusion", "`inclusion = mixed`"),
        (
            "metric = auto(states = [x1])",
            "metric",
            "`metric = auto(states = [..])`",
        ),
    ] {
        let src = chain_with(&format!("analysis a {{ horizon = 1  {field} }}"));
        let d = one_error(&src);
        assert_eq!(
            d.message,
            format!("{message} does not apply to discrete-time models")
        );
        let analysis = span_of(&src, "analysis", 0).start;
        let key_at = src[analysis..].find(key).unwrap() + analysis;
        assert_eq!(d.span(), key_at..key_at + key.len(), "{field}");
        assert!(d
            .help
            .unwrap()
            .contains("does not apply to discrete-time models"));
    }
}

#[test]
fn allowed_settings_and_the_stored_spec() {
    let m = model(&chain_with(
        "analysis a { method = interval  delta = 1e-2  horizon = 1  step = 0.2 \
         metric = [[2, 0], [0, 1]]  radius = amgf  guarantee = pointwise  inclusion = natural \
         outputs = [x2] }\n\
         analysis b { horizon = 0.3  metric = auto }",
    ));
    let a = &m.analyses[0].spec;
    assert_eq!(a.method, Method::Interval);
    assert_eq!(a.delta, 1e-2);
    assert_eq!(a.guarantee, Guarantee::Pointwise);
    assert_eq!(a.outputs, [1]);
    assert_eq!(a.metric, MetricChoice::Matrix(vec![1.0, 0.0, 0.0, 0.5]));
    assert_eq!(a.rate, Rate::Local);
    assert_eq!(a.integrator, Integrator::Validated);
    assert!(!a.first_order);
    assert_eq!(a.split, Split::Off);
    assert_eq!(a.transform, None);
    let b = &m.analyses[1].spec;
    assert_eq!(b.metric, MetricChoice::Auto);
    assert!(!b.first_order);
}

/// Horizons and steps are stored as exactly `K * period` and `j * period`; the step defaults
/// to one period.
#[test]
fn horizon_and_step_are_whole_periods() {
    let m = model(&chain_with(
        "analysis a { horizon = 0.3 }\n\
         analysis b { horizon = 0.3 + 1e-12  step = 0.2 }\n\
         analysis c { horizon = 1  step = 0.3 - 1e-12 }",
    ));
    let times: Vec<(u64, u64)> = m
        .analyses
        .iter()
        .map(|a| (a.spec.horizon.to_bits(), a.spec.step.to_bits()))
        .collect();
    let bits = |k: f64| (k * 0.1f64).to_bits();
    assert_eq!(
        times,
        [
            (bits(3.0), bits(1.0)),
            (bits(3.0), bits(2.0)),
            (bits(10.0), bits(3.0))
        ]
    );
    assert_eq!(m.analyses[0].spec.horizon, 0.30000000000000004);
}

#[test]
fn horizon_and_step_errors_name_the_nearest_valid_values() {
    let src = chain_with("analysis a { horizon = 0.25 }");
    let d = one_error(&src);
    assert_eq!(
        d.message,
        "the horizon of a discrete-time model is a whole number of periods (0.1), but it is \
         0.25 (2.5 periods)"
    );
    assert_eq!(d.span(), span_of(&src, "0.25", 0));
    assert_eq!(
        d.help.as_deref(),
        Some("write `horizon = 0.2` (2 periods) or `horizon = 0.3` (3 periods)")
    );
    let d = one_error(&chain_with("analysis a { horizon = 0.05 }"));
    assert_eq!(d.help.as_deref(), Some("write `horizon = 0.1` (1 period)"));
    let src = chain_with("analysis a { horizon = 0.3  step = 0.5 }");
    let d = one_error(&src);
    assert_eq!(
        d.message,
        "the report step is 5 periods, longer than the horizon's 3"
    );
    assert_eq!(d.span(), span_of(&src, "0.5", 0));
    assert_eq!(d.help.as_deref(), Some("write `step = 0.3` (3 periods)"));
    let d = one_error(&chain_with("analysis a { horizon = 1  step = 0.15 }"));
    assert_eq!(
        d.help.as_deref(),
        Some("write `step = 0.1` (1 period) or `step = 0.2` (2 periods)")
    );
    let d = one_error(&chain_with("analysis a { horizon = -1 }"));
    assert_eq!(d.message, "the horizon must be positive, but it is -1");
}
