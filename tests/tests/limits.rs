//! The front end's limits (docs/language.md, "Limits"): hostile or oversized input is rejected
//! at once, with one diagnostic whose span is short and points at the cause. Big inputs are
//! generated here rather than stored in tests/bad.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use reachc_compiler::diagnostics::{render, Diagnostic};
use reachc_compiler::driver::{check_source, load, LoadError};
use reachc_compiler::limits::{
    MAX_HEIGHT, MAX_REPORT_STEPS, MAX_STATES, MAX_TABLE_LEN, MAX_UNROLLED, MIN_REPORT_STEP,
};

/// A fresh directory for one test's files.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("reachc-limits-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Checks `src` (tables relative to `dir`) and returns its errors, asserting it took under
/// two seconds (a limit must not itself be slow).
fn errors_in(src: &str, dir: &Path) -> Vec<Diagnostic> {
    let start = Instant::now();
    let (model, diags) = check_source(src, dir);
    assert!(
        start.elapsed() < Duration::from_secs(2),
        "check took {:?}",
        start.elapsed()
    );
    assert!(model.is_none() || diags.is_empty(), "{diags:#?}");
    diags
}

fn errors(src: &str) -> Vec<Diagnostic> {
    errors_in(src, Path::new("."))
}

/// The one error of `src`, with the text its span covers.
fn one_error(src: &str) -> (Diagnostic, String) {
    let diags = errors(src);
    assert_eq!(diags.len(), 1, "{diags:#?}");
    let span = diags[0].span();
    (diags[0].clone(), src[span].to_string())
}

const TAIL: &str = "analysis a { horizon = 1  step = 0.1 }\n";

#[test]
fn nested_loops_stop_at_the_unrolling_limit() {
    let vars = "abcdefghijkl";
    let mut body = String::new();
    for v in vars.chars() {
        body.push_str(&format!("for {v} in 1..10 {{ "));
    }
    body.push_str(&"} ".repeat(vars.len()));
    let src = format!("model m\nstate x in [0, 1]\ndrift {{ x' = -x }}\n{body}\n{TAIL}");
    let (d, at) = one_error(&src);
    assert_eq!(
        d.message,
        format!("`for` loops unroll to more than {MAX_UNROLLED} statements")
    );
    // The head of the loop where the budget ran out, not its body.
    assert!(at.starts_with("for ") && at.ends_with("1..10"), "{at}");
}

#[test]
fn huge_loops_and_families_are_rejected_at_once() {
    let src = format!(
        "model m\nstate x[1..1000000000] in [0, 1]\n\
         drift {{ for i in 1..1000000000 {{ x[i]' = -x[i] }} }}\n{TAIL}"
    );
    let diags = errors(&src);
    assert_eq!(diags.len(), 2, "{diags:#?}");
    assert_eq!(
        diags[0].message,
        "the family `x[1..1000000000]` has 1000000000 elements"
    );
    assert_eq!(&src[diags[0].span()], "1..1000000000");
    assert_eq!(
        diags[1].message,
        format!("`for` loops unroll to more than {MAX_UNROLLED} statements")
    );
    assert_eq!(&src[diags[1].span()], "for i in 1..1000000000");
    // Element counts of far-apart ends are exact.
    let (d, at) = one_error(&format!(
        "model m\nnoise w[-1000000000000000..1000000000000000]\n\
         state x in [0, 1]\ndrift {{ x' = -x }}\n{TAIL}"
    ));
    assert_eq!(
        d.labels[0].message,
        format!("a model has at most {MAX_STATES} noise channels")
    );
    assert_eq!(
        d.message,
        "the family `w[-1000000000000000..1000000000000000]` has 2000000000000001 elements"
    );
    assert_eq!(at, "-1000000000000000..1000000000000000");
}

