use super::*;

/// The paths that first left the tube of `r` in each report interval, recounted from every
/// Euler-Maruyama state ([`result_substeps`]) with `Prs::span_contains` and, at report
/// times, `Prs::contains_at` alone; and how many of those first exits were at a state
/// between report times.
fn recount<S: System>(sys: &S, info: &ModelInfo, r: &Prs, opts: &Options) -> (Vec<u64>, u64) {
    let times: Vec<f64> = r.steps.iter().map(|s| s.t).collect();
    let fine = result_substeps(sys, info, r, opts).unwrap();
    let n = r.n();
    let mut left = vec![0; times.len()];
    let mut between = 0;
    let outside = |k: usize, x: &[f64], report: bool| {
        !x.iter().all(|v| v.is_finite())
            || !r.span_contains(k, x)
            || (report && !r.contains_at(k, x))
    };
    for path in &fine.paths {
        let state = |i: usize| &path[i * n..][..n];
        if outside(0, state(0), true) {
            left[0] += 1;
            continue;
        }
        let mut i = 1;
        'path: for (k, &s) in (1..).zip(&fine.per_interval) {
            for j in 0..s {
                if outside(k, state(i), j + 1 == s) {
                    left[k] += 1;
                    between += u64::from(j + 1 < s);
                    break 'path;
                }
                i += 1;
            }
        }
    }
    (left, between)
}

/// One path, leaving a hand-made tube between two report times and coming back: span `k`
/// narrowed to a P-ball around the path's state at `t_k` with half the distance of the
/// path's farthest state in the interval. The tube check counts it (in interval `k`), while
/// every report-time check passes; with the tube as computed, the path never leaves.
#[test]
fn a_path_leaving_the_tube_between_report_times_is_counted() {
    let (sys, info) = (sys(0.0), info(0.0));
    let r = engine::run_paired(&sys, &info, &info.analyses[0]).unwrap();
    let opts = Options {
        paths: 1,
        seed: 3,
        dt: Some(0.001),
        ..Options::default()
    };
    let fine = result_substeps(&sys, &info, &r, &opts).unwrap();
    assert_eq!(fine.per_interval, vec![10; 50]);
    let k = 20;
    let first = 1 + (k - 1) * 10;
    let state = |j: usize| &fine.paths[0][(first + j) * 2..][..2];
    let end = state(9);
    let dist = |x: &[f64]| ((x[0] - end[0]).powi(2) + (x[1] - end[1]).powi(2)).sqrt();
    let far = (0..9).map(|j| dist(state(j))).fold(0.0, f64::max);
    assert!(far > 1e-3, "{far}");
    let mut hand_made = r.clone();
    hand_made.steps[k].span = crate::prs::Span {
        lo: end.to_vec(),
        hi: end.to_vec(),
        radius: far / 2.0,
    };
    // Back inside at t_k, outside in between.
    assert!(hand_made.span_contains(k, end));
    assert!((0..9).any(|j| !hand_made.span_contains(k, state(j))));

    let simulate = |r: &Prs| simulate(&Paired::new(&sys, &info), r, &opts, &mut |_, _| {}).unwrap();
    let computed = simulate(&r);
    assert_eq!(computed.tube.as_ref().unwrap().outside, 0);
    let rep = simulate(&hand_made);
    let tube = rep.tube.as_ref().unwrap();
    assert_eq!((tube.outside, tube.fraction), (1, 1.0));
    for (j, st) in rep.steps.iter().enumerate() {
        assert_eq!(st.left_tube, Some(u64::from(j == k)), "step {j}");
        assert_eq!(st.outside, 0, "step {j}");
    }
    assert_eq!(rep.horizon.outside_any, 0);
    assert!(rep.verdict.pointwise_passed);
    assert_eq!(rep.verdict.decided_by, Guarantee::Uniform);
    assert_eq!(tube.checks_per_path, 501);
    assert_eq!(
        recount(&sys, &info, &hand_made, &opts),
        (rep.steps.iter().map(|s| s.left_tube.unwrap()).collect(), 1)
    );
}

