//! The generated binaries' `main`: argument parsing, exit codes, skipped analyses, output files.

mod common;

use reachc_runtime::app::{EXIT_FAILED, EXIT_OK, EXIT_USAGE};
use reachc_runtime::model::{
    Analysis, Bounds, Constants, GoalSet, Method, ModelInfo, ModelParts, Transform,
    TransformSource, UnsafeSet, UnsafeShape,
};
use reachc_runtime::{report, Reach};
use reachc_test_support::models;
use reachc_test_support::systems::Linear;

/// `dx = -x dt + 0.5 dW` in one dimension.
const DECAY: Linear = Linear {
    n: 1,
    a: -1.0,
    b: 0.0,
    s: 0.5,
};

fn analysis(name: &str, method: Method, constants: bool) -> Analysis {
    let constants = if constants {
        Ok(Constants::given(&model(vec![]), vec![1.0], -1.0, 0.5, 0.0))
    } else {
        Err(reachc_runtime::model::NoConstants::NotCertified {
            constant: "not bounded c".into(),
        })
    };
    common::decay_analysis(name, method, constants)
}

fn model(analyses: Vec<Analysis>) -> ModelInfo {
    ModelInfo::from_parts(ModelParts {
        analyses,
        ..models::model("decay", &["x"], &["w"], &[(0.9, 1.1)]).into_parts()
    })
}

