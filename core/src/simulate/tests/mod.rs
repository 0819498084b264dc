//! The simulation as a whole: the loops agree, the tube is counted from every Euler state,
//! moving sets are met where they are.

mod moving;
mod tube;

use super::paths::{ChunkStats, Thresholds};
use super::plan::make_plan;
use super::*;
use crate::engine;
use crate::interval::Interval;
use crate::model::*;
use crate::system::{Paired, System};
use crate::test_support::models::model;
use crate::test_support::systems::Linear;

/// `dx = (-x + b u) dt + 0.3 dW` per state, two states and one input (none if `b = 0`).
pub(super) fn sys(b: f64) -> Linear {
    Linear {
        n: 2,
        a: -1.0,
        b,
        s: 0.3,
    }
}

/// With `b != 0`: an input in `[-0.5, 0.5]` and an unsafe half-space `x1 >= 0.4`; the
/// identity metric.
pub(super) fn info(b: f64) -> ModelInfo {
    info_in(b, vec![1.0, 0.0, 0.0, 1.0])
}

/// [`info`] with the metric `metric` (`2 x 2`, row-major); the analysis is time-uniform
/// (the default).
fn info_in(b: f64, metric: Vec<f64>) -> ModelInfo {
    let mut info = model(
        "m",
        &["x1", "x2"],
        &["w1", "w2"],
        &[(0.1, 0.3), (-0.1, 0.1)],
    );
    if b != 0.0 {
        info.inputs = vec!["u".into()];
        info.input_box = vec![Bounds::new(-0.5, 0.5)];
        info.unsafe_sets = vec![UnsafeSet {
            name: "far".into(),
            shape: UnsafeShape::HalfSpace {
                normal: vec![1.0, 0.0],
                offset: 0.4,
            },
            moving: Vec::new(),
        }];
    }
    // |(b u, b u)| <= sqrt(2) |b| / 2 over the input box; mu_P(-I) = -1 in any metric.
    let constants = Constants::given(&info, metric, -1.0, 0.3, b.abs());
    info.analyses.push(Analysis {
        spec: AnalysisSpec {
            name: "a".into(),
            delta: 0.05,
            horizon: 0.5,
            step: 0.01,
            ..AnalysisSpec::default()
        },
        constants: Ok(constants),
    });
    info
}

/// The loops compiled for AVX2 and BMI2 and the eight-lane AVX-512 loop (when the
/// processor has them) and the baseline loops give the same statistics, in the fast loop
/// for additive noise (`b = 0`) and in the general one (an input, an unsafe set, Euler
/// steps finer than the report step); with every state recorded (no threshold) and with
/// the quiet bounds (only candidates and states near the PRS boundary recorded); for the
/// time-uniform result as computed, with its spans narrowed (many paths leave the tube,
/// some at states near its boundary) and as a pointwise result (no tube). 300 paths:
/// blocks of 64 and a last one of 44, whose last 4 paths are not a group of eight.
#[test]
fn the_extensions_do_not_change_the_paths() {
    // The eight-lane loop records a group's steps in turn, the others a step's paths.
    let sorted = ChunkStats::sorted;
    let identity = vec![1.0, 0.0, 0.0, 1.0];
    let skewed = vec![2.0, 0.7, 0.7, 1.0];
    // The factor narrowing the spans: with an input, R_t and the spans are larger.
    for (b, metric, threshold, factor) in [
        (0.0, &identity, f64::NEG_INFINITY, 0.6),
        (0.0, &identity, 0.05, 0.6),
        (1.0, &identity, f64::NEG_INFINITY, 0.4),
        (0.0, &skewed, 0.05, 0.6),
    ] {
        let (sys, info) = (sys(b), info_in(b, metric.clone()));
        let r = engine::run_paired(&sys, &info, &info.analyses[0]).unwrap();
        let mut pointwise = r.clone();
        pointwise.guarantee = Guarantee::Pointwise;
        for (tube, r) in [
            ("computed", r.clone()),
            ("narrow", narrow(&r, factor)),
            ("pointwise", pointwise),
        ] {
            let opts = Options {
                dt: Some(0.004),
                ..Options::default()
            };
            let mut plan = make_plan(&sys, &info, &r, &opts).unwrap();
            let thresholds = Thresholds::uniform(plan.times.len(), plan.sys.n(), threshold);
            let detected = sorted(plan.run_chunk(0..300, &thresholds));
            plan.avx512 = false;
            let avx2 = sorted(plan.run_chunk(0..300, &thresholds));
            plan.avx2 = false;
            let baseline = sorted(plan.run_chunk(0..300, &thresholds));
            let case = format!("b = {b}, metric {metric:?}, threshold {threshold}, {tube}");
            assert_eq!(detected, baseline, "{case}");
            assert_eq!(avx2, baseline, "{case}");
            let records = baseline.candidates.len();
            if threshold < 0.0 {
                assert_eq!(records, 300 * plan.times.len());
            } else {
                assert!(
                    records > 0 && records < 300 * plan.times.len() / 2,
                    "{records}"
                );
            }
            let left: u64 = baseline.left_tube.iter().sum();
            assert_eq!(left, baseline.outside_tube, "{case}");
            match tube {
                "computed" => assert!(baseline.outside_tube < 30, "{case}"),
                "narrow" => assert!(
                    (30..270).contains(&baseline.outside_tube),
                    "{case}: {}",
                    baseline.outside_tube
                ),
                _ => assert_eq!(baseline.outside_tube, 0, "{case}"),
            }
        }
    }
}

/// `r` with the radius of every span after `t = 0` scaled by `factor`: a tube too narrow
/// between report times (the PRS at the report times is unchanged).
pub(super) fn narrow(r: &Prs, factor: f64) -> Prs {
    let mut r = r.clone();
    for st in &mut r.steps[1..] {
        st.span.radius *= factor;
    }
    r
}
