//! Monte Carlo validation (`reachc_runtime::simulate`): quantiles against the exact Gaussian of
//! the linear example, independence of the thread count, a wrong PRS caught by the coverage
//! check, and the `simulate` command line of generated binaries.

mod common;

use reachc_runtime::app::{EXIT_FAILED, EXIT_OK, EXIT_USAGE};
use reachc_runtime::engine;
use reachc_runtime::merge::merge_files;
use reachc_runtime::model::*;
use reachc_runtime::report::simulation::{summary, to_json};
use reachc_runtime::simulate::{self, InputMode, Options, SimReport};
use reachc_runtime::system::Paired;
use reachc_runtime::Prs;
use reachc_test_support::models::model;
use reachc_test_support::systems::Linear;

/// The paper's linear example (specs/linear.sde): n = 2, a = -0.4, s = sqrt(2), X0 = 0.
const LINEAR: Linear = Linear {
    n: 2,
    a: -0.4,
    b: 0.0,
    s: std::f64::consts::SQRT_2,
};

/// A faster decay with an input (`b = 1`) and weaker noise.
const DRIVEN: Linear = Linear {
    n: 2,
    a: -1.0,
    b: 1.0,
    s: 0.5,
};

/// Model info of a [`Linear`] with the exact constants (`c = a`, `sigma = s`, `rho = |b| h`),
/// initial box `[x0 - w, x0 + w]` per state and, with an input, the input box `[-h, h]`.
fn info(sys: &Linear, x0: f64, w: f64, h: f64, delta: f64, sigma_factor: f64) -> ModelInfo {
    let n = sys.n;
    let mut metric = vec![0.0; n * n];
    for i in 0..n {
        metric[i * n + i] = 1.0;
    }
    let mut info = ModelInfo::from_parts(ModelParts {
        states: (1..=n).map(|i| format!("x{i}")).collect(),
        noises: (1..=n).map(|i| format!("w{i}")).collect(),
        unsafe_sets: vec![UnsafeSet {
            name: "far".into(),
            shape: UnsafeShape::HalfSpace {
                normal: (0..n).map(|i| if i == 0 { 1.0 } else { 0.0 }).collect(),
                offset: 1.5,
            },
            moving: Vec::new(),
        }],
        ..model("linear", &[], &[], &vec![(x0 - w, x0 + w); n]).into_parts()
    });
    if sys.b != 0.0 {
        *info.inputs_mut() = vec!["u".into()];
        *info.input_box_mut() = vec![Bounds::new(-h, h)];
    }
    let constants = Constants::given(
        &info,
        metric,
        sys.a,
        // A factor below 1 makes the PRS too small (a wrong analysis).
        sys.s * sigma_factor,
        (sys.b * h * n as f64).abs(),
    );
    info.analyses_mut().push(Analysis {
        spec: AnalysisSpec {
            name: "main".into(),
            delta,
            horizon: 1.5,
            step: 0.01,
            rate: Rate::Global,
            ..AnalysisSpec::default()
        },
        constants: Ok(constants),
    });
    info
}

fn run(sys: &Linear, info: &ModelInfo) -> Prs {
    engine::run_paired(sys, info, &info.analyses()[0]).unwrap()
}

fn simulate(sys: &Linear, info: &ModelInfo, r: &Prs, opts: &Options) -> SimReport {
    simulate::simulate(&Paired::new(sys, info), r, opts, &mut |_, _| {}).unwrap()
}

