//! Property tests for the front end (parser and checker): it never panics, and every
//! diagnostic span lies within the source on char boundaries, for random text, token soups
//! and mutated valid specs.

use proptest::prelude::*;
use std::path::Path;

use reachc_compiler::driver::check_source;
use reachc_compiler::syntax::parse;

/// A valid spec exercising every item kind (with a non-ASCII comment).
const VALID: &str = "/// Doc line.
model demo // θ in a comment
const g = 10
const K1 = -20
state theta in [-pi/10, pi/10]
state x[1..3] in [-1, 1]
state c = 0.5
state z
state q
input u in [-1, 1]
noise w
noise v[1..3]
table ref = csv(\"unicycle_ref.csv\")
let e = theta - ref.px
for i in 1..3 { let y[i] = x[i] * 2 }
drift {
  theta' = g * sin(theta) + K1 * theta - 2^-x[1]^2 + u
  for i in 2..3 { x[i]' = x[i-1] - x[i] }
  x[1]' = -x[1]
  c' = min(c, 1, e) / (1 + c)
  z' = -z + q
  q' = -q * y[2]
}
diffusion { theta: 0.1 * w; x[1]: v[1] }
domain { theta in [-1, 1] }
initial ball { over = [z, q] center = [0, 0] radius = .5 metric = [[1, 0], [0, 2.]] }
unsafe wall halfspace { theta + 2 * c >= 3 }
unsafe b box { theta in [1, 2] c in [3, 4] }
unsafe s ball { over = [theta, c] center = [2, 3] radius = 1e-1 }
analysis main { delta = 1e-3 horizon = 4 step = 0.01 metric = auto radius = paper(eps = 1/16) guarantee = pointwise }
";

/// Words, numbers and punctuation of the language (plus a few stray characters).
const VOCAB: &[&str] = &[
    "model",
    "const",
    "state",
    "input",
    "noise",
    "table",
    "let",
    "for",
    "in",
    "drift",
    "diffusion",
    "domain",
    "discrete",
    "update",
    "initial",
    "unsafe",
    "analysis",
    "ball",
    "box",
    "halfspace",
    "csv",
    "x",
    "y",
    "w",
    "t",
    "pi",
    "e",
    "inf",
    "nan",
    "sin",
    "paper",
    "eps",
    "1",
    "0.4",
    "1e-3",
    "2.5E+2",
    ".5",
    "5.",
    "1e999",
    "2x",
    "\"p.csv\"",
    "\"open",
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    ",",
    ";",
    ":",
    "'",
    "=",
    "+",
    "-",
    "*",
    "/",
    "^",
    ".",
    "..",
    "<=",
    ">=",
    "<",
    "//",
    "///",
    "/*",
    "*/",
    "\n",
    "θ",
    "€",
    "#",
    "\\",
];

/// Where the table of [`VALID`] lives.
fn specs_dir() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../specs"))
}

/// Checks the front end's contract on `src`: parse, then (if it parsed) check.
fn check(src: &str) -> Result<(), TestCaseError> {
    let (_, checked) = check_source(src, specs_dir());
    let (_spec, parsed) = parse(src);
    for d in parsed.iter().chain(&checked) {
        prop_assert!(!d.labels.is_empty(), "diagnostic without a label: {d:?}");
        for l in &d.labels {
            let s = &l.span;
            prop_assert!(
                s.start <= s.end && s.end <= src.len(),
                "span {s:?} out of range: {d:?}"
            );
            prop_assert!(
                src.is_char_boundary(s.start) && src.is_char_boundary(s.end),
                "span {s:?} not on char boundaries: {d:?}"
            );
        }
    }
    Ok(())
}

/// Rounds `i` down to a char boundary of `s`.
fn floor_boundary(s: &str, mut i: usize) -> usize {
    i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

#[derive(Clone, Debug)]
enum Mutation {
    Delete(usize, usize),
    Duplicate(usize, usize),
    Swap(usize, usize, usize),
}

fn apply(src: &str, m: &Mutation) -> String {
    let n = src.len();
    let range = |a: usize, len: usize| {
        let a = floor_boundary(src, a % (n + 1));
        let b = floor_boundary(src, a + len % 40);
        (a, b)
    };
    match *m {
        Mutation::Delete(a, len) => {
            let (a, b) = range(a, len);
            format!("{}{}", &src[..a], &src[b..])
        }
        Mutation::Duplicate(a, len) => {
            let (a, b) = range(a, len);
            format!("{}{}", &src[..b], &src[a..])
        }
        Mutation::Swap(a, len, c) => {
            let (a, b) = range(a, len);
            let (c, d) = range(c, len);
            let ((a, b), (c, d)) = if a <= c {
                ((a, b), (c, d))
            } else {
                ((c, d), (a, b))
            };
            if b > c {
                return src.to_string();
            }
            format!(
                "{}{}{}{}{}",
                &src[..a],
                &src[c..d],
                &src[b..c],
                &src[a..b],
                &src[d..]
            )
        }
    }
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), any::<usize>()).prop_map(|(a, l)| Mutation::Delete(a, l)),
        (any::<usize>(), any::<usize>()).prop_map(|(a, l)| Mutation::Duplicate(a, l)),
        (any::<usize>(), any::<usize>(), any::<usize>())
            .prop_map(|(a, l, c)| Mutation::Swap(a, l, c)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn random_strings(src in any::<String>()) {
        check(&src)?;
    }

    #[test]
    fn random_syntax_chars(src in "[a-z0-9 \n.'=+*/^()\\[\\]{},;:<>\"θ_-]{0,300}") {
        check(&src)?;
        check(&format!("model m\n{src}"))?;
    }

    #[test]
    fn token_soup(words in prop::collection::vec((prop::sample::select(VOCAB), 0..3usize), 0..120)) {
        let mut src = String::new();
        for (w, sep) in words {
            src.push_str(w);
            src.push_str(["", " ", "\n"][sep]);
        }
        check(&src)?;
        check(&format!("model m\ndrift {{ {src}"))?;
    }

    #[test]
    fn mutated_valid_spec(ms in prop::collection::vec(mutation(), 1..6)) {
        let mut src = VALID.to_string();
        for m in &ms {
            src = apply(&src, m);
        }
        check(&src)?;
    }
}

#[test]
fn valid_spec_is_clean() {
    let (spec, diags) = parse(VALID);
    assert!(diags.is_empty(), "{diags:#?}");
    assert_eq!(spec.items.len(), 21);
    let (model, diags) = check_source(VALID, specs_dir());
    assert!(diags.is_empty(), "{diags:#?}");
    let model = model.unwrap();
    assert_eq!(model.states.len(), 7);
    assert_eq!(model.noises.len(), 4);
}

#[test]
fn deep_nesting_everywhere() {
    for open in ["(", "[", "-", "x[", "f(", "2^", "for i in 1..2 { "] {
        for prefix in [
            "model m\nconst k = ",
            "model m\ndrift { x' = ",
            "model m\ndrift { ",
        ] {
            let src = format!("{prefix}{}", open.repeat(10_000));
            check(&src).unwrap();
        }
    }
}