#[test]
fn states_inputs_and_noises_are_counted_across_declarations() {
    let at_limit = format!(
        "model m\nstate x[1..{MAX_STATES}] in [0, 1]\n\
         drift {{ for i in 1..{MAX_STATES} {{ x[i]' = -x[i] }} }}\n{TAIL}"
    );
    assert!(errors(&at_limit).is_empty());
    let one_more = at_limit.replace("drift", "state y in [0, 1]\ndrift");
    let (d, at) = one_error(&one_more);
    assert_eq!(d.message, "too many states");
    assert_eq!(at, "y");
    let (d, at) = one_error(&format!(
        "model m\ninput u[0..{MAX_STATES}] in [0, 1]\nstate x in [0, 1]\ndrift {{ x' = -x }}\n{TAIL}"
    ));
    assert_eq!(
        d.message,
        format!("the family `u[0..{MAX_STATES}]` has 2001 elements")
    );
    assert_eq!(at, format!("0..{MAX_STATES}"));
}

#[test]
fn report_steps_are_bounded_in_check() {
    let spec = |fields: &str| {
        format!("model m\nstate x in [0, 1]\ndrift {{ x' = -x }}\nanalysis a {{ {fields} }}\n")
    };
    let too_many = |steps: &str| {
        format!("{steps} report steps (horizon / step); at most {MAX_REPORT_STEPS:e}")
    };
    let too_short = |step: &str| format!("the report step is {step}; at least {MIN_REPORT_STEP:e}");
    for (fields, at, message) in [
        ("horizon = 1e6  step = 0.01", "0.01", too_many("1.000e8")),
        ("horizon = 1e9  step = 1e-3", "1e-3", too_many("1.000e12")),
        // Short steps: the integrators' subdivisions would be subnormal (a horizon of 1e-320
        // with the default step hung `run`).
        ("horizon = 1  step = 1e-300", "1e-300", too_short("1e-300")),
        ("horizon = 1e-320", "1e-320", too_short("1e-322")),
        (
            "horizon = 1e-99  step = 1e-101",
            "1e-101",
            too_short("1e-101"),
        ),
    ] {
        let (d, span) = one_error(&spec(fields));
        assert_eq!(d.message, message);
        assert_eq!(span, at);
    }
    assert!(errors(&spec("horizon = 1e5  step = 1")).is_empty());
    assert!(errors(&spec("horizon = 1e-98  step = 1e-100")).is_empty());
}

#[test]
fn long_expressions_are_labelled_at_one_operator() {
    // One term a line, as generated code would write it: the report shows one line.
    let sum = vec!["x"; MAX_HEIGHT + 2].join(" +\n");
    let src = format!("model m\nstate x in [0, 1]\ndrift {{ x' = {sum} }}\n{TAIL}");
    let (d, at) = one_error(&src);
    assert_eq!(d.message, "expression too long");
    assert_eq!(at, "+");
    // The operator that passes the limit: the one after MAX_HEIGHT of them.
    let nth_plus = src.match_indices('+').nth(MAX_HEIGHT).unwrap().0;
    assert_eq!(d.span(), nth_plus..nth_plus + 1);
    assert!(render(&[d], "m.sde", &src, false).len() < 2_000);
    let at_limit = vec!["x"; MAX_HEIGHT + 1].join(" + ");
    assert!(errors(&format!(
        "model m\nstate x in [0, 1]\ndrift {{ x' = {at_limit} }}\n{TAIL}"
    ))
    .is_empty());
}

#[test]
fn a_glued_raw_identifier_is_one_error() {
    let src = "model m\nstate x = 0\nnoise r#x\ndrift { x' = 0 }\n";
    let (d, at) = one_error(src);
    assert_eq!(d.message, "unexpected character `#`");
    assert_eq!(at, "#");
}

#[test]
fn invalid_utf8_is_located() {
    let dir = temp_dir("utf8");
    let path = dir.join("bad.sde");
    std::fs::write(
        &path,
        b"model m\nstate x = 0 // caf\xe9\ndrift { x' = 0 }\n",
    )
    .unwrap();
    let Err(LoadError::Spec {
        diagnostics,
        source,
        ..
    }) = load(&path)
    else {
        panic!("invalid UTF-8 is a spec error");
    };
    assert_eq!(diagnostics.len(), 1);
    assert_eq!(diagnostics[0].span().start, 26);
    let shown = render(&diagnostics, "bad.sde", &source, false);
    assert!(shown.contains("bad.sde:2:19"), "{shown}");
    assert!(shown.contains("invalid byte 0xe9 (offset 26)"), "{shown}");
}

