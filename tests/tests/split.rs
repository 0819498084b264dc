//! Splitting the initial set (`split = [..]`, method.md 8.11): the union of the pieces' sets,
//! each at the full delta, against the unsplit result, the pieces themselves, sampled flows
//! from the whole initial box and a Monte Carlo check of the union.

use reachc_e2e::inline;
use reachc_runtime::engine::{Culprit, Problem, RunError, Setting};
use reachc_runtime::model::Split;
use reachc_runtime::probability::SafetyLimit;
use reachc_runtime::prs::{DetSet, Prs, Verdict};
use reachc_runtime::report::simulation::summary;
use reachc_runtime::simulate::{self, Options};
use reachc_runtime::system::Paired;
use reachc_runtime::{Reach, System};

/// A pendulum-like flow from a wide box, where the first-order sets lose the flow's shape
/// (`tests/tests/linearised.rs`), with an unsafe half-space near the horizon's set; the
/// analyses differ only in their split.
fn spec(split: &str) -> String {
    format!(
        "model wide\nstate x in [-1.2, 1.2]\nstate v in [-1, 1]\nnoise w\n\
         drift {{\n x' = v\n v' = -4 * sin(x) - 0.5 * v\n}}\ndiffusion {{\n v: 0.05 * w\n}}\n\
         unsafe far halfspace {{ x >= 1.35 }}\n\
         analysis a {{\n method = contraction\n metric = auto\n delta = 1e-2\n horizon = 2\n \
         step = 0.05\n {split}\n}}\n"
    )
}

fn run(split: &str) -> Prs {
    let (sys, info) = inline(&spec(split));
    Reach::paired(&sys, &info, "a").unwrap().run().unwrap()
}

/// `split = [1, 1]` is one piece: the unsplit result, bit for bit.
#[test]
fn a_split_of_ones_is_the_unsplit_result() {
    let (plain, ones) = (run(""), run("split = [1, 1]"));
    assert!(ones.pieces().is_empty() && ones.split() == &Split::Off);
    assert_eq!(plain.steps(), ones.steps());
    assert_eq!(plain.unsafe_sets(), ones.unsafe_sets());
    assert_eq!(plain.verdict(), ones.verdict());
    assert_eq!(
        reachc_runtime::report::result::to_json(&plain),
        reachc_runtime::report::result::to_json(&ones)
    );
}