/// With X0 = 0, the Euler-Maruyama iterate is exactly Gaussian: per coordinate,
/// `v_{k+1} = (1 + a h)^2 v_k + s^2 h`, and `|X|^2 / v` is chi-square with 2 degrees of
/// freedom, so the (1 - delta) quantile of |X| is `sqrt(-2 v ln delta)`.
#[test]
fn linear_quantiles_match_the_exact_gaussian() {
    let delta = 0.01;
    let info = info(&LINEAR, 0.0, 0.0, 0.0, delta, 1.0);
    let r = run(&LINEAR, &info);
    let paths = 40_000;
    let rep = simulate(
        &LINEAR,
        &info,
        &r,
        &Options {
            paths,
            ..Options::default()
        },
    );
    assert_eq!(rep.quantile_rank, 401, "floor(delta N) + 1");
    let h: f64 = 0.01;
    let mut v = 0.0;
    let mut max_rel: f64 = 0.0;
    for (k, st) in rep.steps.iter().enumerate().skip(1) {
        v = (1.0 + LINEAR.a * h).powi(2) * v + 2.0 * h;
        let exact = (-2.0 * v * delta.ln()).sqrt();
        // Relative standard error of the 0.99 quantile with 40000 samples: about 0.5%.
        let rel = (st.quantile - exact) / exact;
        max_rel = max_rel.max(rel.abs());
        if k % 25 == 0 {
            assert!(
                rel.abs() < 0.025,
                "t = {}: {} vs {exact}",
                st.t,
                st.quantile
            );
        }
        // The PRS (here the stochastic ball alone) is conservative: r_t above the quantile.
        assert!(
            st.r_t > st.quantile && st.prs_radius == st.r_t,
            "t = {}",
            st.t
        );
        assert!(st.max >= st.quantile);
        // Per state, X_i ~ N(0, v): the smallest interval about 0 holding 1 - delta of the
        // paths has half-width z_{1 - delta/2} sqrt(v), z_{0.995} = 2.5758293.
        let exact_i = 2.575_829_303_548_9 * v.sqrt();
        for (i, sp) in st.states.iter().enumerate() {
            let rel = (sp.quantile - exact_i) / exact_i;
            max_rel = max_rel.max(rel.abs());
            if k % 25 == 0 {
                assert!(
                    rel.abs() < 0.025,
                    "t = {}, state {i}: {sp:?} vs {exact_i}",
                    st.t
                );
            }
            // The PRS's box about the nominal: within the ball's, r_t sqrt((P^-1)_ii) = r_t,
            // and above the sample's spread.
            assert!(
                sp.prs <= st.r_t * (1.0 + 1e-12) && sp.prs > sp.quantile,
                "{sp:?}"
            );
            assert!(sp.max >= sp.quantile && sp.ratio() > 1.0, "{sp:?}");
        }
    }
    assert_eq!(rep.states, ["x1", "x2"]);
    assert!(max_rel < 0.04, "largest relative error {max_rel}");
    // The time average of the (correlated) errors is much smaller than each.
    let mean: f64 = {
        let mut v = 0.0;
        let errs: Vec<f64> = rep.steps[1..]
            .iter()
            .map(|st| {
                v = (1.0 + LINEAR.a * h).powi(2) * v + 2.0 * h;
                st.quantile / (-2.0 * v * delta.ln()).sqrt() - 1.0
            })
            .collect();
        errs.iter().sum::<f64>() / errs.len() as f64
    };
    assert!(mean.abs() < 0.01, "mean relative error {mean}");
    assert!(rep.passed(), "{}", summary(&rep));
    // X0 = 0: the t = 0 state is the nominal exactly, inside the (zero-radius) PRS.
    assert_eq!(rep.steps[0].outside, 0);
    assert_eq!(rep.steps[0].quantile, 0.0);
    assert_eq!(rep.steps_per_path, 150);
}