/// A spec over the table `t.csv` holding `csv`, in its own directory.
fn table_spec(name: &str, csv: &[u8]) -> (String, PathBuf) {
    let dir = temp_dir(name);
    std::fs::write(dir.join("t.csv"), csv).unwrap();
    let src = format!(
        "model m\nstate x in [0, 1]\ntable r = csv(\"t.csv\")\ndrift {{ x' = r.y - x }}\n{TAIL}"
    );
    (src, dir)
}

#[test]
fn tables_are_capped() {
    let mut big = b"t,y\n".to_vec();
    while big.len() <= MAX_TABLE_LEN {
        big.extend_from_slice(format!("{},1\n", big.len()).as_bytes());
    }
    let (src, dir) = table_spec("big", &big);
    let diags = errors_in(&src, &dir);
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(
        diags[0].labels[0].message,
        format!("t.csv: the file is larger than the limit of {MAX_TABLE_LEN} bytes (8 MiB)")
    );
    assert_eq!(&src[diags[0].span()], "\"t.csv\"");
}

#[cfg(unix)]
#[test]
fn a_special_file_is_refused() {
    let src = format!(
        "model m\nstate x in [0, 1]\ntable r = csv(\"/dev/zero\")\ndrift {{ x' = r.y - x }}\n{TAIL}"
    );
    let diags = errors(&src);
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(
        diags[0].labels[0].message,
        "/dev/zero: not a regular file (a character device); a table is read from a CSV file"
    );
    assert_eq!(&src[diags[0].span()], "\"/dev/zero\"");
}

#[test]
fn documented_table_forms_are_accepted() {
    for (name, csv) in [
        (
            "comment",
            &b"# made by hand\nt,y\n0,1\n# between rows\n1,3\n"[..],
        ),
        ("crlf", b"t,y\r\n0,1\r\n1,3\r\n"),
        ("spaces", b"t, y\n0, 1\n 1 ,3 \n"),
        ("blank", b"t,y\n\n0,1\n\n1,3\n"),
    ] {
        let (src, dir) = table_spec(name, csv);
        let (model, diags) = check_source(&src, &dir);
        assert!(diags.is_empty(), "{name}: {diags:#?}");
        let table = &model.unwrap().tables[0];
        assert_eq!(table.columns, ["y"], "{name}");
        assert_eq!(table.times, [0.0, 1.0], "{name}");
        assert_eq!(table.values, [vec![1.0, 3.0]], "{name}");
    }
}

#[test]
fn scaled_metrics_are_normalised_exactly() {
    let spec = |s: &str| {
        format!(
            "model m\nstate x in [0, 1]\nstate y in [0, 1]\ndrift {{ x' = -x  y' = -y }}\n\
             analysis a {{ horizon = 1  metric = [[2{s}, 1{s}], [1{s}, 3{s}]] }}\n"
        )
    };
    let metric = |s: &str| {
        let (model, diags) = check_source(&spec(s), Path::new("."));
        assert!(diags.is_empty(), "{s}: {diags:#?}");
        let model = model.unwrap();
        match &model.analyses[0].spec.metric {
            reachc_compiler::model::MetricChoice::Matrix(m) => m.clone(),
            other => panic!("{other:?}"),
        }
    };
    // Largest entry in [1, 2), by a power of two: 2*2^-1 = 1, 3*2^-1 = 1.5.
    assert_eq!(metric(""), [1.0, 0.5, 0.5, 1.5]);
    for s in ["e300", "e-300"] {
        let m = metric(s);
        let max = m.iter().fold(0.0f64, |a, v| a.max(*v));
        assert!((1.0..2.0).contains(&max), "{s}: {m:?}");
        // A power of two apart: the ratios of the entries are exactly the written ones'.
        let written: f64 = format!("3{s}").parse().unwrap();
        assert_eq!((written / m[3]).log2().fract(), 0.0, "{s}: {m:?}");
        assert_eq!(m[0] * 3.0 / 2.0, m[3], "{s}: {m:?}");
    }
}
