//! The bad-spec corpus: every file in `tests/bad/` must fail to load with diagnostics that
//! carry spans, and the rendered report is pinned by a snapshot.

use reachc_compiler::diagnostics::render;
use reachc_compiler::driver::{load, LoadError};
use reachc_e2e::relative;

#[test]
fn bad_specs_render_expected_diagnostics() {
    insta::glob!(
        concat!(env!("CARGO_MANIFEST_DIR"), "/bad"),
        "*.sde",
        |path| {
            let err = load(path).expect_err("a bad spec must not load");
            let LoadError::Spec {
                diagnostics,
                source,
                ..
            } = err
            else {
                panic!("{}: expected spec errors, got {err}", path.display());
            };
            assert!(!diagnostics.is_empty());
            for d in &diagnostics {
                let span = d.span();
                assert!(
                    span.start <= span.end && span.end <= source.len(),
                    "{}: span {span:?} outside the source",
                    path.display()
                );
            }
            insta::assert_snapshot!(render(&diagnostics, &relative(path), &source, false));
        }
    );
}

#[test]
fn many_errors_are_reported_in_one_run() {
    let path = reachc_e2e::workspace().join("tests/bad/many_errors.sde");
    let Err(LoadError::Spec { diagnostics, .. }) = load(&path) else {
        panic!("many_errors.sde must fail with spec errors");
    };
    // 1/0, [2, 1], zz, the second x', w * w, delta = 2, step = 3.
    assert!(
        diagnostics.len() >= 7,
        "only {} diagnostics: {diagnostics:#?}",
        diagnostics.len()
    );
}

#[test]
fn syntax_errors_in_separate_items_are_all_reported() {
    let path = reachc_e2e::workspace().join("tests/bad/syntax_many_errors.sde");
    let Err(LoadError::Spec { diagnostics, .. }) = load(&path) else {
        panic!("syntax_many_errors.sde must fail with spec errors");
    };
    assert!(diagnostics.len() >= 2, "{diagnostics:#?}");
}