/// Paths from a box of initial states, with random piecewise-constant inputs, Euler steps
/// finer than the report step and an unsafe set: 1 and 2 worker threads give the same report.
#[test]
fn results_do_not_depend_on_the_thread_count() {
    let sys = DRIVEN;
    let info = info(&sys, 0.5, 0.2, 0.3, 0.05, 1.0);
    let r = run(&sys, &info);
    let json = |threads: usize, inputs: InputMode| {
        to_json(&simulate(
            &sys,
            &info,
            &r,
            &Options {
                paths: 3_000,
                seed: 7,
                dt: Some(0.004),
                hold: Some(0.05),
                inputs,
                threads: Some(threads),
                ..Options::default()
            },
        ))
    };
    for inputs in [InputMode::Random, InputMode::Corners] {
        let one = json(1, inputs);
        assert_eq!(one, json(2, inputs), "{inputs:?}");
        let v: serde_json::Value = serde_json::from_str(&one).unwrap();
        assert_eq!(v["steps_per_path"], 450);
        assert_eq!(v["inputs"]["mode"], inputs.name());
        // Some paths reach x1 >= 1.5 (the drift pulls towards u / 1 <= 0.3; noise 0.5).
        let hits = v["unsafe_sets"][0]["hits"].as_u64().unwrap();
        assert!(hits > 0 && hits < 3_000, "{hits}");
    }
    // Another seed gives other paths.
    let other = simulate(
        &sys,
        &info,
        &r,
        &Options {
            paths: 3_000,
            seed: 8,
            dt: Some(0.004),
            hold: Some(0.05),
            ..Options::default()
        },
    );
    assert_ne!(to_json(&other), json(1, InputMode::Random));
}

/// `simulate` and `result_paths` run the same paths: with one path, the quantile reported at
/// each time is that path's distance to the nominal, which equals (to the bit) the distance of
/// the recorded path. Covers the fast loop for additive noise (no inputs, no unsafe set) and the
/// general one (inputs, an unsafe set, Euler steps finer than the report step).
#[test]
fn simulated_paths_are_the_recorded_sample_paths() {
    let mut additive = info(&LINEAR, 0.3, 0.2, 0.0, 0.05, 1.0);
    additive.unsafe_sets_mut().clear();
    let general = info(&DRIVEN, 0.5, 0.2, 0.3, 0.05, 1.0);
    for (sys, info, dt) in [(&LINEAR, &additive, None), (&DRIVEN, &general, Some(0.004))] {
        let r = run(sys, info);
        for seed in 0..10 {
            let opts = Options {
                paths: 1,
                seed,
                dt,
                hold: Some(0.05),
                ..Options::default()
            };
            let rep = simulate(sys, info, &r, &opts);
            let sampled = simulate::result_paths(sys, info, &r, &opts).unwrap();
            for (k, (st, res)) in rep.steps.iter().zip(r.steps()).enumerate() {
                let x = &sampled[0][k * sys.n..][..sys.n];
                // The identity metric's distance, summed as the simulation sums it.
                let q = x
                    .iter()
                    .zip(res.nominal())
                    .map(|(x, c)| (x - c) * (x - c))
                    .reduce(|q, t| q + t)
                    .unwrap();
                assert_eq!(st.quantile, q.sqrt(), "seed {seed}, t = {}", st.t);
                // Per state, the one path's deviation.
                for ((sp, x), c) in st.states.iter().zip(x).zip(res.nominal()) {
                    assert_eq!(sp.quantile, (x - c).abs(), "seed {seed}, t = {}", st.t);
                    assert_eq!(sp.max, sp.quantile);
                }
            }
        }
    }
}

