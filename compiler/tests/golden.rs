//! Golden files: the complete generated `src/lib.rs` of two small shipped specs, the pendulum
//! (a transformed frame, lanes) and the Duffing oscillator (an input, state-dependent noise), so
//! that every change to the generated code shows as a snapshot diff (`cargo insta review`).
//! The text depends only on the spec and the reachc version: no paths, no timestamps.

use std::path::Path;

use reachc_compiler::backend::{codegen, prepare};

/// The `src/lib.rs` that `reachc build` writes for `specs/NAME.sde`.
fn lib_rs(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../specs")
        .join(format!("{name}.sde"));
    let mut model = reachc_compiler::driver::load(&path)
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .model;
    let prepared = prepare(&mut model);
    codegen::generate(&model, &prepared)
}

#[test]
fn pendulum_lib_rs() {
    insta::assert_snapshot!(lib_rs("pendulum"));
}

#[test]
fn duffing_lib_rs() {
    insta::assert_snapshot!(lib_rs("duffing"));
}
