//! Every ```sde example in docs/language.md parses (fragments get a `model` line first).

use reachc_compiler::syntax::parse;
use reachc_e2e::workspace;

#[test]
fn language_reference_examples_parse() {
    let text = std::fs::read_to_string(workspace().join("docs/language.md")).unwrap();
    let mut blocks = 0;
    for (k, block) in text.split("```sde\n").skip(1).enumerate() {
        let code = block.split("```").next().unwrap();
        let has_model = code.lines().any(|l| l.trim_start().starts_with("model "));
        let src = if has_model {
            code.to_string()
        } else {
            format!("model doc_example\n{code}")
        };
        let (_, diags) = parse(&src);
        assert!(
            diags.is_empty(),
            "example {} does not parse:\n{src}\n{diags:#?}",
            k + 1
        );
        blocks += 1;
    }
    assert!(blocks >= 20, "only {blocks} examples found");
}