/// A pointwise PRS computed with half the true noise level is too small: the coverage check
/// fails, and a PRS shrunk after the fact as well. The correct one passes. The same for a
/// time-uniform tube, decided by the paths leaving it.
#[test]
fn a_too_small_prs_fails_the_coverage_check() {
    let opts = Options {
        paths: 5_000,
        ..Options::default()
    };
    // The pointwise semantics (the tube's radii are larger: see below).
    let pointwise = |mut info: ModelInfo| {
        info.analyses_mut()[0].spec.guarantee = Guarantee::Pointwise;
        info
    };
    let good = pointwise(info(&LINEAR, 0.0, 0.0, 0.0, 0.01, 1.0));
    let r = run(&LINEAR, &good);
    let rep = simulate(&LINEAR, &good, &r, &opts);
    assert!(rep.passed() && rep.tube.is_none());

    let wrong = pointwise(info(&LINEAR, 0.0, 0.0, 0.0, 0.01, 0.5));
    let rep = simulate(&LINEAR, &wrong, &run(&LINEAR, &wrong), &opts);
    assert!(!rep.passed());
    // Half the radius: with r_t about q_0.99 / 0.86 (the amgf rule's slack at n = 2),
    // P(chi2_2 > ln(100) / (4 * 0.86^2)) = 0.21 of the paths outside at each step.
    let last = rep.steps.last().unwrap();
    assert!(
        last.fraction > 0.15 && last.fraction < 0.25,
        "{}",
        last.fraction
    );
    assert_eq!(
        rep.verdict.failing_steps, 150,
        "every step after t = 0 fails"
    );

    let mut shrunk = r.clone();
    for st in shrunk.steps_mut() {
        st.prs_radius *= 0.6;
    }
    let rep = simulate(&LINEAR, &good, &shrunk, &opts);
    assert!(!rep.passed());
    assert!(rep.verdict.worst_cp_lower > 0.01, "{:?}", rep.verdict);

    // Time-uniform (the default): the correct tube holds, few paths leave it.
    let good = info(&LINEAR, 0.0, 0.0, 0.0, 0.01, 1.0);
    let rep = simulate(&LINEAR, &good, &run(&LINEAR, &good), &opts);
    let tube = rep.tube.clone().unwrap();
    assert!(rep.passed() && tube.fraction < 0.002, "{}", summary(&rep));
    // Half the noise: a quarter of the variance, so the tube's radius is too small by a factor
    // 2 at every time, and most paths leave it; the verdict is the tube's.
    let wrong = info(&LINEAR, 0.0, 0.0, 0.0, 0.01, 0.5);
    let rep = simulate(&LINEAR, &wrong, &run(&LINEAR, &wrong), &opts);
    let tube = rep.tube.clone().unwrap();
    assert!(!rep.passed() && tube.cp_lower > 0.5, "{}", summary(&rep));
    assert_eq!(rep.verdict.decided_by, Guarantee::Uniform);
}

/// The JSON and the summary say what was checked: for a uniform result the tube (all times
/// at once, every Euler-Maruyama step) decides, its count is the per-interval first exits'
/// sum, and the pointwise sentence is absent; a pointwise result keeps every field it had
/// (plus `guarantee`, `outside_tube: null` and the verdict's `decided_by` and
/// `pointwise_status`) and its sentence.
#[test]
fn reports_say_what_was_checked() {
    let sys = DRIVEN;
    let uniform = info(&sys, 0.5, 0.2, 0.3, 0.05, 1.0);
    let mut pointwise = uniform.clone();
    pointwise.analyses_mut()[0].spec.guarantee = Guarantee::Pointwise;
    let opts = Options {
        paths: 2_000,
        seed: 3,
        dt: Some(0.0025),
        ..Options::default()
    };
    // The tube narrowed between report times: paths leave it.
    let mut narrow = run(&sys, &uniform);
    for st in &mut narrow.steps_mut()[1..] {
        st.span.radius *= 0.5;
    }
    let rep = simulate(&sys, &uniform, &narrow, &opts);
    let v: serde_json::Value = serde_json::from_str(&to_json(&rep)).unwrap();
    assert_eq!(v["guarantee"], "uniform");
    let tube = &v["outside_tube"];
    let count = tube["count"].as_u64().unwrap();
    assert!(count > 100 && count < 2_000, "{tube}");
    assert_eq!(tube["fraction"], count as f64 / 2_000.0);
    let (lower, upper) = (
        tube["cp_lower"].as_f64().unwrap(),
        tube["cp_upper"].as_f64().unwrap(),
    );
    assert!(lower < count as f64 / 2_000.0 && count as f64 / 2_000.0 < upper);
    assert_eq!(tube["checks_per_path"], 601);
    assert!(tube["checked"]
        .as_str()
        .unwrap()
        .contains("every Euler-Maruyama step"));
    let steps = v["steps"].as_array().unwrap();
    let left: u64 = steps.iter().map(|s| s["left_tube"].as_u64().unwrap()).sum();
    assert_eq!(left, count);
    assert_eq!(v["verdict"]["status"], "fail");
    assert_eq!(v["verdict"]["decided_by"], "uniform");
    assert_eq!(v["verdict"]["pointwise_status"], "pass");
    let text = summary(&rep);
    assert!(text.contains("uniform guarantee"), "{text}");
    assert!(
        text.contains(&format!("tube, all times at once: {count} paths"))
            && text.contains("checked at every Euler-Maruyama step (601 states per path)"),
        "{text}"
    );
    assert!(text.contains("coverage: FAIL (uniform: "), "{text}");
    assert!(!text.contains("each time separately"), "{text}");

    let r = run(&sys, &pointwise);
    let rep = simulate(&sys, &pointwise, &r, &opts);
    let v: serde_json::Value = serde_json::from_str(&to_json(&rep)).unwrap();
    let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    for key in [
        "model",
        "analysis",
        "method",
        "delta",
        "paths",
        "seed",
        "dt",
        "steps_per_path",
        "initial_states",
        "inputs",
        "noise",
        "compared",
        "quantile_rank",
        "confidence",
        "steps",
        "horizon",
        "unsafe_sets",
        "left_domain",
        "diverged",
        "verdict",
    ] {
        assert!(keys.contains(&key), "{key}");
    }
    assert_eq!(v["guarantee"], "pointwise");
    assert!(v["outside_tube"].is_null());
    let step_keys: Vec<&str> = v["steps"][1]
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    // (Sorted: serde_json's map.)
    assert_eq!(
        step_keys,
        [
            "cp_upper",
            "fraction",
            "max",
            "outside",
            "prs_radius",
            "quantile",
            "r_t",
            "states",
            "t"
        ]
    );
    assert_eq!(v["verdict"]["status"], "pass");
    assert_eq!(v["verdict"]["decided_by"], "pointwise");
    let text = summary(&rep);
    assert!(
        text.contains("the PRS bounds each time separately"),
        "{text}"
    );
    assert!(!text.contains("tube"), "{text}");
}