/// The union: per report time the bounding box of the pieces' sets, the smallest margin of any
/// piece, the verdict those give; membership in some piece; every noise-free flow from the
/// whole initial box inside; tighter than the unsplit result where the remainder dominated.
#[test]
fn the_union_holds_its_pieces_and_every_flow_and_is_tighter() {
    let (sys, info) = inline(&spec("split = [4, 3]"));
    let union = Reach::paired(&sys, &info, "a").unwrap().run().unwrap();
    let plain = run("");
    assert_eq!(union.split(), &Split::Counts(vec![4, 3]));
    assert_eq!(union.pieces().len(), 12);
    // The pieces tile the initial box: state x in 4 parts, v in 3, the cuts shared.
    let boxes: Vec<_> = union
        .pieces()
        .iter()
        .map(|p| p.initial().bounding_box().unwrap())
        .collect();
    assert_eq!((boxes[0][0].lo, boxes[0][1].lo), (-1.2, -1.0));
    assert_eq!((boxes[11][0].hi, boxes[11][1].hi), (1.2, 1.0));
    assert_eq!(boxes[0][1].hi, boxes[1][1].lo);
    assert_eq!(boxes[2][0].hi, boxes[3][0].lo);
    assert_eq!(boxes[0][0].hi, boxes[3][0].lo);
    for (k, st) in union.steps().iter().enumerate() {
        let hull = union.hull_at(k).unwrap();
        assert!(matches!(st.det, DetSet::Box { .. }) && st.r_t == 0.0);
        for p in union.pieces() {
            assert_eq!(p.steps()[k].t, st.t);
            for (u, q) in hull.iter().zip(p.hull_at(k).unwrap()) {
                assert!(u.lo <= q.lo && q.hi <= u.hi, "t = {}: {u:?} vs {q:?}", st.t);
            }
        }
        // The smallest margin of any piece, and one piece reaches each side of the hull.
        let least = union
            .pieces()
            .iter()
            .map(|p| p.steps()[k].margins[0])
            .fold(f64::INFINITY, f64::min);
        assert_eq!(st.margins[0], least);
        for (i, u) in hull.iter().enumerate() {
            assert!(union
                .pieces()
                .iter()
                .any(|p| p.hull_at(k).unwrap()[i].lo == u.lo));
            assert!(union
                .pieces()
                .iter()
                .any(|p| p.hull_at(k).unwrap()[i].hi == u.hi));
        }
    }
    // The verdict: the union meets the half-space where some piece's set does.
    let unsafe_pieces = union
        .pieces()
        .iter()
        .filter(|p| matches!(p.verdict(), Verdict::NotShownSafe { .. }))
        .count();
    assert_eq!(
        matches!(union.verdict(), Verdict::NotShownSafe { .. }),
        unsafe_pieces > 0
    );
    // Noise-free flows from a grid over the whole initial box (RK4, step 1e-3): in the union
    // at every report time, each in the piece it starts in.
    let mut out = [0.0; 2];
    for i in 0..=12 {
        for j in 0..=12 {
            let mut x = [-1.2 + 2.4 * i as f64 / 12.0, -1.0 + 2.0 * j as f64 / 12.0];
            let home = boxes
                .iter()
                .position(|b| {
                    b[0].lo <= x[0] && x[0] <= b[0].hi && b[1].lo <= x[1] && x[1] <= b[1].hi
                })
                .unwrap();
            let mut t = 0.0;
            for (k, st) in union.steps().iter().enumerate() {
                while t < st.t - 1e-12 {
                    let h = (st.t - t).min(1e-3);
                    let f = |y: [f64; 2], out: &mut [f64; 2]| sys.drift(&y, &[], 0.0, out);
                    let mut k1 = [0.0; 2];
                    f(x, &mut k1);
                    let mut k2 = [0.0; 2];
                    f([x[0] + h / 2.0 * k1[0], x[1] + h / 2.0 * k1[1]], &mut k2);
                    let mut k3 = [0.0; 2];
                    f([x[0] + h / 2.0 * k2[0], x[1] + h / 2.0 * k2[1]], &mut k3);
                    f([x[0] + h * k3[0], x[1] + h * k3[1]], &mut out);
                    for d in 0..2 {
                        x[d] += h / 6.0 * (k1[d] + 2.0 * k2[d] + 2.0 * k3[d] + out[d]);
                    }
                    t += h;
                }
                assert!(
                    union.contains_at(k, &x),
                    "t = {}: {x:?} outside the union",
                    st.t
                );
                assert!(
                    union.pieces()[home].contains_at(k, &x),
                    "t = {}: {x:?}",
                    st.t
                );
                assert!(union.span_contains(k, &x));
            }
        }
    }
    // A point outside every piece's set (beyond the hull) is outside; the hull's centre of a
    // late step lies in some piece.
    let k = union.steps().len() - 1;
    let hull = union.hull_at(k).unwrap();
    assert!(!union.contains_at(k, &[hull[0].hi + 0.01, hull[1].hi + 0.01]));
    // Tighter than one piece: the remainder is quadratic in the pieces' widths.
    let width = |p: &Prs, i: usize| {
        let h = p.hull_at(k).unwrap();
        h[i].hi - h[i].lo
    };
    for i in 0..2 {
        eprintln!(
            "state {i}: split {} / unsplit {}",
            width(&union, i),
            width(&plain, i)
        );
        assert!(width(&union, i) < 0.8 * width(&plain, i));
    }
}

