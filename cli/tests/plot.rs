//! `reachc plot` and `reachc run --plot` (interpreter backend): the files written, that they are
//! SVG and PNG pictures of the right size, the error cases and their exit codes; and that the
//! plotted sample paths are the Monte Carlo check's paths.

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

use reachc::plot::input::{MovingSet, ResultFile};
use reachc::plot::regions::Region;
use reachc::plot::scene::moving_regions;
use reachc_compiler::backend::interp::Interpreter;
use reachc_compiler::backend::prepare;
use reachc_runtime::engine;
use reachc_runtime::model::{Bounds, UnsafeShape};
use reachc_runtime::report;
use reachc_runtime::simulate::{self, Options};
use reachc_runtime::system::Paired;

use common::{file_names, reachc, spec, text};

/// A fresh directory for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("reachc-plot-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A complete SVG document; its text.
fn svg(path: &Path) -> String {
    let s = std::fs::read_to_string(path).unwrap();
    assert!(s.starts_with("<svg "), "{}", path.display());
    assert!(s.trim_end().ends_with("</svg>"), "{}", path.display());
    s
}

/// A PNG's width and height (from its IHDR chunk).
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "{}", path.display());
    assert_eq!(&b[12..16], b"IHDR");
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    (be(16), be(20))
}

#[test]
fn run_plot_writes_both_figures_for_each_analysis() {
    let dir = temp_dir("run");
    let out = dir.join("out");
    let plots = dir.join("plots");
    let o = reachc(&[
        "run",
        &spec("pendulum.sde"),
        "--backend",
        "interp",
        "-o",
        out.to_str().unwrap(),
        "--plot",
        plots.to_str().unwrap(),
        "--plot-paths",
        "5",
        "--plot-times",
        "1,4",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    // With whether each has local rates (those also get the rates figure).
    let local = [
        ("contraction", true),
        ("interval", true),
        ("paper_contraction", false),
        ("paper_interval", false),
        ("per_state", false),
        ("per_state_uniform", true),
    ];
    let analyses = local.map(|(a, _)| a);
    let mut expected: Vec<String> = local
        .iter()
        .flat_map(|&(a, local)| {
            let rates = if local {
                &["rates.png", "rates.svg"][..]
            } else {
                &[]
            };
            ["radius.png", "radius.svg"]
                .iter()
                .chain(rates)
                .chain(&["sets.png", "sets.svg", "widths.png", "widths.svg"])
                .map(|f| format!("{a}_{f}"))
                .collect::<Vec<_>>()
        })
        .collect();
    expected.sort();
    // Exactly the pictures: no temporary files left behind.
    assert_eq!(file_names(&plots), expected);
    for a in analyses {
        let sets = svg(&plots.join(format!("{a}_sets.svg")));
        assert!(sets.contains(&format!("pendulum / {a}")), "{a}");
        assert!(
            sets.contains(">\ntheta\n<") && sets.contains(">\nomega\n<"),
            "{a}"
        );
        assert!(
            sets.contains("5 sample paths") && sets.contains("t = 4: PRS"),
            "{a}"
        );
        assert!(!sets.contains("t = 2: PRS"), "{a}: only the chosen times");
        let radius = svg(&plots.join(format!("{a}_radius.svg")));
        // No report beside the results: the run simulated the quantile itself.
        assert!(radius.contains("2000 paths"), "{a}");
        // And its per-state spreads, against the PRS's box.
        let widths = svg(&plots.join(format!("{a}_widths.svg")));
        assert!(
            widths.contains(&format!("pendulum / {a}: half-widths per state"))
                && widths.contains("theta: PRS")
                && widths.contains("omega: paths (1-δ)")
                && widths.contains("2000 paths"),
            "{a}"
        );
        assert_eq!(png_size(&plots.join(format!("{a}_sets.png"))), (1100, 780));
        assert_eq!(
            png_size(&plots.join(format!("{a}_radius.png"))),
            (1100, 560)
        );
    }
    let interval = svg(&plots.join("interval_sets.svg"));
    assert!(interval.contains("deterministic parallelotope"));
    let rates = svg(&plots.join("contraction_rates.svg"));
    assert!(rates.contains("pendulum / contraction: contraction rate"));
    assert!(rates.contains("local") && rates.contains("sigma_t"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plot_reads_a_result_with_or_without_the_spec() {
    let dir = temp_dir("plot");
    let d = dir.to_str().unwrap();
    let run = reachc(&[
        "run",
        &spec("linear.sde"),
        "--backend",
        "interp",
        "--analysis",
        "amgf_rule",
        "-o",
        d,
    ]);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run));
    let result = dir.join("amgf_rule.json");
    let r = result.to_str().unwrap();

    // Without the spec: sets and radii only, next to the result.
    let o = reachc(&["plot", r]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let sets = svg(&dir.join("amgf_rule_sets.svg"));
    assert!(!sets.contains("sample paths (Euler"));
    assert!(sets.contains("no sample paths or unsafe sets"));
    assert!(!svg(&dir.join("amgf_rule_radius.svg")).contains("quantile of"));
    assert!(
        !dir.join("amgf_rule_widths.svg").exists(),
        "no report, no widths"
    );

    // With the spec, chosen states (swapped) and a Monte Carlo report beside the result.
    let sim = reachc(&[
        "simulate",
        &spec("linear.sde"),
        "--backend",
        "interp",
        "--analysis",
        "amgf_rule",
        "--paths",
        "300",
        "-q",
        "-o",
        d,
    ]);
    assert_eq!(sim.status.code(), Some(0), "{}", text(&sim));
    let pics = dir.join("pics");
    let o = reachc(&[
        "plot",
        r,
        "--spec",
        &spec("linear.sde"),
        "--states",
        "x2,x1",
        "--paths",
        "7",
        "-o",
        pics.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let sets = svg(&pics.join("amgf_rule_sets.svg"));
    assert!(sets.contains("7 sample paths"));
    // The vertical axis is x1 now: its label is the rotated one.
    let label = |name: &str| {
        let at = sets.find(&format!(">\n{name}\n<")).unwrap();
        let start = sets[..at].rfind("<text").unwrap();
        sets[start..at].contains("rotate(270")
    };
    assert!(label("x1") && !label("x2"));
    let radius = svg(&pics.join("amgf_rule_radius.svg"));
    assert!(radius.contains("(300 paths)") && radius.contains("amgf_rule.sim.json"));
    // The plotted states' spreads from the report, in the chosen order.
    let widths = svg(&pics.join("amgf_rule_widths.svg"));
    let (x2, x1) = (
        widths.find("x2: PRS").unwrap(),
        widths.find("x1: PRS").unwrap(),
    );
    assert!(x2 < x1 && widths.contains("300 paths"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A result cut by a first-order zonotope (a member written by hand into the JSON of
/// `reachc run`: zonotopes around the nominal) is drawn, with the zonotope named in the
/// legend; a malformed zonotope is refused with the member named.
#[test]
fn plot_draws_a_zonotope_member() {
    let dir = temp_dir("zonotope");
    let d = dir.to_str().unwrap();
    let run = reachc(&[
        "run",
        &spec("linear.sde"),
        "--backend",
        "interp",
        "--analysis",
        "amgf_rule",
        "-o",
        d,
    ]);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run));
    let result = dir.join("amgf_rule.json");
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&result).unwrap()).unwrap();
    let original = json.clone();
    let zonotope = |generators: serde_json::Value| {
        let mut member = original.clone();
        for step in member["steps"].as_array_mut().unwrap() {
            step["det_set"] = serde_json::json!({
                "shape": "zonotope",
                "center": step["nominal"].clone(),
                "radius": 1.0,
                "generators": generators.clone(),
                "remainder": 0.02,
                "hull_lo": [-1.0, -1.0],
                "hull_hi": [1.0, 1.0],
            });
        }
        member["role"] = serde_json::json!("first_order");
        member
    };
    let good = zonotope(serde_json::json!([[0.2, 0.05], [-0.05, 0.1]]));
    json["also"] = serde_json::json!([good]);
    let cut = dir.join("cut.json");
    std::fs::write(&cut, json.to_string()).unwrap();
    let o = reachc(&["plot", cut.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let sets = svg(&dir.join("amgf_rule_sets.svg"));
    assert!(sets.contains("first-order zonotope"), "{sets}");

    json["also"] = serde_json::json!([zonotope(serde_json::json!([[0.2, 0.05, 0.0]]))]);
    std::fs::write(&cut, json.to_string()).unwrap();
    let o = reachc(&["plot", cut.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o).contains("member 1 of the intersection: step 0: malformed Zonotope set"),
        "{}",
        text(&o)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plot_errors_are_usage_errors_and_write_nothing() {
    let dir = temp_dir("errors");
    let d = dir.to_str().unwrap();
    let missing = reachc(&["plot", &format!("{d}/none.json")]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(text(&missing).contains("cannot read"), "{}", text(&missing));

    let bad = dir.join("bad.json");
    std::fs::write(&bad, "{\"model\": \"m\", \"steps\": [").unwrap();
    let o = reachc(&["plot", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o).contains("is not a valid result of `reachc run`"),
        "{}",
        text(&o)
    );

    let run = reachc(&[
        "run",
        &spec("linear.sde"),
        "--backend",
        "interp",
        "--analysis",
        "amgf_rule",
        "-o",
        d,
    ]);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run));
    let r = dir.join("amgf_rule.json");
    let r = r.to_str().unwrap();
    let o = reachc(&["plot", r, "--states", "x1,vx"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o).contains("no state `vx` (the states are: x1, x2)"),
        "{}",
        text(&o)
    );
    let o = reachc(&["plot", r, "--times", "0.5,7"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("time 7 is outside"), "{}", text(&o));
    let o = reachc(&["plot", r, "--spec", &spec("pendulum.sde")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o).contains("is not the result's model"),
        "{}",
        text(&o)
    );
    // A result whose metric is not square is refused, not drawn.
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(r).unwrap()).unwrap();
    json["constants"]["metric"] = serde_json::json!([[1.0]]);
    std::fs::write(&bad, json.to_string()).unwrap();
    let o = reachc(&["plot", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("the metric is not 2 x 2"), "{}", text(&o));
    // An output directory that cannot be made: an I/O error.
    let o = reachc(&["plot", r, "-o", bad.join("sub").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("cannot write"), "{}", text(&o));
    assert!(text(&o).contains("(nothing written)"), "{}", text(&o));
    // None of the failures wrote a picture (nor a temporary file).
    assert!(
        file_names(&dir)
            .iter()
            .all(|f| f.ends_with(".json") || f.ends_with(".csv")),
        "{:?}",
        file_names(&dir)
    );

    // run --plot checks the state names before running anything.
    let o = reachc(&[
        "run",
        &spec("linear.sde"),
        "--backend",
        "interp",
        "-o",
        &format!("{d}/run"),
        "--plot",
        &format!("{d}/pics"),
        "--plot-states",
        "x1,y",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o).contains("--plot-states: no state `y`"),
        "{}",
        text(&o)
    );
    assert!(!dir.join("run").exists() && !dir.join("pics").exists());
    // The plot options need --plot.
    let o = reachc(&["run", &spec("linear.sde"), "--plot-paths", "3"]);
    assert_eq!(o.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `reachc run SPEC --backend interp -o DIR/out --plot DIR/plots EXTRA...`.
fn run_and_plot(spec_name: &str, dir: &Path, extra: &[&str]) -> Output {
    let (out, plots) = (dir.join("out"), dir.join("plots"));
    let spec = spec(spec_name);
    let mut args = vec![
        "run",
        spec.as_str(),
        "--backend",
        "interp",
        "-o",
        out.to_str().unwrap(),
        "--plot",
        plots.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    reachc(&args)
}

#[test]
fn an_analysis_without_a_prs_gets_paths_and_unsafe_sets() {
    let dir = temp_dir("unbounded");
    let plots = dir.join("plots");
    let o = run_and_plot(
        "../tests/good/unbounded_rate.sde",
        &dir,
        &["--plot-paths", "10"],
    );
    // The analysis cannot run (exit 1), its picture is drawn all the same.
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("has no PRS: plotting its sample paths and unsafe sets only"));
    assert_eq!(
        file_names(&plots),
        ["contraction_sets.png", "contraction_sets.svg"]
    );
    let sets = svg(&plots.join("contraction_sets.svg"));
    for name in ["far", "disc", "10 sample paths", "no PRS"] {
        assert!(sets.contains(name), "{name}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn sample_paths_are_the_monte_carlo_paths() {
    // Path p of result_paths is path p of simulate: the largest distance from the nominal at
    // each report time is the report's `max`.
    let mut loaded = reachc_compiler::driver::load(Path::new(&spec("pendulum.sde"))).unwrap();
    let prepared = prepare(&mut loaded.model);
    let info = prepared.info.clone();
    let interp = Interpreter::new(loaded.model, &prepared);
    let analysis = info.analysis("contraction").unwrap();
    let result = engine::run_paired(&interp, &info, analysis).unwrap();
    let opts = Options {
        paths: 64,
        seed: 5,
        ..Options::default()
    };
    let report =
        simulate::simulate(&Paired::new(&interp, &info), &result, &opts, &mut |_, _| {}).unwrap();
    let paths = simulate::result_paths(&interp, &info, &result, &opts).unwrap();
    assert_eq!(paths.len(), 64);
    let p = &result.constants().metric;
    for (k, step) in result.steps().iter().enumerate() {
        let max = paths
            .iter()
            .map(|x| {
                let d: Vec<f64> = (0..2).map(|i| x[2 * k + i] - step.nominal()[i]).collect();
                (0..2)
                    .flat_map(|i| (0..2).map(move |j| (i, j)))
                    .map(|(i, j)| p[i * 2 + j] * d[i] * d[j])
                    .sum::<f64>()
                    .sqrt()
            })
            .fold(0.0, f64::max);
        let expected = report.steps[k].max;
        assert!(
            (max - expected).abs() <= 1e-12 * expected.max(1e-300),
            "t = {}: {max} vs {expected}",
            step.t
        );
    }
}

#[test]
fn envelope_and_reference_trajectory_of_the_unicycle() {
    // The paper's Fig. 7: the union of the PRS over the horizon, the plan from the spec's table.
    let dir = temp_dir("envelope");
    let plots = dir.join("plots");
    let o = run_and_plot(
        "unicycle.sde",
        &dir,
        &["--plot-paths", "5", "--plot-envelope"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    // The empirical rate is labelled in the summary.
    assert!(text(&o).contains("rate: EMPIRICAL"), "{}", text(&o));
    let sets = svg(&plots.join("empirical_sets.svg"));
    // (The legend wraps the label after "report".)
    assert!(sets.contains("union of the PRS over all 500 report"));
    assert!(sets.contains("table `ref` (px, py): reference"));
    // One filled polygon per report time at least (plus unsafe sets and the chosen times).
    assert!(sets.matches("<polygon").count() >= 500);
    // Without the flag: no envelope.
    let o = reachc(&[
        "plot",
        dir.join("out/empirical.json").to_str().unwrap(),
        "-o",
        dir.join("plain").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let plain = svg(&dir.join("plain/empirical_sets.svg"));
    assert!(!plain.contains("union of the PRS"));
    assert!(plain.matches("<polygon").count() < 20);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Goal sets (method.md 8.13) for the test below (written to its directory, not kept with the
/// fuzz campaign's seed specs).
const GOALS_SPEC: &str = r#"/// Goal sets (method.md 8.13): a damped system driven from x = 2 towards the origin, past a wall
/// at y >= 0.5. `home` is reached within [1, 4] (a box), `park` reached within [2, 4] and kept
/// to t = 4 (a ball), `lane` is an intersection (a half-space and a box), `far` is never shown.
model dock
state x in [1.9, 2.1]
state y in [-0.1, 0.1]
noise w1
noise w2
drift {
    x' = -1.5 * x + y
    y' = -1.5 * y
}
diffusion {
    x: 0.05 * w1
    y: 0.05 * w2
}
unsafe wall halfspace { y >= 0.5 }
goal home box { x in [-0.5, 0.5]  y in [-0.5, 0.5] } within [1, 4]
goal park ball { over = [x, y]  center = [0, 0]  radius = 0.6 } within [2, 4] stay
goal lane halfspace { x <= 0.3 } and box { y in [-1, 1] }
goal far box { x in [5, 6] }
analysis contraction {
    method = contraction
    delta = 1e-3
    horizon = 4
    step = 0.05
}
"#;

#[test]
fn goals_are_reported_and_drawn() {
    let dir = temp_dir("goals");
    let plots = dir.join("plots");
    let spec_path = dir.join("goals.sde");
    std::fs::write(&spec_path, GOALS_SPEC).unwrap();
    let o = run_and_plot(spec_path.to_str().unwrap(), &dir, &["--plot-paths", "10"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    for line in [
        "goal `home` (reach within [1, 4]): reached: with probability at least 0.999",
        "goal `park` (reach within [2, 4] and stay until 4): reached",
        "goal `lane` (reach within [0, 4]): reached",
        "goal `far` (reach within [0, 4]): NOT SHOWN REACHED",
    ] {
        assert!(text(&o).contains(line), "{line}\n{}", text(&o));
    }
    let sets = svg(&plots.join("contraction_sets.svg"));
    // `far` is outside the view (it bounds x only, beyond the sets): not drawn.
    assert!(
        sets.contains("goal: home, park, lane"),
        "the legend names the goals"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/contraction.json")).unwrap())
            .unwrap();
    let goals = json["goals"].as_array().unwrap();
    assert_eq!(goals.len(), 4);
    assert_eq!(goals[0]["status"], "reached");
    assert_eq!(goals[3]["why"]["kind"], "not_inside");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A model with a fixed and a second unsafe set and a goal, for the moving sets' test below
/// (whose positions it writes into the result by hand: the compiler gives no moving sets yet).
const MOVING_SPEC: &str = r#"model drift2
state x in [1.9, 2.1]
state y in [-0.1, 0.1]
noise w1
noise w2
drift {
    x' = -1.5 * x + y
    y' = -1.5 * y
}
diffusion {
    x: 0.05 * w1
    y: 0.05 * w2
}
unsafe wall halfspace { y >= 0.5 }
unsafe obs box { x in [-2, -1.5]  y in [-0.5, 0.5] }
goal home box { x in [-0.5, 0.5]  y in [-0.5, 0.5] } within [1, 4]
analysis contraction {
    method = contraction
    delta = 1e-3
    horizon = 4
    step = 0.25
}
"#;

/// The points of the SVG polygon drawn last before the label `label` (the filled region the
/// label names), in pixels.
fn region_before(svg: &str, label: &str) -> Vec<(i64, i64)> {
    let at = svg
        .find(&format!(">\n{label}\n<"))
        .unwrap_or_else(|| panic!("no label `{label}`"));
    let start = svg[..at].rfind("<polygon").unwrap();
    let points = &svg[start..at];
    let points = &points[points.find("points=\"").unwrap() + 8..];
    points[..points.find('"').unwrap()]
        .split_whitespace()
        .map(|p| {
            let (x, y) = p.split_once(',').unwrap();
            (x.parse().unwrap(), y.parse().unwrap())
        })
        .collect()
}

/// A result with a moving unsafe box and a moving goal (positions written by hand into the
/// engine's result of a fixed-set model, 0.125 per report step in x and in y): the plot's
/// reader gives back each step's shapes; `reachc plot` draws each set where it is at the
/// chosen times (default: t = 0 and the horizon), labelled with the time, the fixed wall as
/// before; the obstacle's rectangles at t = 1 and t = 3 are the same rectangle moved right.
#[test]
fn moving_sets_are_read_and_drawn_where_they_are() {
    let dir = temp_dir("moving");
    let spec_path = dir.join("drift2.sde");
    std::fs::write(&spec_path, MOVING_SPEC).unwrap();
    let mut loaded = reachc_compiler::driver::load(&spec_path).unwrap();
    let prepared = prepare(&mut loaded.model);
    let info = prepared.info.clone();
    let interp = Interpreter::new(loaded.model, &prepared);
    let mut prs =
        engine::run_paired(&interp, &info, info.analysis("contraction").unwrap()).unwrap();
    let steps = prs.steps().len();
    assert_eq!(steps, 17);
    // (Multiples of 1/8: the decimals in the file are exact.)
    let obs = |k: usize| {
        let x = k as f64 / 8.0;
        UnsafeShape::Box(vec![
            (0, Bounds::new(x - 2.0, x - 1.5)),
            (1, Bounds::new(-0.5, 0.5)),
        ])
    };
    let home = |k: usize| {
        let y = k as f64 / 8.0;
        vec![UnsafeShape::Box(vec![
            (0, Bounds::new(-0.5, 0.5)),
            (1, Bounds::new(y - 0.5, y + 0.5)),
        ])]
    };
    assert_eq!(prs.unsafe_sets()[1].name, "obs");
    prs.unsafe_sets_mut()[1].swept = (0..steps).map(obs).collect();
    prs.goals_mut()[0].swept = (0..steps).map(home).collect();
    let path = dir.join("contraction.json");
    std::fs::write(&path, report::to_json(&prs)).unwrap();

    let read = ResultFile::read(&path).unwrap();
    let moving = read.moving_sets().unwrap();
    assert_eq!(
        moving,
        [
            MovingSet {
                name: "obs".into(),
                goal: false,
                at: (0..steps).map(|k| vec![obs(k)]).collect(),
            },
            MovingSet {
                name: "home".into(),
                goal: true,
                at: (0..steps).map(home).collect(),
            },
        ]
    );
    // t = 1 and t = 3 are report steps 4 and 12.
    let mut notes = Vec::new();
    let drawn = moving_regions(&read, &moving, [0, 1], &[4, 12], &mut notes);
    let rect = |x: (f64, f64), y: (f64, f64)| Region::Rect { x, y };
    assert_eq!(
        drawn.unsafe_sets,
        [
            ("obs at t = 1".to_string(), rect((-1.5, -1.0), (-0.5, 0.5))),
            ("obs at t = 3".to_string(), rect((-0.5, 0.0), (-0.5, 0.5))),
        ]
    );
    assert_eq!(
        drawn.goals[1],
        (
            "home at t = 3".to_string(),
            vec![rect((-0.5, 0.5), (1.0, 2.0))]
        )
    );

    let spec = spec_path.to_str().unwrap();
    let pics = dir.join("pics");
    let o = reachc(&[
        "plot",
        path.to_str().unwrap(),
        "--spec",
        spec,
        "--times",
        "1,3",
        "--paths",
        "5",
        "-o",
        pics.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let sets = svg(&pics.join("contraction_sets.svg"));
    for label in [
        "obs at t = 1",
        "obs at t = 3",
        "home at t = 1",
        "home at t = 3",
        "unsafe: wall, obs at t = 1, obs at t =",
        "goal: home at t = 1, home at t = 3",
        "moving sets drawn at t = 1, 3",
    ] {
        assert!(sets.contains(label), "{label}");
    }
    assert!(sets.contains(">\nwall\n<"), "the fixed wall as before");
    let (before, after) = (
        region_before(&sets, "obs at t = 1"),
        region_before(&sets, "obs at t = 3"),
    );
    assert_eq!(before.len(), after.len());
    let shift = after[0].0 - before[0].0;
    assert!(shift > 50, "moved right by {shift} px");
    for (b, a) in before.iter().zip(&after) {
        assert!(
            (a.0 - b.0 - shift).abs() <= 1 && a.1 == b.1,
            "{before:?} {after:?}"
        );
    }

    // Without chosen times: at t = 0 and at the horizon; without the spec: the moving sets
    // all the same, from the result.
    let o = reachc(&["plot", path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let sets = svg(&dir.join("contraction_sets.svg"));
    for label in [
        "obs at t = 0",
        "obs at t = 4",
        "home at t = 0",
        "home at t = 4",
        "no sample paths or fixed unsafe sets and",
        "moving sets drawn at t = 0, 4",
    ] {
        assert!(sets.contains(label), "{label}");
    }
    assert!(!sets.contains(">\nwall\n<"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A discrete-time model's figures say what its numbers are: the sample paths are the map's
/// exact steps, and the rates figure shows the map's factor `L_k` (not a contraction rate).
#[test]
fn plots_of_a_map_name_its_steps_and_factors() {
    let dir = temp_dir("map");
    let (out, plots) = (dir.join("out"), dir.join("plots"));
    let o = reachc(&[
        "run",
        &spec("discrete/integrator_chain.sde"),
        "--backend",
        "interp",
        "-o",
        out.to_str().unwrap(),
        "--plot",
        plots.to_str().unwrap(),
        "--plot-paths",
        "5",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let sets = svg(&plots.join("interval_sets.svg"));
    assert!(sets.contains("5 sample paths (exact map steps)"), "{sets}");
    let rates = svg(&plots.join("interval_rates.svg"));
    assert!(rates.contains("map factor") && rates.contains("L_k"));
    assert!(rates.contains("where L_k &gt; 1 the tube grows") || rates.contains("where L_k > 1"));
    assert!(!rates.contains("c_t"));
}