/// The tube count is the recount from every Euler-Maruyama state with `Prs::span_contains`
/// and `Prs::contains_at` alone, interval by interval, with the tube as computed and
/// narrowed: in the fast loops for additive noise (eight-lane groups included), in the
/// general one with a metric that is not diagonal, and with inputs and an unsafe set.
#[test]
fn the_tube_count_is_a_recount_of_every_euler_state() {
    let identity = vec![1.0, 0.0, 0.0, 1.0];
    let skewed = vec![2.0, 0.7, 0.7, 1.0];
    for (b, metric, factor) in [
        (0.0, &identity, 0.6),
        (0.0, &skewed, 0.6),
        (1.0, &identity, 0.4),
    ] {
        let (sys, info) = (sys(b), info_in(b, metric.clone()));
        let r = engine::run_paired(&sys, &info, &info.analyses[0]).unwrap();
        for (factor, r) in [(1.0, r.clone()), (factor, narrow(&r, factor))] {
            let opts = Options {
                paths: 300,
                seed: 11,
                dt: Some(0.004),
                hold: Some(0.05),
                ..Options::default()
            };
            let rep = simulate(&Paired::new(&sys, &info), &r, &opts, &mut |_, _| {}).unwrap();
            let (left, between) = recount(&sys, &info, &r, &opts);
            let case = format!("b = {b}, metric {metric:?}, spans x {factor}");
            let counted: Vec<u64> = rep.steps.iter().map(|s| s.left_tube.unwrap()).collect();
            assert_eq!(counted, left, "{case}");
            let tube = rep.tube.as_ref().unwrap();
            assert_eq!(tube.outside, left.iter().sum::<u64>(), "{case}");
            // Every path outside the PRS at a report time has left the tube.
            assert!(tube.outside >= rep.horizon.outside_any, "{case}");
            if factor < 1.0 {
                // Not vacuous: many first exits, most of them between report times.
                assert!(
                    (30..270).contains(&tube.outside),
                    "{case}: {}",
                    tube.outside
                );
                assert!(2 * between > tube.outside, "{case}: {between}");
            }
        }
    }
}

/// A tube narrowed between report times (its PRS at the report times as computed): the
/// uniform check fails while every report time passes; the same result labelled pointwise
/// passes and reports no tube; the tube as computed passes with few paths leaving it. 1 and
/// 2 threads give the same reports.
#[test]
fn the_uniform_verdict_is_decided_by_the_tube() {
    let (sys, info) = (sys(0.0), info(0.0));
    let r = engine::run_paired(&sys, &info, &info.analyses[0]).unwrap();
    let run = |r: &Prs, threads: usize| {
        let opts = Options {
            paths: 3_000,
            seed: 5,
            dt: Some(0.0025),
            threads: Some(threads),
            ..Options::default()
        };
        simulate(&Paired::new(&sys, &info), r, &opts, &mut |_, _| {}).unwrap()
    };
    let computed = run(&r, 2);
    assert_eq!(computed, run(&r, 1));
    let tube = computed.tube.as_ref().unwrap();
    assert!(
        computed.passed() && tube.fraction < r.delta / 5.0,
        "{tube:?}"
    );
    assert!(tube.cp_lower <= tube.fraction && tube.fraction <= tube.cp_upper);
    assert_eq!(tube.checks_per_path, 201);

    let narrowed = narrow(&r, 0.5);
    let rep = run(&narrowed, 2);
    assert_eq!(rep, run(&narrowed, 1));
    let tube = rep.tube.as_ref().unwrap();
    assert!(!rep.passed());
    assert!(tube.cp_lower > r.delta, "{tube:?}");
    assert_eq!(rep.verdict.decided_by, Guarantee::Uniform);
    assert!(rep.verdict.pointwise_passed);
    assert_eq!(rep.verdict.failing_steps, 0);
    // The per-report-time statistics do not depend on the spans.
    assert_eq!(
        rep.steps.iter().map(|s| s.outside).collect::<Vec<_>>(),
        computed.steps.iter().map(|s| s.outside).collect::<Vec<_>>()
    );

    let mut pointwise = narrowed.clone();
    pointwise.guarantee = Guarantee::Pointwise;
    let rep = run(&pointwise, 2);
    assert!(rep.passed() && rep.tube.is_none());
    assert_eq!(rep.verdict.decided_by, Guarantee::Pointwise);
    assert!(rep.steps.iter().all(|s| s.left_tube.is_none()));
}

