//! `r1` over initial balls (method.md section 6, "r1 over initial balls"): shipped specs started
//! from a ball instead of their box or point get the exact `r1`, below the bound over the ball's
//! bounding box that reachc used before, and a PRS no larger.

use nalgebra::{DMatrix, SymmetricEigen};
use reachc_compiler::backend::interp::Interpreter;
use reachc_compiler::driver::check_source;
use reachc_e2e::{interpreter_of, workspace};
use reachc_runtime::model::ModelInfo;
use reachc_runtime::prs::{BallBound, R1Method};
use reachc_runtime::{Prs, Reach};

/// `specs/FILE` with each `(from, to)` replaced once.
fn edited(file: &str, edits: &[(&str, &str)]) -> (Interpreter, ModelInfo) {
    let mut source = std::fs::read_to_string(workspace().join("specs").join(file)).unwrap();
    for (from, to) in edits {
        assert!(source.contains(from), "{file} has no `{from}`");
        source = source.replacen(from, to, 1);
    }
    let (model, diags) = check_source(&source, &workspace().join("specs"));
    interpreter_of(model.unwrap_or_else(|| panic!("{diags:?}")))
}

/// The analysis from the spec's initial set, and from that set's bounding box (what `r1` was
/// bounded over before).
fn with_and_without_ball(sys: &Interpreter, info: &ModelInfo, analysis: &str) -> (Prs, Prs) {
    let reach = Reach::paired(sys, info, analysis).unwrap();
    let ball = reach.run().unwrap();
    let boxed = reach
        .from_box(&info.initial().bounding_box().unwrap())
        .unwrap();
    let (r1, before) = (ball.r1(), boxed.r1());
    let (end, end_before) = (
        ball.steps().last().unwrap().prs_radius,
        boxed.steps().last().unwrap().prs_radius,
    );
    println!("{analysis}: r1 {before} -> {r1}, PRS radius at the horizon {end_before} -> {end}");
    assert!(r1 < before, "{analysis}: r1 {r1} >= {before}");
    assert!(end <= end_before, "{analysis}: {end} > {end_before}");
    assert_eq!(ball.r1_bound().balls, BallBound::Joint { balls: 1 });
    (ball, boxed)
}

/// `r sqrt(lambda_max(P, M))` for a ball over every state.
fn pencil_radius(p: &[f64], m: &DMatrix<f64>, r: f64) -> f64 {
    let n = m.nrows();
    let l_inv = m.clone().cholesky().unwrap().l().try_inverse().unwrap();
    let c = &l_inv * DMatrix::from_row_slice(n, n, p) * l_inv.transpose();
    let top = SymmetricEigen::new(c).eigenvalues.max();
    r * top.sqrt()
}

/// A ball over every state: `r1 = r sqrt(lambda_max(P, M))` to 1e-9 (the pendulum from the
/// ellipse inscribed in its initial box, msd from a disc, chain10 from a round ball over its 12
/// states, where the bounding box gave `sqrt(12)` times more).
#[test]
fn a_ball_alone_gets_the_pencil_radius() {
    let pi = std::f64::consts::PI;
    let (sys, info) = edited(
        "pendulum.sde",
        &[
            ("state theta in [-pi/10, pi/10]", "state theta"),
            (
                "state omega in [-0.2, 0.2]",
                "state omega\ninitial ball { over = [theta, omega]  center = [0, 0]  radius = 1  \
                 metric = [[100 / pi^2, 0], [0, 25]] }",
            ),
        ],
    );
    let m = DMatrix::from_row_slice(2, 2, &[100.0 / (pi * pi), 0.0, 0.0, 25.0]);
    let (pendulum, _) = with_and_without_ball(&sys, &info, "contraction");

    let (sys, info) = edited(
        "msd.sde",
        &[
            ("state x in [0.9, 1.1]", "state x"),
            (
                "state v in [-0.1, 0.1]",
                "state v\ninitial ball { over = [x, v]  center = [1, 0]  radius = 0.1 }",
            ),
        ],
    );
    let (msd, _) = with_and_without_ball(&sys, &info, "contraction");

    let states: Vec<String> = (1..=12).map(|i| format!("x[{i}]")).collect();
    let chain_ball = format!(
        "state x[1..N]\ninitial ball {{ over = [{}]  center = [{}]  radius = 0.1 }}",
        states.join(", "),
        ["0"; 12].join(", ")
    );
    let (sys, info) = edited(
        "chain10.sde",
        &[("state x[1..N] in [-0.1, 0.1]", chain_ball.as_str())],
    );
    let (chain, chain_box) = with_and_without_ball(&sys, &info, "contraction");
    assert!(chain_box.r1() >= 0.1 * 12f64.sqrt() * (1.0 - 1e-12));

    for (prs, m, r) in [
        (&pendulum, m, 1.0),
        (&msd, DMatrix::identity(2, 2), 0.1),
        (&chain, DMatrix::identity(12, 12), 0.1),
    ] {
        let exact = pencil_radius(&prs.constants().metric, &m, r);
        assert!(
            prs.r1() >= exact * (1.0 - 1e-12) && prs.r1() <= exact * (1.0 + 1e-9),
            "{} {exact}",
            prs.r1()
        );
        assert_eq!(prs.r1_bound().boxes, R1Method::Vertices { active: 0 });
        assert!(reachc_runtime::report::summary(prs).contains("over the initial ball, exact"));
    }
}

/// A disc in (px, py) times a heading interval (unicycle_lookahead, metric = auto): `r1` is the
/// maximum over the two heading ends times the circle, sampled densely, to 1e-9.
#[test]
fn a_ball_times_a_box_gets_the_joint_maximum() {
    let (sys, info) = edited(
        "unicycle_lookahead.sde",
        &[
            ("state px = 5", "state px"),
            (
                "state py = 5",
                "state py\ninitial ball { over = [px, py]  center = [5, 5]  radius = 0.25 }",
            ),
            (
                "state theta = -2 * pi / 3",
                "state theta in [-2 * pi / 3 - 0.1, -2 * pi / 3 + 0.1]",
            ),
        ],
    );
    let (prs, _) = with_and_without_ball(&sys, &info, "contraction");
    assert_eq!(prs.r1_bound().boxes, R1Method::Vertices { active: 1 });
    let p = &prs.constants().metric;
    let mut sampled = 0.0f64;
    let angles = 200_000;
    for dtheta in [-0.1, 0.1] {
        for k in 0..angles {
            let phi = std::f64::consts::TAU * f64::from(k) / f64::from(angles);
            let d = [0.25 * phi.cos(), 0.25 * phi.sin(), dtheta];
            let q: f64 = (0..3)
                .map(|i| d[i] * (0..3).map(|j| p[i * 3 + j] * d[j]).sum::<f64>())
                .sum();
            sampled = sampled.max(q.sqrt());
        }
    }
    assert!(
        sampled <= prs.r1() && prs.r1() <= sampled * (1.0 + 1e-9),
        "r1 {}, sampled {sampled}",
        prs.r1()
    );
}
