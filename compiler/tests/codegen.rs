//! Code generation on every shipped spec: the generated `lib.rs` parses, is deterministic, has
//! no inner attributes, and spec names cannot inject code.

use std::path::{Path, PathBuf};

use reachc_compiler::backend::codegen::{
    generate, generate_with, main_rs, Options, LANES_MAX_STATES,
};
use reachc_compiler::backend::{mangle, prepare};
use reachc_compiler::model::Model;

fn specs() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../specs");
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "sde"))
        .collect();
    out.sort();
    assert!(!out.is_empty());
    out
}

/// Loads and prepares the spec, and generates its code twice (to check determinism).
fn generate_for(path: &Path) -> (Model, String, String) {
    let mut model = reachc_compiler::driver::load(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .model;
    let prepared = prepare(&mut model);
    let code = generate(&model, &prepared);
    let again = generate(&model, &prepared);
    (model, code, again)
}

#[test]
fn every_shipped_spec_generates_parsable_deterministic_code() {
    for path in specs() {
        let (model, code, again) = generate_for(&path);
        let name = path.display();
        let file = syn::parse_file(&code).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(file.attrs.is_empty(), "{name}: inner attributes");
        assert!(!code.contains("#!"), "{name}: contains #!");
        assert!(!code.contains("//!"), "{name}: contains //!");
        assert!(code == again, "{name}: not deterministic");
        let ty = mangle::type_name(&model.name);
        assert!(code.contains(&format!("pub struct {ty};")), "{name}");
        assert!(
            code.contains(&format!("impl reachc_runtime::System for {ty}")),
            "{name}"
        );
        for method in [
            "drift",
            "jac_x",
            "jac_u",
            "diffusion",
            "drift_interval",
            "jac_x_interval",
            "jac_u_interval",
            "diffusion_interval",
        ] {
            assert!(code.contains(&format!("fn {method}(")), "{name}: {method}");
        }
        // The drift in lanes exactly for small models without inputs.
        let lanes = model.inputs.is_empty() && model.states.len() <= LANES_MAX_STATES;
        assert_eq!(code.contains("fn drift_x8("), lanes, "{name}: drift_x8");
        assert!(code.contains("pub fn info() -> reachc_runtime::system::ModelInfo"));
        assert!(code.contains(&format!("pub const N: usize = {};", model.states.len())));
        if !model.tables.is_empty() {
            assert!(code.contains("static T0_TIMES: [f64;"), "{name}");
            assert!(code.contains("reachc_runtime::table::eval("), "{name}");
        }
    }
}

#[test]
fn hostile_names_and_docs_stay_text() {
    let dir = std::env::temp_dir().join(format!("reachc-codegen-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("evil.sde");
    std::fs::write(
        &path,
        "/// } fn evil() { \"quote\" */\n\
         /// ```rust\n\
         ///     compile_error!(\"doctest\");\n\
         model fn\n\
         state type in [0, 1]\n\
         state self in [0, 1]\n\
         noise w\n\
         drift {\n    type' = -self\n    self' = sin(type) - self\n}\n\
         diffusion {\n    self: 0.1 * w\n}\n\
         analysis a {\n    horizon = 1\n}\n",
    )
    .unwrap();
    let (model, code, _) = generate_for(&path);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(model.name, "fn");
    let file = syn::parse_file(&code).unwrap_or_else(|e| panic!("{e}\n{code}"));
    // No item named `evil`, and every mention of it is inside a doc comment.
    for item in &file.items {
        if let syn::Item::Fn(f) = item {
            assert_ne!(f.sig.ident, "evil");
        }
    }
    for line in code.lines().filter(|l| l.contains("fn evil")) {
        assert!(line.trim_start().starts_with("///"), "{line}");
    }
    // The doc is fenced with more backticks than it contains (no doctest can start).
    assert!(code.contains("/// ````text"), "{code}");
    assert!(code.contains("pub struct FnModel;"), "{code}");
    assert!(code.contains(r#"String::from("type")"#) && code.contains(r#"String::from("self")"#));
    assert!(!code.contains("#!"));
}

/// A spec using every node kind and function (tables included).
const ALL_FUNCS: &str = r#"
model all_funcs
state a in [0.5, 1]
state b in [-0.2, 0.2]
state c in [1, 2]
input u in [-0.1, 0.1]
noise w1
noise w2
table ref = csv("unicycle_ref.csv")
drift {
    a' = sin(a*b) * cos(a) + u - a/b^2 + 1/(a*c) - tan(b) + exp(-b) + log(c^2 + 2) + sqrt(c) + abs(b)
    b' = atan(a) + sinh(b) - cosh(b) + tanh(a - b) + sinc(b) + atan2(b, a) + atan2(2, a) + min(a, b, -1) + max(a, 0.5)
    c' = c^0.5 + 2^a + (a + 2)^c - c^(-3) * a + ref.px * t - ref.theta + a^3 * b^(-2) * c - 3 - 2*u*t
}
diffusion {
    a: 0.1 * w1 + b * w2
    b: sin(a) * w2
    c: sqrt(c) * w1
}
analysis x {
    horizon = 1
}
"#;

#[test]
fn every_node_kind_generates() {
    let dir = std::env::temp_dir().join(format!("reachc-codegen-all-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let specs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../specs");
    std::fs::copy(specs.join("unicycle_ref.csv"), dir.join("unicycle_ref.csv")).unwrap();
    let path = dir.join("all_funcs.sde");
    std::fs::write(&path, ALL_FUNCS).unwrap();
    let (_, code, again) = generate_for(&path);
    std::fs::remove_dir_all(&dir).unwrap();
    syn::parse_file(&code).unwrap_or_else(|e| panic!("{e}\n{code}"));
    assert!(code == again);
    for snippet in [
        "pub struct AllFuncs;",
        // Sum: constant first, subtraction for negative coefficients, unit coefficients bare
        "-3.0 + v",
        "- 2.0 * v",
        // Product: numerator / denominator
        "1.0 / (x[0] * x[2])",
        "x[0] / x[1].powi(2)",
        "Interval::point(1.0) / (x[0] * x[2])",
        // constant receivers in function-call form
        "f64::atan2(2.0, x[0])",
        "f64::powf(2.0, x[0])",
        "Interval::pow(Interval::point(2.0), x[0])",
        "f64::min(-1.0, v",
        "Interval::max(Interval::point(0.5), x[0])",
        // shared special functions and tables
        "reachc_runtime::func::sinc(x[1])",
        "reachc_runtime::func::dsinc(x[1])",
        "reachc_runtime::func::dsinc_interval(x[1])",
        "reachc_runtime::func::sign(x[1])",
        "x[1].sign()",
        "reachc_runtime::table::eval(&T0_TIMES, &T0_C0, t)",
        "reachc_runtime::table::eval_interval(&T0_TIMES, &T0_C2, t)",
        "static T0_TIMES: [f64; 101]",
        "static T0_C0: [f64; 101]",
    ] {
        assert!(code.contains(snippet), "missing {snippet:?}:\n{code}");
    }
    // column 1 (ref.py) is never read, so it is not embedded
    assert!(!code.contains("T0_C1"));
}

/// The text of the generated method `name` (from its `fn` to the next method).
fn method_text<'a>(code: &'a str, name: &str) -> &'a str {
    let start = code
        .find(&format!("fn {name}("))
        .unwrap_or_else(|| panic!("no {name}:\n{code}"));
    let rest = &code[start..];
    let end = rest[1..].find("\n    fn ").map_or(rest.len(), |e| e + 1);
    &rest[..end]
}

#[test]
fn small_models_without_inputs_get_a_drift_in_lanes() {
    // tests/good/lanes.sde: no inputs, four states, every function of lanes and of `t` alone.
    let lanes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/good/lanes.sde");
    let (model, code, _) = generate_for(&lanes);
    assert!(model.inputs.is_empty() && model.states.len() == LANES_MAX_STATES);
    let x8 = method_text(&code, "drift_x8");
    assert!(
        x8.starts_with(
            "fn drift_x8(\n        &self,\n        x: &[reachc_runtime::X8],\n        t: f64,\n        \
             out: &mut [reachc_runtime::X8],\n    )"
        ),
        "{x8}"
    );
    for snippet in [
        // functions of lanes: methods and maps of the runtime's functions
        "x[1].tan()",
        ".map(reachc_runtime::func::sinc)",
        ".map(reachc_runtime::func::sign)",
        // `t` alone stays f64
        "reachc_runtime::func::sinc(t)",
        "t.sin()",
        // an f64 receiver of an argument in lanes is widened
        "reachc_runtime::X8::splat(2.0).atan2(x[0])",
        "reachc_runtime::X8::splat(t).atan2(x[0])",
        "reachc_runtime::X8::splat(2.0).powf(x[0])",
        "x[0].atan2(t)",
        "x[0].powf(t)",
        "t.atan2(2.0)",
        "reachc_runtime::X8::max(x[0], t)",
        "reachc_runtime::X8::min(-1.0, ",
        "reachc_runtime::X8::max(0.5, x[0])",
        "f64::max(1.0, t)",
        "reachc_runtime::table::eval(&T0_TIMES, &T0_C0, t)",
        // an output of `t` alone and a constant one, in every lane
        "out[3] = reachc_runtime::X8::splat(3.0);",
    ] {
        assert!(x8.contains(snippet), "missing {snippet:?}:\n{x8}");
    }
    assert!(x8.contains("out[2] = reachc_runtime::X8::splat(v"), "{x8}");
    // The scalar drift is the same text over f64.
    let drift = method_text(&code, "drift");
    assert!(drift.contains("f64::atan2(2.0, x[0])") && drift.contains("out[3] = 3.0;"));
    assert!(!drift.contains("X8") && !method_text(&code, "drift_interval").contains("X8"));

    // Entries that are leaves: zero, `t`, a state.
    let leaves = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/good/lanes_leaves.sde");
    let x8 = method_text(&generate_for(&leaves).1, "drift_x8").to_string();
    for snippet in [
        "out[0] = reachc_runtime::X8::splat(0.0);",
        "out[1] = reachc_runtime::X8::splat(t);",
        "out[2] = x[1];",
    ] {
        assert!(x8.contains(snippet), "missing {snippet:?}:\n{x8}");
    }

    // With an input (the Rust keywords' `where`), more states (linear_n: 10) or a drift split
    // into helpers: no drift_x8 (the trait's default, per lane).
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let (model, code, _) = generate_for(&root.join("tests/good/rust_keywords.sde"));
    assert!(!model.inputs.is_empty() && !code.contains("X8"), "{code}");
    let (model, code, _) = generate_for(&root.join("specs/linear_n.sde"));
    assert!(
        model.states.len() > LANES_MAX_STATES && !code.contains("X8"),
        "{code}"
    );
    let mut model = reachc_compiler::driver::load(&lanes).unwrap().model;
    let prepared = prepare(&mut model);
    let split = Options {
        split_above: 3,
        chunk_size: 3,
    };
    let code = generate_with(&model, &prepared, &split);
    assert!(
        code.contains("fn drift_part0(") && !code.contains("X8"),
        "{code}"
    );
}

#[test]
fn main_rs_calls_the_runtime() {
    let text = main_rs(
        &mangle::crate_ident(&mangle::crate_name("van_der_pol")),
        &mangle::type_name("van_der_pol"),
    );
    syn::parse_file(&text).unwrap();
    assert!(text
        .contains("reachc_runtime::app::main_with(&van_der_pol::VanDerPol, &van_der_pol::info())"));
}