/// The contraction ball cut by a zonotope member (the interval run's boxes as zonotopes of
/// two generators, smaller than the ball, so that paths leave it), checked pointwise, with the
/// identity and a skewed metric: the eight-lane, AVX2 and baseline loops give the same
/// statistics (every state recorded, and with the quiet bounds), and the paths outside at
/// each report time are those `Prs::contains_at` finds outside among the same paths'
/// states ([`result_paths`]).
#[test]
fn a_zonotope_member_is_counted_as_contains_at_decides() {
    let sorted = ChunkStats::sorted;
    for metric in [vec![1.0, 0.0, 0.0, 1.0], vec![2.0, 0.7, 0.7, 1.0]] {
        let (sys, info) = (sys(0.0), info_in(0.0, metric.clone()));
        let mut r = engine::run_paired(&sys, &info, &info.analyses[0]).unwrap();
        r.guarantee = Guarantee::Pointwise;
        let mut boxes = info.clone();
        boxes.analyses[0].spec.method = Method::Interval;
        let b = engine::run_paired(&sys, &boxes, &boxes.analyses[0]).unwrap();
        r.also = vec![check::fixtures::boxes_to_zonotopes(
            b,
            check::fixtures::SQUARE,
            0.2,
        )];
        let opts = Options {
            paths: 300,
            seed: 5,
            dt: Some(0.004),
            ..Options::default()
        };
        for threshold in [f64::NEG_INFINITY, 0.05] {
            let mut plan = make_plan(&sys, &info, &r, &opts).unwrap();
            let thresholds = Thresholds::uniform(plan.times.len(), plan.sys.n(), threshold);
            let detected = sorted(plan.run_chunk(0..300, &thresholds));
            plan.avx512 = false;
            let avx2 = sorted(plan.run_chunk(0..300, &thresholds));
            plan.avx2 = false;
            let baseline = sorted(plan.run_chunk(0..300, &thresholds));
            assert_eq!(detected, baseline, "{metric:?}, {threshold}");
            assert_eq!(avx2, baseline, "{metric:?}, {threshold}");
        }
        let rep = simulate(&Paired::new(&sys, &info), &r, &opts, &mut |_, _| {}).unwrap();
        let paths = result_paths(&sys, &info, &r, &opts).unwrap();
        let outside: Vec<u64> = (0..r.steps.len())
            .map(|k| {
                let outside = paths.iter().filter(|p| !r.contains_at(k, &p[k * 2..][..2]));
                outside.count() as u64
            })
            .collect();
        let counted: Vec<u64> = rep.steps.iter().map(|s| s.outside).collect();
        assert_eq!(counted, outside, "{metric:?}");
        // Not vacuous: the member cuts some paths off, not most.
        let all: u64 = outside.iter().sum();
        let states = 300 * r.steps.len() as u64;
        assert!(
            all > 30 && all < states / 2,
            "{metric:?}: {all} of {states}"
        );
    }
}

/// Malformed spans are refused with a message, not a panic.
#[test]
fn malformed_spans_are_refused() {
    let (sys, info) = (sys(0.0), info(0.0));
    let r = engine::run_paired(&sys, &info, &info.analyses[0]).unwrap();
    let opts = Options {
        paths: 10,
        ..Options::default()
    };
    for (what, change) in [
        (
            "radius",
            &(|s: &mut crate::prs::Span| s.radius = f64::NAN) as &dyn Fn(&mut crate::prs::Span),
        ),
        ("radius", &|s| s.radius = -1.0),
        ("corner", &|s| s.lo.pop().map_or((), drop)),
        ("corner", &|s| s.hi[0] = s.lo[0] - 1.0),
    ] {
        let mut bad = r.clone();
        change(&mut bad.steps[3].span);
        match simulate(&Paired::new(&sys, &info), &bad, &opts, &mut |_, _| {}) {
            Err(SimError::Invalid(m @ SimInvalid::Span { step: 3, .. })) => {
                assert!(m.to_string().contains(what), "{m}")
            }
            other => panic!("{other:?}"),
        }
    }
}