/// The union of the pieces' time-uniform tubes passes the Monte Carlo check from the whole
/// initial box (uniform starts), at every Euler-Maruyama step against the union's spans.
#[test]
fn the_union_passes_the_monte_carlo_check() {
    let (sys, info) = inline(&spec("split = [3, 2]"));
    let union = Reach::paired(&sys, &info, "a").unwrap().run().unwrap();
    let opts = Options {
        paths: 2_000,
        seed: 3,
        ..Options::default()
    };
    let report =
        simulate::simulate(&Paired::new(&sys, &info), &union, &opts, &mut |_, _| {}).unwrap();
    assert!(report.passed(), "{}", summary(&report));
    // Not vacuous: the paths' spread is a sizeable part of the union's set.
    let ratio = report
        .steps
        .iter()
        .map(|s| s.quantile / s.prs_radius)
        .fold(0.0, f64::max);
    assert!(ratio > 0.05, "{ratio}");
}

/// `split = auto`: the pieces are halves of halves of the box (each state's cuts at dyadic
/// points), they tile it (their areas sum to the box's), stay within the budget, and the union
/// is tighter than one piece; the same spec gives the same pieces again.
#[test]
fn an_automatic_split_tiles_the_box_within_its_budget() {
    let auto = run("split = auto(pieces = 12)");
    let plain = run("");
    assert_eq!(
        auto.split(),
        &Split::Auto {
            pieces: 12,
            seconds: None
        }
    );
    let n = auto.pieces().len();
    assert!((2..=12).contains(&n), "{n} pieces");
    let area: f64 = auto
        .pieces()
        .iter()
        .map(|p| {
            let b = p.initial().bounding_box().unwrap();
            (b[0].hi - b[0].lo) * (b[1].hi - b[1].lo)
        })
        .sum();
    assert!((area - 2.4 * 2.0).abs() < 1e-12, "{area}");
    // No two pieces overlap (beyond a shared cut).
    for (a, p) in auto.pieces().iter().enumerate() {
        for q in &auto.pieces()[a + 1..] {
            let (x, y) = (
                p.initial().bounding_box().unwrap(),
                q.initial().bounding_box().unwrap(),
            );
            let overlap = |i: usize| (x[i].hi.min(y[i].hi) - x[i].lo.max(y[i].lo)).max(0.0);
            assert_eq!(overlap(0) * overlap(1), 0.0);
        }
    }
    let k = auto.steps().len() - 1;
    let (a, b) = (auto.hull_at(k).unwrap(), plain.hull_at(k).unwrap());
    for i in 0..2 {
        eprintln!(
            "state {i}: auto {} / unsplit {}",
            a[i].hi - a[i].lo,
            b[i].hi - b[i].lo
        );
        assert!(a[i].hi - a[i].lo < 0.8 * (b[i].hi - b[i].lo));
    }
    assert_eq!(run("split = auto(pieces = 12)").steps(), auto.steps());
}

/// The probability of safety of a split analysis (method.md 8.9): the deterministic sets are
/// the pieces' (the union's own boxes hold the stochastic part too), so a union not shown safe
/// at its `delta` whose pieces' deterministic sets avoid the unsafe set still gets a bound from
/// the search. (With the union's boxes taken as deterministic, the search stopped at once.)
#[test]
fn a_split_analysis_gets_a_probability_of_safety() {
    let source = spec("split = [4, 3]").replace("x >= 1.35", "x >= 1.38");
    let (sys, info) = inline(&source);
    let reach = Reach::paired(&sys, &info, "a").unwrap();
    assert!(matches!(
        reach.run().unwrap().verdict(),
        Verdict::NotShownSafe { .. }
    ));
    let p = reach.safety_probability().unwrap();
    let delta = p.delta.expect("a bound");
    assert!(delta > 1e-2 && delta < 0.2, "{delta}");
    assert!(
        !matches!(p.limit, SafetyLimit::Deterministic { .. }),
        "{:?}",
        p.limit
    );
}

/// A piece that cannot run fails the analysis, and the diagnostic says which piece (the first
/// in order): here `x' = x^2` blows up at `t = 1 / x0`, and from `[2, 3]` the tube around it
/// cannot be closed before the horizon; from `[0, 2]` it can.
#[test]
fn a_failing_piece_is_named() {
    let source = "model blow\nstate x in [0, 4]\nnoise w\ndrift { x' = x^2 }\n\
                  diffusion { x: 0.01 * w }\nanalysis a { horizon = 0.3  split = [4] }\n";
    let (sys, info) = inline(source);
    let err = Reach::paired(&sys, &info, "a").unwrap().run().unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("(in the piece x in [2, 3] of the split initial box)"),
        "{text}"
    );
    // The first two pieces alone run.
    let fine = source.replace("[0, 4]", "[0, 2]").replace("[4]", "[2]");
    let (sys, info) = inline(&fine);
    assert_eq!(
        Reach::paired(&sys, &info, "a")
            .unwrap()
            .run()
            .unwrap()
            .pieces()
            .len(),
        2
    );
}

