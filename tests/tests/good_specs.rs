//! Specs in `tests/good/` that stress the language (not shipped as examples) must check.

use reachc_compiler::driver::load;
use reachc_e2e::{relative, workspace};

#[test]
fn rust_keywords_are_valid_names() {
    let path = workspace().join("tests/good/rust_keywords.sde");
    let model = load(&path)
        .unwrap_or_else(|e| panic!("{}:\n{e}", relative(&path)))
        .model;
    assert_eq!(model.name, "fn");
    let states: Vec<&str> = model.states.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(states, ["type", "impl"]);
    assert_eq!(model.inputs[0].name, "where");
    assert_eq!(model.noises[0].name, "loop");
    assert_eq!(model.analyses[0].spec.name, "async");
    assert_eq!(model.constants, [("self".to_string(), 2.0)]);
}
