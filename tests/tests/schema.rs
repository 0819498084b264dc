//! One schema (issue 30): the types the runtime writes result files and Monte Carlo reports
//! with (`reachc_runtime::report::schema`), which the plots read them with, read every such file
//! back and write it again as the same text: the analyses of shipped specs (their members in
//! full and as boxes), certified probabilities, a split, moving sets, non-finite numbers, and
//! Monte Carlo reports.

use reachc_e2e::{inline, shipped};
use reachc_runtime::engine::RunError;
use reachc_runtime::report::probability::Probabilities;
use reachc_runtime::report::result::{to_json, to_json_with, to_json_within};
use reachc_runtime::report::schema::{ResultJson, ShapeJson, SimJson};
use reachc_runtime::report::simulation;
use reachc_runtime::simulate::{self, Options};
use reachc_runtime::system::Paired;
use reachc_runtime::{Prs, Reach};

/// `again`, `text` read and written again, is `text` (else the first line that differs).
fn same(what: &str, text: &str, again: &str) {
    if let Some((k, (a, b))) = text
        .lines()
        .zip(again.lines())
        .enumerate()
        .find(|(_, (a, b))| a != b)
    {
        panic!("{what}: line {}: written {a:?}, again {b:?}", k + 1);
    }
    assert_eq!(text.len(), again.len(), "{what}");
}

/// A result file round-trips through [`ResultJson`].
fn result_round_trips(what: &str, text: &str) {
    let file: ResultJson = serde_json::from_str(text).unwrap_or_else(|e| panic!("{what}: {e}"));
    same(what, text, &file.to_text());
}

/// A Monte Carlo report round-trips through [`SimJson`].
fn report_round_trips(what: &str, text: &str) {
    let report: SimJson = serde_json::from_str(text).unwrap_or_else(|e| panic!("{what}: {e}"));
    same(what, text, &report.to_text());
}

/// Every analysis of some shipped specs (contraction and interval methods, transforms, several
/// metrics, first-order and box members, pointwise and uniform), written in full and with its
/// members as boxes.
#[test]
fn the_analyses_of_shipped_specs_round_trip() {
    for spec in ["pendulum.sde", "linear.sde", "msd.sde"] {
        let (sys, info) = shipped(spec);
        for analysis in info.analyses() {
            let what = format!("{spec} / {}", analysis.spec.name);
            let prs = match Reach::for_analysis(&sys, &info, analysis).and_then(|r| r.run()) {
                Ok(prs) => prs,
                Err(RunError::NoConstants(_) | RunError::Unsupported(_)) => continue,
                Err(e) => panic!("{what}: {e}"),
            };
            result_round_trips(&what, &to_json(&prs));
            if !prs.also().is_empty() {
                let boxed = to_json_within(&prs, Probabilities::default(), 0);
                assert!(boxed.contains("\"boxed\": true"), "{what}");
                result_round_trips(&format!("{what}, boxed"), &boxed);
            }
        }
    }
}

/// An unsafe set and two goals (reach, reach and stay), with the certified probabilities of
/// safety and of each goal (`reachc run --probability`).
#[test]
fn certified_probabilities_round_trip() {
    let (sys, info) = inline(
        "model ou\nstate x = 0\nnoise w\ndrift { x' = 1 - x }\ndiffusion { x: 0.2 * w }\n\
         unsafe low halfspace { x <= -0.6 }\n\
         goal up halfspace { x >= 0.3 } within [0.5, 2]\n\
         goal hold box { x in [0.3, 1.7] } within [1, 2] stay\n\
         goal far halfspace { x >= 5 }\n\
         analysis a { method = contraction  delta = 0.05  horizon = 2  step = 0.05 }",
    );
    let reach = Reach::paired(&sys, &info, "a").unwrap();
    let prs = reach.run().unwrap();
    let safety = reach.safety_probability().unwrap();
    let goals: Vec<_> = (0..3).map(|g| reach.goal_probability(g).unwrap()).collect();
    let text = to_json_with(
        &prs,
        Probabilities {
            safety: Some(&safety),
            goals: &goals,
        },
    );
    for key in ["safety_probability", "\"not_shown\"", "\"reached\""] {
        assert!(text.contains(key), "{key}");
    }
    result_round_trips("goals and probabilities", &text);
}

/// A split's union with its pieces in brief.
#[test]
fn a_split_round_trips() {
    let (sys, info) = inline(
        "model wide\nstate x in [-1.2, 1.2]\nstate v in [-1, 1]\nnoise w\n\
         drift {\n x' = v\n v' = -4 * sin(x) - 0.5 * v\n}\ndiffusion {\n v: 0.05 * w\n}\n\
         unsafe far halfspace { x >= 1.35 }\n\
         analysis a {\n method = contraction\n metric = auto\n delta = 1e-2\n horizon = 1\n \
         step = 0.05\n split = [2, 2]\n}\n",
    );
    let prs = Reach::paired(&sys, &info, "a").unwrap().run().unwrap();
    assert_eq!(prs.pieces().len(), 4);
    result_round_trips("split", &to_json(&prs));
}