fn tmp_dir(tag: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("reachc-engine-app-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn cli(info: &ModelInfo, args: &[&str]) -> (u8, String, String) {
    common::run_main(&DECAY, info, args)
}

#[test]
fn runs_writes_and_skips_interval() {
    let info = model(vec![
        analysis("main", Method::Contraction, true),
        // A coordinate transform on a system without transformed frames is skipped, not run.
        {
            let mut a = analysis("boxes", Method::Interval, true);
            a.spec.transform = Some(Transform {
                matrix: vec![1.0],
                inverse: vec![1.0],
                frame: 0,
                source: TransformSource::Given,
            });
            a
        },
    ]);
    let dir = tmp_dir("ok");
    let (code, out, err) = cli(&info, &["-o", dir.to_str().unwrap()]);
    assert_eq!(code, EXIT_OK, "{err}");
    assert!(out.contains("analysis `main`"), "{out}");
    assert!(
        err.contains("skipped analysis `boxes`") && err.contains("no frame 0"),
        "{err}"
    );
    let json = std::fs::read_to_string(dir.join("main.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["analysis"], "main");
    let csv = std::fs::read_to_string(dir.join("main.csv")).unwrap();
    // The ball is cut by the interval box of the same run (method.md 8.7): the CSV carries
    // the intersection's bounding box after the ball's radii.
    assert!(csv.starts_with("t,x,det_radius,r_t,psi,c,sigma,prs_radius,prs_x_lo,prs_x_hi\n"));
    assert_eq!(csv.lines().count(), 12);
    assert!(!dir.join("boxes.json").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn quiet_and_named_analysis() {
    let info = model(vec![
        analysis("a", Method::Contraction, true),
        analysis("b", Method::Contraction, true),
    ]);
    let dir = tmp_dir("named");
    let (code, out, _) = cli(
        &info,
        &["--analysis=b", "--quiet", "--out", dir.to_str().unwrap()],
    );
    assert_eq!(code, EXIT_OK);
    assert!(out.is_empty());
    assert!(dir.join("b.json").exists() && !dir.join("a.json").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn exit_codes() {
    let info = model(vec![analysis("nocon", Method::Contraction, false)]);
    let dir = tmp_dir("fail");
    let (code, _, err) = cli(&info, &["-o", dir.to_str().unwrap()]);
    assert_eq!(code, EXIT_FAILED);
    assert!(err.contains("not bounded"), "{err}");
    let (code, _, err) = cli(&info, &["--analysis", "missing"]);
    assert_eq!(code, EXIT_USAGE);
    assert!(err.contains("available: nocon"), "{err}");
    assert_eq!(cli(&info, &["--bogus"]).0, EXIT_USAGE);
    assert_eq!(cli(&info, &["-o"]).0, EXIT_USAGE);
    let (code, out, _) = cli(&info, &["--help"]);
    assert_eq!(code, EXIT_OK);
    assert!(out.contains("usage"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The renderings of both methods' results: JSON fields and shapes, CSV columns, summaries.
#[test]
fn results_render() {
    let info = model(vec![
        analysis("ball", Method::Contraction, true),
        analysis("boxes", Method::Interval, true),
    ]);
    let ball = Reach::paired(&DECAY, &info, "ball").unwrap().run().unwrap();
    let boxes = Reach::paired(&DECAY, &info, "boxes")
        .unwrap()
        .run()
        .unwrap();
    let v: serde_json::Value = serde_json::from_str(&report::to_json(&ball)).unwrap();
    assert_eq!(v["method"], "contraction");
    assert!(v.get("inclusion").is_none());
    // The initial box at t = 0, P-balls after.
    assert_eq!(v["steps"][0]["det_set"]["shape"], "box");
    assert_eq!(v["steps"][1]["det_set"]["shape"], "p_ball");
    assert!(v["steps"][1]["det_set"].get("lo").is_none());
    assert_eq!(
        v["constants"]["how"],
        "given by hand, not certified by reachc"
    );
    assert_eq!(v["verdict"]["status"], "no_unsafe_sets");
    let v: serde_json::Value = serde_json::from_str(&report::to_json(&boxes)).unwrap();
    assert_eq!(v["method"], "interval");
    assert_eq!(v["inclusion"], "jacobian");
    assert_eq!(v["steps"][0]["det_set"]["shape"], "box");
    assert_eq!(v["steps"][0]["det_set"]["lo"][0], 0.9);
    assert_eq!(v["steps"][0]["det_set"]["hi"][0], 1.1);
    // Validated steps and a time-uniform tube by default: nothing unproved.
    assert_eq!(v["guarantee"], "uniform");
    assert_eq!(v["validated"]["not_validated"], serde_json::json!([]));
    let proved: Vec<&str> = v["validated"]["rigorous"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_str().unwrap())
        .collect();
    assert!(
        proved.iter().any(|p| p.starts_with("embedding system on"))
            && proved.iter().any(|p| p.starts_with("time-uniform tube")),
        "{proved:?}"
    );
    // An integrator the user asked for is labelled.
    let mut euler = info.clone();
    euler.analyses_mut()[1].spec.integrator = reachc_runtime::model::Integrator::Euler;
    let unvalidated = Reach::paired(&DECAY, &euler, "boxes")
        .unwrap()
        .run()
        .unwrap();
    let v: serde_json::Value = serde_json::from_str(&report::to_json(&unvalidated)).unwrap();
    assert!(v["validated"]["not_validated"][0]
        .as_str()
        .unwrap()
        .starts_with("time discretisation of the embedding system"));
    let csv = |prs| {
        let mut out = Vec::new();
        report::write_csv(prs, &mut out).unwrap();
        String::from_utf8(out).unwrap()
    };
    let (c_ball, c_boxes) = (csv(&ball), csv(&boxes));
    assert!(
        c_ball.starts_with("t,x,det_radius,r_t,psi,c,sigma,prs_radius,prs_x_lo,prs_x_hi\n0,1,"),
        "{c_ball}"
    );
    assert!(
        c_boxes.starts_with("t,x_lo,x_hi,r_t,psi\n0,0.9,1.1,0,0\n"),
        "{c_boxes}"
    );
    assert_eq!(c_boxes.lines().count(), 12);
    let s = report::summary(&boxes);
    assert!(
        s.contains("interval method") && s.contains("jacobian inclusion"),
        "{s}"
    );
    assert!(s.contains("x [lo, hi]"), "{s}");
    let s = report::summary(&ball);
    assert!(
        s.contains("kappa(n = 1, delta = 0.01)") && s.contains("amgf"),
        "{s}"
    );
}

/// A moving unsafe set's and a moving goal's positions (method.md 8.15) are written per report
/// time as `swept`, in the shapes' JSON form of `reachc inspect --json` (an infinite end
/// `null`); fixed sets have no `swept`. (The positions are filled in by hand: the engine's
/// sets here are fixed.)
#[test]
fn moving_sets_are_written_with_their_positions() {
    let mut info = model(vec![analysis("ball", Method::Contraction, true)]);
    let wall = |offset: f64| UnsafeShape::HalfSpace {
        normal: vec![1.0],
        offset,
    };
    let high = UnsafeShape::Box(vec![(0, Bounds::new(3.0, f64::INFINITY))]);
    *info.unsafe_sets_mut() = vec![
        UnsafeSet {
            name: "high".into(),
            shape: high.clone(),
            moving: vec![],
        },
        UnsafeSet {
            name: "wall".into(),
            shape: wall(2.0),
            moving: vec![],
        },
    ];
    let near = |c: f64| vec![UnsafeShape::Box(vec![(0, Bounds::new(c - 0.5, c + 0.5))])];
    *info.goals_mut() = vec![GoalSet {
        name: "near".into(),
        parts: near(0.0),
        moving: vec![],
        window: None,
        stay: false,
    }];
    let mut prs = Reach::paired(&DECAY, &info, "ball").unwrap().run().unwrap();
    let steps = prs.steps().len();
    assert!(steps > 2);
    // The wall moves out by 0.25 per report interval, the goal's centre by 0.125.
    prs.unsafe_sets_mut()[1].swept = (0..steps).map(|k| wall(2.0 + 0.25 * k as f64)).collect();
    prs.goals_mut()[0].swept = (0..steps).map(|k| near(0.125 * k as f64)).collect();
    let v: serde_json::Value = serde_json::from_str(&report::to_json(&prs)).unwrap();
    let (fixed, moving) = (&v["unsafe_sets"][0], &v["unsafe_sets"][1]);
    assert_eq!(fixed["name"], "high");
    assert!(fixed.get("swept").is_none());
    assert_eq!(moving["name"], "wall");
    let swept = moving["swept"].as_array().unwrap();
    assert_eq!(swept.len(), steps);
    for (k, s) in swept.iter().enumerate() {
        let offset = 2.0 + 0.25 * k as f64;
        assert_eq!(
            *s,
            serde_json::json!({"kind": "halfspace", "normal": [1.0], "offset": offset})
        );
    }
    let goal = v["goals"][0]["swept"].as_array().unwrap();
    assert_eq!(goal.len(), steps);
    for (k, parts) in goal.iter().enumerate() {
        let c = 0.125 * k as f64;
        assert_eq!(
            *parts,
            serde_json::json!([{"kind": "box", "sides": [{"state": "x", "range": [c - 0.5, c + 0.5]}]}])
        );
    }
    // The same form for an unbounded side as `reachc inspect --json`: `null`.
    prs.unsafe_sets_mut()[0].swept = vec![high; steps];
    let v: serde_json::Value = serde_json::from_str(&report::to_json(&prs)).unwrap();
    assert_eq!(
        v["unsafe_sets"][0]["swept"][steps - 1],
        serde_json::json!({"kind": "box", "sides": [{"state": "x", "range": [3.0, null]}]})
    );
    // Without positions the file is the fixed sets' file, byte for byte.
    for u in prs.unsafe_sets_mut() {
        u.swept.clear();
    }
    prs.goals_mut()[0].swept.clear();
    let fixed = Reach::paired(&DECAY, &info, "ball").unwrap().run().unwrap();
    assert_eq!(report::to_json(&prs), report::to_json(&fixed));
}