fn cli(info: &ModelInfo, args: &[&str]) -> (u8, String, String) {
    common::run_main(&LINEAR, info, args)
}

#[test]
fn simulate_command_line() {
    let dir = std::env::temp_dir().join(format!("reachc-simulate-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let d = dir.to_str().unwrap();
    let good = info(&LINEAR, 0.0, 0.0, 0.0, 0.01, 1.0);
    let (code, out, err) = cli(&good, &["simulate", "--paths", "2000", "-o", d]);
    assert_eq!(code, EXIT_OK, "{err}");
    assert!(
        out.contains("coverage: PASS") && out.contains("path-steps/s"),
        "{out}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("main.sim.json")).unwrap()).unwrap();
    assert_eq!(json["verdict"]["status"], "pass");
    assert_eq!(json["paths"], 2000);
    assert_eq!(json["steps"].as_array().unwrap().len(), 151);

    // --delta recomputes the PRS: a larger delta, a smaller PRS.
    let (code, _, err) = cli(
        &good,
        &[
            "simulate", "--paths", "500", "--delta", "0.2", "-q", "-o", d,
        ],
    );
    assert_eq!(code, EXIT_OK, "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("main.sim.json")).unwrap()).unwrap();
    assert_eq!(json["delta"], 0.2);

    // A wrong PRS: exit status 1, the report still written.
    let wrong = info(&LINEAR, 0.0, 0.0, 0.0, 0.01, 0.5);
    let (code, out, _) = cli(&wrong, &["simulate", "--paths", "2000", "-o", d]);
    assert_eq!(code, EXIT_FAILED);
    assert!(out.contains("coverage: FAIL"), "{out}");

    // --progress writes machine-readable lines.
    let (_, _, err) = cli(
        &good,
        &["simulate", "--paths", "10", "--progress", "-q", "-o", d],
    );
    assert!(err.contains("reachc-progress main 10 10"), "{err}");

    // An analysis without constants has no PRS: skipped, not a failure.
    let mut none = good.clone();
    none.analyses_mut()[0].constants = Err(reachc_runtime::model::NoConstants::NotCertified {
        constant: "c".into(),
    });
    let (code, _, err) = cli(&none, &["simulate", "--paths", "10", "-o", d]);
    assert_eq!(code, EXIT_OK);
    assert!(
        err.contains("skipped analysis `main`: no PRS to check"),
        "{err}"
    );

    for bad in [
        &["simulate"][..],
        &["simulate", "--paths", "0"],
        &["simulate", "--paths", "ten"],
        &["simulate", "--paths", "10", "--inputs", "sideways"],
        &["simulate", "--paths", "10", "--delta", "1.5"],
        &["simulate", "--paths", "10", "--dt", "-1"],
        &["simulate", "--paths", "10", "--analysis", "nope"],
        &["simulate", "--paths", "10", "--threads", "0"],
    ] {
        let (code, _, err) = cli(&good, bad);
        assert_eq!(code, EXIT_USAGE, "{bad:?}: {err}");
        assert!(err.starts_with("error: "), "{bad:?}: {err}");
    }
    let (code, out, _) = cli(&good, &["simulate", "--help"]);
    assert_eq!(code, EXIT_OK);
    assert!(out.contains("--paths N"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `simulate --shard I/K` for every shard, then `merge_files`: the unsharded run's reports,
/// byte for byte, for 1 shard, 3 (not dividing the paths) and 8; two analyses (a uniform and a
/// pointwise one), so the parts are grouped by analysis.
#[test]
fn shards_merge_into_the_unsharded_reports() {
    let dir = std::env::temp_dir().join(format!("reachc-simulate-shards-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut info = info(&LINEAR, 0.0, 0.0, 0.0, 0.05, 1.0);
    let mut pointwise = info.analyses()[0].clone();
    pointwise.spec.name = "pointwise".into();
    pointwise.spec.guarantee = Guarantee::Pointwise;
    info.analyses_mut().push(pointwise);
    let run = [
        "simulate", "--paths", "1000", "--seed", "4", "--dt", "0.005",
    ];
    let whole = dir.join("whole");
    let (code, _, err) = cli(
        &info,
        &[&run[..], &["-q", "-o", whole.to_str().unwrap()]].concat(),
    );
    assert_eq!(code, EXIT_OK, "{err}");
    for k in [1, 3, 8] {
        let parts = dir.join(format!("parts-{k}"));
        for i in 0..k {
            let shard = format!("{i}/{k}");
            let args = [
                "--shard",
                &shard,
                "--spec-hash",
                "abc",
                "-o",
                parts.to_str().unwrap(),
            ];
            let (code, out, err) = cli(&info, &[&run[..], &args].concat());
            assert_eq!(code, EXIT_OK, "{err}");
            let (lo, hi) = (i * 1000 / k, (i + 1) * 1000 / k);
            assert!(
                out.contains(&format!(
                    "simulated `main`, shard {shard}: paths {lo}..{hi} of 1000"
                )),
                "{out}"
            );
            assert!(
                out.contains(&format!("main.shard-{i}-of-{k}.part")),
                "{out}"
            );
        }
        let mut files: Vec<_> = std::fs::read_dir(&parts)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        assert_eq!(files.len(), 2 * k);
        let merged = dir.join(format!("merged-{k}"));
        let (mut out, mut err) = (Vec::new(), Vec::new());
        let code = merge_files(&files, &merged, false, &mut out, &mut err);
        let out = String::from_utf8(out).unwrap();
        assert_eq!(code, EXIT_OK, "{}", String::from_utf8_lossy(&err));
        assert!(out.contains("coverage: PASS"), "{out}");
        for name in ["main.sim.json", "pointwise.sim.json"] {
            let read = |d: &std::path::Path| std::fs::read(d.join(name)).unwrap();
            assert!(read(&merged) == read(&whole), "{k} shards: {name} differs");
        }
        if k == 1 {
            continue;
        }
        // A shard missing: an input error naming it, nothing written.
        let (mut out, mut err) = (Vec::new(), Vec::new());
        let missing = dir.join(format!("missing-{k}"));
        let code = merge_files(&files[1..], &missing, true, &mut out, &mut err);
        let err = String::from_utf8(err).unwrap();
        assert_eq!(code, EXIT_USAGE);
        assert!(err.contains("analysis `main`: missing shard 0/"), "{err}");
        assert!(!missing.exists());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