/// Moving unsafe sets (a half-space, a ball, a box) and a moving goal, with their positions.
#[test]
fn moving_sets_round_trip() {
    let prs = moving();
    let text = to_json(&prs);
    assert!(text.contains("\"swept\""));
    result_round_trips("moving sets", &text);
    // Each position reads back as the shape written.
    let file: ResultJson = serde_json::from_str(&text).unwrap();
    for (u, verdict) in prs.unsafe_sets().iter().zip(&file.unsafe_sets) {
        assert_eq!(u.swept.len(), verdict.swept.len(), "{}", u.name);
        for (shape, read) in u.swept.iter().zip(&verdict.swept) {
            let written = serde_json::to_value(ShapeJson::of(prs.states(), shape)).unwrap();
            assert_eq!(serde_json::to_value(read).unwrap(), written);
        }
    }
}

fn moving() -> Prs {
    let (sys, info) = inline(
        "model mv\nstate x = 0\nstate y = 0\nnoise w\ndrift {\n x' = 1\n y' = -y\n}\n\
         diffusion {\n x: 0.1 * w\n y: 0.1 * w\n}\n\
         unsafe wall halfspace { x >= 3 + 0.5 * t }\n\
         unsafe drone ball { over = [x, y]  center = [5 - t, 2]  radius = 0.5 + 0.1 * t }\n\
         unsafe gate box { x in [4 + t, 5 + t] }\n\
         goal home box { x in [-2 + t, 2 + t] } within [0.5, 1]\n\
         analysis a { method = contraction  delta = 0.1  horizon = 1  step = 0.1 }\n",
    );
    Reach::paired(&sys, &info, "a").unwrap().run().unwrap()
}

/// Numbers that may be non-finite are written as `null` and read back as non-finite numbers
/// (unbounded ends of ranges), so they are written as `null` again.
#[test]
fn non_finite_numbers_round_trip() {
    let mut file: ResultJson = serde_json::from_str(&to_json(&moving())).unwrap();
    let step = &mut file.steps[1];
    (step.c, step.sigma, step.psi) = (f64::INFINITY, f64::NAN, f64::INFINITY);
    step.margins[0] = f64::NEG_INFINITY;
    step.prs_hull_hi[0] = f64::INFINITY;
    let u = &mut file.unsafe_sets[0];
    (u.min_margin, u.min_margin_t) = (f64::INFINITY, f64::NAN);
    let g = &mut file.goals[0];
    (g.window[1], g.margins[0], g.margin) = (f64::INFINITY, f64::NAN, Some(f64::INFINITY));
    (file.kappa, file.constants.c) = (f64::INFINITY, f64::NAN);
    let text = file.to_text();
    assert!(text.contains("\"margin\": null"), "{text}");
    result_round_trips("non-finite numbers", &text);
    let back: ResultJson = serde_json::from_str(&text).unwrap();
    assert!(back.steps[1].c.is_nan() && back.goals[0].margin.is_some_and(f64::is_nan));
    assert_eq!(back.goals[0].window, [0.5, f64::INFINITY]);
}

/// Monte Carlo reports: of the pendulum (its per-state spreads), and of a model with an unsafe
/// set and goals checked against certified bounds.
#[test]
fn monte_carlo_reports_round_trip() {
    let (sys, info) = shipped("pendulum.sde");
    let prs = Reach::paired(&sys, &info, "contraction")
        .unwrap()
        .run()
        .unwrap();
    let opts = Options {
        paths: 200,
        seed: 1,
        ..Options::default()
    };
    let report =
        simulate::simulate(&Paired::new(&sys, &info), &prs, &opts, &mut |_, _| {}).unwrap();
    report_round_trips("pendulum", &simulation::to_json(&report));

    let (sys, info) = inline(
        "model ou\nstate x = 0\nnoise w\ndrift { x' = 1 - x }\ndiffusion { x: 0.2 * w }\n\
         unsafe low halfspace { x <= -0.6 }\n\
         goal up halfspace { x >= 0.3 } within [0.5, 2]\n\
         analysis a { method = contraction  delta = 0.05  horizon = 2  step = 0.05 }",
    );
    let prs = Reach::paired(&sys, &info, "a").unwrap().run().unwrap();
    let opts = Options {
        paths: 500,
        seed: 2,
        safety_bound: Some(0.5),
        goal_bounds: vec![Some(0.9)],
        ..Options::default()
    };
    let report =
        simulate::simulate(&Paired::new(&sys, &info), &prs, &opts, &mut |_, _| {}).unwrap();
    let text = simulation::to_json(&report);
    assert!(text.contains("\"safety\": {") && text.contains("\"goals\""));
    report_round_trips("goals", &text);
}