/// Only a box can be split: an initial ball is refused with a diagnostic at the setting.
#[test]
fn an_initial_ball_cannot_be_split() {
    let source = "model b\nstate x\nstate v\ninitial ball { over = [x, v]  center = [0, 0]  \
                  radius = 0.1 }\nnoise w\ndrift {\n x' = v\n v' = -x - v\n}\n\
                  diffusion {\n v: 0.05 * w\n}\nanalysis a {\n horizon = 1\n split = [2, 2]\n}\n";
    let (sys, info) = inline(source);
    let Err(RunError::Unsupported(detail)) = Reach::paired(&sys, &info, "a").unwrap().run() else {
        panic!("a ball cannot be split");
    };
    assert_eq!(detail.culprit, Some(Culprit::Setting(Setting::Split)));
    assert_eq!(*detail.problem, Problem::SplitNotABox, "{detail}");
}

/// `split = auto` cuts a piece that cannot run like one whose sets are infinite: `x' = x^2`
/// from `[0, 3]` to `t = 0.3` cannot be run whole (the tube around the solution from 3, which
/// reaches 30, cannot be closed), but 16 pieces can, and every closed-form solution
/// `x0 / (1 - x0 t)` from a grid of starts lies in the union at every report time. With a budget
/// of one piece, the whole box's failure is the analysis'.
#[test]
fn split_auto_cuts_pieces_that_cannot_run() {
    let source = "model blow\nstate x in [0, 3]\nnoise w\ndrift { x' = x^2 }\n\
                  diffusion { x: 0.01 * w }\nanalysis whole { horizon = 0.3 }\n\
                  analysis auto { horizon = 0.3  split = auto(pieces = 16) }\n\
                  analysis one { horizon = 0.3  split = auto(pieces = 1) }\n";
    let (sys, info) = inline(source);
    let whole = Reach::paired(&sys, &info, "whole")
        .unwrap()
        .run()
        .unwrap_err();
    let one = Reach::paired(&sys, &info, "one")
        .unwrap()
        .run()
        .unwrap_err();
    // (A budget of one piece is the unsplit run.)
    assert_eq!(one, whole);
    let prs = Reach::paired(&sys, &info, "auto").unwrap().run().unwrap();
    assert!(
        prs.pieces().len() > 1 && prs.pieces().len() <= 16,
        "{}",
        prs.pieces().len()
    );
    for i in 0..=60 {
        let x0 = 3.0 * f64::from(i) / 60.0;
        for (k, st) in prs.steps().iter().enumerate() {
            let x = x0 / (1.0 - x0 * st.t);
            assert!(prs.contains_at(k, &[x]), "x0 = {x0}, t = {}: {x}", st.t);
        }
    }
}

/// The time budget of `split = auto`: with `seconds = 0` no round of cuts starts (the whole box
/// alone, whose sets are the unsplit run's); with an hour, the same pieces as without a budget.
#[test]
fn the_time_budget_of_an_automatic_split() {
    let none = run("split = auto(seconds = 0)");
    let plain = run("");
    assert_eq!(none.pieces().len(), 1);
    assert_eq!(none.pieces()[0].steps(), plain.steps());
    let hour = run("split = auto(pieces = 12, seconds = 3600)");
    let free = run("split = auto(pieces = 12)");
    assert_eq!(
        hour.split(),
        &Split::Auto {
            pieces: 12,
            seconds: Some(3600)
        }
    );
    let boxes = |p: &Prs| -> Vec<_> { p.pieces().iter().map(|q| q.initial().clone()).collect() };
    assert_eq!(boxes(&hour), boxes(&free));
    assert_eq!(hour.steps(), free.steps());
}
